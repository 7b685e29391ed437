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

from ..geometry import RutArray
from ..rts import Echoes
from ..scene import RadarConfig
from .fmcw import beat_phase0, chirp_start_s
from .steering import window

__all__ = ["bin_response"]


def _tones(freq_hz: np.ndarray, t0_s: float, dt_s: float, n: int) -> np.ndarray:
    """``exp(2 pi j f (t0 + i dt))`` for i = 0..n-1: (..., n) for frequencies (...).

    Factored as ``exp(2 pi j f (t0 + a B dt)) exp(2 pi j f b dt)``, i = a B + b with
    B ~ sqrt(n): 2 sqrt(n) complex exponentials and n products per frequency instead of n
    exponentials (numpy's complex ``exp`` dominated the model construction: 0.2 s for the
    delay table of ~1000 echoes). Agrees with the direct form to ~1e-15 (tested); each
    phase is a product of two exact-to-rounding factors, no recursion that accumulates."""
    f = np.asarray(freq_hz, float)[..., None]
    block = max(1, int(np.ceil(np.sqrt(n))))
    outer = np.exp(2j * np.pi * f * (t0_s + np.arange(-(-n // block)) * block * dt_s))
    inner = np.exp(2j * np.pi * f * (np.arange(block) * dt_s))
    out = outer[..., :, None] * inner[..., None, :]
    return out.reshape(out.shape[:-2] + (-1,))[..., :n]


def bin_response(echoes: Echoes, radar: RadarConfig, rut: RutArray, range_bin, doppler_bin
                 ) -> np.ndarray:
    """Spectrum contributions of each echo at the given bins.

    ``range_bin``, ``doppler_bin``: (K,) indices into ``RangeDoppler`` (Doppler fftshifted).
    Returns (K, E, V) complex128; sum over axis 1 for the total.
    """
    r = np.atleast_1d(np.asarray(range_bin))
    d = np.atleast_1d(np.asarray(doppler_bin))
    n_l, n_s = radar.chirps_per_tx, radar.samples_per_chirp
    s = radar.slope_hz_per_s
    tau = echoes.tau_s  # (E, V)
    f_d = echoes.doppler_hz
    amp = echoes.amplitude * np.exp(1j * beat_phase0(echoes, radar))  # (E, V)
    # fast time: sum_n w_n exp(j 2 pi (S tau + f_D) t_n) exp(-j 2 pi r n / N)
    w_r = window(radar.range_window, n_s)
    n = np.arange(n_s)
    kern_r = w_r * np.exp(-2j * np.pi * np.outer(r, n) / n_s)  # (K, N)
    t0, dt = radar.adc_start_s, 1.0 / radar.adc_rate_hz
    tau_air = echoes.tau_air_s
    if len(echoes) and np.all(tau_air == tau_air[:1]):  # one geometry (a delay table's block)
        air, group = tau_air[:1], None  # (no groups to tell apart)
    else:
        air, group = np.unique(tau_air, axis=0, return_inverse=True)
        group = np.ravel(group)
    if 4 * air.shape[0] <= len(echoes):
        # many echoes share their air delays (a delay table: one geometry, many RTS delays):
        # exp(j 2 pi S tau t) = exp(j 2 pi S tau_if t) exp(j 2 pi S tau_air t), the element
        # factor folded into the DFT kernel once per geometry, so each echo needs N tones and
        # one (N,) x (N, V K) product instead of V N tones (the same sums; ~1e-14 rounding)
        fast = _tones(s * echoes.tau_if_s + f_d, t0, dt, n_s)  # (E, N)
        if echoes.fast_gain is not None:  # fractional-delay FIR ripple along the chirp
            fast = fast * echoes.fast_gain
        elem = _tones(s * air, t0, dt, n_s)  # (G, V, N)
        kern = (elem[:, :, None, :] * kern_r).reshape(air.shape[0], -1, n_s)  # (G, V K, N)
        if air.shape[0] == 1:  # one geometry: the same product without the row copies
            rr = fast @ kern[0].T
        else:
            rr = np.empty((len(echoes), tau.shape[1] * r.size), complex)
            for g in range(air.shape[0]):  # a few geometries (loop over groups, not echoes)
                sel = np.flatnonzero(group == g)
                rr[sel] = fast[sel] @ kern[g].T
        rr = np.moveaxis(rr.reshape(len(echoes), tau.shape[1], r.size), -1, 0)
    else:
        beat = s * tau + f_d[:, None]  # (E, V)
        fast = _tones(beat, t0, dt, n_s)  # (E, V, N) at t_n
        if echoes.fast_gain is not None:  # fractional-delay FIR ripple along the chirp
            fast = fast * echoes.fast_gain[:, None, :]
        # the window-and-DFT sums as one matrix product (BLAS: 10x numpy's einsum loops
        # here, which were a third of the tolerance model's tables); rounding-level
        # differences only
        rr = np.moveaxis(fast @ kern_r.T, -1, 0)
    # slow time (Doppler bin d of the fftshifted spectrum is DFT index d - L/2)
    t_c = chirp_start_s(radar, rut)  # (L, V)
    w_d = window(radar.doppler_window, n_l)
    l = np.arange(n_l)
    kdop = (d - n_l // 2) % n_l
    kern_d = w_d * np.exp(-2j * np.pi * np.outer(kdop, l) / n_l)  # (K, L)
    # per distinct Doppler shift (a delay table has one): the same arithmetic, fewer rows
    f_u, f_inv = np.unique(f_d, return_inverse=True)
    slow = np.exp(2j * np.pi * f_u[:, None, None] * t_c.T[None, :, :])  # (U, V, L)
    dd = np.moveaxis((slow @ kern_d.T)[np.ravel(f_inv)], -1, 0)
    return amp[None] * rr * dd
