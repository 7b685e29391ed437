"""Calibration under the link budget's thermal noise.

With ``[radar.link]`` and no ``snr_db`` the noise is k T F f_adc (+ the RTS channels' and the
ADC's): the calibration's phasor sweep takes that noise (``rtsgeom.radar.link.relative_noise_power``),
so the frames it averages per step follow from the actual SNR, and the chosen delay stays
within 2 ps of the noiseless one on a low-SNR setup.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import make_scene
from radar.test_link import _setup_paths
from scipy.constants import c

from rtsgeom.calibration.pair import calibrate_pair
from rtsgeom.calibration.probes import probe_front_ends
from rtsgeom.calibration.steps import TARGET_BIAS_PS
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.radar import budget
from rtsgeom.radar import link as lk
from rtsgeom.rts.channels import program_nearest, setup_echoes


def _linked(nf_db=None, **link):
    def mut(d):
        d["radar"].pop("snr_db", None)
        if nf_db is not None:
            d["radar"]["link"] = dict(link, noise_figure_db=nf_db)
    return make_scene(mut)


@pytest.mark.parametrize("nf_db,fs_dbm,dist_m", [(12.0, -25.0, 5.0), (30.0, -25.0, 40.0),
                                                 (15.0, -60.0, 2.0)])
def test_relative_noise_power_is_the_budgets_noise(nf_db, fs_dbm, dist_m):
    """An echo of relative amplitude a: |a|^2 / relative_noise_power(...) times the FFT gain
    is the budget's post-FFT SNR (thermal, and quantisation at the echo's IF response; the
    low full scale makes quantisation count)."""
    scene = _linked(nf_db, adc_full_scale_dbm=fs_dbm)
    setup = build_setup(scene)
    tau, a = 2 * dist_m / c, 3e-4
    raw = setup_echoes(setup, _setup_paths(setup, tau, a))
    b = budget.link_budget(scene, raw, program_nearest(scene.evolve(targets=()), setup), linked=False,
                       predict=True)
    n_rel = lk.relative_noise_power(scene, 0.0, scene.radar.slope_hz_per_s * tau)
    assert b.setup_echoes[0]["snr_after_fft_db"] == pytest.approx(
        10 * np.log10(a * a / n_rel) + b.fft_gain_db, abs=1e-9)


def test_relative_noise_power_counts_the_rts_channels_noise():
    """The channels' re-radiated noise is linear in the programmed rows' squared amplitudes."""
    scene = _linked(12.0)
    setup = build_setup(scene)
    program = program_nearest(scene, setup)
    rl = lk.radar_link(scene.radar)
    g = rl.tx_power_w * rl.tx_gain * rl.rx_gain
    p = float(np.sum(np.abs(program.amplitude) ** 2))
    d = lk.relative_noise_power(scene, p, 1e6) - lk.relative_noise_power(scene, 0.0, 1e6)
    assert d == pytest.approx(lk.channel_noise_w(scene, program, rl) / g, rel=1e-12)


@pytest.mark.slow
def test_linked_calibration_frames_follow_the_link_noise_and_hold_2_ps():
    """No snr_db, NF 35/40/45 dB (one-frame scatter of the fitted point 1.5-5 ps, so 3-25
    frames per step): the scatter grows as the noise amplitude (x 10^(5/20) for +5 dB, same
    draws; the fit is linear there; drawn at one frame it compressed at large scatters, so
    it is drawn at the coarse sweep's frames, see below),
    the frames per step as its square, and with them the chosen delay lands within 2 ps of
    the noiseless sweep's (same probe, 3 noise seeds each). Before, a linked scene's sweep was
    noiseless (1 frame, scatter 0) whatever its SNR."""
    quiet = build_setup(_linked(None))
    probe = probe_front_ends(quiet, exact_paths(quiet), 1)
    ref = calibrate_pair(quiet, exact_paths(quiet), (0, 1), probe, seed=1)
    scatter = {}
    for nf in (35.0, 40.0, 45.0):
        setup = build_setup(_linked(nf))
        paths = exact_paths(setup)
        for seed in range(3):
            cal = calibrate_pair(setup, paths, (0, 1), probe, seed=seed)
            assert cal.frames_per_step > 1
            assert cal.frames_per_step == int(np.ceil((2 * cal.one_frame_scatter_ps
                                                       / TARGET_BIAS_PS) ** 2))
            assert abs(cal.delta_tau_s - ref.delta_tau_s) <= 2e-12 + 1e-15
            scatter.setdefault(nf, []).append(cal.one_frame_scatter_ps)
    ratio = np.array(scatter[40.0]) / np.array(scatter[35.0])
    np.testing.assert_allclose(ratio, 10 ** (5 / 20), rtol=0.15)


def _noisy_calibration(nf, seed, probe):
    setup = build_setup(_linked(nf))
    return calibrate_pair(setup, exact_paths(setup), (0, 1), probe, seed=seed)


@pytest.fixture(scope="module")
def quiet_reference():
    quiet = build_setup(_linked(None))
    probe = probe_front_ends(quiet, exact_paths(quiet), 1)
    return probe, calibrate_pair(quiet, exact_paths(quiet), (0, 1), probe, seed=1)


def test_predicted_angle_noise_follows_the_noise_figure(quiet_reference):
    """The probe-angle noise the coarse sweep's frames are sized from grows as the noise
    amplitude (x 10^(5/20) per 5 dB, in the linear regime) and the coarse frames as its
    square; NF 12 dB keeps one frame per coarse step (the path before), NF 50 dB averages
    ~100 (one frame there: 1 deg of noise per step, a wrong minimum on 3 of 3 seeds)."""
    from rtsgeom.calibration.phasor import PairChannels, phasor_sweep
    from rtsgeom.calibration.probes import probe_angles, probe_ranges
    from rtsgeom.calibration.steps import (
        COARSE_NOISE_DEG,
        coarse_frames,
        predicted_angle_noise,
    )
    from rtsgeom.paths import nominal_model
    from rtsgeom.scene import TargetConfig
    probe, _ = quiet_reference
    noise = {}
    for nf in (12.0, 40.0, 45.0, 50.0):
        s = build_setup(_linked(nf))
        p = exact_paths(s)
        sweep = phasor_sweep(s, p, nominal_model(s, p),
                             PairChannels((0, 1), (0.0, 0.0), probe.gain_correction),
                             [TargetConfig(float(r)) for r in probe_ranges(s, 2)],
                             np.asarray(probe_angles(*probe.angle_rad[[0, 1]])),
                             np.arange(-0.5e-9, 1.0e-9 + 1e-12, 25e-12))
        noise[nf] = predicted_angle_noise(sweep, 0)
    assert coarse_frames(noise[12.0]) == 1
    assert noise[12.0] < COARSE_NOISE_DEG
    np.testing.assert_allclose([noise[45.0] / noise[40.0], noise[50.0] / noise[45.0]],
                               10 ** (5 / 20), rtol=0.12)
    k50 = coarse_frames(noise[50.0])
    assert k50 == int(np.ceil((noise[50.0] / COARSE_NOISE_DEG) ** 2)) and k50 > 30


@pytest.mark.parametrize("seed", [0, 1])
def test_linked_calibration_at_the_maximum_noise_figure(seed, quiet_reference):
    """NF 50 dB (the field's maximum): the coarse sweep averages the frames the predicted
    noise asks for, the fine frames follow from the fit's scatter drawn where it is linear,
    and the chosen delay lands within 2 ps of the noiseless one (before: 48 ps and a period,
    998 ps, off on these seeds, with 410 and 887 frames from a compressed 20-30 ps scatter)."""
    probe, ref = quiet_reference
    cal = _noisy_calibration(50.0, seed, probe)
    assert cal.coarse_frames_per_step > 30
    assert cal.frame_noise_deg > 0.5
    # the fitted centre's scatter, 7-9 ps (the probes' RMS minimum fitted before: 60-120 ps)
    assert cal.one_frame_scatter_ps > 3.0
    assert cal.frames_per_step == int(np.ceil((2 * cal.one_frame_scatter_ps
                                               / TARGET_BIAS_PS) ** 2))
    assert abs(cal.delta_tau_s - ref.delta_tau_s) <= 2e-12 + 1e-15


@pytest.mark.slow
def test_linked_calibration_noise_grid(quiet_reference):
    """NF 45 / 50 dB x 2 seeds (the low noise figures: the tests above): every chosen delay
    within 2 ps of the noiseless one, and the one-frame scatter of the fitted delay (same
    draws) x 10^(5/20) from 45 to 50 dB (it compressed there before: 20-30 ps at 50 dB, under
    45 dB's). The full grid (5 noise figures x 5 seeds): python -m
    benchmarks.calibration_noise."""
    probe, ref = quiet_reference
    scatter = {}
    for nf in (45.0, 50.0):
        for seed in range(2):
            cal = _noisy_calibration(nf, seed, probe)
            assert abs(cal.delta_tau_s - ref.delta_tau_s) <= 2e-12 + 1e-15, (nf, seed)
            scatter.setdefault(nf, []).append(cal.one_frame_scatter_ps)
    ratio = np.array(scatter[50.0]) / np.array(scatter[45.0])
    np.testing.assert_allclose(ratio, 10 ** (5 / 20), rtol=0.15)
