"""Arbitrary angle of arrival: synthesis modes and calibration."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.constants import c

from rtsgeom.calibration.pair import calibrate_pair
from rtsgeom.calibration.probes import probe_front_ends
from rtsgeom.analysis.linearity import linearity
from rtsgeom.synthesis.closed_form import array_factor, g_paper, ratio_array_factor, ratio_paper
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths

from conftest import far_field as ideal_far_field
from conftest import make_scene


def far_field(doc):
    doc["radar"].pop("snr_db", None)
    ideal_far_field(doc)
    doc["targets"] = []


def test_closed_form_ratios_are_positive_between_the_beams():
    th1, th2 = np.radians(3.4), np.radians(12.2)
    alpha = np.radians(np.linspace(4, 11.5, 9))
    assert np.all(ratio_paper(th1, th2, alpha) > 0)
    assert np.all(ratio_array_factor(th1, th2, alpha, 8) > 0)
    # as printed (without the minus sign) eq. (23) would be negative: A1 g1 + A2 g2 = 0
    assert np.all(g_paper(th1, alpha) / g_paper(th2, alpha) < 0)
    assert array_factor(0.0, 8) == 1.0
    assert abs(array_factor(2 / 8, 8)) < 1e-12  # first null at u = 2/N


@pytest.fixture(scope="module")
def far_setup():
    setup = build_setup(make_scene(far_field))
    paths = exact_paths(setup)
    return setup, paths, probe_front_ends(setup, paths)


@pytest.mark.slow
def test_modes_in_the_ideal_far_field(far_setup):
    setup, paths, probe = far_setup
    res = {m: linearity(setup, paths, (0, 1), m, probe, None, points=7) for m in
           ("array-factor", "paper", "exact")}
    assert res["array-factor"].max_abs_error_deg < 0.02  # exact in the far field
    assert res["exact"].max_abs_error_deg < 0.02
    # the paper's sinc is not the 8-element beam: exact only at the symmetric mid-point,
    # ~0.3 deg off in between
    assert 0.15 < res["paper"].max_abs_error_deg < 0.6
    assert abs(res["paper"].error_deg[3]) < 0.05


def test_array_factor_of_positions_and_weights():
    """The weighted array factor is the beamformer output for one plane wave: equal to
    |sum w e^{j 2 pi x u}| / sum w on symmetric arrays (the filled row's Dirichlet kernel
    when untapered), and repeated positions count as often as they occur."""
    u = np.linspace(-0.6, 0.6, 41)
    x = np.arange(8) * 0.5
    np.testing.assert_allclose(array_factor(u, positions_wl=x), array_factor(u, 8), atol=1e-12)
    w = np.hanning(10)[1:-1]
    direct = np.abs(np.exp(2j * np.pi * u[:, None] * (x - x.mean())) @ w) / w.sum()
    np.testing.assert_allclose(np.abs(array_factor(u, positions_wl=x, weights=w)), direct,
                               atol=1e-12)
    # a repeated element: the same as weight 2 on one copy
    xr = np.r_[x, x[3]]
    wr = np.r_[np.ones(8), 1.0]
    w2 = np.ones(8)
    w2[3] = 2.0
    np.testing.assert_allclose(array_factor(u, positions_wl=xr, weights=wr),
                               array_factor(u, positions_wl=x, weights=w2), atol=1e-12)


@pytest.fixture(scope="module")
def default_cal():
    setup = build_setup(make_scene())
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, 1)
    cal = calibrate_pair(setup, paths, (0, 1), probe, seed=1, span_s=(-0.5e-9, 1.5e-9))
    return setup, paths, probe, cal


@pytest.mark.slow
def test_calibration_sweep_period(default_cal):
    setup, _, _, cal = default_cal
    period = 1 / (setup.scene.rts.f_rts_hz + setup.scene.radar.bandwidth_hz / 2)
    t, e = cal.sweep_delta_tau_s, cal.sweep_error_deg
    step = t[1] - t[0]
    interior = np.arange(1, len(e) - 1)
    mins = interior[(e[interior] < e[interior - 1]) & (e[interior] <= e[interior + 1])]
    maxs = interior[(e[interior] > e[interior - 1]) & (e[interior] >= e[interior + 1])]
    deep = sorted(mins, key=lambda i: e[i])[:2]
    # minima one period apart; the second is pulled by up to ~2 steps because the delay also
    # moves channel J by c dtau / 2 = one range bin per period (the paper's range offset)
    assert abs(abs(t[deep[1]] - t[deep[0]]) - period) <= 1.5 * step
    # maxima are broad and noisy (one frame per step since the sweep's minimum is fitted):
    # the two highest at least half a period apart
    top = sorted(maxs, key=lambda i: -e[i])
    top = [top[0], next(i for i in top if abs(t[i] - t[top[0]]) > period / 2)]
    # the later one sits 1.4 range bins off: looser
    assert abs(abs(t[top[1]] - t[top[0]]) - period) <= 3 * step
    assert cal.residual_error_deg < 0.02
    assert abs(cal.range_offset_m) < 0.01


@pytest.mark.slow
def test_exact_linearity_after_calibration(default_cal):
    setup, paths, probe, cal = default_cal
    lin = linearity(setup, paths, (0, 1), "exact", probe, cal, points=9, seed=1)
    assert lin.max_abs_error_deg <= 0.02


@pytest.mark.slow
def test_radial_offset_shifts_calibrated_delay(default_cal):
    setup0, _, _, cal0 = default_cal
    dr = 0.5e-3

    def mutate(doc):
        doc["rts"]["front_ends"][1]["radial_offset_mm"] = dr * 1e3
    setup = build_setup(make_scene(mutate))
    paths = exact_paths(setup)
    cal = calibrate_pair(setup, paths, (0, 1), probe_front_ends(setup, paths, 1), seed=1)
    r = setup.scene.radar
    f_rts = setup.scene.rts.f_rts_hz
    period = 1 / (f_rts + r.bandwidth_hz / 2)
    predicted = -(r.f_c_hz + r.bandwidth_hz / 2) / (f_rts + r.bandwidth_hz / 2) * 2 * dr / c
    assert predicted == pytest.approx(-0.26e-9, abs=0.01e-9)
    shift = cal.delta_tau_s - cal0.delta_tau_s
    wrapped = (shift - predicted + period / 2) % period - period / 2
    assert abs(wrapped) <= setup.scene.rts.calibration_step_s  # measured: -259.0 ps


@pytest.mark.slow
def test_quarter_wave_radial_error_breaks_uncalibrated_synthesis(default_cal):
    _, _, _, cal0 = default_cal
    lam = build_setup(make_scene()).rut.wavelength_m

    def mutate(doc):
        doc["rts"]["front_ends"][1]["radial_offset_mm"] = lam / 4 * 1e3
    setup = build_setup(make_scene(mutate))
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, 1)
    bad = linearity(setup, paths, (0, 1), "exact", probe, None, points=5, seed=1)
    assert bad.max_abs_error_deg > 1.0  # destructive interference: the synthesis falls apart
    cal = calibrate_pair(setup, paths, (0, 1), probe, seed=1)
    good = linearity(setup, paths, (0, 1), "exact", probe, cal, points=5, seed=1)
    assert good.max_abs_error_deg < 0.05


def test_paper_g_is_accurate_near_zero():
    # the series -u/6 + u^3/240 replaces the cancelling closed form near u = 0
    for u in (1e-9, 1e-6, 1e-4, 2e-3):
        ref = 2 * np.cos(np.float128(u) / 2) / np.float128(u) - 4 * np.sin(np.float128(u) / 2) / np.float128(u) ** 2 \
            if u >= 1e-4 else -u / 6
        got = float(g_paper(np.arcsin(u), 0.0))
        assert got == pytest.approx(float(ref), rel=1e-6)


def test_closed_form_modes_refuse_angles_outside_the_geometric_span():
    from rtsgeom.pipeline.pair import pair_amplitudes
    from rtsgeom.errors import AngleUnreachable
    from rtsgeom.scene import TargetConfig
    setup = build_setup(make_scene())
    paths = exact_paths(setup)
    probes = np.radians([6.0, 10.0])
    t = TargetConfig(37.0, 0.0, 10.0, np.radians(12.5))  # inside the measured, outside 3.4..12.2
    for mode in ("paper", "array-factor"):
        with pytest.raises(AngleUnreachable, match="geometric"):
            pair_amplitudes(setup, paths, (0, 1), t, mode, probes)
    end = TargetConfig(37.0, 0.0, 10.0, setup.fe_azimuth_rad()[1])  # exactly at front end 1
    for mode in ("paper", "array-factor"):
        a_i, a_j, _ = pair_amplitudes(setup, paths, (0, 1), end, mode, probes)
        assert np.isfinite(a_i) and np.isfinite(a_j) and a_j > 1e3 * a_i
    a_i, a_j, _ = pair_amplitudes(setup, paths, (0, 1), t, "exact", probes)
    assert a_i > 0 and a_j > 0
