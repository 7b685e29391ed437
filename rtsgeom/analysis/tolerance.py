"""Mounting-tolerance Monte Carlo of the arbitrary-angle synthesis (paper section "Arbitrary
Angle of Arrival", "Constraints": a radial error of lambda/4 already cancels the composite).

Each draw moves both front ends of a pair radially, tangentially and in height (normal with
given sigmas, or uniform within given bounds). The operator does not know the errors: the
amplitudes of the set-points across the pair's span (21 by default, ends excluded as in
``aoa.linearity``) are designed once on the nominal setup (:class:`~rtsgeom.aoa.model.ChannelModel`,
its ``solve`` and ``amplitudes`` for the phase the calibration establishes, see
:meth:`PairPhasors.coherence_phase`).
For every draw the synthesized angle is evaluated uncalibrated (no delay offset) and after
the calibration, with the target at a sub-bin position drawn per draw (uniform over one range
bin, in steps of the RTS's delay resolution; its own stream ``default_rng([seed, 1])``, so the
mounting errors are the same draws as without it).

The model of one draw (the target's sub-bin position, the bin the RuT detects, the
calibration at phasor level, the mounting errors as phasor factors) is
:class:`~rtsgeom.analysis.tolerance_model.PairPhasors`; ``tolerance_verify`` pushes draws
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

from .._util import frozen
from .tolerance_model import PROBE_FRACTIONS, PairPhasors  # noqa: F401 (public here too)

__all__ = ["AXES", "DISTRIBUTIONS", "CASES", "ALL_CASES", "NOMINAL_AMPLITUDES", "PairPhasors",
           "ToleranceResult", "draw_offsets", "standard_draws", "subbin_draws", "evaluate_chunk",
           "monte_carlo", "max_sigma_for_yield", "percentiles"]

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
    if distribution not in DISTRIBUTIONS:
        raise ValueError(f"distribution {distribution!r}: must be one of "
                         f"{', '.join(DISTRIBUTIONS)}")
    rng = np.random.default_rng(seed)
    chunk = max(1, int(chunk))
    for start in range(0, draws, chunk):
        k = min(chunk, draws - start)
        if distribution == "normal":
            yield rng.standard_normal((k, front_ends, 3))
        else:
            yield rng.uniform(-1.0, 1.0, (k, front_ends, 3))


def subbin_draws(seed: int, draws: int, positions: int, chunk: int = DEFAULT_CHUNK
                 ) -> Iterator[np.ndarray]:
    """The target's sub-bin position per draw, chunk by chunk: indices (k,) into
    ``PairPhasors.subbin_steps`` (``positions`` equally likely positions across one range bin),
    from their own stream ``numpy.random.default_rng([seed, 1])`` (the mounting errors keep
    theirs). The stream does not depend on ``chunk``."""
    rng = np.random.default_rng([int(seed), 1])
    chunk = max(1, int(chunk))
    for start in range(0, draws, chunk):
        k = min(chunk, draws - start)
        yield np.minimum((rng.random(k) * positions).astype(int), positions - 1)


def draw_offsets(seed: int, draws: int, sigma_m, distribution: str = "normal") -> np.ndarray:
    """All mounting errors (draws, 2, 3) of a study at once (the per-axis scale ``sigma_m``
    (3,) is the standard deviation, or the bound of the uniform distribution)."""
    z = list(standard_draws(seed, draws, distribution, max(draws, 1)))
    z = z[0] if z else np.zeros((0, 2, 3))
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
    same offsets give the same bits."""
    for case in cases:
        if case not in ALL_CASES:
            raise ValueError(f"case {case!r}: must be one of {', '.join(ALL_CASES)}")
    err, det = _blocked(model, offsets_m, subbin, tuple(cases), pose)
    steps = det["steps"]
    out = {"steps": steps, "range_offset_m": model.range_offset_m(offsets_m, steps, pose)}
    for case in cases:
        e = np.degrees(err[case])
        k = np.argmax(np.abs(e), axis=-1)
        out[case] = np.take_along_axis(e, k[:, None], axis=-1)[:, 0]
        out[case + "_fallbacks"] = int(np.count_nonzero(~det["converged"][case]))
        out[case + "_off_bin"] = int(np.count_nonzero(det["bin"][case]))
    return out


#: draws per block inside a chunk: the temporaries (draws x set-points x bins) stay below
#: glibc's mmap threshold, which saves the page-fault system time of 10 000-draw blocks
#: (measured: 0.4-0.6 s of system time per 20 000 draws at 10 000, none at 1000; user time
#: the same). Elementwise and row-wise arithmetic only, so the bits do not depend on it.
BLOCK_DRAWS = 1000


def _blocked(model: PairPhasors, offsets_m, subbin, cases, pose):
    """``model.draw_errors`` in blocks of :data:`BLOCK_DRAWS` draws, joined."""
    n = len(offsets_m)
    if n <= BLOCK_DRAWS:
        return model.draw_errors(offsets_m, subbin, cases, pose, return_detail=True)
    parts = []
    for b in range(0, n, BLOCK_DRAWS):
        sl = slice(b, b + BLOCK_DRAWS)
        sub_pose = None if pose is None else {
            k: (None if v is None else np.asarray(v)[sl]) for k, v in pose.items()}
        parts.append(model.draw_errors(offsets_m[sl], None if subbin is None else subbin[sl],
                                       cases, sub_pose, return_detail=True))

    def join(items):
        first = items[0]
        if isinstance(first, dict):
            return {k: join([i[k] for i in items]) for k in first}
        return np.concatenate(items)

    return join([p[0] for p in parts]), join([p[1] for p in parts])


def _evaluate_part(model: PairPhasors, part: tuple, cases) -> dict:
    offsets, subbin = part
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
            "draws": self.draws,
            "seed": self.seed,
            "distribution": self.distribution,
            "scale": "sigma" if self.distribution == "normal" else "bound",
            "sigma_mm": {a: float(s * 1e3) for a, s in zip(AXES, self.sigma_m)},
            "spec_deg": self.spec_deg,
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
    chunk order, e.g. a process pool's ``map``; the draws are all made here first). The
    outcome depends on neither."""
    t0, c0 = time.perf_counter(), time.process_time()
    sigma = np.asarray(sigma_m, float).reshape(3)
    if np.any(~np.isfinite(sigma)) or np.any(sigma < 0):
        raise ValueError(f"sigma_m {sigma.tolist()}: must be finite and >= 0")
    parts: list[dict] = []
    done = 0
    n_u = model.subbin_steps.size
    subs = (subbin_draws(seed, draws, n_u, chunk) if subbin
            else (np.full(k.shape[0], model.subbin_zero) for k in
                  standard_draws(seed, draws, distribution, chunk)))
    chunks = ((z * sigma, u) for z, u in zip(standard_draws(seed, draws, distribution, chunk),
                                             subs))
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


def max_sigma_for_yield(model: PairPhasors, sigma_m, draws: int, seed: int, target_yield: float,
                        spec_deg: float = 0.1, case: str = "calibrated", axis: str = "all",
                        distribution: str = "normal", rel_tol: float = 0.01,
                        cap_m: float = 0.01, chunk: int = DEFAULT_CHUNK,
                        progress: Progress | None = None, mapper: Mapper | None = None,
                        subbin: bool = True) -> dict:
    """The largest mounting tolerance that keeps ``target_yield`` of the setups within
    ``spec_deg`` for ``case``, by bisection on the scale with the same seed (the same unit
    draws scaled: common random numbers, so the yield curve is smooth and, up to the rare
    draw whose error is not monotone in the scale, monotone).

    ``axis="all"`` scales the three sigmas together (their ratios as given; all ones where
    all are zero); an axis name varies that axis alone, the other two held at ``sigma_m``.
    Returns the sigmas found (m), the yield there, the bracket and the evaluations; the search
    stops at ``cap_m`` (a tolerance that large is reported as ``capped``)."""
    base = np.asarray(sigma_m, float).reshape(3)
    if axis == "all":
        direction = base / base.max() if base.max() > 0 else np.ones(3)
        fixed = np.zeros(3)
    elif axis in AXES:
        direction = np.eye(3)[AXES.index(axis)]
        fixed = base * (1 - direction)
    else:
        raise ValueError(f"axis {axis!r}: must be 'all' or one of {', '.join(AXES)}")
    history = []

    def yield_at(t: float) -> float:
        res = monte_carlo(model, fixed + t * direction, draws, seed, distribution, spec_deg,
                          (case,), chunk, progress, f"{case}: sigma {t * 1e3:.4g} mm", mapper,
                          subbin)
        y = res.yield_(case)
        history.append({"scale_mm": t * 1e3, "yield": y})
        return y

    def result(t, y, capped=False, note=None):
        sig = fixed + t * direction
        return {"case": case, "axis": axis, "target_yield": target_yield, "spec_deg": spec_deg,
                "sigma_mm": {a: float(s * 1e3) for a, s in zip(AXES, sig)},
                "yield": y, "capped": capped, "note": note,
                "evaluations": history}

    y0 = yield_at(0.0)
    if y0 < target_yield:
        return result(0.0, y0, note="the setup misses the spec even without the varied errors")
    start = min(float(np.max(base * direction)) or 1e-4, cap_m)
    return result(*largest_passing_scale(yield_at, y0, target_yield, start, cap_m, rel_tol))


def largest_passing_scale(yield_at, y0: float, target_yield: float, start: float, cap: float,
                          rel_tol: float, max_bisections: int = 60) -> tuple[float, float, bool]:
    """The largest scale t in [0, cap] with ``yield_at(t) >= target_yield`` (``y0`` the yield
    at 0, which passes): double from ``start`` until the yield drops (or ``cap``: then
    ``capped``), then bisect geometrically to ``rel_tol``. Common random numbers (the same
    seed in every evaluation) keep the yield monotone in t. Returns (t, yield, capped)."""
    lo, y_lo, hi = 0.0, y0, start
    y_hi = yield_at(hi)
    while y_hi >= target_yield:
        if hi >= cap:
            return hi, y_hi, True
        lo, y_lo = hi, y_hi
        hi = min(2 * hi, cap)
        y_hi = yield_at(hi)
    for _ in range(max_bisections):
        if hi - lo <= rel_tol * hi:
            break
        mid = math.sqrt(lo * hi) if lo > 0 else 0.5 * hi
        y = yield_at(mid)
        if y >= target_yield:
            lo, y_lo = mid, y
        else:
            hi = mid
    return lo, y_lo, False
