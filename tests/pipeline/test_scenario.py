"""Scenario playback: trajectories against closed forms, the [scenario] section's checks, a
crossing drive against the straight-line geometry and the switched baseline's staircase, a
static scenario against `run`, and the `play` command's output folder."""

from __future__ import annotations

import csv
import json
import tomllib
from pathlib import Path

import numpy as np
import pytest
from scipy.constants import c

import rtsgeom
from rtsgeom.cli import main
from rtsgeom.errors import ParameterError, SceneError
from rtsgeom.analysis.playback import PROGRAMME_COLUMNS, TRACK_COLUMNS
from rtsgeom.scene import TargetConfig, parse_scene
from rtsgeom.scene.scenario import frame_times, trajectory

CROSSING = Path(__file__).resolve().parents[2] / "scenes" / "crossing.toml"
DEG = np.pi / 180


def crossing_doc(**scenario) -> dict:
    doc = tomllib.loads(CROSSING.read_text())
    doc["scenario"].update(scenario)
    return doc


def scene_of(doc) -> rtsgeom.Scene:
    return parse_scene(doc, "scenario.toml")


# ------------------------------------------------------------------------------------------
# Trajectories
# ------------------------------------------------------------------------------------------


def test_a_straight_crossing_follows_its_closed_form():
    """20 m ahead, -3 m to +3 m in 2 s: x = v t', y = x0 with t' = t - 1 s; the range
    sqrt(x0^2 + (v t')^2), the radial velocity v^2 t' / r, the azimuth atan2(v t', x0)."""
    x0, v = 20.0, 3.0
    r0, a0 = np.hypot(x0, 3.0), np.arctan2(3.0, x0)
    t = np.linspace(0.0, 2.0, 41)
    sp = trajectory([[0.0, r0, -a0, 0.0], [2.0, r0, a0, 0.0]], t)
    tc = t - 1.0
    r = np.sqrt(x0 ** 2 + (v * tc) ** 2)
    np.testing.assert_allclose(sp.range_m, r, rtol=0, atol=1e-12)
    np.testing.assert_allclose(sp.velocity_mps, v ** 2 * tc / r, rtol=0, atol=1e-12)
    np.testing.assert_allclose(sp.azimuth_rad, np.arctan2(v * tc, x0), rtol=0, atol=1e-12)
    np.testing.assert_allclose(sp.elevation_rad, 0.0, atol=1e-15)
    # the radial velocity is the derivative of the range (central differences)
    dr = np.gradient(sp.range_m, t)
    np.testing.assert_allclose(sp.velocity_mps[1:-1], dr[1:-1], atol=2e-3)


def test_segments_join_at_waypoints_and_the_target_rests_outside_them():
    """A cut-in with a climb: three waypoints; the positions at the waypoints' times are the
    waypoints, the path is continuous, straight with constant speed on each segment; before
    the first and after the last the target stands still there."""
    wp = np.array([[0.0, 30.0, 10 * DEG, 0.0], [1.0, 25.0, 2 * DEG, 1 * DEG],
                   [3.0, 24.0, -1 * DEG, 0.0]])
    sp = trajectory(wp, wp[:, 0])
    np.testing.assert_allclose(sp.range_m, wp[:, 1], atol=1e-12)
    np.testing.assert_allclose(sp.azimuth_rad, wp[:, 2], atol=1e-12)
    np.testing.assert_allclose(sp.elevation_rad, wp[:, 3], atol=1e-12)
    t = np.linspace(0.0, 3.0, 301)
    p = trajectory(wp, t).position_m
    step = np.linalg.norm(np.diff(p, axis=0), axis=1)
    assert step.max() < 2 * np.median(step[:100])  # continuous: no jump at t = 1 s
    seg1 = p[(t > 1.0) & (t < 3.0)]  # collinear: second differences vanish at constant speed
    np.testing.assert_allclose(np.diff(seg1, 2, axis=0), 0.0, atol=1e-9)
    rest = trajectory(wp, [-1.0, 5.0])
    np.testing.assert_allclose(rest.velocity_mps, 0.0)
    np.testing.assert_allclose(rest.range_m, [30.0, 24.0], atol=1e-12)
    one = trajectory(wp[:1], t[:5])
    np.testing.assert_allclose(one.range_m, 30.0) and np.testing.assert_allclose(
        one.velocity_mps, 0.0)


def test_frame_times_cover_the_duration():
    np.testing.assert_allclose(frame_times(0.1, 2.0), np.arange(21) * 0.1)
    assert frame_times(0.3, 1.0).size == 4 and frame_times(0.5, 0.0).size == 1


# ------------------------------------------------------------------------------------------
# The [scenario] section's checks
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("change, field, allowed", [
    ({"waypoints": [[0.0, 20.0]]}, "scenario.targets[0].waypoints", "rows"),
    ({"waypoints": [[0.0, 20.0, 95.0]]}, "scenario.targets[0].waypoints[0][2]", "[-90, 90]"),
    ({"waypoints": [[0.5, 20.0, 0.0], [2.0, 20.0, 1.0]]}, "scenario.targets[0].waypoints[0][0]",
     "0"),
    ({"waypoints": [[0.0, 20.0, 0.0], [0.0, 20.0, 1.0], [2.0, 20, 1]]},
     "scenario.targets[0].waypoints[1][0]", "increase strictly"),
    ({"waypoints": [[0.0, 20.0, 0.0], [1.5, 20.0, 1.0]]}, "scenario.targets[0].waypoints[1][0]",
     "scenario.duration_s"),
    ({"waypoints": [[0.0, 20.0, 0.0], [1.0, 60.0, 1.0], [2.0, 20, 1]]},
     "scenario.targets[0].waypoints[0]", "every range <"),
    ({"waypoints": [[0.0, 20.0, 0.0], [2.0, 20.0, 0.0, 5.0]]}, "radar.elevation_processing",
     "true"),
])
def test_bad_waypoints_name_the_field(change, field, allowed):
    doc = crossing_doc()
    doc["scenario"]["targets"][0].update(change)
    with pytest.raises(SceneError) as exc:
        scene_of(doc)
    msg = str(exc.value)
    assert f"{field} = " in msg and allowed in msg.split(": must be ")[1], msg


def test_scenario_limits_frames_and_velocity():
    with pytest.raises(SceneError, match=r"scenario.frame_period_s = .*at most 100000"):
        scene_of(crossing_doc(frame_period_s=1e-4, duration_s=20.0))
    doc = crossing_doc()  # 40 m/s radially: beyond the radar's unambiguous velocity
    doc["scenario"]["targets"][0]["waypoints"] = [[0.0, 10.0, 0.0], [2.0, 30.0, 0.0]]
    doc["scenario"]["targets"][0]["waypoints"][1][0] = 0.5
    doc["scenario"]["duration_s"] = 0.5
    with pytest.raises(SceneError, match=r"waypoints\[0\] = .*radial velocity"):
        scene_of(doc)


def test_a_scene_with_a_scenario_evolves_and_loads_in_si():
    scene = rtsgeom.load_scene(CROSSING)
    tg = scene.scenario.targets[0]
    assert len(tg.waypoints[0]) == 4 and tg.waypoints[1][2] == pytest.approx(
        np.arctan2(3.0, 20.0), abs=1e-9)
    assert scene.evolve(seed=3).scenario == scene.scenario  # re-checked in file units


# ------------------------------------------------------------------------------------------
# Playing a drive
# ------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def crossing():
    """The bundled crossing at 11 frames (0.2 s apart), the synthesis and the baseline."""
    scene = scene_of(crossing_doc(frame_period_s=0.2))
    return scene, rtsgeom.play(scene)


def test_a_crossing_plays_on_the_straight_line_within_the_spec(crossing):
    """Set-points follow the geometry to 1e-3, no lost or split frame, the azimuth within
    0.05 deg in every frame, and at least one hand-over between pairs on the way."""
    scene, res = crossing
    t = res.time_s
    assert t.size == 11
    tc = t - 1.0
    r = np.sqrt(20.0 ** 2 + (3.0 * tc) ** 2)
    np.testing.assert_allclose(res.set["range_m"][:, 0], r, atol=1e-3)
    np.testing.assert_allclose(res.set["azimuth_deg"][:, 0], np.degrees(np.arctan2(3 * tc, 20)),
                               atol=1e-3)
    np.testing.assert_allclose(res.set["velocity_mps"][:, 0], 9 * tc / r, atol=1e-3)
    s = res.summary()
    assert s["frames"] == 11 and s["lost_frames"] == 0 and s["split_frames"] == 0
    err = np.abs(res.angle_error_deg)
    assert np.all(err < 0.05), err.ravel()
    assert s["handovers"] >= 1 and s["handover_jump_deg"] < 0.05
    # the detected range and velocity follow too (within a range / Doppler bin)
    assert np.all(np.abs(res.detected["range_m"] - res.set["range_m"])
                  < scene.radar.range_resolution_m)
    assert np.all(np.abs(res.detected["velocity_mps"] - res.set["velocity_mps"])
                  < scene.radar.velocity_resolution_mps)


def test_the_track_keeps_its_range_where_two_bins_carry_nearly_equal_power(crossing):
    """The crossing's frames at 0.6 s and 1.4 s sit midway between two range bins (margin 1.1
    over the neighbour): the pair's design is the same at both bins, so the planner keeps J at
    its calibrated delay instead of moving it by one IF period (one range bin), which put the
    detected range 73 and 42 mm off. summary.json carries the range and velocity errors."""
    scene, res = crossing
    s = res.summary()
    r_err = np.abs(res.detected["range_m"] - res.set["range_m"])
    v_err = np.abs(res.detected["velocity_mps"] - res.set["velocity_mps"])
    assert s["range_error_m"]["max"] == pytest.approx(r_err.max(), rel=1e-12)
    assert s["range_error_m"]["p95"] == pytest.approx(np.percentile(r_err, 95), rel=1e-12)
    assert s["velocity_error_mps"]["max"] == pytest.approx(v_err.max(), rel=1e-12)
    assert s["targets"][0]["range_error_m"]["max"] == s["range_error_m"]["max"]
    assert s["range_error_m"]["max"] < 0.01, r_err.ravel()  # a bin is 150 mm
    assert s["velocity_error_mps"]["max"] < 0.05 * scene.radar.velocity_resolution_mps
    assert set(s["baseline"]) >= {"range_error_m", "velocity_error_mps"}


def test_the_programme_carries_each_target_on_two_adjacent_channels(crossing):
    """Per frame two adjacent channels at the target's delay (2 R / c0 less the arc, plus
    the channel's calibrated offset) and Doppler 2 f_c v / c0."""
    scene, res = crossing
    p = res.programme_dataframe()
    assert list(p.columns) == list(PROGRAMME_COLUMNS)
    for f, rows in p.groupby("frame"):
        assert len(rows) == 2 and np.diff(rows["channel"].to_numpy()).item() == 1
        v = res.set["velocity_mps"][f, 0]
        np.testing.assert_allclose(rows["doppler_hz"], 2 * scene.radar.f_c_hz * v / c,
                                   rtol=1e-12)
        tau = 2 * (res.set["range_m"][f, 0] - scene.rts.arc_radius_m) / c
        off = np.asarray(res.calibration["channel_delay_offsets_s"])[rows["channel"]]
        assert abs(rows["delay_s"].iloc[0] - tau - off[0]) < 1e-15  # channel I: exact
        # J: its calibrated offset, or a period of the IF phase away where the bin is
        # ambiguous (pipeline.pair.plan_pair), to the quantisation of the delay
        pair = [c for c in res.calibration["pairs"] if c["pair"] == list(rows["channel"])][0]
        miss = rows["delay_s"].iloc[1] - tau - off[1]
        m = round(miss / pair["period_s"])
        assert m in (-1, 0, 1) and abs(miss - m * pair["period_s"]) < 0.05 * pair["period_s"]


def test_the_switched_baseline_shows_its_staircase(crossing):
    """Each target on its nearest front end: the detected angle steps between the front
    ends' own angles and the error reaches about half the spacing (8 deg)."""
    _, res = crossing
    base = res.baseline
    assert base is not None and base.mode == "nearest"
    levels = np.unique(np.round(base.detected["azimuth_deg"][:, 0], 1))
    assert 2 <= levels.size <= 5
    worst = base.summary()["angle_error_deg"]["max"]
    assert 0.3 * 8.0 < worst < 0.7 * 8.0
    assert base.summary()["handover_jump_deg"] > 0.5 * 8.0


def test_the_switched_baseline_keeps_a_target_midway_between_two_front_ends():
    """A target at the exact midpoint of two front ends (4 deg between 0 and 8 deg) whose set
    azimuth rounds to 4 deg +- 1 ulp frame by frame stays on one front end: no hand-over
    (``argmin`` alternated: 8 hand-overs and 8-deg jumps). Over a grid of midpoints and
    roundings the tie goes to the lower index; a front end nearer by 1e-6 rad wins."""
    from rtsgeom.rts.channels import nearest_front_ends
    doc = crossing_doc(duration_s=2.0, frame_period_s=0.1)
    doc["scenario"]["targets"][0]["waypoints"] = [[0.0, 35.0, 4.0], [5.0, 15.0, 4.0]]
    res = rtsgeom.Playback(amplitudes="nearest")(scene_of(doc))
    assert res.summary()["handovers"] == 0
    assert {c for c in res.channels.ravel()} == {(2,)}
    az = np.radians(np.arange(-16.0, 16.1, 8.0))
    for k in range(az.size - 1):
        mid = 0.5 * (az[k] + az[k + 1])
        a = mid + np.arange(-8, 9) * np.spacing(mid)  # roundings of the midpoint
        np.testing.assert_array_equal(nearest_front_ends(az, a), k)
        assert nearest_front_ends(az, mid + 1e-6)[0] == k + 1
        assert nearest_front_ends(az, mid - 1e-6)[0] == k


def test_a_static_scenario_reproduces_run():
    """A target at rest in [scenario] plays frame 0 exactly as `run` runs it in [[targets]]
    (the same calibration, programme, noise and detection); later frames the same programme.
    On the full chain to an ulp; on the fast path within its tolerance of the full chain."""
    doc = crossing_doc(duration_s=0.1, frame_period_s=0.1)
    doc["radar"]["snr_db"] = 20.0
    doc["scenario"]["targets"][0]["waypoints"] = [[0.0, 20.0, 3.0]]
    scene = scene_of(doc)
    res = rtsgeom.play(scene, baseline=False, chain="full")
    fast = rtsgeom.play(scene, baseline=False)
    static = scene.evolve(targets=(TargetConfig(range_m=20.0, angle_rad=3 * DEG),),
                          scenario=None)
    run = rtsgeom.run_scene(static)
    m = run.matches[0]["detection"]
    # the set azimuth comes through atan2 of the position: equal to an ulp, not bit for bit
    for r, tol in ((res, 1e-9), (fast, 1e-6)):
        assert r.detected["range_m"][0, 0] == pytest.approx(m["range_m"], abs=tol)
        assert r.detected["azimuth_deg"][0, 0] == pytest.approx(m["angle_deg"], abs=tol)
        assert r.detected["velocity_mps"][0, 0] == pytest.approx(m["velocity_mps"], abs=tol)
    assert fast.summary()["chain"] == {"asked": "fast", "full_chain_frames": 0, "reasons": {}}
    assert abs(m["angle_deg"] - 3.0) > 1e-6  # noise: a number worth reproducing
    prog = res.programme[res.programme[:, 0] == 0]
    np.testing.assert_array_equal(prog[:, 2], run.program.front_end)
    np.testing.assert_array_equal(prog[:, 3], run.program.delay_s)
    np.testing.assert_allclose(prog[:, 5], np.abs(run.program.amplitude), rtol=1e-12)
    np.testing.assert_allclose(prog[:, 6], np.angle(run.program.amplitude), atol=1e-12)
    np.testing.assert_array_equal(res.programme[res.programme[:, 0] == 1][:, 1:], prog[:, 1:])
    assert res.calibration["channel_delay_offsets_s"] == run.calibration[
        "channel_delay_offsets_s"]


def test_play_refuses_a_scene_without_a_scenario():
    scene = rtsgeom.load_scene(CROSSING).evolve(scenario=None)
    with pytest.raises(ParameterError, match=r"no \[scenario\]"):
        rtsgeom.play(scene)
    with pytest.raises(ParameterError, match="amplitudes"):
        rtsgeom.Playback(amplitudes="best")


def test_play_writes_one_whole_folder(tmp_path):
    """`rtsgeom play`: programme.csv, tracks.csv, summary.json, playback.png; tracks empty
    where lost; a scene without a scenario writes nothing (exit 2)."""
    doc = CROSSING.read_text().replace("frame_period_s = 0.1 ", "frame_period_s = 1.0 ")
    src = tmp_path / "drive.toml"
    src.write_text(doc)
    out = tmp_path / "out"
    assert main(["play", str(src), "--out", str(out), "--quiet", "--amplitudes", "nearest"]) == 0
    assert sorted(p.name for p in out.iterdir() if not p.name.startswith(".")) == [
        "playback.png", "programme.csv", "summary.json", "tracks.csv"]
    tracks = list(csv.DictReader((out / "tracks.csv").open()))
    assert list(tracks[0]) == list(TRACK_COLUMNS) and len(tracks) == 3
    prog = list(csv.DictReader((out / "programme.csv").open()))
    assert len(prog) == 3 and {r["channel"] for r in prog} <= {"0", "1", "2", "3", "4"}
    s = json.loads((out / "summary.json").read_text())
    assert s["frames"] == 3 and s["mode"] == "nearest" and set(s["angle_error_deg"]) == {
        "max", "p95"} and "tolerance" not in s
    bare = tmp_path / "bare.toml"
    bare.write_text(doc.split("[scenario]")[0])
    assert main(["play", str(bare), "--out", str(tmp_path / "none"), "--quiet"]) == 2
    assert not (tmp_path / "none").exists()


def test_tracks_are_empty_where_lost(crossing):
    """A lost frame's detected columns are empty fields in tracks.csv, the set ones not."""
    import dataclasses
    _, res = crossing
    det = {k: v.copy() for k, v in res.detected.items()}
    for v in det.values():
        v[3, 0] = np.nan
    lost = dataclasses.replace(res, detected=det, baseline=None)
    rows = list(csv.DictReader(lost.tracks_csv().splitlines()))
    assert rows[3]["azimuth_deg"] == rows[3]["range_m"] == rows[3]["velocity_mps"] == ""
    assert float(rows[3]["set_azimuth_deg"]) == res.set["azimuth_deg"][3, 0]
    assert lost.summary()["lost_frames"] == 1 and "1 lost" in repr(lost)


def test_forked_workers_play_the_same_frames():
    """Frames played in two forked processes: the same tracks and programme, bit for bit."""
    doc = crossing_doc(frame_period_s=0.5)
    doc["radar"]["snr_db"] = 20.0
    scene = scene_of(doc)
    one = rtsgeom.play(scene, amplitudes="nearest")
    two = rtsgeom.play(scene, amplitudes="nearest", workers=2)
    np.testing.assert_array_equal(one.programme, two.programme)
    for k in one.detected:
        np.testing.assert_array_equal(one.detected[k], two.detected[k])
    assert one.summary() == two.summary()


def test_drive_tolerance_through_the_tolerance_engine():
    """Mounting errors over the whole drive: the drive's azimuths are the engine's set-points
    (pair by pair), a perfect setup stays on the nominal design, and the yield falls as the
    errors grow, the calibration keeping more setups within the spec."""
    scene = rtsgeom.load_scene(CROSSING)
    exact = rtsgeom.drive_tolerance(scene, sigma_mm=(0.0, 0.0, 0.0), draws=10)
    sets = np.sort(np.concatenate([m.set_rad for m in exact.model.sets]))
    times = scene.scenario.frame_times()
    want = trajectory(scene.scenario.targets[0].waypoints, times).azimuth_rad
    np.testing.assert_allclose(sets, np.sort(want), atol=1e-12)
    assert np.abs(exact.arc_worst("calibrated")).max() < 1e-3
    small = rtsgeom.drive_tolerance(scene, sigma_mm=(0.05, 0.05, 0.05), draws=300, spec_deg=0.05)
    large = rtsgeom.drive_tolerance(scene, sigma_mm=(0.5, 0.5, 0.5), draws=300, spec_deg=0.05)
    assert small.yield_("calibrated") > large.yield_("calibrated")
    assert large.yield_("calibrated") >= large.yield_("uncalibrated")
    assert np.median(np.abs(large.arc_worst("uncalibrated"))) > np.median(
        np.abs(small.arc_worst("uncalibrated")))


@pytest.mark.slow
def test_play_animates_and_adds_the_drive_tolerance(tmp_path):
    """`--gif`: one animation frame per drive frame; `--tolerance-draws`: the drive's yield
    in summary.json with the sigma and the pairs the drive visits."""
    src = tmp_path / "drive.toml"
    src.write_text(CROSSING.read_text().replace("frame_period_s = 0.1 ", "frame_period_s = 1.0 "))
    out = tmp_path / "out"
    assert main(["play", str(src), "--out", str(out), "--quiet", "--amplitudes", "nearest",
                 "--gif", "--tolerance-draws", "50", "--sigma-mm", "0.2", "0.2", "0"]) == 0
    from PIL import Image
    assert Image.open(out / "playback.gif").n_frames == 3
    t = json.loads((out / "summary.json").read_text())["tolerance"]
    assert t["draws"] == 50 and t["sigma_mm"] == [0.2, 0.2, 0.0]
    assert t["pairs"] and 0.0 <= t["yield"]["calibrated"] <= 1.0


@pytest.mark.parametrize("snr_db", [None, 12.0])
def test_the_fast_path_plays_the_full_chains_drive(snr_db):
    """Three targets crossing the arc (one passing another's cell), five frames: the tracks
    and the truth twin's on the fast path within 1 mm, 1e-3 m/s and 1e-3 deg of the full
    chain's, the same statuses and splits; the summary says which chain ran."""
    doc = crossing_doc(duration_s=0.4, frame_period_s=0.1)
    t0 = doc["scenario"]["targets"][0]
    doc["scenario"]["targets"] = [
        t0, dict(t0, waypoints=[[0.0, 20.2, 6.0], [0.4, 20.2, -2.0]]),
        dict(t0, waypoints=[[0.0, 26.0, -4.0], [0.4, 26.0, 4.0]])]
    if snr_db is not None:
        doc["radar"]["snr_db"] = snr_db
    scene = scene_of(doc)
    fast, full = (rtsgeom.play(scene, baseline=False, chain=c) for c in ("fast", "full"))
    for key, tol in (("range_m", 1e-3), ("velocity_mps", 1e-3), ("azimuth_deg", 1e-3)):
        for a, b in ((fast.detected, full.detected), (fast.truth, full.truth)):
            np.testing.assert_array_equal(np.isnan(a[key]), np.isnan(b[key]))
            np.testing.assert_allclose(a[key], b[key], rtol=0, atol=tol)
    assert np.isfinite(fast.detected["azimuth_deg"]).sum() >= 12
    np.testing.assert_array_equal(fast.status, full.status)
    np.testing.assert_array_equal(fast.split, full.split)
    assert fast.summary()["chain"]["full_chain_frames"] == 0
    assert full.summary()["chain"] == {"asked": "full", "full_chain_frames": 0, "reasons": {}}


def _noisy_crossing(duration_s: float, snr_db: float) -> dict:
    """The crossing with many noise detections around its target: a low per-sample SNR and
    a CFAR threshold of 1 dB."""
    doc = crossing_doc(duration_s=duration_s, frame_period_s=0.1)
    doc["radar"].update(snr_db=snr_db, cfar={"kind": "ca", "threshold_db": 1.0})
    return doc


def test_splits_are_counted_where_the_radar_sees_the_target():
    """Without rts.compensate_air_path the RuT sees a target R_c (here 5 range bins) further
    than its set range: a split is an unclaimed detection within the gate of that cell (where
    the association looks and the fast path forms the map), the same on both chains, and
    never a noise detection at the set range, 5 bins away from the target's echo."""
    doc = _noisy_crossing(0.3, -38.0)
    doc["rts"]["compensate_air_path"] = False
    scene = scene_of(doc)
    fast, full = (rtsgeom.play(scene, amplitudes="nearest", chain=c) for c in ("fast", "full"))
    np.testing.assert_array_equal(fast.split, full.split)
    assert full.split.sum() >= 3  # the noise splits the target in some frames
    assert fast.summary()["chain"]["full_chain_frames"] == 0


def test_clouds_use_the_playbacks_gate():
    """An object's cloud is the detections within the play's gate (``Playback(bins=...)``)
    of its scatterers, as the matches: at gates 0 and 1 too, where the fast path's windows
    are narrower than the default gate of two bins; the same clouds on both chains."""
    from rtsgeom.analysis.playback import Playback
    doc = _noisy_crossing(0.2, -30.0)
    doc["scenario"]["targets"][0]["scatterers"] = [[0.0, 0.0, 0.0, 10.0], [1.5, 0.0, 0.0, 10.0]]
    scene = scene_of(doc)
    for bins, least in ((0, 0), (1, 6)):  # gate 1: both sources, both scatterers, 3 frames
        fast, full = (Playback(amplitudes="nearest", bins=bins, chain=c)(scene)
                      for c in ("fast", "full"))
        rows = [sorted(r.clouds[0]) for r in (fast, full)]
        assert len(rows[0]) == len(rows[1]) >= least
        for a, b in zip(*rows):
            assert a[:3] == b[:3]
            np.testing.assert_allclose(a[3:6], b[3:6], rtol=0, atol=1e-3)
