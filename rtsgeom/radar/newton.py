"""Numerical kernels of the beamformer's peak search (:meth:`rtsgeom.radar.steering.Steering.peak`):
Newton steps on the log power of tapered snapshots in D direction cosines (what ``peak`` runs
for D = 2), the D = 1 peak with its global check (:func:`peak_1d`: the definition that
``rtsgeom.synthesis.kernels.peak_1d`` compiles, bit for bit, for large batches), and the parabolic
interpolation of a sampled peak. Plain numpy on (V_s, n) arrays, no state.
"""

from __future__ import annotations

import numpy as np

__all__ = ["newton", "parabolic", "lattice", "newton_1d", "peak_1d", "STEP_CLIP", "STEP_TOL",
           "P_SLACK"]

#: Newton: each step clipped to this in u, converged when a step is below ``STEP_TOL``
STEP_CLIP = 0.05
STEP_TOL = 1e-6
#: the global check's relative slack (rounding of the powers)
P_SLACK = 1e-9


def newton(kv, xr, xi, u, p_max, steps):
    """Newton steps on log P from ``u`` (n, D) for tapered snapshots (V_s, n) split in real and
    imaginary parts: (u, accepted); accepted needs the power at the peak >= ``p_max``. With
    ``p_max`` None: (u, accepted without the power condition, the power at the peak).

    With B = sum_v y_v (y_v = w_v x_v e^{j k p_v . u}), C_a = sum k_va y_v, D_ab = sum k_va
    k_vb y_v: dB/du_a = j C_a, d2B/du_a du_b = -D_ab, so for log P, P = |B|^2,
    g_a = 2 (Im B Re C_a - Re B Im C_a) / P and
    H_ab = 2 (Re C_a Re C_b + Im C_a Im C_b - Re B Re D_ab - Im B Im D_ab) / P - g_a g_b."""
    n_d = kv.shape[1]
    u = np.array(u, float)
    ok = np.zeros(u.shape[0], bool)
    p_last = np.zeros(u.shape[0])
    act = np.arange(u.shape[0])
    pairs = [(a, b) for a in range(n_d) for b in range(a, n_d)]
    for _ in range(steps):
        if act.size == 0:
            break
        ar, ai, ua = xr[:, act], xi[:, act], u[act]
        ph = np.sum(kv[:, :, None] * ua.T[None], axis=1)  # (V_s, n)
        co, si = np.cos(ph), np.sin(ph)
        y = np.stack([ar * co - ai * si, ar * si + ai * co])  # (2, V_s, n): Re, Im
        # row sums: bit-stable
        bb = y.sum(axis=1)
        cc = [(y * kv[:, a, None]).sum(axis=1) for a in range(n_d)]
        dd = {(a, b): (y * (kv[:, a] * kv[:, b])[:, None]).sum(axis=1) for a, b in pairs}
        p = bb[0] ** 2 + bb[1] ** 2
        with np.errstate(divide="ignore", invalid="ignore"):
            g = np.stack([2 * (bb[1] * cc[a][0] - bb[0] * cc[a][1]) / p for a in range(n_d)])
            h = np.empty((n_d, n_d, act.size))
            for a, b in pairs:
                h[a, b] = h[b, a] = (2 * (cc[a][0] * cc[b][0] + cc[a][1] * cc[b][1]
                                          - bb[0] * dd[a, b][0] - bb[1] * dd[a, b][1]) / p
                                     - g[a] * g[b])
            if n_d == 1:
                step = np.where(h[0, 0] < 0, -g[0] / h[0, 0], np.nan)[:, None]
            else:
                hm, gm = np.moveaxis(h, -1, 0), g.T  # (n, D, D), (n, D)
                concave = np.all(np.linalg.eigvalsh(np.where(np.isfinite(hm), hm, 0.0)) < 0,
                                 axis=-1) & np.all(np.isfinite(hm), axis=(-2, -1))
                safe = np.where(concave[:, None, None], hm, -np.eye(n_d))
                step = np.where(concave[:, None], -np.linalg.solve(safe, gm[..., None])[..., 0],
                                np.nan)
        fine = np.all(np.isfinite(step), axis=-1)
        u[act] = ua + np.clip(np.where(fine[:, None], step, 0.0), -STEP_CLIP, STEP_CLIP)
        p_last[act] = p  # within ~1e-10 (relative) of the power at the final u
        done = fine & (np.max(np.abs(np.where(fine[:, None], step, 0.0)), axis=-1) < STEP_TOL)
        ok[act[done]] = True
        act = act[fine & ~done]
    radius = np.sqrt(np.sum(u ** 2, axis=-1))
    if p_max is None:
        return u, ok & (radius < 1), p_last
    return u, ok & (radius < 1) & (p_last >= p_max * (1 - P_SLACK))


def parabolic(y0, y1, y2) -> np.ndarray:
    """Sub-bin offset of a peak from three samples."""
    den = y0 - 2 * y1 + y2
    return np.where(den < 0, 0.5 * (y0 - y2) / np.where(den == 0, -1, den), 0.0)


# -- D = 1: the definition of the compiled peak (rtsgeom.synthesis.kernels.peak_1d) --------------------
#
# Vectorised over the snapshots with, per snapshot, exactly the compiled kernel's arithmetic:
# sums accumulated element by element from 0.0 (explicit loops over the V_s elements, not
# numpy's reductions, whose order depends on the array's layout), complex products written
# out as (ac - bd, ad + bc) (the kernel's, CPython's), cosines and sines from numpy (equal to
# the C library's that the kernel calls, checked bit for bit by tests/radar/test_kernels_peak.py).
# Steering.peak runs this while numba's set-up would cost more (``rtsgeom._lib.util.use_kernels``:
# no numba import for a few thousand snapshots, the calibration), the kernel after; both give
# the same bits.


def lattice(k: np.ndarray, kappa: float):
    """The wavenumbers ``k`` (V_s,) as k_0 + m_v kappa + r_v (m_v >= 0 integers, r_v the
    remainder, set to 0 at rounding level): (k_0, kappa, m, r) for :func:`lattice_phasors`.
    ``kappa`` the grid's wavenumber step (2 pi pitch / lambda; 0: no grid, every r_v kept)."""
    k = np.asarray(k, float)
    k0 = float(k.min())
    m = np.zeros(k.size, np.int64)
    if kappa > 0:
        m = np.round((k - k0) / kappa).astype(np.int64)
    r = k - (k0 + m * kappa)
    r[np.abs(r) <= 1e-13 * np.abs(k).max()] = 0.0
    return k0, float(kappa), m, r


def lattice_phasors(lat, u):
    """e^{j k_v u} for the wavenumbers of lattice ``lat`` (:func:`lattice`) at ``u`` (n,):
    (real, imaginary) lists of V_s arrays (n,). ``e^{j k_0 u} z^{m_v} e^{j r_v u}``,
    z = e^{j kappa u}, the powers by products, the last factor only where r_v != 0 (two
    cosines and sines per snapshot on a uniform grid instead of two per element)."""
    k0, kappa, m, r = lat
    pr, pi_ = [np.cos(k0 * u)], [np.sin(k0 * u)]
    zr, zi = np.cos(kappa * u), np.sin(kappa * u)
    for _ in range(int(m.max())):
        a, b = pr[-1], pi_[-1]
        pr.append(a * zr - b * zi)
        pi_.append(a * zi + b * zr)
    er, ei = [], []
    for v in range(m.size):
        a, b = pr[m[v]], pi_[m[v]]
        if r[v] != 0.0:
            c, s = np.cos(r[v] * u), np.sin(r[v] * u)
            a, b = a * c - b * s, a * s + b * c
        er.append(a)
        ei.append(b)
    return er, ei


# The numpy definitions of the compiled kernels are as silent as the kernels
# (``error_model="numpy"``: inf/NaN propagate without warnings): a warning must not depend on
# which of the two paths a process happened to take (``_lib.util.use_kernels``).
@np.errstate(all="ignore")
def newton_1d(k, lat, xr, xi, u, steps):
    """Newton steps on log P(u), P = |B|^2, B(u) = sum_v y_v, y_v = x_v e^{j k_v u}, for
    tapered snapshots ``xr + j xi`` (V_s, n) (wavenumbers times positions ``k`` (V_s,), their
    lattice ``lat``) from ``u`` (n,), at most ``steps``: (u, converged, P at the last step's
    start), each (n,).

    With C = sum k_v y_v and D = sum k_v^2 y_v (dB/du = j C, d2B/du2 = -D):
    g = d log P / du = 2 (Im B Re C - Re B Im C) / P and
    h = 2 (|C|^2 - Re B Re D - Im B Im D) / P - g^2; the step -g / h where h < 0 (else no
    step: not concave, not converged), clipped to +-``STEP_CLIP``; converged when a step is
    below ``STEP_TOL`` (it is still applied) and |u| < 1."""
    u = np.array(u, float)
    conv = np.zeros(u.size, bool)
    p_last = np.zeros(u.size)
    kk = k * k
    act = np.arange(u.size)
    for _ in range(steps):
        if act.size == 0:
            break
        ua = u[act]
        er, ei = lattice_phasors(lat, ua)
        b0, b1, c0, c1, d0, d1 = np.zeros((6, act.size))
        for v in range(k.size):
            ar, ai = xr[v, act], xi[v, act]
            yr = ar * er[v] - ai * ei[v]
            yi = ar * ei[v] + ai * er[v]
            b0 += yr
            b1 += yi
            c0 += yr * k[v]
            c1 += yi * k[v]
            d0 += yr * kk[v]
            d1 += yi * kk[v]
        p = b0 * b0 + b1 * b1
        g = 2 * (b1 * c0 - b0 * c1) / p  # (warnings off: the function's errstate)
        h = 2 * (c0 * c0 + c1 * c1 - b0 * d0 - b1 * d1) / p - g * g
        step = -g / h
        p_last[act] = p
        go = (h < 0) & np.isfinite(step)
        u[act[go]] = ua[go] + np.minimum(np.maximum(step[go], -STEP_CLIP), STEP_CLIP)
        done = go & (np.abs(step) < STEP_TOL)
        conv[act[done]] = np.abs(u[act[done]]) < 1
        act = act[go & ~done]
    return u, conv, p_last


@np.errstate(all="ignore")
def peak_1d(k, lat, x, u0, gc, gs, grid, iterations):
    """:meth:`Steering.peak` for D = 1 on tapered snapshots ``x`` (n, V_s): Newton
    (:func:`newton_1d`, ``iterations`` steps) from ``u0`` (n,), accepted when it converged
    and no point of the grid ``grid`` (G,) (steering cos/sin tables ``gc``, ``gs`` (V_s, G))
    has more power than the peak (``1 - P_SLACK`` relative; each grid point's power summed
    over the elements in order); otherwise Newton again from the grid's maximum (numpy's
    argmax: the first maximum, or the first NaN) with ``iterations + 4`` steps under the same
    test. Returns (u (n,): the first Newton's where both fail, accepted (n,))."""
    xr, xi = np.ascontiguousarray(x.real.T), np.ascontiguousarray(x.imag.T)
    u, conv, p_last = newton_1d(k, lat, xr, xi, u0, iterations)
    br = np.zeros((x.shape[0], gc.shape[1]))
    bi = np.zeros_like(br)
    for v in range(k.size):
        a, b = xr[v, :, None], xi[v, :, None]
        br += a * gc[v] - b * gs[v]
        bi += a * gs[v] + b * gc[v]
    power = br * br + bi * bi
    best = np.argmax(power, axis=1)
    floor = power[np.arange(best.size), best] * (1 - P_SLACK)
    ok = conv & (p_last >= floor)
    redo = np.flatnonzero(~ok)
    if redo.size:
        u2, conv2, p2 = newton_1d(k, lat, xr[:, redo], xi[:, redo], grid[best[redo]],
                                  iterations + 4)
        good = conv2 & (p2 >= floor[redo])
        u[redo[good]] = u2[good]
        ok[redo[good]] = True
    return u, ok
