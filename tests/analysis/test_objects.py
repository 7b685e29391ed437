"""What the radar sees of an extended object against the truth, through the project's one
association: the clouds where the RuT sees the RTS's targets (R_c further without
``compensate_air_path``), and a budgeted drive compared cell by cell with the truth twin
(kept / merged / dropped, no errors against scatterers the RTS merged on purpose)."""

from __future__ import annotations

import csv
import io
import tomllib

import numpy as np
import pytest
from scene.test_objects import BOX, CAR, bench_doc

from rtsgeom.analysis.objects import (
    CLOUD_COLUMNS,
    SUMMARY_KEYS,
    clouds_csv,
    object_summary,
    objects_lines,
    play_objects,
    run_objects,
)
from rtsgeom.analysis.playback import Playback
from rtsgeom.analysis.playback.result import BUDGET_ROLES
from rtsgeom.pipeline.run import associate_targets, run_scene
from rtsgeom.scene import parse_scene


@pytest.mark.parametrize("compensate", [True, False])
def test_clouds_take_the_rts_targets_where_the_radar_sees_them(compensate):
    """Without compensate_air_path the RuT sees the RTS's targets R_c (0.8 m, five range
    bins) further: the clouds keep its detections (the association compares them at the
    apparent range) and the summary refers them to the real scene. The clouds' own
    association re-implemented at the set range dropped every RTS detection (no RTS cloud,
    no comparison)."""
    doc = bench_doc(compensate_air_path=compensate, aoa_mode="nearest")
    doc["targets"] = [{"range_m": 15.0, "scatterers": BOX, "heading_deg": 30.0}]
    s = parse_scene(doc, "box.toml")
    r = run_scene(s)
    rows, section = run_objects(r)
    f = section["frames"][0]
    rts = [x for x in rows if x[1] == "rts"]
    # every RTS detection the one association gives a scatterer is in the cloud
    a, _, _ = associate_targets(s, r.detections, r.rd, 2, r.cube.steering)
    assert len(rts) == int(np.sum((a.owner >= 0) | (a.nearest >= 0))) >= 4
    assert f["rts_detections"] == len(rts) and f["truth_detections"] >= 4
    bin_m = s.radar.range_resolution_m
    assert abs(f["centroid_range_diff_m"]) <= bin_m  # referred to the real scene
    assert f["reproduced_share"] == 1.0
    assert f["paired_range_diff_max_bins"] <= 1.0


def test_budgeted_drive_is_compared_cell_by_cell():
    """The bundled car with one target per channel (three frames): no angle error or
    hand-over is reported against scatterers (the RTS merges and drops them on purpose:
    19 deg and 26 'hand-overs' were printed); each frame says kept / merged / dropped, and
    each RTS detection lies within 0.2 deg and one range bin of the truth twin's detection
    of its cell."""
    doc = tomllib.loads(CAR.read_text())
    doc["rts"]["max_targets_per_channel"] = 1
    doc["scenario"]["frame_period_s"] = 1.0
    s = parse_scene(doc, "car1.toml")
    res = Playback(baseline=False)(s)
    summ = res.summary()
    assert summ["point_targets"] == 0
    assert summ["angle_error_deg"]["max"] is None and summ["handovers"] == 0
    assert summ["lost_frames"] == 0
    b = summ["budget"]
    assert b["max_targets_per_channel"] == 1 and b["merged"]["max"] >= 2
    role = np.asarray(res.role)
    assert set(role.ravel()) <= set(BUDGET_ROLES)
    for f, counts in enumerate(res.budget):
        assert np.isin(role[f], ("kept", "lead")).sum() == counts["kept"]
        assert (role[f] == "dropped").sum() == counts["dropped"]
    _, section = play_objects(res)
    for fr in section["frames"]:
        assert fr["merged"] >= 2 and fr["paired_detections"] >= 1
        assert fr["paired_azimuth_diff_max_deg"] <= 0.2
        assert fr["paired_range_diff_max_bins"] <= 1.0
    line, = objects_lines(section)
    assert "budget: kept 2" in line and "merged" in line and "dropped" in line
    # the tracks say which scatterer carries a merged target
    tracks = res.tracks_csv().splitlines()
    assert tracks[0].endswith(",status,budget")
    assert any(t.endswith(",merged_by_rts,merged") for t in tracks[1:])


def test_reference_power_of_every_merged_group_at_once(monkeypatch):
    """The merged targets' reference powers (a 0 dBsm point alone through the truth twin) in
    one batch: equal to the serial simulation and detection of each point over a grid of
    ranges, velocities and azimuths, and the budget runs the truth twin once per frame (one
    more run per merged group before)."""
    import rtsgeom.pipeline.merge as merge
    from rtsgeom.calibration.probes import probe_front_ends
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import compute_paths
    from rtsgeom.pipeline.plan import bracketing_pair
    from rtsgeom.radar import process
    from rtsgeom.radar.truth import simulate_truth
    from rtsgeom.scene import TargetConfig
    s = parse_scene(bench_doc(), "b.toml")
    setup = build_setup(s)
    refs = [TargetConfig(range_m=r, velocity_mps=v, rcs_dbsm=0.0, angle_rad=np.radians(a))
            for r in (3.0, 12.34, 30.0) for v in (-4.0, 0.0, 1.7) for a in (-40.0, 0.0, 21.0)]
    got = merge.reference_power_db(setup, refs)
    assert len(refs) > merge.REFERENCE_CHUNK  # more than one block
    serial = [float(process(simulate_truth(setup, [t], s.seed, 0.0)[1])[1].power_db.max())
              for t in refs]
    np.testing.assert_allclose(got, serial, atol=1e-6)

    calls = []
    monkeypatch.setattr(merge, "simulate_truth",
                        lambda *a, **k: calls.append(1) or simulate_truth(*a, **k))
    doc = bench_doc(max_targets_per_channel=1)
    doc["targets"] = [{"range_m": 15.0, "scatterers": [
        [0.8, 0.0, 0.0, 10.0], [0.0, 0.02, 0.0, 7.0], [-0.8, 0.0, 0.0, 10.0],
        [0.5, 3.0, 0.0, 5.0], [-0.5, 3.02, 0.0, 5.0]]}]
    s1 = parse_scene(doc, "m.toml")
    setup1 = build_setup(s1)
    probe = probe_front_ends(setup1, compute_paths(setup1, "exact"), s1.seed)
    b = merge.budget_targets(setup1, s1.targets, probe, bracketing_pair)
    assert any(b.truth_found) and len(calls) == 1  # the cells' view, nothing per group


def test_run_prints_scatterers_as_written_and_the_budget(tmp_path, capsys):
    """`rtsgeom run` of a budget of one: each scatterer by its name in the file, merged and
    dropped ones said so (no error against a scatterer the RTS merged), and the object's line
    comparing each RTS detection with the truth twin's of its cell."""
    from rtsgeom.cli import main
    text = CAR.read_text()
    text = text[:text.index("[scenario]")].replace("max_targets_per_channel = 3",
                                                   "max_targets_per_channel = 1")
    path = tmp_path / "m.toml"
    path.write_text(text + "[[targets]]\nrange_m = 15.0\nscatterers = [[0.8, 0.0, 0.0, 10.0], "
                    "[0.0, 0.02, 0.0, 7.0], [-0.8, 0.0, 0.0, 10.0], [0.5, 3.0, 0.0, 5.0], "
                    "[-0.5, 3.02, 0.0, 5.0]]\n")
    assert main(["run", str(path), "--out", str(tmp_path / "o"), "--no-report"]) == 0
    out = capsys.readouterr().out
    assert "targets[0].scatterers[0]: carries the RTS's merged target of" in out
    assert "targets[0].scatterers[1]: merged into targets[0].scatterers[0]'s target" in out
    assert "errors" not in out.split("object targets[0]")[0]  # nothing against scatterers
    line = next(x for x in out.splitlines() if x.startswith("object targets[0]"))
    az = float(line.split("max |azimuth| ")[1].split(" deg")[0])
    assert az <= 0.2 and "budget: kept" in line



def test_clouds_csv_writes_every_column_of_every_row():
    """One CSV row per detection with all of :data:`CLOUD_COLUMNS`: the numbers to six
    significant digits, a missing elevation (azimuth-only RuT) empty."""
    rng = np.random.default_rng(11)
    rows = [(f, src, k, *rng.uniform(-50, 50, 3), (np.nan if f % 2 else rng.uniform(-5, 5)),
             rng.uniform(-90, 0)) for f in range(4) for src in ("truth", "rts") for k in range(2)]
    got = list(csv.reader(io.StringIO(clouds_csv(rows))))
    assert tuple(got[0]) == CLOUD_COLUMNS
    assert len(got) == len(rows) + 1
    for r, line in zip(rows, got[1:]):
        assert len(line) == len(CLOUD_COLUMNS)
        assert line[:3] == [str(r[0]), r[1], str(r[2])]
        for x, text in zip(r[3:], line[3:]):
            if np.isfinite(x):
                assert float(text) == pytest.approx(x, rel=1e-5)
            else:
                assert text == ""


@pytest.mark.parametrize("snr_db", [None, 15.0])
def test_the_fast_path_gives_the_full_chains_clouds(snr_db):
    """The budgeted car (three frames: merged, kept and dropped scatterers, several in one
    cell) played on the fast path and on the full chain: the same clouds (each detection
    within 1 mm, 1e-3 m/s and 1e-3 deg), statuses and roles, no frame left to the full chain;
    with noise as without (the same realisation)."""
    doc = tomllib.loads(CAR.read_text())
    doc["rts"]["max_targets_per_channel"] = 1
    doc["scenario"]["frame_period_s"] = 1.0
    if snr_db is not None:
        doc["radar"]["snr_db"] = snr_db
    s = parse_scene(doc, "car1.toml")
    fast, full = (Playback(baseline=False, chain=c)(s) for c in ("fast", "full"))
    assert fast.summary()["chain"] == {"asked": "fast", "full_chain_frames": 0,
                                       "reasons": {}}
    assert full.summary()["chain"]["asked"] == "full"
    a, b = fast.clouds[0], full.clouds[0]
    assert [r[:3] for r in a] == [r[:3] for r in b] and len(a) >= 10
    np.testing.assert_allclose(np.array([r[3:6] for r in a]), np.array([r[3:6] for r in b]),
                               rtol=0, atol=1e-3)
    np.testing.assert_array_equal(fast.status, full.status)
    np.testing.assert_array_equal(fast.role, full.role)
    # the programme is the budget's: one target per channel and frame, the merged ones' lead
    rows = fast.programme
    per = {(int(f), int(ch)): {int(t) for t in rows[(rows[:, 0] == f) & (rows[:, 2] == ch), 1]}
           for f, ch in {(r[0], r[2]) for r in rows}}
    assert per and max(len(t) for t in per.values()) == 1
    lead = {int(t) for t in rows[:, 1]}
    assert lead <= {k for k in range(fast.role.shape[1]) if set(fast.role[:, k]) & {"kept",
                                                                                    "lead"}}


# -- the clouds compared, in closed form on hand-made rows --

SCALE = (0.5, 0.2, 0.02)  # one range bin, one Doppler bin, one direction-cosine cell


def _rows(frame, source, obj, pts):
    return [(frame, source, obj, r, v, az, np.nan, -30.0) for r, v, az in pts]


TRUTH = [(10.0, 0.0, -2.0), (10.5, 0.0, 0.0), (11.0, 0.0, 3.0)]


@pytest.mark.parametrize("dr, daz, offset", [(0.0, 0.0, 0.0), (0.1, 0.2, 0.0), (-0.2, -0.3, 0.0),
                                             (1.5, 0.0, 1.5), (0.0, 5.0, 0.0)])
def test_object_summary_of_a_shifted_cloud_is_the_shift(dr, daz, offset):
    """The RTS's cloud is the truth's moved by (dr, daz) beyond ``offset`` (the air path the
    radar sees in addition): centroid and extent differences are the shift and zero, every
    truth detection reproduced where the shift is within a cell, and the paired differences
    the shift."""
    rts = [(r + dr + offset, v, az + daz) for r, v, az in TRUTH]
    rows = (_rows(4, "truth", 1, TRUTH) + _rows(4, "rts", 1, rts) + _rows(4, "rts", 0, rts[:1])
            + _rows(5, "truth", 1, TRUTH[:1]))
    s = object_summary(rows, SCALE, 1, 4, offset)
    assert list(s) == list(SUMMARY_KEYS)
    assert (s["object"], s["frame"], s["truth_detections"], s["rts_detections"]) == (1, 4, 3, 3)
    assert s["centroid_azimuth_diff_deg"] == pytest.approx(daz, abs=1e-12)
    assert s["centroid_range_diff_m"] == pytest.approx(dr, abs=1e-12)
    assert s["azimuth_span_diff_deg"] == pytest.approx(0.0, abs=1e-12)
    assert s["range_depth_diff_m"] == pytest.approx(0.0, abs=1e-12)
    u = np.abs(np.sin(np.radians(np.array(TRUTH)[:, 2] + daz)) - np.sin(np.radians(
        np.array(TRUTH)[:, 2])))
    inside = abs(dr) <= SCALE[0] and np.all(u <= SCALE[2])
    assert s["reproduced_share"] == (1.0 if inside else 0.0)  # every one moved alike
    if inside:
        assert s["paired_detections"] == 3
        assert s["paired_azimuth_diff_max_deg"] == pytest.approx(abs(daz), abs=1e-12)
        assert s["paired_range_diff_max_bins"] == pytest.approx(abs(dr) / SCALE[0], abs=1e-12)


def test_object_summary_of_an_empty_cloud_has_no_differences():
    s = object_summary(_rows(0, "truth", 0, TRUTH), SCALE, 0, 0)
    assert (s["truth_detections"], s["rts_detections"]) == (3, 0)
    for k in ("centroid_azimuth_diff_deg", "centroid_range_diff_m", "azimuth_span_diff_deg",
              "range_depth_diff_m", "paired_azimuth_diff_max_deg",
              "paired_range_diff_max_bins"):
        assert s[k] is None, k
    assert s["reproduced_share"] == 0.0 and s["paired_detections"] == 0
    none = object_summary(_rows(0, "rts", 0, TRUTH), SCALE, 0, 0)
    assert none["reproduced_share"] is None and none["paired_detections"] == 0


def test_summary_table_adds_each_frames_budget_counts():
    from rtsgeom.analysis.objects import summary_table
    rows = _rows(0, "truth", 0, TRUTH) + _rows(0, "rts", 0, TRUTH) + _rows(1, "truth", 1, TRUTH)
    budget = [{"kept": 3, "merged": 1, "dropped": 0, "other": 9}, None]
    t = summary_table(rows, SCALE, 2, [0, 1], budget)
    assert [(r["object"], r["frame"]) for r in t] == [(0, 0), (1, 0), (0, 1), (1, 1)]
    assert [r.get("kept") for r in t] == [3, 3, None, None]
    assert "other" not in t[0] and t[0]["merged"] == 1 and t[1]["dropped"] == 0
    assert t[0]["reproduced_share"] == 1.0 and t[3]["truth_detections"] == 3
    assert all("kept" not in r for r in summary_table(rows, SCALE, 2, [0, 1]))


def test_objects_lines_say_each_objects_counts_share_and_budget():
    from rtsgeom.analysis.objects import objects_lines

    def row(o, t, r, share, az, rb, **budget):
        return {"object": o, "truth_detections": t, "rts_detections": r,
                "reproduced_share": share, "paired_azimuth_diff_max_deg": az,
                "paired_range_diff_max_bins": rb, **budget}
    section = {"objects": ["targets[0]", "targets[1]", "targets[2]"], "frames": [
        row(0, 5, 4, 0.8, 0.1234, 0.5, kept=2, merged=1, dropped=0),
        row(0, 7, 4, 0.6, 0.25, 0.25, kept=3, merged=1, dropped=2),
        row(1, 3, 3, None, None, None)]}
    assert objects_lines(section) == [
        "object targets[0]: 2 frame(s), truth 5-7 / RTS 4 detections a frame, 60 % (worst "
        "frame) of the truth's reproduced within a cell; each RTS detection against the truth "
        "twin's of its cell: max |azimuth| 0.250 deg, max |range| 0.50 bins; budget: kept 2-3, "
        "merged 1, dropped 0-2",
        "object targets[1]: no truth twin detection",
        "object targets[2]: no truth twin detection"]


def test_the_resolution_cell_is_named_per_axis():
    from rtsgeom.analysis.objects import _cell
    assert _cell((0.5, 0.2, 0.02)) == {"range_m": 0.5, "velocity_mps": 0.2,
                                       "direction_cosine": 0.02}
    assert _cell(np.array([0.5, 0.2, 0.02, 0.04])) == {
        "range_m": 0.5, "velocity_mps": 0.2, "direction_cosine": 0.02,
        "direction_cosine_elevation": 0.04}


def _u_scale(u: float, factor: float) -> float:
    """A cell ``s`` whose ``s * factor`` is exactly ``u`` in floating point."""
    s = u / factor
    for _ in range(64):
        if s * factor == u:
            return s
        s = np.nextafter(s, np.inf if s * factor < u else -np.inf)
    raise AssertionError("no exact cell")


@pytest.mark.parametrize("az_deg", [0.7, 3.1])
def test_pairs_counts_a_detection_one_cell_away_as_close_with_a_1e9_margin(az_deg):
    """Each truth detection paired with the RTS's of its cell (-1: none); close where every
    axis differs by at most one cell times (1 + 1e-9), the bound itself included: 1 + 1e-10
    cells and exactly (1 + 1e-9) cells away in u are close, 1 + 1e-8 are not (still paired:
    the gate is on range and Doppler only); a detection beyond one range bin is not paired."""
    from rtsgeom.analysis.objects import pairs
    u = float(np.sin(np.radians(az_deg)))
    truth = np.array([[20.0, 1.0, 0.0, 0.0]])
    rts = np.array([[20.0, 1.0, az_deg, 0.0]])
    for factor, close in [(1 + 1e-10, True), (1 + 1e-9, True), (1 + 1e-8, False)]:
        sc = (0.1, 0.05, _u_scale(u, factor))
        det, ok = pairs(truth, rts, sc)
        assert det.tolist() == [0] and ok.tolist() == [close], (factor, ok)
    far = np.array([[20.0 + 0.1 * (1 + 1e-6), 1.0, 0.0, 0.0], [20.0, 1.0, 0.0, 0.0]])
    det, ok = pairs(np.array([[20.0, 1.0, 0.0, 0.0]] * 2), far[:1], (0.1, 0.05, 0.01))
    assert det.tolist() == [-1, -1] and ok.tolist() == [False, False]
    det, ok = pairs(truth, far, (0.1, 0.05, 0.01))
    assert det.tolist() == [1] and ok.tolist() == [True]
