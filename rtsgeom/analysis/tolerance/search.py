"""The one yield search of the tolerance studies: the largest error scale that keeps a target
fraction of the built setups within the spec, by a safeguarded secant search on the scale with
the same seed at every scale (the same unit draws scaled: common random numbers, so the yield
curve is smooth and, up to the rare draw whose error is not monotone in the scale, monotone).

The scale runs along a line of :class:`~.draws.Bounds`: the three offsets' sigmas
(:func:`max_sigma_for_yield`: all together with their ratios as given, or one axis with the
others held; metres) or every bound of a study at once (:func:`max_scale_for_yield`: a factor,
rotations and RuT pose included). Each evaluation is the one Monte-Carlo driver
(:func:`~.montecarlo.monte_carlo`); where the line passes through no error at all the draws
differ only in the target's sub-bin position, which is evaluated once per position.
"""

from __future__ import annotations

import math

import numpy as np

import dataclasses
from dataclasses import dataclass

from .config import MonteCarlo
from .draws import AXES, DEFAULT_CHUNK, Bounds, draw_subbins
from .montecarlo import ToleranceModel, as_bounds, simulate
from .phasors import ChannelPhasors

__all__ = ["critical_ratio", "search_direction", "largest_passing_scale", "YieldSearch",
           "max_sigma_for_yield", "max_scale_for_yield"]


def critical_ratio(worst_deg, spec_deg: float, target_yield: float) -> float:
    """The error of the draw that decides the yield, over the spec: with the errors |e| sorted,
    the k-th smallest, k the fewest passing draws that make ``target_yield`` (NaN fails), so
    that the yield reaches the target exactly when it is <= 1 (up to rounding). Unlike the
    yield (a step function of the scale) it is continuous in the scale (an order statistic of
    continuous errors) and close to a power of it, which :func:`largest_passing_scale`
    interpolates. ``worst_deg`` (draws,) or (draws, pairs): a draw's worst over the last axis."""
    a = np.abs(np.asarray(worst_deg, float))
    a = a.reshape(a.shape[0], -1).max(axis=-1) if a.ndim > 1 else a.ravel()
    n = a.size
    if n == 0 or not spec_deg > 0:
        return math.nan
    k = max(int(math.ceil(target_yield * n)), 0)
    while k > 0 and (k - 1) / n >= target_yield:
        k -= 1
    while k <= n and k / n < target_yield:
        k += 1
    if k == 0:
        return 0.0
    if k > n:
        return math.inf
    a = np.where(np.isnan(a), np.inf, a)
    return float(np.partition(a, k - 1)[k - 1] / spec_deg)



def search_direction(sigma_m, axis: str) -> tuple[np.ndarray, np.ndarray]:
    """The yield searches' line in sigma space, sigma = fixed + t * direction (m): ``axis``
    "all" scales the three sigmas together (their ratios as given; all ones where all are
    zero), an axis name varies that axis alone with the other two held at ``sigma_m``."""
    base = np.asarray(sigma_m, float).reshape(3)
    if axis == "all":
        return (base / base.max() if base.max() > 0 else np.ones(3)), np.zeros(3)
    if axis in AXES:
        direction = np.eye(3)[AXES.index(axis)]
        return direction, base * (1 - direction)
    raise ValueError(f"axis {axis!r}: must be 'all' or one of {', '.join(AXES)}")



def _angles(errors_deg: np.ndarray) -> np.ndarray:
    """The angle columns (draws, P, C') of a study's errors (draws, P, C): a cell's angular
    distance is not an angle error the spec applies to."""
    return errors_deg if errors_deg.shape[-1] == 1 else errors_deg[..., :2]


def _zero_errors(model: ToleranceModel, draws: int, seed: int, case: str, subbin: bool
                 ) -> np.ndarray:
    """:func:`~.montecarlo.monte_carlo`'s errors (draws, P, C) with every error zero: the draws
    differ only in the target's sub-bin position, so each position drawn is evaluated once
    (the evaluation is row by row: the same bits)."""
    steps = model.subbin_steps
    centre = int(np.flatnonzero(steps == 0)[0])
    u = draw_subbins(seed, draws, steps.size) if subbin else np.full(draws, centre)
    uniq, inv = np.unique(u, return_inverse=True)
    errors = {"offsets_m": np.zeros((uniq.size, model.count, 3)), "yaw_rad": None,
              "pitch_rad": None, "rut_offset_m": None, "rut_yaw_rad": None, "subbin": uniq}
    parts = []
    for b in range(0, uniq.size, DEFAULT_CHUNK):
        sl = slice(b, b + DEFAULT_CHUNK)
        part = {k: (v[sl] if v is not None else None) for k, v in errors.items()}
        parts.append(np.stack([s[case] for s in model.evaluate(part, (case,))], 1))
    n_p = len(model.sets)
    out = (np.concatenate(parts) if parts
           else np.zeros((0, n_p, len(model.sets[0].columns) if n_p else 1)))
    return out[np.ravel(inv)]


@dataclass(frozen=True)
class YieldSearch:
    """The yield search's question: the largest scale that keeps ``target_yield`` of the
    setups within ``spec_deg`` for ``case``, to ``rel_tol``, stopping at ``cap``.

    Parameters
    ----------
    target_yield : float
        Fraction of setups within the spec, in (0, 1].
    spec_deg : float
        Angle-error spec (deg).
    case : str
        The case the spec applies to (``calibrated``, ``uncalibrated`` ...).
    rel_tol : float, optional
        The result lies within ``rel_tol`` of the smallest failing scale evaluated (default:
        0.01 for the sigmas, 0.02 for a factor).
    cap : float, optional
        The search stops there (``capped``): metres for the sigmas (default 0.01), a factor
        otherwise (default 100).
    slope : float
        The power of the scale the deciding draw's error is taken to follow until two
        evaluations measure it (:func:`largest_passing_scale`).
    """

    target_yield: float
    spec_deg: float = 0.1
    case: str = "calibrated"
    rel_tol: float | None = None
    cap: float | None = None
    slope: float = 1.0

    def sigma(self, model, sigma_m, mc: MonteCarlo, axis: str = "all",
              bounds: Bounds | None = None) -> dict:
        """The largest mounting tolerance (the offsets' sigmas) that keeps the target yield.
        ``axis="all"`` scales the three sigmas together (their ratios as given by
        ``sigma_m``; all ones where all are zero); an axis name varies that axis alone, the
        other two held at ``sigma_m``. ``bounds``: rotations and RuT pose errors drawn at
        every scale (held). Returns the sigmas found (m), the yield there, the evaluations."""
        base = np.asarray(sigma_m, float).reshape(3)
        direction, fixed = search_direction(base, axis)
        held = bounds if bounds is not None else Bounds()
        cap_m = 0.01 if self.cap is None else self.cap
        search = dataclasses.replace(self, cap=cap_m,
                                     rel_tol=0.01 if self.rel_tol is None else self.rel_tol)

        def line(t: float) -> Bounds:
            return held.with_offsets(fixed + t * direction)

        start = min(float(np.max(base * direction)) or 1e-4, cap_m)
        history, (t, y, capped, note) = _search(
            model, line, start, mc, search, lambda t: f"{self.case}: sigma {t * 1e3:.4g} mm")
        sig = fixed + t * direction
        return {"case": self.case, "axis": axis, "target_yield": self.target_yield,
                "spec_deg": self.spec_deg,
                "sigma_mm": {a: float(s * 1e3) for a, s in zip(AXES, sig)},
                "yield": y, "capped": capped, "note": note,
                "evaluations": [{"scale_mm": s * 1e3, "yield": v} for s, v in history]}

    def scale(self, model, bounds, mc: MonteCarlo) -> dict:
        """The largest factor s on ``bounds`` (every bound of the study: offsets, rotations,
        RuT pose) that keeps the target yield (for an arc: every pair). Returns the factor,
        the scaled bounds, the yield there and whether the search hit the cap."""
        bounds = as_bounds(bounds)
        search = dataclasses.replace(self, cap=100.0 if self.cap is None else self.cap,
                                     rel_tol=0.02 if self.rel_tol is None else self.rel_tol)
        history, (s, y, capped, _) = _search(
            model, bounds.scaled, 1.0, mc, search, lambda s: f"{self.case}: factor {s:.4g}")
        return {"case": self.case, "factor": s, "scales": bounds.scaled(s).to_dict(),
                "yield": y, "capped": capped,
                "evaluations": [{"scale": t, "yield": v} for t, v in history]}


def _search(model, line, start: float, mc: MonteCarlo, search: YieldSearch, label
            ) -> tuple[list, tuple]:
    """The largest passing scale t on the line ``line(t) -> Bounds``: (evaluations [(t,
    yield)], (t, yield, capped, note))."""
    if isinstance(model, ChannelPhasors):
        model = ToleranceModel.of(model)
    history = []
    case, spec_deg, target_yield = search.case, search.spec_deg, search.target_yield

    def yield_at(t: float) -> tuple[float, float]:
        bounds = line(t)
        if bounds.zero:
            e = _zero_errors(model, mc.draws, mc.seed, case, mc.subbin)
        else:
            e = simulate(model, bounds, mc, spec_deg, (case,), label(t)).errors_deg[case]
        a = np.abs(_angles(e)).reshape(e.shape[0], -1)
        y = float(np.mean(np.all(a <= spec_deg, axis=-1))) if a.size else float("nan")
        history.append((t, y))
        return y, critical_ratio(a, spec_deg, target_yield)

    y0, _ = yield_at(0.0)
    if y0 < target_yield:
        return history, (0.0, y0, False, "the setup misses the spec even without the varied "
                                         "errors")
    t, y, capped = largest_passing_scale(yield_at, y0, target_yield, start, search.cap,
                                         search.rel_tol, slope=search.slope)
    return history, (t, y, capped, None)


def max_sigma_for_yield(model, sigma_m, mc: MonteCarlo, target_yield: float,
                        spec_deg: float = 0.1, case: str = "calibrated", axis: str = "all",
                        **options) -> dict:
    """The largest mounting tolerance (the offsets' sigmas) that keeps ``target_yield`` of the
    setups within ``spec_deg`` for ``case``: :meth:`YieldSearch.sigma`.

    Parameters
    ----------
    model : ToleranceModel or ChannelPhasors
    sigma_m : array_like of 3 float
        The sigmas' ratios (``axis="all"``), or the held sigmas (an axis name), m.
    mc : MonteCarlo
        The draws of every evaluation (its seed set).
    target_yield, spec_deg, case
        As :class:`YieldSearch`.
    axis : {'all', 'radial', 'tangential', 'height'}
    **options
        :class:`YieldSearch`'s ``rel_tol``, ``slope``; ``cap_m`` (the cap, m); ``bounds``
        (rotations and RuT pose, held).

    Returns
    -------
    dict
        ``sigma_mm`` per axis, ``yield``, ``capped``, ``note``, ``evaluations``.
    """
    rest = dict(options)
    bounds = rest.pop("bounds", None)
    search = YieldSearch(target_yield, spec_deg, case, rest.pop("rel_tol", 0.01),
                         rest.pop("cap_m", 0.01), **rest)
    return search.sigma(model, sigma_m, mc, axis, bounds)


def max_scale_for_yield(model, bounds, mc: MonteCarlo, target_yield: float,
                        spec_deg: float = 0.1, case: str = "calibrated", **options) -> dict:
    """The largest factor s on ``bounds`` that keeps ``target_yield`` of the setups within
    ``spec_deg``: :meth:`YieldSearch.scale`.

    Parameters
    ----------
    model : ToleranceModel or ChannelPhasors
    bounds : Bounds or array_like of 3 float
        Every bound of the study (SI), scaled together.
    mc : MonteCarlo
        The draws of every evaluation (its seed set).
    target_yield, spec_deg, case
        As :class:`YieldSearch`.
    **options
        :class:`YieldSearch`'s ``rel_tol`` (default 0.02), ``cap`` (default 100).

    Returns
    -------
    dict
        ``factor``, ``scales``, ``yield``, ``capped``, ``evaluations``.
    """
    return YieldSearch(target_yield, spec_deg, case, **options).scale(model, bounds, mc)


def largest_passing_scale(evaluate, y0: float, target_yield: float, start: float, cap: float,
                          rel_tol: float, max_evaluations: int = 60, slope: float = 1.0
                          ) -> tuple[float, float, bool]:
    """The largest scale t in [0, cap] with yield >= ``target_yield`` (``y0`` the yield at 0,
    which passes), to ``rel_tol``: returns the largest passing t evaluated (its yield) once a
    failing one lies within ``rel_tol`` above it, or ``cap`` if that passes (``capped``).

    ``evaluate(t)`` returns the yield, or (yield, r) with r :func:`critical_ratio` (the deciding
    draw's error over the spec: passing iff r <= 1). With r the next scale is the secant
    estimate of r(t) = 1 on log r against log t (r is close to a power of t: a few
    evaluations instead of doubling and bisecting, ~17 per search before), aimed rel_tol / 3
    beside the estimate so that the next evaluation closes the bracket from the side still
    open; bisection (geometric) where there is no estimate or the bracket stops shrinking.
    Only the yields decide pass or fail. Common random numbers (the same seed in every
    evaluation) keep the yield monotone in t."""
    lo, y_lo, hi = 0.0, y0, math.inf
    logs: dict[float, float] = {}  # t -> log r, where r is finite and > 0
    widths: list[float] = []
    t = min(start, cap)
    for _ in range(max_evaluations):
        out = evaluate(t)
        y, r = out if isinstance(out, tuple) else (out, math.nan)
        if y >= target_yield:
            lo, y_lo = t, y
            if t >= cap:
                return t, y, True
        else:
            hi = t
        if 0 < r < math.inf and t > 0:
            logs[t] = math.log(r)
        if hi < math.inf:
            if hi - lo <= rel_tol * hi:
                break
            widths.append(hi - lo)
        t = _next_scale(lo, hi, logs, cap, rel_tol, widths, slope)
    return lo, y_lo, False


def _next_scale(lo: float, hi: float, logs: dict, cap: float, rel_tol: float,
                widths: list, slope: float = 1.0) -> float:
    """:func:`largest_passing_scale`'s next evaluation, strictly inside (lo, hi)."""
    est = _secant(lo, hi, logs, slope)
    d = rel_tol / 3
    if hi == math.inf:  # nothing failed yet: aim just above the estimate (at most x10)
        t = 2 * lo if est is None else max(est * (1 + d), lo * (1 + d))
        return min(t, 10 * lo, cap)
    # the bracket shrank by less than half over the last two evaluations: bisect
    stalled = len(widths) >= 3 and widths[-1] > 0.5 * widths[-3]
    mid = math.sqrt(lo * hi) if lo > 0 else 0.5 * hi
    if est is None or stalled:
        return mid
    a, b = est * (1 - d), est * (1 + d)
    if lo == 0:
        t = a
    elif a <= lo:
        t = b
    elif b >= hi:
        t = a
    else:
        t = a if est - lo > hi - est else b
    if not lo < t < hi:
        return mid
    margin = 0.05 * (hi - lo)  # progress even when the estimate sits on an end
    return min(max(t, lo + margin), hi - margin)


def _secant(lo: float, hi: float, logs: dict, slope: float = 1.0) -> float | None:
    """Where log r(t) = 0, linear in log t through the bracket's ends (their r known), else
    through the two points nearest to it; one point: r taken proportional to t^slope."""
    pts = [(t, v) for t, v in logs.items()]
    if not pts:
        return None
    ends = [(t, logs[t]) for t in (lo, hi) if t in logs and 0 < t < math.inf]
    if len(ends) == 2 and ends[0][1] != ends[1][1]:
        (t1, v1), (t2, v2) = ends
    else:
        near = sorted(pts, key=lambda p: abs(p[1]))
        if len(near) == 1 or near[0][0] == near[1][0]:
            t1, v1 = near[0]
            return t1 * math.exp(min(-v1 / slope, 700.0))  # r proportional to t^slope
        (t1, v1), (t2, v2) = near[:2]
    slope = (v2 - v1) / (math.log(t2) - math.log(t1))
    if not slope > 0 or not math.isfinite(slope):
        return None
    est = math.exp(min(math.log(t1) - v1 / slope, 700.0))  # far beyond any cap
    return est if est > 0 else None
