"""Angle accuracy over the field of view: the synthesized angle's error after calibration on a
grid of set angles, its uncertainty budget (:mod:`.budget`) and the Monte Carlo that validates
it.

Per adjacent pair of the arc the lab's procedure runs as ``rtsgeom run`` does it: the pair is
calibrated on the setup as built (``calibration.pair.calibrate_pair``, the delay sweep) and
each set angle is planned as the planner plans it (``pipeline.pair.pair_design``); the RuT's
snapshot of that programme comes from the phasor model (``synthesis.model.ChannelModel``,
which agrees with the ADC-cube chain), times the scene's radar's channel gains, searched by
the RuT's beamformer (Newton from the set angle with its global check,
``radar.processing.refine_angles``). The error there is the datasheet's ``error_deg``.

The inputs of the budget, per set angle of pair (I, J):

* each front end's mounting offset (radial, tangential, height; ``sigma_m``): the tolerance
  model (``analysis.tolerance``: the operator calibrates and designs on the nominal setup,
  the RuT sees the setup as built), its coefficient by central differences over +-sigma, its
  Monte Carlo the engine's draws (``tolerance.draws.draw_offsets``);
* the calibration's residual (the fitted delay's scatter, ``Calibration.one_frame_scatter_ps``
  over the frames averaged), the calibration's step (the fitted delay rounded to the RTS's
  delay step: rectangular, half a step) and the RTS's delay quantisation of each set-point
  (each channel's delay realised to the step, independently [assumed]: the difference is
  triangular, one step wide each side): all three move J's delay against I's, one coefficient
  d e / d tau_J from the phasor model;
* each RuT antenna's phase error (``sigma_phase_rad``: radars of the type about the scene's
  own, ``[radar.channels]``): the coefficients from the phasor model with that antenna's phase
  moved, the Monte Carlo's draws ``analysis.transfer.draw_channel_gains``;
* receiver noise at the scene's SNR, complex Gaussian on each virtual channel of the detected
  cell: one row, the root sum of squares of the coefficients of every channel's in-phase and
  quadrature part. The SNR is ``radar.snr_db`` (per sample) after the range and Doppler FFTs'
  coherent gain and their windows' losses (:func:`effective_snr`); without it and with
  ``[radar.link]`` the link budget's (:func:`link_snr`: thermal, RTS channel and quantisation
  noise of ``radar.link.relative_noise_power`` for the set angle's programme, against the
  detected cell's amplitude, as ``rtsgeom info`` and ``run``'s ``link_budget`` compute a
  target's SNR after the FFTs); neither: noiseless.

The Monte Carlo draws every input at once; the mounting draws go through the tolerance model
and the others through the phasor model at J's drawn delay (interpolated between nine models
across the delay's spread); the two deviations add per draw (their interaction, second order
in the errors, is neglected).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.constants import c

from ...calibration.pair import calibrate_pair
from ...calibration.probes import probe_angles, probe_ranges
from ...calibration.phasor import PairChannels
from ...pipeline.pair import pair_design
from ...radar.budget import window_snr_loss
from ...radar.link import relative_noise_power
from ...radar.windows import window
from ...radar.channels import antenna_gains, channel_coupling, channel_gain, virtual_gain
from ...radar.processing import refine_angles, tdm_compensate
from ...radar.steering import Steering
from ...scene import TargetConfig
from ...synthesis.model import ChannelModel
from ..tolerance import AXES, ChannelPhasors
from ..tolerance.draws import NOISE_STREAM, PHASE_STREAM, draw_offsets
from ..transfer import CHUNK_SNAPSHOTS, draw_channel_gains
from .budget import (K_COVERAGE, RECTANGULAR, TRIANGULAR, BudgetRow, combined,
                     coverage_interval, validate)

__all__ = ["AccuracyInputs", "AnglePoint", "pair_accuracy", "effective_snr", "link_snr"]

DELAY_NODES = 9  # phasor models across J's delay spread (the Monte Carlo interpolates)
FALLBACK_MM = 0.1  # the mounting coefficient's step where no tolerance is given (mm)
FALLBACK_PHASE_DEG = 1.0  # the antenna phase coefficient's step where no spread is given


@dataclass(frozen=True)
class AccuracyInputs:
    """What the budget draws: mounting sigmas (3,) m (radial, tangential, height), each
    antenna's phase spread (rad), the effective SNR per virtual channel at the detection
    (linear; None: noiseless), the Monte Carlo's draws and seed."""

    sigma_m: tuple[float, float, float]
    sigma_phase_rad: float
    snr_effective: float | None
    draws: int
    seed: int


@dataclass(frozen=True)
class AnglePoint:
    """One set angle's accuracy: the error after calibration, the budget, U and the Monte
    Carlo's interval."""

    pair: tuple[int, int]
    set_deg: float
    error_deg: float
    budget: tuple[BudgetRow, ...]
    combined_deg: float
    expanded_deg: float
    mc_interval_deg: tuple[float, float]
    mc_mean_deg: float
    mc_std_deg: float
    validated: bool
    end_difference: float  # the GUM interval's larger end difference, relative to U
    snr_effective_db: float | None = None  # at the detection cell (None: noiseless)

    @property
    def mc_half_width_deg(self) -> float:
        lo, hi = self.mc_interval_deg
        return 0.5 * (hi - lo)

    @property
    def accuracy_deg(self) -> float:
        """|error| + U where the budget is validated; else the Monte Carlo's interval's larger
        |end| (what the spec's ``angle_accuracy_deg`` is checked against)."""
        if self.validated:
            return abs(self.error_deg) + self.expanded_deg
        return max(abs(self.mc_interval_deg[0]), abs(self.mc_interval_deg[1]))

    def to_dict(self) -> dict:
        lo, hi = self.mc_interval_deg
        return {"set_angle_deg": self.set_deg, "pair": list(self.pair),
                "error_deg": self.error_deg,
                "combined_standard_uncertainty_deg": self.combined_deg,
                "coverage_factor": K_COVERAGE,
                "expanded_uncertainty_deg": self.expanded_deg,
                "monte_carlo_half_width_deg": self.mc_half_width_deg,
                "monte_carlo_interval_deg": [lo, hi],
                "monte_carlo_mean_deg": self.mc_mean_deg,
                "monte_carlo_std_deg": self.mc_std_deg,
                "gum_validated": self.validated,
                "gum_end_difference_of_u": self.end_difference,
                "accuracy_deg": self.accuracy_deg,
                "accuracy_from": "gum" if self.validated else "monte_carlo",
                "snr_effective_db": self.snr_effective_db,
                "budget": [r.to_dict() for r in self.budget]}


def effective_snr(radar) -> float | None:
    """The SNR per virtual channel at the detection cell (linear): the scene's per-sample
    ``snr_db`` times the range and Doppler FFTs' coherent gain with their windows' losses
    (``radar.budget.window_snr_loss``); None without ``snr_db`` (noiseless, or the link's
    noise: :func:`link_snr`, per set angle)."""
    if radar.snr_db is None:
        return None
    n_s, n_c = radar.samples_per_chirp, radar.chirps_per_tx
    gain = (n_s * window_snr_loss(radar.range_window, n_s)
            * n_c * window_snr_loss(radar.doppler_window, n_c))
    return 10 ** (radar.snr_db / 10) * gain


def link_snr(scene, model: ChannelModel, w) -> float:
    """The SNR per virtual channel at the detection cell (linear) of programme weights ``w``
    (Q,) on ``model`` under ``[radar.link]``'s noise: the cell's power (the strongest candidate
    bin's mean over the virtual channels) over the windowed FFTs' noise ``N_rel sum w_r^2 sum
    w_d^2``, ``N_rel`` the link's noise per sample referred to the model's relative amplitudes
    (``radar.link.relative_noise_power``: thermal k T0 F f_adc, the programmed RTS channels'
    re-radiated noise and the ADC's quantisation at the echo's IF response). For a target on a
    bin centre it is the link budget's ``snr_after_fft_db`` (``radar.budget.link_budget``)."""
    radar = scene.radar
    x = np.tensordot(np.asarray(w), model.responses, axes=([0], [1]))  # (K, V)
    p_cell = float(np.max(np.mean(np.abs(x) ** 2, axis=-1)))
    beat_hz = radar.slope_hz_per_s * 2.0 * model.range_m / c + model.doppler_hz
    n_rel = float(relative_noise_power(scene, float(np.sum(np.abs(w) ** 2)), beat_hz))
    g = (np.sum(window(radar.range_window, radar.samples_per_chirp) ** 2)
         * np.sum(window(radar.doppler_window, radar.chirps_per_tx) ** 2))
    return p_cell / (n_rel * float(g))


def _angles(model: ChannelModel, w, gains, start_rad: float, coupling=None, noise=None
            ) -> np.ndarray:
    """The RuT's azimuths (B,) rad of programme weights ``w`` on ``model`` seen by radars of
    virtual gains ``gains`` (B, V) (``analysis.transfer.snapshot_angles``'s snapshot) plus
    ``noise`` (B, V) on the detected cell, its peak by Newton from ``start_rad``."""
    x = np.tensordot(w, model.responses, axes=([0], [1]))  # (K, V)
    if coupling is not None:
        x = x @ coupling.T
    gains = np.asarray(gains)
    n = max(gains.shape[0], 1 if noise is None else np.shape(noise)[0])
    gains = np.broadcast_to(gains, (n, gains.shape[-1]))
    out = np.empty(n)
    # in blocks of transfer's snapshot budget: (B, K, V) at a million draws is gigabytes
    step = max(1, CHUNK_SNAPSHOTS // x.shape[0])
    for a in range(0, n, step):
        xb = x[None] * gains[a:a + step, None, :]
        k = np.argmax(np.sum(np.abs(xb) ** 2, axis=-1), axis=-1)
        sel = np.take_along_axis(xb, k[:, None, None], axis=1)[:, 0]
        sel = tdm_compensate(sel, model.doppler_hz, model.setup.rut, model.setup.scene.radar)
        if noise is not None:
            sel = sel + noise[a:a + step]
        out[a:a + step] = refine_angles(sel, model.steering, None, start_rad)
    return out


class _Point:
    """One set angle's planned programme on the phasor model: the error as a function of J's
    delay change, the radar's gains and noise on the detected cell."""

    def __init__(self, ideal, paths, pair, target, off_j, w, st, coupling, g_gold):
        self.ideal, self.paths, self.pair, self.target = ideal, paths, pair, target
        self.off_j, self.w, self.st, self.coupling, self.g_gold = off_j, w, st, coupling, g_gold
        self.model = self.at_delay(0.0)
        x = np.tensordot(w, self.model.responses, axes=([0], [1]))
        self.amplitude = float(np.sqrt(np.max(np.mean(np.abs(x) ** 2, axis=-1))))

    def at_delay(self, d_s: float) -> ChannelModel:
        return ChannelModel.build(self.ideal, self.paths, self.pair, self.target,
                                  (0.0, self.off_j + d_s), steering=self.st)

    def error_deg(self, gains=None, model=None, noise=None) -> np.ndarray:
        g = self.g_gold[None] if gains is None else gains
        a = _angles(model or self.model, self.w, g, self.target.angle_rad, self.coupling, noise)
        return np.degrees(a - self.target.angle_rad)


def _antenna_gains(rut, phases_rad) -> np.ndarray:
    """Virtual gains (B, V) of per-antenna phase errors (B, N_tx + N_rx), Tx first."""
    n_tx = rut.tx_local.shape[0]
    n_rx = rut.rx_local.shape[0]
    zero = np.zeros_like(phases_rad)
    return virtual_gain(rut, antenna_gains(zero[:, :n_tx], phases_rad[:, :n_tx], n_tx),
                        antenna_gains(zero[:, n_tx:], phases_rad[:, n_tx:], n_rx))


def _mounting(setup, pair, angles, sigma_m, draws, seed):
    """The tolerance model of the pair at the set angles: the coefficients (2, 3, M) deg/m
    and the draws' deviations (draws, M)."""
    m = ChannelPhasors.build(setup, pair, set_rad=angles)
    zero = np.zeros((1, 2, 3))
    e0 = m.angle_errors(zero, "calibrated")[0]
    steps = np.array([s if s > 0 else FALLBACK_MM * 1e-3 for s in sigma_m])
    off = np.zeros((2, 2, 3, 2, 3))  # (sign, front end, axis) x the pair's offsets
    for q in range(2):
        for a in range(3):
            off[0, q, a, q, a], off[1, q, a, q, a] = steps[a], -steps[a]
    e = m.angle_errors(off, "calibrated")  # (2, 2, 3, M)
    coef = (e[0] - e[1]) / (2 * steps[None, :, None])
    dev = np.zeros((draws, angles.size))
    if any(sigma_m):
        drawn = draw_offsets(seed, draws, np.asarray(sigma_m, float), "normal", 2)
        dev = m.angle_errors(drawn, "calibrated") - e0
    return coef, dev


def pair_accuracy(setup, ideal, paths, pair, probe, angles_rad, inputs: AccuracyInputs,
                  progress=None) -> list[AnglePoint]:
    """Every set angle of ``pair``'s accuracy (module doc). ``setup``: as built (the scene's
    own errors, calibrated on); ``ideal``: the same with an ideal radar (the phasor model the
    scene's channel gains multiply)."""
    scene = setup.scene
    cal = calibrate_pair(setup, paths, pair, probe, seed=scene.seed)
    res = scene.rts.delay_resolution_s
    rut = setup.rut
    st = Steering.build(rut, scene.radar)
    coupling = channel_coupling(scene.radar, rut)
    g_gold = channel_gain(scene.radar, rut)
    g_gold = np.ones(rut.num_virtual, complex) if g_gold is None else g_gold
    rng_m = float(probe_ranges(setup, 1)[0])
    coef_mount, dev_mount = _mounting(setup, pair, angles_rad, inputs.sigma_m,
                                             inputs.draws, inputs.seed)
    u_res = cal.one_frame_scatter_ps * 1e-12 / math.sqrt(max(cal.frames_per_step, 1))
    delay_inputs = (("calibration residual (J's fitted delay)", u_res, "normal",
                     "the sweep's fitted delay scatter over the frames averaged"),
                    ("calibration step (J's delay rounded)", 0.5 * res * RECTANGULAR,
                     "rectangular", f"half the RTS delay step {res * 1e12:g} ps"),
                    ("RTS delay quantisation (J against I)", res * TRIANGULAR, "triangular",
                     "each channel's delay realised to the step [assumed independent]"))
    u_delay = math.sqrt(sum(u ** 2 for _, u, _, _ in delay_inputs))
    n_ant = rut.tx_local.shape[0] + rut.rx_local.shape[0]
    rng = np.random.default_rng([inputs.seed, NOISE_STREAM])
    # its own stream: the offsets' draw_offsets(seed) would repeat the same normals
    ph_draw = draw_channel_gains(rut, inputs.draws, inputs.sigma_phase_rad, 0.0,
                                 [inputs.seed, PHASE_STREAM])[0]
    z_noise = (rng.standard_normal((inputs.draws, rut.num_virtual))
               + 1j * rng.standard_normal((inputs.draws, rut.num_virtual)))
    d_draw = (rng.normal(0.0, 1.0, inputs.draws) * u_res
              + rng.uniform(-0.5, 0.5, inputs.draws) * res
              + (rng.uniform(-0.5, 0.5, inputs.draws) - rng.uniform(-0.5, 0.5, inputs.draws))
              * res)
    out = []
    for m, alpha in enumerate(angles_rad):
        t = TargetConfig(rng_m, 0.0, 10.0, float(alpha))
        channels = PairChannels(pair, (0.0, cal.delta_tau_s),
                                probe.gain_correction[list(pair)])
        a_i, a_j, _, off_j = pair_design(ideal, paths, channels, t, scene.rts.aoa_mode,
                                         probe_angles(*probe.angle_rad[list(pair)]),
                                         cal.quantisation_residual_s)
        pt = _Point(ideal, paths, pair, t, off_j, np.array([a_i, a_j]), st, coupling, g_gold)
        e0 = float(pt.error_deg()[0])
        rows = _mount_rows(pair, inputs.sigma_m, coef_mount[..., m])
        # J's delay: one coefficient for the three delay inputs
        h = max(u_delay, 0.1 * res)
        e_d = [float(pt.error_deg(model=pt.at_delay(s * h))[0]) for s in (1, -1)]
        c_tau = (e_d[0] - e_d[1]) / (2 * h * 1e12)  # deg/ps
        rows += [BudgetRow(q, u * 1e12, "ps", dist, c_tau, note)
                 for q, u, dist, note in delay_inputs]
        rows += _antenna_rows(pt, rut, n_ant, inputs.sigma_phase_rad)
        snr, snr_from = _point_snr(scene, inputs, pt)
        u_noise = 0.0 if snr is None else 1 / math.sqrt(2 * snr)
        rows.append(_noise_row(pt, rut, u_noise, snr, snr_from))
        u_c = combined(rows)
        # Monte Carlo: every input drawn
        nodes = np.linspace(-1, 1, DELAY_NODES) * max(4 * u_delay, res)
        e_nodes = np.array([pt.error_deg(model=pt.at_delay(d))[0] for d in nodes])
        dev_delay = np.interp(d_draw, nodes, e_nodes) - e0
        noise = None if u_noise == 0 else z_noise * u_noise * pt.amplitude
        dev_gain = pt.error_deg(gains=g_gold[None] * ph_draw, noise=noise) - e0
        total = e0 + dev_mount[:, m] + dev_delay + dev_gain
        interval = coverage_interval(total)
        ok, diff = validate(e0, K_COVERAGE * u_c, interval)
        fin = total[np.isfinite(total)]
        out.append(AnglePoint(tuple(pair), float(np.degrees(alpha)), e0,
                              tuple(rows), u_c, K_COVERAGE * u_c, interval,
                              float(np.mean(fin)), float(np.std(fin)), ok, diff,
                              None if snr is None else 10 * math.log10(snr)))
        if progress:
            progress(f"angle accuracy: pair {tuple(pair)}", m + 1, angles_rad.size)
    return out


def _point_snr(scene, inputs: AccuracyInputs, pt: "_Point") -> tuple[float | None, str]:
    """The SNR at the set angle's detection cell and where it comes from: ``snr_db`` (which
    overrides the link's noise in the chain, ``radar.frame.simulate``), else the link budget
    where the scene has ``[radar.link]``, else None (noiseless)."""
    if inputs.snr_effective is not None:
        return inputs.snr_effective, "radar.snr_db"
    if scene.radar.link is not None:
        return link_snr(scene, pt.model, pt.w), "the link budget ([radar.link])"
    return None, "noiseless (no radar.snr_db, no [radar.link])"


def _mount_rows(pair, sigma_m, coef) -> list[BudgetRow]:
    """Rows of the six mounting offsets: coefficients ``coef`` (2, 3) deg/m."""
    rows = []
    for q, fe in enumerate(pair):
        for a, axis in enumerate(AXES):
            rows.append(BudgetRow(f"front end {fe} {axis} offset", sigma_m[a] * 1e3, "mm",
                                  "normal", float(coef[q, a]) * 1e-3,
                                  "tolerance model, calibrated on the nominal setup"))
    return rows


def _antenna_rows(pt: _Point, rut, n_ant: int, sigma_rad: float) -> list[BudgetRow]:
    """One row per RuT antenna's phase error: coefficients by central differences."""
    h = sigma_rad if sigma_rad > 0 else math.radians(FALLBACK_PHASE_DEG)
    ph = np.concatenate([np.eye(n_ant) * h, -np.eye(n_ant) * h])
    e = pt.error_deg(gains=pt.g_gold[None] * _antenna_gains(rut, ph))
    coef = (e[:n_ant] - e[n_ant:]) / (2 * math.degrees(h))  # deg/deg
    n_tx = rut.tx_local.shape[0]
    names = [f"RuT Tx {k} phase" for k in range(n_tx)] + [
        f"RuT Rx {k} phase" for k in range(n_ant - n_tx)]
    return [BudgetRow(name, math.degrees(sigma_rad), "deg", "normal", float(c),
                      "radars of the type about the scene's own")
            for name, c in zip(names, coef)]


def _noise_row(pt: _Point, rut, u_noise: float, snr, snr_from: str) -> BudgetRow:
    """Receiver noise: the coefficients of each virtual channel's in-phase and quadrature
    noise (relative to the echo's rms amplitude), combined by their root sum of squares."""
    v = rut.num_virtual
    h = u_noise if u_noise > 0 else 1e-3
    eye = np.eye(v) * h * pt.amplitude
    noise = np.concatenate([eye, -eye, 1j * eye, -1j * eye])
    gains = np.repeat(pt.g_gold[None], noise.shape[0], axis=0)
    e = pt.error_deg(gains=gains, noise=noise)
    c_re = (e[:v] - e[v:2 * v]) / (2 * h)
    c_im = (e[2 * v:3 * v] - e[3 * v:]) / (2 * h)
    c = float(np.sqrt(np.sum(c_re ** 2 + c_im ** 2)))
    note = (snr_from if snr is None else
            f"each of {v} virtual channels' I and Q, SNR {10 * math.log10(snr):.1f} dB at the "
            f"detection, from {snr_from}")
    return BudgetRow("receiver noise (per I/Q, relative to the echo)", u_noise, "1", "normal",
                     c, note)
