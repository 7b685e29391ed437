"""Frames per step of the 2-D pair calibration (its sweep through the full chain): the fitted
point's scatter estimated from the measured sweep itself (``fit.fit_scatter``) against the
scatter of real refits, over a grid of noise levels and curve shapes, the one sizing rule
(``steps.frames_for``) shared with the arc pair, and (slow) the frames growing as
the SNR falls while the pair stays at its coherence point."""

from __future__ import annotations

import numpy as np
import pytest

PERIOD = 1.0e-9
ODD = [True, True]  # both columns cross zero at the point


def _curves(d, true_s, amp_rad):
    """Two crossing columns as the elevation pair gives them (odd about the coherence
    point, with a second harmonic)."""
    th = 2 * np.pi * (d - true_s) / PERIOD
    return np.stack([amp_rad * np.sin(th), 0.7 * amp_rad * np.sin(th) + 0.2 * amp_rad
                     * np.sin(2 * th)], axis=1)


@pytest.mark.parametrize("sigma_rad", [2e-5, 1e-4, 4e-4])
@pytest.mark.parametrize("amp_rad, true_ps", [(np.radians(0.03), 29.0),
                                              (np.radians(0.1), -140.0)])
def test_fit_scatter_from_one_sweep_is_the_refits_scatter(sigma_rad, amp_rad, true_ps):
    """From ONE noisy sweep (its residual about the fit, refitted on drawn sweeps) the
    estimate is within 35 % of the std of the minima of 200 independent noisy sweeps
    (32 draws: ~13 % statistical), and the frames it asks for grow as sigma^2."""
    from rtsgeom.calibration.steps import TARGET_BIAS_PS, fine_frames
    from rtsgeom.calibration.fit import CentreFit, fit_centre, fit_scatter
    near = true_ps * 1e-12 + 30e-12
    d = near + np.arange(-25, 26) * 10e-12
    clean = _curves(d, true_ps * 1e-12, amp_rad)
    rng = np.random.default_rng(7)

    def fit(e):
        return fit_centre(d, e, PERIOD, near, CentreFit(2, 125e-12, odd=ODD), return_fit=True)
    truth = np.std([fit(clean + sigma_rad * rng.standard_normal(clean.shape))[0]
                    for _ in range(200)])
    one = clean + sigma_rad * rng.standard_normal(clean.shape)
    _, fitted = fit(one)
    assert fitted.shape == one.shape and np.all(np.isfinite(fitted))
    scatter, noise = fit_scatter(fit, fitted, one, 2, 3, (0, 1), odd=ODD)
    assert abs(scatter / truth - 1) < 0.35, (scatter, truth)
    assert abs(noise / sigma_rad - 1) < 0.25
    want = (2 * truth / (TARGET_BIAS_PS * 1e-12)) ** 2
    assert 0.4 * want <= fine_frames(scatter) <= 2.0 * want + 1


def test_fit_scatter_is_zero_without_noise_and_unknown_without_enough_steps():
    """No noise: no scatter. Too few steps for a residual (the curves pass through them): not
    "no noise" but unknown (NaN), which the sweep answers with a second, independent one."""
    from rtsgeom.calibration.fit import CentreFit, fit_centre, fit_scatter
    d = np.arange(-25, 26) * 10e-12
    clean = _curves(d, 0.0, np.radians(0.05))

    def fit(e):
        return fit_centre(d, e, PERIOD, 0.0, CentreFit(2, 125e-12, odd=ODD), return_fit=True)
    _, fitted = fit(clean)
    assert fit_scatter(fit, fitted, clean, 2, 0, (0, 1), odd=ODD)[0] < 1e-15
    few = np.full_like(clean, np.nan)
    few[:4] = clean[:4]
    _, f_few = fit(few)
    assert np.all(np.isnan(f_few))
    assert all(np.isnan(fit_scatter(fit, f_few, few, 2, 0, (0, 1), odd=ODD)))


@pytest.mark.parametrize("sigma_rad", [5e-5, 3e-4])
def test_coarse_rts_steps_measure_the_noise_from_a_repeated_sweep(sigma_rad):
    """100 ps RTS steps leave 5 fine steps, too few for a residual beside 2 harmonics a column:
    it is no measure of the noise (the frames were sized to 1, the scatter reported 0).
    With a second, independent sweep the noise is that of their difference: within 40 % of
    sigma on 5 steps x 2 columns, and the scatter grows with it."""
    from rtsgeom.calibration.fit import CentreFit, fit_centre, fit_scatter
    d = np.arange(-2, 3) * 100e-12
    clean = _curves(d, 20e-12, np.radians(0.05))
    rng = np.random.default_rng(11)
    one = clean + sigma_rad * rng.standard_normal(clean.shape)
    two = clean + sigma_rad * rng.standard_normal(clean.shape)

    def fit(e):
        return fit_centre(d, e, PERIOD, 0.0, CentreFit(2, 250e-12, odd=ODD), return_fit=True)
    _, fitted = fit(one)
    # 4 coefficients a column and the shared point on 5 steps: less than one degree of
    # freedom a column, no residual to measure the noise by
    assert all(np.isnan(fit_scatter(fit, fitted, one, 2, 0, (0, 1), odd=ODD)))
    scatter, noise = fit_scatter(fit, fitted, one, 2, 0, (0, 1), repeat=two, odd=ODD)
    assert abs(noise / sigma_rad - 1) < 0.4 and scatter > 0


@pytest.mark.parametrize("scatter, target, k", [(0.0, 1.0, 1), (1.0, 1.0, 1), (1.01, 1.0, 2),
                                                (2.5, 1.0, 7), (1e9, 1.0, 1 << 20)])
def test_frames_for_is_the_square_of_the_scatter_over_the_target(scatter, target, k):
    """The one sizing rule of both sweeps and both pairs (coarse: probe-angle noise over
    COARSE_NOISE_DEG; fine: 2 sigma of the minimum over TARGET_BIAS_PS)."""
    from rtsgeom.calibration.steps import (COARSE_NOISE_DEG, TARGET_BIAS_PS, coarse_frames,
                                           fine_frames, frames_for)
    assert frames_for(scatter, target) == k
    assert coarse_frames(scatter * COARSE_NOISE_DEG) == k
    assert fine_frames(scatter * TARGET_BIAS_PS * 1e-12 / 2) == k


@pytest.mark.slow
@pytest.mark.heavy
@pytest.mark.parametrize("snr_drop_db", [0.0, 10.0])
def test_elevation_pair_frames_grow_as_snr_falls_and_it_stays_at_its_point(snr_drop_db):
    """sphere4's elevation pair (0, 1) at its SNR and 10 dB below: fitted along the pair's
    line, one frame a step scatters the fitted point by ~1.2 ps at both (its residual is
    mostly the curves' misfit, not noise; fitted on the zero crossings across the line it was
    ~8 and ~25 ps), and the frames the rule chooses bring it within 5 ps of the continuous
    coherence point."""
    from rtsgeom.calibration.probes import probe_front_ends
    from rtsgeom.calibration.pair import calibrate_pair, pair_coherence
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.scene import load_scene
    scene = load_scene("scenes/sphere4.toml")
    scene = scene.evolve(radar=scene.radar.evolve(snr_db=scene.radar.snr_db - snr_drop_db))
    setup = build_setup(scene)
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, scene.seed)
    got = calibrate_pair(setup, paths, (0, 1), probe, seed=scene.seed).to_dict()
    point = pair_coherence(setup, paths, (0, 1), probe, near_s=got["delta_tau_s"]).continuous_s
    assert abs(got["delta_tau_s"] - point) < 5e-12
    scatter = got["one_frame_scatter_ps"]
    assert 0.3 < scatter < 4.0 * 10 ** (snr_drop_db / 20)
    assert abs(got["frames_per_step"] - max(1, np.ceil((2 * scatter / 2.0) ** 2))) <= 1


@pytest.mark.slow
@pytest.mark.heavy
# 30 dB below, front end 3 alone falls under the CFAR threshold at the probe range (it warns;
# the pair calibrated here is (0, 1))
@pytest.mark.filterwarnings("ignore:front end\\(s\\) \\[3\\] not detected alone")
def test_elevation_pair_30_db_below_averages_its_coarse_sweep_too():
    """30 dB below sphere4's SNR one frame's probe noise (~0.19 deg) is beyond
    COARSE_NOISE_DEG: the coarse sweep is measured again with the frames that bring it
    below (coarse_frames, the arc pair's rule), the fine sweep with more than one, and the
    pair still lands within 5 ps of its coherence point."""
    from rtsgeom.calibration.probes import probe_front_ends
    from rtsgeom.calibration.steps import COARSE_NOISE_DEG
    from rtsgeom.calibration.pair import calibrate_pair, pair_coherence
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.scene import load_scene
    scene = load_scene("scenes/sphere4.toml")
    scene = scene.evolve(radar=scene.radar.evolve(snr_db=scene.radar.snr_db - 30.0))
    setup = build_setup(scene)
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, scene.seed)
    got = calibrate_pair(setup, paths, (0, 1), probe, seed=scene.seed).to_dict()
    assert got["frame_noise_deg"] > COARSE_NOISE_DEG
    assert got["coarse_frames_per_step"] == int(np.ceil((got["frame_noise_deg"]
                                                         / COARSE_NOISE_DEG) ** 2)) > 1
    assert got["frames_per_step"] > 1
    point = pair_coherence(setup, paths, (0, 1), probe, near_s=got["delta_tau_s"]).continuous_s
    assert abs(got["delta_tau_s"] - point) < 5e-12
