"""Compiled per-snapshot kernels of the Monte-Carlo hot path (numba): the beamformer's 1-D peak
(:meth:`rtsgeom.radar.steering.Steering.peak`, D = 1) and the pair's closed-form design for
the bin the RuT detects (:func:`rtsgeom.calibration.sweep.ratio_from_beams`,
:func:`~rtsgeom.calibration.sweep.detected_bin_choice`, ``tolerance_model._Design``).

Why compiled: each of these is a few dozen flops per snapshot or set-point, applied to tens of
millions of them; written with numpy, every intermediate (cosines, partial sums, the power of
every design at every bin) is a temporary array as large as the batch, and the loops over
Newton steps, design bins and plan alternatives run in Python over ever smaller subsets. No
numpy formulation avoids those temporaries; a scalar loop per snapshot does.

Rules: ``cache=True`` (compiled once per machine into ``__pycache__``; see README
"Performance" for the cost), ``nogil=True`` (threads may share them), no ``fastmath`` (IEEE
arithmetic: the results agree with the numpy definitions to rounding, tested in
``tests/test_kernels.py``; ``peak_1d`` and ``ratio_one`` bit for bit with theirs in
``radar/newton.py`` and ``aoa/sweep.py``, ``tests/test_kernels_peak.py``), ``error_model="numpy"`` (0/0 is NaN, as in numpy); the small
per-snapshot helpers ``inline="always"`` (numba-level inlining lets it drop the reference
counting of the arrays passed down: the planned design 760 -> 320 ns per set-point, the
Newton steps about 2x). numba is
imported only with this module, which the callers import inside the functions that need it
(``rtsgeom --help`` and ``info`` do not load it).

Small batches skip them: ``Steering.peak`` (D = 1) and ``aoa.sweep.ratio_from_beams`` run
their numpy definitions (``radar.newton.peak_1d``, ``aoa.sweep._ratios``) until a process's
work in them would pass half of numba's set-up (``rtsgeom._lib.util.use_kernels``), the same
arithmetic bit for bit (tested), because
importing numba and setting up its target on the first call costs about 0.5 s per process,
more than the rest of ``rtsgeom calibrate`` (issue 17).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..radar.newton import P_SLACK, STEP_CLIP, STEP_TOL

__all__ = ["peak_1d", "newton_1d", "ratio_one", "ratios", "choice_row",
           "bin_choice_rows", "design_rows", "plan_rows", "detect_rows"]

_JIT = dict(cache=True, nogil=True, error_model="numpy")
# (numba's cache is keyed on this file: after changing the constants in radar/newton.py,
# touch this file or clear __pycache__/kernels.*.nb*)


# -- the beamformer's peak (Steering.peak, D = 1) ------------------------------------------------


@njit(inline="always", **_JIT)
def _phasors(lat, u, pw, e):
    """e^{j k_v u} (V_s,) into ``e`` for the wavenumbers of lattice ``lat`` (``radar.newton.lattice``):
    ``e^{j k_0 u} z^{m_v} e^{j r_v u}``, z = e^{j kappa u}, the powers by products (``pw``:
    scratch of max m + 1), the last factor only where r_v != 0 (two cosines and sines per
    snapshot and step on a uniform grid instead of two per element)."""
    k0, kappa, m, r = lat
    base = complex(math.cos(k0 * u), math.sin(k0 * u))
    z = complex(math.cos(kappa * u), math.sin(kappa * u))
    pw[0] = base
    for i in range(1, pw.size):
        pw[i] = pw[i - 1] * z
    for v in range(m.size):
        ev = pw[m[v]]
        if r[v] != 0.0:
            ev = ev * complex(math.cos(r[v] * u), math.sin(r[v] * u))
        e[v] = ev


@njit(inline="always", **_JIT)
def newton_1d(k, lat, x, u, steps, pw, e):
    """Newton steps on log P(u), P = |B|^2, B(u) = sum_v y_v, y_v = x_v e^{j k_v u}, for one
    tapered snapshot ``x`` (V_s,) (wavenumbers times positions ``k`` (V_s,), their lattice
    ``lat``; scratch ``pw``, ``e``) from ``u``, at most ``steps``: (u, converged, P at the
    last step's start).

    With C = sum k_v y_v and D = sum k_v^2 y_v (dB/du = j C, d2B/du2 = -D):
    g = d log P / du = 2 (Im B Re C - Re B Im C) / P and
    h = 2 (|C|^2 - Re B Re D - Im B Im D) / P - g^2; the step -g / h where h < 0 (else no
    step: not concave, not converged), clipped to +-``STEP_CLIP``; converged when a step is
    below ``STEP_TOL`` (it is still applied) and |u| < 1."""
    p = 0.0
    for _ in range(steps):
        _phasors(lat, u, pw, e)
        b0 = b1 = c0 = c1 = d0 = d1 = 0.0
        for v in range(k.size):
            y = x[v] * e[v]
            yr, yi = y.real, y.imag
            b0 += yr
            b1 += yi
            c0 += yr * k[v]
            c1 += yi * k[v]
            d0 += yr * (k[v] * k[v])
            d1 += yi * (k[v] * k[v])
        p = b0 * b0 + b1 * b1
        g = 2 * (b1 * c0 - b0 * c1) / p
        h = 2 * (c0 * c0 + c1 * c1 - b0 * d0 - b1 * d1) / p - g * g
        if not h < 0:
            return u, False, p
        step = -g / h
        if not math.isfinite(step):
            return u, False, p
        u += min(max(step, -STEP_CLIP), STEP_CLIP)
        if abs(step) < STEP_TOL:
            return u, abs(u) < 1, p
    return u, False, p


@njit(**_JIT)
def _mirrored(gc, gs):
    """Whether the grid's tables are exactly mirror-symmetric: column G-1-g is column g with
    the sine negated (a grid symmetric about u = 0, as :meth:`Steering.grid`'s)."""
    n_g = gc.shape[1]
    for v in range(gc.shape[0]):
        for g in range(n_g):
            if gc[v, g] != gc[v, n_g - 1 - g] or gs[v, g] != -gs[v, n_g - 1 - g]:
                return False
    return True


@njit(inline="always", **_JIT)
def _grid_bound(xn, gc, gs, sa, sb, sc, sd):
    """An upper bound on the largest of the grid's powers as :func:`peak_1d` computes them,
    on a mirror-symmetric grid (:func:`_mirrored`): B(u_g) and B(-u_g) share their four
    partial sums sum x_r cos, x_i sin, x_r sin, x_i cos (half the products of the direct
    sums), plus the difference the other rounding order can make (both sums of 2 V products
    of magnitude <= |x_v|, each within 2 V unit roundoffs of sum |x_v| (sum |x_v|)^2 ...
    taken 4x generously; scratch ``sa`` .. ``sd`` of (G + 1) // 2). NaN where x is."""
    n_v, n_g = gc.shape
    half = sa.size
    sa[:] = 0.0
    sb[:] = 0.0
    sc[:] = 0.0
    sd[:] = 0.0
    s1 = 0.0
    for v in range(n_v):
        s1 += abs(xn[v].real) + abs(xn[v].imag)
    v = 0
    while v + 4 <= n_v:  # four elements per pass over the sums (a quarter of their loads)
        r0, r1, r2, r3 = xn[v].real, xn[v + 1].real, xn[v + 2].real, xn[v + 3].real
        i0, i1, i2, i3 = xn[v].imag, xn[v + 1].imag, xn[v + 2].imag, xn[v + 3].imag
        for g in range(half):
            c0, c1, c2, c3 = gc[v, g], gc[v + 1, g], gc[v + 2, g], gc[v + 3, g]
            s0, s1_, s2, s3 = gs[v, g], gs[v + 1, g], gs[v + 2, g], gs[v + 3, g]
            sa[g] = sa[g] + r0 * c0 + r1 * c1 + r2 * c2 + r3 * c3
            sb[g] = sb[g] + i0 * s0 + i1 * s1_ + i2 * s2 + i3 * s3
            sc[g] = sc[g] + r0 * s0 + r1 * s1_ + r2 * s2 + r3 * s3
            sd[g] = sd[g] + i0 * c0 + i1 * c1 + i2 * c2 + i3 * c3
        v += 4
    while v < n_v:
        xr, xi = xn[v].real, xn[v].imag
        for g in range(half):
            sa[g] += xr * gc[v, g]
            sb[g] += xi * gs[v, g]
            sc[g] += xr * gs[v, g]
            sd[g] += xi * gc[v, g]
        v += 1
    p_max = 0.0
    for g in range(half):
        r0, i0 = sa[g] - sb[g], sc[g] + sd[g]
        r1, i1 = sa[g] + sb[g], sd[g] - sc[g]
        p_max = max(p_max, r0 * r0 + i0 * i0, r1 * r1 + i1 * i1)
    return p_max + (64.0 * (n_v + 2) * 2.0 ** -53) * (s1 * s1)


@njit(**_JIT)
def peak_1d(k, lat, x, u0, gc, gs, grid, iterations, u_out, ok_out):
    """:meth:`Steering.peak` for D = 1, per tapered snapshot ``x[n]`` (n, V_s): Newton
    (:func:`newton_1d`, ``iterations`` steps) from ``u0[n]``, accepted when it converged and
    no point of the grid ``grid`` (G,) (steering cos/sin tables ``gc``, ``gs`` (V_s, G)) has
    more power than the peak (``1 - P_SLACK`` relative); otherwise Newton again from the
    grid's maximum (``iterations + 4`` steps) under the same test. Fills ``u_out`` (n,) (the
    first Newton's u where both fail) and ``ok_out`` (n,).

    On a mirror-symmetric grid a converged peak is first tested against
    :func:`_grid_bound` (half the products); only where that bound does not already
    prove the test passes are the grid's powers formed directly (each point's sum in element
    order), so the outcome is bit for bit the direct test's."""
    n_v, n_g = gc.shape
    pw = np.empty(lat[2].max() + 1, np.complex128)
    e = np.empty(n_v, np.complex128)
    br = np.empty(n_g)
    bi = np.empty(n_g)
    half = (n_g + 1) // 2 if _mirrored(gc, gs) else 0
    sa, sb, sc, sd = np.empty(half), np.empty(half), np.empty(half), np.empty(half)
    for n in range(x.shape[0]):
        xn = x[n]
        u, conv, p_last = newton_1d(k, lat, xn, u0[n], iterations, pw, e)
        if conv and half:
            if p_last >= _grid_bound(xn, gc, gs, sa, sb, sc, sd) * (1 - P_SLACK):
                u_out[n], ok_out[n] = u, True
                continue
        # the grid's powers, vectorised over the grid (each point's sum in element order)
        br[:] = 0.0
        bi[:] = 0.0
        for v in range(n_v):
            xr, xi = xn[v].real, xn[v].imag
            for g in range(n_g):
                br[g] += xr * gc[v, g] - xi * gs[v, g]
                bi[g] += xr * gs[v, g] + xi * gc[v, g]
        p_max = -1.0
        best = 0
        for g in range(n_g):
            pg = br[g] * br[g] + bi[g] * bi[g]
            if pg > p_max:
                p_max, best = pg, g
            elif not pg == pg:  # NaN: no peak (numpy's argmax stops at the first NaN)
                p_max, best = pg, g
                break
        floor = p_max * (1 - P_SLACK)
        if conv and p_last >= floor:
            u_out[n], ok_out[n] = u, True
            continue
        u2, conv2, p2 = newton_1d(k, lat, xn, grid[best], iterations + 4, pw, e)
        if conv2 and p2 >= floor:
            u_out[n], ok_out[n] = u2, True
        else:
            u_out[n], ok_out[n] = u, False


# -- the pair's design for the bin the RuT detects (aoa.sweep, tolerance_model._Design) ----------


@njit(inline="always", **_JIT)
def _re(f, g):
    """Re(conj(f) g)."""
    return f.real * g.real + f.imag * g.imag


@njit(inline="always", **_JIT)
def _argmax(a, row):
    """numpy's argmax of row ``row`` of a 2-D array: the first maximum, or the first NaN."""
    best = 0
    for i in range(a.shape[1]):
        if a[row, i] != a[row, i]:
            return i
        if a[row, i] > a[row, best]:
            best = i
    return best


@njit(inline="always", **_JIT)
def ratio_one(bi, bi1, bi2, bj, bj1, bj2, e):
    """:func:`rtsgeom.calibration.sweep.ratio_from_beams` for one set-point: the ratio rho >= 0 that
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


@njit(inline="always", **_JIT)
def _root(bi, bi1, bi2, y, y1, y2, r):
    """(rho, P) of root ``r`` of :func:`ratio_one`, (NaN, -inf) where it is not a maximum of
    P at a non-negative rho."""
    p = _re(bi, bi) + r * (2 * _re(bi, y) + r * _re(y, y))
    p2 = 2 * (_re(bi, bi2) + r * (_re(bi, y2) + _re(y, bi2)) + r * r * _re(y, y2)) \
        + 2 * (_re(bi1, bi1) + r * (2 * _re(bi1, y1)) + r * r * _re(y1, y1))
    if math.isfinite(r) and r >= 0 and p2 < 0:
        return r, p
    return np.nan, -np.inf


@njit(**_JIT)
def ratios(bi, bi1, bi2, bj, bj1, bj2, e, out):
    """:func:`ratio_one` over flat arrays (N,) (the broadcast of ``ratio_from_beams``)."""
    for n in range(out.size):
        out[n] = ratio_one(bi[n], bi1[n], bi2[n], bj[n], bj1[n], bj2[n], e[n])


@njit(inline="always", **_JIT)
def choice_row(rho, co, si, p_ii, p_jj, c_re, c_im, power, det):
    """:func:`rtsgeom.calibration.sweep.detected_bin_choice` for one row of K design bins: ratios
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
    margin: the detected bin's power over the next strongest (1 where not consistent)."""
    n_k = rho.size
    mid = n_k // 2
    best, best_rank = 0, 4 * n_k
    for kd in range(n_k):
        fin = math.isfinite(rho[kd]) and rho[kd] > 0
        r = rho[kd] if fin else 0.0
        for kb in range(n_k):
            q = co[kd] * c_re[kb] - si[kd] * c_im[kb]
            power[kd, kb] = p_ii[kb] + (r * r) * p_jj[kb] + 2 * r * q
        det[kd] = _argmax(power, kd) if fin else 0
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
    if consistent:  # the largest over the second largest (numpy's sort: NaN last)
        m1 = m2 = -np.inf
        for kb in range(n_k):
            p = power[k, kb]
            if p != p:
                m1 = np.nan
                break
            if p > m1:
                m1, m2 = p, m1
            elif p > m2:
                m2 = p
        margin = m1 / max(m2, 1e-300)
    return rho[k], k, consistent, margin


@njit(**_JIT)
def bin_choice_rows(rho, co, si, p_ii, p_jj, c_re, c_im, rho_out, k_out, ok_out, mg_out):
    """:func:`choice_row` for each row of (N, K) arrays."""
    n_k = rho.shape[1]
    power = np.empty((n_k, n_k))
    det = np.empty(n_k, np.int64)
    for n in range(rho.shape[0]):
        rho_out[n], k_out[n], ok_out[n], mg_out[n] = choice_row(
            rho[n], co[n], si[n], p_ii[n], p_jj[n], c_re[n], c_im[n], power, det)


@njit(inline="always", **_JIT)
def _cross(table, ri, rj, lo, c):
    """c_ij = sum_v conj(table[0, ri, b, v]) table[1, rj, b, v] at bins b = lo + (0 ..
    c.size - 1)."""
    for b in range(c.size):
        acc = 0j
        for v in range(table.shape[3]):
            acc += table[0, ri, lo + b, v].conjugate() * table[1, rj, lo + b, v]
        c[b] = acc


@njit(**_JIT)
def _scratch(n_k):
    """Work arrays of :func:`_design_one` for ``n_k`` bins."""
    return (np.empty(n_k), np.empty(n_k), np.empty(n_k), np.empty(n_k), np.empty(n_k),
            np.empty(n_k), np.empty(n_k), np.empty((n_k, n_k)), np.empty(n_k, np.int64),
            np.empty(n_k, np.complex128))


@njit(inline="always", **_JIT)
def _design_one(beams_i, beams_j, bi_row, rj, m, lo, e, power, ri, p_one, unit_gain, sc):
    """One set-point ``m`` of ``tolerance_model._Design.__call__``: the ratio per design bin
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


@njit(**_JIT)
def design_rows(beams_i, beams_j, i0, table, power, p_one, unit_gain, row_i, row_j, sub,
                e, sp, lo, n_k, amps, k_out, ok_out, mg_out):
    """``tolerance_model._Design.__call__``: :func:`_design_one` for every draw n (I at table
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


@njit(**_JIT)
def plan_rows(beams_i, beams_j, i0, table, power, p_one, unit_gain, row_i, row_j, sub, e,
              period, lo, n_k, lo_far, n_k_far, min_margin, amps, shift):
    """``tolerance_model._Design.planned`` (``aoa.plan.pair_design``'s choice of J's delay)
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


@njit(**_JIT)
def detect_rows(x_i, x_j, sel, a_i, a_j, snaps, det):
    """The RuT's detection of each draw n and set-point m (``PairPhasors.draw_errors``):
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
            kb = _argmax(power, 0)
            det[n, m] = kb
            for v in range(n_v):
                snaps[n, m, v] = ai * x_i[n, kb, v] + aj * x_j[s, n, kb, v]
