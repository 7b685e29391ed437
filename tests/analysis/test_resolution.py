"""Tests of ``rtsgeom.analysis.resolution``: closed forms and invariants on grids of inputs."""

from __future__ import annotations

import numpy as np
import pytest

from rtsgeom.analysis.resolution import ResolutionStudy
from rtsgeom.errors import ParameterError


@pytest.mark.parametrize("seps", [(0.0,), (5.0, 121.0), (-1.0,)])
def test_a_bad_separation_says_the_allowed_range(seps):
    with pytest.raises(ParameterError, match=r"separations in \(0, 120\] deg"):
        ResolutionStudy(separations_deg=seps)


# -- the config: each declared range enforced exactly at its edges, in full words --

RESOLUTION_BOUNDS = [
    ("velocity_mps", [-1e3, 1e3],
     [(-1000.5, "resolution: velocity_mps = -1000.5: must be in [-1000, 1000] m/s"),
      (1000.5, "resolution: velocity_mps = 1000.5: must be in [-1000, 1000] m/s")]),
    ("rcs_dbsm", [-100.0, 100.0],
     [(-100.5, "resolution: rcs_dbsm = -100.5: must be in [-100, 100] dBsm"),
      (100.5, "resolution: rcs_dbsm = 100.5: must be in [-100, 100] dBsm")]),
    ("range_m", [None, 0.1, 1e4],
     [(0.05, "resolution: range_m = 0.05: must be in [0.1, 10000] m"),
      (10000.5, "resolution: range_m = 10000.5: must be in [0.1, 10000] m")]),
    ("centre_deg", [None, -90.0, 90.0],
     [(-90.5, "resolution: centre_deg = -90.5: must be in [-90, 90] deg"),
      (90.5, "resolution: centre_deg = 90.5: must be in [-90, 90] deg")]),
    ("amplitudes", [None, "exact", "array-factor", "paper", "nearest"],
     [("ideal", "resolution: amplitudes = 'ideal': must be one of exact, array-factor, paper, "
                "nearest")]),
    ("separations_deg", [(), (120.0,), (1e-3, 2.0)],
     [((0.0,), "resolution: separations_deg = (0.0,): must be separations in (0, 120] deg"),
      ((-1.0, 2.0), "resolution: separations_deg = (-1.0, 2.0): must be separations in "
                    "(0, 120] deg"),
      ((120.5,), "resolution: separations_deg = (120.5,): must be separations in (0, 120] deg"),
      ((float("nan"),), "resolution: separations_deg = (nan,): must be separations in "
                        "(0, 120] deg"),
      ((float("inf"),), "resolution: separations_deg = (inf,): must be separations in "
                        "(0, 120] deg"),
      (((1.0, 2.0),), "resolution: separations_deg = ((1.0, 2.0),): must be separations in "
                      "(0, 120] deg")]),
    ("phases_deg", [(-360.0, 360.0), (0.0,)],
     [((), "resolution: phases_deg = (): must be one or more phases in [-360, 360] deg"),
      ((360.5,), "resolution: phases_deg = (360.5,): must be one or more phases in "
                 "[-360, 360] deg"),
      ((0.0, -360.5), "resolution: phases_deg = (0.0, -360.5): must be one or more phases in "
                      "[-360, 360] deg"),
      (((0.0, 1.0),), "resolution: phases_deg = ((0.0, 1.0),): must be one or more phases in "
                      "[-360, 360] deg")]),
]


@pytest.mark.parametrize("name, ok, bad", RESOLUTION_BOUNDS,
                         ids=[r[0] for r in RESOLUTION_BOUNDS])
def test_resolution_study_enforces_each_range_at_its_edges(name, ok, bad):
    from conftest import assert_bounds
    assert_bounds(lambda v: ResolutionStudy(**{name: v}), ok, bad)


@pytest.mark.parametrize("seps, phases", [(10_000, 2), (5_000, 4), (20_000, 1)])
def test_resolution_cases_are_capped_at_twenty_thousand(seps, phases):
    """separations x phases <= 20 000 is taken; one more separation is refused naming both
    counts."""
    s = tuple(np.linspace(0.01, 120.0, seps))
    ResolutionStudy(separations_deg=s, phases_deg=(0.0,) * phases)
    with pytest.raises(ParameterError) as exc:
        ResolutionStudy(separations_deg=s + (1.0,), phases_deg=(0.0,) * phases)
    assert str(exc.value) == (f"resolution: {seps + 1} separations x {phases} phases: at most "
                              "20000 cases")


def test_separations_the_arc_cannot_reach_are_refused(default_scene):
    from conftest import assert_refused
    assert_refused(lambda: ResolutionStudy(centre_deg=60.0)(default_scene),
                   "resolution: the arc reaches no separation of 2 deg or more about centre_deg "
                   "60: give separations_deg")
    with pytest.raises(ParameterError) as exc:
        ResolutionStudy(separations_deg=(100.0,))(default_scene)
    assert str(exc.value).startswith("resolution: separations_deg up to 100 about centre_deg "
                                     "7.8: ")
    assert str(exc.value).endswith(": must be within the measured span of the front ends "
                                   "[3.9728, 12.7565] deg (no pair can reach it)")
