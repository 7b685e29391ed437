"""The tolerance search (``largest_passing_scale`` with ``critical_ratio``) on synthetic
Monte Carlos whose answer is known: per-draw errors e_i(t) = s_i t^p (+ an offset), common
random numbers, so the largest passing scale is an order statistic in closed form."""

import math

import numpy as np
import pytest

from rtsgeom.analysis.tolerance.search import critical_ratio, largest_passing_scale


def _study(p, offset, target, spec=0.1, draws=2000, seed=0, ratio=True):
    s = np.abs(np.random.default_rng(seed).standard_normal(draws))  # per-draw sensitivity
    calls = []

    def evaluate(t):
        e = offset + s * t ** p
        calls.append(t)
        y = float(np.mean(np.abs(e) <= spec))
        return (y, critical_ratio(e, spec, target)) if ratio else y

    # exact: the largest t with at least k draws passing, k = ceil(target * draws)
    k = math.ceil(target * draws - 1e-9)
    t_true = ((spec - offset) / np.sort(s)[k - 1]) ** (1 / p)
    return evaluate, calls, t_true


@pytest.mark.parametrize("p", [0.5, 1.0, 2.0, 3.0])
@pytest.mark.parametrize("target", [0.5, 0.9, 0.95, 0.99])
@pytest.mark.parametrize("start", [1e-3, 1.0, 30.0])
def test_search_brackets_the_exact_answer_within_rel_tol(p, target, start):
    rel_tol = 0.02
    evaluate, calls, t_true = _study(p, 0.002, target)
    y0 = evaluate(0.0)[0]
    t, y, capped = largest_passing_scale(evaluate, y0, target, start, 1e6, rel_tol)
    assert not capped and y >= target
    assert t <= t_true * (1 + 1e-12)
    assert t >= t_true * (1 - rel_tol)
    # failing evaluations above t: the nearest within rel_tol
    assert min(c for c in calls if c > t) - t <= rel_tol * min(c for c in calls if c > t)


@pytest.mark.parametrize("p", [1.0, 2.0])
def test_secant_needs_far_fewer_evaluations_than_bisection(p):
    n = {}
    for ratio in (True, False):
        evaluate, calls, t_true = _study(p, 0.0, 0.95, ratio=ratio)
        out = evaluate(0.0)
        largest_passing_scale(evaluate, out[0] if ratio else out, 0.95, 1e-3, 10.0, 0.02)
        n[ratio] = len(calls)
    assert n[True] <= 7 and n[True] < n[False] / 2, n


def test_cap_and_non_power_law():
    # passes everywhere up to the cap
    evaluate, calls, _ = _study(1.0, 0.0, 0.95, spec=1e9)
    t, y, capped = largest_passing_scale(evaluate, 1.0, 0.95, 0.1, 5.0, 0.02)
    assert capped and t == 5.0
    # a yield with a step (errors jump at t = 1): the search still brackets to rel_tol
    s = np.abs(np.random.default_rng(1).standard_normal(500))
    calls = []

    def stepped(t):
        e = s * t * (1 if t < 1 else 40)
        calls.append(t)
        return float(np.mean(e <= 0.1)), critical_ratio(e, 0.1, 0.9)

    t, y, _ = largest_passing_scale(stepped, 1.0, 0.9, 0.01, 100.0, 0.02)
    fails = [c for c in calls if c > t]
    assert y >= 0.9 and min(fails) - t <= 0.02 * min(fails)


def test_critical_ratio_decides_the_yield():
    rng = np.random.default_rng(3)
    for n in (1, 7, 100, 2001):
        e = rng.standard_normal(n) * 0.1
        e[rng.random(n) < 0.05] = np.nan
        for target in (0.01, 0.5, 0.93, 0.95, 1.0):
            for spec in (0.01, 0.05, 0.1, 0.2):
                y = float(np.mean(np.abs(e) <= spec))
                r = critical_ratio(e, spec, target)
                assert (y >= target) == (r <= 1), (n, target, spec, y, r)


@pytest.mark.parametrize("subbin", [True, False])
def test_yield_without_errors_per_subbin_position_is_the_monte_carlos(subbin):
    """The search's sigma-0 evaluation (each sub-bin position drawn evaluated once) gives the
    Monte Carlo's worst errors bit for bit, for both cases and distributions."""
    from rtsgeom.analysis.tolerance.phasors import ChannelPhasors
    from rtsgeom.analysis.tolerance import ToleranceModel
    from rtsgeom.analysis.tolerance.search import _zero_errors
    from rtsgeom.analysis.tolerance.montecarlo import monte_carlo
    from rtsgeom.geometry import build_setup
    from rtsgeom.scene import load_scene
    model = ChannelPhasors.build(build_setup(load_scene("scenes/diewald2022.toml")), (0, 1), 5)
    for case in ("uncalibrated", "calibrated"):
        for dist in ("normal", "uniform"):
            mc = monte_carlo(model, [0.0] * 3, 700, 5, dist, cases=(case,), subbin=subbin)
            got = _zero_errors(ToleranceModel.of(model), 700, 5, case, subbin)[:, 0, 0]
            assert np.array_equal(mc.worst_error_deg[case], got)


@pytest.mark.parametrize("n, target", [(1, 0.5), (4, 0.5), (4, 0.75), (10, 0.95), (20, 0.95),
                                       (7, 1.0), (5, 0.0), (3, 1e-9)])
def test_the_critical_ratio_is_the_order_statistic_that_decides_the_yield(n, target):
    """With |e| sorted, the k-th smallest over the spec, k the fewest passing draws whose share
    reaches the target (0 for a target of 0); the yield meets the target exactly where the
    ratio is <= 1."""
    import math
    from rtsgeom.analysis.tolerance.search import critical_ratio
    e = np.arange(1, n + 1, dtype=float) * 0.01 * np.where(np.arange(n) % 2, 1, -1)
    k = math.ceil(target * n - 1e-12)
    want = 0.0 if k == 0 else abs(e[k - 1]) / 0.02
    got = critical_ratio(np.random.default_rng(n).permutation(e), 0.02, target)
    assert got == pytest.approx(want, rel=1e-15)
    for scale in (0.5, 1.0, 2.0):  # the yield at this spec scale against the ratio
        spec = 0.02 * got * scale if got else 0.02
        share = float(np.mean(np.abs(e) <= spec * (1 + 1e-12)))
        if got:
            assert (share >= target) == (scale >= 1.0), (scale, share)


def test_the_critical_ratio_of_pairs_nans_and_nothing():
    import math
    from rtsgeom.analysis.tolerance.search import critical_ratio
    worst = np.array([[0.01, -0.03], [0.02, 0.0], [-0.05, 0.04]])  # a draw's worst: 3, 2, 5
    assert critical_ratio(worst, 0.01, 2 / 3) == pytest.approx(3.0)
    assert critical_ratio([0.01, np.nan, 0.02], 0.01, 1.0) == math.inf  # NaN fails
    assert critical_ratio([0.01, np.nan, 0.02], 0.01, 2 / 3) == pytest.approx(2.0)
    assert math.isnan(critical_ratio([], 0.1, 0.9))
    assert math.isnan(critical_ratio([0.1], 0.0, 0.9))
    assert math.isnan(critical_ratio([0.1], -1.0, 0.9))


@pytest.mark.parametrize("sigma, axis, direction, fixed", [
    ((1e-4, 2e-4, 4e-4), "all", (0.25, 0.5, 1.0), (0.0, 0.0, 0.0)),
    ((0.0, 0.0, 0.0), "all", (1.0, 1.0, 1.0), (0.0, 0.0, 0.0)),
    ((1e-4, 2e-4, 4e-4), "radial", (1.0, 0.0, 0.0), (0.0, 2e-4, 4e-4)),
    ((1e-4, 2e-4, 4e-4), "tangential", (0.0, 1.0, 0.0), (1e-4, 0.0, 4e-4)),
    ((1e-4, 2e-4, 4e-4), "height", (0.0, 0.0, 1.0), (1e-4, 2e-4, 0.0))])
def test_the_search_line_in_sigma_space(sigma, axis, direction, fixed):
    from rtsgeom.analysis.tolerance.search import search_direction
    d, f = search_direction(sigma, axis)
    assert np.allclose(d, direction, rtol=0, atol=1e-15)
    assert np.allclose(f, fixed, rtol=0, atol=1e-18)


def test_a_search_line_of_another_axis_is_refused():
    from conftest import assert_refused
    from rtsgeom.analysis.tolerance.search import search_direction
    assert_refused(lambda: search_direction((1e-4,) * 3, "yaw"),
                   "axis 'yaw': must be 'all' or one of radial, tangential, height", ValueError)
