"""The draws' error scales (Bounds): tolerances to scales (a sigma level for normal errors, the
bound itself for uniform ones), scaling, the flags of rotation and RuT-pose errors, the check,
in closed form."""

from __future__ import annotations

import math

import pytest

from rtsgeom.analysis.tolerance.draws import Bounds
from rtsgeom.errors import ParameterError

TOL = {"offsets_m": (3e-4, 6e-4, 9e-4), "yaw_rad": 0.03, "pitch_rad": 0.06,
       "rut_position_m": (1e-3, 2e-3, 3e-3), "rut_yaw_rad": 0.009}


@pytest.mark.parametrize("distribution, level, k", [("normal", 3.0, 1 / 3), ("normal", 2.0, 0.5),
                                                    ("uniform", 3.0, 1.0), ("uniform", 2.0, 1.0)])
def test_bounds_from_tolerances_divide_by_the_sigma_level_for_normal_errors(distribution, level,
                                                                            k):
    b = Bounds.from_tolerances(TOL, distribution, level)
    assert b.offsets_m == pytest.approx(tuple(k * v for v in TOL["offsets_m"]), rel=1e-15)
    assert b.rut_position_m == pytest.approx(tuple(k * v for v in TOL["rut_position_m"]),
                                             rel=1e-15)
    assert (b.yaw_rad, b.pitch_rad, b.rut_yaw_rad) == pytest.approx(
        (k * 0.03, k * 0.06, k * 0.009), rel=1e-15)
    assert Bounds.from_tolerances({}, distribution, level) == Bounds()
    assert Bounds.from_tolerances({"yaw_rad": 0.3}, "normal") == Bounds(yaw_rad=0.3 / 3.0)


@pytest.mark.parametrize("s", [0.0, 0.5, 2.0])
def test_bounds_scale_every_field_and_swap_offsets(s):
    b = Bounds.from_tolerances(TOL, "uniform")
    sc = b.scaled(s)
    assert sc == Bounds(tuple(s * v for v in b.offsets_m), s * b.yaw_rad, s * b.pitch_rad,
                        tuple(s * v for v in b.rut_position_m), s * b.rut_yaw_rad)
    w = b.with_offsets([1, 2, 3])
    assert w.offsets_m == (1.0, 2.0, 3.0) and all(type(v) is float for v in w.offsets_m)
    assert (w.yaw_rad, w.pitch_rad, w.rut_position_m, w.rut_yaw_rad) == (
        b.yaw_rad, b.pitch_rad, b.rut_position_m, b.rut_yaw_rad)


@pytest.mark.parametrize("kw, rotations, pose", [
    ({}, False, False), ({"offsets_m": (1e-3,) * 3}, False, False), ({"yaw_rad": 1e-3}, True, False),
    ({"pitch_rad": 1e-3}, True, False), ({"rut_yaw_rad": 1e-3}, False, True),
    ({"rut_position_m": (0.0, 0.0, 1e-3)}, False, True),
    ({"rut_position_m": (1e-3, 0.0, 0.0)}, False, True)])
def test_bounds_flag_rotations_and_rut_pose(kw, rotations, pose):
    b = Bounds(**kw)
    assert (b.rotations, b.rut_pose) == (rotations, pose)
    b.check()


def test_bounds_check_and_dict_in_display_units():
    for kw in ({"yaw_rad": -1e-9}, {"offsets_m": (0.0, math.inf, 0.0)},
               {"rut_position_m": (0.0, 0.0, math.nan)}):
        with pytest.raises(ParameterError, match=r"^tolerance bounds \[.*\]: must be finite "
                                                 r"and >= 0$"):
            Bounds(**kw).check()
    d = Bounds.from_tolerances(TOL, "uniform").to_dict()
    assert d.pop("rut_position_mm") == pytest.approx([1.0, 2.0, 3.0], rel=1e-12)
    assert d == pytest.approx({"radial_mm": 0.3, "tangential_mm": 0.6, "height_mm": 0.9,
                               "yaw_deg": math.degrees(0.03), "pitch_deg": math.degrees(0.06),
                               "rut_yaw_deg": math.degrees(0.009)}, rel=1e-12)
