"""Mounting-tolerance Monte Carlo of a 2-D cell of front ends (issue 15: the tolerance study
for a cell of Q = 3 or 4 front ends on a sphere, a RuT beamforming in azimuth and elevation;
the pair study, :mod:`rtsgeom.analysis.tolerance.driver`, is the arc's).

Each draw moves every front end of the cell radially, tangentially and in height (the pair
study's unit draws, :func:`~rtsgeom.analysis.tolerance.driver.standard_draws` with ``front_ends=Q``,
scaled by the per-axis sigmas or bounds). The operator does not know the errors: the channel
weights of set directions over the cell (an n x n azimuth x elevation grid inside it,
:func:`~rtsgeom.analysis.linearity2d.cell_grid`) are designed once on the nominal setup
(:meth:`ChannelModel.solve <rtsgeom.synthesis.model.ChannelModel.solve>`, ``exact``: peak matching on
the modelled 2-D beamformer output), for the channel phases the cell's calibration
establishes (:func:`~rtsgeom.calibration.channels.tree_phases`: each measured pair of the spanning tree
coherent at the midpoint of its front ends' directions).

The target sits at a sub-bin position drawn per draw (uniform over one range bin in steps of
the RTS delay resolution, :func:`~rtsgeom.analysis.tolerance.subbin.subbin_positions`, the pair study's
stream :func:`~rtsgeom.analysis.tolerance.driver.subbin_draws`; ``subbin=False``: the bin centre), and
the RuT picks the range bin: a draw at phasor level is, as in
``PairPhasors.draw_errors`` (eq. 15/16 with the exact legs, :meth:`ChannelModel.perturbed`)::

    x_qkv(draw) = table[q, u + k_q, k, v] * (x_qv(draw) / x_qv(nominal))
                  * exp(s_qkv(u + k_q) d_qv)

with ``table[q, D, k, v]`` channel q's spectrum at candidate bin k (the set range's and
``HALF_BINS`` either side) with its RTS delay offset by D steps
(``tolerance_model.response_table``, through the ADC-cube chain's ``rts.channel_echoes``),
``u`` the sub-bin position and ``k_q`` the channel's calibration delay (steps), and ``s`` the
table's log-magnitude slope over the delay (the echo slides along the range window by the air
delay change d as by an RTS delay; bounded, ``tolerance_model.slide``). The detected bin is the
strongest candidate of the weighted sum (power over the virtual elements), the snapshot that
bin's. ``uncalibrated``: k = 0 and the nominal amplitudes. ``calibrated``: the cell's
calibration at phasor level: the tree phases of the draw's channels (the pairs' probes at the
nominal directions, probes at a bin centre) as delays by eq. (27) (wrapped to the smallest
|delay|, quantised to the delay resolution, refined on the table's exact phase), the amplitude
calibration (each channel's power over the virtual elements against the model's) and each
channel's known loss from its delay divided out, at the bin the operator's nominal model
detects for that set direction, sub-bin position and delays (the amplitudes are designed once,
at the bin centre: every channel slides alike with the target's position, so the design holds
across the bin up to what the calibration delays move).

With ``bounds`` the front ends' rotations (yaw, pitch) and the RuT's pose errors (position,
yaw) are drawn too (``analysis.arc``'s streams, the offsets unchanged) and enter through
:meth:`ChannelModel.perturbed`.

Not modelled (the pair study has them): a redesign of the amplitudes per sub-bin position and
delay (the pair study's ``_Design``), and the planner's alternative delays one IF period away.
``verify_cell_draws`` pushes draws through the full ADC-cube chain.
"""

from __future__ import annotations

import dataclasses
import functools
import time
from dataclasses import dataclass

import numpy as np
from scipy.constants import c

from ..._lib.util import frozen
from ..linearity2d import cell_grid
from ...calibration.channels import pair_edges, spanning_tree, tree_phases
from ...synthesis.model import ChannelModel
from ...errors import ParameterError
from ...geometry import Setup
from ...geometry.setup import nominal_setup
from ...paths import exact_paths
from ...radar.steering import Steering
from .driver import (AXES, CASES, DEFAULT_CHUNK, draws_header, Mapper, Progress,
                     largest_passing_scale, percentiles, search_direction)
from .arc import Bounds, _scale, arc_draws
from .subbin import centre_index, subbin_positions
from .pair import reference_target, response_table, slide

__all__ = ["CellPhasors", "CellToleranceResult", "ANGLES", "monte_carlo_cell",
           "max_sigma_for_yield_cell", "evaluate_cell_chunk",
           "verify_cell_draws"]

ANGLES = ("azimuth", "elevation", "angular_distance")
STAT_KEYS = ("azimuth_error_deg", "elevation_error_deg", "angular_distance_deg")
REFINE_STEPS = 8  # the calibration delay refined +-this many steps on the table's phase
#: candidate range bins either side of the set range's: an echo lies at most half a bin (its
#: sub-bin position) plus half an IF period of calibration delay (~0.3 bins on sphere4) from
#: the set range's bin centre, so the combined peak is within one bin; one more is compared
HALF_BINS = 2
#: draws per block of :meth:`CellPhasors.draw` (its (n, M, K, V) temporaries bounded)
BLOCK_DRAWS = 500


def _wrap(phi):
    return np.angle(np.exp(1j * np.asarray(phi)))


@dataclass(frozen=True)
class CellPhasors:
    """The design (set directions, amplitudes) and the delay tables of one cell of front ends
    on its nominal :class:`~rtsgeom.synthesis.model.ChannelModel` (``cells``, 2-D beamformer)."""

    cells: ChannelModel  # Q channels, nominal setup, target at the bin centre
    set_rad: np.ndarray  # (M, 2) set (azimuth, elevation)
    set_u: np.ndarray  # (M, 2) their direction cosines
    amplitudes: np.ndarray  # (M, Q) designed |w| (the strongest 1)
    phases: np.ndarray  # (Q,) the nominal calibration's channel phases (the design's)
    tree: tuple  # ((parent, child), ...) front-end indices, the calibration's spanning tree
    delay_factor: np.ndarray  # (Q, 2 S + 1, V) F_q(k), k = -S..S
    delay_log_slope: np.ndarray  # (Q, 2 S + 1, V) Re d ln F / d tau (1/s)
    cal_slope_hz: float  # f_rts + B/2: eq. (27)
    delay_resolution_s: float
    table: np.ndarray  # (Q, D, K, V) channel q's spectrum at candidate bin k, RTS delay
    # offset (j - table_zero) steps (the middle bin: the set range's)
    table_log_slope: np.ndarray  # (Q, D, K, V) d ln|table| / d tau (1/s)
    table_zero: int
    subbin_steps: np.ndarray  # (U,) the target's sub-bin positions (delay steps, 0 centre)

    @classmethod
    def build(cls, setup: Setup, cell=None, grid: int = 5,
              range_m: float | None = None) -> "CellPhasors":
        """Design on the nominal setup of ``setup`` for the cell ``cell`` (front-end indices;
        default all, which must be 3 or 4), ``grid`` x ``grid`` set directions (the points
        inside the cell), the target at the centre of the range bin nearest ``range_m``
        (default the calibration's first probe range)."""
        nom = nominal_setup(setup)
        radar, rts = nom.scene.radar, nom.scene.rts
        if Steering.auto(nom.rut, radar).dims != 2:
            raise ParameterError("tolerance --cell needs a RuT that beamforms in azimuth and "
                                 "elevation (an array with elevation extent, e.g. "
                                 "radar.use_elevation_tx = true)")
        n_fe = nom.fe.count
        cell = tuple(range(n_fe)) if cell is None else tuple(sorted(int(q) for q in cell))
        if len(cell) not in (3, 4) or len(set(cell)) != len(cell) or not all(
                0 <= q < n_fe for q in cell):
            raise ParameterError(f"cell {list(cell)}: must be 3 or 4 distinct front-end indices "
                                 f"in [0, {n_fe - 1}]")
        target = reference_target(nom, range_m)
        paths = exact_paths(nom)
        cs = ChannelModel.build(nom, paths, cell, target,
                                steering=Steering.auto(nom.rut, radar))
        st = cs.steering
        u_fe = cs.fe_directions()
        all_u = nom.fe_direction_cosines()
        tree = tuple(spanning_tree(all_u, pair_edges(all_u, cell), cell[0]))
        phases = tree_phases(cs, tree)
        sets = cell_grid(st, u_fe, int(grid))
        if sets.shape[0] == 0:
            raise ParameterError(f"cell {list(cell)}: no set direction of a {grid} x {grid} "
                                 "grid lies inside it")
        set_u = st.directions(sets)
        amps = np.stack([np.abs(cs.solve(u, phases, "exact")) for u in set_u])
        res = rts.delay_resolution_s
        slope = rts.f_rts_hz + 0.5 * radar.bandwidth_hz
        max_steps = int(np.ceil(0.5 / (slope * res))) + REFINE_STEPS + 1
        sub = subbin_positions(radar.range_resolution_m, res)
        # rows: every sub-bin position plus every calibration delay, one more for the slope
        z = int(np.max(np.abs(sub))) + max_steps + 1
        steps = np.arange(-z, z + 1)
        table = np.stack([response_table(nom, paths, q, target, res, steps, HALF_BINS)
                          for q in cell])  # (Q, D, K, V)
        with np.errstate(divide="ignore"):
            log_slope = np.gradient(np.log(np.abs(table)), res, axis=1)
        ks = slice(z - max_steps, z + max_steps + 1)
        factor = table[:, ks, HALF_BINS] / table[:, z:z + 1, HALF_BINS]  # (Q, 2 S + 1, V)
        return cls(cs, frozen(sets), frozen(set_u), frozen(amps), frozen(phases), tree,
                   frozen(factor), frozen(log_slope[:, ks, HALF_BINS]), float(slope),
                   float(res), frozen(table), frozen(log_slope), z, frozen(sub))

    cell = property(lambda self: tuple(self.cells.channels))
    setup = property(lambda self: self.cells.setup)  # nominal
    range_m = property(lambda self: self.cells.range_m)
    x_nominal = property(lambda self: self.cells.phasors)  # (Q, V)

    @property
    def max_steps(self) -> int:
        return (self.delay_factor.shape[1] - 1) // 2

    @property
    def subbin_zero(self) -> int:
        """Index of the bin centre in :attr:`subbin_steps`."""
        return centre_index(self.subbin_steps)

    # -- one draw ---------------------------------------------------------------------------

    def calibration_steps(self, xq: np.ndarray) -> np.ndarray:
        """The cell's calibration in delay steps (..., Q) (the reference channel 0) for the
        channels' phasors (..., Q, V): the tree phases (:func:`tree_phases`) as delays by
        eq. (27), wrapped to the smallest |delay|, quantised, refined on the table's phase."""
        psi = tree_phases(self.cells, self.tree, xq)  # (..., Q)
        mask = self.cells.steering.mask
        table_phase = np.angle(self.delay_factor[..., mask].mean(-1))  # (Q, D)
        s = self.max_steps
        sign = np.sign(np.median(table_phase[:, s + 1]))
        k0 = np.round(_wrap(psi) / (sign * 2 * np.pi * self.cal_slope_hz
                                    * self.delay_resolution_s)).astype(int)
        r = s - REFINE_STEPS - 1
        cand = np.clip(k0[..., None], -r, r) + np.arange(-REFINE_STEPS, REFINE_STEPS + 1)
        q = np.arange(psi.shape[-1])[:, None]
        miss = np.abs(_wrap(psi[..., None] - table_phase[q, cand + s]))
        return np.take_along_axis(cand, np.argmin(miss, -1)[..., None], -1)[..., 0]

    def gain_correction(self, xq: np.ndarray) -> np.ndarray:
        """The amplitude calibration: per channel sqrt(modelled / measured power), (..., Q)."""
        p = np.sum(xq.real ** 2 + xq.imag ** 2, axis=-1)
        x0 = self.x_nominal
        return np.sqrt(np.sum(x0.real ** 2 + x0.imag ** 2, axis=-1) / p)

    def draw(self, offsets_m, cases=CASES, pose: dict | None = None, subbin=None) -> dict:
        """Per case the detected minus set (azimuth, elevation) (n, M, 2) rad, the angular
        distance (n, M) rad, whether the beamformer's Newton peak converged (n, M), the
        detected range bin as an offset from the set range's (n, M) and the programme
        amplitudes (n, M, Q) (relative: times ``cells.unit_gain``), for mounting errors
        ``offsets_m`` (n, Q, 3), ``pose`` (the rotations ``yaw_rad``, ``pitch_rad`` (n, Q) and
        RuT pose errors ``rut_offset_m`` (n, 3), ``rut_yaw_rad`` (n,) of
        :meth:`ChannelModel.air_legs`; None: none) and the target's sub-bin positions
        ``subbin`` (n,) (indices into :attr:`subbin_steps`; None: the bin centre); and the
        calibration steps (n, Q) and the range offset between the channels after calibration
        (n,) m. Blocks of :data:`BLOCK_DRAWS` draws (row by row: the same bits)."""
        off = np.asarray(offsets_m, float)
        n = off.shape[0]
        u = np.full(n, self.subbin_zero) if subbin is None else np.asarray(subbin, int)
        pose = {k: v for k, v in (pose or {}).items() if v is not None}
        for case in cases:
            if case not in CASES:
                raise ValueError(f"case {case!r}: must be one of {', '.join(CASES)}")
        parts = []
        for b in range(0, max(n, 1), BLOCK_DRAWS):
            sl = slice(b, b + BLOCK_DRAWS)
            parts.append(self._draw(off[sl], cases, {k: np.asarray(v)[sl]
                                                     for k, v in pose.items()}, u[sl]))
        if len(parts) == 1:
            return parts[0]

        def join(items):
            first = items[0]
            if isinstance(first, dict):
                return {k: join([i[k] for i in items]) for k in first}
            return np.concatenate(items)

        return join(parts)

    def _draw(self, off, cases, pose, u) -> dict:
        cm, st = self.cells, self.cells.steering
        x, shift = cm.perturbed(off, return_shift=True, **pose)  # (n, Q, V)
        nom = self.x_nominal
        fac = x / np.where(nom != 0, nom, 1.0)  # the draw's factor per channel and element
        steps = self.calibration_steps(x)
        n, n_q = off.shape[0], len(self.cell)
        q = np.arange(n_q)
        d_u = self.subbin_steps[u]  # (n,)
        out = {"steps": steps, "range_offset_m": self._range_offset(off, steps, pose)}
        v_set = _unit_vectors(self.set_u)
        mask = st.mask
        for case in cases:
            cal = case == "calibrated"
            rows = self.table_zero + d_u[:, None] + (steps if cal else 0)  # (n, Q)
            t_nom = self.table[q, rows]  # (n, Q, K, V) the operator's nominal model
            xk = t_nom * fac[:, :, None] * slide(self.table_log_slope[q, rows],
                                                 shift[:, :, None])
            amps = np.broadcast_to(self.amplitudes, (n,) + self.amplitudes.shape)
            if cal:  # the gains measured, each delay's known loss divided out at the bin
                # the operator's nominal model detects (target at its sub-bin position)
                t_pos = self.table[q, self.table_zero + d_u[:, None]]  # delays at 0
                k_plan = _detected_bin(np.einsum("nmq,nqkv->nmkv", amps, t_nom))  # (n, M)
                pick = k_plan[:, :, None, None]
                f_d = np.take_along_axis(t_nom[..., mask].mean(-1)[:, None], pick, -1)[..., 0]
                f_0 = np.take_along_axis(t_pos[..., mask].mean(-1)[:, None], pick, -1)[..., 0]
                loss = np.abs(f_d) / np.maximum(np.abs(f_0), 1e-300)  # (n, M, Q)
                amps = amps * self.gain_correction(x)[:, None, :] / loss
            y = np.einsum("nmq,nqkv->nmkv", amps, xk)  # (n, M, K, V)
            det = _detected_bin(y)  # (n, M): the RuT's bin
            snaps = np.take_along_axis(y, det[:, :, None, None], 2)[:, :, 0]  # (n, M, V)
            uu, ok = st.peak(snaps, self.set_u)
            ang = st.angles(uu)
            dist = 2 * np.arcsin(np.clip(np.linalg.norm(_unit_vectors(uu) - v_set, axis=-1) / 2,
                                         0.0, 1.0))
            out[case] = {"error_rad": ang - self.set_rad, "distance_rad": dist,
                         "converged": ok, "bin": det - HALF_BINS, "amplitudes": amps}
        return out

    def _range_offset(self, off, steps, pose=None) -> np.ndarray:
        """The largest range offset (m) between a channel's echo and the reference's after
        calibration: c0/2 times the element-mean air delay plus the delay offset, (n,)."""
        t_a, t_b = self.cells.air_legs(off, **(pose or {}))
        tot = (t_a + t_b).mean(-1) + steps * self.delay_resolution_s  # (n, Q)
        return 0.5 * c * np.max(np.abs(tot - tot[:, :1]), axis=-1)

    def to_dict(self) -> dict:
        k = self.calibration_steps(self.x_nominal)
        fe = self.cells.steering.angles(self.cells.fe_directions())
        return {
            "cell": list(self.cell),
            "range_m": self.range_m,
            "front_end_directions_deg": [[float(a) for a in np.degrees(d)] for d in fe],
            "set_points": int(self.set_rad.shape[0]),
            "set_directions_deg": [[float(a) for a in np.degrees(d)] for d in self.set_rad],
            "spanning_tree": [list(e) for e in self.tree],
            "nominal_delta_tau_s": [float(x) * self.delay_resolution_s for x in k],
            "delay_resolution_s": self.delay_resolution_s,
        }


def _detected_bin(y) -> np.ndarray:
    """The RuT's range bin of spectra ``y`` (..., K, V): the strongest candidate, the power
    summed over the virtual elements (as ``PairPhasors.draw_errors`` picks it), (...,)."""
    return np.argmax(np.sum(y.real ** 2 + y.imag ** 2, -1), -1)


def _unit_vectors(u) -> np.ndarray:
    """Unit direction vectors (..., 3) of direction cosines (..., 2) (the front hemisphere)."""
    u = np.asarray(u, float)
    w = np.sqrt(np.clip(1.0 - np.sum(u ** 2, axis=-1), 0.0, None))
    return np.concatenate([u, w[..., None]], axis=-1)


def evaluate_cell_chunk(model: CellPhasors, offsets_m: np.ndarray, cases=CASES,
                        pose: dict | None = None, subbin=None) -> dict:
    """Per draw of ``offsets_m`` (k, Q, 3), per case: the signed azimuth and elevation errors of
    the worst set-point in each (the largest |error|), the largest angular distance (deg),
    (k, 3), the count of peaks Newton left unconverged and of set-points detected off the set
    range's bin; the calibration steps (k, Q) and range offsets (k,). ``pose``, ``subbin``:
    :meth:`CellPhasors.draw`'s. Pure: the same offsets give the same bits."""
    d = model.draw(offsets_m, cases, pose, subbin)
    out = {"steps": d["steps"], "range_offset_m": d["range_offset_m"]}
    for case in cases:
        e = np.degrees(d[case]["error_rad"])  # (k, M, 2)
        k = np.argmax(np.abs(e), axis=1)  # (k, 2)
        worst = np.take_along_axis(e, k[:, None, :], axis=1)[:, 0]
        out[case] = np.column_stack([worst, np.degrees(d[case]["distance_rad"].max(-1))])
        out[case + "_fallbacks"] = int(np.count_nonzero(~d[case]["converged"]))
        out[case + "_off_bin"] = int(np.count_nonzero(d[case]["bin"]))
    return out


@dataclass(frozen=True)
class CellToleranceResult:
    """A cell's Monte-Carlo run: per draw and case the worst signed azimuth and elevation
    errors and the worst angular distance (deg), (draws, 3)."""

    model: CellPhasors
    sigma_m: np.ndarray  # (3,) radial, tangential, height
    distribution: str
    draws: int
    seed: int
    spec_deg: float
    worst_error_deg: dict  # case -> (draws, 3): azimuth, elevation, angular distance
    delay_s: np.ndarray  # (draws, Q) calibration delay offsets (reference: 0)
    range_offset_m: np.ndarray  # (draws,) largest range offset between the channels
    fallbacks: dict
    elapsed_s: float = 0.0
    cpu_s: float = 0.0
    bounds: Bounds | None = None  # with the rotations and RuT pose errors drawn
    subbin_steps: np.ndarray | None = None  # (draws,) the target's sub-bin offset (delay
    # steps); None: at the bin centre
    off_bin: dict | None = None  # case -> set-points detected off the set range's bin

    def yield_(self, case: str) -> float:
        """Fraction of draws whose every set-point is within the spec in both angles."""
        e = self.worst_error_deg[case]
        if not e.size:
            return float("nan")
        return float(np.mean(np.all(np.abs(e[:, :2]) <= self.spec_deg, axis=-1)))

    def stats(self, case: str) -> dict:
        e = np.abs(self.worst_error_deg[case])
        out = {key: percentiles(e[:, k]) for k, key in enumerate(STAT_KEYS)}
        out["angle_error_deg"] = percentiles(np.max(e[:, :2], axis=-1))
        out.update({"yield": self.yield_(case), "fallbacks": self.fallbacks[case]})
        if self.off_bin is not None:
            out["detected_off_bin"] = self.off_bin[case]
        return out

    def to_dict(self) -> dict:
        out = {
            **draws_header(self.draws, self.seed, self.distribution, self.sigma_m,
                           self.spec_deg),
            "bounds": None if self.bounds is None else self.bounds.to_dict(),
            "yield_rule": "every set-point within spec_deg in azimuth and in elevation",
            "cell": self.model.to_dict(),
            "subbin": {"distribution": ("uniform over one range bin"
                                        if self.subbin_steps is not None else "bin centre"),
                       "positions": (int(self.model.subbin_steps.size)
                                     if self.subbin_steps is not None else 1),
                       "step_s": self.model.delay_resolution_s},
        }
        for case in self.worst_error_deg:
            out[case] = self.stats(case)
        out["calibration"] = {
            "abs_delta_tau_ps": percentiles(np.abs(self.delay_s[:, 1:]), 1e12),
            "abs_range_offset_mm": percentiles(self.range_offset_m, 1e3),
        }
        return out


def _evaluate(model: CellPhasors, part: dict, cases) -> dict:
    pose = {k: part[k] for k in ("yaw_rad", "pitch_rad", "rut_offset_m", "rut_yaw_rad")}
    out = evaluate_cell_chunk(model, part["offsets_m"], cases, pose, part.get("subbin"))
    out["subbin"] = part.get("subbin")
    return out


def monte_carlo_cell(model: CellPhasors, sigma_m, draws: int, seed: int,
                     distribution: str = "normal", spec_deg: float = 0.1, cases=CASES,
                     chunk: int = DEFAULT_CHUNK, progress: Progress | None = None,
                     label: str = "tolerance", mapper: Mapper | None = None,
                     bounds: Bounds | None = None, subbin: bool = True) -> CellToleranceResult:
    """``draws`` setups of the cell with mounting errors scaled by ``sigma_m`` (3,) (the pair
    study's :func:`~rtsgeom.analysis.tolerance.driver.monte_carlo` for a cell: the same unit draws
    per front end, chunked, optionally mapped; the outcome depends on neither). ``bounds``:
    also the front ends' rotations and the RuT's pose errors (``analysis.arc``'s draws, their
    own streams; its offsets are replaced by ``sigma_m``): the offsets stay the same draws.
    ``subbin``: the target at a sub-bin position drawn per draw (the pair study's stream,
    :func:`~rtsgeom.analysis.tolerance.driver.subbin_draws`); False: at the bin centre."""
    t0, c0 = time.perf_counter(), time.process_time()
    sigma = np.asarray(sigma_m, float).reshape(3)
    if np.any(~np.isfinite(sigma)) or np.any(sigma < 0):
        raise ValueError(f"sigma_m {sigma.tolist()}: must be finite and >= 0")
    n_q = len(model.cell)
    b = dataclasses.replace(bounds or Bounds((0.0, 0.0, 0.0)), offsets_m=tuple(sigma))
    positions = model.subbin_steps.size if subbin else None

    def scaled(unit):
        return {**_scale(unit, b), "subbin": unit.get("subbin")}

    chunks = (scaled(u) for u in arc_draws(seed, draws, n_q, distribution, chunk, positions))
    func = functools.partial(_evaluate, model, cases=tuple(cases))
    parts, done = [], 0
    for part in (map(func, chunks) if mapper is None else mapper(func, list(chunks))):
        parts.append(part)
        done += len(part["steps"])
        if progress:
            progress(label, done, draws)

    def joined(key, shape):
        return frozen(np.concatenate([p[key] for p in parts]) if parts else np.zeros(shape))

    return CellToleranceResult(
        model, frozen(sigma), distribution, int(draws), int(seed), float(spec_deg),
        {case: joined(case, (0, 3)) for case in cases},
        frozen(joined("steps", (0, n_q)) * model.delay_resolution_s),
        joined("range_offset_m", (0,)),
        {case: sum(p[case + "_fallbacks"] for p in parts) for case in cases},
        time.perf_counter() - t0, time.process_time() - c0, b,
        frozen(model.subbin_steps[joined("subbin", (0,)).astype(int)]) if subbin else None,
        {case: sum(p[case + "_off_bin"] for p in parts) for case in cases})


def max_sigma_for_yield_cell(model: CellPhasors, sigma_m, draws: int, seed: int,
                             target_yield: float, spec_deg: float = 0.1,
                             case: str = "calibrated", axis: str = "all",
                             distribution: str = "normal", rel_tol: float = 0.01,
                             cap_m: float = 0.01, chunk: int = DEFAULT_CHUNK,
                             progress: Progress | None = None,
                             mapper: Mapper | None = None, subbin: bool = True) -> dict:
    """The pair study's ``max_sigma_for_yield`` for a cell (the same search,
    :func:`~rtsgeom.analysis.tolerance.driver.largest_passing_scale`, the same keys; ``subbin``:
    :func:`monte_carlo_cell`'s, the same positions at every scale)."""
    base = np.asarray(sigma_m, float).reshape(3)
    direction, fixed = search_direction(base, axis)
    history = []

    def yield_at(t: float) -> float:
        res = monte_carlo_cell(model, fixed + t * direction, draws, seed, distribution,
                               spec_deg, (case,), chunk, progress,
                               f"{case}: sigma {t * 1e3:.4g} mm", mapper, subbin=subbin)
        y = res.yield_(case)
        history.append({"scale_mm": t * 1e3, "yield": y})
        return y

    def result(t, y, capped=False, note=None):
        sig = fixed + t * direction
        return {"case": case, "axis": axis, "target_yield": target_yield, "spec_deg": spec_deg,
                "sigma_mm": {a: float(s * 1e3) for a, s in zip(AXES, sig)},
                "yield": y, "capped": capped, "note": note, "evaluations": history}

    y0 = yield_at(0.0)
    if y0 < target_yield:
        return result(0.0, y0, note="the setup misses the spec even without the varied errors")
    start = min(float(np.max(base * direction)) or 1e-4, cap_m)
    return result(*largest_passing_scale(yield_at, y0, target_yield, start, cap_m, rel_tol))


# the full-chain check lives in its own module (size); re-exported here, where it was
from .verify_cell import verify_cell_draws
