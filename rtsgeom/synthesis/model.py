"""The modelled RuT output of a set of RTS channels synthesizing one target, and the channel
weights that put it at a set direction (paper section "Arbitrary Angle of Arrival", eqs. 14-23).

:class:`ChannelModel` holds, for channels q = 0..Q-1 each programmed with unit amplitude, the
target's delay and Doppler, the spectrum at the target's candidate range bins (the set range's
bin and its neighbours, at the target's Doppler bin) per virtual element, ``responses[k, q, v]``
(``radar.phasors.bin_response`` through the exact or ray-traced paths: near field, Rx/Tx
separation, real element positions, windows), and the RuT's beamformer
(:class:`~rtsgeom.radar.steering.Steering`: the azimuth row, D = 1, or azimuth x elevation,
D = 2). Programme weights ``w`` (Q,) (amplitude times e^{j phase}) combine them linearly::

    snapshot(w) = sum_q w_q H[k*, q, :]       (TDM-compensated, strongest candidate bin k*)
    direction(w) = the beamformer's peak of snapshot(w)

:meth:`ChannelModel.solve` finds the weights for a set direction, for fixed channel phases
(what the channels' delays give, or what a calibration establishes), per mode:

``exact``
    peak matching on the modelled RuT output: the beamformer's peak at the set direction is
    D conditions on the Q - 1 free log-amplitudes (the strongest channel's fixed at 1).
    The front-end pair (Q = 2, D = 1, ``w = (1, rho e^{j phase})``) has it in closed form
    (:mod:`.pair`: the design for the bin the RuT detects; a bracketing root finder on the
    searched peak where no bin has one); any other set of channels takes Gauss-Newton with
    minimum-norm steps from the ``array-factor`` start, so that extra freedom (Q > D + 1: a
    quadrilateral in 2-D) stays at the closed form's choice.
``array-factor``
    the closed form for an ideal far field in D dimensions (:mod:`.closed_form`; for the pair
    paper eqs. 22/23 with the true array factor of the RuT's array).
``paper``
    the pair only: paper eq. (23) as printed (with its sign fixed).

:meth:`ChannelModel.perturbed` applies mounting errors of the front ends at phasor level (the
changed two-way air delay's phase and free-space amplitude), which is what the tolerance study
draws.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy.constants import c

from ..errors import AngleUnreachable, ParameterError, SceneError
from ..geometry import Setup
from ..geometry.arrays import posed_positions
from ..geometry.frontends import ModuleLayout, antenna_positions
from ..paths import Paths
from ..paths.exact import leg_delays
from ..radar.phasors import bin_response
from ..radar.processing import tdm_compensate
from ..radar.steering import Steering
from ..rts.channels import (KIND_DIRECT, RtsProgram, channel_echoes, nominal_link_gain,
                            requested_delay, target_amplitude)
from ..scene import TargetConfig
from ..scene.registry import SYNTHESIS_MODES
from .closed_form import array_factor_args, closed_form_amplitudes, ratio_array_factor, ratio_paper
from .pair import JUMP_RAD, design_at_detected_bin, design_ratio

__all__ = ["ChannelModel", "SOLVERS", "target_direction", "require_air_path_compensation"]

SOLVERS = SYNTHESIS_MODES  # the registry lists every AoA mode once (scene/registry.py)


def require_air_path_compensation(scene) -> None:
    """:class:`~rtsgeom.scene.scene.SceneError` (one line, exit 2) for an RTS that does not subtract
    the air path (``rts.compensate_air_path = false``): its echoes appear about R_c beyond the
    set range (``rts.requested_delay``), and the synthesis models, the calibration and the
    studies built on them look for each echo at its set range's bin. Not modelled yet; a plain
    program of the RTS (``run --amplitudes nearest``) is."""
    if not scene.rts.compensate_air_path:
        raise SceneError(
            "rts.compensate_air_path = false: the AoA synthesis, its calibration and the "
            "studies built on them (calibrate, run and adc with synthesized amplitudes, "
            "tolerance, design, nearfield, linearity) assume the RTS subtracts the air path, "
            "so that each echo lies at its set range's bin; without it the echoes lie about "
            f"R_c = {scene.rts.arc_radius_m:g} m further, which they do not model yet: set it "
            "to true, or run the plain program (run --amplitudes nearest)")


def target_direction(steering: Steering, target: TargetConfig) -> np.ndarray:
    """A target's set direction cosines (D,) for ``steering``."""
    el = target.elevation_rad
    if steering.dims == 1:
        return np.array([np.sin(target.angle_rad)])
    return steering.directions(np.array([target.angle_rad, el]))


@dataclass(frozen=True)
class ChannelModel:
    """The modelled RuT output of channels ``channels`` (Q,) for one target.

    Build it on the *nominal* setup (``geometry.nominal_setup``) for a design: the design
    knows the setup as drawn, not its mounting errors. Directions go in as direction cosines
    ``u`` (D,): ``sin(azimuth)`` for a RuT that beamforms in azimuth (D = 1), ``(sin az cos
    el, sin el)`` for one that beamforms in both (D = 2); :meth:`direction` returns the
    detected angles, :meth:`angles` converts.

    Attributes
    ----------
    setup, channels, responses, doppler_hz, unit_gain, range_m, steering, fe_u
        As the fields say (``responses[k, q, v]``: the module doc).
    """

    setup: Setup
    channels: tuple[int, ...]  # (Q,) front-end index per channel
    responses: np.ndarray  # (K, Q, V) candidate range bins, the set range's in the middle
    doppler_hz: float
    unit_gain: float  # program amplitude of one channel that gives the target's amplitude
    range_m: float
    steering: Steering
    fe_u: np.ndarray | None = None  # (Q, D) closed form's front-end directions (None: geometric)

    @classmethod
    def build(cls, setup: Setup, paths: Paths, channels, target: TargetConfig,
              delta_tau_s=None, half_bins: int = 1, steering: Steering | None = None
              ) -> "ChannelModel":
        """``delta_tau_s`` (Q,): the channels' calibration delay offsets (default zeros);
        ``half_bins``: candidate range bins on either side of the set range's bin (the
        calibration sweep moves channel J by up to ~2 bins: it asks for more); ``steering``:
        the RuT's beamformer (default the azimuth row; ``Steering.auto`` is the one the RuT
        runs, 2-D where it beamforms in elevation too)."""
        scene, radar = setup.scene, setup.scene.radar
        require_air_path_compensation(scene)
        ch = tuple(int(q) for q in channels)
        n_q = len(ch)
        dtau = np.zeros(n_q) if delta_tau_s is None else np.asarray(delta_tau_s, float)
        lam = setup.rut.wavelength_m
        f_d = 2 * radar.f_c_hz * target.velocity_mps / c
        tau = float(requested_delay(scene, target.range_m))
        prog = RtsProgram.build(list(range(n_q)), list(ch), list(tau + dtau), [f_d] * n_q,
                                [1.0] * n_q)
        ech = channel_echoes(setup, paths, prog)
        ech = ech.select(ech.kind == KIND_DIRECT)  # ghosts land bins away
        rbin = (target.range_m * 2 * radar.slope_hz_per_s / c * radar.samples_per_chirp
                / radar.adc_rate_hz)
        r0 = int(np.round(rbin))
        h = int(half_bins)
        rbins = np.arange(r0 - h, r0 + h + 1) % radar.samples_per_chirp
        nu = f_d  # slow-time frequency per TDM cycle equals f_D
        dbin = int(np.round(nu * radar.tdm_cycle_s * radar.chirps_per_tx)) + radar.chirps_per_tx // 2
        dbin %= radar.chirps_per_tx
        resp = bin_response(ech, radar, setup.rut, rbins, np.full(rbins.size, dbin))  # (K, E, V)
        per_q = np.stack([resp[:, ech.target == q].sum(1) for q in range(n_q)], 1)
        amp = target_amplitude(target.range_m, target.rcs_m2, lam) / nominal_link_gain(scene, lam)
        st = Steering.build(setup.rut, radar) if steering is None else steering
        return cls(setup, ch, per_q, f_d, float(amp), float(target.range_m), st)

    @property
    def count(self) -> int:
        return len(self.channels)

    @property
    def dims(self) -> int:
        return self.steering.dims

    @cached_property
    def phasors(self) -> np.ndarray:
        """Each channel's TDM-compensated spectrum at the set range's bin, (Q, V)."""
        return tdm_compensate(self.responses[self.responses.shape[0] // 2], self.doppler_hz,
                              self.setup.rut, self.setup.scene.radar)

    def fe_directions(self) -> np.ndarray:
        """The channels' front ends' direction cosines (Q, D) seen from the RuT (geometric, or
        :attr:`fe_u` where given)."""
        if self.fe_u is not None:
            return np.asarray(self.fe_u, float)
        u = self.setup.fe_direction_cosines()[list(self.channels)]
        return u[:, :1] if self.dims == 1 else u

    def angles(self, u):
        """The direction (azimuth, or (azimuth, elevation); rad) of direction cosines ``u``
        (..., D): the inverse of the steering's ``directions``."""
        u = np.asarray(u, float)
        return np.arcsin(np.clip(u[..., 0], -1.0, 1.0)) if self.dims == 1 else Steering.angles(u)

    # -- the synthesized target -------------------------------------------------------------

    def combined(self, w) -> np.ndarray:
        """The combined target in every candidate bin (..., K, V) for weights ``w`` (..., Q)."""
        w = np.asarray(w)
        x = self.responses[:, 0] * w[..., 0, None, None]
        for q in range(1, self.count):  # Q terms, summed in channel order (not over draws)
            x = x + w[..., q, None, None] * self.responses[:, q]
        return x

    def snapshot(self, w) -> np.ndarray:
        """The combined target at its strongest candidate bin, TDM-compensated: (..., V)."""
        x = self.combined(w)
        k = np.argmax(np.sum(np.abs(x) ** 2, axis=-1), axis=-1)  # (...)
        x = np.take_along_axis(x, k[..., None, None], axis=-2)[..., 0, :]
        return tdm_compensate(x, self.doppler_hz, self.setup.rut, self.setup.scene.radar)

    def direction(self, w) -> np.ndarray:
        """Detected direction of the combined target for weights ``w`` (..., Q): azimuth
        (...,) (D = 1) or (azimuth, elevation) (..., 2), rad."""
        return self.steering.search(self.snapshot(w))

    def direction_cosines(self, w, u0=None) -> np.ndarray:
        """Direction cosines (..., D) of the beamformer's (global) peak for weights w (..., Q):
        Newton from ``u0`` (default: the grid's maximum) with the global check."""
        snap = self.snapshot(w)
        if u0 is None:
            if self.dims == 1:
                return np.sin(self.steering.search(snap))[..., None]
            return self.steering.directions(self.steering.search(snap))
        return self.steering.peak(snap, u0)[0]

    def coherent_phases(self, u, phasors=None) -> np.ndarray:
        """The phase to give each channel so that all channels' beamformer outputs add in phase
        with channel 0's at direction cosines ``u`` (P, D) (the circular mean over them):
        what the phase calibration establishes when its probes sit there. (..., Q), channel 0
        at 0; ``phasors`` (..., Q, V) default :attr:`phasors` (e.g. a draw's,
        :meth:`perturbed`)."""
        x = self.phasors if phasors is None else np.asarray(phasors)
        b = self.steering.beam(x, np.atleast_2d(u))  # (..., Q, P)
        z = b[..., :1, :] * np.conj(b)
        mag = np.abs(z)
        return np.angle(np.sum(z / np.where(mag > 0, mag, 1.0), axis=-1))

    def pair_phase(self, angles_rad, phasors=None) -> np.ndarray:
        """The pair's (Q = 2, D = 1) phase of channel 1 that :meth:`coherent_phases` gives at
        the azimuths ``angles_rad`` (P,) (the calibration's probes), (...,)."""
        u = self.steering.directions(np.atleast_1d(np.asarray(angles_rad, float)))
        return self.coherent_phases(u, phasors)[..., 1]

    def weights(self, amplitudes, phases=None) -> np.ndarray:
        """Programme weights w = a e^{j phi} (..., Q) of amplitudes (..., Q) and channel phases
        (Q,) (default zeros)."""
        ph = np.zeros(self.count) if phases is None else np.asarray(phases, float)
        return np.asarray(amplitudes, float) * np.exp(1j * ph)

    def pair_weights(self, rho, phases=None) -> np.ndarray:
        """The pair's weights (..., 2) ``(1, rho e^{j phi_1})`` for ratios ``rho`` (...,) and
        channel phases ``phases`` (2,) (default zeros; :meth:`pair_phase` gives phi_1)."""
        rho = np.asarray(rho, float)
        return self.weights(np.stack([np.ones_like(rho), rho], axis=-1), phases)

    def solve(self, u, phases=None, mode: str = "exact", log_span: float = 12.0,
              tol: float = 1e-10, max_iter: int = 30) -> np.ndarray:
        """Weights (Q,) whose beamformer peak is at direction cosines ``u`` (D,), for the
        channel phases ``phases`` (Q,) (e.g. :meth:`coherent_phases`): the pair
        ``(1, rho e^{j phi_1})`` (:meth:`pair_ratio` at the azimuth arcsin u), more channels
        with the strongest at amplitude 1 (module docstring). :class:`AngleUnreachable`
        outside what the channels reach."""
        if mode not in SOLVERS:
            raise ParameterError(f"mode {mode!r}: must be one of {', '.join(SOLVERS)}")
        u_set = np.atleast_1d(np.asarray(u, float))
        if self.count == 2 and self.dims == 1:  # the pair: its closed form
            return self.pair_weights(self.pair_ratio(float(np.arcsin(u_set[0])), phases, mode,
                                                     log_span), phases)
        if mode == "paper":
            raise ParameterError("mode 'paper': eq. 23 is defined for a pair of front ends in "
                                 "azimuth only; use exact or array-factor")
        if mode == "array-factor":
            a0 = closed_form_amplitudes(self.steering, self.fe_directions(), u_set, phases)
            return self.weights(a0, phases)
        # The start of the peak matching: the closed form with the phases the weighted
        # channels have at u_set relative to coherence there (the given phases are programme
        # phases; this model's channels carry their own delays and calibration offsets), then
        # coherent; each start tried in turn until one reaches u_set.
        starts = []
        for ph in ((None if phases is None else self._coherence_offsets(u_set, phases)), None):
            try:
                starts.append(closed_form_amplitudes(self.steering, self.fe_directions(), u_set,
                                                     ph))
            except AngleUnreachable:
                pass
        # a channel the closed form leaves at 0 stays there (its log-amplitude's column of
        # the Jacobian vanishes): the same starts with every channel at 0.1 or more next,
        # then equal amplitudes
        starts += [np.maximum(a, 0.1) for a in starts] + [np.ones(self.count)]
        for n, a0 in enumerate(starts):
            try:
                return self.weights(self._peak_match(u_set, a0, phases, tol, max_iter), phases)
            except AngleUnreachable:
                if n == len(starts) - 1:
                    raise

    def pair_ratio(self, direction: float, phases=None, mode: str = "exact",
                   log_span: float = 12.0) -> float:
        """The pair's ratio rho = A_1 / A_0 of :meth:`solve` (Q = 2, D = 1, direction the
        azimuth in rad). ``exact``: Bartlett's peak condition in closed form for the bin the
        RuT detects (:func:`~.pair.design_at_detected_bin`; for a smoothed Capon or MUSIC a
        bisection on its peak, :func:`~.pair.estimator_ratio`), else a bracketing root
        finder (:class:`AngleUnreachable` outside the span the pair reaches, or across a jump
        of a smoothed estimator's angle); ``paper``, ``array-factor``: their closed forms
        with the front ends' geometric azimuths, span ends included exactly."""
        if self.count != 2:
            raise ParameterError(f"pair_ratio: {self.count} channels; a ratio needs a pair")
        if mode not in SOLVERS:
            raise ParameterError(f"mode {mode!r}: must be one of {', '.join(SOLVERS)}")
        if mode == "exact":
            rho = self._solve_pair_closed(direction, phases)
            return rho if rho is not None else self._solve_pair(direction, phases, log_span)
        return self._closed_form(direction, mode)

    def _solve_pair_closed(self, alpha: float, phases) -> float | None:
        """The exact ratio in closed form (``synthesis.pair.design_ratio``) at each candidate bin;
        the one whose design the RuT detects at that same bin (design and detection agree on
        the bin; nearest the set range's bin first). Where none is (two bins of nearly equal
        power, each design moving the peak to the other bin), the bin's design whose
        detected angle is nearest ``alpha``. None where no bin has a design (the root finder
        decides, and reports an unreachable angle)."""
        return self.solve_checked(alpha, phases)[0]

    def solve_checked(self, alpha: float, phases) -> tuple[float | None, bool, float]:
        """:meth:`_solve_pair_closed` with whether design and detection agree on the bin and
        the detected bin's power over the next strongest (1 where they do not agree)."""
        ph = np.zeros(2) if phases is None else np.asarray(phases, float)
        x = tdm_compensate(self.responses, self.doppler_hz, self.setup.rut,
                           self.setup.scene.radar)  # (K, 2, V)
        r, _, ok, margin = design_at_detected_bin(self.steering, x, alpha, ph[1] - ph[0])
        if ok:
            return float(r), True, float(margin)
        rho = design_ratio(self.steering, x[:, 0], x[:, 1], alpha, ph[1] - ph[0])  # (K,)
        n_k = rho.size
        ks = [k for k in sorted(range(n_k), key=lambda k: abs(k - n_k // 2))
              if np.isfinite(rho[k]) and rho[k] > 0]
        if not ks:
            return None, False, 1.0
        miss = [abs(float(self.direction(self.pair_weights(rho[k], phases))) - alpha)
                for k in ks]
        return float(rho[ks[int(np.argmin(miss))]]), False, 1.0

    def _solve_pair(self, alpha: float, phases, log_span: float) -> float:
        """Reference: brentq on the searched beamformer peak of the strongest bin."""
        def angle(log_rho):
            return float(self.direction(self.pair_weights(np.exp(log_rho), phases)))
        lo, hi = angle(-log_span), angle(log_span)
        if not (min(lo, hi) <= alpha <= max(lo, hi)):
            raise AngleUnreachable(
                f"angle {np.degrees(alpha):.4f} deg is outside the span this front-end pair "
                f"can synthesize [{np.degrees(min(lo, hi)):.4f}, {np.degrees(max(lo, hi)):.4f}] deg")
        from scipy.optimize import brentq  # here: scipy.optimize costs ~0.3 s of imports
        x = brentq(lambda x: angle(x) - alpha, -log_span, log_span, xtol=1e-10)
        got = angle(x)
        # brentq closed in on a jump of the detected angle. Only for a smoothed estimator:
        # Bartlett's jump (front ends beyond the resolution) is what the design map's
        # worst_error_deg measures, its ratio kept as before.
        if self.steering.smoothing and abs(got - alpha) > JUMP_RAD:
            st = self.steering
            raise AngleUnreachable(
                f"angle {np.degrees(alpha):.4f} deg: the {st.estimator} estimator's detected "
                f"angle jumps across it (to {np.degrees(got):.4f} deg at amplitude ratio "
                f"{np.exp(x):.4g}): with radar.angle_subarray = {st.subarray} it resolves the "
                "two front ends (or a spurious direction) instead of one synthesized direction "
                "(front ends too far apart for this estimator; see README, \"The RuT's "
                "direction estimator\")")
        return float(np.exp(x))

    def _closed_form(self, alpha: float, mode: str) -> float:
        th = self.setup.fe_azimuth_rad()[list(self.channels)]  # the nominal angles
        lo, hi = np.sort(th)
        if not lo <= alpha <= hi:
            raise AngleUnreachable(
                f"angle {np.degrees(alpha):.4f} deg is outside the span the {mode} closed form "
                f"can address: the front ends' geometric angles [{np.degrees(lo):.4f}, "
                f"{np.degrees(hi):.4f}] deg (use the exact mode for the measured span)")
        eps = 1e-9 * (hi - lo)
        if abs(alpha - th[0]) <= eps:  # at a span end: that channel alone
            rho = 0.0
        elif abs(alpha - th[1]) <= eps:
            rho = 1e12
        elif mode == "paper":
            rho = float(ratio_paper(th[0], th[1], alpha))
        else:
            rho = float(ratio_array_factor(th[0], th[1], alpha,
                                           **array_factor_args(self.steering)))
        return float(np.clip(rho, 0.0, 1e12))

    def _coherence_offsets(self, u_set, phases) -> np.ndarray:
        """Phases (Q,) for :func:`closed_form_amplitudes` that put each channel as far from
        coherence with channel 0 at ``u_set`` as the weighted model's channels are: its
        array factor's coherent phase ``-arg AF_q(u_set)`` plus the model's deviation
        ``phi_q + arg b_q(u_set) - phi_0 - arg b_0(u_set)`` (b: the channels' beams)."""
        st = self.steering
        u_set = np.atleast_1d(np.asarray(u_set, float))
        b = st.beam(self.phasors, u_set[None])[:, 0]  # (Q,)
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
                f"{list(self.channels)} cannot put the beamformer's peak there (closest "
                f"{np.round(u_set + r, 6).tolist()}): outside what this cell can synthesize")
        return amps(x)

    def reference_power(self) -> float:
        """Beamformer power of channel 0 alone at its own (global) peak: the level
        :meth:`amplitudes` keeps. Depends on channel 0 only, so a sweep that moves only
        other channels' delays may compute it once and pass it in."""
        e0 = np.eye(self.count)[0]
        u_one = self.direction_cosines(e0)
        return float(self.steering.power(self.snapshot(e0), np.atleast_2d(u_one))[0])

    def amplitudes(self, w, u, p_ref: float | None = None) -> np.ndarray:
        """Programme amplitudes (Q,): ``|w|`` scaled so the combined beamformer peak (at
        direction cosines ``u`` (D,)) is as strong as channel 0 alone at its own peak (the
        target keeps its RCS); ``p_ref``: that single-channel power (:meth:`reference_power`)
        when known."""
        st = self.steering
        p_sum = st.power(self.snapshot(w), np.atleast_2d(u))[0]
        p_one = self.reference_power() if p_ref is None else p_ref
        return self.unit_gain * np.sqrt(p_one / max(p_sum, 1e-300)) * np.abs(w)

    # -- mounting errors --------------------------------------------------------------------

    def air_legs(self, offsets_m, yaw_rad=None, pitch_rad=None, rut_offset_m=None,
                 rut_yaw_rad=None) -> tuple[np.ndarray, np.ndarray]:
        """Delays of both legs (RuT Tx -> FE Rx, FE Tx -> RuT Rx) per virtual element,
        (..., Q, V) each, for mounting errors ``offsets_m`` (..., Q, 3) (radial, tangential,
        height) of the channels' front ends, their mounting rotations ``yaw_rad``/``pitch_rad``
        (..., Q) (added to the setup's own) and the RuT's pose errors ``rut_offset_m`` (..., 3),
        ``rut_yaw_rad`` (...,) (the same leading shape as ``offsets_m``'s draws). The front ends keep their signed antenna layout."""
        fe, rut = self.setup.fe, self.setup.rut
        q = list(self.channels)

        def pick(a, extra):
            base = None if a is None else a[q]
            if extra is None:
                return base
            return np.asarray(extra, float) + (0.0 if base is None else base)

        ro = None if fe.rx_offset_m is None else fe.rx_offset_m[q]
        to = None if fe.tx_offset_m is None else fe.tx_offset_m[q]
        el = None if fe.elevation_rad is None else fe.elevation_rad[q]
        rx, tx, _ = antenna_positions(fe.arc_centre, fe.arc_radius_m, fe.angle_rad[q],
                                      fe.separation_m[q], offsets_m, elevation_rad=el,
                                      layout=ModuleLayout(ro, to, pick(fe.yaw_rad, yaw_rad),
                                                          pick(fe.pitch_rad, pitch_rad)))
        if rut_offset_m is None and rut_yaw_rad is None:
            rut_tx, rut_rx = rut.tx_world, rut.rx_world
        else:
            rut_tx, rut_rx = posed_positions(rut, rut_offset_m, rut_yaw_rad)
        t_a, t_b = leg_delays(rut_tx, rut_rx, rx, tx)
        return t_a[..., rut.virtual_tx], t_b[..., rut.virtual_rx]

    @cached_property
    def _nominal_legs(self) -> tuple[np.ndarray, np.ndarray]:
        t_a, t_b = self.air_legs(np.zeros((self.count, 3)))
        return t_a + t_b, t_a * t_b

    @property
    def f_air_hz(self) -> float:
        """f_c + S (t_mid - tau_t): d phase / d tau_air at the bin / 2 pi (eq. 8; t_mid the
        centre of the ADC window, tau_t the target's total delay)."""
        radar = self.setup.scene.radar
        return radar.f_center_hz - radar.slope_hz_per_s * 2 * self.range_m / c

    def perturbed(self, offsets_m, return_shift: bool = False, yaw_rad=None, pitch_rad=None,
                  rut_offset_m=None, rut_yaw_rad=None):
        """:attr:`phasors` for mounting errors ``offsets_m`` (..., Q, 3) of the front ends (and
        the rotations and RuT pose errors of :meth:`air_legs`)::

            x_qv(draw) = x_qv * (a_qv b_qv / a'_qv b'_qv) exp(j 2 pi f_air (tau'_qv - tau_qv))

        (eq. 15/16 with the exact legs a, b, tau = a + b; primed: the draw). Neglected:
        -S dtau^2 / 2 and the beat-frequency shift S dtau against the range bin (3e-3 bins
        per mm of path; quadratic in the magnitude at the bin centre), and the change of the
        antenna patterns' gains with the rotations (none for isotropic patterns). A RuT yaw
        error turns the frame the RuT measures in: it shows up as an angle error of the
        detections, as on a real bench. ``return_shift``: also the air delay change
        (..., Q, V) (s)."""
        tau0, legs0 = self._nominal_legs
        t_a, t_b = self.air_legs(offsets_m, yaw_rad, pitch_rad, rut_offset_m, rut_yaw_rad)
        d = t_a + t_b - tau0
        x = self.phasors * (legs0 / (t_a * t_b)) * np.exp(2j * np.pi * self.f_air_hz * d)
        return (x, d) if return_shift else x
