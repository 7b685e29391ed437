"""The modelled RuT output of a set of RTS channels synthesizing one target (paper section
"Arbitrary Angle of Arrival", eqs. 14-23; ``shared/design/channel-sets.md``).

:class:`ChannelModel` holds, for channels q = 0..Q-1 each programmed with unit amplitude, the
target's delay and Doppler, the spectrum at the target's candidate range bins (the set range's
bin and its neighbours, at the target's Doppler bin) per virtual element, ``responses[k, q, v]``
(``radar.phasors.bin_response`` through the exact or ray-traced paths: near field, Rx/Tx
separation, real element positions, windows), and the RuT's beamformer
(:class:`~rtsgeom.radar.steering.Steering`). Programme weights ``w`` (Q,) (amplitude times
e^{j phase}) combine them linearly::

    snapshot(w) = sum_q w_q H[k*, q, :]       (TDM-compensated, strongest candidate bin k*)
    direction(w) = the beamformer's peak of snapshot(w)

The front-end pair is Q = 2 with ``w = (1, rho e^{j phase})``: :meth:`ChannelModel.solve` finds
``rho`` by a bracketing root finder (``exact``) or the closed forms ``paper`` and
``array-factor`` (``aoa.synthesis``). :meth:`ChannelModel.perturbed` applies mounting errors
of the front ends at phasor level (the changed two-way air delay's phase and free-space
amplitude), which is what the tolerance study draws.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy.constants import c

from ..geometry import Setup
from ..geometry.frontends import antenna_positions
from ..paths import Paths
from ..paths.exact import leg_delays
from ..radar.phasors import bin_response
from ..radar.processing import tdm_compensate
from ..radar.steering import Steering
from ..scene.registry import SYNTHESIS_MODES
from ..rts.channels import (KIND_DIRECT, RtsProgram, channel_echoes, nominal_link_gain,
                            requested_delay, target_amplitude)
from ..errors import SceneError
from ..scene import TargetConfig
from ..errors import AngleUnreachable

__all__ = ["ChannelModel", "AngleUnreachable", "SOLVERS", "estimator_ratio"]

SOLVERS = SYNTHESIS_MODES  # the registry lists every AoA mode once (rtsgeom/registry.py)


#: How far the root finder's angle may miss the set angle before it counts as a jump (a
#: smoothed Capon or MUSIC resolving the front ends); continuous peaks meet it to ~1e-8 rad.
JUMP_RAD = np.radians(1e-3)


def estimator_ratio(st: Steering, x_i, x_j, alpha_rad, phase=0.0,
                    log_span: float = 12.0, grid: int = 13, iterations: int = 40
                    ) -> np.ndarray:
    """The ratio rho >= 0 (...,) for which the estimator's detected angle of
    ``x_i + rho e^{j phase} x_j`` (snapshots (..., V)) is ``alpha_rad`` (broadcast against
    (...,), as ``phase``), by bisection on
    log rho, batched over all snapshots: what ``aoa.sweep.design_ratio`` (Bartlett's peak
    condition in closed form) is for an estimator without one (a smoothed Capon or MUSIC,
    ``Steering.smoothing``). The bracket is the first sign change of (angle - alpha) on
    ``grid`` log-spaced ratios over e^{+-log_span}; NaN where there is none, or where the
    bisection closes in on a jump of the detected angle (the estimator resolves the
    channels, :data:`JUMP_RAD`). Bisection, not a faster root finder: the detected angle of
    such an estimator can jump, and bisection stays inside its bracket."""
    x_i, x_j = np.broadcast_arrays(np.asarray(x_i), np.asarray(x_j))
    shape, n_v = x_i.shape[:-1], x_i.shape[-1]
    ph = np.broadcast_to(np.exp(1j * np.asarray(phase, float)), shape)
    xi = x_i.reshape(-1, n_v)
    xj = (x_j * ph[..., None]).reshape(-1, n_v)
    alpha = np.broadcast_to(np.asarray(alpha_rad, float), shape).reshape(-1)  # (n,)
    n = xi.shape[0]
    lr = np.linspace(-log_span, log_span, grid)
    f = st.search(xi[:, None, :] + np.exp(lr)[None, :, None] * xj[:, None, :]) - alpha[:, None]
    change = (np.sign(f[:, :-1]) * np.sign(f[:, 1:]) <= 0) & np.isfinite(f[:, :-1] + f[:, 1:])
    has = change.any(axis=1)
    k = np.argmax(change, axis=1)
    rows = np.arange(n)
    lo, hi, f_lo = lr[k], lr[k + 1], f[rows, k]
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        f_mid = st.search(xi + np.exp(mid)[:, None] * xj) - alpha
        left = np.sign(f_mid) == np.sign(f_lo)
        lo, f_lo = np.where(left, mid, lo), np.where(left, f_mid, f_lo)
        hi = np.where(left, hi, mid)
    x = 0.5 * (lo + hi)
    got = st.search(xi + np.exp(x)[:, None] * xj)
    ok = has & (np.abs(got - alpha) < JUMP_RAD)
    return np.where(ok, np.exp(x), np.nan).reshape(shape)


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


@dataclass(frozen=True)
class ChannelModel:
    """The modelled RuT output of channels ``channels`` (Q,) for one target.

    Build it on the *nominal* setup (``geometry.nominal_setup``) for a design: the design
    knows the setup as drawn, not its mounting errors.
    """

    setup: Setup
    channels: tuple[int, ...]  # (Q,) front-end index per channel
    responses: np.ndarray  # (K, Q, V) candidate range bins, the set range's in the middle
    doppler_hz: float
    unit_gain: float  # program amplitude of one channel that gives the target's amplitude
    range_m: float
    steering: Steering

    @classmethod
    def build(cls, setup: Setup, paths: Paths, channels, target: TargetConfig,
              delta_tau_s=None, half_bins: int = 1) -> "ChannelModel":
        """``delta_tau_s`` (Q,): the channels' calibration delay offsets (default zeros);
        ``half_bins``: candidate range bins on either side of the set range's bin (the
        calibration sweep moves channel J by up to ~2 bins: it asks for more)."""
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
        return cls(setup, ch, per_q, f_d, float(amp), float(target.range_m),
                   Steering.build(setup.rut, radar))

    @property
    def count(self) -> int:
        return len(self.channels)

    @cached_property
    def phasors(self) -> np.ndarray:
        """Each channel's TDM-compensated spectrum at the set range's bin, (Q, V)."""
        return tdm_compensate(self.responses[self.responses.shape[0] // 2], self.doppler_hz,
                              self.setup.rut,
                              self.setup.scene.radar)

    # -- the synthesized target -------------------------------------------------------------

    def snapshot(self, w) -> np.ndarray:
        """Spectrum of the combined target for programme weights ``w`` (..., Q) at its
        strongest candidate bin, TDM-compensated: (..., V)."""
        w = np.asarray(w)
        x = self.responses[:, 0] * w[..., 0, None, None]
        for q in range(1, self.count):  # Q terms, summed in channel order (not over draws)
            x = x + w[..., q, None, None] * self.responses[:, q]
        k = np.argmax(np.sum(np.abs(x) ** 2, axis=-1), axis=-1)  # (...)
        x = np.take_along_axis(x, k[..., None, None], axis=-2)[..., 0, :]
        return tdm_compensate(x, self.doppler_hz, self.setup.rut, self.setup.scene.radar)

    def direction(self, w) -> np.ndarray:
        """Detected azimuth (rad) of the combined target for weights ``w`` (..., Q)."""
        return self.steering.search(self.snapshot(w))

    def coherent_phases(self, probes_rad, phasors=None) -> np.ndarray:
        """The phase to give each channel so that all channels' beamformer outputs add in phase
        with channel 0's at the probe angle(s) ``probes_rad`` (the circular mean over them):
        what the phase calibration establishes when its probes sit there. (..., Q), channel 0
        at 0; ``phasors`` (..., Q, V) default :attr:`phasors` (e.g. a draw's,
        :meth:`perturbed`)."""
        x = self.phasors if phasors is None else np.asarray(phasors)
        u = self.steering.directions(np.atleast_1d(np.asarray(probes_rad, float)))
        b = self.steering.beam(x, u)  # (..., Q, P)
        z = b[..., :1, :] * np.conj(b)
        mag = np.abs(z)
        return np.angle(np.sum(z / np.where(mag > 0, mag, 1.0), axis=-1))

    def weights(self, ratios, phases=None) -> np.ndarray:
        """Weights (..., Q) from amplitude ratios (..., Q - 1) to channel 0 and channel phases
        (Q,) (default zeros): ``(1, r_1 e^{j phi_1}, ...)``."""
        r = np.asarray(ratios, float)
        ph = np.zeros(self.count) if phases is None else np.asarray(phases, float)
        rest = r * np.exp(1j * ph[1:])
        return np.concatenate([np.ones(rest.shape[:-1] + (1,), complex), rest], axis=-1)

    def solve(self, direction: float, phases=None, mode: str = "exact",
              log_span: float = 12.0) -> np.ndarray:
        """Weights (Q,) that put the detected angle at ``direction`` (rad), for the channel
        phases ``phases`` (Q,) (e.g. :meth:`coherent_phases`).

        Q = 2 only (peak matching with more channels has free parameters left, see
        ``channel-sets.md``). ``exact``: the ratio rho = |w_1 / w_0| on the modelled RuT
        output read by the RuT's own direction estimator (``steering.estimator``): Bartlett's
        peak condition in closed form (``sweep.design_ratio``), for a smoothed Capon or MUSIC
        a bisection on its peak (:func:`estimator_ratio`), else a bracketing root finder
        (AngleUnreachable outside the span the pair reaches, or across a jump of a smoothed
        estimator's angle); ``paper``, ``array-factor``: their closed forms (``aoa.synthesis``) with
        the front ends' geometric azimuths, span ends included exactly."""
        return self.weights([self.solve_ratio(direction, phases, mode, log_span)], phases)

    def solve_ratio(self, direction: float, phases=None, mode: str = "exact",
                    log_span: float = 12.0) -> float:
        """The pair's ratio rho = A_1 / A_0 of :meth:`solve` (Q = 2)."""
        if self.count != 2:
            raise NotImplementedError(f"solve: {self.count} channels; only pairs (Q = 2) so far")
        if mode not in SOLVERS:
            raise ValueError(f"mode {mode!r}: must be one of {', '.join(SOLVERS)}")
        if mode == "exact":
            rho = self._solve_pair_closed(direction, phases)
            return rho if rho is not None else self._solve_pair(direction, phases, log_span)
        return self._closed_form(direction, mode)

    def _solve_pair_closed(self, alpha: float, phases) -> float | None:
        """The exact ratio in closed form (``aoa.sweep.design_ratio``) at each candidate bin;
        the one whose design the RuT detects at that same bin (design and detection agree on
        the bin; nearest the set range's bin first). Where none is (two bins of nearly equal
        power, each design moving the peak to the other bin), the bin's design whose
        detected angle is nearest ``alpha``. None where no bin has a design (the root finder
        decides, and reports an unreachable angle)."""
        return self.solve_checked(alpha, phases)[0]

    def solve_checked(self, alpha: float, phases) -> tuple[float | None, bool, float]:
        """:meth:`_solve_pair_closed` with whether design and detection agree on the bin and
        the detected bin's power over the next strongest (1 where they do not agree)."""
        from ..calibration.sweep import design_at_detected_bin, design_ratio
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
        miss = [abs(float(self.direction(self.weights([rho[k]], phases))) - alpha) for k in ks]
        return float(rho[ks[int(np.argmin(miss))]]), False, 1.0

    def _solve_pair(self, alpha: float, phases, log_span: float) -> float:
        """Reference: brentq on the searched beamformer peak of the strongest bin."""
        def angle(log_rho):
            return float(self.direction(self.weights([np.exp(log_rho)], phases)))
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
        from .closed_form import array_factor_args, ratio_array_factor, ratio_paper
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

    def scale(self, w, direction: float) -> float:
        """The factor on the weights ``w`` (Q,) that makes the combined beamformer peak (at
        ``direction``) as strong as channel 0 alone at its own peak (the target keeps its
        RCS): programme amplitudes ``scale * |w|`` (:meth:`amplitudes`)."""
        st = self.steering
        p_sum = st.power(self.snapshot(w), st.directions(np.array([direction])))[0]
        single = self.snapshot(np.eye(self.count)[0])
        p_one = st.power(single, st.directions(np.array([st.search(single)])))[0]
        return float(self.unit_gain * np.sqrt(p_one / max(p_sum, 1e-300)))

    def amplitudes(self, w, direction: float) -> np.ndarray:
        """Programme amplitudes (Q,) for weights ``w``: ``scale(w, direction) * |w|``."""
        return self.scale(w, direction) * np.abs(np.asarray(w))

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
                                      fe.separation_m[q], offsets_m, rx_offset_m=ro,
                                      tx_offset_m=to, yaw_rad=pick(fe.yaw_rad, yaw_rad),
                                      pitch_rad=pick(fe.pitch_rad, pitch_rad), elevation_rad=el)
        if rut_offset_m is None and rut_yaw_rad is None:
            rut_tx, rut_rx = rut.tx_world, rut.rx_world
        else:
            from ..geometry.arrays import posed_positions
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
