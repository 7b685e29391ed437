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


@pytest.fixture
def recorded(monkeypatch):
    """design_grid and coverage_designs replaced by recorders of their arguments."""
    import rtsgeom.analysis.design_study as ds
    calls = []
    monkeypatch.setattr(ds, "design_grid", lambda *a, **k: calls.append(("grid", a, k)) or "G")
    monkeypatch.setattr(ds, "coverage_designs",
                        lambda *a, **k: calls.append(("coverage", a, k)) or "C")
    return calls


@pytest.mark.parametrize("pair, want_pair", [((0, 1), (0, 1)), ((1, 0), (0, 1))])
def test_the_grid_is_called_with_the_studys_fields(default_scene, recorded, pair, want_pair):
    """The grid's call: the scene, the pair in canonical order, the radii and spacings, the
    spec with the yield, the draws, the seed (the scene's) and the set-points, the workers,
    no progress without a reporter."""
    from rtsgeom.analysis.design import DesignSpec
    got = DesignStudy(radius_m=(1.0, 2.0), spacing_deg=(8.0,), pair=pair, spec_deg=0.05,
                      target_yield=0.9, mc=MonteCarlo(40), points=5, workers=3)(default_scene)
    assert got == "G"
    assert recorded == [("grid", (default_scene, want_pair, (1.0, 2.0), (8.0,),
                                  DesignSpec(0.05, 0.9, 40, default_scene.seed, 5)),
                         {"workers": 3, "progress": None})]


def test_the_coverage_is_called_with_the_studys_fields(default_scene, recorded):
    told = []
    got = DesignStudy(radius_m=(1.0,), coverage_deg=(-10, 12), spec_deg=0.2, target_yield=0.8,
                      mc=MonteCarlo(30, seed=9, progress=lambda *a: told.append(a)))(
        default_scene)
    assert got == "C"
    [(kind, args, kw)] = recorded
    assert (kind, args) == ("coverage", (default_scene, (-10.0, 12.0), (1.0,), 0.2, 0.8, 30, 9))
    assert set(kw) == {"points", "workers", "progress"}
    assert (kw["points"], kw["workers"]) == (11, 1)
    kw["progress"](1, 2)
    assert told == [("designs", 0, 2), ("designs", 1, 2)]


def test_a_scene_of_cells_gets_no_arc_design(sphere_scene, recorded):
    from conftest import assert_refused
    for study in (DesignStudy(), DesignStudy(coverage_deg=(-5.0, 5.0))):
        assert_refused(lambda: study(sphere_scene),
                       f"design {sphere_scene.source}: this scene's front ends form 2-D cells "
                       "(azimuth and elevation); the arc design varies the azimuth spacing of "
                       "front ends on an arc and synthesizes in azimuth only, it has no design "
                       "for a cell: use `tolerance SCENE --cell all` (the cell's mounting "
                       "tolerance), `linearity SCENE --grid N` and `nearfield SCENE` for the "
                       "cell")
    assert recorded == []


def test_evolve_checks_again():
    from conftest import assert_refused
    s = DesignStudy().evolve(radius_m=[3], points=5)
    assert (s.radius_m, s.points) == ((3.0,), 5) and s.spacing_deg == DesignStudy().spacing_deg
    assert_refused(lambda: DesignStudy().evolve(points=2),
                   "DesignStudy: points = 2: must be in [3, 201]")
    assert DesignStudy().radius_m == (0.5, 1.0, 1.5, 2.0)
    assert DesignStudy().spacing_deg == (4.0, 8.0, 12.0, 16.0, 20.0)
    assert (DesignStudy().pair, DesignStudy().coverage_deg, DesignStudy().spec_deg,
            DesignStudy().target_yield, DesignStudy().mc, DesignStudy().points,
            DesignStudy().workers) == ((0, 1), None, 0.1, 0.95, None, None, 1)
