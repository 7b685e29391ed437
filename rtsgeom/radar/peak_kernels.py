"""The beamformer's 1-D peak (:meth:`rtsgeom.radar.steering.Steering.peak`, D = 1), compiled
(numba): the same arithmetic as its numpy definition :func:`rtsgeom.radar.newton.peak_1d`, bit
for bit (tested), for the large batches of the Monte-Carlo studies.

Compiled by the kernels' rules (:mod:`rtsgeom._lib.jit`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .._lib.jit import JIT
from .newton import P_SLACK, STEP_CLIP, STEP_TOL

__all__ = ["peak_1d", "newton_1d"]

# (numba's cache is keyed on this file: after changing the constants in newton.py, touch this
# file or clear __pycache__/peak_kernels.*.nb*)


# -- the beamformer's peak (Steering.peak, D = 1) ------------------------------------------------


@njit(inline="always", **JIT)
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


@njit(inline="always", **JIT)
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


@njit(**JIT)
def _mirrored(gc, gs):
    """Whether the grid's tables are exactly mirror-symmetric: column G-1-g is column g with
    the sine negated (a grid symmetric about u = 0, as :meth:`Steering.grid`'s)."""
    n_g = gc.shape[1]
    for v in range(gc.shape[0]):
        for g in range(n_g):
            if gc[v, g] != gc[v, n_g - 1 - g] or gs[v, g] != -gs[v, n_g - 1 - g]:
                return False
    return True


@njit(inline="always", **JIT)
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


@njit(**JIT)
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
