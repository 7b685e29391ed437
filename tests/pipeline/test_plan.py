"""Tests of ``rtsgeom.pipeline.plan``: closed forms and invariants on grids of inputs."""

from __future__ import annotations

import re

import numpy as np
import pytest
from conftest import ROOT, make_scene, small_noiseless
from scipy.constants import c

from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.radar import process
from rtsgeom.radar.frame import simulate
from rtsgeom.rts.channels import requested_delay


def test_plan_reports_each_pairs_calibration_delay_in_picoseconds():
    """``run``'s progress line for a calibrated pair gives delta_tau in ps: the value
    the calibration record holds (s) times 1e12, within the printed precision."""
    from rtsgeom.pipeline.plan import plan_targets

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


def test_plan_record_says_where_its_calibration_came_from():
    """Measured front-end angles (no calibration file): the record's source is "measured"."""
    from rtsgeom.pipeline.plan import plan_targets
    setup = build_setup(small_noiseless())
    _, record, _ = plan_targets(setup, exact_paths(setup), "array-factor", calibrate=False)
    assert record["source"] == "measured"


@pytest.mark.parametrize("velocity_mps", [-5.0, 0.0, 3.0])
def test_cell_plan_programs_the_doppler_of_each_targets_velocity(velocity_mps):
    """Front ends on a sphere (N channels per target): every channel of target k is programmed
    with the Doppler 2 f_c v_k / c0 of its set velocity."""
    import tomllib

    from rtsgeom.pipeline.plan import plan_targets, uses_cells
    from rtsgeom.scene import parse_scene
    doc = tomllib.loads((ROOT / "scenes" / "sphere4.toml").read_text())
    for k, t in enumerate(doc["targets"]):
        t["velocity_mps"] = velocity_mps * (k + 1) / len(doc["targets"])
    scene = parse_scene(doc, str(ROOT / "scenes" / "sphere4.toml"))
    assert uses_cells(scene)
    setup = build_setup(scene)
    prog, _, _ = plan_targets(setup, exact_paths(setup), "array-factor", calibrate=False)
    for k, t in enumerate(scene.targets):
        rows = np.asarray(prog.target) == k
        assert rows.sum() >= 3
        np.testing.assert_allclose(prog.doppler_hz[rows], 2 * scene.radar.f_c_hz * t.velocity_mps
                                   / c, rtol=1e-12, atol=1e-9)


@pytest.mark.parametrize("mode", ["exact", "array-factor", "paper"])
def test_plan_programs_two_channels_per_target_at_the_set_range_and_doppler(small_setup, mode):
    """``plan_targets`` without calibration: per target the bracketing pair, each at the
    requested delay and Doppler 2 f_c v / c0, positive amplitudes; with exact amplitudes on the
    nominal setup the chain detects each target at its set angle."""
    from rtsgeom.pipeline.plan import plan_targets
    setup, paths = small_setup
    scene = setup.scene
    prog, record, warnings = plan_targets(setup, paths, mode, calibrate=False)
    assert len(prog) == 2 * len(scene.targets) and not warnings
    assert record["mode"] == mode and record["pairs"] == []
    for k, t in enumerate(scene.targets):
        rows = prog.target == k
        assert sorted(prog.front_end[rows].tolist()) == [0, 1]
        # channel I at the requested delay; J there too, or a whole IF period away where its
        # echo straddles a range-bin boundary (aoa.plan.pair_design: same phase, next bin)
        d = np.sort(prog.delay_s[rows]) - requested_delay(scene, t.range_m)
        period = 1 / (scene.rts.f_rts_hz + scene.radar.bandwidth_hz / 2)
        assert abs(d[0]) < 1e-15 or abs(d[1]) < 1e-15, d
        assert np.all((np.abs(d) < 1e-15) | (np.abs(np.abs(d) - period) < 0.02 * period)), d
        np.testing.assert_allclose(prog.doppler_hz[rows], 2 * scene.radar.f_c_hz * t.velocity_mps / c,
                                   rtol=1e-12)
        assert np.all(np.abs(prog.amplitude[rows]) > 0)
    if mode == "exact":
        _, cube = simulate(setup, paths, prog)
        rd, det = process(cube)
        from rtsgeom.pipeline.matching import match_targets
        for e in match_targets(scene, det, rd):
            assert abs(e["error"]["angle_deg"]) < 0.05


def test_a_pair_is_checked_against_the_arc_or_the_cells(crossing_bench, sphere_scene):
    """On an arc: two adjacent indices in range (either order); in a scene of 2-D cells: a
    measured edge where cells are asked for, refused with what to use otherwise."""
    from conftest import assert_refused
    from rtsgeom.geometry import build_setup
    from rtsgeom.pipeline.plan import check_pair, measured_pairs
    arc, sph = build_setup(crossing_bench), build_setup(sphere_scene)
    assert check_pair(arc, 3, 2, "p") == (2, 3) and check_pair(arc, 0, 1, "p", True) == (0, 1)
    for i, j in ((0, 2), (0, 5), (-1, 0), (4, 4)):
        assert_refused(lambda: check_pair(arc, i, j, "pair X"),
                       "pair X: must be two adjacent front-end indices in [0, 4]")
    assert_refused(lambda: check_pair(arc, 0, 5, "pair X", True),
                   "pair X: must be two neighbouring front-end indices in [0, 4]")
    edges = measured_pairs(sph)
    assert edges == [(0, 1), (0, 2), (0, 3), (1, 3), (2, 3)]
    assert [check_pair(sph, j, i, "p", True) for i, j in edges] == edges
    assert_refused(lambda: check_pair(sph, 0, 1, "pair X"),
                   "pair X: this scene's front ends form 2-D cells (azimuth and elevation), not "
                   "pairs on an arc: use `run`, `linearity --grid N`, `nearfield` and `tolerance "
                   "--cell` for the cell")
    assert_refused(lambda: check_pair(sph, 1, 2, "pair X", True),
                   "pair X: not neighbours in this scene's cells; its pairs are 0 1, 0 2, 0 3, "
                   "1 3, 2 3")
    assert_refused(lambda: check_pair(sph, 0, 4, "pair X", True),
                   "pair X: must be two neighbouring front-end indices in [0, 3]")
    assert measured_pairs(arc) == [(0, 1), (1, 2), (2, 3), (3, 4)]


def test_a_budget_merged_target_is_named_by_its_strongest_member_and_its_count():
    """``target_namer``: without a budget each target its own label; under a budget a
    synthesized target is its strongest member's label, with "(merged target of N
    scatterers)" where it merges N > 1 of them, for merges of 1, 2 and 3."""
    from types import SimpleNamespace

    from conftest import small_quiet
    from rtsgeom.pipeline.plan import target_namer
    from rtsgeom.scene.objects import target_labels
    scene = small_quiet(targets=[{"range_m": 30.0 + 5 * k, "angle_deg": 2.0 * k}
                                 for k in range(4)])
    names = target_labels(scene, None, None)
    assert len(set(names)) == 4
    plain = target_namer(scene)
    assert [plain(k) for k in range(4)] == list(names)
    budget = SimpleNamespace(lead=lambda: [2, 3, 0], members=[(1, 2), (3,), (0, 1, 2)])
    named = target_namer(scene, budget=budget)
    assert [named(k) for k in range(3)] == [
        f"{names[2]} (merged target of 2 scatterers)", names[3],
        f"{names[0]} (merged target of 3 scatterers)"]


def test_a_calibration_file_without_a_pair_the_run_needs_is_refused_naming_it():
    """Loaded pairs that lack one the run needs: one SceneError naming the first missing pair,
    the pairs the file has and the command that calibrates it (one pair missing, or two)."""
    from rtsgeom.errors import SceneError
    from rtsgeom.pipeline.plan import calibrate_pairs
    have = {(0, 1): object()}
    for pairs in ([(0, 1), (1, 2)], [(1, 2), (2, 3)]):
        with pytest.raises(SceneError) as e:
            calibrate_pairs(None, None, pairs, None, loaded=have)
        assert str(e.value) == (
            f"calibration file: has no pair (1, 2) (it has [(0, 1)]): run `rtsgeom calibrate "
            f"SCENE --pair 1 2 --out DIR`")
    assert calibrate_pairs(None, None, [(0, 1)], None, loaded=have) == {(0, 1): have[(0, 1)]}


def _probe(angles_deg, clipped=0, model_deg=None):
    from rtsgeom.calibration.probes import FrontEndProbe
    n = len(angles_deg)
    return FrontEndProbe(np.radians(angles_deg), np.zeros(n), np.ones(n), clipped,
                         None if model_deg is None else np.radians(model_deg))


@pytest.mark.parametrize("clipped", [0, 7])
def test_target_pairs_refuses_a_lost_front_end_or_a_target_outside_the_span_whole(clipped):
    """``target_pairs``: the first front end the RuT does not detect (with the probe frame's
    clipping, if any), a target outside the measured span (either side), each one whole
    SceneError; a target exactly on the span's end is in its pair."""
    from conftest import assert_refused
    from rtsgeom.calibration.probes import clipping_note
    from rtsgeom.errors import SceneError
    from rtsgeom.pipeline.plan import target_pairs
    from rtsgeom.scene import TargetConfig
    setup = build_setup(small_noiseless())
    src = setup.scene.source
    lost = _probe([-4.0, np.nan, np.nan], clipped)
    t = TargetConfig(20.0, angle_rad=0.0)
    assert_refused(lambda: target_pairs(setup, lost, [t]),
                   f"{src}: rts.front_ends[1]: the RuT does not detect this front end alone "
                   "(blocked line of sight, or an echo far weaker than the noise"
                   f"{clipping_note(clipped)}): cannot synthesize angles with it", SceneError)
    probe = _probe([-4.0, 4.0 + 1e-3 * clipped])
    lo, hi = -4.0, 4.0 + 1e-3 * clipped
    assert target_pairs(setup, probe, [TargetConfig(20.0, angle_rad=np.radians(lo))],
                        "x")[0] == [(0, 1)]
    for a in (lo - 0.01, hi + 0.01):
        far = [t, TargetConfig(20.0, angle_rad=np.radians(a))]
        assert_refused(lambda: target_pairs(setup, probe, far, "frames[3].targets"),
                       f"{src}: frames[3].targets[1].angle_deg = {a:g}: must be within the "
                       f"measured span of the front ends [{lo:.4f}, {hi:.4f}] deg (no pair can "
                       "reach it)", SceneError)


def test_target_pairs_warns_of_each_pair_wider_than_the_angular_resolution():
    """A pair wider than the RuT's angular resolution (eq. 24) warns for each target on it,
    naming the target, the pair and both angles; a pair narrower does not."""
    from rtsgeom.geometry.farfield import angular_resolution_rad
    from rtsgeom.pipeline.plan import target_pairs
    from rtsgeom.scene import TargetConfig
    setup = build_setup(small_noiseless())
    res = np.degrees(angular_resolution_rad(setup.rut))
    wide, narrow = 1.5 * res, 0.5 * res
    probe = _probe([-narrow, 0.0, wide])
    targets = [TargetConfig(20.0, angle_rad=np.radians(a))
               for a in (0.5 * wide, -0.5 * narrow, 0.25 * wide)]
    pairs, warns = target_pairs(setup, probe, targets, lambda k: f"T{k}")
    assert pairs == [(1, 2), (0, 1), (1, 2)]
    assert warns == [f"T{k}: front ends (1, 2) are {wide:.2f} deg apart, more than the RuT's "
                     f"angular resolution {res:.2f} deg (eq. 24): expect two peaks"
                     for k in (0, 2)]


def test_plan_targets_refuses_a_budget_or_a_calibration_file_on_cells(sphere_scene):
    """Front ends on a sphere: ``rts.max_targets_per_channel`` and a calibration file are
    refused, each whole, before any measurement."""
    from conftest import assert_refused
    from rtsgeom.errors import SceneError
    from rtsgeom.pipeline.plan import plan_targets
    setup = build_setup(sphere_scene)
    src = sphere_scene.source
    assert_refused(lambda: plan_targets(setup, None, "exact", calibration={}),
                   f"{src}: --calibration: a calibration file holds pair calibrations; front "
                   "ends on a sphere are calibrated per channel by the run itself", SceneError)
    budget = build_setup(sphere_scene.evolve(
        rts=sphere_scene.rts.evolve(max_targets_per_channel=2)))
    assert_refused(lambda: plan_targets(budget, None, "exact"),
                   f"{src}: rts.max_targets_per_channel = 2: must be left out for front ends "
                   "on a sphere or targets in elevation (the budget merges targets on an "
                   "arc's pairs)", SceneError)


def test_an_uncalibrated_arc_plan_s_record_is_its_parts_whole():
    """``plan_targets`` without calibration: the record is mode, source, the probe's angles
    (deg) and gain corrections, zero offsets, no pairs and each target's realised plan, as
    ``probe_front_ends`` and ``program_pairs`` give them; the programme is theirs."""
    from rtsgeom.calibration.probes import probe_front_ends
    from rtsgeom.pipeline.plan import FixedCalibration, plan_targets, program_pairs, target_pairs
    setup = build_setup(small_noiseless())
    paths = exact_paths(setup)
    program, record, warns = plan_targets(setup, paths, "array-factor", calibrate=False)
    probe = probe_front_ends(setup, paths, setup.scene.seed)
    pairs, notes = target_pairs(setup, probe, setup.scene.targets)
    zero = np.zeros(setup.fe.count)
    want, realised, notes2 = program_pairs(setup, paths, "array-factor", setup.scene.targets,
                                           pairs, FixedCalibration(probe, {}, zero))
    assert record == {
        "mode": "array-factor", "source": "measured",
        "front_end_angles_deg": [float(x) for x in np.degrees(probe.angle_rad)],
        "gain_correction": [float(x) for x in probe.gain_correction],
        "channel_delay_offsets_s": [0.0] * setup.fe.count, "pairs": [], "targets": realised}
    assert warns == notes + notes2
    for f in ("target", "front_end", "delay_s", "doppler_hz", "amplitude"):
        assert np.array_equal(getattr(program, f), getattr(want, f)), f
