"""Numerical kernels of the beamformer's peak search (:meth:`rtsgeom.radar.steering.Steering.peak`):
Newton steps on the log power of tapered snapshots in D direction cosines (what ``peak`` runs
for D = 2; D = 1 runs compiled, snapshot by snapshot: ``rtsgeom.kernels.newton_1d``, the
same steps), and the parabolic interpolation of a sampled peak. Plain numpy on (V_s, n)
arrays, no state.
"""

from __future__ import annotations

import numpy as np

__all__ = ["newton", "parabolic"]


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
        u[act] = ua + np.clip(np.where(fine[:, None], step, 0.0), -0.05, 0.05)
        p_last[act] = p  # within ~1e-10 (relative) of the power at the final u
        done = fine & (np.max(np.abs(np.where(fine[:, None], step, 0.0)), axis=-1) < 1e-6)
        ok[act[done]] = True
        act = act[fine & ~done]
    radius = np.sqrt(np.sum(u ** 2, axis=-1))
    if p_max is None:
        return u, ok & (radius < 1), p_last
    return u, ok & (radius < 1) & (p_last >= p_max * (1 - 1e-9))


def parabolic(y0, y1, y2) -> np.ndarray:
    """Sub-bin offset of a peak from three samples."""
    den = y0 - 2 * y1 + y2
    return np.where(den < 0, 0.5 * (y0 - y2) / np.where(den == 0, -1, den), 0.0)
