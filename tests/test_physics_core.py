"""Tests written for the survivors of a *fresh* mutation sample (``python -m benchmarks.mutation
--sample 160 --seed 3``, issue 22): behaviour of the physics core that no earlier test checked.

Each test checks a closed form or an invariant on a grid of inputs through public functions.
No module-scoped fixtures: mutmut runs, per mutant, only the tests that reached the mutated
function, and a shared fixture is attributed to the first test that built it (so a check in a
later test would not run). Small setups keep them fast.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from conftest import make_scene


# -- aoa.synthesis.array_factor ----------------------------------------------------------


@pytest.mark.parametrize("n", [2, 4, 7, 8, 16])
def test_array_factor_of_filled_positions_is_the_dirichlet_kernel(n):
    """``array_factor`` with the positions of a filled lambda/2 array equals its closed form
    sin(n pi u/2) / (n sin(pi u/2)) (docstring), for any u, also past the grating lobes."""
    from rtsgeom.aoa.synthesis import array_factor
    u = np.linspace(-1.9, 1.9, 381)
    closed = array_factor(u, n)
    for offset in (0.0, 3.25):  # the centroid is removed: a shifted array has the same AF
        got = array_factor(u, positions_wl=offset + 0.5 * np.arange(n))
        np.testing.assert_allclose(got, closed, atol=1e-12)
    # a sparse array is not that kernel (here: 2 elements 2 lambda apart, cos(2 pi u))
    np.testing.assert_allclose(array_factor(u, positions_wl=[0.0, 2.0]), np.cos(2 * np.pi * u),
                               atol=1e-12)


# -- analysis.tolerance: the yield search and an empty Monte-Carlo --------------------------


@pytest.mark.parametrize("t_star", [0.013, 0.7, 3.0, 41.0])
@pytest.mark.parametrize("rel_tol", [0.2, 0.02, 1e-3])
def test_largest_passing_scale_stops_when_the_bracket_is_within_rel_tol(t_star, rel_tol):
    """A yield that passes for t <= t*: the search returns lo <= t* within rel_tol of it and
    stops as soon as the bracket is that narrow, so its cost is the doublings plus
    ceil(log2(log(hi/lo) / log(1 + rel_tol))) + 1 geometric bisections, not all of them."""
    from rtsgeom.analysis.tolerance import largest_passing_scale
    calls = []

    def yield_at(t):
        calls.append(t)
        return 1.0 if t <= t_star else 0.5

    start = 0.1
    t, y, capped = largest_passing_scale(yield_at, 1.0, 0.9, start, 1e6, rel_tol)
    assert not capped and y == 1.0
    assert t <= t_star and t_star - t <= rel_tol * t_star * (1 + rel_tol)
    doublings = max(0, math.ceil(math.log2(t_star / start)))
    lo = start * 2 ** (doublings - 1) if doublings else 0.0
    hi = start * 2 ** doublings
    ratio = math.log(hi / lo) / math.log(1 + rel_tol) if lo > 0 else hi / (rel_tol * t_star)
    bound = doublings + 1 + math.ceil(math.log2(max(ratio, 1.0))) + 2
    assert len(calls) <= bound, (len(calls), bound)


def test_largest_passing_scale_caps():
    from rtsgeom.analysis.tolerance import largest_passing_scale
    for cap in (0.5, 3.0, 10.0):
        t, y, capped = largest_passing_scale(lambda t: 1.0, 1.0, 0.9, 0.1, cap, 0.01)
        assert capped and t == cap and y == 1.0


def test_monte_carlo_without_draws_has_no_errors_and_no_yield():
    """Zero draws: every case's error array is empty and its yield undefined (NaN), never a
    phantom draw with zero error (a 100 % yield)."""
    from rtsgeom.analysis.tolerance import PairPhasors, monte_carlo
    from rtsgeom.geometry import build_setup
    model = PairPhasors.build(build_setup(make_scene()), (0, 1), 3)
    res = monte_carlo(model, [1e-4, 1e-4, 1e-4], 0, 1)
    for case, e in res.worst_error_deg.items():
        assert e.shape == (0,)
        assert math.isnan(res.yield_(case))
    full = monte_carlo(model, [1e-4, 1e-4, 1e-4], 7, 1)
    assert all(e.shape == (7,) for e in full.worst_error_deg.values())


# -- analysis.nearfield: the rows and the synthesized-angle errors --------------------------


@pytest.mark.parametrize("separation_m", [0.0, 0.02])
def test_nearfield_rows_and_exact_synthesis_on_the_nominal_setup(separation_m):
    """Each row's bias is detected - geometric and the sum of its parts; on a setup without
    mounting errors the exact amplitudes put every set-point on its angle (the design model
    is the RuT's), the array-factor closed form is off by a finite amount."""
    from rtsgeom.analysis.nearfield import nearfield

    def mutate(doc):
        for fe in doc["rts"]["front_ends"]:
            fe["rx_tx_separation_m"] = separation_m
    radii = np.array([0.5, 2.0])
    nf = nearfield(make_scene(mutate), radii, points=3)
    d = nf.to_dict()
    for i, row in enumerate(d["radii"]):
        assert row["radius_m"] == pytest.approx(radii[i])
        for fe in row["front_ends"]:
            assert fe["bias_deg"] == pytest.approx(fe["detected_deg"] - fe["geometric_deg"],
                                                   abs=1e-12)
            parts = (fe["separation_part_deg"] + fe["parallax_part_deg"]
                     + fe["beat_frequency_part_deg"] + fe["curvature_part_deg"])
            assert parts == pytest.approx(fe["bias_deg"], abs=1e-9)
        syn = row["synthesis"][0]
        assert syn["exact_max_abs_error_deg"] is not None
        assert syn["exact_max_abs_error_deg"] < 1e-6
        assert 1e-3 < syn["array_factor_max_abs_error_deg"] < 2.0


# -- aoa.sweep.fit_minimum ------------------------------------------------------------------


@pytest.mark.parametrize("true_ps", [-3.0, 0.0, 7.4])
@pytest.mark.parametrize("bad_rows", [(), (2,), (0, 5, 11)])
def test_fit_minimum_finds_the_minimum_of_the_periodic_criterion_despite_lost_steps(true_ps,
                                                                                   bad_rows):
    """Probe errors of the criterion's shape e_p = c_p (1 - cos(theta - theta_0)) (even,
    periodic, minimum at delta_0) over one period of steps: the fit returns delta_0 within
    its 0.05 ps grid, also when some steps lost a probe (NaN: no detection) -- only those
    steps are dropped."""
    from rtsgeom.aoa.sweep import fit_minimum
    period, step = 1.0e-9, 25e-12
    near = 0.0
    d = near + np.arange(-20, 21) * step
    th = 2 * np.pi * (d - true_ps * 1e-12) / period
    e = np.stack([0.8 * (1 - np.cos(th)) + 0.05 * np.sin(th) ** 2,
                  -0.5 * (1 - np.cos(th))], axis=1)
    for r in bad_rows:
        e[r, r % 2] = np.nan
    got = fit_minimum(d, e, period, near)
    assert got == pytest.approx(true_ps * 1e-12, abs=0.051e-12)


# -- aoa.calibration.fir_effect -------------------------------------------------------------


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
    from rtsgeom.aoa.calibration import (fir_effect, if_phase_slope_hz, probe_ranges,
                                         probe_total_delay)
    from rtsgeom.aoa.synthesis import PairModel
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.scene import TargetConfig
    ideal = build_setup(_fir_scene(taps, "ideal"))
    fir = build_setup(_fir_scene(taps, "windowed-sinc"))
    paths = exact_paths(ideal)
    ranges = probe_ranges(ideal, 2)
    f_if = if_phase_slope_hz(fir.scene, probe_total_delay(fir, ranges))
    measured, predicted = [], []
    for d in (0.1e-9, 0.37e-9, 0.63e-9, 0.81e-9):
        z = 0j
        for r in ranges:
            m0 = PairModel.build(ideal, paths, (0, 1), TargetConfig(float(r)), (0.0, d))
            m1 = PairModel.build(fir, paths, (0, 1), TargetConfig(float(r)), (0.0, d))
            z += np.exp(1j * (m1.coherent_phase([0.1]) - m0.coherent_phase([0.1])))
        measured.append(np.degrees(np.angle(z)))
        predicted.append(fir_effect(fir, d)["predicted_shift_ps"] * 1e-12 * 360 * f_if)
    m, p = np.array(measured), np.array(predicted)
    assert np.max(np.abs(p)) > 0.1  # deg: 5 taps ~5 deg, 9 taps ~0.15 deg
    gain = float(np.sum(m * p) / np.sum(p * p))
    assert 0.7 < gain < 1.3


# -- aoa.plan: the calibration's progress report ---------------------------------------------


def test_plan_reports_each_pairs_calibration_delay_in_picoseconds():
    """``run``'s progress line for a calibrated pair gives delta_tau in ps: the value
    the calibration record holds (s) times 1e12, within the printed precision."""
    from rtsgeom.aoa.plan import plan_targets
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths

    def mutate(doc):
        doc["radar"].pop("snr_db", None)
        doc["radar"].update(chirps_per_tx=32, samples_per_chirp=128, adc_rate_hz=12.5e6)
        doc["rts"]["front_ends"][1]["radial_offset_mm"] = 0.4
    setup = build_setup(make_scene(mutate))
    lines = []
    _, record, _ = plan_targets(setup, exact_paths(setup), "exact", progress=lines.append)
    shown = [float(m.group(1)) for m in
             (re.search(r"delta_tau (-?[0-9.]+) ps", s) for s in lines) if m]
    assert len(shown) == 1
    cal = record["pairs"][0] if "pairs" in record else record
    want_ps = float(cal["delta_tau_s"]) * 1e12
    assert abs(want_ps) > 1.0  # the 0.4 mm offset moves the point by ~2.7 ps
    assert shown[0] == pytest.approx(want_ps, abs=0.051)
