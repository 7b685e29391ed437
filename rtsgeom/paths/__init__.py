"""Propagation paths per antenna-element pair (stage 2): exact distances or ray tracing."""

from .table import DIRECTIONS, Paths
from .exact import exact_paths

__all__ = ["DIRECTIONS", "Paths", "exact_paths"]
