"""Several targets in one scene: the angle peaks of a cell, the two-target resolution against an
independent model, the association's rules on random target sets, the truth twin and the
resolution test."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rtsgeom.analysis.resolution import ResolutionStudy, min_separation
from rtsgeom.geometry import build_setup
from rtsgeom.pipeline.cells import shared_cell_warnings
from rtsgeom.pipeline.run import run_scene
from rtsgeom.radar import process
from rtsgeom.radar.association import associate
from rtsgeom.radar.peaks import angle_peaks, two_target_resolution
from rtsgeom.radar.steering import Steering
from rtsgeom.radar.truth import simulate_truth
from rtsgeom.scene import TargetConfig, load_scene

ROOT = Path(__file__).resolve().parents[2]
LAM = 3.9e-3


def _line(n: int, taper=None) -> Steering:
    """A uniform line of ``n`` elements at lambda/2, unweighted, Bartlett."""
    pos = (np.arange(n) - (n - 1) / 2)[:, None] * LAM / 2
    return Steering(np.ones(n, bool), pos, np.ones(n) if taper is None else taper, LAM,
                    np.array([n * LAM / 2]), pitch_m=LAM / 2)


def _snap(st: Steering, u_sources, amps=None) -> np.ndarray:
    k = 2 * np.pi / LAM * st.positions_m[:, 0]
    amps = np.ones(len(u_sources)) if amps is None else np.asarray(amps)
    return np.sum(amps[:, None] * np.exp(-1j * k[None] * np.asarray(u_sources)[:, None]), 0)


@pytest.mark.parametrize("n", [4, 6, 8, 12, 16])
def test_two_target_resolution_matches_an_independent_scan(n):
    """The smallest separation of two equal in-phase sources that gives two spectrum peaks,
    from a direct scan of the array factor (peak counting on a dense grid), within 0.0015 in u;
    for N = 8 it is the 19.4 deg the array is known for."""
    st = _line(n)
    k = 2 * np.pi / LAM * st.positions_m[:, 0]
    u = np.linspace(-1, 1, 4001)
    seps = np.arange(0.02, 1.0, 0.001)
    x = 2 * np.cos(np.outer(seps, k) / 2)  # (S, V)
    p = np.abs(x @ np.exp(1j * np.outer(k, u))) ** 2  # (S, U)
    two = np.zeros(seps.size, bool)
    for i, row in enumerate(p):  # the two strongest local maxima, one on either side
        peaks = np.flatnonzero((row[1:-1] > row[:-2]) & (row[1:-1] >= row[2:])) + 1
        top = peaks[np.argsort(row[peaks])[-2:]]
        two[i] = len(top) == 2 and np.prod(np.sign(u[top])) < 0
    first = seps[np.flatnonzero(~two)[-1] + 1]
    assert abs(two_target_resolution(st)[0] - first) < 0.0015
    if n == 8:
        assert abs(np.degrees(2 * np.arcsin(two_target_resolution(st)[0] / 2)) - 19.4) < 0.1


def test_a_taper_widens_the_resolution():
    plain = two_target_resolution(_line(8))[0]
    hann = two_target_resolution(_line(8, np.hanning(10)[1:-1]))[0]
    assert hann > 1.2 * plain


@pytest.mark.parametrize("sep", [0.35, 0.45, 0.6])
@pytest.mark.parametrize("ratio", [1.0, 0.7])
def test_two_sources_give_two_peaks_at_the_spectrum_maxima(sep, ratio):
    """Two resolved sources: two directions, each at a local maximum of the spectrum (a dense
    scan), the weaker's level its power ratio; threshold 1 keeps only the strongest."""
    st = _line(8)
    x = _snap(st, [-sep / 2, sep / 2], [1.0, ratio])[None]
    ang, lev = angle_peaks(st, x, 3, 0.5)
    got = np.sort(np.sin(ang[0][np.isfinite(ang[0])]))
    u = np.linspace(-1, 1, 200001)
    p = st.power(x[0], u[:, None])
    loc = np.flatnonzero((p[1:-1] > p[:-2]) & (p[1:-1] >= p[2:])) + 1
    loc = loc[p[loc] >= 0.25 * p.max()]  # amplitude at least half the strongest's
    ref = np.sort(u[loc])
    assert got.shape == ref.shape and np.allclose(got, ref, atol=2e-5)
    assert lev[0, 0] == 0 and np.all(lev[0, 1:][np.isfinite(lev[0, 1:])] <= 0)
    one, _ = angle_peaks(st, x, 3, 1.0)
    assert np.all(np.isnan(one[0, 1:]))
    assert one[0, 0] == st.search(x)[0]  # the strongest is the search's, bit for bit


def test_one_source_gives_one_peak():
    st = _line(8)
    ang, _ = angle_peaks(st, _snap(st, [0.2])[None], 4, 0.5)
    assert np.isfinite(ang[0, 0]) and np.all(np.isnan(ang[0, 1:]))


@settings(max_examples=300, deadline=None)
@given(st.lists(st.tuples(st.floats(0, 6), st.floats(-3, 3), st.floats(-1, 1)), min_size=1,
                max_size=6),
       st.lists(st.tuples(st.floats(0, 6), st.floats(-3, 3), st.floats(-1, 1)), max_size=8))
def test_association_rules_hold_on_random_sets(targets, detections):
    """No target gets a detection that lies nearer another target; a detection serves at most
    one target of its own; a merged target shares an owned detection within the gate and one
    angular cell; the assignment takes as many pairs as the rules allow."""
    t, d = np.array(targets), np.array(detections).reshape(-1, 3)
    scale = np.array([1.0, 1.0, 0.3])
    a = associate(t, d, scale, gate=2.0)
    dist = (np.sqrt((((d[None] - t[:, None]) / scale) ** 2).sum(-1)) if len(d)
            else np.zeros((len(t), 0)))
    own = [i for i in range(len(t)) if i in a.owner]  # the targets with a detection of their own
    assert all(a.status[i] in ("detected", "merged") for i in own)
    assert all(a.status[i] == "detected" for i in own if not a.merged_with[i])
    for i in own:
        j = a.detection[i]
        assert a.owner[j] == i
        assert np.all(dist[i, j] <= dist[:, j] + 1e-12)
        assert np.all(np.abs(d[j, :2] - t[i, :2]) <= 2.0 + 1e-12)
    assert len({a.detection[i] for i in own}) == len(own)
    for i, s in enumerate(a.status):
        if s == "merged":
            j = a.detection[i]
            assert np.all(np.abs(d[j, :2] - t[i, :2]) <= 2.0 + 1e-12)
            if a.owner[j] != i:  # served by another target's detection: one angular cell
                assert abs(d[j, 2] - t[i, 2]) <= scale[2] + 1e-12
            assert a.merged_with[i] and a.owner[j] in a.merged_with[i] + (i,)
        if s == "not_detected":
            assert a.detection[i] == -1
    # maximal: an unused detection allowed for a target without one of its own would have
    # been taken
    for i, s in enumerate(a.status):
        if i not in a.owner:
            for j in np.flatnonzero(a.owner < 0):
                ok = (np.all(np.abs(d[j, :2] - t[i, :2]) <= 2.0)
                      and np.all(dist[i, j] <= dist[:, j]))
                assert not ok


def _two_target_bench(angle_deg: float):
    scene = load_scene(ROOT / "scenes" / "crossing.toml")
    tg = tuple(TargetConfig(range_m=20.0, velocity_mps=0.0, rcs_dbsm=10.0,
                            angle_rad=float(np.radians(s * angle_deg)), elevation_rad=0.0)
               for s in (-1, 1))
    return dataclasses.replace(scene, scenario=None, targets=tg)


@pytest.mark.slow
@pytest.mark.parametrize("angle_deg", [4.0, 10.0])
def test_two_targets_in_one_cell_are_never_given_the_far_detection(angle_deg):
    """The crossing bench, two targets at +-a deg at 20 m in one cell: the RTS's one
    detection serves both ('merged'), none is matched to a detection nearer the other; the
    truth twin resolves +-10 deg into two detections near +-7.75 deg (the 8-element array's
    two peaks) and merges +-4 deg; both situations are warned about before the run."""
    scene = _two_target_bench(angle_deg)
    r = run_scene(scene)
    assert [m["status"] for m in r.matches] == ["merged", "merged"]
    assert r.matches[0]["merged_with"] == [1]
    assert any("share a range-Doppler cell" in w for w in r.warnings)
    truth = [m["truth"] for m in r.matches]
    if angle_deg == 10.0:
        assert [m["truth_status"] for m in r.matches] == ["detected", "detected"]
        assert abs(truth[0]["angle_deg"] + 7.75) < 0.3 and abs(truth[1]["angle_deg"] - 7.75) < 0.3
    else:
        assert truth == [None, None]


@pytest.mark.parametrize("radius_m", [3.0, 6.0])
@pytest.mark.parametrize("angle_deg", [-4.0, 3.0])
def test_one_target_far_beyond_the_fraunhofer_distance_agrees_with_the_truth(radius_m,
                                                                             angle_deg):
    scene = load_scene(ROOT / "scenes" / "crossing.toml")
    tg = (TargetConfig(range_m=30.0, velocity_mps=1.0, rcs_dbsm=10.0,
                       angle_rad=float(np.radians(angle_deg)), elevation_rad=0.0),)
    scene = dataclasses.replace(scene, scenario=None, targets=tg)
    scene = scene.evolve(rts=scene.rts.evolve(arc_radius_m=radius_m))
    m = run_scene(scene).matches[0]
    assert m["status"] == m["truth_status"] == "detected"
    assert abs(m["vs_truth"]["angle_deg"]) < 0.02


@pytest.mark.parametrize("angle_deg", [-20.0, 0.0, 25.0])
@pytest.mark.parametrize("range_m", [15.0, 30.0])
def test_the_truth_twin_sees_a_point_target_where_it_is(angle_deg, range_m):
    """A real point target: detected at its range within a quarter bin, its velocity within
    its f_mid / f_c reading, its angle within the RuT's own near-field bias (below 0.03 deg
    at 15 m for the AWR1843's Tx/Rx groups, falling as 1/R, and the TDM compensation's)."""
    scene = dataclasses.replace(load_scene(ROOT / "scenes" / "crossing.toml"), scenario=None)
    setup = build_setup(scene)
    t = TargetConfig(range_m=range_m, velocity_mps=2.0, rcs_dbsm=10.0,
                     angle_rad=float(np.radians(angle_deg)), elevation_rad=0.0)
    _, cube = simulate_truth(setup, [t])
    _, det = process(cube)
    radar = scene.radar
    assert len(det) == 1
    assert abs(det.range_m[0] - range_m) < 0.25 * radar.range_resolution_m
    f_mid = radar.f_c_hz + radar.slope_hz_per_s * (
        radar.adc_start_s + 0.5 * (radar.samples_per_chirp - 1) / radar.adc_rate_hz)
    assert abs(det.velocity_mps[0] - 2.0 * f_mid / radar.f_c_hz) < 0.05 * \
        radar.velocity_resolution_mps
    # the near-field bias, plus the TDM compensation with an interpolated Doppler (~0.005 deg)
    assert abs(det.angle_deg[0] - angle_deg) < 0.03 * 15.0 / range_m + 0.005


def test_no_warning_for_targets_in_different_cells():
    scene = load_scene(ROOT / "scenes" / "diewald2022.toml")
    assert shared_cell_warnings(build_setup(scene), scene.targets) == []


def test_min_separation_is_the_start_of_the_resolved_tail():
    assert min_separation([1, 2, 3, 4, 5], [False, True, False, True, True]) == 4
    assert min_separation([1, 2, 3], [True, True, True]) == 1
    assert min_separation([1, 2, 3], [True, True, False]) is None


@pytest.mark.slow
def test_resolution_study_truth_matches_the_array():
    """On the crossing bench's 8-element lambda/2 row, unweighted: the truth twin resolves two
    equal in-phase targets from the array's own 19.4 deg (on a 0.5-deg grid: 19.5), and
    anti-phase targets sooner; the RTS's minimum is reported beside it."""
    scene = load_scene(ROOT / "scenes" / "crossing.toml")
    res = ResolutionStudy(separations_deg=tuple(np.arange(16.0, 24.01, 0.5)),
                          phases_deg=(0.0, 180.0))(scene)
    ms = res.min_separation_deg
    assert abs(ms["truth"]["0"] - 19.4) <= 1.0
    assert ms["truth"]["180"] < ms["truth"]["0"]
    assert ms["rts"]["0"] is not None
    t = res.table
    assert set(t["source"]) == {"truth", "rts"} and len(t["resolved"]) == 17 * 2 * 2
    ok = t["resolved"].astype(bool)
    assert np.all(np.isfinite(t["angle_1_deg"][ok]) & np.isfinite(t["angle_2_deg"][ok]))


def test_two_sources_give_two_peaks_in_2d():
    """A 4 x 4 grid at lambda/2 (2-D beamformer): two sources, two peaks, each at a local
    maximum of a dense 2-D scan of the spectrum (within its 2e-3 grid step)."""
    g = (np.arange(4) - 1.5) * LAM / 2
    pos = np.stack(np.meshgrid(g, g, indexing="ij"), -1).reshape(-1, 2)
    st2 = Steering(np.ones(16, bool), pos, np.ones(16), LAM, np.array([2 * LAM, 2 * LAM]))
    src = np.array([[-0.35, 0.0], [0.3, 0.2]])
    k = 2 * np.pi / LAM
    x = np.exp(-1j * k * src @ pos.T).sum(0)[None]
    ang, lev = angle_peaks(st2, x, 2, 0.5)
    u_got = st2.directions(ang[0])
    axis = np.arange(-1, 1.0001, 2e-3)
    uu = np.stack(np.meshgrid(axis, axis, indexing="ij"), -1).reshape(-1, 2)
    p = st2.power(x[0], uu).reshape(axis.size, axis.size)
    from scipy import ndimage
    peak = (p == ndimage.maximum_filter(p, 3)) & (p >= 0.25 * p.max())
    ref = uu[peak.ravel()]
    assert len(ref) == 2
    for u in u_got:
        assert np.min(np.linalg.norm(ref - u, axis=1)) < 3e-3
    assert np.all(lev[0] <= 0)


def test_a_smoothed_estimator_reports_both_sources():
    """Capon with spatial smoothing on 8 elements: two sources of different phase give two
    directions, each within 0.5 deg of a source (the smoothing decorrelates them)."""
    st = dataclasses.replace(_line(8), estimator="capon", subarray=5)
    x = _snap(st, [-0.3, 0.25], [1.0, 0.8 * np.exp(1j * 1.0)])[None]
    ang, _ = angle_peaks(st, x, 2, 0.5)
    got = np.sort(np.degrees(ang[0]))
    ref = np.sort(np.degrees(np.arcsin([-0.3, 0.25])))
    assert np.all(np.isfinite(got)) and np.allclose(got, ref, atol=0.5)


@pytest.mark.parametrize("kwargs, field", [
    ({"centre_deg": float("nan")}, "centre_deg"), ({"range_m": True}, "range_m"),
    ({"separations_deg": (0.0, 10.0)}, "separations_deg"), ({"phases_deg": ()}, "phases_deg"),
    ({"velocity_mps": float("inf")}, "velocity_mps"), ({"amplitudes": "best"}, "amplitudes")])
def test_bad_resolution_arguments_name_the_field(kwargs, field):
    from rtsgeom.errors import ParameterError
    with pytest.raises(ParameterError, match=field):
        ResolutionStudy(**kwargs)


def test_the_numbers_option_reads_grids_and_lists_and_refuses_the_rest():
    import argparse
    from rtsgeom.cli._common import numbers
    parse = numbers(1e-3, 120.0, 1000, "deg", "10,20")
    assert parse("2:30:1") == tuple(float(x) for x in range(2, 31))
    assert parse("10,90.5") == (10.0, 90.5)
    phases = numbers(-360.0, 360.0, 36, "deg", "0,90")
    assert phases("0,90,-0") == (0.0, 90.0, 0.0) and str(phases("-0")[0]) == "0.0"
    for bad in ("1:200:1", "5:1:1", "1:2:0", "a,b", "", "nan", "0.1:1000:1e-5"):
        with pytest.raises(argparse.ArgumentTypeError):
            parse(bad)


def test_the_resolution_command_writes_its_three_files(tmp_path):
    import csv
    import json
    from rtsgeom.cli import main
    out = tmp_path / "res"
    assert main(["resolution", str(ROOT / "scenes" / "crossing.toml"), "--out", str(out),
                 "--separations-deg", "12,26", "--phases-deg", "0", "--quiet"]) == 0
    s = json.loads((out / "summary.json").read_text())
    assert set(s["min_separation_deg"]) == {"truth", "rts"}
    assert s["min_separation_deg"]["truth"]["0"] == 26.0  # 12 deg merges, 26 resolves
    rows = list(csv.DictReader((out / "resolution.csv").open()))
    assert len(rows) == 4 and {r["source"] for r in rows} == {"truth", "rts"}
    assert (out / "resolution.png").stat().st_size > 0


def test_a_scene_without_static_targets_runs_and_an_empty_frame_associates():
    """crossing.toml has only a drive: `run` simulates its bench with no target (the
    association's points once failed to reshape an empty set); a frame without detections
    leaves every target not detected."""
    from rtsgeom.pipeline.matching import detection_points, target_points
    scene = load_scene(ROOT / "scenes" / "crossing.toml")
    assert run_scene(scene).matches == []
    assert target_points([], 1).shape == (0, 3) and target_points([], 2).shape == (0, 4)
    empty = associate(target_points(_two_target_bench(4.0).targets, 1), np.zeros((0, 3)),
                      [1.0, 1.0, 0.3])
    assert empty.status == ("not_detected", "not_detected")
    from rtsgeom.radar.processing import Detections
    none = Detections(*(np.zeros(0),) * 5, np.zeros(0, int), np.zeros(0, int))
    assert detection_points(none, 2).shape == (0, 4)


@pytest.mark.parametrize("estimator, subarray", [("bartlett", 0), ("capon", 5), ("music", 5)])
def test_a_batch_without_candidates_refines_to_nothing(estimator, subarray):
    """``peaks._refine_1d`` of snapshots none of which has a grid candidate (every one NaN):
    no spectrum row is evaluated and every refined direction and value is NaN, for the plain
    and the smoothed estimators; with one candidate its row alone is refined."""
    from rtsgeom.radar import peaks
    st = dataclasses.replace(_line(8), estimator=estimator, subarray=subarray)
    x = np.stack([_snap(st, [-0.3, 0.25], [1.0, 0.8 * np.exp(1j * 1.0)]), _snap(st, [0.1])])
    u, val = peaks._refine_1d(st, x, np.full((2, 5), np.nan))
    assert u.shape == (2, 5, 1) and val.shape == (2, 5)
    assert np.isnan(u).all() and np.isnan(val).all()
    assert peaks._spectrum_rows(st, x[:0], np.zeros((0, 3))).shape == (0, 3)
    cand = np.full((2, 5), np.nan)
    cand[1, 2] = np.arcsin(0.1) + np.radians(0.2)
    u, val = peaks._refine_1d(st, x, cand)
    assert np.isfinite(u[1, 2, 0]) and abs(u[1, 2, 0] - 0.1) < 1e-5
    assert np.isnan(np.delete(val.ravel(), 7)).all()


@pytest.mark.parametrize("estimator, subarray", [("bartlett", 0), ("capon", 5)])
def test_the_1d_refinement_lands_on_a_lone_source_between_its_zoom_steps(estimator, subarray):
    """One noiseless source at angles off the zoom grids (0.005 deg, then 1e-4 deg around the
    candidate): the parabola through the finest three points moves the peak towards the source,
    to within 1e-8 in u (a parabola fitted the wrong way would leave up to 3e-6)."""
    from rtsgeom.radar import peaks
    st = dataclasses.replace(_line(8), estimator=estimator, subarray=subarray)
    true_deg = np.array([-23.45678, -3.21037, 0.00003, 7.00007, 18.76543])
    u_true = np.sin(np.radians(true_deg))
    x = np.stack([_snap(st, [u]) for u in u_true])
    cand = np.radians(true_deg + 0.0231)[:, None]  # a grid candidate 0.0231 deg off
    u, _ = peaks._refine_1d(st, x, cand)
    assert np.abs(u[:, 0, 0] - u_true).max() < 1e-8
