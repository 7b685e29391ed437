"""Calibration with a coarse RTS delay resolution (``rts.delay_resolution_s``: 1 to 250 ps).

The RTS rounds every delay it is given (``rts.realised_delay``), so the model of a coarse
RTS has a phase that is a staircase in the delay offset. The coherence point is defined on
the continuous model (``aoa.calibration.continuous_delay_setup``, equal to the quantised one
at every realisable offset) and then quantised to the nearest realisable offset; the sweep's
fitted optimum must find that continuous point within a fraction of a step, and the delay
it sets must be the realisable one nearest it. Grids: delay resolutions x radial mounting
offsets x arc radii.
"""

from __future__ import annotations

import numpy as np
import pytest

from conftest import make_scene
from rtsgeom.calibration.pair import calibrate_pair, pair_coherence
from rtsgeom.calibration.steps import (continuous_delay_setup, fine_window, realisable,
                                       realisation_shift)
from rtsgeom.calibration.probes import probe_angles, probe_front_ends, probe_ranges
from rtsgeom.synthesis.model import ChannelModel
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.rts.fir import realised_delay
from rtsgeom.rts.channels import requested_delay
from rtsgeom.scene import TargetConfig

RES_PS = (1.0, 5.0, 10.0, 25.0, 50.0, 100.0)


def _scene(res_ps, radius_m=1.0, dr_mm=0.0, fe=1, fractional=True):
    def mutate(doc):
        doc["radar"].pop("snr_db", None)
        doc["rts"]["arc_radius_m"] = radius_m
        doc["rts"]["fractional_delay"] = fractional
        doc["rts"]["fractional_delay_step_s"] = res_ps * 1e-12 if fractional else 1e-12
        doc["rts"]["calibration_step_ps"] = max(25.0, res_ps)
        doc["rts"]["front_ends"][fe]["radial_offset_mm"] = dr_mm
    return build_setup(make_scene(mutate))


@pytest.fixture(scope="module")
def probe():
    s = _scene(1.0)
    return probe_front_ends(s, exact_paths(s), 1)


def _tolerance(res):
    """How close the fitted optimum comes to the continuous coherence point: 1.5 ps or a tenth
    of a step (measured: <= 1.1 ps up to 50 ps steps, 3.7 ps at 100 ps, 17 ps at 250 ps)."""
    return max(1.5e-12, 0.1 * res)


@pytest.mark.parametrize("radius", [1.0, 3.0])
@pytest.mark.parametrize("dr_mm", [0.0, 0.3, -0.6])
def test_coherence_point_is_the_continuous_one_whatever_the_step(radius, dr_mm, probe):
    """The coherence point does not depend on the RTS's delay step (it did: Newton on the
    staircase landed within a step of it, up to 7 / 18 / 27 / 18 ps off at 10 / 25 / 50 /
    100 ps steps); its realisable delay is the nearest whole step and the residual at most half a
    step."""
    alphas = probe_angles(*probe.angle_rad[[0, 1]])
    ref = _scene(1e-3, radius, dr_mm)
    truth = pair_coherence(ref, exact_paths(ref), (0, 1), alphas=alphas).continuous_s
    for res_ps in RES_PS:
        s = _scene(res_ps, radius, dr_mm)
        cp = pair_coherence(s, exact_paths(s), (0, 1), alphas=alphas)
        res = res_ps * 1e-12
        assert cp.delay_resolution_s == pytest.approx(res)
        assert cp.continuous_s == pytest.approx(truth, abs=0.05e-12)
        assert cp.delta_tau_s == pytest.approx(float(realisable(cp.continuous_s, res)), abs=1e-18)
        assert abs(cp.quantisation_residual_s) <= res / 2 * (1 + 1e-9)
        assert cp.continuous_s - cp.delta_tau_s == pytest.approx(cp.quantisation_residual_s,
                                                                 abs=1e-18)


@pytest.mark.parametrize("res_ps", [25.0, 50.0, 250.0])
def test_continuous_model_equals_the_quantised_one_at_realisable_offsets(res_ps, probe):
    """At every realisable offset (the step divides 1/f_s = 250 ps) the continuous model's
    coherent phase is the RTS's own; between them the quantised one is flat (the staircase)
    and the continuous one moves by 2 pi f_if per second of delay."""
    s = _scene(res_ps, fractional=res_ps < 250.0)
    paths = exact_paths(s)
    cont = continuous_delay_setup(s)
    assert cont.scene.rts.delay_resolution_s <= 1e-15
    alphas = probe_angles(*probe.angle_rad[[0, 1]])
    rts = s.scene.rts
    t = TargetConfig(float(probe_ranges(s, 2)[0]))
    tau = float(requested_delay(s.scene, t.range_m))
    o = float(realised_delay(tau, rts.f_s_hz, rts.fractional_delay,
                             rts.fractional_delay_step_s)) - tau
    res = res_ps * 1e-12
    for k in (-3, 0, 2):
        d = k * res
        q = ChannelModel.build(s, paths, (0, 1), t, (0.0, d)).pair_phase(alphas)
        c_ = ChannelModel.build(cont, paths, (0, 1), t, (o, o + d)).pair_phase(alphas)
        assert np.angle(np.exp(1j * (q - c_))) == pytest.approx(0.0, abs=1e-6)
        # a third of a step further: the quantised model has not moved, the continuous one has
        q2 = ChannelModel.build(s, paths, (0, 1), t, (0.0, d + res / 3)).pair_phase(alphas)
        c2 = ChannelModel.build(cont, paths, (0, 1), t, (o, o + d + res / 3)).pair_phase(alphas)
        assert np.angle(np.exp(1j * (q2 - q))) == pytest.approx(0.0, abs=1e-6)
        assert abs(np.angle(np.exp(1j * (c2 - c_)))) > 0.5 * 2 * np.pi * 1e9 * res / 3


def test_fine_window_and_realisation_shift():
    """The fine sweep spans +-period/4 in the RTS's steps (at least one either side) and fits
    two harmonics, one where only 3 points remain; the quantiser's offset error is zero where
    the step divides 1/f_s and up to a step where it does not."""
    period = 1.0038e-9
    assert fine_window(period / 4, 5e-12) == (50, 5e-12, 2)
    assert fine_window(period / 4, 50e-12) == (5, 50e-12, 2)
    assert fine_window(period / 4, 100e-12) == (2, 100e-12, 2)
    assert fine_window(period / 4, 250e-12) == (1, 250e-12, 1)
    d = np.arange(-5, 6) * 50e-12
    s50 = _scene(50.0)
    assert np.all(realisation_shift(s50, probe_ranges(s50, 2), d) == pytest.approx(0.0,
                                                                                  abs=1e-18))
    s100 = _scene(100.0)
    d = np.arange(-5, 6) * 100e-12
    sh = realisation_shift(s100, probe_ranges(s100, 2), d)
    assert np.max(np.abs(sh)) > 10e-12 and np.max(np.abs(sh)) <= 100e-12 + 1e-18


def _check_calibration(res_ps, radius, dr_mm, probe, fractional=True, full_chain=False):
    s = _scene(res_ps, radius, dr_mm, fractional=fractional)
    paths = exact_paths(s)
    cal = calibrate_pair(s, paths, (0, 1), probe, seed=1, full_chain=full_chain)
    res = s.scene.rts.delay_resolution_s
    cp = pair_coherence(s, paths, (0, 1), alphas=probe_angles(*probe.angle_rad[[0, 1]]),
                        near_s=cal.delta_tau_s)
    fitted = cal.delta_tau_s + cal.quantisation_residual_s
    tol = _tolerance(res)
    assert abs(fitted - cp.continuous_s) <= tol, (fitted - cp.continuous_s) * 1e12
    # the realised delay is the nearest realisable one (unless the point sits within the
    # fit's tolerance of a half-step boundary, where either neighbour is right)
    assert abs(cal.delta_tau_s - cp.continuous_s) <= res / 2 + tol
    if abs(cp.quantisation_residual_s) < res / 2 - tol:
        assert cal.delta_tau_s == pytest.approx(cp.delta_tau_s, abs=1e-18)
    assert abs(cal.quantisation_residual_s) <= res / 2 * (1 + 1e-9)
    steps = np.concatenate([[cal.delta_tau_s], cal.refine_delta_tau_s]) / res
    assert np.allclose(steps, np.round(steps), rtol=0, atol=1e-6)
    return cal


@pytest.mark.parametrize("res_ps, radius, dr_mm", [(25.0, 1.0, 0.3), (100.0, 3.0, -0.6),
                                                   (100.0, 1.0, 0.3)])
def test_calibration_finds_the_continuous_point_on_coarse_steps(res_ps, radius, dr_mm, probe):
    """The paper's 25 ps and a 100 ps step (5 fine points; before, the fit fell back to the
    coarse minimum and set a delay one step from the nearest, 54 to 88 ps from the point)."""
    _check_calibration(res_ps, radius, dr_mm, probe)


@pytest.mark.parametrize("res_ps, radius, dr_mm", [(25.0, 1.0, 0.3), (100.0, 3.0, -0.6)])
def test_full_chain_calibration_finds_the_continuous_point_on_coarse_steps(res_ps, radius,
                                                                          dr_mm, probe):
    """Every step through the ADC-cube chain (measured: 0.04 ps and 1.0 ps from the point)."""
    cal = _check_calibration(res_ps, radius, dr_mm, probe, full_chain=True)
    assert cal.method == "full-chain"


@pytest.mark.slow
@pytest.mark.parametrize("radius", [1.0, 3.0])
@pytest.mark.parametrize("dr_mm", [0.0, 0.3, -0.6])
def test_calibration_finds_the_continuous_point_on_the_resolution_grid(radius, dr_mm, probe):
    """The grid, 1 to 100 ps fractional-delay steps and whole 4 GSPS samples (250 ps, 3 fine
    points: one harmonic through them) x 3 radial offsets x 2 arc radii, sampled so that the
    suite stays short: each (offset, radius) case takes two of the steps, in turn, so the six
    cases visit every step twice; whole samples on the largest offset. The full 42-setup grid:
    python -m benchmarks.calibration_resolution."""
    case = [0.0, 0.3, -0.6].index(dr_mm) * 2 + [1.0, 3.0].index(radius)
    for res_ps in (RES_PS[case % len(RES_PS)], RES_PS[(case + 3) % len(RES_PS)]):
        _check_calibration(res_ps, radius, dr_mm, probe)
    if dr_mm == -0.6:
        _check_calibration(250.0, radius, dr_mm, probe, fractional=False)
