"""The phase calibration's delay sweep (paper section "Calibration", eq. 27): one engine for
every pair, on an arc or in a 2-D beamformer, on the phasor model or the full chain.

Channel I keeps its delay, channel J's RTS delay is swept by Delta tau_rts over at least one
period ``1 / (f_rts + B/2)`` (eq. 27; paper: [-0.5, 1] ns in 25 ps steps) while two probe
targets synthesized by the pair are detected; the coherence point is where their errors are
jointly smallest:

1. coarse sweep over the span (``SweepConfig.span_s`` / ``step_s``, default the scene's
   ``calibration_span_ns`` / ``calibration_step_ps``): the RMS minimum nearest zero delay
   (``fit.coarse_minimum``);
2. the probes placed for the fine window: within their range bins, so that the bin the RuT
   detects each in keeps a power margin over its neighbours (``probes.place_in_bins``);
3. fine sweep over +-period/4 around it in steps the RTS can set; the coherence point is the
   common centre of symmetry of its signed error curves (``fit.fit_centre``);
4. the frames per step sized so that the noise moves the fitted minimum by less than
   ``steps.TARGET_BIAS_PS`` (2 sigma): predicted before the sweep where the probes have a
   model of their noise (the phasor model), measured on the sweep's own residual where not
   (the full chain of a 2-D pair);
5. the fitted optimum rounded to a delay the RTS can set and confirmed through the full
   ADC-cube chain.

What is measured is the probes' business (``phasor.PhasorProbes``, ``beam.BeamProbes``):
``measure(deltas, frames) -> signed errors (S, C)``, their placement, their noise, which
columns are odd about the coherence point, what each step adds beyond its offset and the
phase mismatch the coherence point zeroes (:func:`coherence_point`).
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from scipy.constants import c

from .._lib.results import Result
from .._lib.util import frozen
from ..errors import CalibrationFailed, ParameterError
from .fit import (CentreFit, coarse_minimum, continuous_steps, fit_centre, fit_scatter,
                  rms_error_deg)
from .probes import mean_air_delay
from .steps import coarse_frames, continuous_delay_setup, fine_frames, fine_window, realisable

__all__ = ["SweepConfig", "Calibration", "CoherencePoint", "Probes", "run_sweep",
           "coherence_point"]


@dataclass(frozen=True)
class SweepConfig:
    """How the delay sweep runs.

    Attributes
    ----------
    span_s, step_s : tuple of float, float or None
        The coarse sweep's span (s, s) and step (s); None: the scene's
        ``rts.calibration_span_ns`` and ``rts.calibration_step_ps``.
    frames : int or None
        Frames coherently averaged per step; None: as many as the noise needs.
    full_chain : bool
        Evaluate every step through the ADC-cube chain instead of the phasor model (a pair on
        an arc; a pair in a 2-D beamformer is always measured through the chain).
    seed : int
        The receiver noise's seed.
    """

    span_s: tuple[float, float] | None = None
    step_s: float | None = None
    frames: int | None = None
    full_chain: bool = False
    seed: int = 0

    def __post_init__(self):
        if self.span_s is not None:
            span = (tuple(self.span_s) if isinstance(self.span_s, (tuple, list, np.ndarray))
                    else ())
            if not (len(span) == 2 and all(_real(x) for x in span)
                    and math.isfinite(span[0]) and math.isfinite(span[1])
                    and span[0] < span[1]):
                raise ParameterError(f"span_s: must be two finite delays, low < high; got "
                                     f"{self.span_s}")
            object.__setattr__(self, "span_s", (float(span[0]), float(span[1])))
        if self.step_s is not None and not (_real(self.step_s) and math.isfinite(self.step_s)
                                            and self.step_s > 0):
            raise ParameterError(f"step_s: must be a positive delay (s); got {self.step_s}")
        f = self.frames
        if f is not None:
            if not (_real(f) and math.isfinite(f) and f == int(f) and f >= 1):
                raise ParameterError(f"frames: must be a whole number >= 1; got {f}")
            object.__setattr__(self, "frames", int(f))

    def evolve(self, **changes) -> "SweepConfig":
        """A copy with ``changes`` (unknown names: :class:`ParameterError`)."""
        unknown = set(changes) - {f.name for f in dataclasses.fields(self)}
        if unknown:
            raise ParameterError(f"{sorted(unknown)}: not a sweep setting; allowed: "
                                 f"{[f.name for f in dataclasses.fields(self)]}")
        return dataclasses.replace(self, **changes)


def _real(x) -> bool:
    """A real number (numpy's included), not a bool."""
    return isinstance(x, numbers.Real) and not isinstance(x, (bool, np.bool_))


class Probes(Protocol):
    """What a sweep measures with (module doc)."""

    setup: object
    pair: tuple[int, int]
    base_offsets: tuple[float, float]
    period_s: float
    ranges: np.ndarray
    seed: int
    noisy: bool
    method: str
    dims: int
    predicts_noise: bool
    fine_step_s: float

    def measure(self, deltas, frames: int = 1, repeat: int = 0) -> np.ndarray: ...
    def frame_noise_deg(self, grid) -> float | None: ...
    def placed(self, window_s) -> "Probes": ...
    def fit_columns(self, e) -> tuple[np.ndarray, np.ndarray]: ...
    reference: object  # (phase_rad) -> Probes on the nominal setup, or None: no offset taken
    def sweep_phase(self, deltas): ...
    def confirm(self, delta_s: float, frames: int) -> float: ...
    def phase(self, continuous, delta_s: float) -> float: ...


@dataclass(frozen=True, repr=False)
class Calibration(Result):
    """The phase calibration of a pair (I, J): channel J's delay offset relative to I.

    ``print(cal)`` is a summary; ``to_dataframe()`` the sweep (one row per evaluated delay:
    ``stage`` coarse or fine, ``delta_tau_ps``, ``angle_error_deg``); ``plot()`` the figure
    of ``rtsgeom calibrate --out``.

    Attributes
    ----------
    pair : tuple of int
    delta_tau_s : float
        The delay offset of channel J (eq. 27's coherence point).
    residual_error_deg : float
    range_offset_m : float
    period_s : float
    sweep_delta_tau_s, sweep_error_deg : arrays
        The coarse sweep.
    """

    pair: tuple[int, int]
    delta_tau_s: float  # delay offset of J relative to I (what the RTS can set)
    residual_error_deg: float  # RMS probe error at delta_tau_s, through the full chain
    range_offset_m: float  # c0 / 2 x the two channels' total delay mismatch
    sweep_delta_tau_s: np.ndarray
    sweep_error_deg: np.ndarray
    refine_delta_tau_s: np.ndarray
    refine_error_deg: np.ndarray
    probe_angles_deg: tuple  # per probe: its angle (D = 1) or (azimuth, elevation) (D = 2)
    period_s: float  # exact: 1 / (f_rts + S t_mid - S tau) at the probes (eq. 27 refined)
    frames_per_step: int = 1  # frames averaged (coherently) per fine-sweep step
    frame_noise_deg: float = 0.0  # 1-sigma probe noise of one frame (deg)
    method: str = "phasor"  # what evaluated the sweep: phasor model or full-chain
    probe_ranges_m: tuple = ()  # the probes' set ranges (placed within a bin)
    one_frame_scatter_ps: float = 0.0  # 1-sigma of the fitted delay with one frame per step
    # the fitted optimum minus delta_tau_s, which is quantised to what the RTS can set
    # (rts.delay_resolution_s); |residual| <= resolution / 2
    quantisation_residual_s: float = 0.0
    delay_resolution_s: float = 0.0  # the RTS's delay step the chosen delay is a multiple of
    coarse_frames_per_step: int = 1  # frames averaged per coarse-sweep step
    coarse_minimum_s: float = float("nan")  # the coarse sweep's minimum
    fit_columns: tuple = ()  # the columns (probe x axis) the fit used
    odd_columns: tuple = ()  # those of them odd about the coherence point
    dims: int = 1  # the beamformer's dimensions the probes were detected in

    @property
    def fit_s(self) -> float:
        """The fitted optimum before rounding to a realisable delay."""
        return self.delta_tau_s + self.quantisation_residual_s

    def _summary(self):
        return (f"pair {tuple(self.pair)} phase calibration ({self.method}, {self.dims}-D)", [
            ("delta_tau", f"{self.delta_tau_s * 1e12:.2f} ps (fit {self.fit_s * 1e12:.2f} ps, "
                          f"{self.delay_resolution_s * 1e12:g} ps steps)"),
            ("residual_error", f"{self.residual_error_deg:.4g} deg"),
            ("range_offset", f"{self.range_offset_m * 1e3:.3g} mm"),
            ("period", f"{self.period_s * 1e12:.1f} ps (eq. 27)"),
            ("sweep", f"{self.sweep_delta_tau_s.size} coarse + {self.refine_delta_tau_s.size} "
                      f"fine steps, {self.frames_per_step} frame(s) a fine step"),
            ("frame_noise", f"{self.frame_noise_deg:.3g} deg (1 sigma, one frame)"),
            ("one_frame_scatter", f"{self.one_frame_scatter_ps:.3g} ps"),
            ("probe_angles_deg", self.probe_angles_deg)])

    def _columns(self) -> dict:
        n, m = self.sweep_delta_tau_s.size, self.refine_delta_tau_s.size
        return {"stage": ["coarse"] * n + ["fine"] * m,
                "delta_tau_ps": 1e12 * np.r_[self.sweep_delta_tau_s, self.refine_delta_tau_s],
                "angle_error_deg": np.r_[np.ravel(self.sweep_error_deg),
                                         np.ravel(self.refine_error_deg)]}

    def plot(self, title: str = ""):
        """The angle error over the swept delay, the chosen delay and its residual."""
        from ..viz.figures import calibration_sweep_figure  # matplotlib: only for the figure
        return calibration_sweep_figure(
            self.sweep_delta_tau_s, self.sweep_error_deg, self.delta_tau_s, self.period_s,
            title or f"Phase calibration, pair {tuple(self.pair)}",
            residual_error_deg=self.residual_error_deg,
            refine_delta_tau_s=self.refine_delta_tau_s, refine_error_deg=self.refine_error_deg)

    def to_dict(self) -> dict:
        """The calibration as JSON values (a value that is not finite, e.g. a residual where
        the chain detected no probe, as null)."""
        def num(x):
            return float(x) if np.isfinite(x) else None

        def pts(t, e):
            return [{"delta_tau_s": float(a), "angle_error_deg": num(b)} for a, b in zip(t, e)]
        return {
            "pair": list(self.pair),
            "delta_tau_s": self.delta_tau_s,
            "residual_error_deg": num(self.residual_error_deg),
            "range_offset_m": self.range_offset_m,
            "period_s": num(self.period_s),
            "frames_per_step": self.frames_per_step,
            "frame_noise_deg": num(self.frame_noise_deg),
            "method": self.method,
            "probe_ranges_m": list(self.probe_ranges_m),
            "one_frame_scatter_ps": num(self.one_frame_scatter_ps),
            "quantisation_residual_s": self.quantisation_residual_s,
            "delay_resolution_s": self.delay_resolution_s,
            "coarse_frames_per_step": self.coarse_frames_per_step,
            "coarse_minimum_s": num(self.coarse_minimum_s),
            "fit_s": self.fit_s,
            "fit_columns": list(self.fit_columns),
            "odd_columns": list(self.odd_columns),
            "dims": self.dims,
            "points": int(self.sweep_delta_tau_s.size + self.refine_delta_tau_s.size + 1),
            "probe_angles_deg": [list(a) if isinstance(a, tuple) else a
                                 for a in self.probe_angles_deg],
            "sweep": pts(self.sweep_delta_tau_s, self.sweep_error_deg),
            "refinement": pts(self.refine_delta_tau_s, self.refine_error_deg),
        }

    @classmethod
    def from_dict(cls, d: dict) -> "Calibration":
        """Inverse of :meth:`to_dict` (a calibration file written by ``rtsgeom calibrate``)."""
        def arr(key, field):
            return frozen(np.array([np.nan if p[field] is None else p[field]
                                    for p in d.get(key, [])], float))
        def num(key, default):
            v = d.get(key, default)
            return np.nan if v is None else float(v)
        angles = tuple(tuple(float(x) for x in a) if isinstance(a, (list, tuple)) else float(a)
                       for a in d.get("probe_angles_deg", (np.nan, np.nan)))
        return cls((int(d["pair"][0]), int(d["pair"][1])), float(d["delta_tau_s"]),
                   num("residual_error_deg", np.nan), float(d.get("range_offset_m", 0.0)),
                   arr("sweep", "delta_tau_s"), arr("sweep", "angle_error_deg"),
                   arr("refinement", "delta_tau_s"), arr("refinement", "angle_error_deg"),
                   angles, num("period_s", np.nan), int(d.get("frames_per_step", 1)),
                   num("frame_noise_deg", 0.0), str(d.get("method", "phasor")),
                   tuple(d.get("probe_ranges_m", ())), num("one_frame_scatter_ps", 0.0),
                   float(d.get("quantisation_residual_s", 0.0)),
                   float(d.get("delay_resolution_s", 0.0)),
                   int(d.get("coarse_frames_per_step", 1)),
                   num("coarse_minimum_s", np.nan),
                   tuple(int(q) for q in d.get("fit_columns", ())),
                   tuple(int(q) for q in d.get("odd_columns", ())), int(d.get("dims", 1)))


RECENTRE_S = 10e-12  # a fit this far from the fine sweep's centre is measured again around it


class _FineSweep:
    """The fine sweep's delays around ``centre`` and the fit of its errors."""

    def __init__(self, probes, centre: float, steps, period: float):
        self.t = centre + np.arange(-steps.steps, steps.steps + 1) * steps.step_s
        self.centre, self.period, self.steps = centre, period, steps
        self.extra, self.search_phase = probes.sweep_phase(self.t)

    def fit(self, e, columns, selected: bool = False):
        """(coherence point, fitted curves) of the errors ``e`` (S, C) on ``columns`` (the
        indices, and which of them are odd: ``probes.fit_columns``; ``fit.fit_centre``);
        ``selected``: ``e`` holds those columns only."""
        cols, odd = columns
        e = np.asarray(e, float) if selected else np.asarray(e, float)[:, cols]
        e = continuous_steps(e, self.t.size // 2)  # one curve: up to a jump either side
        w = self.steps
        extra = None if self.extra is None else np.asarray(self.extra, float)[:, cols]
        search = None if self.search_phase is None else (
            lambda f: np.asarray(self.search_phase(f), float)[:, cols])
        return fit_centre(self.t, e, self.period, self.centre,
                          CentreFit(w.harmonics, max(self.period / 8, w.step_s), odd, extra,
                                    search), return_fit=True)


def run_sweep(probes: Probes, config: SweepConfig = SweepConfig()) -> Calibration:
    """The calibration of ``probes``' pair by the delay sweep (module doc). Raises
    :class:`CalibrationFailed` when no probe is detected at any step."""
    setup = probes.setup
    rts = setup.scene.rts
    res = rts.delay_resolution_s  # every delay the sweep sets and reports is a multiple
    span = config.span_s or rts.calibration_span_s
    step = config.step_s or rts.calibration_step_s
    grid = np.unique(realisable(np.arange(span[0], span[1] + step / 2, step), res))
    period = probes.period_s

    def coarse(frames: int):
        errs = rms_error_deg(probes.measure(grid, frames))
        if not np.any(np.isfinite(errs)):
            raise CalibrationFailed(f"pair {probes.pair}: no probe detected at any step of "
                                    "the sweep")
        return errs, float(realisable(coarse_minimum(grid, errs), res))

    # frames per coarse step from the predicted noise (the link budget's or snr_db's), before
    # the sweep: one frame at NF 50 dB (0.9 deg of probe-angle noise) picked a wrong minimum
    frame_noise = probes.frame_noise_deg(grid) or 0.0  # None: measured on the fine sweep
    k_coarse = int(config.frames) if config.frames is not None else coarse_frames(frame_noise)
    errs, near = coarse(k_coarse)
    if grid.size < 3:  # no sweep to speak of (e.g. only the period asked for)
        return _calibration(probes, grid, errs, grid, errs, near, near, k_coarse, k_coarse,
                            frame_noise, 0.0, (np.zeros(0, int), np.zeros(0, bool)))
    half = period / 4
    # the window's delays as the RTS realises them (a coarse RTS would round them)
    probes = probes.placed(np.unique(realisable(near + np.arange(-half, half + 1e-15, step),
                                                res)))
    # fine steps the RTS can set (an RTS whose delay moves in 25 ps cannot take 5 ps ones)
    steps = fine_window(half, res * max(1, round(probes.fine_step_s / res)))
    fine = _FineSweep(probes, near, steps, period)
    scatter = 0.0  # the fitted point's 1-sigma with one frame a step
    if config.frames is not None or not probes.noisy:
        n_frames = 1 if config.frames is None else int(config.frames)
        e_fine = probes.measure(fine.t, n_frames)
        columns = probes.fit_columns(e_fine)
        if probes.noisy:  # the sweep's own scatter at its frames, referred to one frame
            scatter = (_measured_scatter(probes, fine, e_fine, columns, config)[0]
                       * np.sqrt(n_frames))
    elif probes.predicts_noise:  # the model's own noise sizes the frames, then measure
        columns = probes.fit_columns(None)
        scatter = probes.predicted_scatter(fine.t, k_coarse, lambda e: fine.fit(e, columns))
        n_frames = fine_frames(scatter)
        e_fine = probes.measure(fine.t, n_frames)
    else:  # a one-frame sweep, its residual sizes the frames, then again where needed
        e_fine = probes.measure(fine.t, 1)
        columns = probes.fit_columns(e_fine)
        scatter, noise = _measured_scatter(probes, fine, e_fine, columns, config)
        # the direction-cosine noise taken as the probe-angle noise (du = cos(theta) d theta:
        # exact at broadside, an underestimate by cos(theta) off it)
        frame_noise = float(np.degrees(noise))
        n_frames = fine_frames(scatter)
        redo = n_frames > 1
        if coarse_frames(frame_noise) > k_coarse:  # too noisy to trust its minimum: again
            k_coarse = coarse_frames(frame_noise)
            errs, near_k = coarse(k_coarse)
            redo, near = redo or near_k != near, near_k
        if redo:  # the same columns (a recentred 2-D sweep switching to the along ones jumped)
            fine = _FineSweep(probes, near, steps, period)
            e_fine = probes.measure(fine.t, n_frames)
    best_fit, _ = fine.fit(e_fine, columns)
    if abs(best_fit - fine.centre) > RECENTRE_S:  # measured again, centred on the point: on a
        # window lopsided about it the fit drifts (5 ps at 46 ps off, sphere4's elevation pair,
        # where a noisy coarse minimum was 50 ps from the point); the same columns
        centre = float(realisable(best_fit, res))
        probes = probes.placed(np.unique(realisable(
            centre + np.arange(-half, half + 1e-15, step), res)))
        fine = _FineSweep(probes, centre, steps, period)
        e_fine = probes.measure(fine.t, n_frames)
        best_fit, _ = fine.fit(e_fine, columns)
    if not np.isfinite(best_fit):
        raise CalibrationFailed(f"pair {probes.pair}: the probes were detected at too few "
                                "steps of the fine sweep to fit it")
    if probes.reference is not None:
        best_fit -= _fit_offset(probes, steps, period, fine.centre, best_fit, columns)
    return _calibration(probes, grid, errs, fine.t, rms_error_deg(e_fine), near, best_fit,
                        k_coarse, n_frames, frame_noise, scatter, columns)


def _fit_offset(probes, steps, period: float, centre_s: float, fit_s: float, columns) -> float:
    """The fit's own offset from the coherence point (s): the geometry's (a pair in a 2-D
    beamformer fitted along its line, 14 ps for sphere4's elevation pair; the 86-element
    cascade at 3 m, 9 ps), found by the same fit on the same probes on the nominal setup,
    noiseless, minus the nominal point (:func:`coherence_point`). The reference is set up as
    the measurement was: channel J given the hardware phase that puts its point where the
    measured fit is (where J's echo sits in its range bin shapes the curves: a 90 deg phase
    offset on a front end moved the offset by 23 ps), its fine sweep placed about that point
    as the measured sweep (centred at ``centre_s``) was about the point it found (``fit_s``
    less the offset: placed once without, then with it; the fit moves with the window by 2
    ps)."""
    # the reference's point where the measured one is (channel J's echo at the same delay:
    # where it sits in its range bin shapes the curves): J given the phase that moves it there
    nominal = coherence_point(probes.reference(), 0.0).continuous_s
    ref = probes.reference(2 * np.pi * (fit_s - nominal) / period)
    point = coherence_point(ref, fit_s).continuous_s
    res = probes.setup.scene.rts.delay_resolution_s
    offset = 0.0
    for _ in range(2):
        centre = float(realisable(point + centre_s - (fit_s - offset), res))
        fine = _FineSweep(ref, centre, steps, period)
        got, _ = fine.fit(ref.measure(fine.t, 1), columns)
        if not np.isfinite(got):
            return 0.0
        offset = got - point
    return offset


def _measured_scatter(probes, fine: _FineSweep, e, columns, config) -> tuple[float, float]:
    """The fitted point's one-frame scatter (s) and one frame's noise (rad) from the sweep's
    own residual (``fit.fit_scatter``); where the fit leaves none (a coarse RTS's few
    steps), from a second, independent sweep."""
    cols = columns[0]
    _, fitted = fine.fit(e, columns)
    e = np.asarray(e, float)[:, cols]

    def fit(x):
        return fine.fit(x, columns, selected=True)
    out = fit_scatter(fit, fitted, e, fine.steps.harmonics, config.seed, probes.pair,
                      odd=columns[1])
    if not np.isfinite(out[0]):
        again = probes.measure(fine.t, 1, repeat=1)[:, cols]
        out = fit_scatter(fit, fitted, e, fine.steps.harmonics, config.seed, probes.pair,
                          repeat=again, odd=columns[1])
    if not np.isfinite(out[0]):
        raise CalibrationFailed(f"pair {probes.pair}: the probes were not detected at enough "
                                "steps of the fine sweep to measure its noise")
    return out


def _calibration(probes, grid, errs, fine_t, fine_e, near, best_fit, k_coarse, n_frames,
                 frame_noise, scatter, columns) -> Calibration:
    """The sweep's result: the fitted optimum rounded to a delay the RTS can set, confirmed
    through the full chain."""
    setup = probes.setup
    res = setup.scene.rts.delay_resolution_s
    best = float(realisable(best_fit, res))
    air = mean_air_delay(setup)
    i, j = probes.pair
    b = probes.base_offsets
    range_offset = 0.5 * c * ((air[j] + b[1] + best) - (air[i] + b[0]))
    return Calibration(probes.pair, best, probes.confirm(best, n_frames), float(range_offset),
                       frozen(grid), frozen(errs), frozen(np.asarray(fine_t)),
                       frozen(np.asarray(fine_e)), probes.probe_angles_deg, probes.period_s,
                       int(n_frames), float(frame_noise), probes.method,
                       tuple(float(r) for r in probes.ranges), float(scatter) * 1e12,
                       float(best_fit - best), float(res), int(k_coarse), float(near),
                       tuple(int(q) for q in columns[0]),
                       tuple(int(q) for q, o in zip(*columns) if o), int(probes.dims))


@dataclass(frozen=True)
class CoherencePoint:
    """The pair's phase-coherence point on the continuous delay model and the delay the RTS
    can set nearest it (``steps.realisable``)."""

    continuous_s: float  # the coherence point (continuous delay offset of channel J)
    delta_tau_s: float  # the nearest realisable offset: a whole number of resolution steps
    quantisation_residual_s: float  # continuous_s - delta_tau_s, |.| <= resolution / 2
    delay_resolution_s: float  # rts.delay_resolution_s


def coherence_point(probes: Probes, near_s: float = 0.0, iterations: int = 4
                    ) -> CoherencePoint:
    """The delay offset of channel J that makes both channels coherent at ``probes``'
    directions on the setup *as built*, the one nearest ``near_s``: the point the sweep
    should find (a check: a lab does not know the setup as built).

    Newton on the probes' phase mismatch (``probes.phase``), slope ``2 pi f_if`` (eq. 27),
    on the **continuous** delay model (``steps.continuous_delay_setup``): channel J's offset
    unrounded. On the RTS's own (quantised) model the phase is a staircase and Newton lands
    anywhere within a step of the point (up to 7 / 18 / 27 / 18 ps off at 10 / 25 / 50 / 100
    ps steps: ``benchmarks.calibration_resolution``); the continuous model equals it at
    every realisable offset (when the step divides 1/f_s). Then quantised: the nearest
    realisable offset and the residual."""
    cont = continuous_delay_setup(probes.setup)
    period = probes.period_s
    d = float(near_s)
    for _ in range(2):  # Newton, then move to the period nearest near_s and polish there
        for _ in range(iterations):
            d += probes.phase(cont, d) * period / (2 * np.pi)
        d += np.round((near_s - d) / period) * period
    res = probes.setup.scene.rts.delay_resolution_s
    q = float(realisable(d, res))
    return CoherencePoint(float(d), q, float(d - q), float(res))

