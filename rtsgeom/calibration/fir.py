"""The fractional-delay FIR as the calibration sees it: the filter's gain
at an echo's range bin (its response along the chirp's IF sweep, ``rts.fir_if_gain``,
weighted by the range window), the phase it adds to each step of the calibration sweep, and
the shift of the coherence point it predicts."""

from __future__ import annotations

import numpy as np

from ..rts.fir import fir_if_gain, fir_modelled, realised_delay
from ..rts.channels import requested_delay
from ..radar.windows import window
from .probes import if_phase_slope_hz, mean_air_delay, probe_ranges, probe_total_delay

__all__ = ["fir_bin_gain", "fir_effect", "fir_sweep_phase"]


def fir_bin_gain(scene, delays_s, tau_total_s) -> np.ndarray:
    """The fractional-delay FIR's gain on each echo as the range DFT sees it at the echo's
    range bin: its beat-signal gain along the chirp (``rts.fir_if_gain``, at the setting of
    each programmed delay ``delays_s`` (E,), echo total delay ``tau_total_s`` (E,)) weighted
    by the range window and the echo's tone, (E,) complex; ones for an ideal delay."""
    delays = np.atleast_1d(np.asarray(delays_s, float))
    tau = np.atleast_1d(np.asarray(tau_total_s, float))
    g = fir_if_gain(scene, delays, tau)  # (E, N)
    if g is None:
        return np.ones(delays.size, complex)
    radar = scene.radar
    n_s = radar.samples_per_chirp
    t_n = radar.adc_start_s + np.arange(n_s) / radar.adc_rate_hz
    beat = radar.slope_hz_per_s * tau  # (E,)
    r0 = np.round(beat * n_s / radar.adc_rate_hz)  # the echo's range bin
    kern = window(radar.range_window, n_s) * np.exp(
        2j * np.pi * (beat[:, None] * t_n - r0[:, None] * np.arange(n_s) / n_s))
    return np.sum(kern * g, 1) / np.sum(kern, 1)


def fir_effect(setup, delta_tau_s: float, base_offsets=(0.0, 0.0), ranges=None) -> dict:
    """The fractional-delay FIR at the settings the calibration's two probe targets (at
    ``ranges``, default :func:`probe_ranges`; a calibration's ``probe_ranges_m``) program on
    channels I (delay ``base``) and J (``base + delta_tau_s``): its gain and phase ripple
    along the chirp's IF sweep (``rts.fir_if_gain``) and the shift of the coherence point it
    predicts, the mean over the probes of ``(phi_I - phi_J) / (2 pi f_if)``, phi the
    range-window-weighted phase of each channel's beat-signal gain (what the range DFT sees
    at the target's bin, :func:`fir_bin_gain`), f_if = 1 / period."""
    scene = setup.scene
    model = scene.rts.fractional_delay_filter if scene.rts.fractional_delay else "none"
    rng = probe_ranges(setup, 2) if ranges is None or len(ranges) == 0 else np.asarray(ranges)
    base = requested_delay(scene, rng)  # (2,) one per probe
    delays = np.concatenate([base + base_offsets[0], base + base_offsets[1] + delta_tau_s])
    tau = np.concatenate([requested_delay(scene, rng)] * 2) + np.mean(mean_air_delay(setup))
    g = fir_if_gain(scene, delays, tau)  # (4, N): I of both probes, then J of both
    if g is None:
        return {"model": model, "gain_ripple_db": 0.0, "phase_ripple_deg": 0.0,
                "predicted_shift_ps": 0.0}
    phi = np.angle(fir_bin_gain(scene, delays, tau)).reshape(2, 2)  # [channel, probe]
    period = 1.0 / float(if_phase_slope_hz(scene, probe_total_delay(setup, rng)))
    shift = float(np.angle(np.mean(np.exp(1j * (phi[0] - phi[1])))) / (2 * np.pi) * period)
    return {"model": model,
            "gain_ripple_db": float(np.ptp(20 * np.log10(np.abs(g)))),
            "phase_ripple_deg": float(np.ptp(np.degrees(np.angle(g)))),
            "predicted_shift_ps": shift * 1e12}


def fir_sweep_phase(setup, ranges, deltas, base_offsets, continuous: bool = False
                    ) -> np.ndarray | None:
    """The phase (S, P) the fractional-delay FIR adds to channel J relative to channel I of
    each probe (at ``ranges``) at every sweep step ``deltas`` (S,): the beat-signal phase of
    the filter's own response at the probe's bin (:func:`fir_bin_gain`) at J's setting
    (base + delta) minus I's, both at the settings the RTS realises (``rts.realised_delay``;
    with ``continuous``: J at its realised base plus the unrounded delta, the continuous
    model of ``calibration.continuous_delay_setup``). It cycles with the setting every
    1/f_s, which the RTS's designer knows; the fit of the sweep takes it out
    (``fit.fit_centre``). None for an ideal delay."""
    scene = setup.scene
    rts = scene.rts
    if not fir_modelled(scene):
        return None

    def realise(t):
        return realised_delay(t, rts.f_s_hz, rts.fractional_delay, rts.fractional_delay_step_s)
    base = requested_delay(scene, np.asarray(ranges, float))  # (P,)
    air = float(np.mean(mean_air_delay(setup)))
    d = np.asarray(deltas, float)
    g_i = fir_bin_gain(scene, realise(base + base_offsets[0]), base + air)  # (P,)
    if continuous:
        j_delay = realise(base + base_offsets[1])[None, :] + d[:, None]  # (S, P)
    else:
        j_delay = realise(base[None, :] + base_offsets[1] + d[:, None])
    g_j = fir_bin_gain(scene, j_delay.ravel(), np.broadcast_to(base + air, j_delay.shape).ravel())
    return np.angle(g_j.reshape(j_delay.shape) / g_i[None, :])
