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
from ..calibration.phasor import HALF_BINS
from ..geometry import Setup
from ..paths import Paths, nominal_model
from ..rts.fir import fir_modelled, realised_delay
from ..rts.channels import requested_delay
from ..scene import TargetConfig
from ..synthesis.model import ChannelModel

__all__ = ["pair_amplitudes", "MIN_BIN_MARGIN", "PairPlan", "nearest_setting", "plan_pair",
           "pair_design", "residual_warning"]


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


def plan_pair(setup: Setup, paths: Paths, pair, target: TargetConfig, mode: str, probes_rad,
              offsets=(0.0, 0.0), gain_correction=(1.0, 1.0), residual_s: float = 0.0
              ) -> PairPlan:
    """Channel J's delay and both amplitudes for a target synthesized by ``pair``, planned on
    realised delays: J's delay offset chosen among the calibrated one and one period of the
    target's IF phase either side (``m = 0, -1, 1``: the same phase, J's echo a period's
    range further), the first whose exact design the RuT detects at the bin it was designed
    for, with the largest power margin (where J's echo straddles a range-bin boundary no
    design is consistent).

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
    scene = setup.scene
    f_if = float(if_phase_slope_hz(scene, 2 * target.range_m / c))
    period = 1.0 / f_if
    if mode != "exact":
        a_i, a_j, rho = pair_amplitudes(setup, paths, pair, target, mode, probes_rad, offsets,
                                        gain_correction)
        return PairPlan(a_i, a_j, rho, float(offsets[1]), float(offsets[1] - offsets[0]),
                        float(offsets[1] - offsets[0]), 0.0, 0, f_if)
    nom, nom_paths = nominal_model(setup, paths)
    cont = continuous_delay_setup(nom)
    rts = scene.rts
    tau = float(requested_delay(scene, target.range_m))
    o_i = float(offsets[0])
    # I's delay as realised, as an offset from the request: the continuous model's base
    base_i = float(realised_delay(tau + o_i, rts.f_s_hz, rts.fractional_delay,
                                  rts.fractional_delay_step_s)) - tau
    fir = fir_modelled(scene)

    def ideal(want):  # the continuous model with J exactly at the planned difference
        return ChannelModel.build(cont, nom_paths, pair, target, (base_i, base_i + want),
                                  HALF_BINS)

    best = None
    for m in (0, -1, 1):
        shift = m * period
        want = float(offsets[1] - offsets[0]) + residual_s + shift
        model = ideal(want)
        phase = float(model.pair_phase(probes_rad))
        if m == 0:
            phase0 = phase
        for _ in range(2 if m and fir else 0):
            # the FIR's response a period later: Newton back to the calibrated phase
            miss = np.angle(np.exp(1j * (phase - phase0)))
            shift += miss / (2 * np.pi) * period
            want += miss / (2 * np.pi) * period
            model = ideal(want)
            phase = float(model.pair_phase(probes_rad))
        req, eps = nearest_setting(scene, tau + o_i, want, tau + float(offsets[1]) + shift)
        real = ChannelModel.build(nom, nom_paths, pair, target, (o_i, req - tau), HALF_BINS)
        rho, ok, margin = real.solve_checked(target.angle_rad, (0.0, phase))
        if rho is None:
            continue
        score = (ok, margin if ok else 0.0, -abs(m))
        if best is None or score > best[0]:
            best = (score, real, rho, phase, req - tau, want, eps, m)
        if ok and margin > MIN_BIN_MARGIN:  # the calibrated offset unless it is ambiguous
            break
    if best is None:
        a_i, a_j, rho = pair_amplitudes(setup, paths, pair, target, mode, probes_rad, offsets,
                                        gain_correction)
        return PairPlan(a_i, a_j, rho, float(offsets[1]), float(offsets[1] - offsets[0]),
                        float(offsets[1] - offsets[0]), 0.0, 0, f_if)
    _, model, rho, phase, off_j, want, eps, m = best
    a_i, a_j = model.amplitudes(model.pair_weights(rho, (0.0, phase)),
                                np.sin([target.angle_rad]))
    return PairPlan(float(a_i * gain_correction[0]), float(a_j * gain_correction[1]),
                    float(rho), float(off_j), float(want + eps), float(want), float(eps), int(m),
                    f_if)


def pair_design(setup: Setup, paths: Paths, pair, target: TargetConfig, mode: str, probes_rad,
                offsets=(0.0, 0.0), gain_correction=(1.0, 1.0), residual_s: float = 0.0
                ) -> tuple[float, float, float, float]:
    """:func:`plan_pair` as (A_I, A_J, rho, J's requested delay offset)."""
    p = plan_pair(setup, paths, pair, target, mode, probes_rad, offsets, gain_correction,
                  residual_s)
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
