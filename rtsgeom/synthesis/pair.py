"""The exact design of a front-end pair (Q = 2, D = 1) in closed form: the fast path of
:meth:`ChannelModel.solve <rtsgeom.synthesis.model.ChannelModel.solve>` and of every study
that designs pairs in bulk (the calibration sweep, the tolerance model).

The ratio ``rho = A_J / A_I`` that puts the beamformer's peak of ``x_I + rho e^{j phase} x_J``
at the set direction is a root of a quadratic in rho (:func:`design_ratio`, paper eqs. 14 and
17-23 with the RuT's own snapshots instead of the far-field array factor); the bin the RuT
detects decides which candidate range bin the design is made for
(:func:`design_at_detected_bin`). For an estimator without such a closed form (a smoothed Capon
or MUSIC) :func:`estimator_ratio` bisects on its peak.
"""

from __future__ import annotations

import numpy as np

from .._lib.util import use_kernels
from .choice import bin_choice_rows_numpy
from ..radar.steering import Steering

__all__ = ["JUMP_RAD", "beam_derivatives", "design_ratio", "ratio_from_beams",
           "design_at_detected_bin", "detected_bin_choice", "estimator_ratio"]


#: How far the root finder's angle may miss the set angle before it counts as a jump (a
#: smoothed Capon or MUSIC resolving the front ends); continuous peaks meet it to ~1e-8 rad.
JUMP_RAD = np.radians(1e-3)


def estimator_ratio(st: Steering, x_i, x_j, alpha_rad, phase=0.0,
                    log_span: float = 12.0, grid: int = 13, iterations: int = 40
                    ) -> np.ndarray:
    """The ratio rho >= 0 (...,) for which the estimator's detected angle of
    ``x_i + rho e^{j phase} x_j`` (snapshots (..., V)) is ``alpha_rad`` (broadcast against
    (...,), as ``phase``), by bisection on
    log rho, batched over all snapshots: what ``design_ratio`` (Bartlett's peak
    condition in closed form) is for an estimator without one (a smoothed Capon or MUSIC,
    ``Steering.smoothing``). The bracket is the first sign change of (angle - alpha) on
    ``grid`` log-spaced ratios over e^{+-log_span}; NaN where there is none, or where the
    bisection closes in on a jump of the detected angle (the estimator resolves the
    channels, :data:`JUMP_RAD`). Bisection, not a faster root finder: the detected angle of
    such an estimator can jump, and bisection stays inside its bracket."""
    x_i, x_j = np.broadcast_arrays(np.asarray(x_i), np.asarray(x_j))
    shape, n_v = x_i.shape[:-1], x_i.shape[-1]
    ph = np.broadcast_to(np.exp(1j * np.asarray(phase, float)), shape)
    xi = x_i.reshape(-1, n_v)
    xj = (x_j * ph[..., None]).reshape(-1, n_v)
    alpha = np.broadcast_to(np.asarray(alpha_rad, float), shape).reshape(-1)  # (n,)
    n = xi.shape[0]
    lr = np.linspace(-log_span, log_span, grid)
    f = st.search(xi[:, None, :] + np.exp(lr)[None, :, None] * xj[:, None, :]) - alpha[:, None]
    change = (np.sign(f[:, :-1]) * np.sign(f[:, 1:]) <= 0) & np.isfinite(f[:, :-1] + f[:, 1:])
    has = change.any(axis=1)
    k = np.argmax(change, axis=1)
    rows = np.arange(n)
    lo, hi, f_lo = lr[k], lr[k + 1], f[rows, k]
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        f_mid = st.search(xi + np.exp(mid)[:, None] * xj) - alpha
        left = np.sign(f_mid) == np.sign(f_lo)
        lo, f_lo = np.where(left, mid, lo), np.where(left, f_mid, f_lo)
        hi = np.where(left, hi, mid)
    x = 0.5 * (lo + hi)
    got = st.search(xi + np.exp(x)[:, None] * xj)
    ok = has & (np.abs(got - alpha) < JUMP_RAD)
    return np.where(ok, np.exp(x), np.nan).reshape(shape)


def beam_derivatives(st: Steering, x, u):
    """Beamformer output b(u) and its first two derivatives in u at directions ``u`` (...,)
    for snapshots ``x`` (..., V) (D = 1): three arrays (...,)."""
    w = st.weighted(x)  # (..., V_s)
    k = st.wavevector[:, 0]  # (V_s,)
    e = np.exp(1j * k * np.asarray(u)[..., None])
    y = w * e
    return y.sum(-1), (1j * k * y).sum(-1), (-(k * k) * y).sum(-1)


def design_ratio(st: Steering, x_i, x_j, alpha_rad, phase=0.0):
    """The exact amplitude design in closed form: the ratio rho >= 0 (...,) for which the
    beamformer peak of ``x_i + rho e^{j phase} x_j`` (snapshots (..., V)) lies at
    ``alpha_rad``.

    With b_q(u) the channels' beam responses at u = sin(alpha), the peak condition
    dP/du = 0, P = |b_I + rho y|^2 (y = e^{j phase} b_J), is the quadratic
    ``Re(b_I* b_I') + rho Re(b_I* y' + y* b_I') + rho^2 Re(y* y') = 0``; of its non-negative
    roots the one where P is a maximum (P'' < 0) with the larger P. NaN where none is (the
    angle is outside the pair's span). Agrees with the root finder on the searched peak
    (``ChannelModel.solve``) to its tolerance (tested). A smoothed Capon or MUSIC
    (``Steering.smoothing``) has no such closed form: ``model.estimator_ratio`` solves it on
    the estimator's own peak."""
    if st.smoothing:
        return estimator_ratio(st, x_i, x_j, alpha_rad, phase)
    u = np.sin(np.asarray(alpha_rad, float))
    return ratio_from_beams(beam_derivatives(st, x_i, u), beam_derivatives(st, x_j, u), phase)


def ratio_from_beams(beam_i, beam_j, phase=0.0):
    """:func:`design_ratio` from the channels' beam responses and their first two derivatives
    in u at the set direction, ``(b, b', b'')`` each (...,) (e.g. gathered from a table),
    broadcast with ``phase``: rho (...).

    P, dP/du and d2P/du2 of ``b_I + rho y`` are quadratics in rho with real coefficients
    (``Re(conj(f) g)`` of the beams), formed once; the roots and the maximum test are then
    real arithmetic (:func:`_ratios`, the definition), compiled per set-point for large
    batches (``rtsgeom.synthesis.kernels.ratio_one``, the same bits: the Monte-Carlo studies call it for
    millions of set-points; small batches numpy, without numba's import:
    ``rtsgeom._lib.util.use_kernels``)."""
    arrs = np.broadcast_arrays(*(np.asarray(b, complex) for b in (*beam_i, *beam_j)),
                               np.exp(1j * np.asarray(phase, float)))
    flat = [np.ascontiguousarray(a).reshape(-1) for a in arrs]
    if not use_kernels(flat[0].size, 2e-7):  # numpy ~0.2 us per set-point (measured)
        return _ratios(*flat).reshape(arrs[0].shape)
    from .kernels import ratios
    out = np.empty(arrs[0].shape)
    ratios(*flat, out.reshape(-1))
    return out


@np.errstate(all="ignore")  # as silent as the compiled kernel (radar/newton.py)
def _ratios(bi, bi1, bi2, bj, bj1, bj2, e):
    """The ratio rho >= 0 per set-point (flat arrays (N,)) that puts the peak of
    P(u) = |b_I + rho y|^2 (y = e b_J, e = e^{j phase} J's phase factor) at the set
    direction, from the beams and their first two derivatives in u there.

    dP/du = 0 is a0 + a1 rho + a2 rho^2 = 0 with a0 = Re(b_I* b_I'), a1 = Re(b_I* y' + y* b_I'),
    a2 = Re(y* y'); of its roots the non-negative ones with P'' < 0 (P'' = 2 Re(s* s'') +
    2 |s'|^2, s = b_I + rho y, a quadratic in rho), the one with the larger P (the first on a
    tie); NaN where none is. Real arithmetic in the compiled kernel's order
    (``kernels.ratio_one``, its compiled form: the complex products written out as
    (ac - bd, ad + bc)), so both give the same bits (tested)."""
    def mul(f, g):
        return (f[0] * g[0] - f[1] * g[1], f[0] * g[1] + f[1] * g[0])

    def re(f, g):  # Re(conj(f) g)
        return f[0] * g[0] + f[1] * g[1]

    bi, bi1, bi2, bj, bj1, bj2, e = ((a.real, a.imag) for a in (bi, bi1, bi2, bj, bj1, bj2, e))
    y, y1, y2 = mul(e, bj), mul(e, bj1), mul(e, bj2)
    a0 = re(bi, bi1)
    a1 = re(bi, y1) + re(y, bi1)
    a2 = re(y, y1)
    disc = a1 * a1 - 4 * a0 * a2
    sq = np.sqrt(np.where(disc >= 0, disc, np.nan))
    lin = -a0 / a1  # a2 = 0: the one root of the linear equation
    out = []
    for sign in (1, -1):
        r = np.where(a2 != 0, (-a1 + sign * sq) / (2 * a2), lin)
        p = re(bi, bi) + r * (2 * re(bi, y) + r * re(y, y))
        p2 = (2 * (re(bi, bi2) + r * (re(bi, y2) + re(y, bi2)) + r * r * re(y, y2))
              + 2 * (re(bi1, bi1) + r * (2 * re(bi1, y1)) + r * r * re(y1, y1)))
        keep = np.isfinite(r) & (r >= 0) & (p2 < 0)
        out.append((np.where(keep, r, np.nan), np.where(keep, p, -np.inf)))
    (r0, s0), (r1, s1) = out
    # numpy's argmax over (s0, s1): the first maximum, or the first NaN
    return np.where((s0 == s0) & ((s1 != s1) | (s1 > s0)), r1, r0)


def design_at_detected_bin(st: Steering, h, alpha_rad, phase=0.0):
    """The exact design of a pair for the bin the RuT detects (the bin logic of the module
    docstring, vectorised): ``h`` (..., K, 2, V) the TDM-compensated unit responses of
    channels I and J at K candidate range bins (the set range's in the middle), ``alpha_rad``
    and ``phase`` broadcast against (...,).

    For each design bin k the closed-form ratio (:func:`design_ratio`) and the bin the RuT
    then detects (the strongest candidate of ``I + rho e^{j phase} J``, power summed over all
    virtual elements); the design bin chosen is the one where design and detection agree,
    nearest the set range's bin first. Returns ``rho`` (...), ``bin`` (...) (index into K;
    where no bin agrees: the fixed point of "design at the reported bin" from the middle
    bin, as :func:`phasor_sweep`), ``consistent`` (...) and ``margin`` (...) (the detected
    bin's power over the next strongest; 1 where not consistent). NaN ``rho`` where no bin
    has a design."""
    h = np.asarray(h)
    x_i, x_j = h[..., 0, :], h[..., 1, :]  # (..., K, V)
    a = np.asarray(alpha_rad, float)[..., None]
    ph = np.asarray(phase, float)[..., None]
    rho = design_ratio(st, x_i, x_j, a, ph)  # (..., K)
    p_ii = np.sum(x_i.real ** 2 + x_i.imag ** 2, -1)  # (..., K)
    p_jj = np.sum(x_j.real ** 2 + x_j.imag ** 2, -1)
    c_ij = np.sum(np.conj(x_i) * x_j, -1)
    return detected_bin_choice(rho, ph, p_ii, p_jj, c_ij)


def detected_bin_choice(rho, phase, p_ii, p_jj, c_ij, margin: bool = True):
    """The bin logic of :func:`design_at_detected_bin` from the ratios per design bin ``rho``
    (..., K), J's phase (broadcast) and the channels' power sums over the virtual elements at
    each candidate bin: ``p_ii``, ``p_jj`` (..., K) and ``c_ij = sum conj(x_i) x_j``:
    (rho, k, consistent, margin), each (...). ``margin=False``: the fourth result is None.

    Per row (``rtsgeom.synthesis.kernels.choice_row``, compiled): the power of each design at every bin,
    |I + r e^{j ph} J|^2 = p_ii + r^2 p_jj + 2 r Re(e^{j ph} c_ij) (r = 0 where rho is not a
    positive number), each design's detected bin the strongest; of the designs detected at
    their own bin the one nearest the middle (ties to the lower bin), else the fixed point of
    "design at the reported bin" from the middle bin; the margin is the detected bin's power
    over the next strongest (1 where not consistent)."""
    rho = np.asarray(rho, float)
    c_ij = np.asarray(c_ij)
    n_k = rho.shape[-1]
    lead = np.broadcast_shapes(rho.shape[:-1], np.shape(p_ii)[:-1], np.shape(p_jj)[:-1],
                               c_ij.shape[:-1])
    rows = [np.ascontiguousarray(np.broadcast_to(a, lead + (n_k,)), float).reshape(-1, n_k)
            for a in (rho, *(f(np.broadcast_to(np.asarray(phase, float), rho.shape))
                                   for f in (np.cos, np.sin)), p_ii, p_jj, c_ij.real,
                      np.imag(c_ij))]
    n = rows[0].shape[0]
    if use_kernels(n, 1e-7 * n_k * n_k):  # numpy 0.03-0.1 us per row and bin pair (measured)
        from .kernels import bin_choice_rows
        out, k = np.empty(n), np.empty(n, np.int64)
        ok, mg = np.empty(n, bool), np.empty(n)
        bin_choice_rows(*rows, out, k, ok, mg)
    else:
        out, k, ok, mg = bin_choice_rows_numpy(*rows)
    out, k, ok, mg = (a.reshape(lead) for a in (out, k, ok, mg))
    return out, k, ok, (mg if margin else None)
