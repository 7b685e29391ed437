"""The one Monte-Carlo driver of the tolerance studies and its result.

A study is a :class:`ToleranceModel`: one or more channel sets (:class:`~.phasors.ChannelPhasors`)
on shared draws. A front-end pair's study and a cell's are one set whose draw is its own front
ends; a whole arc's is every adjacent pair, one draw per front end shared by the pairs it
belongs to (a front end between two pairs is one physical module: its offsets and rotations
enter both), the RuT's pose and the target's sub-bin position shared by every pair. A draw
*passes* only if every set's worst set-point stays within the spec in every angle, so an arc's
yield is the fraction of built arcs that meet the spec everywhere -- not a product of pair
yields (which would treat shared front ends as independent).

The draws are evaluated chunk by chunk (:mod:`.draws`: the same draws whatever the chunk size),
in this process one chunk in memory at a time, or by a ``mapper(func, chunks)`` (a process pool
or a Dask cluster; each chunk is sent as its streams' states, a few hundred bytes). The outcome
depends on neither.
"""

from __future__ import annotations

import functools
import time
from dataclasses import dataclass, field
from pathlib import Path
import numpy as np

from ..._lib.results import Result
from ..._lib.util import frozen
from ...errors import ParameterError
from .config import Mapper, MonteCarlo, Progress
from .draws import AXES, Bounds, DrawChunk, DrawStreams, draw_chunks
from .present import columns as _columns, figure as _figure, summary as _summary
from .phasors import CASES, ChannelPhasors

__all__ = ["ToleranceModel", "ToleranceResult", "monte_carlo", "simulate", "percentiles",
           "as_bounds", "Progress", "Mapper", "MonteCarlo"]
KINDS = ("pair", "cell", "arc")
STAT_KEYS = ("azimuth_error_deg", "elevation_error_deg", "angular_distance_deg")


@dataclass(frozen=True)
class ToleranceModel:
    """Channel sets evaluated on shared draws of ``count`` front ends: set p reads the draw's
    front ends ``columns[p]``. ``kind`` names the study (``pair``, ``cell``: one set drawing
    its own front ends; ``arc``: every set on one draw per front end of the arc)."""

    sets: tuple[ChannelPhasors, ...]
    count: int
    columns: tuple[tuple[int, ...], ...]
    kind: str

    @classmethod
    def of(cls, model: ChannelPhasors) -> "ToleranceModel":
        """One channel set alone: a pair's or a cell's study (its own front ends drawn)."""
        q = len(model.front_ends)
        return cls((model,), q, (tuple(range(q)),), "pair" if model.dims == 1 and q == 2
                   else "cell")

    @classmethod
    def arc(cls, models, count: int) -> "ToleranceModel":
        """The channel sets of an arc of ``count`` front ends (each set reads its own front
        ends' columns), one target for all: their sub-bin positions must agree."""
        models = tuple(models)
        steps = [np.asarray(m.subbin_steps) for m in models]
        if any(s.shape != steps[0].shape or not np.array_equal(s, steps[0]) for s in steps[1:]):
            raise ParameterError("arc: the pairs' models disagree on the target's sub-bin "
                                 "positions (built for different ranges or radars); build them "
                                 "on one setup")
        return cls(models, int(count), tuple(m.front_ends for m in models), "arc")

    @property
    def subbin_steps(self) -> np.ndarray:
        return self.sets[0].subbin_steps if self.sets else np.zeros(1, int)

    @property
    def delay_resolution_s(self) -> float:
        return float(self.sets[0].delay_resolution_s) if self.sets else 0.0

    def evaluate(self, errors: dict, cases) -> list[dict]:
        """Each set's :meth:`~.phasors.ChannelPhasors.evaluate` of one chunk's ``errors``
        (:meth:`.draws.DrawChunk.errors`), its front ends' columns of the shared draw."""
        out = []
        for m, q in zip(self.sets, self.columns):
            # an adjacent run of columns as a slice: a view, so that with the set's own front
            # ends the sums round as in a study of the set alone (the same bits)
            cols = slice(q[0], q[-1] + 1) if list(q) == list(range(q[0], q[-1] + 1)) else list(q)
            pose = {"yaw_rad": errors["yaw_rad"], "pitch_rad": errors["pitch_rad"],
                    "rut_offset_m": errors["rut_offset_m"], "rut_yaw_rad": errors["rut_yaw_rad"]}
            for key in ("yaw_rad", "pitch_rad"):
                if pose[key] is not None:
                    pose[key] = pose[key][:, cols]
            pose = None if all(v is None for v in pose.values()) else pose
            out.append(m.evaluate(errors["offsets_m"][:, cols], cases, pose, errors["subbin"]))
        return out


def as_bounds(bounds) -> Bounds:
    """:class:`Bounds` as given, or from the offsets' scales (3,) (m) alone."""
    if isinstance(bounds, Bounds):
        return bounds
    sigma = np.asarray(bounds, float).reshape(3)
    if np.any(~np.isfinite(sigma)) or np.any(sigma < 0):
        raise ParameterError(f"sigma_m {sigma.tolist()}: must be finite and >= 0")
    return Bounds(tuple(float(s) for s in sigma))


def percentiles(values: np.ndarray, scale: float = 1.0) -> dict:
    """p50, p95, p99 and max of ``values`` (times ``scale``); None where there are none."""
    a = np.asarray(values, float) * scale
    if a.size == 0:
        return {"p50": None, "p95": None, "p99": None, "max": None}
    p = np.percentile(a, [50, 95, 99])
    return {"p50": float(p[0]), "p95": float(p[1]), "p99": float(p[2]), "max": float(a.max())}


def draws_header(draws: int, seed: int, distribution: str, sigma_m, spec_deg: float) -> dict:
    """The leading keys of a pair's or a cell's study JSON: what was drawn."""
    return {"draws": draws, "seed": seed, "distribution": distribution,
            "scale": "sigma" if distribution == "normal" else "bound",
            "sigma_mm": {a: float(s * 1e3) for a, s in zip(AXES, sigma_m)},
            "spec_deg": spec_deg}


@dataclass(frozen=True, repr=False)
class ToleranceResult(Result):
    """A Monte-Carlo run: per draw, set and case the worst signed errors (deg), (draws, P, C)
    (C: the sets' columns, :attr:`ChannelPhasors.columns`), the calibration delays and the
    channels' range offsets.

    Counters, per case and set: ``off_bin_per_set`` the set-points the RuT detected in
    another range bin than the set range's, ``fallbacks_per_set`` those whose peak search fell
    back to the grid search; both count (draw, set-point) pairs, so their largest value is
    ``draws`` x the set's set-points (2330 of 2000 x 21 = 42 000 is 5.5 % of the set-points,
    not more than one per draw). ``print(result)`` is a summary; ``to_dataframe()`` one row
    per draw; ``plot()`` the figure of ``rtsgeom tolerance --out``.

    Attributes
    ----------
    model : ToleranceModel
    bounds : Bounds
    distribution : str
    draws, seed : int
    spec_deg : float
    errors_deg : dict
        Case -> (draws, P, C) worst signed errors.
    """

    model: ToleranceModel
    bounds: Bounds
    distribution: str
    draws: int
    seed: int
    spec_deg: float
    errors_deg: dict  # case -> (draws, P, C)
    steps: tuple  # per set (draws, Q): calibration delay steps (channel 0 at 0)
    range_offsets_m: tuple  # per set (draws, Q): each channel's echo's from channel 0's
    fallbacks_per_set: dict  # case -> (P,) snapshots left to the grid search
    off_bin_per_set: dict  # case -> (P,) set-points detected off the set range's bin
    subbin_steps: np.ndarray | None = None  # (draws,) the target's sub-bin offset (delay
    # steps), shared by every set; None: at the bin centre
    errors: dict = field(default_factory=dict)  # per-draw errors (SI), when kept
    elapsed_s: float = 0.0
    cpu_s: float = 0.0  # process CPU time of the run (this process only)

    # -- per draw ---------------------------------------------------------------------------

    @property
    def sigma_m(self) -> np.ndarray:
        return np.asarray(self.bounds.offsets_m, float)

    @property
    def worst_error_deg(self) -> dict:
        """Per case: a pair's (draws,), a cell's (draws, 3) (azimuth, elevation, angular
        distance), an arc's (draws, P) (each pair's worst)."""
        if self.model.kind == "pair":
            return {k: v[:, 0, 0] for k, v in self.errors_deg.items()}
        if self.model.kind == "cell":
            return {k: v[:, 0, :] for k, v in self.errors_deg.items()}
        return {k: v[:, :, 0] for k, v in self.errors_deg.items()}

    @property
    def delay_s(self) -> np.ndarray:
        """Calibration delays (s): a pair's J (draws,), a cell's (draws, Q) (reference 0), an
        arc's each pair's J (draws, P)."""
        res = self.model.delay_resolution_s
        if self.model.kind == "pair":
            return frozen(self.steps[0][:, 1] * res)
        if self.model.kind == "cell":
            return frozen(self.steps[0] * res)
        return frozen(np.stack([s[:, -1] for s in self.steps], -1) * res
                      if self.steps else np.zeros((self.draws, 0)))

    @property
    def range_offset_m(self) -> np.ndarray:
        """Range offset between the channels after calibration (m): a pair's J - I (draws,),
        a cell's largest |offset| (draws,), an arc's each pair's J - I (draws, P)."""
        if self.model.kind == "pair":
            return frozen(self.range_offsets_m[0][:, 1])
        if self.model.kind == "cell":
            return frozen(np.max(np.abs(self.range_offsets_m[0]), axis=-1))
        return frozen(np.stack([r[:, -1] for r in self.range_offsets_m], -1)
                      if self.range_offsets_m else np.zeros((self.draws, 0)))

    @property
    def fallbacks(self) -> dict:
        if self.model.kind == "arc":
            return self.fallbacks_per_set
        return {k: int(v[0]) for k, v in self.fallbacks_per_set.items()}

    @property
    def off_bin(self) -> dict:
        if self.model.kind == "arc":
            return self.off_bin_per_set
        return {k: int(v[0]) for k, v in self.off_bin_per_set.items()}

    def passes(self, case: str) -> np.ndarray:
        """(draws,) bool: every set's every angle within the spec."""
        e = np.abs(self.errors_deg[case])
        n_angles = 1 if e.shape[-1] == 1 else 2  # a cell's third column is a distance
        return np.all(e[..., :n_angles] <= self.spec_deg, axis=(-2, -1))

    def yield_(self, case: str) -> float:
        """Fraction of draws whose every set-point is within the spec in every angle."""
        p = self.passes(case)
        return float(np.mean(p)) if p.size else float("nan")

    def set_yield(self, case: str, p: int) -> float:
        e = np.abs(self.errors_deg[case][:, p, 0])
        return float(np.mean(e <= self.spec_deg)) if e.size else float("nan")

    def arc_worst(self, case: str) -> np.ndarray:
        """(draws,) the signed error of the worst set (and angle)."""
        e = self.errors_deg[case][..., 0]
        k = np.argmax(np.abs(e), axis=-1)
        return np.take_along_axis(e, k[:, None], axis=-1)[:, 0]

    # -- statistics and files -----------------------------------------------------------------

    def stats(self, case: str) -> dict:
        """A pair's or a cell's percentiles of |worst error|, the yield and the counters:
        ``fallbacks`` and ``detected_off_bin`` count (draw, set-point) pairs (at most
        ``set_points_total``: draws x set-points), not draws."""
        e = np.abs(self.errors_deg[case][:, 0])
        if self.model.kind == "cell":
            out = {key: percentiles(e[:, k]) for k, key in enumerate(STAT_KEYS)}
            out["angle_error_deg"] = percentiles(np.max(e[:, :2], axis=-1))
        else:
            out = {"angle_error_deg": percentiles(e[:, 0])}
        out.update({"yield": self.yield_(case), "fallbacks": self.fallbacks[case],
                    "detected_off_bin": self.off_bin[case],
                    "set_points_total": self.draws * int(np.shape(
                        self.model.sets[0].set_rad)[0])})
        return out

    # -- presentation (.present) ----------------------------------------------------------

    def _summary(self):
        return _summary(self)

    def _columns(self) -> dict:
        return _columns(self)

    def plot(self, title: str = ""):
        """A pair's or a cell's CDF of each draw's worst |error|, an arc's of each arc's worst
        error, with the spec; the title says the study, the drawn scales and the spec."""
        return _figure(self, title)

    def _subbin_dict(self) -> dict:
        positions = int(self.model.subbin_steps.size)
        drawn = self.subbin_steps is not None
        if self.model.kind == "arc":
            return {"distribution": ("uniform over one range bin, one position per draw shared "
                                     "by every pair" if drawn else "bin centre"),
                    "positions": positions, "step_s": self.model.delay_resolution_s}
        return {"distribution": "uniform over one range bin" if drawn else "bin centre",
                "positions": positions if drawn or self.model.kind == "pair" else 1,
                "step_s": self.model.delay_resolution_s}

    def to_dict(self) -> dict:
        if self.model.kind == "arc":
            return self._arc_dict()
        out = draws_header(self.draws, self.seed, self.distribution, self.sigma_m, self.spec_deg)
        if self.model.kind == "cell":
            out["bounds"] = self.bounds.to_dict()
            out["yield_rule"] = "every set-point within spec_deg in azimuth and in elevation"
            out["cell"] = self.model.sets[0].to_dict()
        else:
            out["pair"] = self.model.sets[0].to_dict()
        out["subbin"] = self._subbin_dict()
        for case in self.errors_deg:
            out[case] = self.stats(case)
        delay = self.delay_s[:, 1:] if self.model.kind == "cell" else self.delay_s
        range_offset = self.range_offset_m
        out["calibration"] = {
            "abs_delta_tau_ps": percentiles(np.abs(delay), 1e12),
            "abs_range_offset_mm": percentiles(np.abs(range_offset), 1e3)}
        return out

    def _arc_dict(self) -> dict:
        pairs = [list(s.front_ends) for s in self.model.sets]
        out = {"pairs": [], "front_ends": self.model.count, "draws": self.draws,
               "seed": self.seed, "distribution": self.distribution,
               "scale": "sigma" if self.distribution == "normal" else "bound",
               "scales": self.bounds.to_dict(), "spec_deg": self.spec_deg,
               "subbin": self._subbin_dict()}
        delay, rng = self.delay_s, self.range_offset_m
        for p, pair in enumerate(pairs):
            entry = {"pair": pair}
            for case in self.errors_deg:
                entry[case] = {"angle_error_deg": percentiles(
                    np.abs(self.errors_deg[case][:, p, 0])),
                    "yield": self.set_yield(case, p),
                    "fallbacks": int(self.fallbacks_per_set[case][p])}
            entry["calibration"] = {
                "abs_delta_tau_ps": percentiles(np.abs(delay[:, p]), 1e12),
                "abs_range_offset_mm": percentiles(np.abs(rng[:, p]), 1e3)}
            out["pairs"].append(entry)
        out["arc"] = {case: {"angle_error_deg": percentiles(np.abs(self.arc_worst(case))),
                             "yield": self.yield_(case),
                             "worst_pair_counts": np.bincount(
                                 np.argmax(np.abs(self.errors_deg[case][..., 0]), axis=-1),
                                 minlength=len(pairs)).tolist()}
                      for case in self.errors_deg}
        return out

    def save_npz(self, path: str | Path) -> None:
        """Per-draw errors (SI, as kept: ``offsets_m`` (draws, F, 3), ``yaw_rad``/``pitch_rad``
        (draws, F), ``rut_offset_m`` (draws, 3), ``rut_yaw_rad`` (draws,)) and worst angle
        errors per set for sensitivity analysis: ``<case>_deg`` (draws, P), ``pairs`` (P, 2),
        ``delay_s``, ``range_offset_m`` (draws, P), ``subbin_steps`` (draws,) (the target's
        sub-bin offset in delay steps; zeros at the bin centre)."""
        arrays = dict(self.errors)
        arrays["subbin_steps"] = (np.zeros(self.draws, int) if self.subbin_steps is None
                                  else np.asarray(self.subbin_steps))
        arrays.update({f"{case}_deg": v[..., 0] for case, v in self.errors_deg.items()})
        arrays.update(pairs=np.array([s.front_ends for s in self.model.sets]),
                      delay_s=self.delay_s, range_offset_m=self.range_offset_m,
                      spec_deg=np.float64(self.spec_deg))
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(path.name + ".part")
        with open(tmp, "wb") as fh:
            np.savez_compressed(fh, **arrays)
        tmp.replace(path)


def _study(model) -> ToleranceModel:
    return ToleranceModel.of(model) if isinstance(model, ChannelPhasors) else model


def _evaluate(model, part: DrawChunk, bounds: Bounds, cases, keep: bool) -> dict:
    errors = part.errors(bounds)
    out = {"sets": _study(model).evaluate(errors, cases), "subbin": errors["subbin"],
           "k": part.k}
    if keep:
        out["errors"] = errors
    return out


def monte_carlo(model, bounds, draws: int, seed: int, distribution: str = "normal",
                spec_deg: float = 0.1, cases=CASES, **options) -> ToleranceResult:
    """``draws`` setups of ``model`` drawn from ``seed``: :func:`simulate` with a
    :class:`~.config.MonteCarlo` of these.

    Parameters
    ----------
    model : ToleranceModel or ChannelPhasors
        The channel sets (one alone: a pair's or a cell's study).
    bounds : Bounds or array_like of 3 float
        The error scales (SI), or the three offsets' scales (m) alone.
    draws, seed, distribution
        As :class:`~.config.MonteCarlo`.
    spec_deg : float
        The angle spec of the yield (deg).
    cases : tuple of str
        The cases evaluated (``uncalibrated``, ``calibrated``, ...).
    **options
        :class:`~.config.MonteCarlo`'s ``chunk``, ``mapper``, ``progress``, ``subbin``, and
        :func:`simulate`'s ``label``, ``keep_errors``.

    Returns
    -------
    ToleranceResult

    Raises
    ------
    ParameterError
        A draw count, seed, distribution or scale outside its range.
    """
    mc, rest = MonteCarlo.split(dict(options, draws=int(draws), seed=int(seed),
                                     distribution=distribution))
    return simulate(model, bounds, mc, spec_deg, cases, **rest)


def simulate(model, bounds, mc: MonteCarlo, spec_deg: float = 0.1, cases=CASES,
             label: str = "tolerance", keep_errors: bool = False) -> ToleranceResult:
    """The one Monte-Carlo driver: ``mc.draws`` setups of ``model`` (a
    :class:`ToleranceModel`, or one :class:`~.phasors.ChannelPhasors` alone) with errors of
    scale ``bounds`` (:class:`Bounds`, or the three offsets' scales (3,) m: the standard
    deviation, or the uniform bound) and, with ``mc.subbin``, the target at a sub-bin
    position drawn per draw (False: at the bin centre), evaluated chunk by chunk: in this
    process, one chunk in memory at a time, or by ``mc.mapper(func, chunks)`` (results in
    chunk order). ``keep_errors``: the per-draw errors in the result
    (:meth:`ToleranceResult.save_npz`). ``mc.seed`` must be set (:meth:`MonteCarlo.seeded`).

    Returns
    -------
    ToleranceResult
    """
    if mc.seed is None:
        raise ParameterError("simulate: MonteCarlo.seed is None (give a seed, or "
                             "mc.seeded(scene.seed))")
    draws, seed, distribution = mc.draws, mc.seed, mc.distribution
    chunk, progress, mapper, subbin = mc.chunk, mc.progress, mc.mapper, mc.subbin
    t0, c0 = time.perf_counter(), time.process_time()
    shared = model  # what a process pool keeps across the studies of one model (by identity)
    model = _study(model)
    bounds = as_bounds(bounds)
    bounds.check()
    positions = model.subbin_steps
    streams = DrawStreams(
        positions=positions.size if subbin else None,
        centre=int(np.flatnonzero(positions == 0)[0]) if positions.size else 0,
        rotations=bounds.rotations, rut=bounds.rut_pose)
    chunks = draw_chunks(seed, draws, model.count, distribution, chunk, streams)
    func = functools.partial(_evaluate, shared, bounds=bounds, cases=tuple(cases),
                             keep=keep_errors)
    parts, done = [], 0
    for part in (map(func, chunks) if mapper is None else mapper(func, list(chunks))):
        parts.append(part)
        done += part["k"]
        if progress:
            progress(label, done, draws)
    n_p = len(model.sets)

    def joined(p, key, shape):
        if not parts:
            return np.zeros(shape)
        return np.concatenate([pt["sets"][p][key] for pt in parts])

    errors_deg = {case: frozen(np.stack([joined(p, case, (0, len(model.sets[p].columns)))
                                         for p in range(n_p)], 1)) for case in cases}
    steps = tuple(frozen(joined(p, "steps", (0, len(model.columns[p])))) for p in range(n_p))
    offsets = tuple(frozen(joined(p, "range_offset_m", (0, len(model.columns[p]))))
                    for p in range(n_p))
    counts = {suffix: {case: np.array([sum(pt["sets"][p][case + suffix] for pt in parts)
                                       for p in range(n_p)]) for case in cases}
              for suffix in ("_fallbacks", "_off_bin")}
    sub = None
    if subbin:
        idx = (np.concatenate([pt["subbin"] for pt in parts]) if parts else np.zeros(0, int))
        sub = frozen(positions[idx.astype(int)])
    kept = {}
    if keep_errors and parts:
        for key in ("offsets_m", "yaw_rad", "pitch_rad", "rut_offset_m", "rut_yaw_rad"):
            vals = [pt["errors"][key] for pt in parts]
            if vals[0] is None:
                shape = {"offsets_m": (model.count, 3), "yaw_rad": (model.count,),
                         "pitch_rad": (model.count,), "rut_offset_m": (3,),
                         "rut_yaw_rad": ()}[key]
                kept[key] = np.zeros((draws,) + shape)
            else:
                kept[key] = np.concatenate(vals)
    return ToleranceResult(model, bounds, distribution, int(draws), int(seed), float(spec_deg),
                           errors_deg, steps, offsets, counts["_fallbacks"], counts["_off_bin"],
                           sub, kept, time.perf_counter() - t0, time.process_time() - c0)
