"""Setup geometry: the RuT's MIMO array, the front-end arc and the metal sheet (stage 1)."""

from .arrays import RutArray, rut_array, yaw_matrix
from .frontends import FrontEnds, antenna_positions, front_ends
from .setup import Setup, build_setup

__all__ = ["RutArray", "rut_array", "yaw_matrix", "FrontEnds", "antenna_positions",
           "front_ends", "Setup", "build_setup"]
