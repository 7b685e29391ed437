"""Two-channel synthesis of an arbitrary angle of arrival (paper section "Arbitrary Angle of
Arrival", eqs. 17-23).

Two adjacent channels I, J generate the same range and Doppler; their amplitude ratio
``rho = A_J / A_I`` steers the beamformer peak between the two front ends. Three modes:

``paper``
    eq. (22)/(23) as printed: g_q is the derivative of sinc((sin theta_q - sin alpha)/2), and
    the ratio follows from A_I g_I + A_J g_J = 0, i.e. ``A_I / A_J = -g_J / g_I`` (the printed
    eq. 23 drops the minus sign; between the beams the ratio is positive only with it). The
    sinc is not the beam of an N_A-element array, which costs ~0.3 deg mid-span.
``array-factor``
    the same condition with the true array factor ``sin(N_A pi u / 2) / sin(pi u / 2)``,
    ``u = sin theta_q - sin alpha`` (lambda/2 spacing): exact in the ideal far field.
``exact``
    ``rho`` solved numerically so that the RuT's own beamformer output -- from the per-element
    geometry through the windowed range/Doppler DFTs (``radar.phasors``) -- peaks at the set
    angle: near field, Rx/Tx separation, real element positions, windowing, calibration delay.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from ..geometry import Setup
from ..paths import Paths
from ..radar.phasors import bin_response
from ..radar.processing import angle_spectrum, estimate_angles, tdm_compensate
from ..registry import SYNTHESIS_MODES
from ..rts import RtsProgram, channel_echoes, nominal_link_gain, requested_delay, target_amplitude
from ..scene import TargetConfig
from scipy.constants import c

__all__ = ["MODES", "g_paper", "array_factor", "ratio_paper", "ratio_array_factor", "PairModel",
           "AngleUnreachable"]

MODES = SYNTHESIS_MODES  # the registry (rtsgeom/registry.py) lists every AoA mode once


class AngleUnreachable(ValueError):
    """The set angle lies outside what the front-end pair can synthesize."""


def g_paper(theta, alpha):
    """Paper eq. (22): derivative substitute of sinc((sin theta - sin alpha) / 2).

    Near u = sin theta - sin alpha = 0 the two terms cancel catastrophically; there its series
    -u/6 + u^3/240 is used."""
    u = np.asarray(np.sin(theta) - np.sin(alpha), float)
    small = np.abs(u) < 1e-3
    us = np.where(small, 1.0, u)
    exact = 2 * np.cos(us / 2) / us - 4 * np.sin(us / 2) / us ** 2
    return np.where(small, -u / 6 + u ** 3 / 240, exact)


def ratio_paper(theta_i, theta_j, alpha):
    """A_J / A_I from eq. (23) with the sign fixed: A_I g_I + A_J g_J = 0."""
    return -g_paper(theta_i, alpha) / g_paper(theta_j, alpha)


def array_factor(u, n: int):
    """Normalised array factor of n elements at lambda/2: sin(n pi u/2) / (n sin(pi u/2))."""
    u = np.asarray(u, float)
    den = n * np.sin(np.pi * u / 2)
    small = np.abs(den) < 1e-12
    return np.where(small, 1.0, np.sin(n * np.pi * u / 2) / np.where(small, 1.0, den))


def ratio_array_factor(theta_i, theta_j, alpha, n: int, h: float = 1e-6):
    """A_J / A_I with the true array factor: A_I AF_I'(alpha) + A_J AF_J'(alpha) = 0."""
    def d_af(theta):
        return (array_factor(np.sin(theta) - np.sin(alpha + h), n)
                - array_factor(np.sin(theta) - np.sin(alpha - h), n)) / (2 * h)
    return -d_af(theta_i) / d_af(theta_j)


@dataclass(frozen=True)
class PairModel:
    """The modelled RuT output of one front-end pair for one target (range, velocity).

    Build it on the *nominal* setup (``geometry.nominal_setup``): the design knows the setup
    as drawn, not its mounting errors.

    ``responses[k, q, v]``: the spectrum at candidate range bin k (the set range's bin and its
    neighbours, at the target's Doppler bin) of channel q in (I, J) programmed with unit
    amplitude, its delay (channel J with ``delta_tau_s``) and Doppler, through the exact paths.
    """

    setup: Setup
    pair: tuple[int, int]
    responses: np.ndarray  # (K, 2, V)
    doppler_hz: float
    unit_gain: float  # program amplitude of one channel that gives the target's amplitude

    @classmethod
    def build(cls, setup: Setup, paths: Paths, pair: tuple[int, int], target: TargetConfig,
              delta_tau_s: tuple[float, float] = (0.0, 0.0)) -> "PairModel":
        """``delta_tau_s``: the calibration delay offsets of channels I and J."""
        scene, radar = setup.scene, setup.scene.radar
        i, j = pair
        lam = setup.rut.wavelength_m
        f_d = 2 * radar.f_c_hz * target.velocity_mps / c
        tau = float(requested_delay(scene, target.range_m))
        prog = RtsProgram.build([0, 1], [i, j], [tau + delta_tau_s[0], tau + delta_tau_s[1]],
                                [f_d, f_d], [1.0, 1.0])
        ech = channel_echoes(setup, paths, prog)
        ech = ech.select(ech.kind == 0)  # ghosts land bins away
        rbin = target.range_m * 2 * radar.slope_hz_per_s / c * radar.samples_per_chirp / radar.adc_rate_hz
        r0 = int(np.round(rbin))
        rbins = np.array([r0 - 1, r0, r0 + 1]) % radar.samples_per_chirp
        nu = f_d  # slow-time frequency per TDM cycle equals f_D
        dbin = int(np.round(nu * radar.tdm_cycle_s * radar.chirps_per_tx)) + radar.chirps_per_tx // 2
        dbin %= radar.chirps_per_tx
        resp = bin_response(ech, radar, setup.rut, rbins, np.full(3, dbin))  # (K, E, V)
        per_q = np.stack([resp[:, ech.target == 0].sum(1), resp[:, ech.target == 1].sum(1)], 1)
        amp = target_amplitude(target.range_m, target.rcs_m2, lam) / nominal_link_gain(scene, lam)
        return cls(setup, pair, per_q, f_d, float(amp))

    def snapshot(self, rho, phase=0.0) -> np.ndarray:
        """Spectrum of the combined target at its strongest candidate bin, (..., V)."""
        rho = np.asarray(rho, float)
        x = self.responses[:, 0] + (rho[..., None, None] * np.exp(1j * phase)) * self.responses[:, 1]
        k = np.argmax(np.sum(np.abs(x) ** 2, axis=-1), axis=-1)  # (...)
        x = np.take_along_axis(x, k[..., None, None], axis=-2)[..., 0, :]
        radar, rut = self.setup.scene.radar, self.setup.rut
        return tdm_compensate(x, self.doppler_hz, rut, radar)

    def angle(self, rho, phase=0.0) -> np.ndarray:
        """Detected angle (rad) of the combined target for amplitude ratio(s) rho."""
        return estimate_angles(self.snapshot(rho, phase), self.setup.rut, self.setup.scene.radar)

    def coherent_phase(self, alpha) -> float:
        """Phase to give channel J so both channels' beamformer outputs add in phase at the
        angle(s) ``alpha`` (the circular mean over several): what the phase calibration
        establishes when its probes sit at those angles."""
        radar, rut = self.setup.scene.radar, self.setup.rut
        k = 1  # the set range's bin
        snaps = tdm_compensate(self.responses[k], self.doppler_hz, rut, radar)
        x = snaps[:, rut.azimuth_mask]
        steer = np.exp(1j * 2 * np.pi / rut.wavelength_m * np.outer(
            rut.virtual_local[rut.azimuth_mask, 0], np.sin(np.atleast_1d(alpha))))
        b = x @ steer  # (2, A)
        z = b[0] * np.conj(b[1])
        return float(np.angle(np.sum(z / np.maximum(np.abs(z), 1e-300))))

    def solve(self, alpha: float, phase: float = 0.0, log_span: float = 12.0) -> float:
        """The ratio rho = A_J / A_I that puts the detected angle at ``alpha`` (rad)."""
        lo, hi = self.angle(np.exp(-log_span), phase), self.angle(np.exp(log_span), phase)
        if not (min(lo, hi) <= alpha <= max(lo, hi)):
            raise AngleUnreachable(
                f"angle {np.degrees(alpha):.4f} deg is outside the span this front-end pair "
                f"can synthesize [{np.degrees(min(lo, hi)):.4f}, {np.degrees(max(lo, hi)):.4f}] deg")
        f = lambda x: float(self.angle(np.exp(x), phase)) - alpha  # noqa: E731
        return float(np.exp(brentq(f, -log_span, log_span, xtol=1e-10)))

    def design(self, alpha: float, probes_rad) -> tuple[float, float, float]:
        """Programmed amplitudes (A_I, A_J) and ratio for a target at ``alpha`` (rad), for the
        one channel phase the calibration establishes with its probes at ``probes_rad``.

        Not the phase coherent at ``alpha`` itself: for a spacing beyond the beam's first null
        (lambda / d_A) that phase flips by pi near the span's ends and the design fails there.
        """
        phase = self.coherent_phase(probes_rad)
        rho = self.solve(alpha, phase)
        a_i, a_j = self.amplitudes(rho, alpha, phase)
        return a_i, a_j, rho

    def amplitudes(self, rho: float, alpha: float, phase: float = 0.0) -> tuple[float, float]:
        """Program amplitudes (A_I, A_J) with ratio rho, scaled so the combined beamformer peak
        is as strong as one channel alone at its own peak (the target keeps its RCS)."""
        radar, rut = self.setup.scene.radar, self.setup.rut
        snap = self.snapshot(rho, phase)
        p_sum = angle_spectrum(snap, rut, radar, np.array([alpha]))[0]
        single = self.snapshot(0.0)
        p_one = angle_spectrum(single, rut, radar,
                               np.array([estimate_angles(single, rut, radar)]))[0]
        scale = self.unit_gain * np.sqrt(p_one / max(p_sum, 1e-300))
        return scale, scale * rho
