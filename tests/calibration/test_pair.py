"""Tests of ``rtsgeom.calibration.pair``: closed forms and invariants on grids of inputs."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import make_scene, small_noiseless

from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths


@pytest.mark.parametrize("fe, dr_mm", [(1, -0.097), (0, -0.3)])
def test_nd_pair_calibration_lands_on_the_coherence_point(fe, dr_mm):
    """The N-channel pair sweep (``ncal.calibrate_pair_nd``, full ADC-cube chain at each
    step, a parabola through the points around the minimum) lands within 3 ps of the
    phasor model's coherence point for a radial offset that puts the point half a coarse
    step (100 ps) off the sweep grid, on either front end; its period is 1/(f_rts + S t_mid
    - S tau) as the pair calibration's."""
    from rtsgeom.calibration.pair import calibrate_pair, pair_coherence
    from rtsgeom.calibration.probes import probe_angles, probe_front_ends
    from rtsgeom.geometry.farfield import two_way_lengths
    setup = build_setup(small_noiseless(
        lambda d: d["rts"]["front_ends"][fe].update(radial_offset_mm=dr_mm)))
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, 1)
    got = calibrate_pair(setup, paths, (0, 1), probe, seed=1, span_s=(-0.3e-9, 0.3e-9),
                         step_s=100e-12).to_dict()
    point = pair_coherence(setup, paths, (0, 1),
                           alphas=probe_angles(*probe.angle_rad[[0, 1]])).continuous_s
    period = got["period_s"]
    dist = (got["delta_tau_s"] - point + period / 2) % period - period / 2
    assert abs(dist) < 3e-12
    assert got["residual_error_deg"] < 0.05
    # the range offset the pair's echoes get: half the path of J's delay plus its air-path
    # excess over I (each front end's two-way line-of-sight length, mean over the elements)
    air = two_way_lengths(setup.rut, setup.fe.rx, setup.fe.tx).mean(axis=1)
    assert got["range_offset_m"] == pytest.approx(
        0.5 * (299792458.0 * got["delta_tau_s"] + air[1] - air[0]), abs=1e-9)


@pytest.mark.parametrize("snr_db", [-10.0, 0.0])
def test_calibration_sweep_noise_is_the_adc_chains_within_a_factor_of_a_few(snr_db):
    """The phasor sweep adds receiver noise of the scene's SNR to each step's spectra (what
    sizes the frames per step and ``one_frame_scatter_ps``); the full ADC-cube chain adds it
    to the samples. Near the coherence point both give the probes' angles a noise variance
    (noisy minus noiseless squared error, 6 seeds x 2 steps x 2 probes, each seed its own
    noise realisation in both); they agree within a
    factor 5 (measured: the phasor model's is 1.4-1.5 times the chain's at SNR -10 and 0 dB),
    where a noise level off by the windows' sum w^2 (thousands) would not."""
    from rtsgeom.calibration.pair import calibrate_pair
    from rtsgeom.calibration.probes import probe_front_ends

    def scene(snr):
        def m(doc):
            doc["radar"].pop("snr_db", None)
            if snr is not None:
                doc["radar"]["snr_db"] = snr
            doc["radar"]["chirps_per_tx"] = 32
            for fe in doc["rts"]["front_ends"]:
                fe.pop("return_loss_fe_db", None)
                fe.pop("return_loss_be_db", None)
        return build_setup(make_scene(m))
    clean = scene(None)
    paths = exact_paths(clean)
    probe = probe_front_ends(clean, paths, 1)
    kw = dict(span_s=(0.0, 25e-12), step_s=25e-12, frames=1)  # two steps at coherence
    e0 = {fc: calibrate_pair(clean, paths, (0, 1), probe, seed=1, full_chain=fc,
                             **kw).sweep_error_deg for fc in (False, True)}
    noisy = scene(snr_db)
    var = {}
    for fc in (False, True):
        d = [calibrate_pair(noisy, paths, (0, 1), probe, seed=s, full_chain=fc,
                            **kw).sweep_error_deg ** 2 - e0[fc] ** 2 for s in range(6)]
        var[fc] = float(np.mean(d))
        # each seed its own noise: no two seeds share a realisation
        assert len({np.asarray(x).round(12).tobytes() for x in d}) == len(d)
    assert var[True] > 0 and var[False] > 0
    assert 0.2 < var[False] / var[True] < 5.0


@pytest.mark.parametrize("dr_mm", [0.0, -0.2])
def test_pair_calibration_places_its_probes_over_the_fine_window_and_reports_its_frames(dr_mm):
    """Step 2 of ``calibrate_pair``: the probes' ranges are where ``sweep.place_probes`` puts
    them for the window +-period/4 around the coarse minimum (the fine sweep's centre), not
    for one delay of it; a noiseless sweep averages one frame per step, ``frames`` sets it."""
    from rtsgeom.calibration.pair import calibrate_pair
    from rtsgeom.calibration.phasor import PairChannels, place_probes
    from rtsgeom.calibration.probes import probe_angles, probe_front_ends, probe_ranges
    from rtsgeom.paths import nominal_model
    setup = build_setup(small_noiseless(
        lambda d: d["rts"]["front_ends"][1].update(radial_offset_mm=dr_mm)))
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, 0)
    span = (-0.6e-9, 0.6e-9)
    cal = calibrate_pair(setup, paths, (0, 1), probe, span_s=span)
    assert cal.frames_per_step == 1
    near = cal.refine_delta_tau_s[cal.refine_delta_tau_s.size // 2]
    half, step = cal.period_s / 4, setup.scene.rts.calibration_step_s
    alphas = np.asarray(probe_angles(probe.angle_rad[0], probe.angle_rad[1]))
    expect = place_probes(setup, paths, nominal_model(setup, paths),
                          PairChannels((0, 1), (0.0, 0.0), tuple(probe.gain_correction[[0, 1]])),
                          probe_ranges(setup, 2), alphas, near + np.arange(-half, half + 1e-15, step))
    np.testing.assert_allclose(cal.probe_ranges_m, expect, rtol=1e-12)
    assert calibrate_pair(setup, paths, (0, 1), probe, span_s=span, frames=3).frames_per_step == 3


def test_calibrate_pair_sweep_refinement_and_probes(cal_setup, calibrated):
    """The sweep covers span/step, the refinement steps by step/5 down to the FIR's resolution
    around the best point (9 points per level), the probe angles are the pair's 1/4 and 3/4
    points, and the calibrated pair is coherent: residual below 0.05 deg with the gain error
    corrected by the probe."""
    from rtsgeom.calibration.probes import probe_angles
    setup, paths = cal_setup
    probe, cal = calibrated
    assert probe.gain_correction[0] == pytest.approx(10 ** (-3 / 20), rel=0.02)
    np.testing.assert_allclose(cal.sweep_delta_tau_s, np.arange(0, 1.2e-9 + 1e-10, 200e-12),
                               atol=1e-18)
    # the fine sweep (fitted with the criterion's periodic shape): 5 ps steps over a half
    # period around the coarse minimum, the chosen delay inside it
    fine = np.sort(cal.refine_delta_tau_s)
    assert np.allclose(np.diff(fine), 5e-12, rtol=1e-6)
    assert fine[-1] - fine[0] == pytest.approx(cal.period_s / 2, abs=10e-12)
    assert fine[0] <= cal.delta_tau_s <= fine[-1]
    want = np.degrees(probe_angles(*probe.angle_rad[[0, 1]]))
    np.testing.assert_allclose(cal.probe_angles_deg, want, rtol=1e-12)
    assert cal.residual_error_deg < 0.05
    assert np.isfinite(cal.sweep_error_deg).all()
