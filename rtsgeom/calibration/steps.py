"""The calibration's steps as the RTS can set them and the frames each needs (coarse delay
steps, high noise figures).

* What the RTS can set: every delay it is given is rounded (``rts.realised_delay``) to its
  resolution ``rts.delay_resolution_s`` (the fractional-delay FIR's step, or 1/f_s without
  one; the paper's RTS moves in 25 ps). The calibration's optimum is defined on the
  continuous model (:func:`continuous_delay_setup`) and rounded at the end
  (:func:`realisable`); a fine sweep of few points is fitted with fewer harmonics
  (:func:`fine_window`); what each step adds beyond its nominal offset, the FIR's
  phase and the quantiser's offset error, is known in advance (:func:`sweep_phase`).
* The frames: one rule (:func:`frames_for`): K coherently averaged frames divide a
  one-frame scatter by sqrt(K), so a step averages ceil((scatter / target)^2) of them. Each
  coarse-sweep step averages as many as bring the predicted probe-angle noise below
  ``COARSE_NOISE_DEG`` (:func:`predicted_angle_noise`, :func:`coarse_frames`), before the
  sweep, from the noise the link budget (or ``snr_db``) predicts; each fine-sweep step as
  many as bring the fitted minimum's 2-sigma scatter below ``TARGET_BIAS_PS`` (the pair on
  an arc: a Monte-Carlo of the phasor model; a 2-D pair: of its own measured sweep,
  ``fit.fit_scatter``).

The sweep (:mod:`.sweep`) uses these.
"""

from __future__ import annotations

import copy
import dataclasses
import warnings
from typing import NamedTuple

import numpy as np

from ..geometry import Setup
from ..rts.fir import realised_delay
from ..rts.channels import requested_delay
from .fir import fir_sweep_phase

__all__ = ["continuous_delay_setup", "CONTINUOUS_STEP_S", "COARSE_NOISE_DEG",
           "predicted_angle_noise", "coarse_frames", "MAX_FRAMES", "realisation_shift",
           "sweep_phase", "realisable", "FINE_STEP_S", "fine_window",
           "FineWindow", "SIZE_DRAWS", "TARGET_BIAS_PS", "frames_for", "fine_frames",
           "adds_noise", "reference_setup", "reference_probes"]


def continuous_delay_setup(setup: Setup) -> Setup:
    """The same setup with an RTS that realises any delay (1 fs steps, the field's minimum;
    ``rts.realised_delay`` rounds to these): the continuous model the calibration's optimum
    is defined on. A coarse RTS rounds every delay it is given, so its model's phase is a
    staircase in the delay (flat over each step, jumping 2 pi f_if res at each edge); it
    agrees with this one at every realisable delay. The fractional-delay FIR keeps its
    modelled response (``rts.fir_if_gain``, continuous in its setting); an RTS without one
    (whole 1/f_s samples) gets none (``fractional_delay_filter = "ideal"``)."""
    rts = setup.scene.rts
    if rts.fractional_delay and rts.fractional_delay_step_s <= CONTINUOUS_STEP_S:
        return setup
    flt = rts.fractional_delay_filter if rts.fractional_delay else "ideal"
    cont = dataclasses.replace(rts, fractional_delay=True,
                               fractional_delay_step_s=CONTINUOUS_STEP_S,
                               fractional_delay_filter=flt)
    return _variant(setup, rts=cont)


def _variant(setup: Setup, **changes) -> Setup:
    """``setup`` with its scene's sections replaced, not validated again (a derived variant,
    :meth:`~rtsgeom.scene.evolve.Evolvable.derive`): the variants the sweep makes (a
    continuous RTS, noise off, a channel's phase) are valid by construction, and checking
    every front end and rule again costs O(F) per pair, O(F^2) for all pairs of an arc."""
    return dataclasses.replace(setup, scene=dataclasses.replace(setup.scene, **changes))


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
    delta / period`` and known in advance (``fit.fit_centre``'s ``extra_phase_rad``):
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


class FineWindow(NamedTuple):
    """The fitted fine sweep's layout (:func:`fine_window`)."""

    steps: int  # steps either side of the coarse minimum
    step_s: float  # the fine sweep's step
    harmonics: int  # harmonics of each column's fitted periodic shape


def fine_window(half_s: float, step_s: float) -> FineWindow:
    """The fine sweep: steps either side of the coarse minimum (+-``half_s``, period / 4, in
    steps of ``step_s``, at least one) and the harmonics of the fit (``fit.fit_centre``): 2,
    or 1 where an RTS's coarse steps leave only 3 points (250 ps at 1 ns), so that each
    column's coefficients and the shared centre stay fewer than its points."""
    k = max(1, int(np.floor(half_s / step_s + 1e-9)))
    return FineWindow(k, step_s, 2 if 2 * k + 1 >= 5 else 1)


def reference_setup(setup: Setup, channel: int, phase_rad: float = 0.0) -> Setup:
    """The (nominal) setup as the sweep's reference: no receiver noise and front end
    ``channel``'s hardware phase set to ``phase_rad`` (the RTS's channels read it from the
    scene when they synthesize, ``rts.channels``), wrapped to (-pi, pi]: the same phasor, and
    inside the scene's declared range (a radar's own antenna phases of +-180 deg put the
    unwrapped phase at 448 deg, which the scene's re-check refused naming a field nobody
    wrote)."""
    scene = setup.scene
    fes = list(scene.rts.front_ends)
    wrapped = float(np.angle(np.exp(1j * float(phase_rad))))
    fes[channel] = dataclasses.replace(fes[channel], phase_offset_rad=wrapped)
    rts = dataclasses.replace(scene.rts, front_ends=tuple(fes))
    radar = dataclasses.replace(scene.radar, snr_db=None, link=None)
    return _variant(setup, rts=rts, radar=radar)


def reference_probes(probes, phase_rad: float = 0.0):
    """A copy of ``probes`` (``sweep.Probes``) on their nominal setup and paths as the sweep's
    reference (:func:`reference_setup`: noiseless, channel J at the hardware phase
    ``phase_rad``); the probes' own state beyond that is theirs to reset."""
    out = copy.copy(probes)
    out.setup = reference_setup(probes.nominal[0], probes.pair[1], phase_rad)
    out.paths, out.noisy = probes.nominal[1], False
    return out


def adds_noise(scene) -> bool:
    """Whether the scene's radar adds receiver noise (``snr_db``, or ``[radar.link]``: kTBF
    noise), so that a sweep's frames per step must be sized."""
    return scene.radar.snr_db is not None or scene.radar.link is not None
