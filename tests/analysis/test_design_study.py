"""DesignStudy's config: each declared range enforced exactly at its edges, the error naming
the field, the value and the allowed range in full; the values normalised; the Monte-Carlo
config and set-points it draws with."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import assert_bounds
from rtsgeom.analysis.design_study import DesignStudy
from rtsgeom.analysis.tolerance.config import MonteCarlo
from rtsgeom.errors import ParameterError

BOUNDS = [
    ("radius_m", [(0.1, 100.0), 1.5],
     [((0.05,), "DesignStudy: radius_m = [0.05]: must be one or more values in [0.1, 100]"),
      ((1.0, 100.5), "DesignStudy: radius_m = [1.0, 100.5]: must be one or more values in "
                     "[0.1, 100]"),
      ((), "DesignStudy: radius_m = []: must be one or more values in [0.1, 100]")]),
    ("spacing_deg", [(0.1, 90.0)],
     [((0.05,), "DesignStudy: spacing_deg = [0.05]: must be one or more values in [0.1, 90]"),
      ((90.5,), "DesignStudy: spacing_deg = [90.5]: must be one or more values in [0.1, 90]"),
      ((), "DesignStudy: spacing_deg = []: must be one or more values in [0.1, 90]")]),
    ("coverage_deg", [None, (-80.0, 80.0), (0.0, 0.5)],
     [((-80.5, 0.0), "DesignStudy: coverage_deg = (-80.5, 0): need -80 <= A < B <= 80 deg"),
      ((0.0, 80.5), "DesignStudy: coverage_deg = (0, 80.5): need -80 <= A < B <= 80 deg"),
      ((10.0, 10.0), "DesignStudy: coverage_deg = (10, 10): need -80 <= A < B <= 80 deg"),
      ((10.0, -10.0), "DesignStudy: coverage_deg = (10, -10): need -80 <= A < B <= 80 deg")]),
    ("spec_deg", [1e-6, 90.0], [(0.0, "DesignStudy: spec_deg = 0: must be in [1e-06, 90] deg"),
                                (90.5, "DesignStudy: spec_deg = 90.5: must be in [1e-06, 90] deg")]),
    ("points", [None, 3, 201], [(2, "DesignStudy: points = 2: must be in [3, 201]"),
                                (202, "DesignStudy: points = 202: must be in [3, 201]")]),
    ("target_yield", [1.0, 1e-9], [(0.0, "DesignStudy: target_yield = 0: must be in (0, 1]"),
                                   (1.5, "DesignStudy: target_yield = 1.5: must be in (0, 1]")]),
    ("workers", [None, 1, 1024], [(0, "DesignStudy: workers = 0: must be in [1, 1024]"),
                                  (1025, "DesignStudy: workers = 1025: must be in [1, 1024]")]),
    ("mc", [None, MonteCarlo(1), MonteCarlo(10_000_000)],
     [(MonteCarlo(0), "DesignStudy: draws = 0: must be in [1, 1e+07]"),
      ({"draws": 10}, "DesignStudy: mc must be a MonteCarlo")]),
]


@pytest.mark.parametrize("name, ok, bad", BOUNDS, ids=[b[0] for b in BOUNDS])
def test_design_study_enforces_each_range_at_its_edges(name, ok, bad):
    assert_bounds(lambda v: DesignStudy(**{name: v}), ok, bad)


def test_design_study_values_are_tuples_of_floats():
    s = DesignStudy(radius_m=[1, 2], spacing_deg=8, coverage_deg=[-10, 20])
    assert s.radius_m == (1.0, 2.0) and s.spacing_deg == (8.0,) and s.coverage_deg == (-10.0,
                                                                                     20.0)
    assert all(type(v) is float for v in s.radius_m + s.spacing_deg + s.coverage_deg)


@pytest.mark.parametrize("coverage, mc, points, want", [
    (None, None, None, (2000, 21)), ((-10.0, 10.0), None, None, (300, 11)),
    (None, MonteCarlo(50, seed=3), 7, (50, 7)), ((-10.0, 10.0), MonteCarlo(40), 5, (40, 5))])
def test_design_draws_and_points_are_the_documented_defaults(coverage, mc, points, want):
    """2000 draws and 21 set-points for the grid, 300 and 11 with ``coverage_deg``; a given
    ``mc`` or ``points`` wins; the seed is the scene's unless ``mc`` has one."""
    from types import SimpleNamespace
    s = DesignStudy(coverage_deg=coverage, mc=mc, points=points)
    got, n = s.draws_config(SimpleNamespace(seed=17))
    assert (got.draws, n) == want
    assert got.seed == (17 if mc is None or mc.seed is None else mc.seed)


@pytest.mark.parametrize("coverage, radii, spacings, n", [
    (None, (1.0,), (8.0, 10.0), 2), (None, (1.0, 1.5), (8.0, 10.0, 12.0), 6),
    ((-5.0, 5.0), (1.0,), (8.0,), 2), ((-5.0, 5.0), (1.0, 1.5), (8.0, 10.0), 4)])
def test_design_progress_counts_every_design_from_the_start(default_scene, coverage, radii,
                                                           spacings, n):
    """('designs', done, total) from 0 to the count to come: radii x spacings on the grid,
    two candidate arcs per radius for a coverage."""
    told = []
    DesignStudy(radius_m=radii, spacing_deg=spacings, coverage_deg=coverage, points=3,
                mc=MonteCarlo(20, progress=lambda *a: told.append(a)))(default_scene)
    assert told == [("designs", k, n) for k in range(n + 1)]


def test_the_design_draws_with_the_mc_seed_else_the_scenes(default_scene):
    def grid(mc):
        g = DesignStudy(radius_m=(1.0,), spacing_deg=(8.0,), mc=mc, points=3)(default_scene)
        return g.seed, g.metrics
    seed0, m0 = grid(MonteCarlo(200))
    assert seed0 == default_scene.seed
    s, m = grid(MonteCarlo(200, seed=default_scene.seed))
    assert s == seed0 and all(np.array_equal(m[k], m0[k], equal_nan=True) for k in m0)
    s, m = grid(MonteCarlo(200, seed=default_scene.seed + 1))
    assert s == default_scene.seed + 1
    assert any(not np.array_equal(m[k], m0[k], equal_nan=True) for k in m0)
