"""Small shared helpers (no physics)."""

from __future__ import annotations

import numpy as np


_BLAS_CONTROLLER = None

#: Batches of at least this many items (snapshots, set-points) run the compiled kernels
#: (``rtsgeom.kernels``); smaller ones their numpy definitions, bit for bit the same results
#: (tested), without numba's ~0.5 s import and first-call set-up per process. At this size
#: the numpy forms take ~50 ms (the 1-D peak's, the dearer one), a tenth of that set-up.
KERNEL_MIN_BATCH = 20_000


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


def frozen(values, dtype=None) -> np.ndarray:
    """Return a read-only copy of ``values`` so frozen dataclasses stay immutable all the way down."""
    a = np.array(values, dtype=dtype, copy=True)
    a.flags.writeable = False
    return a
