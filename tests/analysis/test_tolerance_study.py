"""ToleranceStudy's config: each declared range enforced exactly at its edges, the error naming
the field, the value and the allowed range in full; the combinations it refuses."""

from __future__ import annotations

import pytest

from conftest import assert_bounds
from rtsgeom.analysis.tolerance.config import MonteCarlo
from rtsgeom.analysis.tolerance.draws import Bounds
from rtsgeom.analysis.tolerance.study import ToleranceStudy
from rtsgeom.errors import ParameterError

BOUNDS = [
    ("spec_deg", [1e-6, 90.0],
     [(0.0, "ToleranceStudy: spec_deg = 0: must be in [1e-06, 90] deg"),
      (90.5, "ToleranceStudy: spec_deg = 90.5: must be in [1e-06, 90] deg")]),
    ("points", [3, 201], [(2, "ToleranceStudy: points = 2: must be in [3, 201]"),
                          (202, "ToleranceStudy: points = 202: must be in [3, 201]")]),
    ("verify", [0, 10_000], [(-1, "ToleranceStudy: verify = -1: must be in [0, 10000]"),
                             (10_001, "ToleranceStudy: verify = 10001: must be in [0, 10000]")]),
    ("invert_yield", [None, 1.0, 1e-9],
     [(0.0, "ToleranceStudy: invert_yield = 0: must be in (0, 1]"),
      (1.5, "ToleranceStudy: invert_yield = 1.5: must be in (0, 1]")]),
    ("invert_axis", ["all", "radial", "tangential", "height"],
     [("yaw", "ToleranceStudy: invert_axis = 'yaw': must be one of all, radial, tangential, "
              "height")]),
    ("mc", [MonteCarlo(1), MonteCarlo(10_000_000)],
     [(MonteCarlo(0), "ToleranceStudy: draws = 0: must be in [1, 1e+07]"),
      (None, "ToleranceStudy: mc must be a MonteCarlo")]),
    ("bounds", [Bounds(), Bounds((1e-3, 0.0, 0.0), 0.01)],
     [((1e-4,) * 3, "ToleranceStudy: bounds must be a Bounds (the error scales, SI)"),
      (Bounds((-1e-4, 0.0, 0.0)), "tolerance bounds [-0.0001, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, "
                                  "0.0]: must be finite and >= 0"),
      (Bounds(rut_yaw_rad=float("nan")), "tolerance bounds [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, "
                                         "0.0, nan]: must be finite and >= 0")]),
]


@pytest.mark.parametrize("name, ok, bad", BOUNDS, ids=[b[0] for b in BOUNDS])
def test_tolerance_study_enforces_each_range_at_its_edges(name, ok, bad):
    assert_bounds(lambda v: ToleranceStudy(**{name: v}), ok, bad)


def test_tolerance_study_takes_a_cell_or_a_pair_not_both():
    ToleranceStudy(cell="all")
    ToleranceStudy(pair=(0, 1))
    with pytest.raises(ParameterError) as exc:
        ToleranceStudy(cell="all", pair=(0, 1))
    assert str(exc.value) == ("ToleranceStudy: cell and pair: give one of them (the cell study "
                              "is of the cell's front ends)")


def test_tolerance_study_cases_and_defaults():
    from rtsgeom.analysis.tolerance.phasors import CASES, NOMINAL_AMPLITUDES
    assert ToleranceStudy().cases == CASES == ("uncalibrated", "calibrated")
    assert ToleranceStudy(nominal_amplitudes=True).cases == CASES + (NOMINAL_AMPLITUDES,)
    d = ToleranceStudy()
    assert (d.bounds, d.pair, d.cell, d.mc, d.spec_deg, d.points, d.verify, d.invert_yield,
            d.invert_axis, d.sigma_level, d.keep_draws) == (
        Bounds((1e-4,) * 3), None, None, MonteCarlo(), 0.1, 21, 0, None, "all", None, False)


def test_a_scene_with_its_own_errors_gets_the_whole_warning(default_scene):
    from conftest import DRAWS_REPLACE_TEXT, moved_front_end, the_warnings
    from rtsgeom.errors import NominalSetupWarning
    study = ToleranceStudy(pair=(0, 1), mc=MonteCarlo(20), points=5)
    assert the_warnings(lambda: study(moved_front_end(default_scene)), NominalSetupWarning) == [
        "tolerance " + DRAWS_REPLACE_TEXT]
    assert the_warnings(lambda: study(default_scene), NominalSetupWarning) == []


def test_the_combinations_the_study_does_not_model_are_refused(default_scene, sphere_scene,
                                                              crossing_bench):
    from conftest import assert_refused
    mc = MonteCarlo(10)
    rot = Bounds((1e-4,) * 3, 1e-3)
    verify = ("verify: only for one pair with offsets (not pair='all', rotations or RuT-pose "
              "errors)")
    assert_refused(lambda: ToleranceStudy(pair="all", verify=2, mc=mc, points=3)(crossing_bench),
                   verify)
    assert_refused(lambda: ToleranceStudy(rot, pair=(0, 1), verify=2, mc=mc, points=3)(
        default_scene), verify)
    assert_refused(lambda: ToleranceStudy(Bounds((1e-4,) * 3, rut_yaw_rad=1e-3), pair=(0, 1),
                                          verify=1, mc=mc, points=3)(default_scene), verify)
    assert_refused(lambda: ToleranceStudy(cell="all", nominal_amplitudes=True, mc=mc, points=3)(
        sphere_scene), "nominal_amplitudes: only for the pair study (the cell study designs its "
                       "amplitudes once, at the bin centre)")
    for kw in ({"invert_yield": 0.9}, {"verify": 1}):
        assert_refused(lambda: ToleranceStudy(rot, cell="all", mc=mc, points=3, **kw)(
            sphere_scene), "verify, invert_yield: only without rotation or RuT-pose errors so far")
    assert_refused(lambda: ToleranceStudy(cell="all", mc=mc, points=3)(default_scene),
                   "cell: tolerance --cell needs a RuT that beamforms in azimuth and elevation "
                   "(an array with elevation extent, e.g. radar.use_elevation_tx = true)")
    for cell, shown in (((0, 1), "[0, 1]"), ((0, 1, 9), "[0, 1, 9]"), ((0, 1, 1), "[0, 1, 1]"),
                        ((0, 1, 2, 3, 0), "[0, 0, 1, 2, 3]")):  # shown sorted
        assert_refused(lambda: ToleranceStudy(cell=cell, mc=mc, points=3)(sphere_scene),
                       f"cell: cell {shown}: must be 3 or 4 distinct front-end indices in [0, 3]")
