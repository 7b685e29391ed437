"""The pair's closed-form design for the bin the RuT detects, compiled (numba): one set-point's
ratio (:func:`ratio_one`, bit for bit :func:`rtsgeom.synthesis.pair._ratios`) and bin choice
(:func:`choice_row`, :func:`rtsgeom.synthesis.pair.detected_bin_choice`'s rule), and their
batched loops.

Compiled by the kernels' rules (:mod:`rtsgeom._lib.jit`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .._lib.jit import JIT
from .choice import SAME_DESIGN_LN

__all__ = ["ratio_one", "ratios", "choice_row", "bin_choice_rows", "argmax_row",
           "SAME_DESIGN_LN"]


# -- the pair's design for the bin the RuT detects (synthesis.pair, the tolerance model's) ------


@njit(inline="always", **JIT)
def _re(f, g):
    """Re(conj(f) g)."""
    return f.real * g.real + f.imag * g.imag


@njit(inline="always", **JIT)
def argmax_row(a, row):
    """numpy's argmax of row ``row`` of a 2-D array: the first maximum, or the first NaN."""
    best = 0
    for i in range(a.shape[1]):
        if a[row, i] != a[row, i]:
            return i
        if a[row, i] > a[row, best]:
            best = i
    return best


@njit(inline="always", **JIT)
def ratio_one(bi, bi1, bi2, bj, bj1, bj2, e):
    """:func:`rtsgeom.synthesis.pair.ratio_from_beams` for one set-point: the ratio rho >= 0 that
    puts the peak of P(u) = |b_I + rho y|^2 (y = e b_J, e = e^{j phase} J's phase factor) at
    the set direction, from the beams and their first two derivatives in u there (complex
    scalars).

    dP/du = 0 is a0 + a1 rho + a2 rho^2 = 0 with a0 = Re(b_I* b_I'), a1 = Re(b_I* y' + y* b_I'),
    a2 = Re(y* y'); of its roots the non-negative ones with P'' < 0 (P'' = 2 Re(s* s'') +
    2 |s'|^2, s = b_I + rho y, a quadratic in rho), the one with the larger P (the first on a
    tie); NaN where none is."""
    y, y1, y2 = e * bj, e * bj1, e * bj2
    a0 = _re(bi, bi1)
    a1 = _re(bi, y1) + _re(y, bi1)
    a2 = _re(y, y1)
    disc = a1 * a1 - 4 * a0 * a2
    sq = math.sqrt(disc) if disc >= 0 else np.nan
    r0, s0 = _root(bi, bi1, bi2, y, y1, y2, (-a1 + sq) / (2 * a2) if a2 != 0 else -a0 / a1)
    r1, s1 = _root(bi, bi1, bi2, y, y1, y2, (-a1 - sq) / (2 * a2) if a2 != 0 else -a0 / a1)
    # numpy's argmax over (s0, s1): the first maximum, or the first NaN
    return r1 if (s0 == s0 and (s1 != s1 or s1 > s0)) else r0


@njit(inline="always", **JIT)
def _root(bi, bi1, bi2, y, y1, y2, r):
    """(rho, P) of root ``r`` of :func:`ratio_one`, (NaN, -inf) where it is not a maximum of
    P at a non-negative rho."""
    p = _re(bi, bi) + r * (2 * _re(bi, y) + r * _re(y, y))
    p2 = 2 * (_re(bi, bi2) + r * (_re(bi, y2) + _re(y, bi2)) + r * r * _re(y, y2)) \
        + 2 * (_re(bi1, bi1) + r * (2 * _re(bi1, y1)) + r * r * _re(y1, y1))
    if math.isfinite(r) and r >= 0 and p2 < 0:
        return r, p
    return np.nan, -np.inf


@njit(**JIT)
def ratios(bi, bi1, bi2, bj, bj1, bj2, e, out):
    """:func:`ratio_one` over flat arrays (N,) (the broadcast of ``ratio_from_beams``)."""
    for n in range(out.size):
        out[n] = ratio_one(bi[n], bi1[n], bi2[n], bj[n], bj1[n], bj2[n], e[n])


@njit(inline="always", **JIT)
def choice_row(rho, co, si, p_ii, p_jj, c_re, c_im, power, det):
    """:func:`rtsgeom.synthesis.pair.detected_bin_choice` for one row of K design bins: ratios
    ``rho`` (K,), J's phase per design bin as cos and sin ``co``, ``si`` (K,), the channels'
    power sums over the
    elements ``p_ii``, ``p_jj`` and ``c_ij = sum conj(x_i) x_j`` (``c_re``, ``c_im``) (K,)
    at each bin; scratch ``power`` (K, K), ``det`` (K,). Returns (rho, k, consistent,
    margin).

    The power of design k at bin b, |I + r e^{j ph} J|^2 = p_ii + r^2 p_jj
    + 2 r Re(e^{j ph} c_ij) (r = 0 where rho is not a positive number: a design that does
    not exist detects nothing); design k's detected bin the strongest; of the designs
    detected at their own bin the one nearest the middle (ties to the lower bin); where none
    is, the fixed point of "design at the reported bin" from the middle bin (4 steps).
    margin: the detected bin's power over the strongest other bin whose own design differs
    from the chosen one (1 where not consistent): a bin whose design ratio is within
    ``SAME_DESIGN_LN`` of the chosen (``|ln(rho_b / rho_k)|``) is the same programme's design
    there, so detecting it instead reports the same angle and is no ambiguity (a target
    midway between two bins with I and J coherent at both: margin 1.1 over an equivalent bin
    while every other bin is 11 dB down); inf where every other bin is equivalent."""
    n_k = rho.size
    mid = n_k // 2
    best, best_rank = 0, 4 * n_k
    for kd in range(n_k):
        fin = math.isfinite(rho[kd]) and rho[kd] > 0
        r = rho[kd] if fin else 0.0
        for kb in range(n_k):
            q = co[kd] * c_re[kb] - si[kd] * c_im[kb]
            power[kd, kb] = p_ii[kb] + (r * r) * p_jj[kb] + 2 * r * q
        det[kd] = argmax_row(power, kd) if fin else 0
        if fin and det[kd] == kd:
            rank = abs(kd - mid) * 2 + (1 if kd > mid else 0)
            if rank < best_rank:
                best, best_rank = kd, rank
    consistent = best_rank < 4 * n_k
    k = best
    if not consistent:
        k = det[mid]
        for _ in range(4):
            k = det[k]
    margin = 1.0
    if consistent:  # the detected bin's power over the strongest bin of another design
        m1 = power[k, k]
        m2 = -np.inf
        for kb in range(n_k):
            p = power[k, kb]
            if p != p:
                m1 = np.nan
                break
            if kb == k or (math.isfinite(rho[kb]) and rho[kb] > 0
                           and abs(math.log(rho[kb] / rho[k])) <= SAME_DESIGN_LN):
                continue
            if p > m2:
                m2 = p
        margin = m1 / max(m2, 1e-300) if m2 > -np.inf else np.inf
    return rho[k], k, consistent, margin


@njit(**JIT)
def bin_choice_rows(rho, co, si, p_ii, p_jj, c_re, c_im, rho_out, k_out, ok_out, mg_out):
    """:func:`choice_row` for each row of (N, K) arrays."""
    n_k = rho.shape[1]
    power = np.empty((n_k, n_k))
    det = np.empty(n_k, np.int64)
    for n in range(rho.shape[0]):
        rho_out[n], k_out[n], ok_out[n], mg_out[n] = choice_row(
            rho[n], co[n], si[n], p_ii[n], p_jj[n], c_re[n], c_im[n], power, det)
