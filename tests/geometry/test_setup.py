"""The setup as built and as designed (``rtsgeom.geometry.setup``): the errors a scene
carries named in full and in order, the warning about them (three named, the rest counted),
the nominal scene and setup (the same objects where nothing is zeroed), the pose and mounting
overrides of ``build_setup`` and the front ends' directions seen from the RuT in closed form."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest

from conftest import ROOT, default_doc
from rtsgeom.errors import NominalSetupWarning
from rtsgeom.geometry.setup import (DRAWS_REPLACE, FRONT_END_ERRORS, RUT_POSE_ERRORS,
                                    build_setup, nominal_scene, nominal_setup, setup_errors,
                                    warn_setup_errors)
from rtsgeom.scene import load_scene, parse_scene


def _doc_scene(fe0=None, fe1=None, radar=None, channels=None):
    doc = copy.deepcopy(default_doc())
    doc["rts"]["front_ends"][0].update(fe0 or {})
    doc["rts"]["front_ends"][1].update(fe1 or {})
    doc["radar"].update(radar or {})
    if channels:
        doc["radar"]["channels"] = channels
    return parse_scene(doc, "s.toml")


EVERY = dict(fe0={"radial_offset_mm": 0.1, "pitch_offset_deg": 0.5},
             fe1={"tangential_offset_mm": -0.1, "height_offset_mm": 0.2, "yaw_offset_deg": 1.0,
                  "gain_offset_db": 0.3, "phase_offset_deg": 5.0},
             radar={"position_offset_mm": [0.0, 0.1, 0.0], "yaw_offset_deg": 0.2},
             channels={"rx_phase_deg": [0.0, 10.0, 0.0, 0.0]})
EVERY_FIELDS = ["rts.front_ends[0].radial_offset_mm", "rts.front_ends[0].pitch_offset_deg",
                "rts.front_ends[1].tangential_offset_mm", "rts.front_ends[1].height_offset_mm",
                "rts.front_ends[1].yaw_offset_deg", "rts.front_ends[1].gain_offset_db",
                "rts.front_ends[1].phase_offset_deg", "radar.position_offset_mm",
                "radar.yaw_offset_deg", "radar.channels"]


def test_the_errors_a_scene_carries_in_full_and_in_order():
    assert FRONT_END_ERRORS == ("radial_offset_m", "tangential_offset_m", "height_offset_m",
                                "yaw_offset_rad", "pitch_offset_rad", "gain_offset_db",
                                "phase_offset_rad")
    assert RUT_POSE_ERRORS == ("position_offset_m", "yaw_offset_rad")
    assert setup_errors(_doc_scene(**EVERY)) == EVERY_FIELDS
    assert setup_errors(_doc_scene()) == []
    assert setup_errors(_doc_scene(radar={"position_offset_mm": [0.0, 0.0, -0.1]})) == [
        "radar.position_offset_mm"]
    # ideal channels given explicitly are no error
    assert setup_errors(_doc_scene(channels={"rx_phase_deg": [0.0] * 4})) == []


@pytest.mark.parametrize("n, named", [(1, 1), (3, 3), (4, 3), (10, 3)])
def test_the_warning_names_three_fields_and_counts_the_rest(n, named):
    from conftest import the_warnings
    scene = _doc_scene(**EVERY)
    fields = EVERY_FIELDS[:n]
    import rtsgeom.geometry.setup as setup_mod

    got = []
    orig = setup_mod.setup_errors
    try:
        setup_mod.setup_errors = lambda s: list(fields)
        msgs = the_warnings(lambda: got.append(warn_setup_errors(scene, "design")),
                            NominalSetupWarning)
        msgs2 = the_warnings(lambda: warn_setup_errors(scene, "kpi", "works on {} alone"),
                             NominalSetupWarning)
    finally:
        setup_mod.setup_errors = orig
    more = f" and {n - 3} more" if n > 3 else ""
    listed = ", ".join(fields[:named]) + more
    assert got == [fields]
    assert msgs == ["design " + DRAWS_REPLACE.format(listed)]
    assert msgs2 == [f"kpi works on {listed} alone"]


def test_a_scene_without_errors_is_not_warned_about():
    from conftest import the_warnings
    got = []
    assert the_warnings(lambda: got.append(warn_setup_errors(_doc_scene(), "tolerance")),
                        NominalSetupWarning) == []
    assert got == [[]]


def test_the_nominal_scene_zeroes_every_error_and_keeps_the_rest():
    """Every error zero, the channels ideal (none), a front end without errors the same
    object; a scene without errors itself; its setup then the same setup."""
    scene = _doc_scene(fe1=EVERY["fe1"], radar=EVERY["radar"], channels=EVERY["channels"])
    nom = nominal_scene(scene)
    assert setup_errors(nom) == []
    assert nom.rts.front_ends[0] is scene.rts.front_ends[0]
    for name in FRONT_END_ERRORS:
        assert getattr(nom.rts.front_ends[1], name) == 0.0
    assert nom.radar.channels is None and nom.radar.yaw_offset_rad == 0.0
    assert tuple(nom.radar.position_offset_m) == (0.0, 0.0, 0.0)
    assert nom.rts.front_ends[1].angle_rad == scene.rts.front_ends[1].angle_rad
    assert nom.targets == scene.targets and nom.sheet == scene.sheet
    clean = _doc_scene()
    assert nominal_scene(clean) is clean
    s = build_setup(clean)
    assert nominal_setup(s) is s
    only_channels = _doc_scene(channels=EVERY["channels"])
    assert nominal_scene(only_channels).radar.channels is None
    only_pose = _doc_scene(radar={"yaw_offset_deg": 0.2})
    assert nominal_scene(only_pose).radar.yaw_offset_rad == 0.0
    moved = build_setup(scene)
    nominal = nominal_setup(moved)
    np.testing.assert_allclose(nominal.fe.module, build_setup(nom).fe.module, atol=0)
    assert not np.allclose(nominal.fe.module, moved.fe.module, rtol=0, atol=1e-9)


def test_build_setup_takes_the_pose_and_mounting_overrides(default_scene):
    """The RuT's position and yaw errors and the front ends' offsets and rotations given
    instead of the scene's, each as its own function places them."""
    from rtsgeom.geometry.arrays import rut_array
    from rtsgeom.geometry.frontends import front_ends
    from rtsgeom.scene.rules import arc_centre_m
    off = np.array([[1e-4, -2e-4, 3e-4], [0.0, 5e-4, -1e-4]])
    yaw, pitch = np.array([0.01, -0.02]), np.array([0.0, 0.015])
    s = build_setup(default_scene, off, yaw_rad=yaw, pitch_rad=pitch,
                    rut_offset_m=np.array([1e-3, 0.0, -2e-3]), rut_yaw_rad=0.004)
    rut = rut_array(default_scene.radar, position_offset_m=np.array([1e-3, 0.0, -2e-3]),
                    yaw_offset_rad=0.004)
    np.testing.assert_array_equal(s.rut.position, rut.position)
    np.testing.assert_array_equal(s.rut.rx_world, rut.rx_world)
    np.testing.assert_array_equal(s.rut.tx_world, rut.tx_world)
    fe = front_ends(default_scene, np.asarray(arc_centre_m(default_scene), float), yaw_rad=yaw,
                    pitch_rad=pitch, offsets_m=off)
    for name in ("rx", "tx", "module", "offsets_m", "yaw_rad", "pitch_rad", "arc_centre"):
        np.testing.assert_array_equal(getattr(s.fe, name), getattr(fe, name))
    plain = build_setup(default_scene)
    assert not np.array_equal(plain.rut.rx_world, s.rut.rx_world)
    yawed = build_setup(default_scene, rut_yaw_rad=0.004)
    np.testing.assert_allclose(yawed.fe_azimuth_rad(), plain.fe_azimuth_rad() - 0.004,
                               rtol=0, atol=1e-12)


def test_the_front_ends_directions_seen_from_the_rut_in_closed_form():
    """RuT at the arc centre: u = (sin az cos el, sin el) of each front end's angles on the
    sphere, az the azimuth seen from the RuT; dims 1: sin az alone."""
    scene = load_scene(ROOT / "scenes" / "sphere4.toml")
    s = build_setup(scene)
    az = np.array([f.angle_rad for f in scene.rts.front_ends])
    el = np.array([f.elevation_rad for f in scene.rts.front_ends])
    assert np.any(el != 0)
    np.testing.assert_allclose(s.fe_direction_cosines(),
                               np.stack([np.sin(az) * np.cos(el), np.sin(el)], -1), atol=1e-12)
    np.testing.assert_allclose(s.fe_direction_cosines(1)[:, 0], np.sin(s.fe_azimuth_rad()),
                               atol=0)
    assert s.fe_direction_cosines(1).shape == (4, 1)
    np.testing.assert_allclose(s.fe_azimuth_rad(), np.arctan2(np.sin(az) * np.cos(el),
                                                              np.cos(az) * np.cos(el)),
                               atol=1e-12)


def test_the_sheet_is_built_once_or_not_at_all(default_scene):
    import rtsgeom
    s = build_setup(default_scene)
    assert s.sheet is s.sheet and s.sheet.is_watertight
    off = build_setup(rtsgeom.replace(default_scene, sheet=rtsgeom.replace(
        default_scene.sheet, enabled=False)))
    assert off.sheet is None
    assert math.isclose(float(np.min(np.hypot(*(s.sheet.vertices - s.fe.arc_centre)[:, :2].T))),
                        s.fe.arc_radius_m + default_scene.sheet.radius_offset_m, abs_tol=2e-5)
