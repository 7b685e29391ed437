"""``design``'s tolerance search: the full search started where a pilot on a prefix
of the same draws puts the answer, with the power law the pilot measured."""

from __future__ import annotations

import pytest

from rtsgeom.analysis.design import pilot_estimate, tolerance_search
from rtsgeom.analysis.tolerance.phasors import ChannelPhasors
from rtsgeom.analysis.tolerance.config import MonteCarlo
from rtsgeom.analysis.tolerance.search import largest_passing_scale, max_sigma_for_yield
from rtsgeom.geometry import build_setup

from .test_yield_search import _study


@pytest.mark.parametrize("p", [0.5, 1.0, 2.0, 3.0])
@pytest.mark.parametrize("miss", [0.9, 0.97, 1.05, 1.3])
def test_a_start_near_the_answer_with_its_power_closes_in_few_evaluations(p, miss):
    """Started ``miss`` times the exact answer with the true power: the bracket closes within
    rel_tol in at most three evaluations (two-sided: the secant is exact on a power law); the
    answer is the same order statistic as from a far start."""
    rel_tol = 0.02
    evaluate, calls, t_true = _study(p, 0.0, 0.95)
    t, y, capped = largest_passing_scale(evaluate, 1.0, 0.95, miss * t_true, 1e6, rel_tol,
                                         slope=p)
    assert not capped and t_true * (1 - rel_tol) <= t <= t_true * (1 + 1e-12)
    assert len(calls) <= 3, calls
    # with the power unknown (taken as 1) it takes more wherever p is far from 1
    evaluate, calls1, _ = _study(p, 0.0, 0.95)
    largest_passing_scale(evaluate, 1.0, 0.95, miss * t_true, 1e6, rel_tol)
    if p >= 2:  # measured: 4 evaluations at every start above, 3 with the power known
        assert len(calls1) > len(calls)


@pytest.fixture(scope="module")
def model():
    from conftest import make_scene
    return ChannelPhasors.build(build_setup(make_scene()), (0, 1), 5)


@pytest.mark.parametrize("case", ["calibrated", "uncalibrated"])
def test_pilot_started_search_agrees_with_the_plain_search(model, case):
    """The same draws, the same spec: the pilot only moves the start, so the tolerance agrees
    with the search from 0.1 mm to the search's rel_tol (both are the largest passing scale
    evaluated within rel_tol of a failing one: each lies within rel_tol below the exact
    answer), with fewer full Monte Carlos."""
    draws, seed, rel_tol = 1000, 3, 0.02
    plain = max_sigma_for_yield(model, [1e-4] * 3, MonteCarlo(draws=draws, seed=seed), 0.95,
                                0.1, case, rel_tol=rel_tol)
    fast = tolerance_search(model, case, draws, seed, 0.95, 0.1, rel_tol)
    a, b = plain["sigma_mm"]["radial"], fast["sigma_mm"]["radial"]
    assert a > 0 and b > 0 and not fast["capped"]
    assert abs(a - b) <= rel_tol * max(a, b)
    assert len(fast["evaluations"]) < len(plain["evaluations"])
    t, slope = pilot_estimate(model, case, seed, 0.95, 0.1)
    assert 0.5 < t / (b * 1e-3) < 2 and 0.2 < slope < 20
