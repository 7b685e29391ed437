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
    clouds_csv,
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
