"""Synthesis with N channels in azimuth and elevation (issue 15; ``shared/design/
channel-sets.md``; Schoeder et al., "A Unified Model of Coherent Direction-of-Arrival Simulation
for Radar Target Simulators", IEEE TAES 2023).

:class:`ChannelSet` is :class:`~rtsgeom.synthesis.model.ChannelModel` seen through the beamformer the
RuT actually runs (``Steering.auto``: 2-D when its virtual array has elevation extent). A
target at direction cosines u* inside a cell of Q front ends gets one complex weight per channel
``w_q = a_q e^{j phi_q}`` (channel phases ``phi`` fixed: what the channels' delays give, or
what a calibration establishes); the amplitudes ``a`` (the strongest 1) are solved per mode:

``exact``
    peak matching on the modelled RuT output (per-element geometry, near field, windows, TDM
    compensation, calibration delays): the beamformer's peak at u* is D conditions on Q - 1
    free log-amplitudes (the strongest channel's fixed); Gauss-Newton with minimum-norm steps (pseudo-inverse of the D x
    (Q - 1) Jacobian) from the ``array-factor`` start, so the extra freedom (Q > D + 1: a
    quadrilateral in 2-D) stays at the closed form's choice. The 1-D pair (Q = 2, D = 1) is
    the same call and takes ``ChannelModel.solve``'s bracketing fast path.
``array-factor``
    the closed form in D dimensions for an ideal far field: channel q's beam is the array
    factor AF_q(u) = sum_v t_v e^{j k p_v . (u - u_q)} / sum_v t_v (u_q: the front end's
    direction cosines seen from the RuT); the peak condition
    ``d|B|^2/du = 0`` at u* with B real there is linear in a: ``G a = 0``,
    ``G_dq = Re(e^{j phi_q} dAF_q/du_d (u*))``, phi_q = -arg AF_q(u*) (coherent at u*). Of the
    solutions the one with the largest peak power per unit norm, ``a = P_null(G) f``,
    f_q = |AF_q(u*)| (for a triangle the null space is one line; for the pair it is paper eq.
    22/23 with the true array factor, ``aoa.synthesis.ratio_array_factor``).
``paper``
    the pair only (eq. 23); with more channels it is not defined.
"""

from __future__ import annotations

import dataclasses
import itertools
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..geometry import Setup
from ..paths import Paths
from ..radar.steering import Steering
from ..scene import TargetConfig
from .model import SOLVERS, ChannelModel
from ..errors import AngleUnreachable

__all__ = ["ChannelSet", "closed_form_amplitudes", "target_direction"]


def target_direction(steering: Steering, target: TargetConfig) -> np.ndarray:
    """A target's set direction cosines (D,) for ``steering``."""
    el = getattr(target, "elevation_rad", 0.0)
    if steering.dims == 1:
        return np.array([np.sin(target.angle_rad)])
    return steering.directions(np.array([target.angle_rad, el]))


def closed_form_amplitudes(steering: Steering, u_fe, u_set, phases=None) -> np.ndarray:
    """The ``array-factor`` amplitudes a (Q,) (the largest 1) of channels at direction cosines
    ``u_fe`` (Q, D) synthesizing ``u_set`` (D,) (module docstring); ``phases`` (Q,): the
    channels' programmed phases, default coherent at ``u_set`` (given ones are taken as making
    the channels coherent there: B(u*) is rotated real by channel 0's phase)."""
    u_fe = np.asarray(u_fe, float)
    du = np.asarray(u_set, float)[None, :] - u_fe  # (Q, D)
    t = steering.taper
    e = t * steering.steer(du)  # (Q, V_s)
    af = e.sum(-1) / t.sum()
    d_af = 1j * (e @ steering.wavevector) / t.sum()  # (Q, D)
    phi = -np.angle(af) if phases is None else np.asarray(phases, float)
    rot = np.exp(1j * (phi - np.angle(np.exp(1j * phi[0]) * af[0])))  # B(u*) real, channel 0
    g = np.real(rot[:, None] * d_af).T  # (D, Q)
    f = np.real(rot * af)
    a = f - g.T @ np.linalg.lstsq(g @ g.T, g @ f, rcond=None)[0]  # P_null(G) f
    if np.any(a < -1e-12 * np.abs(a).max()) and a.size > g.shape[0] + 1:
        # more channels than conditions and P_null f not all positive (near a corner of a
        # quadrilateral): of the sub-cells of D + 1 channels (its triangles) whose one
        # solution is non-negative, the one with the largest peak power per unit norm
        best, score = None, -np.inf
        for sub in itertools.combinations(range(a.size), g.shape[0] + 1):
            null = np.linalg.svd(g[:, sub])[2][-1]
            null = null * np.sign(null @ f[list(sub)] or 1.0)
            if np.all(null >= -1e-12) and null @ f[list(sub)] / np.linalg.norm(null) > score:
                best, score = (sub, null), null @ f[list(sub)] / np.linalg.norm(null)
        if best is not None:
            a = np.zeros(a.size)
            a[list(best[0])] = best[1]
    if np.max(a) <= 0:
        raise AngleUnreachable("the array-factor closed form gives no channel a weight here")
    a = a / np.max(a)
    if np.any(a < -1e-9):
        raise AngleUnreachable(f"the array-factor closed form needs a negative amplitude "
                               f"{a.min():.3g} here: the direction is outside the cell")
    return np.clip(a, 0.0, None)


@dataclass(frozen=True)
class ChannelSet:
    """Channels ``model.channels`` synthesizing one target, seen by the RuT's own beamformer
    (``model.steering`` = ``Steering.auto``)."""

    model: ChannelModel
    fe_u: np.ndarray | None = None  # (Q, D) front-end directions for the closed form (None:
    #                                  the geometric ones seen from the RuT)

    @classmethod
    def build(cls, setup: Setup, paths: Paths, channels, target: TargetConfig,
              delta_tau_s=None) -> "ChannelSet":
        m = ChannelModel.build(setup, paths, channels, target, delta_tau_s)
        st = Steering.auto(setup.rut, setup.scene.radar)
        return cls(m if st.dims == m.steering.dims else dataclasses.replace(m, steering=st))

    @property
    def steering(self) -> Steering:
        return self.model.steering

    @property
    def dims(self) -> int:
        return self.steering.dims

    @property
    def count(self) -> int:
        return self.model.count

    def fe_directions(self) -> np.ndarray:
        """The channels' front ends' direction cosines (Q, D) seen from the RuT (geometric)."""
        if self.fe_u is not None:
            return np.asarray(self.fe_u, float)
        u = self.model.setup.fe_direction_cosines()[list(self.model.channels)]
        return u[:, :1] if self.dims == 1 else u

    def weights(self, amplitudes, phases=None) -> np.ndarray:
        """w = a e^{j phi} (..., Q)."""
        ph = np.zeros(self.count) if phases is None else np.asarray(phases, float)
        return np.asarray(amplitudes, float) * np.exp(1j * ph)

    def direction_cosines(self, w, u0=None) -> np.ndarray:
        """Direction cosines (..., D) of the beamformer's (global) peak for weights w (..., Q):
        Newton from ``u0`` (default: the grid's maximum) with the global check."""
        snap = self.model.snapshot(w)
        if u0 is None:
            if self.dims == 1:
                return np.sin(self.steering.search(snap))[..., None]
            return self.steering.directions(self.steering.search(snap))
        return self.steering.peak(snap, u0)[0]

    def direction(self, w) -> np.ndarray:
        """Detected azimuth (...,) (D = 1) or (azimuth, elevation) (..., 2) rad."""
        return self.steering.search(self.model.snapshot(w))

    def coherent_phases(self, u) -> np.ndarray:
        """Channel phases (Q,) that make all channels' beam outputs add in phase with channel
        0's at direction cosines ``u`` (P, D) (circular mean over P)."""
        b = self.steering.beam(self.model.phasors, np.atleast_2d(u))  # (Q, P)
        z = b[:1] * np.conj(b)
        return np.angle(np.sum(z / np.where(np.abs(z) > 0, np.abs(z), 1.0), axis=-1))

    def solve(self, u_set, phases=None, mode: str = "exact", tol: float = 1e-10,
              max_iter: int = 30) -> np.ndarray:
        """Weights w (Q,) whose beamformer peak is at ``u_set`` (D,) (the pair: w_0 = 1; else
        the strongest channel's amplitude 1)."""
        if mode not in SOLVERS:
            raise ParameterError(f"mode {mode!r}: must be one of {', '.join(SOLVERS)}")
        u_set = np.atleast_1d(np.asarray(u_set, float))
        if self.count == 2 and self.dims == 1:  # the pair: ChannelModel's fast path
            return self.model.solve(float(np.arcsin(u_set[0])), phases, mode)
        if mode == "paper":
            raise ParameterError("mode 'paper': eq. 23 is defined for a pair of front ends in "
                             "azimuth only; use exact or array-factor")
        if mode == "array-factor":
            a0 = closed_form_amplitudes(self.steering, self.fe_directions(), u_set, phases)
            return self.weights(a0, phases)
        # The start of the peak matching: the closed form with the phases the weighted
        # channels have at u_set relative to coherence there (the given phases are programme
        # phases on this model, whose channels carry their own: delays, calibration offsets;
        # handed to the closed form as they are, a calibrated channel 87 deg off its
        # geometric phase (a 0.5 mm radial offset) gave a start the Gauss-Newton did not
        # recover from, sphere4), then coherent; each start tried in turn until one reaches
        # u_set.
        starts = []
        for ph in ((None if phases is None else self._coherence_offsets(u_set, phases)), None):
            try:
                starts.append(closed_form_amplitudes(self.steering, self.fe_directions(), u_set,
                                                     ph))
            except AngleUnreachable:
                pass
        # a channel the closed form leaves at 0 stays there (its log-amplitude's column of
        # the Jacobian vanishes): the same starts with every channel at 0.1 or more next
        # (sphere4 with a 180 deg phase on a front end, (5, 3) deg: the triangle's start
        # stopped 0.008 off in elevation), then equal amplitudes
        starts += [np.maximum(a, 0.1) for a in starts] + [np.ones(self.count)]
        for n, a0 in enumerate(starts):
            try:
                return self.weights(self._peak_match(u_set, a0, phases, tol, max_iter), phases)
            except AngleUnreachable:
                if n == len(starts) - 1:
                    raise

    def _coherence_offsets(self, u_set, phases) -> np.ndarray:
        """Phases (Q,) for :func:`closed_form_amplitudes` that put each channel as far from
        coherence with channel 0 at ``u_set`` as the weighted model's channels are: its
        array factor's coherent phase ``-arg AF_q(u_set)`` plus the model's deviation
        ``phi_q + arg b_q(u_set) - phi_0 - arg b_0(u_set)`` (b: the channels' beams)."""
        st = self.steering
        u_set = np.atleast_1d(np.asarray(u_set, float))
        b = st.beam(self.model.phasors, u_set[None])[:, 0]  # (Q,)
        dev = np.asarray(phases, float) + np.angle(b)
        dev = np.angle(np.exp(1j * (dev - dev[0])))
        af = np.sum(st.taper * st.steer(u_set[None, :] - self.fe_directions()), -1)
        return -np.angle(af) + dev

    def _peak_match(self, u_set, a0, phases, tol, max_iter) -> np.ndarray:
        ref = int(np.argmax(a0))  # the strongest channel keeps amplitude 1
        free = np.flatnonzero(np.arange(a0.size) != ref)
        x = np.log(np.maximum(a0[free], 1e-6))  # log-amplitudes of the others

        def amps(xx):
            a = np.ones(a0.size)
            a[free] = np.exp(np.clip(xx, -40.0, 40.0))  # beyond: a diverging (unreachable) fit
            return a

        def resid(xx):
            return self.direction_cosines(self.weights(amps(xx), phases), u_set) - u_set

        r = resid(x)
        h = 1e-5
        for _ in range(max_iter):
            if np.max(np.abs(r)) < tol:
                break
            jac = np.stack([(resid(x + h * e) - r) / h for e in np.eye(x.size)], axis=-1)
            step = -np.linalg.pinv(jac) @ r  # minimum-norm Gauss-Newton step
            for damp in (1.0, 0.5, 0.25, 0.125, 0.0625):
                r_new = resid(x + damp * step)
                if np.linalg.norm(r_new) < np.linalg.norm(r):
                    x, r = x + damp * step, r_new
                    break
            else:
                break
        if np.max(np.abs(r)) > 1e3 * tol:
            raise AngleUnreachable(
                f"direction cosines {np.round(u_set, 6).tolist()}: the channels "
                f"{list(self.model.channels)} cannot put the beamformer's peak there (closest "
                f"{np.round(u_set + r, 6).tolist()}): outside what this cell can synthesize")
        return amps(x)

    def reference_power(self) -> float:
        """Beamformer power of channel 0 alone at its own (global) peak: the level
        :meth:`amplitudes` keeps. Depends on channel 0 only, so a sweep that moves only
        other channels' delays may compute it once and pass it in (``ncal``'s 2-D sweep:
        one 2-D grid search a probe instead of one a step)."""
        single = self.model.snapshot(np.eye(self.count)[0])
        u_one = self.direction_cosines(np.eye(self.count)[0])
        return float(self.steering.power(single, np.atleast_2d(u_one))[0])

    def amplitudes(self, w, u_set, p_ref: float | None = None) -> np.ndarray:
        """Programme amplitudes (Q,): ``|w|`` scaled so the combined beamformer peak (at
        ``u_set``) is as strong as channel 0 alone at its own peak (the target keeps its RCS);
        ``p_ref``: that single-channel power (:meth:`reference_power`) when known."""
        st = self.steering
        u_set = np.atleast_2d(np.asarray(u_set, float))
        p_sum = st.power(self.model.snapshot(w), u_set)[0]
        p_one = self.reference_power() if p_ref is None else p_ref
        return self.model.unit_gain * np.sqrt(p_one / max(p_sum, 1e-300)) * np.abs(w)
