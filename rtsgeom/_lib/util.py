"""Small shared helpers (no physics)."""

from __future__ import annotations

import functools
import sys

import numpy as np


_BLAS_CONTROLLER = None

#: numba's cost per process before the first compiled kernel (``rtsgeom.synthesis.kernels``) returns:
#: its import (~0.2 s) and its target's set-up on the first call of a cached kernel (~0.3 s),
#: quiet 2-core machine
KERNEL_SETUP_S = 0.5
#: the compiled kernels (numba): once one is loaded, numba's set-up is paid
KERNEL_MODULES = ("rtsgeom.radar.peak_kernels", "rtsgeom.synthesis.kernels",
                  "rtsgeom.analysis.tolerance.kernels")
_numpy_s = 0.0  # what this process has spent so far in the kernels' numpy definitions (est.)


def use_kernels(n: int, numpy_s_per_item: float) -> bool:
    """Whether a batch of ``n`` items (snapshots, set-points) runs the compiled kernels or
    their numpy definitions, which give the same bits (tested): the kernels once they are
    loaded, and once this process's numpy work (this batch included, estimated at
    ``numpy_s_per_item``) would pass half of numba's set-up ``KERNEL_SETUP_S``; numpy
    before that (ski rental: a command with a few thousand snapshots, ``calibrate``, never
    pays for numba; one with millions pays at most 0.25 s of numpy before it does)."""
    global _numpy_s
    if any(m in sys.modules for m in KERNEL_MODULES):
        return True
    if _numpy_s + n * numpy_s_per_item > KERNEL_SETUP_S / 2:
        return True
    _numpy_s += n * numpy_s_per_item
    return False


def single_threaded_blas():
    """Context manager limiting BLAS to one thread (``threadpoolctl``; the controller is built
    once: inspecting the loaded libraries takes milliseconds). For products too small to
    share out (a multi-threaded BLAS spends more on thread hand-offs than on the arithmetic,
    worst on a busy machine) and where the reduction order must not depend on the threads."""
    global _BLAS_CONTROLLER
    from threadpoolctl import ThreadpoolController
    if _BLAS_CONTROLLER is None:
        _BLAS_CONTROLLER = ThreadpoolController()
    return _BLAS_CONTROLLER.limit(limits=1, user_api="blas")


def one_blas_thread(func):
    """Decorator: ``func`` runs under :func:`single_threaded_blas`."""
    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        with single_threaded_blas():
            return func(*args, **kwargs)
    return wrapper


def frozen(values, dtype=None) -> np.ndarray:
    """Return a read-only copy of ``values`` so frozen dataclasses stay immutable all the way down."""
    a = np.array(values, dtype=dtype, copy=True)
    a.flags.writeable = False
    return a


def tones(freq_hz: np.ndarray, t0_s: float, dt_s: float, n: int) -> np.ndarray:
    """``exp(2 pi j f (t0 + i dt))`` for i = 0..n-1: (..., n) for frequencies (...).

    Factored as ``exp(2 pi j f (t0 + a B dt)) exp(2 pi j f b dt)``, i = a B + b with
    B ~ sqrt(n): 2 sqrt(n) complex exponentials and n products per frequency instead of n
    exponentials (numpy's complex ``exp`` dominated the model construction: 0.2 s for the
    delay table of ~1000 echoes). Agrees with the direct form to ~1e-15 (tested); each
    phase is a product of two exact-to-rounding factors, no recursion that accumulates."""
    f = np.asarray(freq_hz, float)[..., None]
    block = max(1, int(np.ceil(np.sqrt(n))))
    outer = np.exp(2j * np.pi * f * (t0_s + np.arange(-(-n // block)) * block * dt_s))
    inner = np.exp(2j * np.pi * f * (np.arange(block) * dt_s))
    out = outer[..., :, None] * inner[..., None, :]
    return out.reshape(out.shape[:-2] + (-1,))[..., :n]


_PACKAGE_DIR = str(__import__("pathlib").Path(__file__).resolve().parents[1])


def warn_caller(message: str, category: type[Warning]) -> None:
    """``warnings.warn`` attributed to the first frame outside the rtsgeom package: the
    user's line that called the API, however deep inside the package the warning is raised
    (a fixed ``stacklevel`` names a line of the package whenever the call chain inside it is
    longer or shorter than counted). Python 3.12's ``skip_file_prefixes`` does this; 3.11 needs
    the walk."""
    import os
    import warnings
    level, f = 2, sys._getframe(1)  # stacklevel 2: warn_caller's caller
    while f is not None and os.path.abspath(f.f_code.co_filename).startswith(
            _PACKAGE_DIR + os.sep):
        f, level = f.f_back, level + 1
    warnings.warn(message, category, stacklevel=level)


def tell(progress, message: str | None, stage: str | None = None, done: int = 0,
         total: int = 0) -> None:
    """Report to a ``progress`` callback (None: nothing): a count ``progress.count(stage,
    done, total)`` where it has one (the CLI's ``steps``: a bar on a terminal, plain lines
    elsewhere), else the ``message`` as ``progress(message)`` (a list's ``append`` keeps the
    messages; None sends nothing: a count per frame is no message)."""
    if progress is None:
        return
    count = getattr(progress, "count", None)
    if count is not None and stage is not None:
        count(stage, done, total)
    elif message is not None:
        progress(message)
