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
