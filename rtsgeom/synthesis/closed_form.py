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

from ..geometry import Setup
from ..paths import Paths
from ..scene import TargetConfig
from .model import SOLVERS, ChannelModel
from ..errors import AngleUnreachable

__all__ = ["MODES", "g_paper", "array_factor", "ratio_paper", "ratio_array_factor", "array_factor_args", "PairModel",
           "AngleUnreachable"]

MODES = SOLVERS


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


def array_factor(u, n: int = 0, positions_wl=None, weights=None):
    """Normalised array factor: of ``n`` elements at lambda/2, sin(n pi u/2) / (n sin(pi u/2));
    or, with ``positions_wl`` (element positions in wavelengths, any spacing, sparse,
    non-uniform or repeated) and optional ``weights`` (the beamformer's taper per element),
    the real part of sum_k w_k exp(j 2 pi x_k u) / sum_k w_k about the weighted centroid (the
    same Dirichlet kernel for a filled untapered lambda/2 array; exact for a symmetric array
    and taper). This is the beamformer output of eq. (14) for one plane wave, u = sin theta -
    sin alpha."""
    u = np.asarray(u, float)
    if positions_wl is not None:
        x = np.asarray(positions_wl, float)
        w = np.ones_like(x) if weights is None else np.asarray(weights, float)
        x = x - np.sum(w * x) / np.sum(w)
        return np.cos(2 * np.pi * u[..., None] * x) @ w / np.sum(w)
    den = n * np.sin(np.pi * u / 2)
    small = np.abs(den) < 1e-12
    return np.where(small, 1.0, np.sin(n * np.pi * u / 2) / np.where(small, 1.0, den))


def ratio_array_factor(theta_i, theta_j, alpha, n: int = 0, h: float = 1e-6,
                       positions_wl=None, weights=None):
    """A_J / A_I with the true array factor: A_I AF_I'(alpha) + A_J AF_J'(alpha) = 0
    (``n`` lambda/2 elements, or the positions ``positions_wl`` and taper ``weights`` of
    :func:`array_factor`)."""
    def d_af(theta):
        return (array_factor(np.sin(theta) - np.sin(alpha + h), n, positions_wl, weights)
                - array_factor(np.sin(theta) - np.sin(alpha - h), n, positions_wl,
                               weights)) / (2 * h)
    return -d_af(theta_i) / d_af(theta_j)


def array_factor_args(steering) -> dict:
    """The keyword arguments of :func:`ratio_array_factor` that make its array factor the RuT's
    own azimuth beamformer (:class:`~rtsgeom.radar.steering.Steering`, D = 1): a filled,
    untapered lambda/2 row without repeated elements is the closed form in ``n``; anything
    else (a taper, repeated virtual elements such as the cascade's 144 on 86 positions, gaps,
    another spacing) its element positions and taper weights."""
    x = np.asarray(steering.positions_m)[:, 0] / steering.wavelength_m
    w = np.asarray(steering.taper, float)
    xs = np.sort(x)
    if (x.size > 1 and np.all(w == w[0])
            and np.allclose(np.diff(xs), 0.5, rtol=1e-9, atol=1e-12)):
        return {"n": int(x.size)}
    return {"positions_wl": x, "weights": w}


@dataclass(frozen=True)
class PairModel:
    """The front-end pair's view of :class:`~rtsgeom.synthesis.model.ChannelModel` (Q = 2): weights
    ``w = (1, rho e^{j phase})`` written as the ratio ``rho = A_J / A_I`` and J's phase.

    Build it on the *nominal* setup (``geometry.nominal_setup``): the design knows the setup
    as drawn, not its mounting errors. ``responses[k, q, v]`` (K, 2, V): the spectrum at
    candidate range bin k of channel q in (I, J) (``ChannelModel.responses``).
    """

    model: ChannelModel

    @classmethod
    def build(cls, setup: Setup, paths: Paths, pair: tuple[int, int], target: TargetConfig,
              delta_tau_s: tuple[float, float] = (0.0, 0.0)) -> "PairModel":
        """``delta_tau_s``: the calibration delay offsets of channels I and J."""
        return cls(ChannelModel.build(setup, paths, pair, target, delta_tau_s))

    setup = property(lambda self: self.model.setup)
    pair = property(lambda self: self.model.channels)
    responses = property(lambda self: self.model.responses)
    doppler_hz = property(lambda self: self.model.doppler_hz)
    unit_gain = property(lambda self: self.model.unit_gain)

    def _w(self, rho, phase=0.0) -> np.ndarray:
        return self.model.weights(np.asarray(rho, float)[..., None], (0.0, phase))

    def snapshot(self, rho, phase=0.0) -> np.ndarray:
        """Spectrum of the combined target at its strongest candidate bin, (..., V)."""
        return self.model.snapshot(self._w(rho, phase))

    def angle(self, rho, phase=0.0) -> np.ndarray:
        """Detected angle (rad) of the combined target for amplitude ratio(s) rho."""
        return self.model.direction(self._w(rho, phase))

    def coherent_phase(self, alpha) -> float:
        """Phase to give channel J so both channels' beamformer outputs add in phase at the
        angle(s) ``alpha`` (the circular mean over several): what the phase calibration
        establishes when its probes sit at those angles."""
        return float(self.model.coherent_phases(alpha)[1])

    def solve(self, alpha: float, phase: float = 0.0, log_span: float = 12.0,
              mode: str = "exact") -> float:
        """The ratio rho = A_J / A_I that puts the detected angle at ``alpha`` (rad)."""
        return self.model.solve_ratio(alpha, (0.0, phase), mode, log_span)

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
        scale = self.model.scale(self._w(rho, phase), alpha)
        return scale, scale * rho
