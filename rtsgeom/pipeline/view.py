"""The report's 3D view of a run's setup, rendered beside the run: what the view needs (the
geometry and its exact paths) and nothing of the simulation, so that ``rtsgeom run`` forks it
before importing the rest of the pipeline (0.3 s of imports the view's process does not need)."""

from __future__ import annotations

from .._lib.parallel import Forked, fork_call
from ..geometry import build_setup
from ..paths import compute_paths, exact_paths

__all__ = ["REPORT_VIEW_SIZE", "setup_png", "start_setup_view"]

#: the report's 3D view in pixels: the report shows it at most 1100 CSS pixels wide, so a
#: larger render is scaled down (its labels to 9-10 px) and costs more (1600 x 1000: +0.15 s
#: of the main job's critical CPU); ``rtsgeom show --png`` has its own ``--size``
REPORT_VIEW_SIZE = (1280, 800)


def setup_png(setup, paths, paths_method: str) -> bytes:
    """The report's 3D view of ``setup`` with its ``paths`` as PNG bytes."""
    from ..viz.scene3d import setup_png_bytes
    if paths_method != "exact":  # the view draws reflections through their hit points,
        # which the table alone does not carry
        paths = compute_paths(setup, paths_method, for_drawing=True)
    return setup_png_bytes(setup, paths, REPORT_VIEW_SIZE)


def start_setup_view(scene) -> Forked:
    """The report's 3D view of ``scene``'s setup with its exact paths, rendered in a process
    forked now (``_lib.parallel.fork_call``) while the run simulates: it depends on the
    geometry alone, and its imports (pyvista, VTK, trimesh) and render take ~1.5 s of CPU beside
    the run's. Pass it to :func:`rtsgeom.pipeline.output.write_run` (``setup_view``).
    matplotlib, which the run's own figures need and pyvista's colours import, is imported
    here before the fork (the view's process inherits it instead of importing it again:
    ~0.3 s of CPU)."""
    from ..viz import figures  # noqa: F401
    setup = build_setup(scene)
    return fork_call(setup_png, setup, exact_paths(setup), "exact")
