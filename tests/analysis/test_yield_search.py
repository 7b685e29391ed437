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


# -- the search's answers read whole, on a made-up Monte Carlo -----------------------------

SENS = np.abs(np.random.default_rng(11).standard_normal(300))  # per-draw sensitivity


class _FakeRuns:
    """A Monte Carlo in closed form: draw i's error (deg) offset + SENS_i * 1e3 * (the sum of
    the offsets' scales (m) + the rotations' and pose's bounds); a cell's two angles (the
    elevation 1.5 times the azimuth) and an angular distance far beyond any spec."""

    def __init__(self, offset=0.0, cols=1, spec=0.1):
        self.offset, self.cols, self.spec = offset, cols, spec
        self.calls = []  # (bounds or None where zero, label, yield)

    def errors(self, bounds):
        mag = 0.0 if bounds is None else (sum(bounds.offsets_m) + bounds.yaw_rad
                                          + bounds.rut_yaw_rad)
        e = self.offset + SENS * 1e3 * mag
        cols = [e, -1.5 * e, np.full_like(e, 1e3)][:self.cols]
        return np.stack(cols, -1)[:, None, :]  # (draws, 1, C)

    def _record(self, bounds, label, e):
        a = np.abs(e if e.shape[-1] == 1 else e[..., :2]).reshape(e.shape[0], -1)
        self.calls.append((bounds, label, float(np.mean(np.all(a <= self.spec, -1)))))

    def simulate(self, model, bounds, mc, spec_deg, cases, label):
        from types import SimpleNamespace
        assert spec_deg == self.spec and mc.draws == 300
        e = self.errors(bounds)
        self._record(bounds, label, e)
        return SimpleNamespace(errors_deg={cases[0]: e})

    def zero(self, model, draws, seed, case, subbin):
        assert (draws, seed, subbin) == (300, 5, True)
        e = self.errors(None)
        self._record(None, None, e)
        return e


@pytest.fixture
def fake(monkeypatch):
    import rtsgeom.analysis.tolerance.search as search_mod
    runs = {}

    def make(**kw):
        runs["f"] = f = _FakeRuns(**kw)
        monkeypatch.setattr(search_mod, "simulate", f.simulate)
        monkeypatch.setattr(search_mod, "_zero_errors", f.zero)
        return f
    return make


def _model(cols=1):
    from types import SimpleNamespace
    from rtsgeom.analysis.tolerance.montecarlo import ToleranceModel
    return ToleranceModel((SimpleNamespace(front_ends=(0, 1)),), 2, ((0, 1),),
                          "pair" if cols == 1 else "cell")


def _mc():
    from rtsgeom.analysis.tolerance.config import MonteCarlo
    return MonteCarlo(300, seed=5)


@pytest.mark.parametrize("axis, sigma, start, t_of", [
    ("all", (1e-4, 2e-4, 4e-4), 4e-4, lambda b: b.offsets_m[2]),
    ("all", (0.0, 0.0, 0.0), 1e-4, lambda b: b.offsets_m[0]),
    ("radial", (1e-4, 2e-5, 1e-5), 1e-4, lambda b: b.offsets_m[0]),
    ("height", (2e-5, 0.0, 0.0), 1e-4, lambda b: b.offsets_m[2]),
])
@pytest.mark.parametrize("cols", [1, 3])
def test_the_sigma_search_in_full(fake, axis, sigma, start, t_of, cols):
    """YieldSearch.sigma: the search's line (the held sigmas, the first scale the largest
    varied sigma, or 0.1 mm), each evaluation's label, sigma and yield (a cell's angular
    distance left out of the spec), the answer the largest passing sigma evaluated with a
    failing one within 1 % above it; the defaults (1 %, a 10 mm cap, slope 1) those given."""
    from rtsgeom.analysis.tolerance.search import AXES, YieldSearch, search_direction
    f = fake(offset=0.002, cols=cols)
    got = YieldSearch(0.9).sigma(_model(cols), sigma, _mc(), axis)
    direction, fixed = search_direction(sigma, axis)
    ts = [0.0 if b is None else t_of(b) for b, _, _ in f.calls]
    ys = [y for _, _, y in f.calls]
    assert ts[0] == 0.0 and ts[1] == start
    for (b, label, _), t in zip(f.calls, ts):
        if b is not None:
            np.testing.assert_array_equal(b.offsets_m, fixed + t * direction)
            assert label == f"calibrated: sigma {t * 1e3:.4g} mm"
            assert (b.yaw_rad, b.rut_yaw_rad) == (0.0, 0.0)
        else:
            assert not any(fixed)
    t = max(t for t, y in zip(ts, ys) if y >= 0.9)
    fail = min(t2 for t2, y in zip(ts, ys) if y < 0.9)
    assert t < fail <= t * 1.01 / 0.99 + 1e-18 and fail - t <= 0.01 * fail
    sig = fixed + t * direction
    assert got == {"case": "calibrated", "axis": axis, "target_yield": 0.9, "spec_deg": 0.1,
                   "sigma_mm": {a: float(s * 1e3) for a, s in zip(AXES, sig)},
                   "yield": ys[ts.index(t)], "capped": False, "note": None,
                   "evaluations": [{"scale_mm": a * 1e3, "yield": y} for a, y in zip(ts, ys)]}
    n = len(f.calls)
    assert YieldSearch(0.9, 0.1, "calibrated", 0.01, 0.01, 1.0).sigma(
        _model(cols), sigma, _mc(), axis) == got
    assert YieldSearch(0.9, rel_tol=0.1).sigma(_model(cols), sigma, _mc(), axis) != got
    assert len(f.calls) > 2 * n


def test_a_search_that_passes_up_to_its_cap_or_fails_without_errors(fake):
    """Passing everywhere: the cap (10 mm by default, or as given) with its yield; failing
    at no error at all: 0 with the note and the one evaluation."""
    from rtsgeom.analysis.tolerance.search import YieldSearch
    f = fake(spec=1e9)
    got = YieldSearch(0.9, 1e9).sigma(_model(), (1e-4, 0.0, 0.0), _mc(), "radial")
    assert got["capped"] and got["sigma_mm"] == {"radial": 10.0, "tangential": 0.0,
                                                 "height": 0.0}
    assert got["yield"] == 1.0 and got["evaluations"][-1] == {"scale_mm": 10.0, "yield": 1.0}
    got = YieldSearch(0.9, 1e9, cap=2e-3).sigma(_model(), (1e-4, 0.0, 0.0), _mc(), "radial")
    assert got["capped"] and got["sigma_mm"]["radial"] == 2.0
    got = YieldSearch(0.9, 1e9).scale(_model(), Bounds_((1e-4, 0.0, 0.0)), _mc())
    assert got["capped"] and got["factor"] == 100.0
    f = fake(offset=0.2)
    got = YieldSearch(0.9).sigma(_model(), (1e-4, 2e-4, 0.0), _mc(), "all")
    assert got == {"case": "calibrated", "axis": "all", "target_yield": 0.9, "spec_deg": 0.1,
                   "sigma_mm": {"radial": 0.0, "tangential": 0.0, "height": 0.0},
                   "yield": 0.0, "capped": False,
                   "note": "the setup misses the spec even without the varied errors",
                   "evaluations": [{"scale_mm": 0.0, "yield": 0.0}]}
    assert len(f.calls) == 1
    got = YieldSearch(0.9).scale(_model(), Bounds_((1e-4, 0.0, 0.0)), _mc())
    assert (got["factor"], got["capped"], got["evaluations"]) == (0.0, False,
                                                                  [{"scale": 0.0, "yield": 0.0}])


def Bounds_(offsets, **rest):
    from rtsgeom.analysis.tolerance.draws import Bounds
    return Bounds(offsets, **rest)


def test_the_factor_search_in_full(fake):
    """YieldSearch.scale: every bound scaled together (rotations and RuT pose too), from 1;
    each evaluation's label and factor; the answer's scaled bounds; the defaults (2 %, cap
    100) those given."""
    from rtsgeom.analysis.tolerance.search import YieldSearch
    f = fake(offset=0.002)
    bounds = Bounds_((1e-5, 2e-5, 0.0), yaw_rad=1e-5, rut_yaw_rad=2e-5)
    got = YieldSearch(0.8, case="uncalibrated").scale(_model(), bounds, _mc())
    ss = [0.0 if b is None else b.yaw_rad / 1e-5 for b, _, _ in f.calls]
    ys = [y for _, _, y in f.calls]
    assert ss[:2] == [0.0, 1.0]
    for (b, label, _), s in zip(f.calls[1:], ss[1:]):
        assert b == bounds.scaled(s) and label == f"uncalibrated: factor {s:.4g}"
    s = max(s for s, y in zip(ss, ys) if y >= 0.8)
    fail = min(s2 for s2, y in zip(ss, ys) if y < 0.8)
    assert s < fail and fail - s <= 0.02 * fail
    assert got == {"case": "uncalibrated", "factor": s, "scales": bounds.scaled(s).to_dict(),
                   "yield": ys[ss.index(s)], "capped": False,
                   "evaluations": [{"scale": a, "yield": y} for a, y in zip(ss, ys)]}
    assert YieldSearch(0.8, 0.1, "uncalibrated", 0.02, 100.0).scale(_model(), bounds,
                                                                    _mc()) == got
    assert YieldSearch(0.8, case="uncalibrated", rel_tol=0.2).scale(_model(), bounds,
                                                                    _mc()) != got


def test_the_functions_are_the_searchs_calls(fake):
    """max_sigma_for_yield and max_scale_for_yield: YieldSearch with their options (the
    sigma's cap as cap_m, 1 % and 10 mm by default; held rotations drawn at every sigma)."""
    from rtsgeom.analysis.tolerance.search import (YieldSearch, max_scale_for_yield,
                                                   max_sigma_for_yield)
    f = fake(offset=0.002)
    sig = (1e-4, 2e-4, 4e-4)
    assert max_sigma_for_yield(_model(), sig, _mc(), 0.9) == YieldSearch(0.9).sigma(
        _model(), sig, _mc())
    held = Bounds_((0.0,) * 3, yaw_rad=1e-5)
    got = max_sigma_for_yield(_model(), sig, _mc(), 0.9, 0.1, "uncalibrated", "tangential",
                              rel_tol=0.05, cap_m=3e-4, slope=2.0, bounds=held)
    f.calls.clear()
    assert got == YieldSearch(0.9, 0.1, "uncalibrated", 0.05, 3e-4, 2.0).sigma(
        _model(), sig, _mc(), "tangential", held)
    assert all(b is not None and b.yaw_rad == 1e-5 for b, _, _ in f.calls)
    assert got["sigma_mm"]["tangential"] <= 0.3
    b = Bounds_(sig)
    assert max_scale_for_yield(_model(), b, _mc(), 0.9) == YieldSearch(0.9).scale(
        _model(), b, _mc())
    assert max_scale_for_yield(_model(), sig, _mc(), 0.9, 0.1, "calibrated", rel_tol=0.1,
                               cap=3.0) == YieldSearch(0.9, rel_tol=0.1, cap=3.0).scale(
        _model(), b, _mc())
    fake(spec=1e9)
    assert max_sigma_for_yield(_model(), sig, _mc(), 0.9, 1e9)["sigma_mm"]["height"] == 10.0


L = math.log


@pytest.mark.parametrize("lo, hi, logs, cap, widths, want", [
    # nothing failed yet: double without an estimate, else just above it, at most x10 and cap
    (1.0, math.inf, {}, 100.0, [], 2.0),
    (3.0, math.inf, {}, 5.0, [], 5.0),
    (1.0, math.inf, {1.0: L(0.5)}, 100.0, [], 2.0 * 1.01),
    (1.0, math.inf, {1.0: L(1.5)}, 100.0, [], 1.0 * 1.01),  # the estimate below lo
    (1.0, math.inf, {1.0: L(1e-3)}, 100.0, [], 10.0),
    (1.0, math.inf, {1.0: L(1e-3)}, 7.0, [], 7.0),
    # a bracket: beside the secant estimate est = 2^(2/3), on the side nearer the open end
    (1.0, 4.0, {1.0: L(0.5), 4.0: L(4.0)}, 100.0, [], 2 ** (2 / 3) * 1.01),
    (1.0, 4.0, {1.0: L(0.25), 4.0: L(2.0)}, 100.0, [], 4 ** (2 / 3) * 0.99),
    # stalled (the last width over half the one two before): the geometric middle
    (1.0, 4.0, {1.0: L(0.5), 4.0: L(4.0)}, 100.0, [1.0, 0.9, 0.55], 2.0),
    (1.0, 4.0, {1.0: L(0.5), 4.0: L(4.0)}, 100.0, [1.0, 0.9, 0.5], 2 ** (2 / 3) * 1.01),
    (1.0, 4.0, {}, 100.0, [], 2.0),  # no estimate
    (0.0, 4.0, {}, 100.0, [], 2.0),  # from 0: the arithmetic middle
    (0.0, 4.0, {4.0: L(2.0)}, 100.0, [], 2.0 * 0.99),  # from 0: below the estimate
    # the estimate at an end: 5 % of the bracket inside it; beyond it: the middle
    (1.0, 4.0, {1.0: L(0.9999), 4.0: L(4.0)}, 100.0, [], 1.0 + 0.05 * 3),
    (1.0, 4.0, {1.0: L(0.25), 4.0: L(1.0001)}, 100.0, [], 4.0 - 0.05 * 3),
    (1.0, 4.0, {1.0: L(0.1), 4.0: L(0.2)}, 100.0, [], 2.0),
])
def test_the_next_scale_of_each_branch(lo, hi, logs, cap, widths, want):
    """_next_scale's rules in its docstring's words, each branch on a bracket whose estimate
    is known in closed form (rel_tol 0.03: 1 % beside the estimate)."""
    from rtsgeom.analysis.tolerance.search import _next_scale
    assert _next_scale(lo, hi, logs, cap, 0.03, widths) == pytest.approx(want, rel=1e-12)


@pytest.mark.parametrize("lo, hi, logs, slope, want", [
    (1.0, math.inf, {}, 1.0, None),
    (1.0, math.inf, {2.0: L(0.5)}, 1.0, 4.0),  # one point: r ~ t^slope
    (1.0, math.inf, {2.0: L(0.25)}, 2.0, 4.0),
    (1.0, math.inf, {2.0: -800.0}, 1.0, 2.0 * math.exp(700.0)),  # bounded
    (1.0, 4.0, {1.0: L(0.5), 4.0: L(2.0)}, 1.0, 2.0),  # through the ends
    # the ends equal: through the two points nearest r = 1
    (1.0, 4.0, {1.0: L(0.5), 4.0: L(0.5), 2.0: L(0.8), 3.0: L(1.2)}, 1.0,
     math.exp(L(2.0) - L(0.8) / ((L(1.2) - L(0.8)) / (L(3.0) - L(2.0))))),
    (1.0, 4.0, {1.0: L(2.0), 4.0: L(0.5)}, 1.0, None),  # falling: no estimate
    (1.0, 4.0, {1.0: L(0.5), 2.0: L(0.5)}, 1.0, None),  # flat
])
def test_the_secant_estimate_of_each_branch(lo, hi, logs, slope, want):
    from rtsgeom.analysis.tolerance.search import _secant
    got = _secant(lo, hi, logs, slope)
    assert got == want if want is None else got == pytest.approx(want, rel=1e-12)


# -- the module-level searches forward every argument unchanged (a spy in place of the study) --

def _spy(monkeypatch, method):
    from rtsgeom.analysis.tolerance.search import YieldSearch
    calls = []

    def spy(self, *args):
        calls.append((self, args))
        return {"spied": True}
    monkeypatch.setattr(YieldSearch, method, spy)
    return calls


def test_max_sigma_for_yield_forwards_every_argument(monkeypatch):
    from rtsgeom.analysis.tolerance.config import MonteCarlo
    from rtsgeom.analysis.tolerance.draws import Bounds
    from rtsgeom.analysis.tolerance.search import YieldSearch, max_sigma_for_yield
    calls = _spy(monkeypatch, "sigma")
    model, sigma, mc = object(), (1e-4, 2e-4, 3e-4), MonteCarlo(draws=7, seed=3)
    held = Bounds((0.0, 0.0, 0.0))
    got = max_sigma_for_yield(model, sigma, mc, 0.8, 0.25, "uncalibrated", "height",
                              bounds=held, rel_tol=0.03, cap_m=0.002, slope=2.5)
    assert got == {"spied": True}
    (search, args), = calls
    assert search == YieldSearch(0.8, 0.25, "uncalibrated", 0.03, 0.002, 2.5)
    assert args[0] is model and args[1] is sigma and args[2] is mc
    assert args[3] == "height" and args[4] is held and len(args) == 5
    calls.clear()
    max_sigma_for_yield(model, sigma, mc, 0.9)  # the defaults
    (search, args), = calls
    assert search == YieldSearch(0.9, 0.1, "calibrated", 0.01, 0.01, 1.0)
    assert args[3:] == ("all", None)


def test_max_scale_for_yield_forwards_every_argument(monkeypatch):
    from rtsgeom.analysis.tolerance.config import MonteCarlo
    from rtsgeom.analysis.tolerance.search import YieldSearch, max_scale_for_yield
    calls = _spy(monkeypatch, "scale")
    model, bounds, mc = object(), (1e-4, 2e-4, 3e-4), MonteCarlo(draws=7, seed=3)
    got = max_scale_for_yield(model, bounds, mc, 0.8, 0.25, "uncalibrated", rel_tol=0.05,
                              cap=7.0, slope=0.5)
    assert got == {"spied": True}
    (search, args), = calls
    assert search == YieldSearch(0.8, 0.25, "uncalibrated", 0.05, 7.0, 0.5)
    assert len(args) == 3 and args[0] is model and args[1] is bounds and args[2] is mc
    calls.clear()
    max_scale_for_yield(model, bounds, mc, 0.9)
    (search, args), = calls
    assert search == YieldSearch(0.9, 0.1, "calibrated", None, None, 1.0)
