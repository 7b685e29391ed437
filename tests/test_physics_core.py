"""Tests written for the survivors of a *fresh* mutation sample (``python -m benchmarks.mutation
--sample 160 --seed 3``): behaviour of the physics core that no earlier test checked.

Each test checks a closed form or an invariant on a grid of inputs through public functions.
No module-scoped fixtures: mutmut runs, per mutant, only the tests that reached the mutated
function, and a shared fixture is attributed to the first test that built it (so a check in a
later test would not run). Small setups keep them fast.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from conftest import make_scene


def _small_noiseless(mutate=None):
    def m(doc):
        doc["radar"].pop("snr_db", None)
        doc["radar"].update(chirps_per_tx=32, samples_per_chirp=128, adc_rate_hz=12.5e6)
        if mutate:
            mutate(doc)
    return make_scene(m)


# -- analysis.tolerance: the yield search and an empty Monte-Carlo --------------------------


@pytest.mark.parametrize("t_star", [0.013, 0.7, 3.0, 41.0])
@pytest.mark.parametrize("rel_tol", [0.2, 0.02, 1e-3])
def test_largest_passing_scale_stops_when_the_bracket_is_within_rel_tol(t_star, rel_tol):
    """A yield that passes for t <= t*: the search returns lo <= t* within rel_tol of it and
    stops as soon as the bracket is that narrow, so its cost is the doublings plus
    ceil(log2(log(hi/lo) / log(1 + rel_tol))) + 1 geometric bisections, not all of them."""
    from rtsgeom.analysis.tolerance.search import largest_passing_scale
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
    from rtsgeom.analysis.tolerance.search import largest_passing_scale
    for cap in (0.5, 3.0, 10.0):
        t, y, capped = largest_passing_scale(lambda t: 1.0, 1.0, 0.9, 0.1, cap, 0.01)
        assert capped and t == cap and y == 1.0


def test_monte_carlo_without_draws_has_no_errors_and_no_yield():
    """Zero draws: every case's error array is empty and its yield undefined (NaN), never a
    phantom draw with zero error (a 100 % yield)."""
    from rtsgeom.analysis.tolerance.phasors import ChannelPhasors
    from rtsgeom.analysis.tolerance.montecarlo import monte_carlo
    from rtsgeom.geometry import build_setup
    model = ChannelPhasors.build(build_setup(make_scene()), (0, 1), 3)
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


# -- radar.capture: probe captures round trip --------------------------------------------


@pytest.mark.parametrize("fmt", ["npy", "bin"])
@pytest.mark.parametrize("active", [0, 1])
def test_probe_capture_round_trip(tmp_path, fmt, active):
    """A probe capture written (``.npy`` or DCA1000 ``.bin`` + sidecar) reads back with its
    active front end, probe range, velocity and amplitude, and the same samples (DCA1000:
    within int16 quantisation). The default probe is the calibration's first probe range."""
    from rtsgeom.calibration.probes import probe_ranges
    from rtsgeom.geometry import build_setup
    from rtsgeom.identify.capture import (capture_probe, read_capture, simulate_capture,
                                          write_capture)
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
    from rtsgeom.analysis.tolerance.draws import Bounds
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
    from rtsgeom.analysis.tolerance.draws import Bounds, draw_chunks
    draws, count = 400, 3
    ref = None
    unit = Bounds((1.0,) * 3, 1.0, 1.0, (1.0,) * 3, 1.0)
    for chunk in (1, 37, 400, 10_000):
        parts = list(draw_chunks(5, draws, count, distribution, chunk, rotations=True, rut=True))
        assert len(parts) == -(-draws // chunk)
        errs = [p.errors(unit) for p in parts]
        got = {"offsets": np.concatenate([e["offsets_m"] for e in errs]),
               "rotations": np.concatenate([np.stack([e["yaw_rad"], e["pitch_rad"]], -1)
                                            for e in errs]),
               "rut": np.concatenate([np.column_stack([e["rut_offset_m"], e["rut_yaw_rad"]])
                                      for e in errs])}
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
    from rtsgeom.analysis.tolerance.draws import Bounds
    from rtsgeom.analysis.tolerance import ChannelPhasors, ToleranceModel
    from rtsgeom.analysis.tolerance.search import max_scale_for_yield
    from rtsgeom.geometry import build_setup
    setup = build_setup(make_scene())
    models = ToleranceModel.arc([ChannelPhasors.build(setup, (0, 1), 3)], 2)
    b = Bounds((1e-4, 1e-4, 1e-4))
    # the nominal calibrated synthesis is exact to ~1e-5 deg: a spec below that fails at 0
    res = max_scale_for_yield(models, b, 20, 1, 0.9, spec_deg=1e-12, case="uncalibrated")
    assert res["factor"] == 0.0 and res["yield"] == 0.0 and not res["capped"]
    ok = max_scale_for_yield(models, b, 20, 1, 0.9, spec_deg=0.1, case="calibrated",
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
    b1, b2 = np.array(p1.outer_bias_deg), np.array(p2.outer_bias_deg)
    assert np.all(b1 > 0.3) and np.all(b1 < 0.9)
    np.testing.assert_allclose(b1 / b2, 2.0, rtol=0.1)
    ev = evaluate_arc(p2, draws=20, points=3)
    assert ev.plan.outer_bias_deg == p2.outer_bias_deg and ev.problem is None
    assert ev.worst_calibrated_deg < 1e-3
    assert 0.0 <= ev.tolerance_yield <= 1.0 and ev.sigma_mm > 0


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


# -- radar.frame: the physical link's receiver noise ----------------------------------------


def test_linked_frame_noise_is_the_receivers_thermal_noise_through_the_if_chain():
    """With ``[radar.link]`` and no ``snr_db`` the frame's noise per sample is k T0 F f_adc at
    the receiver input (no RTS channel programmed here) through the IF chain (mean |H|^2 over
    the bins) plus the ADC's quantisation, for a grid of noise figures (within 5 %); the
    seed decides the realisation."""
    from rtsgeom.radar import link as lk
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.radar.frame import simulate
    from rtsgeom.rts.channels import program_nearest

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
