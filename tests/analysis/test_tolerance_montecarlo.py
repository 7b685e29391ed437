"""The Monte Carlo's result at its edges: a study of no draws (the engine takes 0) has no yield
(NaN) and says nothing else (no warning); yields count the draws within the spec."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from conftest import two_front_end_pair
from rtsgeom.analysis.tolerance.montecarlo import monte_carlo


@pytest.fixture(scope="module")
def pair_model():
    return two_front_end_pair(1.0)[1]


def test_a_study_of_no_draws_has_no_yield_and_warns_of_nothing(pair_model):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = monte_carlo(pair_model, [1e-4] * 3, 0, 1, "normal", 0.05)
        for case in res.errors_deg:
            assert res.passes(case).shape == (0,)
            assert math.isnan(res.yield_(case))


@pytest.mark.parametrize("spec", [1e-4, 0.01, 10.0])
def test_the_yield_is_the_share_of_draws_within_the_spec(pair_model, spec):
    res = monte_carlo(pair_model, [1e-4] * 3, 50, 2, "normal", spec)
    for case, e in res.errors_deg.items():
        within = np.all(np.abs(e[..., :1]) <= spec, axis=(-2, -1))
        assert np.array_equal(res.passes(case), within)
        assert res.yield_(case) == pytest.approx(float(np.mean(within)), abs=0)


@pytest.mark.parametrize("draws, chunk", [(250, 100), (100, 100), (301, 150), (7, 100)])
@pytest.mark.parametrize("mapped", [False, True])
def test_the_progress_counts_every_draw_chunk_by_chunk_up_to_the_total(pair_model, draws,
                                                                      chunk, mapped):
    """``progress(label, done, draws)`` after each chunk: done grows by the chunk's draws and
    ends at the total, with the study's label, in this process and through a mapper."""
    from conftest import CountedProgress
    told = CountedProgress()
    extra = {"mapper": lambda f, xs: [f(x) for x in xs]} if mapped else {}
    monte_carlo(pair_model, [1e-4] * 3, draws, 3, "normal", 0.05, chunk=chunk,
                progress=told, label="pair (0, 1)", **extra)
    want = [min(draws, (k + 1) * chunk) for k in range(-(-draws // chunk))]
    assert told.calls == [("pair (0, 1)", d, draws) for d in want]


# -- the result's numbers on made-up draws, compared whole with their definitions ---------


def _sets(pairs, positions=5, res=2e-12, points=3):
    """What the result reads of its channel sets: front ends, sub-bin positions, step, set
    angles."""
    from types import SimpleNamespace
    return tuple(SimpleNamespace(front_ends=tuple(p), subbin_steps=np.arange(positions) - 2,
                                 delay_resolution_s=res, set_rad=np.zeros(points))
                 for p in pairs)


def _pct(a, scale=1.0):
    a = np.asarray(a, float) * scale
    p = np.percentile(a, [50, 95, 99])
    return {"p50": float(p[0]), "p95": float(p[1]), "p99": float(p[2]), "max": float(a.max())}


def _result(kind, errors, steps, offsets, subbin=None, distribution="normal", **over):
    from rtsgeom.analysis.tolerance.draws import Bounds
    from rtsgeom.analysis.tolerance.montecarlo import ToleranceModel, ToleranceResult
    pairs = {"arc": [(0, 1), (1, 2)], "pair": [(0, 1)], "cell": [(0, 1, 2)]}[kind]
    model = ToleranceModel(_sets(pairs), 3 if kind != "pair" else 2,
                           tuple(tuple(p) for p in pairs), kind)
    draws = next(iter(errors.values())).shape[0]
    fields = dict(model=model, bounds=Bounds((1e-4, 2e-4, 3e-4), 0.01), distribution=distribution,
                  draws=draws, seed=7, spec_deg=0.05, errors_deg=errors, steps=steps,
                  range_offsets_m=offsets,
                  fallbacks_per_set={c: np.arange(len(pairs)) + k for k, c in enumerate(errors)},
                  off_bin_per_set={c: 2 * np.arange(len(pairs)) + k for k, c in
                                   enumerate(errors)},
                  subbin_steps=subbin)
    fields.update(over)
    return ToleranceResult(**fields)


RNG = np.random.default_rng(3)
ARC_ERR = {"calibrated": np.round(RNG.normal(0, 0.04, (8, 2, 1)), 3),
           "uncalibrated": np.round(RNG.normal(0, 0.4, (8, 2, 1)), 3)}
ARC_ERR["calibrated"][2, 1, 0] = 0.05  # exactly at the spec: passes
ARC_ERR["calibrated"][3, 0, 0] = -0.0500001  # just beyond: fails
ARC_STEPS = tuple(np.stack([np.zeros(8, int), np.arange(8) - p], -1) for p in range(2))
ARC_OFFS = tuple(np.stack([np.zeros(8), 1e-3 * (np.arange(8) - 3 * p)], -1) for p in range(2))


@pytest.mark.parametrize("subbin, distribution", [(None, "normal"),
                                                   (np.arange(8) % 5 - 2, "uniform")])
def test_an_arcs_dict_in_full(subbin, distribution):
    """Every key of an arc's JSON from its definition: what was drawn, the sub-bin positions
    shared by the pairs, per pair the |error| percentiles, yield within the spec (its edge
    included), grid-search fallbacks and calibration; the arc's worst error per draw (the
    worst pair's, signed), its yield (every pair within) and which pair was worst how often."""
    res = _result("arc", ARC_ERR, ARC_STEPS, ARC_OFFS, subbin, distribution)
    want = {"pairs": [], "front_ends": 3, "draws": 8, "seed": 7, "distribution": distribution,
            "scale": "sigma" if distribution == "normal" else "bound",
            "scales": res.bounds.to_dict(), "spec_deg": 0.05,
            "subbin": {"distribution": "bin centre" if subbin is None else
                       "uniform over one range bin, one position per draw shared by every pair",
                       "positions": 5, "step_s": 2e-12}}
    for p, pair in enumerate([[0, 1], [1, 2]]):
        entry = {"pair": pair}
        for k, (case, e) in enumerate(ARC_ERR.items()):
            a = np.abs(e[:, p, 0])
            entry[case] = {"angle_error_deg": _pct(a), "yield": float(np.mean(a <= 0.05)),
                           "fallbacks": p + k}
        entry["calibration"] = {
            "abs_delta_tau_ps": _pct(np.abs(np.arange(8) - p) * 2e-12, 1e12),
            "abs_range_offset_mm": _pct(np.abs(1e-3 * (np.arange(8) - 3 * p)), 1e3)}
        want["pairs"].append(entry)
    want["arc"] = {}
    for case, e in ARC_ERR.items():
        e = e[..., 0]
        worst = np.array([row[np.argmax(np.abs(row))] for row in e])
        np.testing.assert_array_equal(res.arc_worst(case), worst)
        want["arc"][case] = {
            "angle_error_deg": _pct(np.abs(worst)),
            "yield": float(np.mean(np.all(np.abs(e) <= 0.05, axis=1))),
            "worst_pair_counts": [int(np.sum(np.argmax(np.abs(e), 1) == p)) for p in (0, 1)]}
    assert res._arc_dict() == want
    assert res.to_dict() == want
    assert 0 < want["arc"]["calibrated"]["yield"] < 1


def test_an_arcs_per_draw_arrays_are_each_pairs():
    res = _result("arc", ARC_ERR, ARC_STEPS, ARC_OFFS)
    np.testing.assert_array_equal(res.delay_s, np.stack([np.arange(8) - p for p in (0, 1)],
                                                        -1) * 2e-12)
    np.testing.assert_array_equal(res.range_offset_m, np.stack(
        [1e-3 * (np.arange(8) - 3 * p) for p in (0, 1)], -1))
    for case, e in ARC_ERR.items():
        np.testing.assert_array_equal(res.worst_error_deg[case], e[:, :, 0])
    assert res.fallbacks is res.fallbacks_per_set and res.off_bin is res.off_bin_per_set
    empty = _result("arc", {"calibrated": np.zeros((4, 0, 1))}, (), ())
    assert empty.delay_s.shape == (4, 0) and empty.range_offset_m.shape == (4, 0)


def test_a_pairs_and_a_cells_statistics_in_full():
    """A pair's stats: |error| percentiles, yield, fallbacks and off-bin counts of its one set,
    draws x set-points; a cell's: per angle and the angular distance, the angle error the
    larger of azimuth and elevation, its yield over both angles (not the distance)."""
    e_pair = {"calibrated": np.array([[[0.01]], [[-0.05]], [[0.07]], [[-0.02]]])}
    steps = (np.array([[0, 3], [0, -2], [0, 1], [0, 0]]),)
    offs = (np.array([[0.0, 2e-3], [0.0, -1e-3], [0.0, 0.5e-3], [0.0, 0.0]]),)
    pair = _result("pair", e_pair, steps, offs)
    assert pair.stats("calibrated") == {
        "angle_error_deg": _pct([0.01, 0.05, 0.07, 0.02]), "yield": 0.75, "fallbacks": 0,
        "detected_off_bin": 0, "set_points_total": 12}
    np.testing.assert_array_equal(pair.delay_s, np.array([3, -2, 1, 0]) * 2e-12)
    np.testing.assert_array_equal(pair.range_offset_m, [2e-3, -1e-3, 0.5e-3, 0.0])
    np.testing.assert_array_equal(pair.worst_error_deg["calibrated"], e_pair["calibrated"][:, 0, 0])
    assert pair._subbin_dict() == {"distribution": "bin centre", "positions": 5,
                                   "step_s": 2e-12}
    e_cell = {"uncalibrated": np.array([[[0.01, -0.04, 9.0]], [[0.06, 0.0, 0.0]],
                                        [[-0.03, 0.05, 0.0]]])}
    cell = _result("cell", e_cell, (np.array([[0, 1, -4], [0, 2, 2], [0, 0, 1]]),),
                   (np.array([[0.0, 1e-3, -3e-3], [0.0, 2e-3, 1e-3], [0.0, 0.0, 0.0]]),),
                   fallbacks_per_set={"uncalibrated": np.array([4])},
                   off_bin_per_set={"uncalibrated": np.array([6])})
    a = np.abs(e_cell["uncalibrated"][:, 0])
    assert cell.stats("uncalibrated") == {
        "azimuth_error_deg": _pct(a[:, 0]), "elevation_error_deg": _pct(a[:, 1]),
        "angular_distance_deg": _pct(a[:, 2]), "angle_error_deg": _pct([0.04, 0.06, 0.05]),
        "yield": 2 / 3, "fallbacks": 4, "detected_off_bin": 6, "set_points_total": 9}
    np.testing.assert_array_equal(cell.delay_s, np.array([[0, 1, -4], [0, 2, 2], [0, 0, 1]])
                                  * 2e-12)
    np.testing.assert_array_equal(cell.range_offset_m, [3e-3, 2e-3, 0.0])
    np.testing.assert_array_equal(cell.worst_error_deg["uncalibrated"], a * np.sign(
        e_cell["uncalibrated"][:, 0]))
    assert cell._subbin_dict() == {"distribution": "bin centre", "positions": 1,
                                   "step_s": 2e-12}
    drawn = _result("cell", e_cell, cell.steps, cell.range_offsets_m, np.zeros(3, int))
    assert drawn._subbin_dict() == {"distribution": "uniform over one range bin",
                                    "positions": 5, "step_s": 2e-12}


def test_percentiles_and_the_draws_header():
    from rtsgeom.analysis.tolerance.montecarlo import draws_header, percentiles
    assert percentiles([]) == {"p50": None, "p95": None, "p99": None, "max": None}
    x = np.arange(101.0)
    assert percentiles(x, 2.0) == {"p50": 100.0, "p95": 190.0, "p99": 198.0, "max": 200.0}
    assert draws_header(10, 3, "uniform", (1e-3, 0.0, 2.5e-4), 0.1) == {
        "draws": 10, "seed": 3, "distribution": "uniform", "scale": "bound",
        "sigma_mm": {"radial": 1.0, "tangential": 0.0, "height": 0.25}, "spec_deg": 0.1}
    assert draws_header(1, 0, "normal", (0, 0, 0), 1.0)["scale"] == "sigma"


def test_monte_carlo_forwards_every_argument_to_the_one_driver(monkeypatch):
    """The old-style call parts its options into a MonteCarlo and simulate's own, unchanged."""
    import rtsgeom.analysis.tolerance.montecarlo as mcmod
    from rtsgeom.analysis.tolerance.config import MonteCarlo
    calls = []
    monkeypatch.setattr(mcmod, "simulate", lambda *a, **k: calls.append((a, k)) or "spied")
    model, bounds, mapper, progress = object(), (1e-4, 2e-4, 3e-4), map, (lambda *a: None)
    got = mcmod.monte_carlo(model, bounds, 12, 5, "uniform", 0.3, ("uncalibrated",),
                            chunk=4, mapper=mapper, progress=progress, subbin=False,
                            label="spy", keep_errors=True)
    assert got == "spied"
    (args, kw), = calls
    assert args[0] is model and args[1] is bounds
    assert args[2] == MonteCarlo(draws=12, seed=5, distribution="uniform", chunk=4,
                                 subbin=False)
    assert args[2].mapper is mapper and args[2].progress is progress
    assert args[3:] == (0.3, ("uncalibrated",)) and kw == {"label": "spy", "keep_errors": True}
    calls.clear()
    mcmod.monte_carlo(model, bounds, 12, 5)  # the defaults
    (args, kw), = calls
    assert args[2] == MonteCarlo(draws=12, seed=5) and args[3:] == (0.1, mcmod.CASES)
    assert kw == {}
