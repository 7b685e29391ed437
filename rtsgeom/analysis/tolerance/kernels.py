"""The tolerance model's per-draw design, plan and detection, compiled (numba): for one draw and
set-point the pair's exact design at the bin the RuT detects (:func:`design_rows`), the
planner's choice among J's alternative delays (:func:`plan_rows`) and the detected bin's
snapshot (:func:`detect_rows`), built on the pair's kernels (:mod:`rtsgeom.synthesis.kernels`).

Compiled by the kernels' rules (:mod:`rtsgeom._lib.jit`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..._lib.jit import JIT
from ...synthesis.kernels import argmax_row, choice_row, ratio_one

__all__ = ["design_rows", "plan_rows", "detect_rows"]


@njit(inline="always", **JIT)
def _cross(table, ri, rj, lo, c):
    """c_ij = sum_v conj(table[0, ri, b, v]) table[1, rj, b, v] at bins b = lo + (0 ..
    c.size - 1)."""
    for b in range(c.size):
        acc = 0j
        for v in range(table.shape[3]):
            acc += table[0, ri, lo + b, v].conjugate() * table[1, rj, lo + b, v]
        c[b] = acc


@njit(**JIT)
def _scratch(n_k):
    """Work arrays of :func:`_design_one` for ``n_k`` bins."""
    return (np.empty(n_k), np.empty(n_k), np.empty(n_k), np.empty(n_k), np.empty(n_k),
            np.empty(n_k), np.empty(n_k), np.empty((n_k, n_k)), np.empty(n_k, np.int64),
            np.empty(n_k, np.complex128))


@njit(inline="always", **JIT)
def _design_one(beams_i, beams_j, bi_row, rj, m, lo, e, power, ri, p_one, unit_gain, sc):
    """One set-point ``m`` of ``tolerance.pair._Design.__call__``: the ratio per design bin
    (:func:`ratio_one` at bins lo + 1 .. lo + K' - 2, NaN at the two outer ones, which are
    only compared), the detected-bin choice (:func:`choice_row`) and the programme
    amplitudes A_I = g sqrt(p_one / |b_I + rho e b_J|^2), A_J = rho A_I at the chosen bin
    (e = e^{j phase}, J's phase factor); ``sc``: :func:`_scratch` of K' bins with c_ij (:func:`_cross`) in its last
    array. Returns (A_I, A_J, bin (index from lo), consistent, margin)."""
    rho, co, si, p_ii, p_jj, c_re, c_im, pw, det, c = sc
    n_k = rho.size
    for b in range(n_k):
        kb = lo + b
        if 0 < b < n_k - 1:
            rho[b] = ratio_one(beams_i[bi_row, 0, m, kb], beams_i[bi_row, 1, m, kb],
                               beams_i[bi_row, 2, m, kb], beams_j[rj, 0, m, kb],
                               beams_j[rj, 1, m, kb], beams_j[rj, 2, m, kb], e)
        else:
            rho[b] = np.nan
        co[b], si[b] = e.real, e.imag
        p_ii[b] = power[0, ri, kb]
        p_jj[b] = power[1, rj, kb]
        c_re[b] = c[b].real
        c_im[b] = c[b].imag
    r, k, ok, mg = choice_row(rho, co, si, p_ii, p_jj, c_re, c_im, pw, det)
    s = beams_i[bi_row, 0, m, lo + k] + r * e * beams_j[rj, 0, m, lo + k]
    p_sum = abs(s) ** 2
    scale = unit_gain * math.sqrt(p_one / (p_sum if not p_sum < 1e-300 else 1e-300))
    return scale, scale * r, k, ok, mg


@njit(**JIT)
def design_rows(beams_i, beams_j, i0, table, power, p_one, unit_gain, row_i, row_j, sub,
                e, sp, lo, n_k, amps, k_out, ok_out, mg_out):
    """``tolerance.pair._Design.__call__``: :func:`_design_one` for every draw n (I at table
    row ``row_i[n]``, J at ``row_j[n]``, sub-bin index ``sub[n]``, J's phase factor ``e[n]``)
    and every set-point (``sp`` empty) or set-point ``sp[n]``, over the ``n_k`` bins from
    ``lo``. Fills ``amps`` (n, M', 2), ``k_out`` (bin index into the table's K), ``ok_out``,
    ``mg_out`` (n, M')."""
    sc = _scratch(n_k)
    for n in range(row_i.size):
        ri, rj = row_i[n], row_j[n]
        _cross(table, ri, rj, lo, sc[-1])
        for q in range(amps.shape[1]):
            a_i, a_j, k, ok, mg = _design_one(
                beams_i, beams_j, ri - i0, rj, sp[n] if sp.size else q, lo, e[n], power,
                ri, p_one[sub[n]], unit_gain, sc)
            amps[n, q, 0], amps[n, q, 1] = a_i, a_j
            k_out[n, q], ok_out[n, q], mg_out[n, q] = k + lo, ok, mg


@njit(**JIT)
def plan_rows(beams_i, beams_j, i0, table, power, p_one, unit_gain, row_i, row_j, sub, e,
              period, lo, n_k, lo_far, n_k_far, min_margin, amps, shift):
    """``tolerance.pair._Design.planned`` (the planner's choice of J's delay)
    for every draw n and set-point: the design with J at ``row_j[n]`` (``n_k`` bins from
    ``lo``), and where its bin is not consistent or its margin not above ``min_margin``, J
    at ``row_j[n] - period`` and then ``+ period`` (``n_k_far`` bins from ``lo_far``; J's
    phase factor ``e[0 | 1 | 2, n]`` for the three), keeping the best by (consistent, margin
    where consistent, the earlier) and stopping at the first that passes. Fills ``amps``
    (n, M, 2) and ``shift`` (n, M) (0, -1, 1)."""
    sc = _scratch(n_k)
    sc_m, sc_p = _scratch(n_k_far), _scratch(n_k_far)
    for n in range(row_i.size):
        ri, rj = row_i[n], row_j[n]
        u = p_one[sub[n]]
        _cross(table, ri, rj, lo, sc[-1])
        have_m = have_p = False
        for q in range(amps.shape[1]):
            a_i, a_j, k, ok, mg = _design_one(beams_i, beams_j, ri - i0, rj, q, lo, e[0, n],
                                              power, ri, u, unit_gain, sc)
            best_ok, best_mg, best_s = ok, (mg if ok else 0.0), 0
            done = ok and mg > min_margin
            for s in (-1, 1):
                if done:
                    break
                r2 = rj + s * period
                if s < 0 and not have_m:
                    _cross(table, ri, r2, lo_far, sc_m[-1])
                    have_m = True
                if s > 0 and not have_p:
                    _cross(table, ri, r2, lo_far, sc_p[-1])
                    have_p = True
                b_i, b_j, _, ok2, mg2 = _design_one(
                    beams_i, beams_j, ri - i0, r2, q, lo_far, e[1 if s < 0 else 2, n],
                    power, ri, u, unit_gain, sc_m if s < 0 else sc_p)
                mg2 = mg2 if ok2 else 0.0
                if int(ok2) > int(best_ok) or (ok2 == best_ok and mg2 > best_mg):
                    a_i, a_j, best_ok, best_mg, best_s = b_i, b_j, ok2, mg2, s
                done = ok2 and mg2 > min_margin
            amps[n, q, 0], amps[n, q, 1] = a_i, a_j
            shift[n, q] = best_s


@njit(**JIT)
def detect_rows(x_i, x_j, sel, a_i, a_j, snaps, det):
    """The RuT's detection of each draw n and set-point m (``tolerance.pair.PairProcedure.draw``):
    channel I's spectra ``x_i`` (n, K, V) times ``a_i[n, m]`` plus J's ``x_j[sel[n, m], n]``
    ((S, n, K, V): J at its alternative delays) times ``a_j[n, m]``; the detected bin the
    strongest, power a_I^2 p_ii + a_J^2 p_jj + 2 a_I a_J Re(sum conj(x_i) x_j) summed over the
    elements (numpy's argmax: the first maximum or NaN). Fills the snapshot at that bin
    ``snaps`` (n, M, V) and the bin ``det`` (n, M)."""
    n_s, _, n_k, n_v = x_j.shape
    p_ii, power = np.empty(n_k), np.empty((1, n_k))
    p_jj, c_ij = np.empty((n_s, n_k)), np.empty((n_s, n_k))
    for n in range(x_i.shape[0]):
        for k in range(n_k):
            acc = 0.0
            for v in range(n_v):
                acc += x_i[n, k, v].real ** 2 + x_i[n, k, v].imag ** 2
            p_ii[k] = acc
            for s in range(n_s):
                pj = cc = 0.0
                for v in range(n_v):
                    xj = x_j[s, n, k, v]
                    pj += xj.real ** 2 + xj.imag ** 2
                    cc += (x_i[n, k, v].conjugate() * xj).real
                p_jj[s, k], c_ij[s, k] = pj, cc
        for m in range(sel.shape[1]):
            s, ai, aj = sel[n, m], a_i[n, m], a_j[n, m]
            for k in range(n_k):
                power[0, k] = ai ** 2 * p_ii[k] + aj ** 2 * p_jj[s, k] + 2 * ai * aj * c_ij[s, k]
            kb = argmax_row(power, 0)
            det[n, m] = kb
            for v in range(n_v):
                snaps[n, m, v] = ai * x_i[n, kb, v] + aj * x_j[s, n, kb, v]
