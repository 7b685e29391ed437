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


# -- aoa.cells / aoa.ncal: cells and the pairs an N-channel calibration measures ------------


@pytest.mark.parametrize("count", [2, 3, 5])
def test_enclosing_interval_is_the_adjacent_pair_in_one_dimension(count):
    """1-D cells: a direction between two neighbouring front ends (in any index order) is
    enclosed by exactly that pair, also with only two front ends; outside the span none."""
    from rtsgeom.aoa.cells import CellUnreachable, enclosing_cell
    rng = np.random.default_rng(count)
    x = np.sort(rng.uniform(-0.5, 0.5, count))
    perm = rng.permutation(count)
    pts = x[perm][:, None]
    for k in range(count - 1):
        for f in (0.0, 0.3, 0.99):
            u = x[k] + f * (x[k + 1] - x[k])
            got = enclosing_cell([u], pts)
            assert sorted(perm[list(got)]) == [k, k + 1]  # channel q sits at rank perm[q]
    for u in (x[0] - 0.01, x[-1] + 0.01):
        with pytest.raises(CellUnreachable):
            enclosing_cell([u], pts)


@pytest.mark.parametrize("grid", [(2, 1), (4, 1), (2, 2), (3, 2), (3, 3)])
def test_pair_edges_are_neighbours_in_1d_and_delaunay_edges_in_2d(grid):
    """The pairs an N-channel calibration sweeps: in 1-D the F - 1 neighbours by direction
    (whatever the channel numbering); in 2-D the edges of the Delaunay triangulation, 3 F - 3
    - h of them for F points with h on the hull (Euler), each joining two given channels."""
    from rtsgeom.aoa.ncal import pair_edges
    n_a, n_e = grid
    rng = np.random.default_rng(n_a * 10 + n_e)
    az = np.arange(n_a) * 0.1 + rng.uniform(-0.01, 0.01, n_a)
    if n_e == 1:
        u = az[:, None]
        perm = rng.permutation(n_a)
        u_fe = np.empty_like(u)
        u_fe[perm] = u  # channel perm[k] sits at the k-th direction
        edges = pair_edges(u_fe, range(n_a))
        want = sorted(tuple(sorted((int(perm[k]), int(perm[k + 1])))) for k in range(n_a - 1))
        assert sorted(edges) == want
        return
    el = np.arange(n_e) * 0.08
    u_fe = np.array([(a, e) for a in az for e in el]) + rng.uniform(-0.003, 0.003, (n_a * n_e, 2))
    f = len(u_fe)
    from scipy.spatial import ConvexHull
    h = len(ConvexHull(u_fe).vertices)
    edges = pair_edges(u_fe, range(f))
    assert len(edges) == len(set(edges)) == 3 * f - 3 - h
    assert all(0 <= i < j < f for i, j in edges)
    # a subset of channels: only edges among them
    sub = [0, 1, f - 1]
    assert {q for e in pair_edges(u_fe, sub) for q in e} == set(sub)


def _small_noiseless(mutate=None):
    def m(doc):
        doc["radar"].pop("snr_db", None)
        doc["radar"].update(chirps_per_tx=32, samples_per_chirp=128, adc_rate_hz=12.5e6)
        if mutate:
            mutate(doc)
    return make_scene(m)


@pytest.mark.parametrize("fe, dr_mm", [(1, -0.097), (0, -0.3)])
def test_nd_pair_calibration_lands_on_the_coherence_point(fe, dr_mm):
    """The N-channel pair sweep (``ncal.calibrate_pair_nd``, full ADC-cube chain at each
    step, a parabola through the points around the minimum) lands within 3 ps of the
    phasor model's coherence point for a radial offset that puts the point half a coarse
    step (100 ps) off the sweep grid, on either front end; its period is 1/(f_rts + S t_mid
    - S tau) as the pair calibration's."""
    from rtsgeom.aoa.calibration import coherence_delay, probe_angles, probe_front_ends
    from rtsgeom.aoa.ncal import calibrate_pair_nd
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    setup = build_setup(_small_noiseless(
        lambda d: d["rts"]["front_ends"][fe].update(radial_offset_mm=dr_mm)))
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, 1)
    got = calibrate_pair_nd(setup, paths, (0, 1), probe, 1, span_s=(-0.3e-9, 0.3e-9),
                            step_s=100e-12)
    point = coherence_delay(setup, paths, (0, 1), probe_angles(*probe.angle_rad[[0, 1]]))
    period = got["period_s"]
    dist = (got["delta_tau_s"] - point + period / 2) % period - period / 2
    assert abs(dist) < 3e-12
    assert got["residual_error_deg"] < 0.05
    assert got["range_offset_m"] == pytest.approx(0.5 * 299792458.0 * got["delta_tau_s"])


def test_channel_calibration_of_one_channel_is_its_own_reference():
    from rtsgeom.aoa.calibration import probe_front_ends
    from rtsgeom.aoa.ncal import calibrate_channels
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    setup = build_setup(_small_noiseless())
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, 1)
    for q in (0, 1):
        cal = calibrate_channels(setup, paths, [q], probe)
        assert cal.reference == q and np.all(cal.offsets_s == 0.0) and cal.tree == []
        assert cal.gain_correction == pytest.approx(tuple(probe.gain_correction))


# -- aoa.linearity2d: the 2-D error map through the ADC-cube chain ---------------------------


def test_2d_error_map_exact_mode_puts_every_grid_point_on_its_direction():
    """sphere4 as built = nominal (no errors, noiseless): ``exact`` amplitudes synthesize
    every grid point inside the four front ends' cell at its (azimuth, elevation) through
    the whole chain (1e-4 deg); ``array-factor`` (closed form, no near field) is off by a
    finite amount. The n x n grid inside a rectangular cell keeps all n^2 points."""
    from rtsgeom.aoa.linearity2d import linearity_grid
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.scene import load_scene
    sc = load_scene("scenes/sphere4.toml")
    sc = sc.evolve(radar=sc.radar.evolve(snr_db=None, samples_per_chirp=128, chirps_per_tx=32,
                                         adc_rate_hz=12.5e6))
    setup = build_setup(sc)
    paths = exact_paths(setup)
    em = linearity_grid(setup, paths, "exact", n=2, calibrate=False, seed=1)
    assert em.set_deg.shape == (4, 2)
    assert max(em.max_abs_error_deg()) < 1e-4
    af = linearity_grid(setup, paths, "array-factor", n=2, calibrate=False, seed=1)
    assert 0.05 < max(af.max_abs_error_deg()) < 1.0


# -- aoa.nchannel: the closed form does not depend on a common phase -------------------------


@pytest.mark.parametrize("common", [0.0, 0.7, -2.1, 3.0])
def test_closed_form_amplitudes_ignore_a_common_phase(common):
    """Adding one phase to every channel's programmed phase changes nothing physical (the
    beamformer output rotates as a whole): the ``array-factor`` amplitudes on sphere4's four
    front ends are the same for phases + c as for phases, over set points in the cell."""
    from rtsgeom.aoa.nchannel import ChannelSet, closed_form_amplitudes
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.scene import TargetConfig, load_scene
    setup = build_setup(load_scene("scenes/sphere4.toml"))
    cs = ChannelSet.build(setup, exact_paths(setup), (0, 1, 2, 3), TargetConfig(25.0))
    st = cs.steering
    u_fe = setup.fe_direction_cosines()
    lo, hi = u_fe.min(0), u_fe.max(0)
    phases = np.array([0.3, -1.2, 2.0, 0.4])
    for fx, fz in ((0.3, 0.4), (0.7, 0.8), (0.5, 0.2)):
        u = lo + np.array([fx, fz]) * (hi - lo)
        a = closed_form_amplitudes(st, u_fe, u, phases)
        b = closed_form_amplitudes(st, u_fe, u, phases + common)
        np.testing.assert_allclose(b, a, rtol=1e-9, atol=1e-12)
        assert np.max(a) == pytest.approx(1.0)


# -- aoa.linearity: the closed forms with measured end angles ---------------------------------


@pytest.mark.parametrize("mode", ["array-factor", "paper"])
def test_measured_end_angles_equal_geometric_ones_in_the_ideal_far_field(mode):
    """In the ideal far field (50 m, no Rx/Tx separation) each front end alone is detected
    at its geometric angle, so the closed forms with measured end angles program the same
    ratios as with the geometric ones: the same detected angles through the chain."""
    from rtsgeom.aoa.calibration import probe_front_ends
    from rtsgeom.aoa.linearity import linearity
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths

    def far(doc):
        doc["rts"]["arc_radius_m"] = 50.0
        doc["sheet"]["enabled"] = False
        for fe in doc["rts"]["front_ends"]:
            fe["rx_tx_separation_m"] = 0.0
            fe.pop("return_loss_fe_db", None)
            fe.pop("return_loss_be_db", None)
        doc["targets"] = [{"range_m": 60.0, "angle_deg": 7.0}]
    setup = build_setup(_small_noiseless(far))
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, 1)
    geo = linearity(setup, paths, (0, 1), mode, probe, None, 5, 1, "geometric")
    meas = linearity(setup, paths, (0, 1), mode, probe, None, 5, 1, "measured")
    assert np.all(np.isfinite(meas.error_deg))
    np.testing.assert_allclose(meas.error_deg, geo.error_deg, atol=0.02)


# -- radar.capture: probe captures round trip --------------------------------------------


@pytest.mark.parametrize("fmt", ["npy", "bin"])
@pytest.mark.parametrize("active", [0, 1])
def test_probe_capture_round_trip(tmp_path, fmt, active):
    """A probe capture written (``.npy`` or DCA1000 ``.bin`` + sidecar) reads back with its
    active front end, probe range, velocity and amplitude, and the same samples (DCA1000:
    within int16 quantisation). The default probe is the calibration's first probe range."""
    from rtsgeom.aoa.calibration import probe_ranges
    from rtsgeom.geometry import build_setup
    from rtsgeom.radar.capture import capture_probe, read_capture, simulate_capture, write_capture
    setup = build_setup(_small_noiseless())
    r0, amp0 = capture_probe(setup)
    assert r0 == pytest.approx(float(probe_ranges(setup, 1)[0]))
    r1, amp1 = capture_probe(setup, 2 * r0)
    assert r1 == 2 * r0 and amp1 == pytest.approx(amp0 / 4, rel=1e-9)  # amplitude ~ 1/R^2
    cap = simulate_capture(setup, active, velocity_mps=-1.5, seed=3)
    out = tmp_path / f"cap.{fmt}"
    write_capture(cap, setup.rut, out, fmt)
    back = read_capture(out)
    assert (back.active, back.range_m, back.velocity_mps, back.amplitude) == (
        active, cap.range_m, -1.5, cap.amplitude)
    assert back.data.shape == cap.data.shape
    tol = 1e-6 if fmt == "npy" else 2.0 / 32767
    assert np.max(np.abs(back.data - cap.data)) <= tol * np.max(np.abs(cap.data))


# -- analysis.arc: tolerance bounds, draws and the arc yield search ---------------------------


@pytest.mark.parametrize("distribution, level", [("normal", 3.0), ("normal", 2.0),
                                                 ("uniform", 3.0)])
def test_bounds_from_tolerances_scale_every_field(distribution, level):
    """A tolerance t is a normal draw's t / sigma_level standard deviation and a uniform
    draw's bound t, for every field (front-end offsets and rotations, the RuT's position
    and yaw); a field left out is 0."""
    from rtsgeom.analysis.arc import Bounds
    tol = {"offsets_m": (1e-4, 2e-4, 3e-4), "yaw_rad": 0.01, "pitch_rad": 0.02,
           "rut_position_m": (4e-4, 5e-4, 6e-4), "rut_yaw_rad": 0.03}
    k = 1.0 / level if distribution == "normal" else 1.0
    b = Bounds.from_tolerances(tol, distribution, level)
    assert b.offsets_m == pytest.approx(tuple(k * v for v in tol["offsets_m"]))
    assert (b.yaw_rad, b.pitch_rad, b.rut_yaw_rad) == pytest.approx((0.01 * k, 0.02 * k,
                                                                      0.03 * k))
    assert b.rut_position_m == pytest.approx(tuple(k * v for v in tol["rut_position_m"]))
    only = Bounds.from_tolerances({"rut_yaw_rad": 0.03}, distribution, level)
    assert only.rut_yaw_rad == pytest.approx(0.03 * k) and only.rut_pose and not only.rotations
    assert only.offsets_m == (0.0, 0.0, 0.0) and only.rut_position_m == (0.0, 0.0, 0.0)


@pytest.mark.parametrize("distribution", ["normal", "uniform"])
def test_arc_draws_do_not_depend_on_the_chunk(distribution):
    """The unit draws are the same whatever the chunk size (each stream from its own
    generator), with the documented shapes; uniform ones fill [-1, 1], normal ones have unit
    variance."""
    from rtsgeom.analysis.arc import arc_draws
    draws, count = 400, 3
    ref = None
    for chunk in (1, 37, 400, 10_000):
        parts = list(arc_draws(5, draws, count, distribution, chunk))
        assert len(parts) == -(-draws // chunk)
        got = {k: np.concatenate([p[k] for p in parts]) for k in ("offsets", "rotations", "rut")}
        assert got["offsets"].shape == (draws, count, 3)
        assert got["rotations"].shape == (draws, count, 2) and got["rut"].shape == (draws, 4)
        if ref is None:
            ref = got
        for k in ref:
            np.testing.assert_array_equal(got[k], ref[k])
    x = ref["offsets"].ravel()
    assert np.unique(x).size == x.size  # independent draws, not one value broadcast
    if distribution == "uniform":
        assert x.min() >= -1.0 and x.max() <= 1.0 and x.min() < -0.98 and x.max() > 0.98
    else:
        assert np.std(x) == pytest.approx(1.0, abs=0.05)


def test_arc_yield_search_stops_at_zero_when_the_nominal_arc_fails():
    """When even the arc without errors misses the spec, the largest passing scale is 0 and
    its yield is the nominal one (0); with a reachable spec the scale is positive."""
    from rtsgeom.analysis.arc import Bounds, arc_models, max_scale_for_yield
    from rtsgeom.geometry import build_setup
    setup = build_setup(make_scene())
    models = arc_models(setup, [(0, 1)], 3)
    b = Bounds((1e-4, 1e-4, 1e-4))
    # the nominal calibrated synthesis is exact to ~1e-5 deg: a spec below that fails at 0
    res = max_scale_for_yield(models, 2, b, 20, 1, 0.9, spec_deg=1e-12, case="uncalibrated")
    assert res["factor"] == 0.0 and res["yield"] == 0.0 and not res["capped"]
    ok = max_scale_for_yield(models, 2, b, 20, 1, 0.9, spec_deg=0.1, case="calibrated",
                             rel_tol=0.1)
    assert ok["factor"] > 0 and ok["yield"] >= 0.9


# -- analysis.coverage: the planned arc ------------------------------------------------------


def test_arc_scene_copies_the_first_front_end_without_its_errors():
    """``arc_scene`` places copies of the first front end (layout, cables) at the given angles
    on the given radius with none of its mounting or channel errors: the modules sit exactly
    on the arc at their angles, unrotated, whatever errors the template had."""
    from rtsgeom.analysis.coverage import arc_scene
    from rtsgeom.geometry import build_setup

    def errors(doc):
        fe = doc["rts"]["front_ends"][0]
        fe.update(radial_offset_mm=0.4, tangential_offset_mm=-0.3, height_offset_mm=0.7,
                  yaw_offset_deg=1.5, pitch_offset_deg=-2.0, gain_offset_db=3.0,
                  phase_offset_deg=20.0)
    scene = make_scene(errors)
    angles = np.radians([-6.0, 2.0, 10.0])
    for radius in (1.0, 2.5):
        variant, _ = arc_scene(scene, radius, angles)
        clean, _ = arc_scene(make_scene(), radius, angles)
        assert len(variant.rts.front_ends) == 3
        for fe in variant.rts.front_ends:
            assert (fe.radial_offset_m, fe.tangential_offset_m, fe.height_offset_m,
                    fe.yaw_offset_rad, fe.pitch_offset_rad, fe.gain_offset_db,
                    fe.phase_offset_rad) == (0.0,) * 7
            assert fe.cable_length_m == scene.rts.front_ends[0].cable_length_m
        s, s0 = build_setup(variant), build_setup(clean)
        np.testing.assert_allclose(s.fe.module, s0.fe.module, atol=1e-12)
        np.testing.assert_allclose(s.fe_azimuth_rad(), angles, atol=1e-9)
        d = np.linalg.norm(s.fe.module - s.fe.arc_centre, axis=-1)
        np.testing.assert_allclose(d, radius, atol=1e-12)


def test_planned_arc_reports_the_outer_front_ends_near_field_bias():
    """``plan_arc``'s outer bias is each outer front end's detected minus module angle (the
    near-field bias, README ~+0.57 deg at 1 m with 20 mm separation): positive, first order
    in 1/R (half at twice the radius), and what ``evaluate_arc`` carries over; the arc's
    calibrated nominal synthesis is exact."""
    from rtsgeom.analysis.coverage import evaluate_arc, plan_arc
    scene = make_scene()
    cov = (math.radians(0.0), math.radians(12.0))
    p1, p2 = plan_arc(scene, cov, 1.0), plan_arc(scene, cov, 2.0)
    b1, b2 = np.array(p1["outer_bias_deg"]), np.array(p2["outer_bias_deg"])
    assert np.all(b1 > 0.3) and np.all(b1 < 0.9)
    np.testing.assert_allclose(b1 / b2, 2.0, rtol=0.1)
    ev = evaluate_arc(p2, draws=20, points=3)
    assert ev["outer_bias_deg"] == p2["outer_bias_deg"] and ev["problem"] is None
    assert ev["worst_calibrated_deg"] < 1e-3
    assert 0.0 <= ev["tolerance_yield"] <= 1.0 and ev["sigma_mm"] > 0


# -- radar.steering: the 2-D search does not depend on the snapshot's phase ------------------


@pytest.mark.parametrize("preset", ["awr1843boost", "iwr6843isk", "awr2944"])
@pytest.mark.parametrize("window", ["none", "hann", "hamming", "blackman"])
def test_2d_search_is_independent_of_the_targets_phase(preset, window):
    """A target's echo carries an arbitrary phase (range, RCS): multiplying a plane wave's
    snapshot by e^{j phi} must not move the 2-D beamformer peak, for every taper and array:
    the same (azimuth, elevation) for phases all around the circle, at the plane wave's
    direction."""
    from rtsgeom.radar.steering import Steering
    from rtsgeom.scene import load_scene
    sc = load_scene("scenes/diewald2022.toml")
    radar = sc.radar.evolve(antenna_preset=preset, use_elevation_tx=True, angle_window=window,
                            elevation_processing=True)
    rut = build_setup_of(sc.evolve(radar=radar, targets=())).rut
    st = Steering.auto(rut, radar)
    assert st.dims == 2
    rng = np.random.default_rng(11)
    ae = np.radians(np.column_stack([rng.uniform(-40, 40, 12), rng.uniform(-20, 20, 12)]))
    x = np.zeros((ae.shape[0], rut.num_virtual), complex)
    x[:, st.mask] = np.exp(-1j * (st.wavevector @ st.directions(ae).T)).T
    for phi in np.linspace(0, 2 * np.pi, 7, endpoint=False):
        got = st.search(x * np.exp(1j * (phi + rng.uniform(0, 0.2))))
        assert np.degrees(np.abs(got - ae)).max() < 1e-6


def build_setup_of(scene):
    from rtsgeom.geometry import build_setup
    return build_setup(scene)


# -- aoa.model: the RuT's pose in the channel model ------------------------------------------


@pytest.mark.parametrize("h_mm", [-3.0, 0.5, 4.0])
def test_raising_the_rut_equals_lowering_every_front_end(h_mm):
    """Only relative geometry matters: the legs with the RuT raised by h (a RuT position
    error alone, no yaw) equal those with every front end lowered by h (height offset -h),
    for both channels of the pair; and they differ from the nominal legs."""
    from rtsgeom.analysis.tolerance import PairPhasors
    from rtsgeom.geometry import build_setup
    model = PairPhasors.build(build_setup(make_scene()), (0, 1), 3)
    h = h_mm * 1e-3
    zero = np.zeros((2, 3))
    raised = model.air_legs(zero, {"rut_offset_m": np.array([0.0, 0.0, h])})
    lowered = model.air_legs(np.array([[0.0, 0.0, -h]] * 2))
    nominal = model.air_legs(zero)
    for a, b, n in zip(raised, lowered, nominal):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-18)
        assert np.max(np.abs(a - n)) > 1e-16


# -- radar.frame: the physical link's receiver noise ----------------------------------------


def test_linked_frame_noise_is_the_receivers_thermal_noise_through_the_if_chain():
    """With ``[radar.link]`` and no ``snr_db`` the frame's noise per sample is k T0 F f_adc at
    the receiver input (no RTS channel programmed here) through the IF chain (mean |H|^2 over
    the bins) plus the ADC's quantisation, for a grid of noise figures (within 5 %); the
    seed decides the realisation."""
    from rtsgeom import link as lk
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.radar.frame import simulate
    from rtsgeom.rts import program_nearest

    def linked(nf_db):
        def m(doc):
            doc["radar"].pop("snr_db", None)
            doc["radar"].update(chirps_per_tx=32, samples_per_chirp=128, adc_rate_hz=12.5e6)
            doc["radar"]["link"] = {"noise_figure_db": nf_db}
            doc["targets"] = []
            for fe in doc["rts"]["front_ends"]:
                fe.pop("return_loss_fe_db", None)
                fe.pop("return_loss_be_db", None)
        return make_scene(m)
    for nf in (12.0, 18.0, 24.0):
        scene = linked(nf)
        radar = scene.radar
        setup = build_setup(scene)
        paths = exact_paths(setup)
        prog = program_nearest(scene, setup)
        assert len(prog) == 0
        _, cube = simulate(setup, paths, prog, seed=4)
        _, again = simulate(setup, paths, prog, seed=4)
        _, other = simulate(setup, paths, prog, seed=5)
        assert np.array_equal(cube.data, again.data) and not np.array_equal(cube.data, other.data)
        rl = lk.radar_link(radar)
        n = radar.samples_per_chirp
        h2 = np.mean(np.abs(lk.if_response(rl, np.arange(n) * radar.adc_rate_hz / n)) ** 2)
        want = lk.thermal_noise_w(radar, rl) * h2 + rl.quantisation_noise_w
        assert np.mean(np.abs(cube.data.astype(complex)) ** 2) == pytest.approx(want, rel=0.05)


# -- aoa.calibration: the paper's procedure reports the exact period ------------------------


def test_paper_procedure_reports_the_exact_period_at_its_target():
    """``calibrate_pair_paper`` (one target at one set angle) reports the period
    1/(f_rts + S t_mid - S tau) at its target's delay, as the pair calibration does at its
    probes' (not eq. 27's 1/(f_rts + B/2))."""
    from scipy.constants import c
    from rtsgeom.aoa.calibration import calibrate_pair_paper, probe_front_ends, probe_ranges
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    for f_rts in (500e6, 300e6):
        setup = build_setup(_small_noiseless(lambda d: d["rts"].update(f_rts_hz=f_rts)))
        paths = exact_paths(setup)
        probe = probe_front_ends(setup, paths, 1)
        cal = calibrate_pair_paper(setup, paths, (0, 1), probe, 1, span_s=(0.0, 50e-12),
                                   step_s=25e-12)
        r = setup.scene.radar
        t_mid = r.adc_start_s + 0.5 * (r.samples_per_chirp - 1) / r.adc_rate_hz
        s = r.bandwidth_hz / r.chirp_duration_s
        tau = 2 * float(probe_ranges(setup, 1)[0]) / c
        assert cal.period_s == pytest.approx(1 / (f_rts + s * t_mid - s * tau), rel=1e-4)


# -- aoa.sweep.design_ratio: the closed-form exact design ------------------------------------


@pytest.mark.parametrize("angle_window", ["none", "hann", "hamming", "blackman"])
@pytest.mark.parametrize("radius", [0.5, 1.0, 3.0])
def test_closed_form_design_is_scale_free_and_puts_the_peak_on_the_set_angle(angle_window,
                                                                            radius):
    """``design_ratio``: the ratio whose composite x_i + rho e^{j phase} x_j peaks at the set
    angle. Its beamformer peak is there (searched), and the ratio does not depend on the
    echoes' common scale (volts or sqrt(W), 1e-6 or 1e6: P'' < 0 is a sign, not a level)."""
    from rtsgeom.aoa.model import ChannelModel
    from rtsgeom.aoa.sweep import design_ratio
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.scene import TargetConfig

    def mutate(doc):
        doc["radar"]["angle_window"] = angle_window
        doc["rts"]["arc_radius_m"] = radius
    setup = build_setup(make_scene(mutate))
    cm = ChannelModel.build(setup, exact_paths(setup), (0, 1), TargetConfig(20.0))
    st = cm.steering
    x_i, x_j = cm.phasors
    th = np.sort(st.search(cm.phasors))
    phase = float(cm.coherent_phases(th[0] + np.array([0.25, 0.75]) * (th[1] - th[0]))[1])
    alphas = th[0] + np.array([0.15, 0.4, 0.6, 0.85]) * (th[1] - th[0])
    rho = design_ratio(st, x_i, x_j, alphas, phase)
    assert np.all(np.isfinite(rho)) and np.all(rho >= 0)
    comp = x_i[None] + (rho * np.exp(1j * phase))[:, None] * x_j[None]
    np.testing.assert_allclose(st.search(comp), alphas, atol=1e-7)
    for scale in (1e-6, 1e-3, 1e3, 1e6):
        np.testing.assert_allclose(design_ratio(st, scale * x_i, scale * x_j, alphas, phase),
                                   rho, rtol=1e-9)


# -- aoa.sweep: the calibration's noise model against the ADC-cube chain -----------------------


@pytest.mark.parametrize("snr_db", [-10.0, 0.0])
def test_calibration_sweep_noise_is_the_adc_chains_within_a_factor_of_a_few(snr_db):
    """The phasor sweep adds receiver noise of the scene's SNR to each step's spectra (what
    sizes the frames per step and ``one_frame_scatter_ps``); the full ADC-cube chain adds it
    to the samples. Near the coherence point both give the probes' angles a noise variance
    (noisy minus noiseless squared error, 6 seeds x 2 steps x 2 probes, each seed its own
    noise realisation in both); they agree within a
    factor 5 (measured: the phasor model's is 1.4-1.5 times the chain's at SNR -10 and 0 dB),
    where a noise level off by the windows' sum w^2 (thousands) would not."""
    from rtsgeom.aoa.calibration import calibrate_pair, probe_front_ends
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths

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
