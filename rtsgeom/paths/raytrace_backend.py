"""Sionna RT's backend, checked before it is imported: the pre-flight (Dr.Jit's LLVM or CUDA
backend, tried in a subprocess because a bad LLVM aborts the process), Dr.Jit's kernel-cache
folder, the lazy import of ``mitsuba`` and ``sionna.rt``, and what the backend reports.
Together with :mod:`rtsgeom.paths.raytrace` (which re-exports these names) it is the one
adapter behind which Sionna RT sits: no other module imports ``sionna``, ``mitsuba`` or
``drjit``.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import threading
from pathlib import Path

from ..errors import RaytraceUnavailable

__all__ = ["RaytraceUnavailable", "preflight", "ensure_available", "backend_info", "INSTALL_HINT"]

INSTALL_HINT = ("install a recent LLVM for Dr.Jit's CPU backend (Debian/Ubuntu: `apt-get install -y "
                "libllvm19`), or set DRJIT_LIBLLVM_PATH to such a libLLVM.so (LLVM 19 is tested; "
                "15 crashes, 14 and older are refused)")

# A tiny kernel run in a subprocess: LLVM 15 passes Dr.Jit's version check but aborts the whole
# process (SIGABRT, "LLVM ERROR: Cannot select ... fmaximum") at the first kernel it compiles.
_SMOKE = r"""
import drjit as dr
from drjit.llvm import Float
x = dr.arange(Float, 64) - 32
y = dr.maximum(dr.sqrt(x * x + 1), 0.0) + dr.minimum(x, 0.0)
dr.eval(y)
print("OK", ".".join(map(str, dr.detail.llvm_version())))
"""


# ------------------------------------------------------------------------------------------
# Backend pre-flight (runs once per process, before the first import of sionna)
# ------------------------------------------------------------------------------------------

SIONNA_LOCK = threading.RLock()  # Dr.Jit and Sionna RT are not thread-safe: one user at a time
_PREFLIGHT: tuple[bool, str, str | None] | None = None


def _default_cache_dir() -> Path:
    """Dr.Jit's kernel cache: ``$RTSGEOM_CACHE_DIR/drjit`` if set, else the user's cache folder
    ``$XDG_CACHE_HOME/rtsgeom/drjit`` (``~/.cache/rtsgeom/drjit``); never inside the source
    checkout, which may be read-only, shared or under version control."""
    base = os.environ.get("RTSGEOM_CACHE_DIR")
    if base:
        return Path(base).expanduser() / "drjit"
    xdg = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(xdg) / "rtsgeom" / "drjit"


def _set_cache_dir() -> None:
    """Point Dr.Jit's kernel cache to a project folder unless the user chose one
    (``DRJIT_CACHE_DIR``). Must run before drjit is imported."""
    if os.environ.get("DRJIT_CACHE_DIR") or "drjit" in sys.modules:
        return
    path = _default_cache_dir()
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError:
        return  # Dr.Jit falls back to its own default ($HOME/.drjit)
    os.environ["DRJIT_CACHE_DIR"] = str(path)


def _run_preflight(timeout_s: float) -> tuple[bool, str, str | None]:
    _set_cache_dir()
    import importlib.util
    missing = []
    for mod in ("drjit", "mitsuba", "sionna"):  # top-level only: find_spec("sionna.rt")
        try:                                    # would import sionna, i.e. sionna.rt
            spec = importlib.util.find_spec(mod)
        except (ImportError, ValueError):
            spec = None
        if spec is None:
            missing.append(mod)
        elif mod == "sionna" and not any((Path(p) / "rt").is_dir()
                                         for p in spec.submodule_search_locations or ()):
            missing.append("sionna.rt")
    if missing:
        return False, (f"Sionna RT is not installed ({', '.join(missing)} missing): "
                       "pip install 'sionna-rt>=1.0'"), None
    if "sionna.rt" in sys.modules:  # imported (and therefore working) already
        import mitsuba as mi
        return True, f"sionna.rt already imported (variant {mi.variant()})", mi.variant()
    try:
        import drjit as dr  # cheap, compiles nothing, never aborts
    except ImportError as exc:
        return False, f"drjit cannot be imported ({exc})", None
    forced = os.environ.get("RTSGEOM_RAYTRACE_BACKEND", "").strip().lower()
    if forced not in ("", "cuda", "llvm"):
        return False, (f"RTSGEOM_RAYTRACE_BACKEND={forced!r}: must be 'cuda' or 'llvm' (or unset: "
                       "CUDA where available, else LLVM)"), None
    if forced != "llvm" and dr.has_backend(dr.JitBackend.CUDA):
        return True, "CUDA backend available", "cuda_ad_mono_polarized"
    if forced == "cuda":
        return False, "RTSGEOM_RAYTRACE_BACKEND=cuda but Dr.Jit finds no CUDA backend", None
    env_path = os.environ.get("DRJIT_LIBLLVM_PATH")
    if not dr.has_backend(dr.JitBackend.LLVM):
        try:
            with open("/proc/self/maps") as fh:
                libs = sorted({ln.split()[-1] for ln in fh if "libLLVM" in ln})
        except OSError:
            libs = []
        why = (f"Dr.Jit cannot use {libs[0]} (LLVM older than 15?)" if libs
               else "no libLLVM shared library was found")
        where = f" (DRJIT_LIBLLVM_PATH={env_path})" if env_path else ""
        return False, (f"Sionna RT needs Dr.Jit's LLVM backend on a machine without CUDA; "
                       f"{why}{where}: {INSTALL_HINT}"), None
    ver = ".".join(map(str, dr.detail.llvm_version()))
    try:
        r = subprocess.run([sys.executable, "-c", _SMOKE], capture_output=True, text=True,
                           timeout=timeout_s, env=os.environ.copy())
    except subprocess.TimeoutExpired:
        return False, f"the LLVM {ver} smoke test timed out after {timeout_s:g} s: {INSTALL_HINT}", None
    except OSError as exc:
        return False, f"cannot start the LLVM smoke test ({exc})", None
    if r.returncode != 0 or "OK" not in r.stdout:
        lines = r.stderr.strip().splitlines()
        err = [ln for ln in lines if "LLVM ERROR" in ln or "Error" in ln] or lines[-1:]
        detail = re.sub(r"0x[0-9a-fA-F]+:? ?", "", err[0]) if err else "no output"  # addresses
        return False, (f"LLVM {ver} is accepted by Dr.Jit but crashes when compiling a kernel "
                       f"(exit code {r.returncode}: {detail[:120]}): {INSTALL_HINT}"), None
    return True, f"LLVM {ver} OK", "llvm_ad_mono_polarized"


def preflight(timeout_s: float = 120.0) -> tuple[bool, str]:
    """Whether Sionna RT can run in this process, and why not. Cached; never crashes the caller
    (the LLVM check compiles a kernel in a subprocess). Sets ``DRJIT_CACHE_DIR`` if unset."""
    global _PREFLIGHT
    with SIONNA_LOCK:
        if _PREFLIGHT is None:
            _PREFLIGHT = _run_preflight(timeout_s)
        return _PREFLIGHT[0], _PREFLIGHT[1]


_RT = None  # (mitsuba, sionna.rt) once imported


def ensure_available():
    """Import Sionna RT (after the pre-flight) and return ``(mitsuba, sionna.rt)``; raises
    :class:`RaytraceUnavailable` with installation advice."""
    global _RT
    with SIONNA_LOCK:
        if _RT is not None:
            return _RT
        ok, msg = preflight()
        if not ok:
            raise RaytraceUnavailable(msg)
        variant = _PREFLIGHT[2]
        try:
            import mitsuba as mi
            if "sionna.rt" not in sys.modules:
                mi.set_variant(variant)  # must precede `import sionna.rt`
            import sionna.rt as rt
        except (ImportError, AttributeError, RuntimeError) as exc:
            raise RaytraceUnavailable(f"cannot import Sionna RT ({exc}): {INSTALL_HINT}") from None
        _RT = (mi, rt)
        return _RT


def backend_info() -> dict:
    """Mitsuba variant, Dr.Jit thread count and Dr.Jit's allocation peak (MiB) of the backend in
    use (device memory on CUDA); for benchmarks. Imports Sionna RT like :func:`trace`."""
    mi, _ = ensure_available()
    import drjit as dr
    variant = mi.variant()
    out = {"variant": variant, "drjit_threads": int(dr.thread_count())}
    backend = dr.JitBackend.CUDA if variant.startswith("cuda") else dr.JitBackend.LLVM
    try:
        out["drjit_peak_mib"] = dr.detail.malloc_watermark(backend) / 2**20
    except (AttributeError, RuntimeError, TypeError):  # not in every Dr.Jit version
        pass
    return out
