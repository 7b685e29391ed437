"""The tolerance model's tables: each channel's spectrum at the target's candidate range bins
over its RTS delay (:func:`response_table`), precomputed once on the nominal setup so that a
draw is a few lookups; the first-order slide of an echo along the range window
(:func:`slide`); the studies' reference target (:func:`reference_target`).

``table[q, D, k, v]``: channel q's spectrum (``radar.phasors.bin_response``, through the same
``rts.channel_echoes`` as the ADC-cube chain: realised (quantised) delays, the fractional-delay
FIR when modelled) at candidate range bin k (the set range's bin in the middle) with its RTS
delay offset by D steps of the delay resolution.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ...calibration.probes import probe_ranges
from ...geometry import Setup
from ...radar.phasors import bin_response
from ...radar.processing import tdm_compensate
from ...rts.channels import KIND_DIRECT, RtsProgram, channel_echoes, requested_delay
from ...rts.fir import fir_modelled, fir_taps
from ...scene import TargetConfig

__all__ = ["response_table", "reference_target", "slide", "MAX_SLIDE", "readonly"]

_TABLE_BYTES = 64 * 2 ** 20  # peak of one block of response_table's temporaries


def response_table(setup: Setup, paths, channel: int, target: TargetConfig, resolution_s: float,
                   steps: np.ndarray, half_bins: int = 2) -> np.ndarray:
    """Channel ``channel``'s TDM-compensated spectrum (unit programme amplitude) at the
    target's candidate range bins with its RTS delay offset by ``steps`` (D,) times
    ``resolution_s``: (D, 2 half_bins + 1, V). The programme goes through
    ``rts.channel_echoes`` (what the ADC-cube chain synthesizes) and
    ``radar.phasors.bin_response``, in blocks of bounded memory."""
    scene, radar, rut = setup.scene, setup.scene.radar, setup.rut
    steps = np.asarray(steps, int)
    # the cable ghosts land bins away and are dropped: not formed at all (the direct echoes
    # do not depend on the return losses; a fifth of the table's time was their copies); the
    # fractional-delay FIR not formed along the chirp (an ideal delay for channel_echoes) but
    # as its taps' whole-sample copies (rts.fir_taps): bin_response then sums a few dozen
    # tones per geometry instead of every echo's N samples (a design's tables 74 -> 15 ms)
    fes = tuple(dataclasses.replace(f, return_loss_fe_db=None) for f in scene.rts.front_ends)
    setup = dataclasses.replace(setup, scene=dataclasses.replace(
        scene, rts=dataclasses.replace(scene.rts, front_ends=fes,
                                       fractional_delay_filter="ideal")))
    tau = float(requested_delay(scene, target.range_m))
    r0 = int(np.round(target.range_m / radar.range_resolution_m))
    rbins = np.arange(r0 - half_bins, r0 + half_bins + 1) % radar.samples_per_chirp
    dbin = np.full(rbins.size, radar.chirps_per_tx // 2)  # velocity 0
    # memory per delay step: per echo (one per path combination of the two legs) the
    # fast-time tones and their FIR gain, (N,) each per element; or with the taps (T,)
    # weights and the (V K) sums, plus the tones at the whole-sample delays the block spans
    # (res / t_s of them per step, (N,) each, three arrays)
    per_step = len(channel_echoes(setup, paths, RtsProgram.build(
        [0], [channel], [tau], [0.0], [1.0])))
    n_s, n_taps = radar.samples_per_chirp, scene.rts.fractional_delay_taps
    row = (per_step * 16 * rut.num_virtual * n_s * 4 if not fir_modelled(scene) else
           per_step * 16 * (2 * n_taps + 4 * rut.num_virtual * rbins.size)
           + 48 * n_s * resolution_s * scene.rts.f_s_hz)
    block = max(1, int(_TABLE_BYTES // row))
    out = np.empty((steps.size, rbins.size, rut.num_virtual), complex)
    for b in range(0, steps.size, block):
        k = steps[b:b + block]
        prog = RtsProgram.build(np.arange(k.size), np.full(k.size, channel),
                                tau + k * resolution_s, np.zeros(k.size), np.ones(k.size))
        ech = channel_echoes(setup, paths, prog)
        ech = ech.select(ech.kind == KIND_DIRECT)  # (none other: see above)
        # (what channel_echoes forms as fast_gain: rts.fir_if_gain of the same delays)
        fir = fir_taps(scene, ech.tau_if_s, ech.tau_if_s + ech.tau_air_s.mean(axis=1))
        resp = bin_response(ech, radar, rut, rbins, dbin, fir)  # (K, E, V)
        acc = np.zeros((k.size,) + resp.shape[::2], complex)  # each target's echoes summed
        np.add.at(acc, ech.target, np.swapaxes(resp, 0, 1))  # (a one-hot einsum was 15 %)
        out[b:b + block] = acc
    return tdm_compensate(out, 0.0, rut, radar)


def readonly(a: np.ndarray) -> np.ndarray:
    """``a`` made read-only in place (an array this module made and shares with no one)."""
    a.flags.writeable = False
    return a


def reference_target(nominal: Setup, range_m: float | None = None) -> TargetConfig:
    """The tolerance studies' reference target: at the centre of the range bin nearest
    ``range_m`` (default: the calibration's first probe range), velocity 0, boresight."""
    bin_m = nominal.scene.radar.range_resolution_m
    r0 = float(probe_ranges(nominal, 1)[0]) if range_m is None else float(range_m)
    return TargetConfig(max(round(r0 / bin_m), 1) * bin_m)


#: Largest |d ln|x| / d tau * shift| the first-order slide applies (see :func:`slide`).
MAX_SLIDE = 0.5


def slide(log_slope, shift_s):
    """exp(d ln|x|/d tau * shift): the first-order change of a spectrum's magnitude as the
    draw's air delay slides the echo along the range window. The log slope is unbounded at the
    window's spectral nulls (a Hann window has them two bins from an echo at a bin centre), where
    exp() of it blew an empty bin up into the strongest one (a phantom detection two bins off);
    the exponent is limited to +-MAX_SLIDE (and NaN at an exact null to 0), which leaves every
    regular bin bit-identical (exponents ~1e-4) and keeps a null bin near null. (In place on
    one temporary: ``nan_to_num`` then ``clip`` made five passes, 4 % of a draw.)"""
    x = np.asarray(log_slope * shift_s, float)
    np.clip(x, -MAX_SLIDE, MAX_SLIDE, out=x)  # +-inf to the bounds; NaN stays NaN ...
    x[np.isnan(x)] = 0.0  # ... and becomes 0
    return np.exp(x, out=x)
