"""The calibration's steps as the RTS can set them and the frames each needs (coarse delay
steps, high noise figures).

* What the RTS can set: every delay it is given is rounded (``rts.realised_delay``) to its
  resolution ``rts.delay_resolution_s`` (the fractional-delay FIR's step, or 1/f_s without
  one; the paper's RTS moves in 25 ps). The calibration's optimum is defined on the
  continuous model (:func:`continuous_delay_setup`) and rounded at the end
  (:func:`realisable`); a fine sweep too sparse for the least-squares fit is fitted through
  its points (:func:`fine_window`); what each step adds beyond its nominal offset, the FIR's
  phase and the quantiser's offset error, is known in advance (:func:`sweep_phase`).
* The frames: one rule (:func:`frames_for`): K coherently averaged frames divide a
  one-frame scatter by sqrt(K), so a step averages ceil((scatter / target)^2) of them. Each
  coarse-sweep step averages as many as bring the predicted probe-angle noise below
  ``COARSE_NOISE_DEG`` (:func:`predicted_angle_noise`, :func:`coarse_frames`), before the
  sweep, from the noise the link budget (or ``snr_db``) predicts; each fine-sweep step as
  many as bring the fitted minimum's 2-sigma scatter below ``TARGET_BIAS_PS`` (the pair on
  an arc: a Monte-Carlo of the phasor model, ``calibration.calibrate_pair``; a 2-D pair: of
  its own measured sweep, :func:`fit_scatter`).

The pair calibration (:mod:`.pair`) and the channels' (:mod:`.channels`) use these.
"""

from __future__ import annotations

import warnings

import numpy as np

from ..geometry import Setup
from ..rts.fir import realised_delay
from ..rts.channels import requested_delay
from .fir import fir_sweep_phase

__all__ = ["continuous_delay_setup", "CONTINUOUS_STEP_S", "COARSE_NOISE_DEG",
           "predicted_angle_noise", "coarse_frames", "MAX_FRAMES", "realisation_shift",
           "sweep_phase", "realisable", "FINE_STEP_S", "MIN_FIT_POINTS", "fine_window",
           "MC_DRAWS", "SIZE_DRAWS", "TARGET_BIAS_PS", "frames_for", "fine_frames",
           "fit_scatter", "rms_error_deg", "coarse_minimum", "adds_noise",
           "SCATTER_DRAW_FRAMES"]


def continuous_delay_setup(setup: Setup) -> Setup:
    """The same setup with an RTS that realises any delay (1 fs steps, the field's minimum;
    ``rts.realised_delay`` rounds to these): the continuous model the calibration's optimum
    is defined on. A coarse RTS rounds every delay it is given, so its model's phase is a
    staircase in the delay (flat over each step, jumping 2 pi f_if res at each edge); it
    agrees with this one at every realisable delay. The fractional-delay FIR keeps its
    modelled response (``rts.fir_if_gain``, continuous in its setting); an RTS without one
    (whole 1/f_s samples) gets none (``fractional_delay_filter = "ideal"``)."""
    import dataclasses
    rts = setup.scene.rts
    if rts.fractional_delay and rts.fractional_delay_step_s <= CONTINUOUS_STEP_S:
        return setup
    flt = rts.fractional_delay_filter if rts.fractional_delay else "ideal"
    cont = rts.evolve(fractional_delay=True, fractional_delay_step_s=CONTINUOUS_STEP_S,
                      fractional_delay_filter=flt)
    return dataclasses.replace(setup, scene=setup.scene.evolve(rts=cont))


CONTINUOUS_STEP_S = 1e-15  # the smallest rts.fractional_delay_step_s: "continuous"


COARSE_NOISE_DEG = 0.1  # the coarse sweep averages until a probe's angle noise is below this
SIZE_DRAWS = 16  # noise realisations that predict the probe-angle noise


def predicted_angle_noise(sweep, seed: int = 0) -> float:
    """The predicted 1-sigma probe-angle noise (deg) of one frame at a sweep's steps: the
    median over steps and probes of the angle's standard deviation over ``SIZE_DRAWS``
    noise realisations of the phasor model (``SweepResult.errors``), whose noise is the
    link budget's (``[radar.link]``) or ``snr_db``'s. The median: where a step's design is
    weak a few draws jump bins, which would dominate a mean (measured 0.005 deg on the
    default scene; 0.011 / 0.085 / 0.28 / 0.5 / 0.9 deg with the link at NF 12 / 30 / 40 /
    45 / 50 dB; the same from 1 to 4096 frames scaled by sqrt(frames)). Its own random
    stream, so the sweep's draws are the same as without it."""
    if not np.any(sweep.noise_sigma > 0):
        return 0.0
    rng = np.random.default_rng(np.random.SeedSequence([int(seed) % 2 ** 32, 1714]))
    e = sweep.errors(1, rng, SIZE_DRAWS)  # (D, S, P)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN steps (no design)
        sig = np.nanmedian(np.nanstd(e, axis=0))
    return float(np.degrees(sig)) if np.isfinite(sig) else 0.0


def frames_for(one_frame_scatter: float, target: float) -> int:
    """Frames per step to average so that a quantity whose scatter with one frame a step is
    ``one_frame_scatter`` scatters less than ``target`` (same unit): the coherent average of
    K frames has 1/K of one frame's noise power (``calibration.simulate_detect``) and a
    quantity linear in the noise 1/sqrt(K) of its scatter, so ceil((scatter / target)^2),
    at least 1 and at most ``MAX_FRAMES``."""
    return int(min(MAX_FRAMES, max(1, np.ceil((one_frame_scatter / target) ** 2))))


def coarse_frames(frame_noise_deg: float) -> int:
    """Frames per coarse-sweep step that bring the predicted probe-angle noise
    (:func:`predicted_angle_noise`) below ``COARSE_NOISE_DEG``: 1 on the default scene and
    with the link up to NF ~30 dB (unchanged there); 8 / 25 / 81 at NF 40 / 45 / 50 dB, where
    one frame per step picked a minimum 48 ps or a period off on 3 of 3 seeds at 50 dB."""
    return frames_for(frame_noise_deg, COARSE_NOISE_DEG)


def fine_frames(one_frame_scatter_s: float) -> int:
    """Frames per fine-sweep step that keep the fitted minimum's 2-sigma scatter below
    ``TARGET_BIAS_PS``, from its 1-sigma scatter with one frame a step (s)."""
    return frames_for(2 * one_frame_scatter_s, TARGET_BIAS_PS * 1e-12)


MAX_FRAMES = 1 << 20
TARGET_BIAS_PS = 2.0  # the averaging keeps the noise's pull on the chosen delay below this


def realisation_shift(setup: Setup, ranges, deltas, base_offsets=(0.0, 0.0)) -> np.ndarray:
    """How much further (S, P) channel J of each probe (at ``ranges``) moves than the offset
    ``deltas`` (S,) it is given: ``Q(tau_J + delta) - Q(tau_J) - delta`` with Q the RTS's
    realised delay (``rts.realised_delay``). Zero where the delay step divides 1/f_s;
    otherwise (e.g. 100 ps FIR steps at 4 GSPS: settings 0/100/200 ps in each 250 ps sample)
    up to a step, different per probe, and the probes' sweep curves are staircases on the
    offset axis (a fit on it landed 20 to 56 ps off)."""
    rts = setup.scene.rts
    base = (requested_delay(setup.scene, np.asarray(ranges, float)) + base_offsets[1])[None, :]
    d = np.asarray(deltas, float)[:, None]
    q = (realised_delay(base + d, rts.f_s_hz, rts.fractional_delay, rts.fractional_delay_step_s)
         - realised_delay(base, rts.f_s_hz, rts.fractional_delay, rts.fractional_delay_step_s))
    return q - d


def sweep_phase(setup: Setup, ranges, deltas, base_offsets, period_s: float):
    """The phase (S, P) each fine-sweep step adds to channel J of each probe beyond ``2 pi
    delta / period`` and known in advance (``sweep.fit_minimum``'s ``extra_phase_rad``):
    the FIR's (``fir.fir_sweep_phase``) and the quantiser's offset error
    (:func:`realisation_shift`), and the function that gives the FIR's on the continuous
    delays the fit searches (``search_phase``). ``(None, None)`` where both are zero (an
    ideal delay whose step divides 1/f_s)."""
    fir = fir_sweep_phase(setup, ranges, deltas, base_offsets)
    shift = realisation_shift(setup, ranges, deltas, base_offsets)
    if fir is None and not np.any(np.abs(shift) > 1e-18):
        return None, None
    extra = (0.0 if fir is None else fir) + 2 * np.pi * shift / period_s
    d = np.asarray(deltas, float)
    step = float(np.min(np.diff(np.sort(d)))) if d.size > 1 else 0.0
    if not np.any(np.abs(shift) > 1e-18) and step <= FINE_STEP_S * (1 + 1e-9):
        return extra, None  # dense and exact: the FIR's phase interpolates between steps
    p = np.asarray(ranges).size
    if fir is None:
        return extra, lambda t: np.zeros((np.size(t), p))
    # the FIR's phase on the continuous delays, once on a 0.5 ps grid over the sweep (it
    # cycles every 1/f_s: smooth on that scale), then interpolated
    grid = np.arange(d.min() - step, d.max() + step + 1e-15, 0.5e-12)
    table = fir_sweep_phase(setup, ranges, grid, base_offsets, continuous=True)
    return extra, lambda t: np.stack([np.interp(t, grid, table[:, k]) for k in range(p)], 1)


def realisable(delay_s, resolution_s: float):
    """``delay_s`` rounded to a whole number of the RTS's delay steps ``resolution_s``
    (``rts.delay_resolution_s``: the fractional-delay FIR's step, or 1/f_s without one).
    An offset that is a multiple of the step moves every channel's realised delay
    (``rts.realised_delay``) by exactly that offset when 1/f_s is a multiple of the step."""
    return np.round(np.asarray(delay_s, float) / resolution_s) * resolution_s


FINE_STEP_S = 5e-12  # step of the fitted fine sweep
MIN_FIT_POINTS = 7  # fine-sweep points a least-squares fit of 2 harmonics (5 coefficients) needs


def fine_window(half_s: float, step_s: float) -> tuple[int, int, str]:
    """Steps either side of the coarse minimum for the fitted fine sweep (+-``half_s``,
    period / 4, in steps of ``step_s``, at least one), the harmonics to fit and the fit's
    criterion (``sweep.fit_minimum``). With ``MIN_FIT_POINTS`` or more points: 2 harmonics,
    least squares, the joint minimum of the fitted errors (``"joint"``). An RTS with steps
    coarser than ~period / 6 (100 ps at 1 ns: 5 points) leaves too few for that (the fit
    fell back to the coarse minimum and the chosen delay was one 100 ps step from the
    realisable one nearest the coherence point): the fitted curves then pass through the
    points (2 harmonics on 5, 1 on 3) and the optimum is their common vertex
    (``"vertex"``: each probe's error is even about the coherence point; a fitted curve
    that interpolates may overshoot zero, which puts the joint minimum beside the vertex).
    Widening the window instead (to a full period) fitted worse: 50 to 120 ps off."""
    k = max(1, int(np.floor(half_s / step_s + 1e-9)))
    if 2 * k + 1 >= MIN_FIT_POINTS:
        return k, 2, "joint"
    return k, (2 if 2 * k + 1 >= 5 else 1), "vertex"


MC_DRAWS = 32  # noise realisations that size the frames per step


SCATTER_DRAW_FRAMES = 16  # fit_scatter draws at this many frames' noise, then scales


def fit_scatter(fit, fitted, e, harmonics: int, seed, pair,
                repeat=None) -> tuple[float, float]:
    """The fitted minimum's 1-sigma scatter (s) with one frame a step, and one frame's noise
    (rad of direction cosine, median over the columns), from a measured fine sweep: its
    errors ``e`` (S, C) at one frame a step, the curves ``fitted`` to them (S, C) and the
    ``fit`` (errors -> (minimum, curves); ``sweep.fit_minimum``). Each column's noise is its
    residual about the curve (least-squares degrees of freedom); ``MC_DRAWS`` sweeps are
    drawn as the curves plus Gaussian noise of that std / sqrt(``SCATTER_DRAW_FRAMES``)
    (where the fit is linear in the noise, as ``calibration.calibrate_pair`` draws at its
    coarse frames) and refitted, their minima's std scaled back to one frame. The 2-D
    counterpart of the arc pair's Monte-Carlo of the phasor model, which a 2-D pair has not:
    on its own data (deterministic seed; ``ncal.calibrate_pair_nd``). The seed: ``seed`` and
    the ``pair`` (i, j) measured.

    Where the fit has no residual degrees of freedom (an RTS with coarse delay steps leaves
    3 or 5 fine steps, through which the curves pass exactly: a zero residual is no evidence
    of no noise) the result is (NaN, NaN): measure the sweep again, independently, and give
    it as ``repeat`` (S, C): each column's noise is then that of the two sweeps' difference,
    var(e - repeat) = 2 sigma^2, with no fit involved."""
    e = np.asarray(e, float)
    if repeat is not None:
        r = (e - np.asarray(repeat, float)) / np.sqrt(2.0)
        ok = np.all(np.isfinite(r), axis=1)
        dof = int(ok.sum())
    else:
        r = e - fitted
        ok = np.all(np.isfinite(r), axis=1)
        dof = int(ok.sum()) - (1 + 2 * harmonics)
    if dof < 1:
        return float("nan"), float("nan")
    sigma = np.sqrt(np.sum(r[ok] ** 2, axis=0) / dof)  # (C,)
    rng = np.random.default_rng(np.random.SeedSequence([int(seed) % 2 ** 32, 1715,
                                                        int(pair[0]), int(pair[1])]))
    base = np.where(np.isfinite(fitted), fitted, e)
    draws = base[None] + (sigma / np.sqrt(SCATTER_DRAW_FRAMES)
                          * rng.standard_normal((MC_DRAWS,) + base.shape))
    est = np.array([fit(d)[0] for d in draws])
    return float(np.std(est) * np.sqrt(SCATTER_DRAW_FRAMES)), float(np.median(sigma))


def rms_error_deg(e) -> np.ndarray:
    """The RMS over the last axis of probe angle errors ``e`` (rad), in degrees; inf where it
    is undefined (a probe not detected), so that a sweep's minimum never lands there."""
    out = np.degrees(np.sqrt(np.mean(np.square(e), axis=-1)))
    return np.where(np.isfinite(out), out, np.inf)


def coarse_minimum(grid, errs) -> float:
    """The coarse sweep's minimum (s) from its RMS errors ``errs`` (deg) at delays ``grid``:
    minima repeat every period; among the local minima about as deep as the deepest (within
    2 x the deepest + 0.01 deg) the one with the smallest |delta tau|, which costs the least
    range offset (paper, "Disadvantages"). The arc pair's and the 2-D pair's one rule."""
    errs, grid = np.asarray(errs, float), np.asarray(grid, float)
    is_min = (np.r_[True, errs[1:] <= errs[:-1]] & np.r_[errs[:-1] <= errs[1:], True])
    good = np.flatnonzero(is_min & (errs <= 2 * np.min(errs) + 0.01))
    return float(grid[int(good[np.argmin(np.abs(grid[good]))])])


def adds_noise(scene) -> bool:
    """Whether the scene's radar adds receiver noise (``snr_db``, or ``[radar.link]``: kTBF
    noise), so that a sweep's frames per step must be sized."""
    return scene.radar.snr_db is not None or scene.radar.link is not None
