"""What the range/Doppler FFTs output at given bins, computed directly from the echoes.

The processing chain is linear, so the spectrum at range bin r, Doppler bin d and virtual
channel v is a sum over echoes of::

    a[e, v] exp(j phi0[e, v]) * D_d(f_D[e], v) * R_r(S tau[e, v] + f_D[e])

with the windowed slow-time and fast-time DFT kernels D and R evaluated exactly (no sinc
approximation, eq. 11 is its limit). This is the paper's eq. 15/16 level with the exact
geometry: a few thousand operations per bin instead of a cube and two FFTs, which is what
makes Monte-Carlo tolerance studies and the `exact` AoA mode fast. It agrees with
``range_doppler(synthesize(...))`` to complex64 precision (tested).
"""

from __future__ import annotations

import numpy as np

from .._lib.util import tones
from ..geometry import RutArray
from ..rts.channels import Echoes, EchoKind
from ..rts.fir import FirTaps
from ..scene import RadarConfig
from .channels import received_amplitude
from .fmcw import beat_phase0, chirp_start_s
from .windows import window

__all__ = ["bin_response", "bin_response_rows"]


def _tap_sums(taps: FirTaps, kern: np.ndarray, slope: float, f_d: float, t0: float,
              dt: float) -> np.ndarray:
    """Each echo's fast-time sums ``sum_n x_e(n) kern[c, n]`` (E, C) for the signal of
    :class:`~rtsgeom.rts.channels.FirTaps` (Doppler ``f_d``): the tones at the taps' whole-sample
    delays m t_s, Q[m] = sum_n exp(j 2 pi (S t_s m + f_D) t_n) kern[:, n] and the same with a
    factor t_n (Q1, the residual's first order), formed once for every m the echoes reach;
    then per echo sum_k w_ek (Q[n_e + k] + j 2 pi S residual_e Q1[n_e + k]), one product per
    buffer position n_e (echoes grouped by it)."""
    n_e, w, res = taps.samples, taps.weights, taps.residual_s
    n_t, n_s = w.shape[1], kern.shape[1]
    out = np.empty((n_e.size, kern.shape[0]), complex)
    lo = int(n_e.min())  # (a group of bin_response's: one echo or more)
    m = lo - (n_t - 1) / 2 + np.arange(int(n_e.max()) - lo + n_t)  # whole-sample delays
    tone = tones(slope * taps.sample_period_s * m + f_d, t0, dt, n_s)  # (M, N)
    q = tone @ kern.T  # (M, C)
    t_n = t0 + np.arange(n_s) * dt
    # the residual's phase 2 pi S r t_n (mu's rounding to 1e-9 samples) to first order,
    # where the residual exceeds the delays' own rounding (where the delay step is a round
    # fraction of the sample period it is that rounding: the term is skipped)
    x = 2j * np.pi * slope * res
    ulp = 4 * np.finfo(float).eps * (np.abs(n_e).max() + n_t) * taps.sample_period_s
    q1 = (tone * t_n) @ kern.T if np.abs(res).max() > ulp else None
    order = np.argsort(n_e, kind="stable")
    starts = np.flatnonzero(np.r_[True, np.diff(n_e[order]) != 0])
    for a, b in zip(starts, np.r_[starts[1:], n_e.size]):
        rows = order[a:b]
        j = int(n_e[rows[0]]) - lo
        wr = w[rows]
        out[rows] = wr @ q[j:j + n_t]
        if q1 is not None:
            out[rows] += (wr * x[rows, None]) @ q1[j:j + n_t]
    return out


def _fast_time_sums(echoes: Echoes, radar: RadarConfig, r: np.ndarray,
                    taps: FirTaps | None) -> np.ndarray:
    """The range windows' DFT sums of each echo's beat tones along the chirp at range bins
    ``r`` (:func:`bin_response`'s fast time): (K, E, V) complex."""
    n_s = radar.samples_per_chirp
    s = radar.slope_hz_per_s
    tau = echoes.tau_s  # (E, V)
    f_d = echoes.doppler_hz
    # fast time: sum_n w_n exp(j 2 pi (S tau + f_D) t_n) exp(-j 2 pi r n / N)
    w_r = window(radar.range_window, n_s)
    n = np.arange(n_s)
    kern_r = w_r * np.exp(-2j * np.pi * np.outer(r, n) / n_s)  # (K, N)
    t0, dt = radar.adc_start_s, 1.0 / radar.adc_rate_hz
    tau_air = echoes.tau_air_s
    if np.all(tau_air == tau_air[:1]):  # one geometry (a delay table's block)
        air, group = tau_air[:1], None  # (no groups to tell apart)
    else:
        air, group = np.unique(tau_air, axis=0, return_inverse=True)
        group = np.ravel(group)
    if taps is not None and (echoes.fast_gain is not None or np.any(f_d != f_d[:1])
                             or taps.samples.shape != (len(echoes),)
                             or np.any(echoes.kind != EchoKind.DIRECT)):
        raise ValueError("bin_response: taps (one row per echo) replace echoes.fast_gain "
                         "(which must be None) and need direct echoes of one Doppler shift "
                         "(a cable ghost's FIR is its direct echo's, not its own delay's)")
    if taps is not None or 4 * air.shape[0] <= len(echoes):
        # many echoes share their air delays (a delay table: one geometry, many RTS delays):
        # exp(j 2 pi S tau t) = exp(j 2 pi S tau_if t) exp(j 2 pi S tau_air t), the element
        # factor folded into the DFT kernel once per geometry, so each echo needs N tones and
        # one (N,) x (N, V K) product instead of V N tones (the same sums; ~1e-14 rounding)
        if taps is None:
            fast = tones(s * echoes.tau_if_s + f_d, t0, dt, n_s)  # (E, N)
            if echoes.fast_gain is not None:  # fractional-delay FIR ripple along the chirp
                fast = fast * echoes.fast_gain
        elem = tones(s * air, t0, dt, n_s)  # (G, V, N)
        kern = (elem[:, :, None, :] * kern_r).reshape(air.shape[0], -1, n_s)  # (G, V K, N)
        if air.shape[0] == 1 and taps is None:  # one geometry: without the row copies
            rr = fast @ kern[0].T
        else:
            rr = np.empty((len(echoes), tau.shape[1] * r.size), complex)
            for g in range(air.shape[0]):  # a few geometries (loop over groups, not echoes)
                sel = slice(None) if group is None else np.flatnonzero(group == g)
                rr[sel] = (fast[sel] @ kern[g].T if taps is None else
                           _tap_sums(taps.select(sel), kern[g], s, f_d[0], t0, dt))
        rr = np.moveaxis(rr.reshape(len(echoes), tau.shape[1], r.size), -1, 0)
    else:
        beat = s * tau + f_d[:, None]  # (E, V)
        fast = tones(beat, t0, dt, n_s)  # (E, V, N) at t_n
        if echoes.fast_gain is not None:  # fractional-delay FIR ripple along the chirp
            fast = fast * echoes.fast_gain[:, None, :]
        # the window-and-DFT sums as one matrix product (BLAS: 10x numpy's einsum loops
        # here, which were a third of the tolerance model's tables); rounding-level
        # differences only
        rr = np.moveaxis(fast @ kern_r.T, -1, 0)
    return rr


def _slow_time_sums(f_d: np.ndarray, radar: RadarConfig, rut: RutArray, d: np.ndarray
                    ) -> np.ndarray:
    """The Doppler windows' DFT sums over the chirps of each echo's Doppler shift ``f_d``
    (E,) at Doppler bins ``d`` (:func:`bin_response`'s slow time): (K, E, V) complex."""
    n_l = radar.chirps_per_tx
    # slow time (Doppler bin d of the fftshifted spectrum is DFT index d - L/2)
    t_c = chirp_start_s(radar, rut)  # (L, V)
    w_d = window(radar.doppler_window, n_l)
    l = np.arange(n_l)
    kdop = (d - n_l // 2) % n_l
    kern_d = w_d * np.exp(-2j * np.pi * np.outer(kdop, l) / n_l)  # (K, L)
    # per distinct Doppler shift (a delay table has one): the same arithmetic, fewer rows
    f_u, f_inv = np.unique(f_d, return_inverse=True)
    slow = np.exp(2j * np.pi * f_u[:, None, None] * t_c.T[None, :, :])  # (U, V, L)
    return np.moveaxis((slow @ kern_d.T)[np.ravel(f_inv)], -1, 0)


def bin_response(echoes: Echoes, radar: RadarConfig, rut: RutArray, range_bin, doppler_bin,
                 taps: FirTaps | None = None) -> np.ndarray:
    """Spectrum contributions of each echo at the given bins.

    ``range_bin``, ``doppler_bin``: (K,) indices into ``RangeDoppler`` (Doppler fftshifted).
    ``taps``: the echoes' fractional-delay FIR as whole-sample copies (:func:`rtsgeom.rts.channels.fir_taps`
    of these echoes, in place of ``echoes.fast_gain``, which must then be None; direct echoes
    of one Doppler shift): the fast-time sums of the tones at the few whole-sample delays the
    taps reach, formed once per geometry (M x N x V K products, M ~ the delays' span in
    samples plus T) and combined per echo, T x V K products (2 T x V K where the setting's
    rounding leaves a residual) instead of N x (V K + T) (a delay table of thousands of
    settings; the same sums to rounding).
    Returns (K, E, V) complex128; sum over axis 1 for the total.
    """
    r = np.atleast_1d(np.asarray(range_bin))
    d = np.atleast_1d(np.asarray(doppler_bin))
    if len(echoes) == 0:  # (every path blocked)
        return np.zeros((r.size, 0, echoes.tau_air_s.shape[1]), complex)
    # (E, V), through the RuT's own channels (radar.channels)
    phi0 = beat_phase0(echoes, radar)
    amp = received_amplitude(echoes.amplitude, radar, rut, phi0) * np.exp(1j * phi0)
    rr = _fast_time_sums(echoes, radar, r, taps)
    dd = _slow_time_sums(echoes.doppler_hz, radar, rut, d)
    return amp[None] * rr * dd


#: echoes per block of :func:`bin_response_rows` (each block holds (E, V, N) fast-time tones)
ROWS_BLOCK = 256


def bin_response_rows(echoes: Echoes, radar: RadarConfig, rut: RutArray, range_bins,
                      doppler_bins) -> np.ndarray:
    """:func:`bin_response` with each echo at its own bins: ``range_bins``, ``doppler_bins``
    (E, K) indices (Doppler fftshifted) -> (K, E, V) complex128.

    The many channel models of a batch of designs (``synthesis.batch.build_models``: every target
    of a drive's frames at its own range and Doppler bins) in one pass, in blocks of
    :data:`ROWS_BLOCK` echoes: per echo the arithmetic of :func:`bin_response`'s per-echo
    branch (its fast-time tones times the windowed DFT kernel of its bins, the same for the
    slow time), so an echo's response does not depend on the batch it is computed in."""
    r = np.asarray(range_bins)
    d = np.asarray(doppler_bins)
    n_v = echoes.tau_air_s.shape[1]
    out = np.empty((r.shape[1], len(echoes), n_v), complex)
    n_l, n_s = radar.chirps_per_tx, radar.samples_per_chirp
    w_r = window(radar.range_window, n_s)
    w_d = window(radar.doppler_window, n_l)
    n, l = np.arange(n_s), np.arange(n_l)
    t_c = chirp_start_s(radar, rut)  # (L, V)
    t0, dt = radar.adc_start_s, 1.0 / radar.adc_rate_hz
    block = np.arange(len(echoes)) // ROWS_BLOCK
    # the windowed DFT kernel of each distinct bin once (elementwise: the same bits)
    r_u, r_inv = np.unique(r, return_inverse=True)
    kern_rs = w_r * np.exp(-2j * np.pi * np.outer(r_u, n) / n_s)  # (U, N)
    d_u, d_inv = np.unique(d, return_inverse=True)
    kern_ds = w_d * np.exp(-2j * np.pi * np.outer((d_u - n_l // 2) % n_l, l) / n_l)
    r_inv, d_inv = r_inv.reshape(r.shape), d_inv.reshape(d.shape)
    for a in range(0, len(echoes), ROWS_BLOCK):
        sel = slice(a, a + ROWS_BLOCK)
        ech = echoes.select(block == a // ROWS_BLOCK)
        phi0 = beat_phase0(ech, radar)
        amp = received_amplitude(ech.amplitude, radar, rut, phi0) * np.exp(1j * phi0)
        kern_r = kern_rs[r_inv[sel]]  # (E, K, N)
        fast = tones(radar.slope_hz_per_s * ech.tau_s + ech.doppler_hz[:, None], t0, dt, n_s)
        if ech.fast_gain is not None:  # fractional-delay FIR ripple along the chirp
            fast = fast * ech.fast_gain[:, None, :]
        rr = np.moveaxis(fast @ np.swapaxes(kern_r, -1, -2), -1, 0)  # (K, E, V)
        kern_d = kern_ds[d_inv[sel]]  # (E, K, L)
        slow = np.exp(2j * np.pi * ech.doppler_hz[:, None, None] * t_c.T[None, :, :])
        dd = np.moveaxis(slow @ np.swapaxes(kern_d, -1, -2), -1, 0)
        out[:, sel] = amp[None] * rr * dd
    return out
