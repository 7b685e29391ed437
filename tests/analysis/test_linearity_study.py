"""LinearityStudy's config: each declared range and choice enforced exactly at its edges, the
error naming the field, the value and the allowed range in full."""

from __future__ import annotations

import pytest

from conftest import assert_bounds
from rtsgeom.analysis.linearity_study import LinearityStudy
from rtsgeom.errors import ParameterError

BOUNDS = [
    ("amplitudes", ["exact", "array-factor", "paper"],
     [("nearest", "LinearityStudy: amplitudes = 'nearest': must be one of exact, array-factor, "
                  "paper")]),
    ("points", [3, 1001], [(2, "LinearityStudy: points = 2: must be in [3, 1001]"),
                           (1002, "LinearityStudy: points = 1002: must be in [3, 1001]")]),
    ("end_angles", ["geometric", "measured"],
     [("nominal", "LinearityStudy: end_angles = 'nominal': must be one of geometric, measured")]),
    ("grid", [None, 2, 50], [(1, "LinearityStudy: grid = 1: must be in [2, 50]"),
                             (51, "LinearityStudy: grid = 51: must be in [2, 50]")]),
]


@pytest.mark.parametrize("name, ok, bad", BOUNDS, ids=[b[0] for b in BOUNDS])
def test_linearity_study_enforces_each_range_at_its_edges(name, ok, bad):
    assert_bounds(lambda v: LinearityStudy(**{name: v}), ok, bad)


def test_a_grid_is_one_cell_not_the_arcs_pairs():
    LinearityStudy(grid=5, pair=(0, 1))
    LinearityStudy(pair="all")
    with pytest.raises(ParameterError) as exc:
        LinearityStudy(grid=5, pair="all")
    assert str(exc.value) == ("LinearityStudy: grid: must be unset with pair 'all' (a grid "
                              "measures one cell; 'all' the arc's pairs)")
    d = LinearityStudy()
    assert (d.pair, d.amplitudes, d.calibrated, d.points, d.end_angles, d.grid, d.fir) == (
        (0, 1), "exact", True, 21, "geometric", None, None)


def test_steps_are_told_each_stage_in_order():
    """``steps(label)`` at each stage, nothing without it."""
    told = []
    study = LinearityStudy(steps=told.append)
    study._step("measuring")
    study._step("sweeping")
    LinearityStudy()._step("nobody listens")
    assert told == ["measuring", "sweeping"]


def test_a_grid_needs_a_rut_with_elevation(default_scene):
    from conftest import assert_refused
    assert_refused(lambda: LinearityStudy(grid=3)(default_scene),
                   "grid: needs a RuT with elevation (an array with elevation extent, e.g. "
                   "radar.use_elevation_tx = true)")
