"""One target's programme on a front-end pair, planned on the delays the RTS realises: channel
J's delay (the calibrated one, or one IF period either side where the bin the RuT detects is
ambiguous), both amplitudes designed for the phase the calibration establishes at that delay.
The planner (:mod:`.plan`), the linearity study and the tolerance model plan pairs this way.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.constants import c

from ..calibration.probes import if_phase_slope_hz
from ..calibration.steps import continuous_delay_setup
from ..calibration.phasor import HALF_BINS, PairChannels
from ..geometry import Setup
from ..paths import Paths, nominal_model
from ..rts.fir import fir_modelled, realised_delay
from ..rts.channels import requested_delay
from ..scene import TargetConfig
from ..radar.processing import tdm_compensate
from ..synthesis.batch import build_models
from ..synthesis.model import ChannelModel
from ..synthesis.pair import design_at_detected_bin

__all__ = ["pair_amplitudes", "MIN_BIN_MARGIN", "PairPlan", "nearest_setting", "plan_pair",
           "pair_design", "plan_pairs", "residual_warning"]


def pair_amplitudes(setup: Setup, paths: Paths, pair, target: TargetConfig, mode: str,
                    probes_rad, offsets=(0.0, 0.0), gain_correction=(1.0, 1.0)
                    ) -> tuple[float, float, float]:
    """Programmed amplitudes (A_I, A_J) and the ratio for a target synthesized by ``pair``.

    ``exact`` solves the ratio on the modelled RuT output of the nominal setup with the
    channels' delay offsets applied (their range offset) and coherent phases (what the
    calibration establishes); ``paper`` and ``array-factor`` use their closed forms with the front ends'
    geometric azimuths seen from the RuT.
    """
    nom, nom_paths = nominal_model(setup, paths)
    model = ChannelModel.build(nom, nom_paths, pair, target, offsets)
    alpha = target.angle_rad
    phase = float(model.pair_phase(probes_rad))  # the phase the calibration establishes
    rho = model.pair_ratio(alpha, (0.0, phase), mode)  # exact: closed form; else closed forms
    a_i, a_j = model.amplitudes(model.pair_weights(rho, (0.0, phase)), np.sin([alpha]))
    return a_i * gain_correction[0], a_j * gain_correction[1], rho


MIN_BIN_MARGIN = 1.2  # detected bin's power over the next strongest that counts as unambiguous


@dataclass(frozen=True)
class PairPlan:
    """One target's programme on a front-end pair, planned on the delays the RTS realises
    (:func:`plan_pair`).

    The calibration makes the pair coherent when channel J's *realised* delay exceeds I's by
    ``planned_difference_s`` (the calibrated offset plus its ``quantisation_residual_s``, plus
    ``period_offset`` periods of the target's IF phase where the bin is ambiguous). The RTS
    realises J's request only to its resolution (``rts.realised_delay``); where the step does
    not divide 1/f_s (100 ps at 4 GSPS: settings 0/100/200 ps in each 250 ps sample) the
    realised difference depends on where the target's delay falls in the sample, up to a
    step. ``quantisation_residual_s`` is what is left after choosing J's nearest setting;
    the amplitudes are designed for the phase it leaves (``residual_phase_deg`` at the
    target's IF, ``calibration.if_phase_slope_hz``)."""

    a_i: float
    a_j: float
    rho: float
    offset_j_s: float  # J's requested delay offset from the target's requested delay
    realised_difference_s: float  # Q(tau + o_J) - Q(tau + o_I), Q = rts.realised_delay
    planned_difference_s: float  # the difference the calibration makes coherent (+ periods)
    quantisation_residual_s: float  # realised_difference_s - planned_difference_s
    period_offset: int  # periods of the IF phase J is moved by (bin ambiguity), 0, -1 or 1
    if_hz: float  # the IF phase slope at the target (1 / its period)

    @property
    def residual_phase_deg(self) -> float:
        """The residual's phase at the target's IF (deg)."""
        return float(np.degrees(2 * np.pi * self.if_hz * self.quantisation_residual_s))

    def to_dict(self) -> dict:
        return {"offset_j_s": self.offset_j_s, "realised_difference_s": self.realised_difference_s,
                "planned_difference_s": self.planned_difference_s,
                "quantisation_residual_s": self.quantisation_residual_s,
                "residual_phase_deg": self.residual_phase_deg,
                "period_offset": self.period_offset}


def nearest_setting(scene, tau_i_s: float, want_s: float, start_s: float
                    ) -> tuple[float, float]:
    """Channel J's requested delay, among the settings near ``start_s``, whose realised delay
    (``rts.realised_delay``) exceeds the realised delay of I's request ``tau_i_s`` by the
    nearest to ``want_s``; ``start_s`` itself where it is one of the nearest (an unchanged
    programme wherever the step divides 1/f_s). Returns (request, realised - wanted)."""
    rts = scene.rts
    res = rts.delay_resolution_s

    def q(d):
        return realised_delay(d, rts.f_s_hz, rts.fractional_delay, rts.fractional_delay_step_s)

    # every setting within two steps: quarter steps reach each (settings need not be evenly
    # spaced: 0/100/200 ps then 250 ps with 100 ps steps at 4 GSPS)
    k = np.arange(-8, 9)
    cand = start_s + k * res / 4
    eps = q(cand) - float(q(tau_i_s)) - want_s
    order = np.lexsort((np.abs(k), np.round(np.abs(eps) / 1e-15)))  # nearest, then closest
    return float(cand[order[0]]), float(eps[order[0]])


def plan_pair(setup: Setup, paths: Paths, channels: PairChannels, target: TargetConfig,
              mode: str, probes_rad, residual_s: float = 0.0) -> PairPlan:
    """Channel J's delay and both amplitudes for a target synthesized by ``channels.pair``
    (with its channels' delay ``offsets`` and ``gain_correction``), planned on
    realised delays: J's delay offset chosen among the calibrated one and one period of the
    target's IF phase either side (``m = 0, -1, 1``: the same phase, J's echo a period's
    range further), the first whose exact design the RuT detects at the bin it was designed
    for, with the largest power margin (where J's echo straddles a range-bin boundary no
    design is consistent). A shifted design counts only where it is consistent: one the RuT
    detects at another bin reaches neither the angle nor the range (J's echo a bin from I's,
    the combined peak half a bin to a bin off); where the calibrated offset has no design at
    all (the angle outside the pair's span as the nominal model reads it) and no shifted one
    is consistent, the angle is unreachable (``AngleUnreachable``), not planned a bin off.

    For each ``m`` the difference the calibration makes coherent, ``offsets[1] - offsets[0]
    + residual_s + m period`` (``residual_s``: the calibration's ``quantisation_residual_s``;
    for m != 0 corrected on the continuous model so J's phase at the bin is the calibrated
    one: the fractional-delay FIR's response cycles every 1/f_s, up to 4 deg with 5 taps),
    is the *planned* difference; J gets the setting whose realised delay minus I's is the
    nearest to it (:func:`nearest_setting`), and the amplitudes are designed on the model of
    what the RTS realises (``ChannelModel`` with the requests) for the phase the calibration
    establishes at the planned difference (``coherent_phase`` of the continuous model,
    ``calsteps.continuous_delay_setup``): the residual's phase is designed for, not assumed
    away. Before this the design took the realised setting for coherent, and at 100 ps
    steps and 4 GSPS J at 33.5 m realised -1100 ps from I, 95 ps off the planned -1005 ps
    (34 deg of IF phase; -0.173 deg of angle).

    ``paper`` / ``array-factor``: :func:`pair_amplitudes` at the calibrated offsets."""
    pair, offsets, gain_correction = (channels.pair, channels.offsets,
                                      channels.gain_correction)
    ctx = _PairContext.of(setup, paths, pair, target, probes_rad, offsets, residual_s)
    if mode != "exact":
        return _closed_form_plan(setup, paths, ctx, mode, gain_correction)
    best, phase0 = None, None
    for m in (0, -1, 1):
        cand, phase = _candidate(ctx, m, phase0)
        if m == 0:
            phase0 = phase
        if cand is None or (m and not cand[0][0]):
            continue  # a shifted design only where the RuT detects it at its own bin
        if best is None or cand[0] > best[0]:
            best = cand
        ok, margin = cand[0][0], cand[0][1]
        if ok and margin > MIN_BIN_MARGIN:  # the calibrated offset unless it is ambiguous
            break
    if best is None:
        return _closed_form_plan(setup, paths, ctx, mode, gain_correction)
    return _finish(ctx, best[1:], gain_correction)


@dataclass(frozen=True)
class _PairContext:
    """What :func:`plan_pair` plans one target's pair on: the nominal and continuous models,
    the target's request ``tau``, I's offset ``o_i`` and its realised part ``base_i`` (as an
    offset from the request), the calibrated difference ``want0`` and the IF phase slope."""

    setup: Setup
    nom: Setup
    nom_paths: Paths
    cont: Setup
    pair: tuple
    target: TargetConfig
    probes_rad: np.ndarray
    offsets: tuple
    tau: float
    o_i: float
    base_i: float
    want0: float
    f_if: float

    @classmethod
    def of(cls, setup, paths, pair, target, probes_rad, offsets, residual_s, models=None,
           cont=None):
        scene = setup.scene
        rts = scene.rts
        nom, nom_paths = models or nominal_model(setup, paths)
        tau = float(requested_delay(scene, target.range_m))
        o_i = float(offsets[0])
        # I's delay as realised, as an offset from the request: the continuous model's base
        base_i = float(realised_delay(tau + o_i, rts.f_s_hz, rts.fractional_delay,
                                      rts.fractional_delay_step_s)) - tau
        cont = continuous_delay_setup(nom) if cont is None else cont
        return cls(setup, nom, nom_paths, cont, tuple(pair), target,
                   probes_rad, (float(offsets[0]), float(offsets[1])), tau, o_i, base_i,
                   float(offsets[1] - offsets[0]) + residual_s,
                   float(if_phase_slope_hz(scene, 2 * target.range_m / c)))

    def ideal(self, want):  # the continuous model with J exactly at the planned difference
        return ChannelModel.build(self.cont, self.nom_paths, self.pair, self.target,
                                  (self.base_i, self.base_i + want), HALF_BINS)

    def setting(self, want, shift):
        """J's request near its calibrated one moved by ``shift``: (request, residual)."""
        return nearest_setting(self.setup.scene, self.tau + self.o_i, want,
                               self.tau + self.offsets[1] + shift)

    def real(self, req):
        """The model of what the RTS realises with J at request ``req``."""
        return ChannelModel.build(self.nom, self.nom_paths, self.pair, self.target,
                                  (self.o_i, req - self.tau), HALF_BINS)


def _candidate(ctx: _PairContext, m: int, phase0):
    """The design with J moved by ``m`` periods of the IF phase: ``((ok, margin, -|m|), model,
    rho, phase, J's offset, planned difference, residual, m)`` or None where no bin has a
    design, and the phase the calibration establishes there."""
    period = 1.0 / ctx.f_if
    shift = m * period
    want = ctx.want0 + shift
    model = ctx.ideal(want)
    phase = float(model.pair_phase(ctx.probes_rad))
    for _ in range(2 if m and fir_modelled(ctx.setup.scene) else 0):
        # the FIR's response a period later: Newton back to the calibrated phase
        miss = np.angle(np.exp(1j * (phase - phase0)))
        shift += miss / (2 * np.pi) * period
        want += miss / (2 * np.pi) * period
        model = ctx.ideal(want)
        phase = float(model.pair_phase(ctx.probes_rad))
    req, eps = ctx.setting(want, shift)
    real = ctx.real(req)
    rho, ok, margin = real.solve_checked(ctx.target.angle_rad, (0.0, phase))
    if rho is None:
        return None, phase
    return ((ok, margin if ok else 0.0, -abs(m)), real, rho, phase, req - ctx.tau, want, eps,
            m), phase


def _finish(ctx: _PairContext, chosen, gain_correction) -> PairPlan:
    """The plan of the chosen design: its amplitudes at the set angle."""
    model, rho, phase, off_j, want, eps, m = chosen
    a_i, a_j = model.amplitudes(model.pair_weights(rho, (0.0, phase)),
                                np.sin([ctx.target.angle_rad]))
    return PairPlan(float(a_i * gain_correction[0]), float(a_j * gain_correction[1]),
                    float(rho), float(off_j), float(want + eps), float(want), float(eps), int(m),
                    ctx.f_if)


def _closed_form_plan(setup, paths, ctx: _PairContext, mode, gain_correction) -> PairPlan:
    """:func:`pair_amplitudes` at the calibrated offsets (``paper``, ``array-factor``, or no
    exact design)."""
    a_i, a_j, rho = pair_amplitudes(setup, paths, ctx.pair, ctx.target, mode, ctx.probes_rad,
                                    ctx.offsets, gain_correction)
    d = ctx.offsets[1] - ctx.offsets[0]
    return PairPlan(a_i, a_j, rho, ctx.offsets[1], d, d, 0.0, 0, ctx.f_if)


def plan_pairs(setup: Setup, paths: Paths, mode: str, rows) -> list[PairPlan | None]:
    """:func:`plan_pair` for many targets at once: ``rows`` of ``(pair, target, probes_rad,
    offsets, gain_correction, residual_s)``. The calibrated offset's design (``m = 0``) of
    every row from two batched model builds (``synthesis.batch.build_models``: the continuous
    model at the planned difference and the realised one); a row whose design the RuT
    detects at its bin with a margin over :data:`MIN_BIN_MARGIN` gets its plan (what
    :func:`plan_pair` returns: it stops there too), any other row None (the caller plans it
    with :func:`plan_pair`, which tries the periods either side and names an unreachable
    angle)."""
    if mode != "exact" or not rows:
        return [None] * len(rows)
    models = nominal_model(setup, paths)
    cont = continuous_delay_setup(models[0])
    ctxs = [_PairContext.of(setup, paths, pair, t, pr, off, res, models, cont)
            for pair, t, pr, off, _, res in rows]
    sets = [c.setting(c.want0, 0.0) for c in ctxs]
    pairs = [c.pair for c in ctxs]
    targets = [c.target for c in ctxs]
    ideal = build_models(cont, models[1], pairs, targets,
                         [(c.base_i, c.base_i + c.want0) for c in ctxs], HALF_BINS)
    real = build_models(models[0], models[1], pairs, targets,
                        [(c.o_i, req - c.tau) for c, (req, _) in zip(ctxs, sets)], HALF_BINS)
    return _batch_plans(ctxs, sets, ideal, real, [row[4] for row in rows])


def _batch_plans(ctxs, sets, ideal, real, gains) -> list[PairPlan | None]:
    """:func:`plan_pairs`' designs, batched over its rows: the phase the calibration
    establishes (``ChannelModel.pair_phase`` of the continuous models), the design for the
    bin the RuT detects (``design_at_detected_bin``) and the amplitudes
    (``ChannelModel.amplitudes``), each as those methods compute it, row by row."""
    st = real[0].steering
    scene = real[0].setup.scene
    rut, radar = real[0].setup.rut, scene.radar
    dop = np.array([m.doppler_hz for m in real])
    mid = HALF_BINS
    # pair_phase: channel J's coherent phase at the row's probes
    x = tdm_compensate(np.stack([m.responses[mid] for m in ideal]), dop[:, None], rut, radar)
    u = st.directions(np.array([np.atleast_1d(np.asarray(c.probes_rad, float)) for c in ctxs]))
    b = np.sum(st.weighted(x)[..., :, None] * np.swapaxes(st.steer(u), -1, -2)[:, None],
               axis=-2)  # (N, Q, P)
    z = b[..., :1, :] * np.conj(b)
    mag = np.abs(z)
    phase = np.angle(np.sum(z / np.where(mag > 0, mag, 1.0), axis=-1))[:, 1]
    # solve_checked: the design for the detected bin
    resp = np.stack([m.responses for m in real])  # (N, K, 2, V)
    h = tdm_compensate(resp, dop[:, None, None], rut, radar)
    alpha = np.array([ctx.target.angle_rad for ctx in ctxs])
    # J's phase minus I's (0), as solve_checked passes it
    rho, _, ok, margin = design_at_detected_bin(st, h, alpha, phase - 0.0)
    good = ok & (margin > MIN_BIN_MARGIN) & np.isfinite(rho)
    # amplitudes: the combined target's power at the set direction over channel I's own
    w = np.stack([np.ones_like(rho), np.where(good, rho, 0.0)], -1) * np.exp(
        1j * np.stack([np.zeros_like(phase), phase], -1))  # (N, 2)
    p_sum = _power_at(st, _snapshots(resp, w, dop, rut, radar), np.sin(alpha))
    one = _snapshots(resp, np.eye(2)[0] * np.ones((len(ctxs), 1)), dop, rut, radar)
    p_one = _power_at(st, one, np.sin(st.search(one)))
    gain = np.array([m.unit_gain for m in real])
    amps = (gain * np.sqrt(p_one / np.maximum(p_sum, 1e-300)))[:, None] * np.abs(w)
    out = []
    for n, ctx in enumerate(ctxs):
        if not good[n]:
            out.append(None)
            continue
        req, eps = sets[n]
        out.append(PairPlan(float(amps[n, 0] * gains[n][0]), float(amps[n, 1] * gains[n][1]),
                            float(rho[n]), float(req - ctx.tau), float(ctx.want0 + eps),
                            float(ctx.want0), float(eps), 0, ctx.f_if))
    return out


def _snapshots(resp, w, dop, rut, radar) -> np.ndarray:
    """``ChannelModel.snapshot`` per row: responses (N, K, 2, V), weights (N, 2) -> (N, V)."""
    x = resp[:, :, 0] * w[:, 0, None, None] + w[:, 1, None, None] * resp[:, :, 1]
    k = np.argmax(np.sum(np.abs(x) ** 2, axis=-1), axis=-1)
    x = np.take_along_axis(x, k[:, None, None], axis=-2)[:, 0, :]
    return tdm_compensate(x, dop, rut, radar)


def _power_at(st, snaps, u) -> np.ndarray:
    """Bartlett power of each snapshot (N, V) at its own direction cosine u (N,) (D = 1)."""
    return np.abs(np.einsum("nv,nv->n", st.weighted(snaps), st.steer(u[:, None]))) ** 2


def pair_design(setup: Setup, paths: Paths, channels: PairChannels, target: TargetConfig,
                mode: str, probes_rad, residual_s: float = 0.0
                ) -> tuple[float, float, float, float]:
    """:func:`plan_pair` as (A_I, A_J, rho, J's requested delay offset)."""
    p = plan_pair(setup, paths, channels, target, mode, probes_rad, residual_s)
    return p.a_i, p.a_j, p.rho, p.offset_j_s


def residual_warning(scene, k: int, plan: PairPlan, name: str | None = None) -> str | None:
    """A run warning for target ``k`` where J's realised delay difference misses the planned
    one by more than half the RTS's delay step (what the calibration's own rounding leaves):
    no setting within reach realises it. The amplitudes are designed for the phase it
    leaves, so the angle holds on the nominal model, but the pair is that much less coherent
    than calibrated (power, sensitivity to the model). None where it does not. ``name``:
    the target as the file names it (default ``targets[k]``)."""
    res = scene.rts.delay_resolution_s
    eps = plan.quantisation_residual_s
    if abs(eps) <= 0.5 * res * (1 + 1e-6) + 1e-15:
        return None
    return (f"{name or f'targets[{k}]'}: channel J's realised delay difference misses the calibrated one by "
            f"{eps * 1e12:.1f} ps ({plan.residual_phase_deg:.1f} deg of IF phase), more than "
            f"half the RTS delay step {res * 1e12:g} ps (rts.fractional_delay_step_s / "
            "rts.f_s_hz): no realisable setting is nearer; the amplitudes are designed for it")
