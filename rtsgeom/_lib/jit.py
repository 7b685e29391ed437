"""The rules every compiled kernel (numba) follows: :data:`JIT`, the options of its ``njit``.

Why compiled: each kernel is a few dozen flops per snapshot or set-point, applied to tens of
millions of them; written with numpy, every intermediate is a temporary array as large as the
batch, and the loops over Newton steps, design bins and plan alternatives run in Python over
ever smaller subsets. A scalar loop per snapshot avoids both.

Rules: ``cache=True`` (compiled once per machine into ``__pycache__``), ``nogil=True`` (threads
may share them), no ``fastmath`` (IEEE arithmetic: the results agree with the numpy definitions
to rounding, tested), ``error_model="numpy"`` (0/0 is NaN, as in numpy); the small per-snapshot
helpers ``inline="always"`` (numba-level inlining drops the reference counting of the arrays
passed down). numba is imported only with the kernel modules, which the callers import inside
the functions that need them (``rtsgeom --help`` and ``info`` do not load it); small batches run
the numpy definitions instead (:func:`rtsgeom._lib.util.use_kernels`: importing numba and
setting up its target costs about 0.5 s per process). This module does not import numba.
"""

__all__ = ["JIT"]

JIT = dict(cache=True, nogil=True, error_model="numpy")
