"""Extended objects: placement and heading against closed-form geometry, every scatterer
detected by the truth twin and the RTS where it lies, the budget's merge against the truth
twin's detection of the cell, dynamic resolution on an approach, the outputs of `run` and
`play`, and one clear line for every bad object input."""

from __future__ import annotations

import copy
import csv
import json
import math
import shutil
import tomllib
from pathlib import Path

import numpy as np
import pytest

import rtsgeom
from rtsgeom.analysis.objects import CLOUD_COLUMNS, SUMMARY_KEYS
from rtsgeom.analysis.playback.frames import frame_targets
from rtsgeom.calibration.probes import probe_front_ends
from rtsgeom.cli import main
from rtsgeom.errors import SceneError
from rtsgeom.geometry import build_setup
from rtsgeom.paths import compute_paths
from rtsgeom.pipeline.merge import budget_targets
from rtsgeom.pipeline.plan import bracketing_pair
from rtsgeom.pipeline.run import run_scene
from rtsgeom.scene import parse_scene
from rtsgeom.scene.mesh import MAX_MESH_FACETS

SCENES = Path(__file__).resolve().parents[2] / "scenes"
CAR = SCENES / "car-crossing.toml"
BOX = [[0.9, 2.25, 0.0, 10.0], [-0.9, 2.25, 0.0, 10.0], [0.9, -2.25, 0.0, 10.0],
       [-0.9, -2.25, 0.0, 10.0]]


def bench_doc(**rts) -> dict:
    """The car-crossing bench without its drive."""
    doc = tomllib.loads(CAR.read_text())
    del doc["scenario"]
    doc["rts"].pop("max_targets_per_channel")
    doc["rts"].update(rts)
    return doc


def with_object(doc, **entry) -> dict:
    doc = copy.deepcopy(doc)
    doc["targets"] = [{"range_m": 15.0, **entry}]
    return doc


# ------------------------------------------------------------------------------------------
# Placement
# ------------------------------------------------------------------------------------------

@pytest.mark.parametrize("heading_deg", [-120.0, -30.0, 0.0, 30.0, 90.0])
@pytest.mark.parametrize("azimuth_deg", [-10.0, 0.0, 7.0])
def test_placement_and_heading_closed_form(heading_deg, azimuth_deg):
    """Origin at (range, azimuth); heading turns +y towards +x: (x, y) -> x (cos h, -sin h)
    + y (sin h, cos h); an RuT without elevation keeps the 3-D range at elevation 0."""
    s = parse_scene(with_object(bench_doc(), scatterers=BOX + [[0.3, -0.4, 0.5, -3.0]],
                                heading_deg=heading_deg, angle_deg=azimuth_deg), "o.toml")
    h, a = math.radians(heading_deg), math.radians(azimuth_deg)
    origin = 15.0 * np.array([math.sin(a), math.cos(a), 0.0])
    for t, (x, y, z, rcs) in zip(s.targets, BOX + [[0.3, -0.4, 0.5, -3.0]]):
        p = origin + [x * math.cos(h) + y * math.sin(h), -x * math.sin(h) + y * math.cos(h), z]
        assert t.range_m == pytest.approx(np.linalg.norm(p), abs=1e-9)
        assert t.angle_rad == pytest.approx(math.atan2(p[0], p[1]), abs=1e-12)
        assert (t.elevation_rad, t.rcs_dbsm, t.object_index) == (0.0, rcs, 0)
    assert len(s.objects) == 1 and s.objects[0].where == "targets[0]"


def test_box_every_scatterer_detected_where_it_lies():
    """A 1.8 m x 4.5 m box of four scatterers turned 30 deg, 15 m ahead: each one detected by
    the truth twin and by the RTS at its geometric range and azimuth (one bin, 0.1 deg)."""
    s = parse_scene(with_object(bench_doc(), scatterers=BOX, heading_deg=30.0), "box.toml")
    ranges = sorted(t.range_m for t in s.targets)
    assert min(np.diff(ranges)) > 2 * s.radar.range_resolution_m  # distinct ranges
    r = run_scene(s)
    bin_m = r.rd.range_m[1] - r.rd.range_m[0]
    for m, t in zip(r.matches, s.targets):
        assert m["status"] == "detected" and m["truth_status"] == "detected", m
        for got in (m["detection"], m["truth"]):
            assert abs(got["range_m"] - t.range_m) <= bin_m
            assert abs(got["angle_deg"] - math.degrees(t.angle_rad)) <= 0.1


def test_budget_merges_at_the_truth_twins_detection():
    """A budget of one target per channel, three scatterers in one range cell within the
    angular resolution and two more in another: merged, counted, and each RTS detection
    within 0.2 deg and one range bin of the truth twin's detection of the same cell."""
    rows = [[0.8, 0.0, 0.0, 10.0], [0.0, 0.02, 0.0, 7.0], [-0.8, 0.0, 0.0, 10.0],
            [0.5, 3.0, 0.0, 5.0], [-0.5, 3.02, 0.0, 5.0]]
    s = parse_scene(with_object(bench_doc(max_targets_per_channel=1), scatterers=rows),
                    "merge.toml")
    r = run_scene(s)
    b = r.calibration["budget"]
    assert b["merged"] >= 3 and b["kept"] + b["dropped"] >= 1
    assert b["kept"] < b["scatterers"]
    assert any(len(t["members"]) > 1 and t["from_truth_twin"] for t in b["targets"])
    bin_m = r.rd.range_m[1] - r.rd.range_m[0]
    td = r.truth_detections
    for t in b["targets"]:
        j = np.argmin(np.abs(r.detections.range_m - t["range_m"]))
        k = np.argmin(np.abs(td.range_m - r.detections.range_m[j]))
        assert abs(r.detections.range_m[j] - td.range_m[k]) <= bin_m
        assert abs(r.detections.angle_deg[j] - td.angle_deg[k]) <= 0.2
        if len(t["members"]) > 1:  # the cell's power too, not the coherent sum's at f_c
            assert abs(r.detections.power_db[j] - td.power_db[k]) <= 0.5
    # the summary says so
    from rtsgeom.analysis.objects import run_objects
    _, section = run_objects(r)
    assert section["frames"][0]["merged"] == b["merged"]


@pytest.mark.parametrize("quarter", [0.0, 1.0])
def test_merge_follows_the_glint_not_the_power_centroid(quarter):
    """Two scatterers 6.1 deg apart in one cell, the weaker a quarter wavelength further
    (anti-phase): the truth twin sees the pair outside their span (glint); the merged target
    goes there, not to the power centroid, and the RTS's detection with it."""
    s0 = parse_scene(with_object(bench_doc(max_targets_per_channel=1), scatterers=[
        [0.8, 0.0, 0.0, 10.0], [-0.8, 0.0, 0.0, 6.0]]), "g.toml")
    lam = s0.radar.wavelength_m
    s = parse_scene(with_object(bench_doc(max_targets_per_channel=1), scatterers=[
        [0.8, 0.0, 0.0, 10.0], [-0.8, quarter * lam / 4, 0.0, 6.0]]), "g.toml")
    r = run_scene(s)
    b = r.calibration["budget"]["targets"][0]
    k = np.argmax(r.truth_detections.power_db)
    j = np.argmax(r.detections.power_db)
    assert b["azimuth_deg"] == pytest.approx(r.truth_detections.angle_deg[k], abs=1e-9)
    assert abs(r.detections.angle_deg[j] - r.truth_detections.angle_deg[k]) <= 0.2
    span = max(abs(math.degrees(t.angle_rad)) for t in s.targets)
    if quarter:  # anti-phase: outside the pair's span, far from the power centroid
        assert r.truth_detections.angle_deg[k] > span
        assert abs(b["azimuth_deg"] - b["power_centroid_azimuth_deg"]) > 3.0


def test_dynamic_resolution_kept_grows_on_approach():
    """A car approaching from 30 m to 5 m: the targets the RTS keeps under its budget grow
    (the RuT resolves more of the car the nearer it comes)."""
    doc = tomllib.loads(CAR.read_text())
    tg = doc["scenario"]["targets"][0]
    tg["waypoints"] = [[0.0, 30.0, 0.0], [5.0, 5.0, 0.0]]
    doc["scenario"].update(duration_s=5.0, frame_period_s=1.0)
    s = parse_scene(doc, "approach.toml")
    _, frames = frame_targets(s)
    setup = build_setup(rtsgeom.replace(s, scenario=None))
    probe = probe_front_ends(setup, compute_paths(setup, "exact"), s.seed)
    kept = [budget_targets(setup, tg, probe, bracketing_pair).counts["kept"] for tg in frames]
    assert kept[-1] > kept[0] and kept[-1] == max(kept), kept


# ------------------------------------------------------------------------------------------
# Outputs
# ------------------------------------------------------------------------------------------

def test_play_writes_clouds_and_object_summary(tmp_path):
    scene = tmp_path / "car.toml"
    text = CAR.read_text()
    assert "frame_period_s = 0.2" in text
    scene.write_text(text.replace("frame_period_s = 0.2", "frame_period_s = 1.0"))
    assert main(["play", str(scene), "--out", str(tmp_path / "out"), "--no-baseline",
                 "--quiet"]) == 0
    with open(tmp_path / "out" / "clouds.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert tuple(rows[0]) == CLOUD_COLUMNS
    assert {r["source"] for r in rows} == {"truth", "rts"}
    assert {r["frame"] for r in rows} == {"0", "1", "2"}
    section = json.loads((tmp_path / "out" / "objects.json").read_text())
    assert len(section["frames"]) == 3
    for f in section["frames"]:
        assert set(SUMMARY_KEYS) <= set(f) and f["kept"] <= f["kept"] + f["merged"]
        assert 0.0 <= f["reproduced_share"] <= 1.0
    assert (tmp_path / "out" / "objects.png").stat().st_size > 10_000


# ------------------------------------------------------------------------------------------
# Bad object input: one clear line naming the field
# ------------------------------------------------------------------------------------------

@pytest.mark.parametrize("entry, field", [
    ({"scatterers": [[0.0, float("nan"), 0.0, 1.0]]}, "targets[0].scatterers[0][1]"),
    ({"scatterers": []}, "targets[0].scatterers"),
    ({"scatterers": [[0.0, 0.0, 1.0]]}, "targets[0].scatterers"),
    ({"scatterers": [[0.0, 0.0, 0.0, 1.0]] * 257}, "targets[0].scatterers"),
    ({"scatterers": [[0.0, 0.0, 0.0, 1.0]], "mesh": "car.ply"}, "targets[0].mesh"),
    ({"mesh": "missing.ply"}, "targets[0].mesh"),
    ({"mesh": "../car.ply"}, "targets[0].mesh"),
    ({"scatterers": [[0.0, -15.0, 0.0, 1.0]]}, "targets[0].scatterers[0]"),
])
def test_bad_object_input_names_the_field(tmp_path, entry, field):
    shutil.copy(SCENES / "car.ply", tmp_path / "car.ply")
    with pytest.raises(SceneError) as exc:
        parse_scene(with_object(bench_doc(), **entry), "o.toml", base_dir=tmp_path)
    msg = str(exc.value)
    assert "\n" not in msg and field in msg, msg


def _mesh_error(tmp_path, name: str, write) -> str:
    write(tmp_path / name)
    with pytest.raises(SceneError) as exc:
        parse_scene(with_object(bench_doc(), mesh=name), "o.toml", base_dir=tmp_path)
    msg = str(exc.value)
    assert "\n" not in msg and "targets[0].mesh" in msg, msg
    return msg


def test_bad_meshes_one_clear_line(tmp_path):
    import trimesh
    assert "trimesh reads" in _mesh_error(tmp_path, "junk.ply",
                                          lambda p: p.write_bytes(b"ply\nthis is not a mesh"))
    # a single triangle whose face looks away from the RuT (normal +y, the RuT at -y)
    away = trimesh.Trimesh([[0, 0, 0], [1, 0, 0], [0, 0, 1]], [[0, 1, 2]], process=False)
    if away.face_normals[0][1] < 0:
        away.invert()
    assert "no facet faces the RuT" in _mesh_error(tmp_path, "away.stl", away.export)
    # more facets than allowed, within the file size: refused after loading
    big = trimesh.creation.icosphere(subdivisions=5)
    assert len(big.faces) > MAX_MESH_FACETS
    assert f"at most {MAX_MESH_FACETS} facets" in _mesh_error(tmp_path, "big.stl", big.export)

    def million(p):  # a binary STL header of a million facets, the body sparse: 50 MB
        with open(p, "wb") as fh:
            fh.write(b"\0" * 80 + (1_000_000).to_bytes(4, "little"))
            fh.truncate(84 + 50 * 1_000_000)
    assert "MiB" in _mesh_error(tmp_path, "million.stl", million)


def test_mesh_object_scatterers_face_the_radar(tmp_path):
    """The bundled car mesh 15 m ahead: nose on, its flat front is one mirror-like scatterer
    (its 1.1 m lie within one resolution cell) 2.25 m before the origin; turned 30 deg, its
    scatterers lie on the side facing the RuT (nearer than the origin but for the far corners)
    and within the object's extent."""
    shutil.copy(SCENES / "car.ply", tmp_path / "car.ply")
    s = parse_scene(with_object(bench_doc(), mesh="car.ply"), "m.toml", base_dir=tmp_path)
    r = np.array([t.range_m for t in s.targets])
    assert len(r) == 1 and abs(r[0] - (15.0 - 4.5 / 2)) < 0.02
    s = parse_scene(with_object(bench_doc(), mesh="car.ply", heading_deg=30.0), "m.toml",
                    base_dir=tmp_path)
    r = np.array([t.range_m for t in s.targets])
    assert 3 <= len(r) <= 32 and np.all(np.abs(r - 15.0) <= 2.5)
    assert np.median(r) < 15.0  # the near half of the car returns most


# ------------------------------------------------------------------------------------------
# The design study
# ------------------------------------------------------------------------------------------

def test_object_design_study_smallest_design():
    """The turned box on boresight at 10 m: without a limit the RTS reproduces every truth
    detection (share 1); a budget of one target per channel keeps fewer targets than the
    box's four scatterers; the smallest design is the unlimited one."""
    from rtsgeom.analysis.object_design import ObjectDesign
    s = parse_scene(with_object(bench_doc(), scatterers=BOX, heading_deg=30.0), "box.toml")
    res = ObjectDesign(ranges_m=(10.0,), spacings_deg=(16.0,), budgets=(None, 1))(s)
    assert res.share[0, 0, 0] == 1.0 and res.kept[0, 0, 0] == 4
    assert res.kept[0, 1, 0] < 4
    assert res.best() == {"front_ends": int(res.front_ends[0]), "spacing_deg": 16.0,
                          "max_targets_per_channel": None}
    df = res.to_dataframe()
    assert len(df) == 2 and "reproduced_share" in df
    assert "smallest design" in repr(res)


def test_object_design_refuses_bad_grid():
    from rtsgeom.analysis.object_design import ObjectDesign
    from rtsgeom.errors import ParameterError
    with pytest.raises(ParameterError, match="budgets"):
        ObjectDesign(budgets=(0,))
    with pytest.raises(ParameterError, match="ranges_m"):
        ObjectDesign(ranges_m=(float("nan"),))
    with pytest.raises(ParameterError, match="has no extended object"):
        ObjectDesign()(rtsgeom.load_scene(SCENES / "crossing.toml"))


def test_an_objects_own_scatterers_raise_no_shared_cell_warning():
    """The bundled car's scatterers share cells by design: no 'share a range-Doppler cell'
    line names them (28 such lines named targets[k] the file does not have)."""
    import dataclasses
    from rtsgeom.pipeline.cells import shared_cell_warnings
    scene = rtsgeom.load_scene(CAR)
    setup = build_setup(dataclasses.replace(scene, scenario=None))
    _, frames = frame_targets(scene)
    assert all(t.object_index >= 0 for t in frames[7])
    assert shared_cell_warnings(setup, frames[7]) == []


# -- an object's pose in closed form --

def _obj(**kw):
    from rtsgeom.scene.objects import ObjectModel
    pts = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.5], [-0.5, -2.0, 0.0]])
    base = dict(where="scenario.targets[0]", points=pts, rcs_dbsm=np.zeros(3), vertices=None,
                faces=None, outline=np.array([[-1.0, -2.0], [1.0, -2.0], [1.0, 2.0],
                                              [-1.0, 2.0]]))
    base.update(kw)
    return ObjectModel(**base)


@pytest.mark.parametrize("along, v, heading, want", [
    (True, (3.0, 4.0, 0.0), 0.2, math.atan2(3.0, 4.0)), (True, (0.0, 0.0, 5.0), 0.2, 0.2),
    (False, (3.0, 4.0, 0.0), 0.2, 0.2), (True, None, -0.4, -0.4),
    (True, (-1.0, 0.0, 0.0), 0.0, -math.pi / 2)])
def test_an_objects_heading_follows_its_motion_where_asked(along, v, heading, want):
    m = _obj(along_velocity=along, heading_rad=heading)
    assert m.heading(None if v is None else np.array(v)) == pytest.approx(want, abs=1e-15)


@pytest.mark.parametrize("h", [0.0, 0.3, -1.2, math.pi])
def test_an_objects_outline_turns_its_plus_y_to_its_heading(h):
    m = _obj(heading_rad=h)
    got = m.outline_at((5.0, 10.0, 1.0))
    c, s = math.cos(h), math.sin(h)
    o = m.outline
    want = np.c_[c * o[:, 0] + s * o[:, 1], -s * o[:, 0] + c * o[:, 1]] + [5.0, 10.0]
    assert np.allclose(got, want, rtol=0, atol=1e-12)
    # the footprint's centre stays at the origin; its +y end points along (sin h, cos h)
    assert np.allclose(got.mean(axis=0), [5.0, 10.0], atol=1e-12)


def test_a_moving_objects_scatterers_are_its_points_turned_and_carried():
    """pos[f, n] = p_f + R(h_f) x_n with h_f along the frame's velocity (the fixed heading in a
    frame at rest); the velocities are the drive's."""
    from types import SimpleNamespace
    from rtsgeom.scene.objects import object_set_points
    m = _obj(along_velocity=True, heading_rad=0.7, moving=True)
    vel = np.array([[3.0, 4.0, 0.0], [0.0, 0.0, 0.0], [-2.0, 0.0, 1.0]])
    p = np.array([[0.0, 20.0, 0.0], [1.0, 21.0, 0.2], [2.0, 22.0, -0.3]])
    pos, v = object_set_points(m, SimpleNamespace(position_m=p, velocity_vec_mps=vel), None)
    assert pos.shape == (3, 3, 3) and np.array_equal(v, vel)
    for f, h in enumerate((math.atan2(3.0, 4.0), 0.7, math.atan2(-2.0, 0.0))):
        c, s = math.cos(h), math.sin(h)
        x = m.points
        want = p[f] + np.c_[c * x[:, 0] + s * x[:, 1], -s * x[:, 0] + c * x[:, 1], x[:, 2]]
        assert np.allclose(pos[f], want, rtol=0, atol=1e-12), f
    fixed = _obj(heading_rad=0.7, moving=True)
    pos2, _ = object_set_points(fixed, SimpleNamespace(position_m=p, velocity_vec_mps=vel), None)
    assert np.allclose(pos2[0], pos[1] - p[1] + p[0], atol=1e-12)  # 0.7 in every frame


def test_hulls_of_points_segments_and_polygons():
    from rtsgeom.scene.objects import _hull
    assert np.array_equal(_hull(np.array([[1.0, 2.0], [1.0, 2.0]])), [[1.0, 2.0]])
    seg = _hull(np.array([[0.0, 0.0], [2.0, 2.0], [1.0, 1.0]]))  # collinear: its two ends
    assert sorted(map(tuple, seg)) == [(0.0, 0.0), (2.0, 2.0)]
    sq = _hull(np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0.5]], float))
    assert sorted(map(tuple, sq)) == [(0.0, 0.0), (0.0, 1.0), (1.0, 0.0), (1.0, 1.0)]
    assert repr(_obj()) == "ObjectModel(scenario.targets[0]: 3 scatterers)"
    assert repr(_obj(points=None, faces=np.zeros((12, 3)), moving=True)) == (
        "ObjectModel(scenario.targets[0]: mesh of 12 facets, moving)")
