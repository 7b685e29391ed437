"""Tests of ``rtsgeom.calibration.fir``: closed forms and invariants on grids of inputs."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import make_scene


def _fir_scene(taps, model):
    def mutate(doc):
        doc["radar"].pop("snr_db", None)
        doc["rts"]["fractional_delay_taps"] = taps
        doc["rts"]["fractional_delay_filter"] = model
    return make_scene(mutate)



@pytest.mark.parametrize("taps", [5, 9])
def test_fir_effect_predicts_the_coherence_shift_in_picoseconds(taps):
    """``fir_effect``'s predicted shift (ps) of the coherence point, turned into the phase it
    adds to channel J relative to I (360 f_if shift), explains the phase measured on the
    phasor model with the filter against without it at fractional delay settings across a
    period: the least-squares gain measured / predicted is 1 within 30 % (first order in
    the filter's phase ripple), and a short filter shifts the point measurably."""
    from rtsgeom.calibration.fir import fir_effect
    from rtsgeom.calibration.probes import (
        if_phase_slope_hz,
        probe_ranges,
        probe_total_delay,
    )
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.scene import TargetConfig
    from rtsgeom.synthesis.model import ChannelModel
    ideal = build_setup(_fir_scene(taps, "ideal"))
    fir = build_setup(_fir_scene(taps, "windowed-sinc"))
    paths = exact_paths(ideal)
    ranges = probe_ranges(ideal, 2)
    f_if = if_phase_slope_hz(fir.scene, probe_total_delay(fir, ranges))
    measured, predicted = [], []
    for d in (0.1e-9, 0.37e-9, 0.63e-9, 0.81e-9):
        z = 0j
        for r in ranges:
            m0 = ChannelModel.build(ideal, paths, (0, 1), TargetConfig(float(r)), (0.0, d))
            m1 = ChannelModel.build(fir, paths, (0, 1), TargetConfig(float(r)), (0.0, d))
            z += np.exp(1j * (m1.pair_phase([0.1]) - m0.pair_phase([0.1])))
        measured.append(np.degrees(np.angle(z)))
        predicted.append(fir_effect(fir, d)["predicted_shift_ps"] * 1e-12 * 360 * f_if)
    m, p = np.array(measured), np.array(predicted)
    assert np.max(np.abs(p)) > 0.1  # deg: 5 taps ~5 deg, 9 taps ~0.15 deg
    gain = float(np.sum(m * p) / np.sum(p * p))
    assert 0.7 < gain < 1.3


@pytest.mark.parametrize("taps", [9, 11, 17])
def test_fir_effect_reports_its_filter_and_a_small_passband_ripple(taps):
    """``fir_effect`` names the filter it evaluated ("none" without a fractional delay, where
    nothing ripples) and a windowed-sinc FIR's gain ripple along the chirp's IF sweep: a
    passband ripple, positive and below 1 dB from 9 taps on, that a twice as long filter does not increase."""
    from rtsgeom.calibration.fir import fir_effect
    from rtsgeom.geometry import build_setup
    fir = fir_effect(build_setup(_fir_scene(taps, "windowed-sinc")), 0.37e-9)
    assert fir["model"] == "windowed-sinc"
    assert 0.0 < fir["gain_ripple_db"] < 1.0 and 0.0 < fir["phase_ripple_deg"] < 10.0
    longer = fir_effect(build_setup(_fir_scene(2 * taps + 1, "windowed-sinc")), 0.37e-9)
    assert longer["gain_ripple_db"] <= fir["gain_ripple_db"] * 1.05

    def off(doc):
        doc["rts"].update(fractional_delay=False, calibration_step_ps=250.0)
    none = fir_effect(build_setup(make_scene(off)), 0.37e-9)
    assert none == {"model": "none", "gain_ripple_db": 0.0, "phase_ripple_deg": 0.0,
                    "predicted_shift_ps": 0.0}


@pytest.mark.parametrize("continuous", [False, True])
def test_fir_sweep_phase_is_j_s_bin_gain_over_i_s_at_the_realised_settings(continuous):
    """``fir_sweep_phase``: per step and probe the angle of J's FIR bin gain (its base offset
    plus the step, realised as a whole or with the step unrounded) over I's (its own base
    offset, realised), each from ``fir_bin_gain`` at the probe's total delay; None for an
    ideal delay. Base offsets of both signs, neither zero, so that their roles show."""
    from rtsgeom.calibration.fir import fir_bin_gain, fir_sweep_phase
    from rtsgeom.calibration.probes import mean_air_delay, probe_ranges
    from rtsgeom.geometry import build_setup
    from rtsgeom.rts.channels import requested_delay
    from rtsgeom.rts.fir import realised_delay
    setup = build_setup(_fir_scene(5, "windowed-sinc"))
    scene, rts = setup.scene, setup.scene.rts
    ranges = probe_ranges(setup, 2)
    deltas = np.array([-0.13e-9, 0.0, 0.041e-9, 0.29e-9])
    offs = (0.07e-9, -0.23e-9)

    def realise(t):
        return realised_delay(t, rts.f_s_hz, rts.fractional_delay, rts.fractional_delay_step_s)
    base = requested_delay(scene, ranges)
    total = base + float(np.mean(mean_air_delay(setup)))
    got = fir_sweep_phase(setup, ranges, deltas, offs, continuous)
    assert got.shape == (deltas.size, ranges.size)
    g_i = fir_bin_gain(scene, realise(base + offs[0]), total)
    for s, d in enumerate(deltas):
        j = realise(base + offs[1]) + d if continuous else realise(base + offs[1] + d)
        np.testing.assert_allclose(got[s], np.angle(fir_bin_gain(scene, j, total) / g_i),
                                   rtol=0, atol=1e-12)
    assert np.ptp(got) > 1e-4  # the FIR's phase moves with the setting
    assert fir_sweep_phase(build_setup(_fir_scene(5, "ideal")), ranges, deltas, offs) is None
