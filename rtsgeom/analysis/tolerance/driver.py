"""Mounting-tolerance Monte Carlo of the arbitrary-angle synthesis (paper section "Arbitrary
Angle of Arrival", "Constraints": a radial error of lambda/4 already cancels the composite).

Each draw moves both front ends of a pair radially, tangentially and in height (normal with
given sigmas, or uniform within given bounds). The operator does not know the errors: the
amplitudes of the set-points across the pair's span (21 by default, ends excluded as in
``aoa.linearity``) are designed once on the nominal setup (:class:`~rtsgeom.synthesis.model.ChannelModel`,
its ``solve`` and ``amplitudes`` for the phase the calibration establishes, see
:meth:`PairPhasors.coherence_phase`).
For every draw the synthesized angle is evaluated uncalibrated (no delay offset) and after
the calibration, with the target at a sub-bin position drawn per draw (uniform over one range
bin, in steps of the RTS's delay resolution; its own stream ``default_rng([seed, 1])``, so the
mounting errors are the same draws as without it).

The model of one draw (the target's sub-bin position, the bin the RuT detects, the
calibration at phasor level, the mounting errors as phasor factors) is
:class:`~rtsgeom.analysis.tolerance.pair.PairPhasors`; ``tolerance_verify`` pushes draws
through the full ADC-cube chain and compares.

Angles come from :func:`~rtsgeom.radar.processing.refine_angles` (Newton on the beamformer
peak from the set angle, global check, fallback to ``estimate_angles``), vectorised over
draws x set-points; the draws are processed in chunks (memory bounded) from one generator
``numpy.random.default_rng(seed)``, so the same seed gives bit-identical results whatever the
chunk size. Every chunk is a pure function of its offsets (:func:`evaluate_chunk`), so a
process pool or cluster can map it (``monte_carlo(..., mapper=...)``).
"""

from __future__ import annotations

import functools
import math
import time
from dataclasses import dataclass
from typing import Callable, Iterable, Iterator

import numpy as np

from ..._lib.util import frozen
from ...errors import ParameterError
from .pair import PROBE_FRACTIONS, PairPhasors  # noqa: F401 (public here too)

__all__ = ["AXES", "search_direction", "DISTRIBUTIONS", "CASES", "ALL_CASES", "NOMINAL_AMPLITUDES", "PairPhasors",
           "ToleranceResult", "draw_offsets", "standard_draws", "unit_block", "DrawChunk", "draw_chunks", "subbin_draws", "evaluate_chunk",
           "monte_carlo", "max_sigma_for_yield", "critical_ratio", "largest_passing_scale",
           "percentiles"]

AXES = ("radial", "tangential", "height")
DISTRIBUTIONS = ("normal", "uniform")
CASES = ("uncalibrated", "calibrated")
# calibrated, but the nominal design's amplitudes kept (the calibration delay's range offset
# not designed for): what skipping that costs
NOMINAL_AMPLITUDES = "calibrated_nominal_amplitudes"
ALL_CASES = CASES + (NOMINAL_AMPLITUDES,)
DEFAULT_CHUNK = 10_000

Progress = Callable[[str, int, int], None]  # (label, draws done, draws total)
Mapper = Callable[[Callable, list], Iterable]  # ordered map of a pure function over chunks


# ------------------------------------------------------------------------------------------
# Draws
# ------------------------------------------------------------------------------------------


def standard_draws(seed: int, draws: int, distribution: str = "normal",
                   chunk: int = DEFAULT_CHUNK, front_ends: int = 2) -> Iterator[np.ndarray]:
    """Unit-scale draws (k, 2, 3) chunk by chunk from ``numpy.random.default_rng(seed)``:
    standard normal, or uniform in [-1, 1]. The stream does not depend on ``chunk``.
    ``front_ends``: (k, front_ends, 3) (a cell of front ends, ``tolerance_cell``)."""
    check_distribution(distribution)
    rng = np.random.default_rng(seed)
    chunk = max(1, int(chunk))
    for start in range(0, draws, chunk):
        yield unit_block(rng, (min(chunk, draws - start), front_ends, 3), distribution)


def subbin_draws(seed: int, draws: int, positions: int, chunk: int = DEFAULT_CHUNK
                 ) -> Iterator[np.ndarray]:
    """The target's sub-bin position per draw, chunk by chunk: indices (k,) into
    ``PairPhasors.subbin_steps`` (``positions`` equally likely positions across one range bin),
    from their own stream ``numpy.random.default_rng([seed, 1])`` (the mounting errors keep
    theirs). The stream does not depend on ``chunk``."""
    rng = np.random.default_rng([int(seed), 1])
    chunk = max(1, int(chunk))
    for start in range(0, draws, chunk):
        yield _subbin_block(rng, min(chunk, draws - start), positions)


def check_distribution(distribution: str) -> None:
    """A clear error naming the allowed draw distributions (every study's draws)."""
    if distribution not in DISTRIBUTIONS:
        raise ParameterError(f"distribution {distribution!r}: must be one of "
                         f"{', '.join(DISTRIBUTIONS)}")


def unit_block(rng: np.random.Generator, shape, distribution: str) -> np.ndarray:
    """The next unit-scale draws of ``shape`` from ``rng``: standard normal, or uniform in
    [-1, 1] (every study's draws: the pair's, the cell's and the arc's offsets, rotations
    and RuT pose)."""
    if distribution == "normal":
        return rng.standard_normal(shape)
    return rng.uniform(-1.0, 1.0, shape)


def _subbin_block(rng: np.random.Generator, k: int, positions: int) -> np.ndarray:
    """The next ``k`` sub-bin indices of :func:`subbin_draws`' stream ``rng``."""
    return np.minimum((rng.random(k) * positions).astype(int), positions - 1)


def _generator_at(state: dict) -> np.random.Generator:
    """A generator whose bit generator continues from the saved ``state``."""
    bit = getattr(np.random, state["bit_generator"])()
    bit.state = state
    return np.random.Generator(bit)


@dataclass(frozen=True)
class DrawChunk:
    """One chunk of a study's draws, as the states of its two streams at the chunk's start:
    a few hundred bytes instead of the draws (10 000 draws: 0.5 MB), which is what a cluster
    ships per chunk. :meth:`offsets` and :meth:`subbin` regenerate the chunk's draws from
    them bit for bit as :func:`standard_draws` and :func:`subbin_draws` make them (a stream
    continued from a saved state is the same stream)."""

    k: int
    state: dict  # bit_generator.state of the mounting-error stream default_rng(seed)
    subbin_state: dict | None  # of the sub-bin stream default_rng([seed, 1]); None: centre
    sigma_m: np.ndarray  # (3,)
    distribution: str
    positions: int  # sub-bin positions across one bin
    centre: int  # the bin centre's index (without sub-bin draws)

    def offsets(self) -> np.ndarray:
        """The chunk's mounting errors (k, 2, 3) (m)."""
        return (unit_block(_generator_at(self.state), (self.k, 2, 3), self.distribution)
                * self.sigma_m)

    def subbin(self) -> np.ndarray:
        """The chunk's sub-bin indices (k,)."""
        if self.subbin_state is None:
            return np.full(self.k, self.centre)
        return _subbin_block(_generator_at(self.subbin_state), self.k, self.positions)


def draw_chunks(seed: int, draws: int, sigma_m, distribution: str, chunk: int,
                positions: int, centre: int, subbin: bool = True) -> Iterator[DrawChunk]:
    """A study's draws chunk by chunk as :class:`DrawChunk` (the streams advanced here by
    drawing each chunk once: normal draws take a varying number of raw numbers each)."""
    check_distribution(distribution)
    sigma = np.asarray(sigma_m, float)
    rng = np.random.default_rng(seed)
    rng_u = np.random.default_rng([int(seed), 1]) if subbin else None
    chunk = max(1, int(chunk))
    for start in range(0, draws, chunk):
        k = min(chunk, draws - start)
        state = rng.bit_generator.state
        unit_block(rng, (k, 2, 3), distribution)
        state_u = None
        if rng_u is not None:
            state_u = rng_u.bit_generator.state
            _subbin_block(rng_u, k, positions)
        yield DrawChunk(k, state, state_u, sigma, distribution, int(positions), int(centre))


def draw_offsets(seed: int, draws: int, sigma_m, distribution: str = "normal",
                 front_ends: int = 2) -> np.ndarray:
    """All mounting errors (draws, front_ends, 3) of a study at once (the per-axis scale
    ``sigma_m`` (3,) is the standard deviation, or the bound of the uniform distribution):
    a pair's, or a cell's of ``front_ends`` (``tolerance_cell``)."""
    z = list(standard_draws(seed, draws, distribution, max(draws, 1), front_ends))
    z = z[0] if z else np.zeros((0, front_ends, 3))
    return z * np.asarray(sigma_m, float)


def draw_subbins(seed: int, draws: int, positions: int) -> np.ndarray:
    """All sub-bin positions (draws,) of a study at once (:func:`subbin_draws`)."""
    z = list(subbin_draws(seed, draws, positions, max(draws, 1)))
    return z[0] if z else np.zeros(0, int)


def evaluate_chunk(model: PairPhasors, offsets_m: np.ndarray, cases=CASES,
                   pose: dict | None = None, subbin=None) -> dict:
    """Per draw of ``offsets_m`` (k, 2, 3) (and ``pose``: rotations (k, 2) and RuT pose
    errors, :meth:`PairPhasors.air_legs`; ``subbin`` (k,): the target's sub-bin positions,
    None: the bin centre): for each case the signed angle error of the worst set-point (deg)
    and the number of snapshots ``refine_angles`` left to ``estimate_angles``; the
    calibration (delay steps of channel J) and the range offset it causes (m). Pure: the
    same offsets give the same bits.

    Evaluated in blocks of :data:`BLOCK_DRAWS` draws, each reduced to these numbers at once
    (the per-set-point detail of a 10 000-draw chunk, joined, was 2-3 % of its time)."""
    cases = tuple(cases)
    for case in cases:
        if case not in ALL_CASES:
            raise ValueError(f"case {case!r}: must be one of {', '.join(ALL_CASES)}")
    n = len(offsets_m)
    parts = []
    for b in range(0, max(n, 1), BLOCK_DRAWS):
        if n <= BLOCK_DRAWS:  # one block: the arguments as given
            off, sub, sub_pose = offsets_m, subbin, pose
        else:
            sl = slice(b, b + BLOCK_DRAWS)
            off, sub = offsets_m[sl], None if subbin is None else subbin[sl]
            sub_pose = None if pose is None else {
                k: (None if v is None else np.asarray(v)[sl]) for k, v in pose.items()}
        err, det = model.draw_errors(off, sub, cases, sub_pose, return_detail=True)
        part = {"steps": det["steps"]}
        for case in cases:
            e = np.degrees(err[case])
            k = np.argmax(np.abs(e), axis=-1)
            part[case] = np.take_along_axis(e, k[:, None], axis=-1)[:, 0]
            part[case + "_fallbacks"] = int(np.count_nonzero(~det["converged"][case]))
            part[case + "_off_bin"] = int(np.count_nonzero(det["bin"][case]))
        parts.append(part)
    steps = parts[0]["steps"] if len(parts) == 1 else np.concatenate([p["steps"] for p in parts])
    out = {"steps": steps, "range_offset_m": model.range_offset_m(offsets_m, steps, pose)}
    for case in cases:
        out[case] = (parts[0][case] if len(parts) == 1
                     else np.concatenate([p[case] for p in parts]))
        for key in (case + "_fallbacks", case + "_off_bin"):
            out[key] = sum(p[key] for p in parts)
    return out


#: draws per block inside a chunk: the temporaries (draws x set-points x bins) stay below
#: glibc's mmap threshold, which saves the page-fault system time of 10 000-draw blocks
#: (measured: 0.4-0.6 s of system time per 20 000 draws at 10 000, none at 1000; user time
#: the same). Elementwise and row-wise arithmetic only, so the bits do not depend on it.
BLOCK_DRAWS = 1000


def _evaluate_part(model: PairPhasors, part: DrawChunk, cases) -> dict:
    offsets, subbin = part.offsets(), part.subbin()
    out = evaluate_chunk(model, offsets, cases, subbin=subbin)
    out["subbin"] = subbin
    return out


# ------------------------------------------------------------------------------------------
# Monte Carlo and its statistics
# ------------------------------------------------------------------------------------------


def percentiles(values: np.ndarray, scale: float = 1.0) -> dict:
    """p50, p95, p99 and max of ``values`` (times ``scale``); None where there are none."""
    a = np.asarray(values, float) * scale
    if a.size == 0:
        return {"p50": None, "p95": None, "p99": None, "max": None}
    p = np.percentile(a, [50, 95, 99])
    return {"p50": float(p[0]), "p95": float(p[1]), "p99": float(p[2]), "max": float(a.max())}


def draws_header(draws: int, seed: int, distribution: str, sigma_m, spec_deg: float) -> dict:
    """The leading keys of a tolerance study's JSON (pair and cell alike): what was drawn."""
    return {"draws": draws, "seed": seed, "distribution": distribution,
            "scale": "sigma" if distribution == "normal" else "bound",
            "sigma_mm": {a: float(s * 1e3) for a, s in zip(AXES, sigma_m)},
            "spec_deg": spec_deg}


@dataclass(frozen=True)
class ToleranceResult:
    """A Monte-Carlo run: per draw the worst signed angle error of each case (deg)."""

    model: PairPhasors
    sigma_m: np.ndarray  # (3,) radial, tangential, height
    distribution: str
    draws: int
    seed: int
    spec_deg: float
    worst_error_deg: dict  # case -> (draws,)
    delay_s: np.ndarray  # (draws,) calibration delay offset of channel J
    range_offset_m: np.ndarray  # (draws,) range offset between the channels after calibration
    fallbacks: dict  # case -> snapshots that needed estimate_angles
    elapsed_s: float = 0.0
    subbin_steps: np.ndarray | None = None  # (draws,) the target's sub-bin offset (delay steps)
    off_bin: dict | None = None  # case -> set-points detected off the set range's bin
    cpu_s: float = 0.0  # process CPU time of the run (time.process_time; this process only)

    def yield_(self, case: str) -> float:
        e = self.worst_error_deg[case]
        return float(np.mean(np.abs(e) <= self.spec_deg)) if e.size else float("nan")

    def stats(self, case: str) -> dict:
        out = {"angle_error_deg": percentiles(np.abs(self.worst_error_deg[case])),
               "yield": self.yield_(case), "fallbacks": self.fallbacks[case]}
        if self.off_bin is not None:
            out["detected_off_bin"] = self.off_bin[case]
        return out

    def to_dict(self) -> dict:
        out = {
            **draws_header(self.draws, self.seed, self.distribution, self.sigma_m,
                           self.spec_deg),
            "pair": self.model.to_dict(),
            "subbin": {
                "distribution": ("uniform over one range bin" if self.subbin_steps is not None
                                 else "bin centre"),
                "positions": int(self.model.subbin_steps.size),
                "step_s": self.model.delay_resolution_s,
            },
        }
        for case in self.worst_error_deg:
            out[case] = self.stats(case)
        out["calibration"] = {
            "abs_delta_tau_ps": percentiles(np.abs(self.delay_s), 1e12),
            "abs_range_offset_mm": percentiles(np.abs(self.range_offset_m), 1e3),
        }
        return out


def monte_carlo(model: PairPhasors, sigma_m, draws: int, seed: int,
                distribution: str = "normal", spec_deg: float = 0.1, cases=CASES,
                chunk: int = DEFAULT_CHUNK, progress: Progress | None = None,
                label: str = "tolerance", mapper: Mapper | None = None,
                subbin: bool = True) -> ToleranceResult:
    """``draws`` setups with mounting errors scaled by ``sigma_m`` (3,) (m; the standard
    deviation, or the uniform bound) and, with ``subbin``, the target at a sub-bin position
    drawn per draw (:func:`subbin_draws`; False: at the bin centre), evaluated chunk by chunk:
    in this process, one chunk in memory at a time, or by ``mapper(func, chunks)`` (results in
    chunk order, e.g. a process pool's ``map``; each chunk is a :class:`DrawChunk`, the streams'
    states at its start, so a cluster is sent a few hundred bytes per chunk, not the draws).
    The outcome depends on neither."""
    t0, c0 = time.perf_counter(), time.process_time()
    sigma = np.asarray(sigma_m, float).reshape(3)
    if np.any(~np.isfinite(sigma)) or np.any(sigma < 0):
        raise ValueError(f"sigma_m {sigma.tolist()}: must be finite and >= 0")
    parts: list[dict] = []
    done = 0
    chunks = draw_chunks(seed, draws, sigma, distribution, chunk, model.subbin_steps.size,
                         model.subbin_zero, subbin)
    func = functools.partial(_evaluate_part, model, cases=tuple(cases))
    for part in (map(func, chunks) if mapper is None else mapper(func, list(chunks))):
        parts.append(part)
        done += len(part["steps"])
        if progress:
            progress(label, done, draws)

    def joined(key):
        return frozen(np.concatenate([p[key] for p in parts]) if parts else np.zeros(0))

    sub = joined("subbin").astype(int)
    return ToleranceResult(model, frozen(sigma), distribution, int(draws), int(seed),
                           float(spec_deg), {case: joined(case) for case in cases},
                           frozen(joined("steps") * model.delay_resolution_s),
                           joined("range_offset_m"),
                           {case: sum(p[case + "_fallbacks"] for p in parts) for case in cases},
                           time.perf_counter() - t0,
                           frozen(model.subbin_steps[sub]) if subbin else None,
                           {case: sum(p[case + "_off_bin"] for p in parts) for case in cases},
                           time.process_time() - c0)


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


def max_sigma_for_yield(model: PairPhasors, sigma_m, draws: int, seed: int, target_yield: float,
                        spec_deg: float = 0.1, case: str = "calibrated", axis: str = "all",
                        distribution: str = "normal", rel_tol: float = 0.01,
                        cap_m: float = 0.01, chunk: int = DEFAULT_CHUNK,
                        progress: Progress | None = None, mapper: Mapper | None = None,
                        subbin: bool = True, slope: float = 1.0) -> dict:
    """The largest mounting tolerance that keeps ``target_yield`` of the setups within
    ``spec_deg`` for ``case``, by a safeguarded secant search on the scale
    (:func:`largest_passing_scale`) with the same seed (the same unit draws scaled: common
    random numbers, so the yield curve is smooth and, up to the rare draw whose error is not
    monotone in the scale, monotone).

    ``axis="all"`` scales the three sigmas together (their ratios as given; all ones where
    all are zero); an axis name varies that axis alone, the other two held at ``sigma_m``.
    Returns the sigmas found (m), the yield there, the bracket and the evaluations; the search
    stops at ``cap_m`` (a tolerance that large is reported as ``capped``). The result is the
    largest passing scale evaluated, within ``rel_tol`` of the smallest failing one. ``slope``:
    the power of the scale the deciding draw's error is taken to follow until two evaluations
    measure it (:func:`largest_passing_scale`)."""
    base = np.asarray(sigma_m, float).reshape(3)
    direction, fixed = search_direction(base, axis)
    history = []

    def yield_at(t: float) -> tuple[float, float]:
        if t == 0.0 and not np.any(fixed):
            worst = _worst_without_errors(model, draws, seed, case, subbin)
        else:
            res = monte_carlo(model, fixed + t * direction, draws, seed, distribution,
                              spec_deg, (case,), chunk, progress,
                              f"{case}: sigma {t * 1e3:.4g} mm", mapper, subbin)
            worst = res.worst_error_deg[case]
        y = float(np.mean(np.abs(worst) <= spec_deg)) if worst.size else float("nan")
        history.append({"scale_mm": t * 1e3, "yield": y})
        return y, critical_ratio(worst, spec_deg, target_yield)

    def result(t, y, capped=False, note=None):
        sig = fixed + t * direction
        return {"case": case, "axis": axis, "target_yield": target_yield, "spec_deg": spec_deg,
                "sigma_mm": {a: float(s * 1e3) for a, s in zip(AXES, sig)},
                "yield": y, "capped": capped, "note": note,
                "evaluations": history}

    y0, _ = yield_at(0.0)
    if y0 < target_yield:
        return result(0.0, y0, note="the setup misses the spec even without the varied errors")
    start = min(float(np.max(base * direction)) or 1e-4, cap_m)
    return result(*largest_passing_scale(yield_at, y0, target_yield, start, cap_m, rel_tol,
                                         slope=slope))


def _worst_without_errors(model: PairPhasors, draws: int, seed: int, case: str,
                          subbin: bool) -> np.ndarray:
    """:func:`monte_carlo`'s worst error per draw (deg) with every mounting error zero: the
    draws differ only in the target's sub-bin position, so each position drawn is evaluated
    once (``evaluate_chunk`` is row by row: the same bits)."""
    u = (draw_subbins(seed, draws, model.subbin_steps.size) if subbin
         else np.full(draws, model.subbin_zero))
    uniq, inv = np.unique(u, return_inverse=True)
    parts = [evaluate_chunk(model, np.zeros((min(DEFAULT_CHUNK, uniq.size - b), 2, 3)), (case,),
                            subbin=uniq[b:b + DEFAULT_CHUNK])[case]
             for b in range(0, uniq.size, DEFAULT_CHUNK)]
    return (np.concatenate(parts) if parts else np.zeros(0))[np.ravel(inv)]


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
