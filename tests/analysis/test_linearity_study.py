"""LinearityStudy's config: each declared range and choice enforced exactly at its edges, the
error naming the field, the value and the allowed range in full."""

from __future__ import annotations

import numpy as np
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


@pytest.fixture(scope="module")
def arc(crossing_bench):
    told = []
    res = LinearityStudy(pair="all", points=3, calibrated=False, steps=told.append)(
        crossing_bench)
    return res, told


def test_the_arc_is_each_adjacent_pair_alone(arc, crossing_bench):
    """pair='all' is every adjacent pair's own study (the same set-points and errors), told
    step by step; the worst pair is the one of the largest |error|."""
    res, told = arc
    assert res.pairs == ((0, 1), (1, 2), (2, 3), (3, 4))
    assert told == ["measuring each front end alone"] + [
        f"pair {p}: sweeping 3 set-points (exact amplitudes)" for p in res.pairs]
    for k in (0, 3):
        one = LinearityStudy(pair=res.pairs[k], points=3, calibrated=False)(crossing_bench)
        assert np.array_equal(res.linearities[k].error_deg, one.error_deg)
        assert np.array_equal(res.linearities[k].set_deg, one.set_deg)
    worst = [float(np.max(np.abs(lin.error_deg))) for lin in res.linearities]
    assert res.worst_deg == pytest.approx(worst, rel=0, abs=0)
    assert res.worst_pair == res.pairs[int(np.argmax(worst))]
    assert (res.calibrated, res.amplitudes) == (False, "exact")


def test_the_arcs_summary_table_and_dict(arc):
    res, _ = arc
    title, rows = res._summary()
    assert title == "exact synthesis over 4 pairs, uncalibrated"
    assert rows == [(f"pair {p}", f"max |error| {w:.4f} deg")
                    for p, w in zip(res.pairs, res.worst_deg)]
    cols = res._columns()
    n = [len(lin.set_deg) for lin in res.linearities]
    assert cols["i"] == [i for (i, _), k in zip(res.pairs, n) for _ in range(k)]
    assert cols["j"] == [j for (_, j), k in zip(res.pairs, n) for _ in range(k)]
    assert cols["error_deg"] == [e for lin in res.linearities for e in lin.error_deg]
    assert cols["detected_deg"] == [e for lin in res.linearities for e in lin.detected_deg]
    assert cols["set_deg"] == [e for lin in res.linearities for e in lin.set_deg]
    d = res.to_dict()
    assert d["arc"] == {"pairs": [list(p) for p in res.pairs],
                        "max_abs_error_deg": max(res.worst_deg),
                        "worst_pair": list(res.worst_pair), "calibrated": False,
                        "amplitudes": "exact"}
    assert d["pairs"] == [lin.to_dict() for lin in res.linearities]


def test_a_pair_with_an_undetected_point_is_the_arcs_worst():
    from types import SimpleNamespace
    from rtsgeom.analysis.linearity_study import ArcLinearity
    lins = (SimpleNamespace(max_abs_error_deg=0.2, to_dict=lambda: {}),
            SimpleNamespace(max_abs_error_deg=float("nan"), to_dict=lambda: {}))
    a = ArcLinearity(((0, 1), (1, 2)), lins, True, "paper")
    assert a.to_dict()["arc"]["max_abs_error_deg"] is None
    assert a._summary()[0] == "paper synthesis over 2 pairs, calibrated"


def test_the_steps_of_a_calibrated_arc_and_of_a_grid(crossing_bench, sphere_scene):
    told = []
    LinearityStudy(pair="all", points=3, steps=told.append)(crossing_bench)
    pairs = ((0, 1), (1, 2), (2, 3), (3, 4))
    assert told == ["measuring each front end alone"] + [
        s for p in pairs for s in (f"calibrating pair {p}",
                                   f"pair {p}: sweeping 3 set-points (exact amplitudes)")]
    told = []  # (a calibrated grid calibrates the cell's channels: a minute, left out)
    LinearityStudy(grid=2, calibrated=False, steps=told.append)(sphere_scene)
    assert told == ["measuring each front end alone",
                    "synthesizing a 2 x 2 grid (exact amplitudes)"]
    told = []
    LinearityStudy(points=3, steps=told.append, amplitudes="paper")(crossing_bench)
    assert told == ["measuring each front end alone", "calibrating the pair",
                    "sweeping 3 set-points (paper amplitudes)"]


def test_an_arc_writes_a_figure_per_pair_and_its_json(arc, tmp_path):
    import json
    res, _ = arc
    names = res.write(tmp_path)
    assert names == [f"linearity_{i}_{j}.png" for i, j in res.pairs] + ["linearity.json"]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(names)
    assert all((tmp_path / n).stat().st_size > 1000 for n in names[:-1])
    assert json.loads((tmp_path / "linearity.json").read_text()) == json.loads(
        json.dumps(res.to_dict()))
