"""Calibration of a front-end pair on the simulated RuT output (paper section "Calibration").

1. Amplitude: each front end alone, its power at the RuT is measured (detections of the
   simulated radar) and compared with the model; the ratio corrects its programmed gain.
2. Phase: channel I keeps its delay, channel J's RTS delay is swept by Delta tau_rts over at
   least one period ``1 / (f_rts + B/2)`` (eq. 27; paper: [-0.5, 1] ns in 25 ps steps) while two
   probe targets synthesized at a quarter and three quarters of the span are detected; the
   RMS angle error is minimised, then refined with decreasing steps down to the fractional-
   delay resolution. The probes sit off mid-span on purpose: a target exactly between two
   symmetric beams keeps its angle over about half a period of phase error (flat-bottomed
   error curve), a quarter-span target gives a sharp V.

The delay offset also moves channel J's echo in range ("Disadvantages"): the reported
``range_offset_m`` is ``c0 / 2`` times the total delay mismatch of the two channels.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.constants import c

from .._lib.util import frozen, one_blas_thread
from ..geometry import Setup
from ..paths import Paths, nominal_model
from ..radar.processing import nearest_detection
from ..rts.channels import RtsProgram, requested_delay
from ..rts.fir import realised_delay
from ..scene import TargetConfig
from ..synthesis.closed_form import ratio_paper
from ..synthesis.model import ChannelModel
from .probes import (FrontEndProbe, if_phase_slope_hz, mean_air_delay, probe_angles,
                     probe_front_ends, probe_ranges, probe_total_delay, simulate_detect)
from .steps import (adds_noise, coarse_frames, coarse_minimum, continuous_delay_setup, fine_frames,
                    fine_window, predicted_angle_noise, realisable, rms_error_deg, sweep_phase,
                    FINE_STEP_S, MC_DRAWS)
from .sweep import chain_errors, fit_minimum, phasor_sweep, place_probes

__all__ = ["Calibration", "CoherencePoint", "coherence_point", "coherence_delay",
           "calibrate_pair", "calibrate_pair_paper"]


@dataclass(frozen=True)
class Calibration:
    pair: tuple[int, int]
    delta_tau_s: float  # delay offset of J relative to I
    residual_error_deg: float
    range_offset_m: float
    sweep_delta_tau_s: np.ndarray
    sweep_error_deg: np.ndarray
    refine_delta_tau_s: np.ndarray
    refine_error_deg: np.ndarray
    probe_angles_deg: tuple[float, float]
    period_s: float  # exact: 1 / (f_rts + S t_mid - S tau) at the probes (eq. 27 refined)
    frames_per_step: int = 1  # frames averaged (coherently) per sweep step
    frame_noise_deg: float = 0.0  # predicted 1-sigma probe-angle noise of one frame (deg)
    method: str = "phasor"  # what evaluated the sweep: phasor model or full-chain
    probe_ranges_m: tuple = ()  # the probes' set ranges (moved within a bin, sweep.place_probes)
    one_frame_scatter_ps: float = 0.0  # 1-sigma of the chosen delay with one frame per step
    # the fitted optimum minus delta_tau_s, which is quantised to what the RTS can set
    # (rts.delay_resolution_s); |residual| <= resolution / 2
    quantisation_residual_s: float = 0.0
    delay_resolution_s: float = 0.0  # the RTS's delay step the chosen delay is a multiple of
    coarse_frames_per_step: int = 1  # frames averaged per coarse-sweep step (coarse_frames)

    def to_dict(self) -> dict:
        def pts(t, e):
            return [{"delta_tau_s": float(a), "angle_error_deg": (None if not np.isfinite(b)
                                                                  else float(b))}
                    for a, b in zip(t, e)]
        return {
            "pair": list(self.pair),
            "delta_tau_s": self.delta_tau_s,
            "residual_error_deg": self.residual_error_deg,
            "range_offset_m": self.range_offset_m,
            "period_s": self.period_s,
            "frames_per_step": self.frames_per_step,
            "frame_noise_deg": self.frame_noise_deg,
            "method": self.method,
            "probe_ranges_m": list(self.probe_ranges_m),
            "one_frame_scatter_ps": self.one_frame_scatter_ps,
            "quantisation_residual_s": self.quantisation_residual_s,
            "delay_resolution_s": self.delay_resolution_s,
            "coarse_frames_per_step": self.coarse_frames_per_step,
            "probe_angles_deg": list(self.probe_angles_deg),
            "sweep": pts(self.sweep_delta_tau_s, self.sweep_error_deg),
            "refinement": pts(self.refine_delta_tau_s, self.refine_error_deg),
        }

    @classmethod
    def from_dict(cls, d: dict) -> "Calibration":
        """Inverse of :meth:`to_dict` (a calibration file written by ``rtsgeom calibrate``)."""
        def arr(key, field):
            return frozen(np.array([np.nan if p[field] is None else p[field]
                                    for p in d.get(key, [])], float))
        return cls((int(d["pair"][0]), int(d["pair"][1])), float(d["delta_tau_s"]),
                   float(d.get("residual_error_deg", np.nan)), float(d.get("range_offset_m", 0.0)),
                   arr("sweep", "delta_tau_s"), arr("sweep", "angle_error_deg"),
                   arr("refinement", "delta_tau_s"), arr("refinement", "angle_error_deg"),
                   tuple(float(x) for x in d.get("probe_angles_deg", (np.nan, np.nan))),
                   float(d.get("period_s", np.nan)), int(d.get("frames_per_step", 1)),
                   float(d.get("frame_noise_deg", 0.0)), str(d.get("method", "phasor")),
                   tuple(d.get("probe_ranges_m", ())), float(d.get("one_frame_scatter_ps", 0.0)),
                   float(d.get("quantisation_residual_s", 0.0)),
                   float(d.get("delay_resolution_s", 0.0)),
                   int(d.get("coarse_frames_per_step", 1)))


@dataclass(frozen=True)
class CoherencePoint:
    """The pair's phase-coherence point on the continuous delay model and the delay the RTS
    can set nearest it (:func:`realisable`)."""

    continuous_s: float  # the coherence point (continuous delay offset of channel J)
    delta_tau_s: float  # the nearest realisable offset: a whole number of resolution steps
    quantisation_residual_s: float  # continuous_s - delta_tau_s, |.| <= resolution / 2
    delay_resolution_s: float  # rts.delay_resolution_s


def coherence_point(setup: Setup, paths: Paths, pair: tuple[int, int], alphas,
                    near_s: float = 0.0, base_offsets=(0.0, 0.0), iterations: int = 4
                    ) -> CoherencePoint:
    """The delay offset of channel J that makes both channels coherent at the probe angles
    ``alphas`` on the setup *as built* (phasor model of both probe targets, with the range
    offset the delay causes), the one nearest ``near_s``: the point the sweep should find.

    Newton on the circular mean of the two probes' coherent phases, slope
    ``2 pi if_phase_slope_hz``, on the **continuous** delay model
    (:func:`continuous_delay_setup`): the base delays of channels I and J realised as the RTS
    realises them (``rts.realised_delay``), channel J's offset added unrounded. On the RTS's
    own (quantised) model the phase is a staircase and Newton lands anywhere within a step
    of the point (up to 7 / 18 / 27 / 18 ps off at 10 / 25 / 50 / 100 ps steps, 148 ps with
    whole 250 ps samples: ``benchmarks.calibration_resolution``); the continuous model
    equals it at every realisable offset (when the step divides 1/f_s). Then quantised: the
    nearest realisable offset and the residual."""
    scene = setup.scene
    rts = scene.rts
    ranges = probe_ranges(setup, 2)
    targets = [TargetConfig(float(r)) for r in ranges]
    f_if = float(if_phase_slope_hz(scene, probe_total_delay(setup, ranges)))
    period = 1.0 / f_if
    cont = continuous_delay_setup(setup)
    # each probe's I and J base delays as the RTS realises them, as offsets from the request
    base = []
    for t in targets:
        tau = float(requested_delay(scene, t.range_m))
        base.append([float(realised_delay(tau + b, rts.f_s_hz, rts.fractional_delay,
                                          rts.fractional_delay_step_s)) - tau
                     for b in base_offsets])

    def phase(d):
        z = 0j
        for t, (o_i, o_j) in zip(targets, base):
            m = ChannelModel.build(cont, paths, pair, t, (o_i, o_j + d))
            z += np.exp(1j * float(m.pair_phase(alphas)))
        return float(np.angle(z))

    d = float(near_s)
    for _ in range(2):  # Newton, then move to the period nearest near_s and polish there
        for _ in range(iterations):
            d += phase(d) / (2 * np.pi * f_if)
        d += np.round((near_s - d) / period) * period
    res = rts.delay_resolution_s
    q = float(realisable(d, res))
    return CoherencePoint(float(d), q, float(d - q), float(res))


def coherence_delay(setup: Setup, paths: Paths, pair: tuple[int, int], alphas,
                    near_s: float = 0.0, base_offsets=(0.0, 0.0), iterations: int = 4) -> float:
    """The continuous coherence point of :func:`coherence_point` (seconds)."""
    return coherence_point(setup, paths, pair, alphas, near_s, base_offsets,
                           iterations).continuous_s


@one_blas_thread
def calibrate_pair(setup: Setup, paths: Paths, pair: tuple[int, int],
                   probe: FrontEndProbe | None = None, base_offsets=(0.0, 0.0),
                   seed: int = 0, span_s=None, step_s=None, full_chain: bool = False,
                   frames: int | None = None) -> Calibration:
    """Sweep channel J's delay offset and return the calibration of the pair (I, J).

    1. Coarse sweep over the scene's span (``calibration_step_ps``) with the probes at their
       ranges; each step's amplitudes designed for the bin the RuT detects
       (:mod:`.sweep`); the deepest minimum nearest zero delay.
    2. The probes moved within their range bin so that design and detection agree on one bin
       over a window of +-period/4 around it (``sweep.place_probes``).
    3. Fine sweep over that window (``FINE_STEP_S`` rounded to whole steps of the RTS's
       delay resolution ``rts.delay_resolution_s``) with ``frames`` coherently averaged
       frames per step (default: as many as keep the chosen delay's 2-sigma scatter below
       ``TARGET_BIAS_PS``, from a Monte-Carlo of the phasor model); the minimum from a
       least-squares fit of the criterion's periodic shape over the window
       (``sweep.fit_minimum``), so every step's information counts.
    4. The fitted optimum rounded to a delay the RTS can set (a whole number of
       ``rts.delay_resolution_s``; the difference is ``quantisation_residual_s``), confirmed
       through the full ADC-cube chain (``residual_error_deg``).

    Steps 1-3 evaluate the phasor model (``radar.phasors``, batched over all steps); with
    ``full_chain`` every step runs through the ADC-cube chain instead (validation; minutes).

    BLAS runs on one thread throughout: the phasor model's products (``bin_response``,
    ``fir_error_response``) are small, and handing them to threads cost more than their
    arithmetic (the whole calibration 1.4-1.7 s CPU -> 0.3 s on a busy 2-core machine);
    one thread also makes the bits independent of the machine's core count (with threads,
    the sweep's errors moved in their 15th digit; the chosen delay and residual did not).
    """
    scene = setup.scene
    rts = scene.rts
    i, j = pair
    probe = probe or probe_front_ends(setup, paths, seed)
    alphas = np.asarray(probe_angles(probe.angle_rad[i], probe.angle_rad[j]))
    nominal = nominal_model(setup, paths)
    corr = (probe.gain_correction[i], probe.gain_correction[j])
    ranges = probe_ranges(setup, 2)
    period = 1.0 / float(if_phase_slope_hz(scene, probe_total_delay(setup, ranges)))
    span = span_s or rts.calibration_span_s
    step = step_s or rts.calibration_step_s
    grid = np.arange(span[0], span[1] + step / 2, step)
    rng = np.random.default_rng(np.random.SeedSequence([int(seed) % 2 ** 32, 1713]))
    noisy = adds_noise(scene)

    def measure(targets, res, k_frames):
        if full_chain:
            return chain_errors(setup, paths, pair, targets, res, base_offsets, k_frames,
                                seed)[0]
        return res.errors(k_frames, rng if noisy else None)

    targets = [TargetConfig(float(r)) for r in ranges]
    coarse = phasor_sweep(setup, paths, nominal, pair, targets, alphas, grid, base_offsets, corr)
    # frames per coarse step from the predicted noise (the link budget's or snr_db's), before
    # the sweep: one frame at NF 50 dB (0.9 deg of probe-angle noise) picked a wrong minimum
    frame_noise = predicted_angle_noise(coarse, seed) if noisy else 0.0
    k_coarse = (coarse_frames(frame_noise) if frames is None else int(frames))
    errs = rms_error_deg(measure(targets, coarse, k_coarse))
    res = rts.delay_resolution_s  # every delay the sweep sets and reports is a multiple
    near = float(realisable(coarse_minimum(grid, errs), res))
    best_fit = near
    if grid.size < 3:  # no sweep to speak of (e.g. only the period asked for)
        fine_t, fine_e, n_frames, noise = grid, errs, k_coarse, 0.0
    else:
        half = period / 4
        # the window's delays as the RTS realises them (a coarse RTS would round them)
        window = np.unique(realisable(near + np.arange(-half, half + 1e-15, step), res))
        ranges = place_probes(setup, paths, nominal, pair, ranges, alphas, window,
                              base_offsets, corr)
        targets = [TargetConfig(float(r)) for r in ranges]
        # fine steps the RTS can set: FINE_STEP_S rounded to whole resolution steps (an RTS
        # whose delay moves in 25 ps cannot take 5 ps steps; the model would round them)
        fine_step = res * max(1, round(FINE_STEP_S / res))
        k_half, harmonics, criterion = fine_window(half, fine_step)
        fine_t = near + np.arange(-k_half, k_half + 1) * fine_step
        search = max(half / 2, fine_step)  # the coarse minimum is within half a step
        fine = phasor_sweep(setup, paths, nominal, pair, targets, alphas, fine_t,
                            base_offsets, corr)
        noise = 0.0
        n_frames = 1 if frames is None else int(frames)
        extra, search_phase = sweep_phase(setup, ranges, fine_t, base_offsets, period)
        if noisy and frames is None:  # scatter of the fitted minimum with one frame per step
            # drawn at the coarse sweep's frames, where the fit is linear in the noise, and
            # scaled to one frame (drawn at one frame, the scatter compressed above ~30 ps:
            # 20-30 ps at NF 50 dB, under NF 45 dB's, and too few frames followed)
            draws = fine.errors(k_coarse, rng, MC_DRAWS)
            est = [fit_minimum(fine_t, e, period, near, harmonics, search, extra, criterion,
                               search_phase) for e in draws]
            noise = float(np.std(est)) * np.sqrt(k_coarse)
            n_frames = fine_frames(noise)
        e_fine = measure(targets, fine, n_frames)
        best_fit = fit_minimum(fine_t, e_fine, period, near, harmonics, search, extra,
                               criterion, search_phase)
        fine_e = rms_error_deg(e_fine)
    best = float(realisable(best_fit, res))  # what the RTS can set; the fit's optimum is between
    confirm = phasor_sweep(setup, paths, nominal, pair, targets, alphas, [best], base_offsets,
                           corr)
    e_conf = chain_errors(setup, paths, pair, targets, confirm, base_offsets, n_frames, seed)[0]
    best_err = float(rms_error_deg(e_conf)[0])
    air = mean_air_delay(setup)
    range_offset = 0.5 * c * ((air[j] + base_offsets[1] + best) - (air[i] + base_offsets[0]))
    return Calibration(pair, float(best), best_err, float(range_offset), frozen(grid),
                       frozen(errs), frozen(np.asarray(fine_t)), frozen(np.asarray(fine_e)),
                       (float(np.degrees(alphas[0])), float(np.degrees(alphas[1]))), period,
                       n_frames, frame_noise, "full-chain" if full_chain else "phasor",
                       tuple(float(r) for r in ranges), noise * 1e12, float(best_fit - best),
                       float(res), int(k_coarse))


def calibrate_pair_paper(setup: Setup, paths: Paths, pair: tuple[int, int],
                         probe: FrontEndProbe | None = None, seed: int = 0,
                         set_angle_rad: float | None = None, span_s=None,
                         step_s=None) -> Calibration:
    """The paper's calibration procedure as written (section "Measurement"): one target at
    one set angle (default: the middle of the pair's geometric span), its amplitudes fixed
    from eq. (23) with the nominal geometric front-end angles (times the amplitude
    calibration's gain correction) and never re-designed, channel J's delay swept over the
    scene's span (paper: [-0.5, 1] ns in 25 ps steps, one frame per step, no refinement),
    the delay with the smallest |angle error| kept.

    rtsgeom's own procedure (:func:`calibrate_pair`) instead re-designs the amplitudes with
    the exact model at every step and uses two probes; with fixed amplitudes the optimum
    is where the *fixed* design happens to hit the set angle, which need not be the
    coherence point (docs/paper-comparison.md)."""
    scene = setup.scene
    rts = scene.rts
    i, j = pair
    probe = probe or probe_front_ends(setup, paths, seed)
    nom, nom_paths = nominal_model(setup, paths)
    th = nom.fe_azimuth_rad()[[i, j]]
    alpha = float(np.mean(th)) if set_angle_rad is None else float(set_angle_rad)
    rng = float(probe_ranges(setup, 1)[0])
    target = TargetConfig(rng, 0.0, 10.0, alpha)
    unit = ChannelModel.build(nom, nom_paths, pair, target).unit_gain
    rho = float(ratio_paper(th[0], th[1], alpha))
    amp = (unit * probe.gain_correction[i], unit * rho * probe.gain_correction[j])
    tau = float(requested_delay(scene, rng))
    span = span_s or rts.calibration_span_s
    step = step_s or rts.calibration_step_s
    grid = np.arange(span[0], span[1] + step / 2, step)
    errs = np.full(grid.size, np.inf)
    for k, d in enumerate(grid):
        prog = RtsProgram.build([0, 0], [i, j], [tau, tau + d], [0.0, 0.0], list(amp))
        step_seed = np.random.SeedSequence([int(seed) % 2 ** 32, int(round(d * 1e15)) + 2 ** 40])
        rd, det = simulate_detect(setup, paths, prog, step_seed)
        n = nearest_detection(det, rd, rng)
        if n is not None:
            errs[k] = abs(np.degrees(det.angle_rad[n] - alpha))
    k = int(np.argmin(errs))
    res = rts.delay_resolution_s
    best = float(realisable(grid[k], res))  # the grid's steps are multiples unless the
    # scene's calibration_step_ps is not (validate warns)
    air = mean_air_delay(setup)
    range_offset = 0.5 * c * ((air[j] + best) - air[i])
    period = 1.0 / float(if_phase_slope_hz(scene, probe_total_delay(setup, [rng])))
    deg = float(np.degrees(alpha))
    return Calibration(pair, best, float(errs[k]), float(range_offset), frozen(grid),
                       frozen(errs), frozen(np.zeros(0)), frozen(np.zeros(0)), (deg, deg), period,
                       1, 0.0, quantisation_residual_s=float(grid[k] - best),
                       delay_resolution_s=float(res))
