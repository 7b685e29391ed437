"""Whole arcs: the mounting-tolerance Monte Carlo of every adjacent pair at once, with one draw
per front end shared by the pairs it belongs to (issue 14, item 4).

A front end between two pairs is one physical module: its radial, tangential and height
errors and its rotations (yaw about the vertical, pitch about the tangent) are drawn once and
enter both pairs (``ChannelModel.perturbed`` of each :class:`~rtsgeom.analysis.tolerance.driver.PairPhasors`);
the RuT's pose error (position x, y, z and yaw) is drawn once per draw and enters every pair.
A draw *passes* only if every pair's worst set-point stays within the spec, so the arc's yield
is the fraction of built arcs that meet the spec everywhere -- not a product of pair yields
(which would treat shared front ends as independent).

The target: one target at one range for the whole arc, at a sub-bin position drawn per draw
(uniform over one range bin in steps of the RTS delay resolution, the pair study's
:func:`~rtsgeom.analysis.tolerance.driver.subbin_draws`) and shared by every pair: each pair's
:class:`~rtsgeom.analysis.tolerance.driver.PairPhasors` reads its tables at that position and follows
the bin the RuT detects there (``subbin=False``: every draw at the bin centre, as before).

Random streams: the position errors come from ``numpy.random.default_rng(seed)`` in chunks of
shape (k, F, 3), the same stream :func:`~rtsgeom.analysis.tolerance.driver.standard_draws` gives a
pair (F = 2), and the sub-bin positions from the pair study's ``default_rng([seed, 1])``
(:func:`~rtsgeom.analysis.tolerance.driver.subbin_draws`), so an arc of two front ends reproduces the
pair study bit for bit, with or without the sub-bin draws; the rotations and the RuT pose come
from their own streams (``default_rng([seed, 3])``, ``[seed, 2]``; the rotations moved from
``[seed, 1]`` when the arc took over the pair study's sub-bin stream), so adding them leaves the
position and sub-bin draws unchanged. No stream depends on the chunk size.

Tolerance bounds are given as the value of the tolerance and the sigma level it stands for:
normal errors have sigma = bound / sigma_level ("+-0.2 mm at 3 sigma"); uniform errors are
uniform in [-bound, +bound] (the sigma level does not apply).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterator

import numpy as np

from ..._lib.util import frozen
from ...errors import ParameterError
from .driver import (CASES, PairPhasors, check_distribution, critical_ratio, evaluate_chunk,
                     largest_passing_scale, percentiles, standard_draws, subbin_draws, unit_block)

__all__ = ["Bounds", "ArcResult", "arc_draws", "arc_monte_carlo", "arc_models",
           "adjacent_pairs", "max_scale_for_yield", "shared_subbin_steps"]

DEFAULT_CHUNK = 10_000
Progress = Callable[[str, int, int], None]


def adjacent_pairs(count: int) -> list[tuple[int, int]]:
    """Every adjacent pair (i, i + 1) of an arc of ``count`` front ends."""
    return [(i, i + 1) for i in range(count - 1)]


@dataclass(frozen=True)
class Bounds:
    """The per-draw error scales (SI): the standard deviation (normal) or the bound (uniform).

    ``offsets_m`` (3,) radial, tangential, height of every front end; ``yaw_rad``,
    ``pitch_rad`` its mounting rotations; ``rut_position_m`` (3,) and ``rut_yaw_rad`` the
    RuT's pose."""

    offsets_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    yaw_rad: float = 0.0
    pitch_rad: float = 0.0
    rut_position_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rut_yaw_rad: float = 0.0

    @classmethod
    def from_tolerances(cls, tol: dict, distribution: str, sigma_level: float = 3.0) -> "Bounds":
        """From tolerances (SI; keys as the fields): the scale is tol / sigma_level for normal
        errors, tol itself for uniform ones."""
        k = 1.0 / sigma_level if distribution == "normal" else 1.0
        return cls(tuple(k * float(v) for v in tol.get("offsets_m", (0.0,) * 3)),
                   k * float(tol.get("yaw_rad", 0.0)), k * float(tol.get("pitch_rad", 0.0)),
                   tuple(k * float(v) for v in tol.get("rut_position_m", (0.0,) * 3)),
                   k * float(tol.get("rut_yaw_rad", 0.0)))

    def scaled(self, s: float) -> "Bounds":
        return Bounds(tuple(s * v for v in self.offsets_m), s * self.yaw_rad, s * self.pitch_rad,
                      tuple(s * v for v in self.rut_position_m), s * self.rut_yaw_rad)

    @property
    def rotations(self) -> bool:
        return self.yaw_rad != 0.0 or self.pitch_rad != 0.0

    @property
    def rut_pose(self) -> bool:
        return any(self.rut_position_m) or self.rut_yaw_rad != 0.0

    def check(self) -> None:
        vals = [*self.offsets_m, self.yaw_rad, self.pitch_rad, *self.rut_position_m,
                self.rut_yaw_rad]
        if not all(math.isfinite(v) and v >= 0 for v in vals):
            raise ParameterError(f"tolerance bounds {vals}: must be finite and >= 0")

    def to_dict(self) -> dict:
        return {"radial_mm": self.offsets_m[0] * 1e3, "tangential_mm": self.offsets_m[1] * 1e3,
                "height_mm": self.offsets_m[2] * 1e3, "yaw_deg": math.degrees(self.yaw_rad),
                "pitch_deg": math.degrees(self.pitch_rad),
                "rut_position_mm": [v * 1e3 for v in self.rut_position_m],
                "rut_yaw_deg": math.degrees(self.rut_yaw_rad)}


#: the rotations' stream, ``default_rng([seed, ROTATION_STREAM])`` (1 is the sub-bin positions')
ROTATION_STREAM = 3


def arc_draws(seed: int, draws: int, count: int, distribution: str = "normal",
              chunk: int = DEFAULT_CHUNK, positions: int | None = None) -> Iterator[dict]:
    """Unit-scale draws chunk by chunk: ``offsets`` (k, F, 3), ``rotations`` (k, F, 2) (yaw,
    pitch) and ``rut`` (k, 4) (x, y, z, yaw), each from its own generator (see the module
    docstring); with ``positions`` (the count of sub-bin positions, ``PairPhasors.subbin_steps``)
    also ``subbin`` (k,), the target's sub-bin position index per draw (the pair study's
    :func:`~rtsgeom.analysis.tolerance.driver.subbin_draws`). None depends on ``chunk``."""
    check_distribution(distribution)
    g_rot = np.random.default_rng([seed, ROTATION_STREAM])
    g_rut = np.random.default_rng([seed, 2])
    chunk = max(1, int(chunk))
    offsets = standard_draws(seed, draws, distribution, chunk, count)  # the pair study's
    subs = None if positions is None else subbin_draws(seed, draws, int(positions), chunk)
    for start in range(0, draws, chunk):
        k = min(chunk, draws - start)
        out = {"offsets": next(offsets),
               "rotations": unit_block(g_rot, (k, count, 2), distribution),
               "rut": unit_block(g_rut, (k, 4), distribution)}
        if subs is not None:
            out["subbin"] = next(subs)
        yield out


def _scale(unit: dict, b: Bounds) -> dict:
    """Physical errors of a chunk: offsets (k, F, 3) m, yaw/pitch (k, F) rad, RuT (k, 3) m and
    (k,) rad (None where the bound is zero: the nominal arithmetic stays untouched)."""
    out = {"offsets_m": unit["offsets"] * np.asarray(b.offsets_m)}
    rot = unit["rotations"]
    out["yaw_rad"] = rot[..., 0] * b.yaw_rad if b.rotations else None
    out["pitch_rad"] = rot[..., 1] * b.pitch_rad if b.rotations else None
    if b.rut_pose:
        out["rut_offset_m"] = unit["rut"][:, :3] * np.asarray(b.rut_position_m)
        out["rut_yaw_rad"] = unit["rut"][:, 3] * b.rut_yaw_rad
    else:
        out["rut_offset_m"] = out["rut_yaw_rad"] = None
    return out


def _pair_pose(err: dict, pair: tuple[int, int]) -> tuple[np.ndarray, dict]:
    # an adjacent pair as a slice (a view: with two front ends the very array the pair study
    # evaluates, so the sums round alike and the results agree bit for bit)
    q = slice(pair[0], pair[0] + 2) if pair[1] == pair[0] + 1 else list(pair)
    pose = {"yaw_rad": None if err["yaw_rad"] is None else err["yaw_rad"][:, q],
            "pitch_rad": None if err["pitch_rad"] is None else err["pitch_rad"][:, q],
            "rut_offset_m": err["rut_offset_m"], "rut_yaw_rad": err["rut_yaw_rad"]}
    if all(v is None for v in pose.values()):
        pose = None
    return err["offsets_m"][:, q], pose


def _evaluate(models: tuple, unit: dict, bounds: Bounds, cases) -> dict:
    err = _scale(unit, bounds)
    sub = unit.get("subbin")  # one target: the same sub-bin position in every pair
    out = {"errors": err, "pairs": [], "subbin": sub}
    for m in models:
        off, pose = _pair_pose(err, m.pair)
        out["pairs"].append(evaluate_chunk(m, off, cases, pose=pose, subbin=sub))
    return out


def shared_subbin_steps(models) -> np.ndarray:
    """The target's sub-bin positions (delay steps) common to every pair's model: one target,
    one range, so every pair must offer the same positions (the same range bin, delay
    resolution and reference target); a clear error where they differ."""
    steps = [np.asarray(m.subbin_steps) for m in models]
    if any(s.shape != steps[0].shape or not np.array_equal(s, steps[0]) for s in steps[1:]):
        raise ParameterError("arc: the pairs' models disagree on the target's sub-bin "
                             "positions (built for different ranges or radars); build them "
                             "with arc_models on one setup")
    return steps[0]


@dataclass(frozen=True)
class ArcResult:
    """An arc's Monte Carlo: per pair and draw the worst signed error of each case (deg)."""

    pairs: tuple[tuple[int, int], ...]
    count: int  # front ends drawn
    bounds: Bounds
    distribution: str
    draws: int
    seed: int
    spec_deg: float
    worst_error_deg: dict  # case -> (draws, P)
    delay_s: np.ndarray  # (draws, P) calibration delay of each pair's second channel
    range_offset_m: np.ndarray  # (draws, P)
    fallbacks: dict  # case -> (P,)
    errors: dict = field(default_factory=dict)  # per-draw offsets and rotations (SI), or {}
    elapsed_s: float = 0.0
    subbin_steps: np.ndarray | None = None  # (draws,) the target's sub-bin offset (delay
    # steps), shared by every pair; None: at the bin centre
    subbin_positions: int = 1  # positions the sub-bin draw chooses among
    delay_resolution_s: float = 0.0

    def passes(self, case: str) -> np.ndarray:
        """(draws,) bool: every pair within the spec."""
        return np.all(np.abs(self.worst_error_deg[case]) <= self.spec_deg, axis=-1)

    def yield_(self, case: str) -> float:
        p = self.passes(case)
        return float(np.mean(p)) if p.size else float("nan")

    def pair_yield(self, case: str, p: int) -> float:
        e = self.worst_error_deg[case][:, p]
        return float(np.mean(np.abs(e) <= self.spec_deg)) if e.size else float("nan")

    def arc_worst(self, case: str) -> np.ndarray:
        """(draws,) the error of the arc's worst pair (signed)."""
        e = self.worst_error_deg[case]
        k = np.argmax(np.abs(e), axis=-1)
        return np.take_along_axis(e, k[:, None], axis=-1)[:, 0]

    def to_dict(self) -> dict:
        out = {"pairs": [], "front_ends": self.count, "draws": self.draws, "seed": self.seed,
               "distribution": self.distribution,
               "scale": "sigma" if self.distribution == "normal" else "bound",
               "scales": self.bounds.to_dict(), "spec_deg": self.spec_deg,
               "subbin": {"distribution": ("uniform over one range bin, one position per "
                                           "draw shared by every pair"
                                           if self.subbin_steps is not None else "bin centre"),
                          "positions": int(self.subbin_positions),
                          "step_s": self.delay_resolution_s}}
        for p, pair in enumerate(self.pairs):
            entry = {"pair": list(pair)}
            for case in self.worst_error_deg:
                entry[case] = {"angle_error_deg": percentiles(
                    np.abs(self.worst_error_deg[case][:, p])),
                    "yield": self.pair_yield(case, p),
                    "fallbacks": int(self.fallbacks[case][p])}
            entry["calibration"] = {
                "abs_delta_tau_ps": percentiles(np.abs(self.delay_s[:, p]), 1e12),
                "abs_range_offset_mm": percentiles(np.abs(self.range_offset_m[:, p]), 1e3)}
            out["pairs"].append(entry)
        out["arc"] = {case: {"angle_error_deg": percentiles(np.abs(self.arc_worst(case))),
                             "yield": self.yield_(case),
                             "worst_pair_counts": np.bincount(
                                 np.argmax(np.abs(self.worst_error_deg[case]), axis=-1),
                                 minlength=len(self.pairs)).tolist()}
                      for case in self.worst_error_deg}
        return out

    def save_npz(self, path: str | Path) -> None:
        """Per-draw errors (SI) and worst angle errors per pair for sensitivity analysis:
        ``offsets_m`` (draws, F, 3), ``yaw_rad``/``pitch_rad`` (draws, F), ``rut_offset_m``
        (draws, 3), ``rut_yaw_rad`` (draws,), ``<case>_deg`` (draws, P), ``pairs`` (P, 2),
        ``delay_s``, ``range_offset_m`` (draws, P), ``subbin_steps`` (draws,) (the target's
        sub-bin offset in delay steps; zeros at the bin centre)."""
        arrays = {k: v for k, v in self.errors.items()}
        arrays["subbin_steps"] = (np.zeros(self.draws, int) if self.subbin_steps is None
                                  else np.asarray(self.subbin_steps))
        arrays.update({f"{case}_deg": v for case, v in self.worst_error_deg.items()})
        arrays.update(pairs=np.array(self.pairs), delay_s=self.delay_s,
                      range_offset_m=self.range_offset_m, spec_deg=np.float64(self.spec_deg))
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(path.name + ".part")
        with open(tmp, "wb") as fh:
            np.savez_compressed(fh, **arrays)
        tmp.replace(path)


def arc_models(setup, pairs, points: int = 21) -> tuple[PairPhasors, ...]:
    """The design (:class:`PairPhasors`) of every pair on the nominal setup."""
    return tuple(PairPhasors.build(setup, p, points) for p in pairs)


def arc_monte_carlo(models, count: int, bounds: Bounds, draws: int, seed: int,
                    distribution: str = "normal", spec_deg: float = 0.1, cases=CASES,
                    chunk: int = DEFAULT_CHUNK, keep_errors: bool = False,
                    progress: Progress | None = None, label: str = "arc",
                    mapper=None, subbin: bool = True) -> ArcResult:
    """``draws`` arcs of ``count`` front ends with errors of scale ``bounds``, every pair of
    ``models`` evaluated on the same draw (shared front ends, shared RuT pose, and with
    ``subbin`` one target at a sub-bin position drawn per draw, shared by every pair; False:
    at the bin centre). ``mapper``: an ordered map over chunks (e.g. a Dask client's,
    ``parallel.map_chunks``)."""
    import functools
    t0 = time.perf_counter()
    bounds.check()
    models = tuple(models)
    positions = shared_subbin_steps(models) if models else np.zeros(1, int)
    func = functools.partial(_evaluate, models, bounds=bounds, cases=tuple(cases))
    chunks = arc_draws(seed, draws, count, distribution, chunk,
                       positions.size if subbin else None)
    parts, done = [], 0
    for part in (map(func, chunks) if mapper is None else mapper(func, list(chunks))):
        parts.append(part)
        done += part["errors"]["offsets_m"].shape[0]
        if progress:
            progress(label, done, draws)
    n_p = len(models)

    def joined(key):
        if not parts:
            return np.zeros((0, n_p))
        return frozen(np.stack([np.concatenate([pt["pairs"][p][key] for pt in parts])
                                for p in range(n_p)], axis=-1))

    worst = {case: joined(case) for case in cases}
    delay = frozen(joined("steps") * np.array([m.delay_resolution_s for m in models]))
    fallbacks = {case: np.array([sum(pt["pairs"][p][case + "_fallbacks"] for pt in parts)
                                 for p in range(n_p)]) for case in cases}
    errors = {}
    if keep_errors and parts:
        for key in ("offsets_m", "yaw_rad", "pitch_rad", "rut_offset_m", "rut_yaw_rad"):
            vals = [pt["errors"][key] for pt in parts]
            if vals[0] is None:
                shape = {"offsets_m": (count, 3), "yaw_rad": (count,), "pitch_rad": (count,),
                         "rut_offset_m": (3,), "rut_yaw_rad": ()}[key]
                errors[key] = np.zeros((draws,) + shape)
            else:
                errors[key] = np.concatenate(vals)
    sub = None
    if subbin:
        idx = (np.concatenate([pt["subbin"] for pt in parts]) if parts
               else np.zeros(0, int))
        sub = frozen(positions[idx.astype(int)])
    return ArcResult(tuple(m.pair for m in models), int(count), bounds, distribution,
                     int(draws), int(seed), float(spec_deg), worst, delay,
                     joined("range_offset_m"), fallbacks, errors, time.perf_counter() - t0,
                     sub, int(positions.size),
                     float(models[0].delay_resolution_s) if models else 0.0)


def max_scale_for_yield(models, count: int, bounds: Bounds, draws: int, seed: int,
                        target_yield: float, spec_deg: float = 0.1, case: str = "calibrated",
                        distribution: str = "normal", rel_tol: float = 0.02,
                        cap: float = 100.0, chunk: int = DEFAULT_CHUNK,
                        subbin: bool = True) -> dict:
    """The largest factor s on ``bounds`` that keeps ``target_yield`` of the *arcs* within
    ``spec_deg`` (every pair), by the secant search with common random numbers (the same seed), as
    :func:`~rtsgeom.analysis.tolerance.driver.max_sigma_for_yield` does for one pair. Returns the
    factor, the scaled bounds, the yield there and whether the search hit ``cap``.
    ``subbin``: :func:`arc_monte_carlo`'s (the same sub-bin positions at every scale)."""
    history = []

    def yield_at(s):
        res = arc_monte_carlo(models, count, bounds.scaled(s), draws, seed, distribution,
                              spec_deg, (case,), chunk, subbin=subbin)
        y = res.yield_(case)
        history.append({"scale": s, "yield": y})
        return y, critical_ratio(res.worst_error_deg[case], spec_deg, target_yield)

    def result(s, y, capped=False):
        return {"case": case, "factor": s, "scales": bounds.scaled(s).to_dict(), "yield": y,
                "capped": capped, "evaluations": history}

    y0, _ = yield_at(0.0)
    if y0 < target_yield:
        return result(0.0, y0)
    return result(*largest_passing_scale(yield_at, y0, target_yield, 1.0, cap, rel_tol))
