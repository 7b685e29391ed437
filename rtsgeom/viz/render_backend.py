"""An OpenGL context for VTK's off-screen rendering (EGL, OSMesa, or Xvfb as a last resort);
:class:`VizError` when there is none. Used by :mod:`rtsgeom.viz.scene3d`; imports no pyvista."""

from __future__ import annotations

import atexit
import os
import shutil
import subprocess
from ..errors import VizError

__all__ = ["VizError", "ensure_render_backend"]


_BACKEND: str | None = None


def _probe_window(class_name: str) -> bool:
    """Whether an off-screen render window of VTK class ``class_name`` gets an OpenGL context."""
    try:
        from vtkmodules import vtkRenderingOpenGL2 as gl
        win = getattr(gl, class_name)()
        win.SetOffScreenRendering(1)
        ok = bool(win.SupportsOpenGL())
        win.Finalize()
        return ok
    except (AttributeError, ImportError, RuntimeError, TypeError):
        return False


def _start_xvfb() -> str | None:
    """Start ``Xvfb`` on a free display number (stopped at exit); return ``:N`` or None."""
    exe = shutil.which("Xvfb")
    if exe is None:
        return None
    read_fd, write_fd = os.pipe()
    try:
        proc = subprocess.Popen([exe, "-displayfd", str(write_fd), "-screen", "0", "1920x1080x24",
                                 "-nolisten", "tcp"], pass_fds=(write_fd,),
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    except OSError:
        os.close(read_fd)
        os.close(write_fd)
        return None
    os.close(write_fd)
    with os.fdopen(read_fd) as f:
        number = f.readline().strip()
    if not number.isdigit():
        proc.terminate()
        return None
    atexit.register(proc.terminate)
    return f":{number}"


def ensure_render_backend() -> str:
    """Make sure VTK can render here; return the backend used.

    With ``DISPLAY`` set, VTK's X window is used. Without it, VTK would first try X (and log a
    warning) before its EGL fallback, so the EGL window (Mesa's llvmpipe works without a GPU) and
    then OSMesa are selected explicitly through ``VTK_DEFAULT_OPENGL_WINDOW`` (unless the user set
    that variable). Only if neither gets an OpenGL context is an ``Xvfb`` server started (when the
    program exists). Otherwise :class:`VizError` says which system packages are missing.
    """
    global _BACKEND
    if _BACKEND is not None:
        return _BACKEND
    if os.environ.get("DISPLAY"):
        _BACKEND = "x11"
        return _BACKEND
    chosen = os.environ.get("VTK_DEFAULT_OPENGL_WINDOW")
    candidates = [chosen] if chosen else ["vtkEGLRenderWindow", "vtkOSOpenGLRenderWindow"]
    for name in candidates:
        if _probe_window(name):
            os.environ["VTK_DEFAULT_OPENGL_WINDOW"] = name
            _BACKEND = name
            return _BACKEND
    display = _start_xvfb()
    if display is not None:
        os.environ["DISPLAY"] = display
        os.environ["VTK_DEFAULT_OPENGL_WINDOW"] = "vtkXOpenGLRenderWindow"
        if _probe_window("vtkXOpenGLRenderWindow"):
            _BACKEND = f"xvfb {display}"
            return _BACKEND
    raise VizError("cannot create an off-screen OpenGL context for VTK: install Mesa's EGL "
                   "(apt: libegl1 libgl1-mesa-dri) or OSMesa (apt: libosmesa6), or Xvfb "
                   "(apt: xvfb), or run with a DISPLAY")
