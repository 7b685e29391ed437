"""The rule by which a pair's design for the bin the RuT detects is chosen
(:func:`rtsgeom.synthesis.pair.detected_bin_choice`), in numpy: the definition of the compiled
``rtsgeom.synthesis.kernels.bin_choice_rows``, bit for bit, and the constant both use. Imports
no numba: a run that chooses the bins of a few targets does not pay numba's set-up."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["SAME_DESIGN_LN", "bin_choice_rows_numpy"]

#: design ratios of two bins this close (|ln(rho_b / rho_k)|, 1 %) are one design: the RuT
#: detecting either reports the set angle to about 0.03 deg on an 8 deg pair (d alpha / d ln
#: rho is about a quarter of the span)
SAME_DESIGN_LN = 0.01


@np.errstate(all="ignore")  # as silent as the compiled kernel (radar/newton.py)
def bin_choice_rows_numpy(rho, co, si, p_ii, p_jj, c_re, c_im):
    """The numpy definition of ``kernels.bin_choice_rows`` (the rule of
    :func:`rtsgeom.synthesis.pair.detected_bin_choice`) for rows (N, K): (rho, k, consistent, margin), each (N,); the compiled kernel's
    arithmetic in its order, its first-NaN argmax and maximum, and the C library's ``log``
    (``math.log``, which the kernel calls), so both give the same bits (tested); for small
    batches, where importing numba would cost more than the rows (``_lib.util.use_kernels``)."""
    n, n_k = rho.shape
    rows, bins = np.arange(n), np.arange(n_k)
    fin = np.isfinite(rho) & (rho > 0)
    r = np.where(fin, rho, 0.0)[:, :, None]  # (N, K design, 1)
    q = co[:, :, None] * c_re[:, None, :] - si[:, :, None] * c_im[:, None, :]
    power = p_ii[:, None, :] + (r * r) * p_jj[:, None, :] + 2 * r * q  # (N, design, bin)
    det = np.where(fin, np.argmax(power, axis=2), 0)  # numpy's argmax: first max or first NaN
    mid = n_k // 2
    rank = np.abs(bins - mid) * 2 + (bins > mid)  # nearest the middle, ties to the lower bin
    agree = fin & (det == bins)
    consistent = agree.any(axis=1)
    k = det[:, mid]  # where no design agrees: the fixed point from the middle bin
    for _ in range(4):
        k = det[rows, k]
    k = np.where(consistent, np.argmin(np.where(agree, rank, 4 * n_k), axis=1), k)
    row = power[rows, k]  # (N, bin): the chosen design's power at every bin
    nan = np.isnan(row)
    first_nan = np.where(nan.any(axis=1), np.argmax(nan, axis=1), n_k)
    rho_k = rho[rows, k]
    same = np.zeros((n, n_k), bool)  # bins whose own design is the chosen one's
    pick = fin & consistent[:, None]
    ratio = (rho / rho_k[:, None])[pick]
    same[pick] = np.array([abs(math.log(x)) <= SAME_DESIGN_LN for x in ratio.tolist()], bool)
    other = (bins < first_nan[:, None]) & (bins != k[:, None]) & ~same
    m2 = np.max(np.where(other, row, -np.inf), axis=1)
    m1 = np.where(first_nan < n_k, np.nan, row[rows, k])
    margin = np.where(m2 > -np.inf, m1 / np.maximum(m2, 1e-300), np.inf)
    return rho_k, k, consistent, np.where(consistent, margin, 1.0)
