"""The calibration sweep evaluated where it is decided: the phasor model at the detected bin.

Each step of the phase calibration (paper section "Calibration") programs both probe targets
on channels I (delay ``base``) and J (``base + delta``) with amplitudes designed for coherent
channels, and reads the probes' angles off the RuT's detections. The RuT detects a probe at the
range bin with the most power, and channel J's echo moves by ``c0 delta / 2`` (0.3 to 2 bins
over the sweep): near a bin boundary two bins carry nearly equal power. The amplitudes must be
designed **for the bin the RuT detects**; otherwise the design is right at one bin and the
angle is read at the other, the error at the coherence point is not zero and the sweep's
minimum moves (up to 75 ps). A lab does the same: it reads the probe's range bin off the
detection list and designs for it (a fixed point: design at bin k, detect, redesign if the
RuT reported another bin).

Everything here is batched over all sweep steps at once (one :class:`ChannelModel` per probe
whose channels are I once and J once per step), with the phasor model
(``radar.phasors.bin_response``, which agrees with the ADC-cube chain to complex64
precision), the exact amplitude design in closed form (:func:`design_ratio`) and the angle by
Newton on the beamformer peak (:meth:`Steering.peak`). Receiver noise is added to the bins'
spectra with the variance the windowed range and Doppler DFTs give it.
"""

from __future__ import annotations

import copy
import dataclasses
from dataclasses import dataclass

import numpy as np
from scipy.constants import c

from ..geometry import Setup
from ..paths import Paths
from ..radar.processing import tdm_compensate
from ..radar.steering import Steering
from ..radar.windows import window
from ..rts.channels import KIND_DIRECT, RtsProgram, channel_echoes, requested_delay
from ..scene import TargetConfig
from ..synthesis.model import ChannelModel
from ..synthesis.pair import beam_derivatives, design_ratio
from ..radar.link import relative_noise_power
from ..radar.processing import nearest_detection
from ..paths import nominal_model
from ..rts.fir import realised_delay
from .fit import MC_DRAWS, rms_error_deg
from .probes import (PLACEMENT_OFFSETS_BINS, FrontEndProbe, if_phase_slope_hz,
                     place_in_bins, probe_angles, probe_program, probe_ranges,
                     probe_total_delay, simulate_detect)
from .steps import (FINE_STEP_S, adds_noise, predicted_angle_noise, reference_probes,
                    sweep_phase)

__all__ = ["SweepResult", "PairChannels", "phasor_sweep", "HALF_BINS", "place_probes",
           "chain_errors", "PhasorProbes"]

HALF_BINS = 3  # candidate bins either side of the set range's bin (J moves <= ~2 bins)


@dataclass(frozen=True)
class SweepResult:
    """Per step s and probe p (noiseless model): the spectra at the candidate bins for the
    design the RuT's bin selects, the design's bin (index into the model's bins,
    ``HALF_BINS`` is the set range's), the designed amplitudes (A_I, A_J), whether design and
    detection agree on the bin, and the detected bin's power over the next strongest."""

    delta_tau_s: np.ndarray  # (S,)
    spectra: np.ndarray  # (S, P, K, V) TDM-compensated
    bin_index: np.ndarray  # (S, P)
    amplitudes: np.ndarray  # (S, P, 2)
    range_bin0: np.ndarray  # (P,) absolute range bin of the set range
    consistent: np.ndarray  # (S, P)
    margin: np.ndarray  # (S, P)
    noise_sigma: np.ndarray  # (S,) per-element noise std of one frame (0: noiseless scene)
    alphas: np.ndarray  # (P,) probe angles (rad)
    steering: Steering

    def errors(self, frames: int = 1, rng=None, draws: int | None = None) -> np.ndarray:
        """Signed probe-angle errors (rad) as the RuT detects them: (S, P), or (draws, S, P)
        with ``draws`` independent noise realisations of ``frames`` coherently averaged
        frames each (noiseless when ``rng`` is None). The detected bin is the strongest
        candidate of the noisy spectra; its angle the beamformer peak (Newton)."""
        x = self.spectra if draws is None else np.broadcast_to(
            self.spectra, (draws,) + self.spectra.shape)
        if rng is not None and np.any(self.noise_sigma > 0):
            sig = (self.noise_sigma / np.sqrt(frames))[:, None, None, None] / np.sqrt(2)
            x = x + sig * (rng.standard_normal(x.shape) + 1j * rng.standard_normal(x.shape))
        power = np.sum(x.real ** 2 + x.imag ** 2, -1)
        k = np.argmax(power, -1)
        sel = np.take_along_axis(x, k[..., None, None], -2)[..., 0, :]
        a = self.alphas
        u, _ = self.steering.peak(sel, np.broadcast_to(np.sin(a)[:, None], sel.shape[:-1] + (1,)))
        err = np.arcsin(np.clip(u[..., 0], -1, 1)) - a
        return np.where(np.isfinite(self.amplitudes).all(-1), err, np.nan)


#: the last few probes' models (:func:`_models`): the sweep's reference measures the delays
#: the sweep measured, on the same nominal models (``phasor_sweep``'s ``j_phase_rad``)
_MODELS: list = []
_MODELS_KEPT = 8


def _models(setup, paths, pair, targets, base_offsets, deltas):
    """One model per probe: channel I, then J at every step's delay (the same ones again
    where the last few calls asked for them: same setup and paths objects, pair, probes,
    offsets and delays)."""
    i, j = pair
    deltas = np.asarray(deltas, float)
    key = (tuple(int(q) for q in pair), tuple(targets),
           tuple(float(b) for b in base_offsets), deltas.tobytes())
    for s, p, k, models in _MODELS:
        if s is setup and p is paths and k == key:
            return models
    ch = [i] + [j] * len(deltas)
    dt = np.concatenate([[base_offsets[0]], base_offsets[1] + deltas])
    models = [ChannelModel.build(setup, paths, ch, t, dt, HALF_BINS) for t in targets]
    _MODELS.insert(0, (setup, paths, key, models))
    del _MODELS[_MODELS_KEPT:]
    return models


def _range_bin(scene, range_m: float) -> int:
    r = scene.radar
    return int(np.round(range_m * 2 * r.slope_hz_per_s / c * r.samples_per_chirp
                        / r.adc_rate_hz))


def _noise_sigma(setup, paths, pair, targets, amps, snr_db) -> np.ndarray:
    """Per-element noise standard deviation (complex) of the range-Doppler spectrum per step
    (S,): the frame's noise power per sample is referred to its strongest direct echo
    (``radar.frame.noise_power``), here the largest programmed amplitude ``amps`` (S, P, 2)
    times its channel's strongest unit echo; the windowed DFTs add sum w_r^2 sum w_d^2."""
    scene, radar = setup.scene, setup.scene.radar
    tau = float(requested_delay(scene, targets[0].range_m))
    prog = RtsProgram.build([0, 1], list(pair), [tau, tau], [0.0, 0.0], [1.0, 1.0])
    ech = channel_echoes(setup, paths, prog)
    ech = ech.select(ech.kind == KIND_DIRECT)
    unit = np.array([np.max(np.abs(ech.amplitude[ech.target == q])) for q in (0, 1)])
    a_max = np.nanmax(np.abs(amps) * unit, axis=(1, 2))  # (S,)
    n0 = a_max ** 2 / 10 ** (snr_db / 10)
    g = (np.sum(window(radar.range_window, radar.samples_per_chirp) ** 2)
         * np.sum(window(radar.doppler_window, radar.chirps_per_tx) ** 2))
    return np.sqrt(n0 * g)


def _linked_noise_sigma(setup, targets, amps) -> np.ndarray:
    """As :func:`_noise_sigma` with ``[radar.link]`` and no ``snr_db``: the per-sample noise
    from the link budget, referred to the model's relative amplitudes
    (:func:`rtsgeom.radar.link.relative_noise_power`; the RTS channels' noise from every programmed
    row ``amps`` (S, P, 2), the quantisation at the weakest probe's IF response)."""
    scene, radar = setup.scene, setup.scene.radar
    beat = radar.slope_hz_per_s * 2.0 * np.array([t.range_m for t in targets]) / c  # (P,)
    n0 = np.max(relative_noise_power(scene, np.nansum(np.abs(amps) ** 2, axis=(1, 2))[:, None],
                                     beat[None, :]), axis=1)  # (S,)
    g = (np.sum(window(radar.range_window, radar.samples_per_chirp) ** 2)
         * np.sum(window(radar.doppler_window, radar.chirps_per_tx) ** 2))
    return np.sqrt(n0 * g)


@dataclass(frozen=True)
class PairChannels:
    """A front-end pair's two channels as the RTS sets them while the pair is swept or
    programmed: the front ends ``pair`` (I, J), the channels' delay offsets ``offsets`` (s;
    added to every request on I and J) and their ``gain_correction`` (the factors the
    amplitudes are multiplied by: :attr:`FrontEndProbe.gain_correction
    <rtsgeom.calibration.probes.FrontEndProbe.gain_correction>`). ``j_phase_rad``: the setup
    swept is the nominal one with channel J's hardware phase set to this (the sweep's
    reference, ``steps.reference_setup``); None: any setup."""

    pair: tuple
    offsets: tuple = (0.0, 0.0)
    gain_correction: tuple = (1.0, 1.0)
    j_phase_rad: float | None = None


def phasor_sweep(setup: Setup, paths: Paths, nominal: tuple[Setup, Paths],
                 channels: PairChannels, targets, alphas, deltas, bins=None) -> SweepResult:
    """The calibration sweep's spectra at every delay ``deltas`` (S,) of channel J, on the
    setup as built (``setup``, ``paths``), with amplitudes designed on the ``nominal`` setup
    for the bin the RuT detects (fixed point, see the module); ``channels``: the pair with
    its channels' offsets and gain corrections; ``bins`` (S, P) forces the design bins (the
    full chain passes the bins its detection reported). Noise and angles:
    :meth:`SweepResult.errors`; the designs alone (no noise level): :func:`_sweep_designs`."""
    res = _sweep_designs(setup, paths, nominal, channels, targets, alphas, deltas, bins)
    radar, pair = setup.scene.radar, channels.pair
    if radar.snr_db is not None:
        sigma = _noise_sigma(setup, paths, pair, targets, res.amplitudes, radar.snr_db)
    elif radar.link is not None:  # the link budget's thermal noise (kTBF, RTS, ADC)
        sigma = _linked_noise_sigma(setup, targets, res.amplitudes)
    else:
        return res
    return dataclasses.replace(res, noise_sigma=sigma)


def _sweep_designs(setup: Setup, paths: Paths, nominal: tuple[Setup, Paths],
                   channels: PairChannels, targets, alphas, deltas, bins=None) -> SweepResult:
    """:func:`phasor_sweep` without the noise level (``noise_sigma`` zeros): the designs'
    bins and margins, all the probe placement reads.

    With ``channels.j_phase_rad`` the swept setup's models are the nominal ones with J's
    responses turned by ``e^{-j phase}`` (the beat carries the conjugate of the channel's
    gain, ``rts.channels.channel_echoes``; the chain is linear in it), not built a second
    time."""
    pair, base_offsets, gain_correction = (channels.pair, channels.offsets,
                                           channels.gain_correction)
    j_phase_rad = channels.j_phase_rad
    deltas = np.atleast_1d(np.asarray(deltas, float))
    n_s, n_p = deltas.size, len(targets)
    nom_models = _models(*nominal, pair, targets, base_offsets, deltas)
    # no mounting errors (nominal_model returns the same objects): the same models, built once
    if j_phase_rad is not None:
        turn = np.r_[1.0, np.full(n_s, np.exp(-1j * float(j_phase_rad)))][None, :, None]
        real_models = [dataclasses.replace(m, responses=m.responses * turn)
                       for m in nom_models]
    elif nominal[0] is setup and nominal[1] is paths:
        real_models = nom_models
    else:
        real_models = _models(setup, paths, pair, targets, base_offsets, deltas)
    st = nom_models[0].steering
    radar = setup.scene.radar
    kbin = np.empty((n_s, n_p), int)
    amps = np.empty((n_s, n_p, 2))
    consistent = np.empty((n_s, n_p), bool)
    margin = np.empty((n_s, n_p))
    snaps = []
    steps = np.arange(n_s)
    for p, (mn, mr, alpha) in enumerate(zip(nom_models, real_models, alphas)):
        hn = tdm_compensate(mn.responses, mn.doppler_hz, setup.rut, radar)  # (K, 1+S, V)
        ha = hn if mr is mn else tdm_compensate(mr.responses, mr.doppler_hz, setup.rut, radar)
        probes_u = st.directions(np.atleast_1d(np.asarray(alphas, float)))
        phases = mn.coherent_phases(probes_u, hn)[..., 1:]  # (K, S): J's coherent phase per bin
        rho = design_ratio(st, hn[:, :1, :], hn[:, 1:, :], alpha, phases)  # (K, S)
        # power normalisation (ChannelModel.amplitudes): the combined peak as strong as I alone
        b_i, _, _ = beam_derivatives(st, hn[:, :1, :], np.sin(alpha))
        b_j, _, _ = beam_derivatives(st, hn[:, 1:, :], np.sin(alpha))
        p_sum = np.abs(b_i + rho * np.exp(1j * phases) * b_j) ** 2  # (K, S)
        k_one = int(np.argmax(np.sum(np.abs(hn[:, 0]) ** 2, -1)))
        u_one, _ = st.peak(hn[k_one, 0], np.sin(alpha))
        p_one = float(st.power(hn[k_one, 0], u_one[None])[0])
        scale = mn.unit_gain * np.sqrt(p_one / np.maximum(p_sum, 1e-300))
        a_i, a_j = scale * gain_correction[0], scale * rho * gain_correction[1]  # (K, S)
        # spectra at every candidate bin for every design bin: (K_design, S, K_bins, V)
        x = (a_i[:, :, None, None] * ha[None, :, 0, :][:, None]
             + a_j[:, :, None, None] * np.moveaxis(ha[:, 1:, :], 0, 1)[None])
        power = np.sum(np.abs(x) ** 2, -1)  # (K_design, S, K_bins)
        det = np.argmax(np.where(np.isfinite(power), power, -1), -1)  # (K_design, S)
        if bins is None:
            k = det[HALF_BINS, steps]  # design at the set range's bin, see what is detected
            for _ in range(4):  # redesign at the reported bin until they agree
                k = det[k, steps]
        else:
            k = np.asarray(bins)[:, p]
        kbin[:, p] = k
        consistent[:, p] = det[k, steps] == k
        pw = np.sort(np.where(np.isfinite(power[k, steps]), power[k, steps], 0.0), -1)
        margin[:, p] = pw[:, -1] / np.maximum(pw[:, -2], 1e-300)
        amps[:, p] = np.stack([a_i[k, steps], a_j[k, steps]], -1)
        snaps.append(x[k, steps])  # (S, K_bins, V)
    x = np.stack(snaps, 1)  # (S, P, K_bins, V)
    sigma = np.zeros(n_s)
    r0 = np.array([_range_bin(setup.scene, t.range_m) for t in targets])
    return SweepResult(deltas, x, kbin, amps, r0, consistent, margin, sigma,
                       np.asarray(alphas, float), st)




def place_probes(setup, paths, nominal, channels: PairChannels, ranges, alphas, window_s,
                 offsets_bins=PLACEMENT_OFFSETS_BINS) -> np.ndarray:
    """Probe ranges (P,) moved within a range bin so that over the delays ``window_s`` the
    design and the detection agree on each probe's bin with the largest power margin
    (``probes.place_in_bins``): the sweep curve stays on one bin, continuous, around the
    coherence point (``channels``: as :func:`phasor_sweep`'s)."""
    def margin(r):
        res = _sweep_designs(setup, paths, nominal, channels,
                             [TargetConfig(float(x)) for x in r], alphas, window_s)
        return np.min(np.where(res.consistent, res.margin, 0.0), axis=0)
    return place_in_bins(setup.scene, ranges, margin, offsets_bins)


def chain_errors(setup, paths, pair, targets, res: SweepResult, base_offsets, frames, seed
                 ) -> tuple[np.ndarray, np.ndarray]:
    """The same steps through the full ADC-cube chain (synthesis, range-Doppler, CFAR,
    angle): signed probe-angle errors (S, P) (NaN: not detected) and the detected candidate
    bins (S, P) (-1: not detected), with the amplitudes of ``res`` (the phasor model's
    design for the bin it predicts the RuT detects)."""
    scene = setup.scene
    base = [(float(requested_delay(scene, t.range_m)) + base_offsets[0],
             float(requested_delay(scene, t.range_m)) + base_offsets[1]) for t in targets]
    n_s, n_p = res.bin_index.shape
    err = np.full((n_s, n_p), np.nan)
    got = np.full((n_s, n_p), -1)
    for s_, d in enumerate(res.delta_tau_s):
        prog = probe_program(res.amplitudes[s_], pair, base, float(d))
        step_seed = np.random.SeedSequence([int(seed) % 2 ** 32,
                                            int(round(d * 1e15)) + 2 ** 40])
        rd, det = simulate_detect(setup, paths, prog, step_seed, frames)
        for p, t in enumerate(targets):
            k = nearest_detection(det, rd, t.range_m)
            if k is not None:
                err[s_, p] = det.angle_rad[k] - res.alphas[p]
                got[s_, p] = int(det.range_bin[k]) - res.range_bin0[p] + HALF_BINS
    return err, got


class PhasorProbes:
    """The probes of a pair on an arc (D = 1) as the sweep measures them: two targets at the
    probe angles (``probes.probe_angles``: a quarter and three quarters of the pair's span),
    their amplitudes designed at every step for the bin the RuT detects, evaluated on the
    phasor model (``full_chain``: the same designs detected through the ADC-cube chain,
    :func:`chain_errors`). Its noise is known to the model: the frames a sweep needs are
    predicted by Monte-Carlo before it is measured. One random stream per calibration, in
    the order the sweep draws from it.

    ``alphas`` (2,) rad: other probe angles (default: from the front ends' measured angles)."""

    dims = 1
    predicts_noise = True
    fine_step_s = FINE_STEP_S  # the model evaluates every step at once: fine steps are cheap

    def __init__(self, setup: Setup, paths: Paths, pair, probe: FrontEndProbe,
                 base_offsets=(0.0, 0.0), seed: int = 0, full_chain: bool = False,
                 alphas=None):
        i, j = pair
        self.setup, self.paths, self.pair = setup, paths, (int(i), int(j))
        self.base_offsets = (float(base_offsets[0]), float(base_offsets[1]))
        self.seed, self.full_chain = int(seed), bool(full_chain)
        self.alphas = np.asarray(probe_angles(probe.angle_rad[i], probe.angle_rad[j])
                                 if alphas is None else alphas, float)
        self.nominal = nominal_model(setup, paths)
        self.gain_correction = (probe.gain_correction[i], probe.gain_correction[j])
        self.ranges = probe_ranges(setup, 2)
        self.period_s = 1.0 / float(if_phase_slope_hz(setup.scene,
                                                      probe_total_delay(setup, self.ranges)))
        self.noisy = adds_noise(setup.scene)
        self.method = "full-chain" if full_chain else "phasor"
        self._rng = np.random.default_rng(np.random.SeedSequence([self.seed % 2 ** 32, 1713]))
        self._last = None  # (deltas, SweepResult) of the last sweep: measured once
        self._j_phase = None  # the reference's channel J phase over the nominal's (reference)

    @property
    def targets(self) -> list[TargetConfig]:
        return [TargetConfig(float(r)) for r in self.ranges]

    @property
    def channels(self) -> PairChannels:
        """The pair's channels as the sweep sets them (:class:`PairChannels`)."""
        return PairChannels(self.pair, self.base_offsets, self.gain_correction, self._j_phase)

    @property
    def probe_angles_deg(self) -> tuple:
        return tuple(float(np.degrees(a)) for a in self.alphas)

    def sweep(self, deltas) -> SweepResult:
        """The phasor model's spectra at the delays ``deltas`` (:func:`phasor_sweep`)."""
        d = np.atleast_1d(np.asarray(deltas, float))
        if self._last is None or not np.array_equal(self._last[0], d):
            self._last = (d, phasor_sweep(self.setup, self.paths, self.nominal,
                                          self.channels, self.targets, self.alphas, d))
        return self._last[1]

    def measure(self, deltas, frames: int = 1, repeat: int = 0) -> np.ndarray:
        """Signed probe-angle errors (S, 2) (rad; NaN: not detected) at ``frames`` coherently
        averaged frames per step."""
        res = self.sweep(deltas)
        if self.full_chain:
            return chain_errors(self.setup, self.paths, self.pair, self.targets, res,
                                self.base_offsets, frames, self.seed)[0]
        return res.errors(frames, self._rng if self.noisy else None)

    def frame_noise_deg(self, grid) -> float:
        """The predicted one-frame probe-angle noise over the sweep ``grid`` (deg)."""
        return predicted_angle_noise(self.sweep(grid), self.seed) if self.noisy else 0.0

    def predicted_scatter(self, deltas, frames: int, fit) -> float:
        """The fitted point's 1-sigma scatter (s) with one frame a step: ``MC_DRAWS`` noise
        realisations of the model at ``frames`` frames (where the fit is linear in the
        noise; drawn at one frame, the scatter compressed above ~30 ps and too few frames
        followed), each fitted (``fit``: errors -> (point, curves)), scaled to one frame."""
        draws = self.sweep(deltas).errors(frames, self._rng, MC_DRAWS)
        return float(np.nanstd([fit(e)[0] for e in draws])) * np.sqrt(frames)

    def placed(self, window_s) -> "PhasorProbes":
        """These probes moved within their range bins so that design and detection agree on
        one bin over the delays ``window_s`` (:func:`place_probes`); the same random
        stream."""
        out = copy.copy(self)
        out.ranges = place_probes(self.setup, self.paths, self.nominal, self.channels,
                                  self.ranges, self.alphas, window_s)
        out._last = None
        return out

    def reference(self, phase_rad: float = 0.0) -> "PhasorProbes":
        """The same probes on the phasor model of the nominal setup, the sweep's reference
        (``steps.reference_setup``: noiseless, channel J given the hardware phase
        ``phase_rad``): what the sweep's fit gives where the coherence point is known
        (``sweep.run_sweep`` subtracts its offset: 9 ps on the 86-element cascade at 3 m,
        inside its far field)."""
        out = reference_probes(self, phase_rad)
        out.full_chain, out.method = False, "phasor"
        # the nominal setup but for channel J's phase: its models are the nominal's, turned
        nominal_phase = self.nominal[0].scene.rts.front_ends[self.pair[1]].phase_offset_rad
        out._j_phase = (out.setup.scene.rts.front_ends[self.pair[1]].phase_offset_rad
                        - nominal_phase)
        out._rng = np.random.default_rng(np.random.SeedSequence([self.seed % 2 ** 32, 1713]))
        out._last = None
        return out

    def fit_columns(self, e):
        """The columns the fit uses, both probes' angle errors, and which are odd: none (on an
        arc each is even about the coherence point, ``fit`` module doc)."""
        return np.arange(len(self.ranges)), np.zeros(len(self.ranges), bool)

    def sweep_phase(self, deltas):
        """What each step adds to channel J beyond its offset, per column
        (``steps.sweep_phase``)."""
        return sweep_phase(self.setup, self.ranges, deltas, self.base_offsets, self.period_s)

    def confirm(self, delta_s: float, frames: int) -> float:
        """The RMS probe error (deg) at ``delta_s`` through the full ADC-cube chain."""
        res = self.sweep([delta_s])
        e = chain_errors(self.setup, self.paths, self.pair, self.targets, res,
                         self.base_offsets, frames, self.seed)[0]
        return float(rms_error_deg(e)[0])

    def phase(self, continuous: Setup, delta_s: float) -> float:
        """The pair's phase mismatch (rad) at the probe angles at channel J's offset
        ``delta_s`` on the continuous delay model ``continuous`` (``steps.
        continuous_delay_setup``), circular mean over the probes at their set ranges: zero
        at the coherence point (``sweep.coherence_point``). Each probe's base delays are
        those the RTS realises (``rts.realised_delay``)."""
        rts = self.setup.scene.rts
        z = 0j
        for r in probe_ranges(self.setup, 2):
            tau = float(requested_delay(self.setup.scene, r))
            o_i, o_j = (float(realised_delay(tau + b, rts.f_s_hz, rts.fractional_delay,
                                             rts.fractional_delay_step_s)) - tau
                        for b in self.base_offsets)
            m = ChannelModel.build(continuous, self.paths, self.pair, TargetConfig(float(r)),
                                   (o_i, o_j + delta_s))
            z += np.exp(1j * float(m.pair_phase(self.alphas)))
        return float(np.angle(z))
