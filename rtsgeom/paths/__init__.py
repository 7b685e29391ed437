"""Propagation paths per antenna-element pair (stage 2): exact distances or ray tracing."""

from importlib import import_module

from .table import DIRECTIONS, Paths
from dataclasses import replace

from ..geometry.setup import nominal_scene, nominal_setup
from .exact import exact_paths
from ..scene.registry import PATH_METHODS

__all__ = ["DIRECTIONS", "Paths", "exact_paths", "compute_paths", "nominal_model"]


def compute_paths(setup, method: str = "exact", *, for_drawing: bool = False):
    """The paths of ``setup`` by a method of the registry (``registry.PATH_METHODS``).

    ``for_drawing``: what the 3D view draws (for ray tracing the table plus each reflection's
    hit points, :func:`rtsgeom.paths.raytrace.trace`). The method's module is imported only
    here, so Sionna loads only when ray tracing is asked for. Adding a method is one registry
    entry.
    """
    try:
        m = PATH_METHODS[method]
    except KeyError:
        raise ValueError(f"paths method {method!r}: must be one of "
                         f"{', '.join(PATH_METHODS)}") from None
    module, func = (m.draw if for_drawing else m.compute).split(":")
    return getattr(import_module(module), func)(setup)


def nominal_model(setup, paths: Paths) -> tuple:
    """The nominal setup and its paths (the ones given when the setup has no errors)."""
    nom = nominal_setup(setup)
    if nom is setup:
        return setup, paths
    s = setup.scene
    if s.radar.channels is not None:  # the radar's channels do not move a path
        bare = replace(s, radar=replace(s.radar, channels=None))
        if nominal_scene(bare) is bare:
            return nom, paths
    if paths.method == "exact":
        return nom, exact_paths(nom)
    from .raytrace import raytrace_paths  # here: Sionna RT loads only for ray tracing
    return nom, raytrace_paths(nom)
