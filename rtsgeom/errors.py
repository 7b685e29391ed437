"""The exceptions a user's input can cause, each a ``ValueError`` (or, for a missing system
capability, a ``RuntimeError``) whose message names the field or argument and its allowed range.
The CLI turns each into ``rtsgeom: error: ...`` and exit code 2; library callers catch the
specific class, never a bare ``ValueError`` (which then stays what it is: a bug).

Defined here, with no imports, so that any module can raise them:

* :class:`ParameterError`: an argument that is not a scene field (a radius sweep, a pair, a
  distribution, an output format's constraint) is outside its allowed range.
* :class:`CaptureError`: a probe capture (read or to simulate) does not fit the scene.

Defined beside what they guard (import them from there):

* ``rtsgeom.scene.scene.SceneError`` (``schema.py``): a scene file or field is invalid;
  ``rtsgeom.radar.link.LinkError`` is one.
* ``rtsgeom._lib.io.OutputError``: an output path cannot or must not be written.
* ``rtsgeom.synthesis.model.AngleUnreachable``, ``rtsgeom.synthesis.cells.CellUnreachable``: a set direction
  lies outside what the front ends can synthesize.
* ``rtsgeom.paths.raytrace.RaytraceUnavailable``, ``rtsgeom.viz.render_backend.VizError``,
  ``rtsgeom._lib.parallel.ClusterError`` (``RuntimeError``): ray tracing, rendering or a cluster is
  not available here.
"""

from __future__ import annotations

__all__ = ["ParameterError", "CaptureError"]


class ParameterError(ValueError):
    """An argument (not a scene field) is outside its allowed range; the message names it."""


class CaptureError(ValueError):
    """A probe capture does not fit the scene, or its file or sidecar cannot be read."""
