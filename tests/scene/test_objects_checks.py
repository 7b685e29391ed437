"""rtsgeom.scene.objects' checks and placements read in full: every refusal of a static and of a
moving object's scatterers (the field, the value and the whole sentence, each bound taken at
its edge and refused just beyond), the placement's errors, the labels a scene file writes, and
the frames' scatterers against the closed-form pose."""

from __future__ import annotations

import copy
import math
import tomllib
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from rtsgeom.errors import SceneError
from rtsgeom.scene import parse_scene
from rtsgeom.scene.objects import (ObjectModel, check_moving_objects, check_static_objects,
                                   frame_objects, object_set_points, place, target_field,
                                   target_labels, targets_per_frame)
from rtsgeom.scene.scenario import frame_times, trajectory
from rtsgeom.scene.sections import TargetConfig

SCENES = Path(__file__).resolve().parents[2] / "scenes"
CAR = tomllib.loads((SCENES / "car-crossing.toml").read_text())
DEG = math.pi / 180.0
INF = math.inf


def bench_doc(targets) -> dict:
    """The car-crossing bench without its drive and budget, with ``targets``."""
    doc = copy.deepcopy(CAR)
    del doc["scenario"]
    doc["rts"].pop("max_targets_per_channel")
    doc["targets"] = targets
    return doc


@pytest.fixture(scope="module")
def radar():
    return parse_scene(bench_doc([]), "b.toml").radar


def recorder():
    out = []
    return out, lambda field, value, allowed: out.append((field, value, allowed))


# ------------------------------------------------------------------------------------------
# A static object's scatterers: in front of the RuT, within +-60 deg of elevation
# ------------------------------------------------------------------------------------------

AZ = "in [-90, 90] deg, in front of the RuT (as a point target's angle_deg): move the object " \
     "or its scatterer"
EL = "in [-60, 60] deg (as a point target's elevation_deg)"


@pytest.mark.parametrize("angle, elevation, want", [
    (math.pi / 2, 60 * DEG, []),  # both at their bounds: taken
    (-math.pi / 2, -60 * DEG, []),
    (math.pi / 2 + 1e-12, math.radians(60.0) + 1e-12, []),  # to the bound's last bit
    (math.pi / 2 + 2e-12, 0.0, [("azimuth_deg", 90.0, AZ)]),
    (-math.pi / 2 - 2e-12, 0.0, [("azimuth_deg", -90.0, AZ)]),
    (2.0, 0.0, [("azimuth_deg", round(math.degrees(2.0), 6), AZ)]),
    (0.0, 60.5 * DEG, [("elevation_deg", 60.5, EL)]),
    (0.0, -60.5 * DEG, [("elevation_deg", -60.5, EL)]),
    (-3.0, 1.2, [("azimuth_deg", round(math.degrees(-3.0), 6), AZ),
                 ("elevation_deg", round(math.degrees(1.2), 6), EL)]),
])
def test_a_static_objects_scatterer_is_refused_beyond_each_bound_in_full(angle, elevation, want):
    """Each scatterer of an object (object_index >= 0) is checked and named as the file writes
    it; a point target (-1) is left to the point targets' own rules."""
    scene = SimpleNamespace(targets=[
        TargetConfig(range_m=5.0, angle_rad=3.0, elevation_rad=1.5),  # a point target: skipped
        TargetConfig(range_m=5.0, object_index=0),
        TargetConfig(range_m=5.0, angle_rad=angle, elevation_rad=elevation, object_index=0)])
    names = ["targets[0]", "targets[1].scatterers[0]", "targets[1].scatterers[1]"]
    got, fail = recorder()
    check_static_objects(scene, fail, names)
    assert got == [(f"targets[1].scatterers[1] (its {f})", v, a) for f, v, a in want]


def test_a_static_object_behind_the_ruT_is_refused_on_load_in_one_sentence():
    doc = bench_doc([{"range_m": 10.0}, {"range_m": 2.0, "scatterers": [
        [0.0, 0.0, 0.0, 1.0], [0.0, -4.0, 0.0, 1.0]]}])
    with pytest.raises(SceneError) as exc:
        parse_scene(doc, "o.toml")
    assert str(exc.value) == f"o.toml: targets[1].scatterers[1] (its azimuth_deg) = 180: must be {AZ}"


# ------------------------------------------------------------------------------------------
# A moving object's scatterers, every frame
# ------------------------------------------------------------------------------------------

def _moving(points, rcs=None, where="scenario.targets[1]", **kw) -> ObjectModel:
    p = np.asarray(points, float)
    return ObjectModel(where, p, np.arange(1.0, len(p) + 1) if rcs is None else np.asarray(rcs),
                       None, None, p[:, :2], moving=True, **kw)


def _drive(models, waypoints, *, elevation=False, compensate=True, arc=0.8, meshes=None):
    """A scene of ``models`` driving on ``waypoints`` ([t_s, range_m, azimuth_rad,
    elevation_rad]) at 1 s frames for 2 s, and the set-points of scenario target 1."""
    times = frame_times(1.0, 2.0)
    targets = [SimpleNamespace(mesh="other.ply"), SimpleNamespace(mesh=meshes)]
    scene = SimpleNamespace(
        objects=tuple(models), radar=SimpleNamespace(elevation_processing=elevation),
        rts=SimpleNamespace(arc_radius_m=arc, compensate_air_path=compensate),
        scenario=SimpleNamespace(targets=targets, frame_times=lambda: times))
    return scene, {1: trajectory(waypoints, times)}


#: on the boresight from 10 m to 20 m in 2 s: the origin at 10, 15, 20 m, 5 m/s receding
AWAY = [[0.0, 10.0, 0.0, 0.0], [2.0, 20.0, 0.0, 0.0]]
NEAR = [[0.0, 20.0, 0.0, 0.0], [2.0, 10.0, 0.0, 0.0]]
TWO = [[0.0, 0.0, 0.0], [0.0, 5.0, 0.0]]  # the origin and 5 m further: range origin + 5 m
FAR = "a scatterer whose range stays < {} m, WHY_R{} (at t = {} s it is {} m)"
AIR = " minus the air path 0.5 m the RTS does not subtract"
SLOW = "a scatterer whose radial velocity stays in (-{0}, {0}) m/s, WHY_V (at t = {1} s it is {2} m/s)"
ARC = ("a scatterer whose range stays > rts.arc_radius_m ({} m): the RTS cannot emit before the "
       "radar signal reached it (at t = {} s it is {} m)")
FRONT = "a scatterer whose azimuth stays in [-90, 90] deg (in front of the RuT) (at t = {} s it is {} deg)"
UP = "a scatterer whose elevation stays in [-60, 60] deg (at t = {} s it is {} deg)"
BEHIND = -10.0 + 5.0 / math.tan(90.5 * DEG)  # at 90.5 deg from the origin 10 m ahead
S0, S1 = ("scenario.targets[1].scatterers[0]", [0.0, 0.0, 0.0, 1.0]), \
    ("scenario.targets[1].scatterers[1]", [0.0, 5.0, 0.0, 2.0])

MOVING_CASES = [
    # range: 20 m reached first by scatterer 1 at 1 s (>=: the bound itself refused)
    ("range at its bound", TWO, AWAY, (20.0, 9.0, 0.0), {}, [(*S1, FAR.format(20, "", 1, 20))]),
    ("range just inside", TWO, AWAY, (np.nextafter(20.0, INF), 9.0, 0.0), {},
     [(*S1, FAR.format(20, "", 2, 25))]),
    ("range less the air path", TWO, AWAY, (20.5, 9.0, 0.5), {},
     [(*S1, FAR.format(20, AIR, 1, 20))]),
    ("an air path of 1e-9 m untold", TWO, AWAY, (14.0 + 1e-9, 9.0, 1e-9), {},
     [(*S1, FAR.format(14, "", 0, 15))]),
    ("within every limit", TWO, AWAY, (25.5, 5.5, 0.0), {}, []),
    # the arc: the range must exceed the arc's radius where the RTS subtracts the air path
    ("at the arc", TWO, AWAY, (30.0, 9.0, 0.0), {"arc": 10.0},
     [(*S0, ARC.format(10, 0, 10))]),
    ("just beyond the arc", TWO, AWAY, (30.0, 9.0, 0.0), {"arc": np.nextafter(10.0, 0)}, []),
    ("the arc not subtracted", TWO, AWAY, (30.0, 9.0, 0.0), {"arc": 12.0, "compensate": False},
     []),
    ("at the RuT", [[0.0, -10.0, 0.0], [0.0, 5.0, 0.0]], AWAY, (30.0, 9.0, 0.0),
     {"compensate": False},
     [("scenario.targets[1].scatterers[0]", [0.0, -10.0, 0.0, 1.0],
       "a scatterer whose range stays > 0 m (at t = 0 s it is 0 m)")]),
    # radial velocity: |v_r| >= v_lim refused, either sign
    ("receding at the limit", TWO, AWAY, (30.0, 5.0, 0.0), {}, [(*S0, SLOW.format(5, 0, 5))]),
    ("approaching at the limit", TWO, NEAR, (30.0, 5.0, 0.0), {}, [(*S0, SLOW.format(5, 0, -5))]),
    ("just below the limit", TWO, NEAR, (30.0, np.nextafter(5.0, INF), 0.0), {}, []),
    # azimuth: 90 deg exactly taken, behind the RuT refused on either side
    ("at 90 deg", [[5.0, -10.0, 0.0], [-5.0, -10.0, 0.0]], AWAY, (30.0, 9.0, 0.0), {}, []),
    ("behind, right", [[0.1234567891, 0.0, 0.0], [5.0, -12.0, 0.0]], AWAY, (30.0, 9.0, 0.0), {},
     [("scenario.targets[1].scatterers[1]", [5.0, -12.0, 0.0, 2.0],
       FRONT.format(0, f"{math.degrees(math.atan2(5.0, -2.0)):.4g}"))]),
    ("behind, left", [[0.1234567891, 0.0, 0.0], [-5.0, -12.0, 0.0]], AWAY, (30.0, 9.0, 0.0), {},
     [("scenario.targets[1].scatterers[1]", [-5.0, -12.0, 0.0, 2.0],
       FRONT.format(0, f"{math.degrees(math.atan2(-5.0, -2.0)):.4g}"))]),
    # elevation: checked with the RuT's elevation processing only (else placed at 0)
    ("above", [[0.1234567891, 0.0, 0.0], [0.0, 0.0, 10 * math.tan(60.5 * DEG)]], AWAY,
     (30.0, 9.0, 0.0), {"elevation": True},
     [("scenario.targets[1].scatterers[1]", [0.0, 0.0, round(10 * math.tan(60.5 * DEG), 6), 2.0],
       UP.format(0, 60.5))]),
    ("below", [[0.1234567891, 0.0, 0.0], [0.0, 0.0, -10 * math.tan(60.5 * DEG)]], AWAY,
     (30.0, 9.0, 0.0), {"elevation": True},
     [("scenario.targets[1].scatterers[1]",
       [0.0, 0.0, round(-10 * math.tan(60.5 * DEG), 6), 2.0], UP.format(0, -60.5))]),
    ("within the elevation", [[0.0, 0.0, 10 * math.tan(59.5 * DEG)]], AWAY, (30.0, 9.0, 0.0),
     {"elevation": True}, []),
    ("no elevation processing", [[0.0, 0.0, 10 * math.tan(60.5 * DEG)]], AWAY, (30.0, 9.0, 0.0),
     {}, []),
    ("just behind", [[5.0, BEHIND, 0.0]], AWAY, (30.0, 9.0, 0.0), {},
     [("scenario.targets[1].scatterers[0]", [5.0, round(BEHIND, 6), 0.0, 1.0],
       FRONT.format(0, 90.5))]),
    # within a metre of the RuT: its radial velocity and elevation as they are
    ("near, fast and steep", [[0.0, -9.8, 0.4]], AWAY, (30.0, 2.0, 0.0),
     {"compensate": False, "elevation": True},
     [("scenario.targets[1].scatterers[0]", [0.0, -9.8, 0.4, 1.0], msg) for msg in (
         SLOW.format(2, 0, f"{0.2 * 5.0 / math.hypot(0.2, 0.4):.4g}"),
         UP.format(0, f"{math.degrees(math.asin(0.4 / math.hypot(0.2, 0.4))):.4g}"))]),
    # every rule a scatterer breaks, one message each, in the rules' order; its row rounded
    ("far, fast and behind", [[0.1234567891, -30.0, 0.0]], NEAR, (5.0, 1.0, 0.5), {},
     [("scenario.targets[1].scatterers[0]", [0.123457, -30.0, 0.0, 1.0], msg) for msg in (
         FAR.format(4.5, AIR, 0, f"{math.hypot(0.1234567891, 10.0):.4g}"),
         SLOW.format(1, 0, f"{-5 * -10.0 / math.hypot(0.1234567891, 10.0):.4g}"),
         FRONT.format(0, f"{math.degrees(math.atan2(0.1234567891, -10.0)):.4g}"))]),
]


@pytest.mark.parametrize("points, waypoints, limits, options, want",
                         [c[1:] for c in MOVING_CASES], ids=[c[0] for c in MOVING_CASES])
def test_a_moving_objects_scatterer_is_refused_in_its_first_frame_outside(points, waypoints,
                                                                          limits, options, want):
    """(field, value, whole sentence) of each rule broken: the first frame any scatterer breaks
    it, the first scatterer in that frame, its row as written and its value then."""
    r_lim, v_lim, air = limits
    others = [_moving(TWO, where="scenario.targets[0]"),  # its waypoints refused: not in sps
              dataclass_static(points)]  # a static object: the static rules' own
    scene, sps = _drive(others + [_moving(points)], waypoints, **options)
    got, fail = recorder()
    check_moving_objects(scene, fail, (r_lim, v_lim, "WHY_R", "WHY_V"), air, sps)
    assert got == want


def dataclass_static(points) -> ObjectModel:
    p = np.asarray(points, float) - 1000.0  # far behind the RuT: would break every rule
    return ObjectModel("targets[0]", p, np.zeros(len(p)), None, None, p[:, :2],
                       origin=(0.0, 0.0, 0.0))


FACING = (np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]), np.array([[0, 1, 2]]))


def _mesh(faces, where="scenario.targets[1]") -> ObjectModel:
    v = FACING[0]
    return ObjectModel(where, None, None, v, np.asarray(faces), v[:, :2], moving=True)


def test_a_moving_mesh_is_named_by_its_file_with_no_facet_or_a_scatterer_outside(radar):
    """A mesh with no facet facing the RuT at the first frame: the placement's sentence under
    the mesh's field; a mesh's scatterer outside: the mesh named, its file the value."""
    times = frame_times(1.0, 2.0)
    scene = SimpleNamespace(
        objects=(_mesh([[0, 2, 1]]),), radar=radar,
        rts=SimpleNamespace(arc_radius_m=0.8, compensate_air_path=True),
        scenario=SimpleNamespace(targets=[None, SimpleNamespace(mesh="away.ply")],
                                 frame_times=lambda: times))
    sps = {1: trajectory(AWAY, times), 0: trajectory(AWAY, times)}
    scene.objects += (_moving([[0.0, -12.0, 0.0]], where="scenario.targets[0]"),)
    got, fail = recorder()
    check_moving_objects(scene, fail, (30.0, 9.0, "WHY_R", "WHY_V"), 0.0, sps)
    assert got == [("scenario.targets[1].mesh", "away.ply",
                    "no facet faces the RuT from 10 m (are its normals pointing inwards, or is "
                    "it open towards the RuT?)"),
                   ("scenario.targets[0].scatterers[0]", [0.0, -12.0, 0.0, 1.0],
                    FRONT.format(0, 180))]
    scene.objects = (_mesh(FACING[1]),)
    scene.scenario.targets[1] = SimpleNamespace(mesh="facing.ply")
    got, fail = recorder()
    check_moving_objects(scene, fail, (12.0, 9.0, "WHY_R", "WHY_V"), 0.0, sps)
    pos, _ = object_set_points(scene.objects[0], sps[1], radar)
    r = np.linalg.norm(pos, axis=-1)
    f = int(np.flatnonzero((r >= 12.0).any(axis=1))[0])
    assert got == [("scenario.targets[1].mesh", "facing.ply",
                    FAR.format(12, "", f"{times[f]:g}", f"{r[f][r[f] >= 12.0][0]:.4g}"))]


# ------------------------------------------------------------------------------------------
# Placement
# ------------------------------------------------------------------------------------------

def _static(points, rcs=None, heading=0.0, where="targets[2]") -> ObjectModel:
    p = np.asarray(points, float)
    return ObjectModel(where, p, np.arange(1.0, len(p) + 1) if rcs is None else np.asarray(rcs),
                       None, None, p[:, :2], heading_rad=heading)


@pytest.mark.parametrize("elevation", [False, True])
@pytest.mark.parametrize("heading", [0.0, 0.4, -2.0])
def test_placed_scatterers_are_the_turned_points_at_the_origin_with_their_radial_velocity(
        elevation, heading):
    """range |p|, azimuth atan2(x, y), elevation asin(z / |p|) (0 without the RuT's elevation),
    radial velocity p . v / |p|, the entry's RCS and the object's index, p = o + R(h) x."""
    pts = np.array([[1.0, 2.0, 0.5], [-0.7, -1.1, 0.0], [0.0, 0.3, -0.8]])
    o, v = np.array([2.0, 14.0, 0.3]), np.array([-1.5, 3.0, 0.2])
    got = place(_static(pts, rcs=[4.0, -2.0, 0.5], heading=heading), o, v,
                SimpleNamespace(elevation_processing=elevation), 7)
    c, s = math.cos(heading), math.sin(heading)
    p = o + np.c_[c * pts[:, 0] + s * pts[:, 1], -s * pts[:, 0] + c * pts[:, 1], pts[:, 2]]
    r = np.linalg.norm(p, axis=1)
    want = [TargetConfig(range_m=float(r[n]), velocity_mps=float(p[n] @ v / r[n]),
                         rcs_dbsm=[4.0, -2.0, 0.5][n],
                         angle_rad=float(math.atan2(p[n, 0], p[n, 1])),
                         elevation_rad=float(math.asin(p[n, 2] / r[n])) if elevation else 0.0,
                         object_index=7) for n in range(3)]
    assert len(got) == 3
    for g, w in zip(got, want):
        for k in ("range_m", "velocity_mps", "rcs_dbsm", "angle_rad", "elevation_rad"):
            assert getattr(g, k) == pytest.approx(getattr(w, k), rel=1e-12, abs=1e-12), k
        assert g.object_index == 7 and g.scatterers is None and g.mesh is None
    at_rest = place(_static(pts), o, None, SimpleNamespace(elevation_processing=False), 0)
    assert [t.velocity_mps for t in at_rest] == [0.0, 0.0, 0.0]


@pytest.mark.parametrize("y, refused", [(1e-3, True), (5e-4, True), (1.5e-3, False)])
def test_a_scatterer_at_the_ruT_is_refused_naming_it(y, refused):
    """Within 1 mm of the RuT (the bound itself refused): no direction to place it in."""
    model = _static([[0.0, 2.0, 0.0], [0.0, y, 0.0], [0.0, 3.0, 0.0]])
    radar = SimpleNamespace(elevation_processing=False)
    if not refused:
        assert place(model, np.zeros(3), None, radar, 0)[1].range_m == y
        return
    with pytest.raises(SceneError) as exc:
        place(model, np.zeros(3), None, radar, 0)
    assert str(exc.value) == ("targets[2].scatterers[1]: lies at the RuT (range 0): move the "
                              "object or its scatterer")


def test_a_placed_mesh_is_its_facets_as_the_ruT_sees_them(radar):
    """A mesh's scatterers are mesh_scatterers' from the RuT in the object's frame (the
    resolution cell in direction 2 / virtual channels), turned and carried to the origin; no
    facet facing the RuT is refused with the origin's distance."""
    from rtsgeom.scene.mesh import mesh_scatterers
    o = np.array([3.0, 10.0, 0.0])
    model = ObjectModel("targets[0]", None, None, FACING[0], FACING[1], FACING[0][:, :2],
                        heading_rad=0.3)
    got = place(model, o, None, radar, 2)
    c, s = math.cos(0.3), math.sin(0.3)
    turn = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
    pts, rcs = mesh_scatterers(FACING[0], FACING[1], turn.T @ (-o), radar.wavelength_m,
                               radar.range_resolution_m,
                               2.0 / (radar.num_tx_active * radar.num_rx))
    p = o + pts @ turn.T
    assert len(got) == len(pts) >= 1
    assert np.allclose([t.range_m for t in got], np.linalg.norm(p, axis=1), rtol=1e-12)
    assert np.allclose([t.angle_rad for t in got], np.arctan2(p[:, 0], p[:, 1]), rtol=1e-12)
    assert [t.rcs_dbsm for t in got] == list(rcs)
    away = ObjectModel("targets[0]", None, None, FACING[0], FACING[1][:, ::-1],
                       FACING[0][:, :2])
    with pytest.raises(SceneError) as exc:
        place(away, np.array([0.0, 12.5, 0.0]), None, radar, 0)
    assert str(exc.value) == ("targets[0].mesh: no facet faces the RuT from 12.5 m (are its "
                              "normals pointing inwards, or is it open towards the RuT?)")


# ------------------------------------------------------------------------------------------
# Loading: the models, the errors, the cap on the expanded targets
# ------------------------------------------------------------------------------------------

def test_objects_load_into_their_models_and_targets_in_file_order():
    """Point targets keep their place; each object's scatterers follow in its place with its
    index; the models of the static objects (their origins, headings) then the drive's."""
    doc = bench_doc([{"range_m": 9.0}, {"range_m": 15.0, "angle_deg": 5.0, "heading_deg": 30.0,
                                        "scatterers": [[0.0, 0.0, 0.0, 1.0],
                                                       [0.5, 1.0, 0.0, 2.0]]},
                     {"range_m": 11.0}, {"range_m": 20.0, "scatterers": [[1.0, 0.0, 0.0, 3.0]]}])
    drive = copy.deepcopy(CAR["scenario"])
    drive["targets"].append({"waypoints": [[0.0, 12.0, 0.0]], "rcs_dbsm": 4.0})
    drive["targets"][0]["heading"] = "fixed"
    drive["targets"][0]["heading_deg"] = -20.0
    doc["scenario"] = drive
    s = parse_scene(doc, "o.toml")
    assert [t.object_index for t in s.targets] == [-1, 0, 0, -1, 1]
    assert [t.range_m for t in s.targets][::3] == [9.0, 11.0]
    assert [m.where for m in s.objects] == ["targets[1]", "targets[3]", "scenario.targets[0]"]
    assert [(m.moving, m.along_velocity) for m in s.objects] == [(False, False), (False, False),
                                                                 (True, False)]
    assert [m.heading_rad for m in s.objects] == pytest.approx([30 * DEG, 0.0, -20 * DEG])
    u = np.array([math.sin(5 * DEG), math.cos(5 * DEG), 0.0])
    assert np.allclose(s.objects[0].origin, 15.0 * u, rtol=0, atol=1e-12)
    assert s.objects[1].origin == (0.0, 20.0, 0.0) and s.objects[2].origin is None
    assert np.array_equal(s.objects[0].points, [[0.0, 0.0, 0.0], [0.5, 1.0, 0.0]])
    assert np.array_equal(s.objects[0].rcs_dbsm, [1.0, 2.0])
    assert s.objects[0].vertices is None and s.objects[0].faces is None
    assert len(s.scenario.targets) == 2 and targets_per_frame(s) == 5 + 12 + 1
    car = parse_scene(copy.deepcopy(CAR), "car.toml")
    assert car.objects[0].along_velocity and car.objects[0].moving


@pytest.mark.parametrize("drive", [False, True])
def test_an_object_of_scatterers_and_a_mesh_is_refused_in_full(drive):
    entry = {"scatterers": [[0.0, 0.0, 0.0, 1.0]], "mesh": "car.ply"}
    if drive:
        doc = copy.deepcopy(CAR)
        doc["scenario"]["targets"][0].update(mesh="car.ply")
        where = "scenario.targets[0]"
    else:
        doc = bench_doc([{"range_m": 9.0}, {"range_m": 15.0, **entry}])
        where = "targets[1]"
    with pytest.raises(SceneError) as exc:
        parse_scene(doc, "o.toml", base_dir=SCENES)
    assert str(exc.value) == (f"o.toml: {where}.mesh = 'car.ply': must be left out where "
                              f"{where}.scatterers is given (an object is one or the other)")


def test_a_static_scatterer_at_the_ruT_is_refused_on_load_naming_the_file():
    with pytest.raises(SceneError) as exc:
        parse_scene(bench_doc([{"range_m": 15.0, "scatterers": [[0.0, 1.0, 0.0, 1.0],
                                                                [0.0, -15.0, 0.0, 1.0]]}]),
                    "o.toml")
    assert str(exc.value) == ("o.toml: targets[0].scatterers[1]: lies at the RuT (range 0): "
                              "move the object or its scatterer")


@pytest.mark.parametrize("objects, refused", [(4, False), (5, True)])
def test_objects_expand_to_at_most_max_targets(objects, refused):
    """4 objects of 256 scatterers are the 1024 point targets allowed; a fifth is refused with
    the count it makes."""
    row = [[0.0, 0.0, 0.0, 1.0]] * 256
    doc = bench_doc([{"range_m": 10.0 + k, "scatterers": row} for k in range(objects)])
    if not refused:
        assert len(parse_scene(doc, "o.toml").targets) == 1024
        return
    with pytest.raises(SceneError) as exc:
        parse_scene(doc, "o.toml")
    assert str(exc.value) == ("o.toml: targets: must expand to at most 1024 point targets (its "
                              "objects' scatterers make 1280)")


# ------------------------------------------------------------------------------------------
# Labels, fields and counts
# ------------------------------------------------------------------------------------------

def test_labels_name_points_scatterers_meshes_and_a_drives_moving_targets():
    """As the file writes them: a point target by its entry's index (an object's entry counted
    once), a scatterer by its object's entry, a mesh's by its number, a drive's moving point
    targets after ``moving_from`` by their scenario entry (an object's entries skipped)."""
    pts = np.zeros((2, 3))
    objects = (ObjectModel("targets[1]", pts, np.zeros(2), None, None, pts[:, :2]),
               ObjectModel("targets[3]", None, None, np.zeros((3, 3)), np.zeros((1, 3), int),
                           pts[:, :2]),
               ObjectModel("scenario.targets[1]", pts, np.zeros(2), None, None, pts[:, :2],
                           moving=True))
    drive = SimpleNamespace(targets=[SimpleNamespace(scatterers=None, mesh=None),
                                     SimpleNamespace(scatterers=((0, 0, 0, 0),), mesh=None),
                                     SimpleNamespace(scatterers=None, mesh="m.ply"),
                                     SimpleNamespace(scatterers=None, mesh=None)])
    t = [TargetConfig(range_m=1.0, object_index=o) for o in (-1, 0, 0, -1, 1, 1, 1, -1, -1,
                                                            -1, -1, 2, 2)]
    scene = SimpleNamespace(targets=t[:8], objects=objects, scenario=drive)
    assert target_labels(scene) == [
        "targets[0]", "targets[1].scatterers[0]", "targets[1].scatterers[1]", "targets[2]",
        "targets[3].mesh (scatterer 0)", "targets[3].mesh (scatterer 1)",
        "targets[3].mesh (scatterer 2)", "targets[4]"]
    frame = target_labels(scene, t, moving_from=8)
    assert frame[8:] == ["scenario.targets[0]", "scenario.targets[3]", "targets[5]",
                         "scenario.targets[1].scatterers[0]", "scenario.targets[1].scatterers[1]"]
    assert target_labels(scene, t)[8:10] == ["targets[5]", "targets[6]"]
    assert target_labels(SimpleNamespace(targets=t[:1], objects=(), scenario=None)) == [
        "targets[0]"]


@pytest.mark.parametrize("label, want", [
    ("targets[2]", "targets[2].range_m"),
    ("targets[1].scatterers[2]", "targets[1].scatterers[2] (its range_m)"),
    ("targets[1].mesh (scatterer 0)", "targets[1].mesh (scatterer 0) (its range_m)"),
    ("scenario.targets[0]", "scenario.targets[0].range_m"),
])
def test_a_targets_field_is_named_as_the_file_writes_it(label, want):
    assert target_field(label, "range_m") == want


def test_a_drives_targets_per_frame_count_each_entrys_scatterers():
    from rtsgeom.scene.mesh import MAX_MESH_SCATTERERS
    drive = SimpleNamespace(targets=[SimpleNamespace(scatterers=((0, 0, 0, 0),) * 3, mesh=None),
                                     SimpleNamespace(scatterers=None, mesh="m.ply"),
                                     SimpleNamespace(scatterers=None, mesh=None)])
    assert MAX_MESH_SCATTERERS == 32
    assert targets_per_frame(SimpleNamespace(targets=(1, 2), scenario=drive)) == 2 + 3 + 32 + 1


# ------------------------------------------------------------------------------------------
# A drive's frames
# ------------------------------------------------------------------------------------------

@pytest.mark.parametrize("elevation", [False, True])
def test_a_drives_frames_carry_each_moving_objects_scatterers_at_its_pose(elevation):
    """Frame f's scatterers of the moving object k (its index among the scene's objects, a
    static one skipped) at object_set_points' positions: range, azimuth, elevation (0 without
    the RuT's), radial velocity p . v / |p| and the points' RCS."""
    times = frame_times(0.5, 1.0)
    wp = [[0.0, 12.0, -0.2, 0.05], [1.0, 9.0, 0.3, 0.0]]
    sp = trajectory(wp, times)
    mov = _moving([[0.5, 1.0, 0.4], [-0.5, -2.0, 0.0]], rcs=[3.0, -1.0], along_velocity=True)
    scene = SimpleNamespace(objects=(_static([[0.0, 0.0, 0.0]]), mov),
                            radar=SimpleNamespace(elevation_processing=elevation),
                            source="d.toml")
    out = frame_objects(scene, {1: sp}, times.size)
    pos, vel = object_set_points(mov, sp, None)
    assert len(out) == 3 and all(len(f) == 2 for f in out)
    for f, frame in enumerate(out):
        for n, t in enumerate(frame):
            p = pos[f, n]
            r = np.linalg.norm(p)
            assert (t.object_index, t.rcs_dbsm) == (1, [3.0, -1.0][n])
            assert t.range_m == pytest.approx(r, rel=1e-12)
            assert t.angle_rad == pytest.approx(math.atan2(p[0], p[1]), abs=1e-12)
            assert t.elevation_rad == pytest.approx(math.asin(p[2] / r) if elevation else 0.0,
                                                    abs=1e-12)
            assert t.velocity_mps == pytest.approx(p @ vel[f] / r, rel=1e-12, abs=1e-12)
    two = frame_objects(SimpleNamespace(objects=(mov, mov), radar=scene.radar), {1: sp}, 3)
    assert [[t.object_index for t in frame] for frame in two] == [[0, 0, 1, 1]] * 3


def test_a_drives_mesh_with_no_facet_facing_is_refused_naming_the_file(radar):
    times = frame_times(1.0, 1.0)
    scene = SimpleNamespace(objects=(_mesh([[0, 2, 1]], where="scenario.targets[0]"),),
                            radar=radar, source="d.toml")
    with pytest.raises(SceneError) as exc:
        frame_objects(scene, {0: trajectory(AWAY, times)}, times.size)
    assert str(exc.value) == ("d.toml: scenario.targets[0].mesh: no facet faces the RuT from "
                              "10 m (are its normals pointing inwards, or is it open towards "
                              "the RuT?)")


def test_a_moving_objects_pose_is_its_drives_and_a_static_ones_its_origin():
    """pose(scene, f): the waypoints' position and velocity at frame f (the entry named by
    the model's index); a static object rests at its origin."""
    wp = np.array([[0.0, 10.0, 0.1, 0.0], [2.0, 14.0, -0.2, 0.0]])
    drive = SimpleNamespace(targets=[None, None, SimpleNamespace(waypoints=wp)],
                            frame_times=lambda: frame_times(0.5, 2.0))
    m = _moving(TWO, where="scenario.targets[2]")
    sp = trajectory(wp, frame_times(0.5, 2.0))
    for f in (0, 3):
        o, v = m.pose(SimpleNamespace(scenario=drive), f)
        assert np.array_equal(o, sp.position_m[f]) and np.array_equal(v, sp.velocity_vec_mps[f])
    s = ObjectModel("targets[0]", np.zeros((1, 3)), np.zeros(1), None, None, np.zeros((1, 2)),
                    origin=(1.0, 2.0, 3.0))
    o, v = s.pose(None, 4)
    assert np.array_equal(o, [1.0, 2.0, 3.0]) and np.array_equal(v, np.zeros(3))


# ------------------------------------------------------------------------------------------
# Meshes: loaded into their models, frozen at a drive's first frame
# ------------------------------------------------------------------------------------------

def test_mesh_objects_load_into_models_of_the_files_geometry():
    """A static and a moving mesh entry: the file's vertices and facets, the footprint's hull
    of its (x, y), the heading (fixed, or along the motion), moving or not; an entry of
    scatterers: its rows, its footprint's hull."""
    from rtsgeom.scene.mesh import load_mesh
    from rtsgeom.scene.objects import _hull
    doc = copy.deepcopy(CAR)
    del doc["scenario"]["targets"][0]["scatterers"]
    doc["scenario"]["targets"][0]["mesh"] = "car.ply"
    doc["targets"] = [{"range_m": 15.0, "mesh": "car.ply", "heading_deg": 30.0},
                      {"range_m": 12.0, "angle_deg": 20.0, "scatterers": [
                          [0.5, 1.0, 0.2, 1.0], [-0.5, 1.0, 0.0, 2.0], [0.0, -1.0, 0.0, 3.0]]}]
    s = parse_scene(doc, "m.toml", base_dir=SCENES)
    v, f = load_mesh(str(SCENES / "car.ply"), "targets[0].mesh", "m.toml")
    static, points, moving = s.objects
    for m, where in ((static, "targets[0]"), (moving, "scenario.targets[0]")):
        assert m.where == where and m.points is None and m.rcs_dbsm is None
        assert np.array_equal(m.vertices, v) and np.array_equal(m.faces, f)
        assert np.array_equal(m.outline, _hull(v[:, :2]))
    assert (static.heading_rad, static.along_velocity, static.moving) == (
        pytest.approx(30 * DEG), False, False)
    assert (moving.heading_rad, moving.along_velocity, moving.moving) == (0.0, True, True)
    rows = np.array([[0.5, 1.0, 0.2], [-0.5, 1.0, 0.0], [0.0, -1.0, 0.0]])
    assert np.array_equal(points.points, rows) and np.array_equal(points.rcs_dbsm, [1, 2, 3])
    assert np.array_equal(points.outline, _hull(rows[:, :2])) and len(points.outline) == 3


def test_a_moving_mesh_is_frozen_as_the_ruT_sees_it_at_the_first_frame(radar):
    """Its scatterers the placement's at the first frame (turned along that frame's motion),
    back in the object's frame: carried to the first frame they lie where placed, at
    elevation 0 for an RuT without it; their RCS the placed ones'."""
    from rtsgeom.scene.mesh import load_mesh
    from rtsgeom.scene.objects import _mesh_frozen
    v, f = load_mesh(str(SCENES / "car.ply"), "m", "m")
    m = ObjectModel("scenario.targets[0]", None, None, v, f, v[:, :2], heading_rad=0.5,
                    along_velocity=True, moving=True)
    wp = [[0.0, 14.0, -0.3, 0.0], [1.0, 12.0, 0.1, 0.0], [2.0, 13.0, 0.4, 0.0]]
    sp = trajectory(wp, frame_times(1.0, 2.0))
    first = place(m, sp.position_m[0], sp.velocity_vec_mps[0], radar, 0)
    frozen = _mesh_frozen(m, sp, radar)
    assert len(first) >= 3 and frozen.vertices is v and frozen.along_velocity
    assert np.array_equal(frozen.rcs_dbsm, [t.rcs_dbsm for t in first])
    pos, _ = object_set_points(frozen, sp, radar)
    want = np.array([[t.range_m * math.sin(t.angle_rad), t.range_m * math.cos(t.angle_rad), 0.0]
                     for t in first])
    assert np.allclose(pos[0], want, rtol=0, atol=1e-9)
    h = math.atan2(*sp.velocity_vec_mps[0][:2])
    c, s = math.cos(h), math.sin(h)
    local = (want - sp.position_m[0]) @ np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
    assert np.allclose(frozen.points, local, rtol=0, atol=1e-9)


def test_a_car_meshs_placed_scatterers_are_merged_to_the_ruTs_resolution(radar):
    """The bundled car turned 30 deg 15 m ahead: its scatterers are mesh_scatterers' with the
    direction cell 2 / (Tx active x Rx) of the RuT's virtual array, carried to the origin."""
    from rtsgeom.scene.mesh import load_mesh, mesh_scatterers
    v, f = load_mesh(str(SCENES / "car.ply"), "m", "m")
    o = np.array([0.0, 15.0, 0.0])
    turn = np.array([[math.cos(0.5), math.sin(0.5), 0.0], [-math.sin(0.5), math.cos(0.5), 0.0],
                     [0.0, 0.0, 1.0]])
    got = place(ObjectModel("targets[0]", None, None, v, f, v[:, :2], heading_rad=0.5), o,
                None, radar, 0)
    pts, rcs = mesh_scatterers(v, f, turn.T @ (-o), radar.wavelength_m,
                               radar.range_resolution_m, 2.0 / (radar.num_tx_active * radar.num_rx))
    p = o + pts @ turn.T
    assert len(got) == len(pts) > 3
    assert np.allclose([t.range_m for t in got], np.linalg.norm(p, axis=1), rtol=1e-12)
    assert np.allclose([t.angle_rad for t in got], np.arctan2(p[:, 0], p[:, 1]), atol=1e-12)
    assert np.allclose([t.rcs_dbsm for t in got], rcs, rtol=1e-12)


def test_static_objects_expand_at_their_direction_and_velocity(radar):
    """The origin r (cos e sin a, cos e cos a, sin e) and the entry's radial velocity along
    it; a placement's error names the scene, or <scene> without a file."""
    import dataclasses
    from rtsgeom.scene.objects import expand_objects
    base = parse_scene(bench_doc([]), "b.toml")
    a, e = 0.2, 0.15
    entry = TargetConfig(range_m=15.0, velocity_mps=-3.0, angle_rad=a, elevation_rad=e,
                         scatterers=((0.0, 0.0, 0.0, 1.0), (1.0, 0.5, 0.3, 2.0)))
    scene = dataclasses.replace(base, targets=(entry,), source=None,
                                radar=dataclasses.replace(radar, elevation_processing=True))
    s = expand_objects(scene, {})
    u = np.array([math.cos(e) * math.sin(a), math.cos(e) * math.cos(a), math.sin(e)])
    assert np.allclose(s.objects[0].origin, 15.0 * u, rtol=0, atol=1e-12)
    for t, x in zip(s.targets, ([0.0, 0.0, 0.0], [1.0, 0.5, 0.3])):
        p = 15.0 * u + np.array(x)
        r = np.linalg.norm(p)
        assert t.range_m == pytest.approx(r, rel=1e-12)
        assert t.velocity_mps == pytest.approx(p @ (-3.0 * u) / r, rel=1e-12)
        assert t.elevation_rad == pytest.approx(math.asin(p[2] / r), abs=1e-12)
    at_ruT = dataclasses.replace(entry, scatterers=((0.0, -15.0, 0.0, 1.0),), angle_rad=0.0,
                                 elevation_rad=0.0)
    with pytest.raises(SceneError) as exc:
        expand_objects(dataclasses.replace(scene, targets=(at_ruT,)), {})
    assert str(exc.value) == ("<scene>: targets[0].scatterers[0]: lies at the RuT (range 0): "
                              "move the object or its scatterer")


def test_a_placement_along_the_motion_turns_with_the_velocity():
    m = _static([[0.0, 2.0, 0.0]])
    along = ObjectModel("targets[0]", m.points, m.rcs_dbsm, None, None, m.outline,
                        heading_rad=1.0, along_velocity=True)
    o, v = np.array([0.0, 10.0, 0.0]), np.array([3.0, -4.0, 0.0])
    h = math.atan2(3.0, -4.0)
    got = place(along, o, v, SimpleNamespace(elevation_processing=False), 0)[0]
    p = o + 2.0 * np.array([math.sin(h), math.cos(h), 0.0])
    assert got.angle_rad == pytest.approx(math.atan2(p[0], p[1]), abs=1e-12)
    assert got.range_m == pytest.approx(np.linalg.norm(p), rel=1e-12)
