"""Geometric invariants of the setup and its exact paths, checked with hypothesis.

* reciprocity: ``distances(a, b) == distances(b, a).T``, bit for bit, with broadcasting;
* mirror symmetry in azimuth: front-end angles negated and reversed, sheet extent mirrored, RuT
  yaw 0 -> mirrored front-end azimuths and antennas, and the same path lengths seen from a
  mirrored RuT (the AWR1843 layout is not itself mirror-symmetric);
* translation of the whole setup (RuT and arc centre by the same vector) changes no path length;
* rotation of the whole setup about z (RuT yaw, front-end angles, sheet, positions) changes no
  path length and no azimuth seen from the RuT.

Scenes are random but valid: 1-4 front ends on arcs of 0.5-5 m with mounting errors, the RuT
anywhere within +-100 m and off the arc centre.
"""

from __future__ import annotations

import copy
import math
import os

import numpy as np
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.paths.exact import distances
from rtsgeom.errors import SceneError
from rtsgeom.scene import parse_scene

from conftest import default_doc

# RTSGEOM_PROPERTY_EXAMPLES=2000 for a deeper run than the suite's default
PROPS = settings(max_examples=int(os.environ.get("RTSGEOM_PROPERTY_EXAMPLES", "50")),
                 deadline=2000, suppress_health_check=[HealthCheck.too_slow])

finite = st.floats(-10.0, 10.0, allow_nan=False)
points = st.lists(st.tuples(finite, finite, finite), min_size=1, max_size=6).map(np.array)


@st.composite
def setups(draw, sheet: bool = False):
    """Parameters of a random valid setup (a dict; ``scene_of`` turns it into a Scene)."""
    radius = draw(st.floats(0.5, 5.0))
    n = draw(st.integers(1, 4))
    start = draw(st.floats(-50.0, 20.0))
    gaps = draw(st.lists(st.floats(8.0, 10.0), min_size=n - 1, max_size=n - 1))
    angles = list(np.cumsum([start, *gaps]))
    mm = st.floats(-5.0, 5.0)
    fes = [{"angle_deg": float(a), "rx_tx_separation_m": draw(st.floats(0.0, 0.03)),
            "radial_offset_mm": draw(mm), "tangential_offset_mm": draw(mm),
            "height_offset_mm": draw(mm)} for a in angles]
    pos = [draw(st.floats(-100.0, 100.0)) for _ in range(3)]
    off = [draw(st.floats(-0.1, 0.1)) * radius for _ in range(2)] + [draw(st.floats(-0.05, 0.05))]
    return {"radius": radius, "front_ends": fes, "position": pos,
            "centre": [p + o for p, o in zip(pos, off)], "yaw": draw(st.floats(-20.0, 20.0)),
            "sheet": ([min(angles) - draw(st.floats(5.0, 20.0)),
                       max(angles) + draw(st.floats(5.0, 30.0))] if sheet else None)}


def scene_of(p: dict):
    doc = copy.deepcopy(default_doc())
    doc["targets"] = []
    doc["radar"].update(position_m=p["position"], yaw_deg=p["yaw"])
    doc["rts"].update(arc_radius_m=p["radius"], arc_center_m=p["centre"],
                      front_ends=copy.deepcopy(p["front_ends"]))
    if p["sheet"] is None:
        doc["sheet"] = {"enabled": False}
    else:
        doc["sheet"].update(angle_min_deg=p["sheet"][0], angle_max_deg=p["sheet"][1],
                            cutout_diameter_m=0.04)
    try:
        return parse_scene(doc, "property.toml")
    except SceneError as exc:  # a combination the strategy cannot rule out up front
        assume(False)
        raise AssertionError from exc


def lengths(setup) -> np.ndarray:
    return exact_paths(setup).length_m


# --------------------------------------------------------------------------------------------


@PROPS
@given(a=points, b=points)
def test_distances_are_reciprocal(a, b):
    d_ab = distances(a, b)
    assert d_ab.shape == (len(a), len(b))
    assert np.array_equal(d_ab, distances(b, a).T)
    assert np.all(d_ab >= 0.0)
    # broadcasting over leading axes gives the same numbers
    stack = np.stack([a, a + 1.0])
    assert np.array_equal(distances(stack, b)[0], d_ab)


@PROPS
@given(p=setups())
def test_each_leg_is_the_same_length_both_ways(p):
    setup = build_setup(scene_of(p))
    rut, fe = setup.rut, setup.fe
    assert np.array_equal(distances(rut.tx_world, fe.rx), distances(fe.rx, rut.tx_world).T)
    paths = exact_paths(setup)
    # the table's RuT Tx -> FE Rx legs are the FE Rx -> RuT Tx distances
    tx_legs = paths.length_m[paths.direction == 0].reshape(fe.count, -1)
    np.testing.assert_allclose(tx_legs, distances(fe.rx, rut.tx_world), rtol=1e-15, atol=0)


def _mirror(points: np.ndarray) -> np.ndarray:
    return points * np.array([-1.0, 1.0, 1.0])


@PROPS
@given(p=setups(sheet=True))
def test_mirror_symmetry_in_azimuth(p):
    p["yaw"] = 0.0
    m = copy.deepcopy(p)
    m["front_ends"] = [dict(fe, angle_deg=-fe["angle_deg"],
                            tangential_offset_mm=-fe["tangential_offset_mm"])
                       for fe in reversed(p["front_ends"])]
    m["sheet"] = [-p["sheet"][1], -p["sheet"][0]]
    m["position"] = [-p["position"][0], *p["position"][1:]]
    m["centre"] = [-p["centre"][0], *p["centre"][1:]]
    s, t = build_setup(scene_of(p)), build_setup(scene_of(m))
    # front-end azimuths seen from the RuT: negated, in reverse order
    np.testing.assert_allclose(t.fe_azimuth_rad(), -s.fe_azimuth_rad()[::-1], rtol=0, atol=1e-12)
    # antennas: the mirror image of an Rx (towards larger azimuth) is the mirrored Tx
    np.testing.assert_allclose(t.fe.rx, _mirror(s.fe.tx)[::-1], rtol=0, atol=1e-12)
    np.testing.assert_allclose(t.fe.tx, _mirror(s.fe.rx)[::-1], rtol=0, atol=1e-12)
    # every path length, seen from a mirrored RuT
    rut_tx, rut_rx = _mirror(s.rut.tx_world), _mirror(s.rut.rx_world)
    np.testing.assert_allclose(distances(t.fe.tx, rut_tx), distances(s.fe.rx, s.rut.tx_world)[::-1],
                               rtol=1e-12)
    np.testing.assert_allclose(distances(t.fe.rx, rut_rx), distances(s.fe.tx, s.rut.rx_world)[::-1],
                               rtol=1e-12)
    # the sheet is the mirror image too: mirrored bounds, the same volume up to the faceting of
    # the cutouts (a 64-gon rotated into place is not the mirror image of its twin)
    if s.fe.count == 1:  # mesh booleans are the slow part
        np.testing.assert_allclose(t.sheet.volume, s.sheet.volume, rtol=1e-6)
        np.testing.assert_allclose(t.sheet.bounds[:, 0], -s.sheet.bounds[::-1, 0], atol=1e-9)


@PROPS
@given(p=setups(), shift=st.tuples(*[st.floats(-100.0, 100.0)] * 3))
def test_translation_changes_no_path_length(p, shift):
    q = copy.deepcopy(p)
    q["position"] = [a + b for a, b in zip(p["position"], shift)]
    q["centre"] = [a + b for a, b in zip(p["centre"], shift)]
    s, t = build_setup(scene_of(p)), build_setup(scene_of(q))
    np.testing.assert_allclose(lengths(t), lengths(s), rtol=1e-12, atol=0)
    np.testing.assert_allclose(t.fe_azimuth_rad(), s.fe_azimuth_rad(), rtol=0, atol=1e-12)


def _rotate(point, phi_deg: float) -> list[float]:
    """Rotate about z by ``phi`` in the azimuth sense (from +y towards +x)."""
    ph = math.radians(phi_deg)
    x, y, z = point
    return [x * math.cos(ph) + y * math.sin(ph), -x * math.sin(ph) + y * math.cos(ph), z]


@PROPS
@given(p=setups(), phi=st.floats(-30.0, 30.0))
def test_rotation_about_z_changes_no_path_length(p, phi):
    q = copy.deepcopy(p)
    q["yaw"] = p["yaw"] + phi
    q["front_ends"] = [dict(fe, angle_deg=fe["angle_deg"] + phi) for fe in p["front_ends"]]
    q["position"] = _rotate(p["position"], phi)
    q["centre"] = _rotate(p["centre"], phi)
    s, t = build_setup(scene_of(p)), build_setup(scene_of(q))
    np.testing.assert_allclose(lengths(t), lengths(s), rtol=1e-12, atol=0)
    # ...and the radar sees everything at the same azimuths
    np.testing.assert_allclose(t.fe_azimuth_rad(), s.fe_azimuth_rad(), rtol=0, atol=1e-12)


@PROPS
@given(p=setups())
def test_random_setups_are_valid_and_warnings_run(p):
    """The strategy above really produces valid scenes (few rejections), so the properties
    are not vacuous; the loader's scalar geometry (used by its consistency checks) agrees with
    the geometry package."""
    from rtsgeom.scene.rules import arc_centre_m, azimuth_from_radar_rad, front_end_module_m
    from rtsgeom.geometry.warnings import scene_warnings
    scene = scene_of(p)
    assert all(w.startswith("property.toml: ") for w in scene_warnings(scene))
    setup = build_setup(scene)
    modules = np.array([front_end_module_m(arc_centre_m(scene), scene.rts.arc_radius_m, fe)
                        for fe in scene.rts.front_ends])
    np.testing.assert_allclose(modules, setup.fe.module, rtol=0, atol=1e-12)
    az = [azimuth_from_radar_rad(scene.radar, m) for m in modules]
    np.testing.assert_allclose(az, setup.fe_azimuth_rad(), rtol=0, atol=1e-12)
