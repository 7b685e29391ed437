"""The probes of a pair in the RuT's own D-dimensional beamformer, detected through the chain.

A phase is measured between two channels as on an arc (paper section "Calibration"): two
probe targets synthesized by the pair at amplitude ratios 1:3 and 3:1, designed at every step
on the nominal model, the probes' detected direction cosines compared with the design's. In
a 2-D beamformer (front ends side by side or stacked in elevation) each probe has an error in
each axis: its columns are (probe, along or across the pair's line). Every step is one full
ADC-cube simulation (no phasor model of a 2-D detection yet), so the noise is measured, not
predicted: from the fine sweep's own residual (``fit.fit_scatter``). As on an arc, the probes
are placed within their range bins for the fine sweep's window (:meth:`BeamProbes.placed`).
"""

from __future__ import annotations

import copy

import numpy as np

from ..geometry import Setup
from ..paths import Paths, nominal_model
from ..radar.processing import nearest_detection
from ..radar.steering import Steering
from ..rts.channels import RtsProgram, requested_delay
from ..scene import TargetConfig
from ..synthesis.model import ChannelModel
from .fit import crossing_columns, rms_error_deg
from .probes import (FrontEndProbe, if_phase_slope_hz, place_in_bins, probe_ranges,
                     probe_total_delay, simulate_detect)
from .steps import adds_noise, reference_probes, sweep_phase

__all__ = ["BeamProbes", "PROBE_RATIOS"]

PROBE_RATIOS = (1 / 3, 3.0)  # the probes' amplitude ratios A_J / A_I
AXIS_TOLERANCE_RAD = np.radians(10.0)  # a pair's line this close to an axis is an axis pair


class BeamProbes:
    """The probes of a pair (I, J) in the RuT's D-dimensional beamformer (module doc).

    Designed at every step, as on an arc: channel J's echo moves by c0 delta / 2 in range (a
    quarter bin over +-period/4) and its gain in the bin with it; a design fixed at delta =
    0 made each probe's error curve lopsided about the coherence point (its vertex 50 to 70
    ps off in elevation, sphere4). Channel I does not move with delta: its single-channel
    peak power (``ChannelModel.reference_power``) is found once a probe."""

    predicts_noise = False
    fine_step_s = 10e-12  # each step one full-chain simulation
    method = "full-chain"

    def __init__(self, setup: Setup, paths: Paths, pair, probe: FrontEndProbe,
                 base_offsets=(0.0, 0.0), seed: int = 0):
        i, j = pair
        self.setup, self.paths, self.pair = setup, paths, (int(i), int(j))
        self.base_offsets = (float(base_offsets[0]), float(base_offsets[1]))
        self.seed = int(seed)
        self.nominal = nominal_model(setup, paths)
        self.gain_correction = np.asarray(probe.gain_correction, float)[list(self.pair)]
        self.steering = Steering.auto(self.nominal[0].rut, setup.scene.radar)
        self.dims = self.steering.dims
        self.ranges = probe_ranges(setup, 2)
        self.period_s = 1.0 / float(if_phase_slope_hz(setup.scene,
                                                      probe_total_delay(setup, self.ranges)))
        self.noisy = adds_noise(setup.scene)
        self._p_ref: dict = {}
        self._base = [float(requested_delay(setup.scene, r)) for r in self.ranges]
        # the pair's own frame: along the line between its front ends (direction cosines)
        # and across it; a probe's error is even about the coherence point along, odd across
        u = self.nominal[0].fe_direction_cosines()[list(self.pair)]
        u = u[:, :1] if self.dims == 1 else u[:, :2]
        along = (u[1] - u[0]) / np.linalg.norm(u[1] - u[0])
        self.frame = (along[None] if self.dims == 1
                      else np.stack([along, [-along[1], along[0]]]))  # (D, D) rows
        # side by side or stacked in elevation (not across a cell's diagonal)
        self.axis_pair = bool(np.min(np.abs(along)) <= np.sin(AXIS_TOLERANCE_RAD))

    def _model(self, r: float, rho: float, delta_s: float):
        """A probe's design on the nominal model at range ``r``, amplitude ratio ``rho`` and
        channel J at ``delta_s``: the pair's model and its weights, coherent at the front
        ends' midpoint ``u_mid``."""
        nom, nom_paths = self.nominal
        cs = ChannelModel.build(nom, nom_paths, self.pair, TargetConfig(float(r)),
                                (self.base_offsets[0], self.base_offsets[1] + delta_s),
                                steering=self.steering)
        u_mid = cs.fe_directions().mean(axis=0)
        return cs, cs.weights([1.0, rho], cs.coherent_phases(u_mid[None])), u_mid

    def design(self, delta_s: float = 0.0):
        """Per probe: the programme amplitudes (2,) (the nominal model's design with channel
        J at ``delta_s``, coherent at the front ends' midpoint, the probe's amplitude ratio,
        times the gain correction) and the direction cosines (D,) the design puts it at."""
        designs, predicted = [], []
        for p, (r, rho) in enumerate(zip(self.ranges, PROBE_RATIOS)):
            cs, w, u_mid = self._model(r, rho, delta_s)
            u_pred = cs.direction_cosines(w, u_mid)
            if p not in self._p_ref:
                self._p_ref[p] = cs.reference_power()
            designs.append(cs.amplitudes(w, u_pred, self._p_ref[p]) * self.gain_correction)
            predicted.append(u_pred)
        return designs, predicted

    def bin_margin(self, ranges, window_s) -> np.ndarray:
        """Per probe at ``ranges`` (P,): the smallest power ratio, over channel J's delays
        ``window_s``, of the candidate range bin the design's target is strongest in (the
        bin the RuT detects it in, :meth:`ChannelModel.snapshot`) over the next strongest."""
        out = np.full(len(ranges), np.inf)
        for p, (r, rho) in enumerate(zip(ranges, PROBE_RATIOS)):
            for d in np.atleast_1d(window_s):
                cs, w, _ = self._model(r, rho, float(d))
                pw = np.sort(np.sum(np.abs(cs.combined(w)) ** 2, axis=-1))  # per bin
                out[p] = min(out[p], pw[-1] / max(pw[-2], 1e-300))
        return out

    @property
    def probe_angles_deg(self) -> tuple:
        _, predicted = self.design(0.0)
        if self.dims == 1:
            return tuple(float(np.degrees(np.arcsin(u[0]))) for u in predicted)
        return tuple(tuple(float(a) for a in np.degrees(self.steering.angles(u)))
                     for u in predicted)

    def _signed(self, delta: float, frames: int = 1, repeat: int = 0) -> np.ndarray:
        """The probes' detected direction-cosine errors (P * D,) at one step, along and
        across the pair's line (NaN: not detected), the coherent average of ``frames`` frames (``repeat`` > 0: an independent
        measurement of the same step, other noise)."""
        designs, predicted = self.design(delta)
        tg, fe, dl, amp = [], [], [], []
        for k, (a, b) in enumerate(zip(self._base, designs)):
            tg += [k, k]
            fe += list(self.pair)
            dl += [a + self.base_offsets[0], a + self.base_offsets[1] + delta]
            amp += list(b)
        prog = RtsProgram.build(tg, fe, dl, np.zeros(len(tg)), amp)
        step_seed = np.random.SeedSequence([self.seed % 2 ** 32, int(round(delta * 1e15))
                                            + 2 ** 40, self.pair[0], self.pair[1]]
                                           + ([int(frames)] if frames > 1 else [])
                                           + ([7919, int(repeat)] if repeat else []))
        rd, det = simulate_detect(self.setup, self.paths, prog, step_seed, frames)
        out = np.full((len(self.ranges), self.dims), np.nan)
        for p, (r, u_pred) in enumerate(zip(self.ranges, predicted)):
            k = nearest_detection(det, rd, r)
            if k is not None:
                out[p] = self.frame @ (_detected_u(self.steering, det, k) - u_pred)
        return out.ravel()

    def measure(self, deltas, frames: int = 1, repeat: int = 0) -> np.ndarray:
        """Signed direction-cosine errors (S, P * D) (NaN: not detected), ``frames``
        coherently averaged frames per step."""
        return np.array([self._signed(float(d), frames, repeat)
                         for d in np.atleast_1d(deltas)])

    def frame_noise_deg(self, grid) -> None:
        """Not predicted: measured on the fine sweep (module doc)."""
        return None

    def placed(self, window_s) -> "BeamProbes":
        """These probes moved within their range bins so that over the delays ``window_s``
        the bin the design's target is strongest in keeps the largest power margin over its
        neighbours (``probes.place_in_bins``, :meth:`bin_margin`), as on an arc. Unplaced,
        a probe whose two channels' echoes straddle a bin boundary (sphere4's side-by-side
        pair at 3 m: bins within 0.002 to 0.15 dB) was detected in either bin from step to
        step and its error jumped by 0.018 in direction cosine with the bin; the receiver
        noise moved which steps jumped, and the fit by 7 ps. Placed, the worst margins over
        the window rose from 0.012 and 0.09 dB to 5.0 and 2.9 dB."""
        out = copy.copy(self)
        out.ranges = place_in_bins(self.setup.scene, self.ranges,
                                   lambda r: self.bin_margin(r, window_s))
        out._p_ref = {}  # the single-channel peak power is the probe's range's
        out._base = [float(requested_delay(self.setup.scene, r)) for r in out.ranges]
        return out

    def reference(self, phase_rad: float = 0.0) -> "BeamProbes":
        """The same probes on the nominal setup as the sweep's reference
        (``steps.reference_setup``: noiseless, channel J given the hardware phase
        ``phase_rad``): what the sweep's fit gives where the coherence point is known
        (``sweep.run_sweep`` subtracts its offset)."""
        out = reference_probes(self, phase_rad)
        return out

    def fit_columns(self, e):
        """The columns the fit uses and which of them are odd (``fit`` module doc): the
        probes' errors along the pair's line (even about the coherence point) for a pair on
        an arc, side by side or stacked in elevation; for a pair across a cell's diagonal the
        errors across its line that cross zero over the sweep ``e`` (along it where none
        does)."""
        across = np.tile(np.arange(self.dims) == 1, len(self.ranges))
        along = np.flatnonzero(~across)
        odd = across & crossing_columns(e)
        if self.dims == 2 and not self.axis_pair and np.any(odd):
            return np.flatnonzero(odd), np.ones(int(odd.sum()), bool)
        return along, np.zeros(along.size, bool)

    def sweep_phase(self, deltas):
        """What each step adds to channel J beyond its offset (``steps.sweep_phase``), per
        column (probe, axis)."""
        extra, search = sweep_phase(self.setup, self.ranges, deltas, self.base_offsets,
                                    self.period_s)
        n = np.size(deltas)
        if extra is not None:
            extra = np.repeat(np.asarray(extra, float).reshape(n, -1), self.dims, axis=1)
        if search is not None:
            per_probe = search
            search = lambda t: np.repeat(np.asarray(per_probe(t), float),  # noqa: E731
                                         self.dims, axis=1)
        return extra, search

    def confirm(self, delta_s: float, frames: int) -> float:
        """The RMS probe error at ``delta_s`` (degrees of direction cosine)."""
        return float(rms_error_deg(self._signed(delta_s, frames)))

    def phase(self, continuous: Setup, delta_s: float) -> float:
        """The pair's phase mismatch (rad) at channel J's offset ``delta_s`` on the continuous
        delay model ``continuous``: the phase between the two channels' beam outputs at the
        probes' designed directions, circular mean over the probes; zero at the coherence
        point (``sweep.coherence_point``)."""
        _, predicted = self.design(0.0)
        z = 0j
        for r, u in zip(self.ranges, predicted):
            cs = ChannelModel.build(continuous, self.paths, self.pair, TargetConfig(float(r)),
                                    (self.base_offsets[0], self.base_offsets[1] + delta_s),
                                    steering=self.steering)
            b = cs.steering.beam(cs.phasors, np.atleast_2d(u))[:, 0]
            z += b[0] * np.conj(b[1]) / max(abs(b[0] * np.conj(b[1])), 1e-300)
        return float(np.angle(z))


def _detected_u(st: Steering, det, k) -> np.ndarray:
    if st.dims == 1:
        return np.array([np.sin(det.angle_rad[k])])
    return st.directions(np.array([det.angle_rad[k], det.elevation_rad[k]]))
