"""Targets at arbitrary angles: pick the bracketing front-end pair, calibrate, set amplitudes.

The reachable span of a pair is *measured* (each front end alone, detected by the simulated
RuT), not assumed: the Rx/Tx separation and the near field bias a single front end's angle.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry import Setup
from ..geometry.farfield import angular_resolution_rad
from ..paths import Paths
from ..rts.channels import RtsProgram, fir_modelled, realised_delay, requested_delay
from ..errors import SceneError
from ..scene import TargetConfig
from scipy.constants import c
from ..calibration.pair import Calibration, calibrate_pair
from ..calibration.probes import FrontEndProbe, probe_angles, probe_front_ends
from ..errors import AngleUnreachable
from ..synthesis.model import ChannelModel
from ..calibration.sweep import HALF_BINS

__all__ = ["bracketing_pair", "pair_amplitudes", "PairPlan", "plan_pair", "pair_design",
           "nearest_setting", "plan_targets", "uses_cells", "channel_offsets",
           "load_calibration", "CALIBRATION_FORMAT", "setup_fingerprint",
           "calibration_mismatch"]

CALIBRATION_FORMAT = "rtsgeom-calibration"


def setup_fingerprint(scene) -> str:
    """SHA-256 of what a calibration is a measurement of: the RTS's arc, front ends (their
    mounting and channel fields) and delay hardware, and the RuT (array, pose, chirp,
    processing). Not the scenario (targets, seed, name), not what only changes noise or
    levels (the RuT's ``snr_db``, ``link`` and CFAR, ``rts.link``), not the calibration
    procedure's own settings (``rts.calibration_span_ns``/``calibration_step_ps``) or the
    AoA mode, and not the sheet or ray tracing (``calibrate`` measures on exact paths).
    Files the scene names (antenna pattern tables) count by their content, not their path,
    so a moved or copied project keeps its fingerprint and an edited table changes it.
    ``calibrate`` writes it as ``setup_sha256``; ``run``/``adc --calibration`` warn when the
    scene's differs (a calibration made before a front end was moved)."""
    import dataclasses
    import hashlib
    from pathlib import Path

    def canonical(v):
        if isinstance(v, dict):
            return {k: canonical(x) for k, x in v.items()}
        if isinstance(v, (list, tuple)):
            return [canonical(x) for x in v]
        if isinstance(v, str) and Path(v).is_absolute() and Path(v).is_file():
            return "sha256:" + hashlib.sha256(Path(v).read_bytes()).hexdigest()
        if isinstance(v, (int, float)) and not isinstance(v, bool):
            return float(v)  # 1, 1.0 and np.float64(1.0) alike
        return v
    radar = dataclasses.asdict(scene.radar)
    for key in ("snr_db", "link", "cfar"):
        radar.pop(key, None)
    rts = dataclasses.asdict(scene.rts)
    for key in ("link", "aoa_mode", "calibration_span_s", "calibration_step_s"):
        rts.pop(key, None)
    return hashlib.sha256(repr(canonical((radar, rts))).encode()).hexdigest()


def calibration_mismatch(doc: dict, scene) -> str | None:
    """The warning for a calibration file made on another setup (:func:`setup_fingerprint`),
    None where it matches or the file predates the fingerprint."""
    made = doc.get("setup_sha256")
    if made is None or made == setup_fingerprint(scene):
        return None
    return ("--calibration: the file was made on another setup (the arc, a front end's "
            "mounting or channel, the RuT or the RTS's delays differ from this scene's): "
            "applied as it is; run `rtsgeom calibrate` on this scene if the setup changed")


def load_calibration(doc: dict, setup: Setup) -> tuple[FrontEndProbe, dict]:
    """The front-end probe and pair calibrations of a calibration file (``rtsgeom calibrate
    --out DIR`` writes DIR/calibration.json): what a lab measures once and reuses for every
    scenario on the same setup. Raises ``SceneError`` naming the field when the file does
    not fit the setup."""
    n = setup.fe.count
    where = "calibration file"
    try:
        ang = np.radians(np.asarray(doc["front_end_angles_deg"], float))
        gain = np.asarray(doc.get("gain_correction", np.ones(n)), float)
        pairs = doc["pairs"] if "pairs" in doc else [doc]
        cals = {}
        for k, p in enumerate(pairs):
            cal = Calibration.from_dict(p)
            cals[cal.pair] = cal
    except (KeyError, TypeError, ValueError) as exc:
        raise SceneError(f"{where}: not an rtsgeom calibration ({exc!s}): write one with "
                         "`rtsgeom calibrate SCENE --out DIR`") from None
    if ang.shape != (n,) or gain.shape != (n,):
        raise SceneError(f"{where}: front_end_angles_deg has {ang.size} entries, gain_correction "
                         f"{gain.size}: the scene has {n} front ends (calibrated on another "
                         "setup?)")
    for (i, j) in cals:
        if not (0 <= i < n and 0 <= j < n):
            raise SceneError(f"{where}: pair ({i}, {j}): must be front-end indices in "
                             f"[0, {n - 1}]")
    probe = FrontEndProbe(ang, np.full(n, np.nan), gain)
    return probe, cals


def bracketing_pair(angle_rad: float, fe_angles_rad: np.ndarray) -> tuple[int, int] | None:
    """Adjacent front ends (by measured angle) whose span contains ``angle_rad``."""
    order = np.argsort(fe_angles_rad)
    a = fe_angles_rad[order]
    for k in range(len(a) - 1):
        if a[k] <= angle_rad <= a[k + 1]:
            return int(order[k]), int(order[k + 1])
    return None


def pair_amplitudes(setup: Setup, paths: Paths, pair, target: TargetConfig, mode: str,
                    probes_rad, offsets=(0.0, 0.0), gain_correction=(1.0, 1.0)
                    ) -> tuple[float, float, float]:
    """Programmed amplitudes (A_I, A_J) and the ratio for a target synthesized by ``pair``.

    ``exact`` solves the ratio on the modelled RuT output of the nominal setup with the
    channels' delay offsets applied (their range offset) and coherent phases (what the
    calibration establishes); ``paper`` and ``array-factor`` use their closed forms with the front ends'
    geometric azimuths seen from the RuT.
    """
    from ..paths import nominal_model
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
    design is consistent, issue 13 item 1).

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
    from ..calibration.probes import if_phase_slope_hz
    from ..paths import nominal_model
    from ..calibration.steps import continuous_delay_setup
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


def residual_warning(scene, k: int, plan: PairPlan) -> str | None:
    """A run warning for target ``k`` where J's realised delay difference misses the planned
    one by more than half the RTS's delay step (what the calibration's own rounding leaves):
    no setting within reach realises it. The amplitudes are designed for the phase it
    leaves, so the angle holds on the nominal model, but the pair is that much less coherent
    than calibrated (power, sensitivity to the model). None where it does not."""
    res = scene.rts.delay_resolution_s
    eps = plan.quantisation_residual_s
    if abs(eps) <= 0.5 * res * (1 + 1e-6) + 1e-15:
        return None
    return (f"targets[{k}]: channel J's realised delay difference misses the calibrated one by "
            f"{eps * 1e12:.1f} ps ({plan.residual_phase_deg:.1f} deg of IF phase), more than "
            f"half the RTS delay step {res * 1e12:g} ps (rts.fractional_delay_step_s / "
            "rts.f_s_hz): no realisable setting is nearer; the amplitudes are designed for it")


def channel_offsets(n_fe: int, cals: dict[tuple[int, int], Calibration]) -> np.ndarray:
    """Per-channel delay offsets from pair calibrations chained along the arc."""
    off = np.zeros(n_fe)
    for (i, j), cal in sorted(cals.items()):
        off[j] = off[i] + cal.delta_tau_s
    return off


def check_pair(setup: Setup, i: int, j: int, name: str) -> tuple[int, int]:
    """A front-end pair of the arc in canonical order (the lower index first: I keeps its
    delay, J is swept); ``name`` labels the argument in the error (``--pair 0 1``).

    Pairs synthesize along the arc's azimuth: two adjacent front ends of an arc. A scene of
    2-D cells (front ends off elevation 0, :func:`uses_cells`) has no such pair: the error
    points to the commands that handle its cells."""
    from ..errors import ParameterError
    if uses_cells(setup.scene):
        raise ParameterError(
            f"{name}: this scene's front ends form 2-D cells (azimuth and elevation), not "
            "pairs on an arc: use `run`, `linearity --grid N`, `nearfield` and `tolerance "
            "--cell` for the cell")
    n = setup.fe.count
    if not (0 <= i < n and 0 <= j < n) or abs(i - j) != 1:
        raise ParameterError(f"{name}: must be two adjacent front-end indices in [0, {n - 1}]")
    return (min(i, j), max(i, j))


def uses_cells(scene) -> bool:
    """Whether the scene needs cells of N front ends in (azimuth, elevation): a front end off
    the arc, or a target with an elevation. Otherwise the cells are pairs on the arc."""
    return (any(fe.elevation_rad for fe in scene.rts.front_ends)
            or any(getattr(t, "elevation_rad", 0.0) for t in scene.targets))


def plan_targets(setup: Setup, paths: Paths, mode: str, calibrate: bool = True, progress=None,
                 calibration: dict | None = None) -> tuple[RtsProgram, dict, list[str]]:
    """The RTS program for the scene's targets at their set directions: the one planner.

    Targets on an arc (every elevation 0): each in the pair of front ends whose *measured*
    span holds it (the N = 2, D = 1 cell), the pairs calibrated along the arc
    (``calibrate_pair``), the ratio by :func:`pair_design`. Front ends on a sphere or targets
    in elevation: the enclosing cell of 3 or 4 front ends and one weight per channel
    (``aoa.plan_cells``; a calibration file, which holds pair calibrations, is refused there).

    ``calibration``: a calibration file's content (:func:`load_calibration`): its front-end
    angles, gain corrections and pair delays are used instead of measuring them again.
    Returns the program, the calibration record (for summary.json) and warnings.
    """
    scene = setup.scene
    if uses_cells(scene):
        if calibration is not None:
            raise SceneError(f"{scene.source}: --calibration: a calibration file holds pair "
                             "calibrations; front ends on a sphere are calibrated per channel "
                             "by the run itself")
        from .plan_cells import plan_cells
        return plan_cells(setup, paths, mode, calibrate, progress)
    seed = scene.seed
    loaded: dict = {}
    if calibration is not None:
        probe, loaded = load_calibration(calibration, setup)
    else:
        probe = probe_front_ends(setup, paths, seed)
    warnings = []
    if calibration is not None and (mismatch := calibration_mismatch(calibration, scene)):
        warnings.append(mismatch)
    lost = np.flatnonzero(~np.isfinite(probe.angle_rad))
    if lost.size:
        raise SceneError(f"{scene.source}: rts.front_ends[{lost[0]}]: the RuT does not detect "
                         "this front end alone (blocked line of sight, or an echo far weaker "
                         "than the noise" + probe.clipping_note() + "): cannot synthesize "
                         "angles with it")
    res = angular_resolution_rad(setup.rut)
    pairs = {}
    for k, t in enumerate(scene.targets):
        pair = bracketing_pair(t.angle_rad, probe.angle_rad)
        if pair is None:
            lo, hi = np.degrees(np.nanmin(probe.angle_rad)), np.degrees(np.nanmax(probe.angle_rad))
            raise SceneError(f"{scene.source}: targets[{k}].angle_deg = "
                             f"{np.degrees(t.angle_rad):g}: must be within the measured span of "
                             f"the front ends [{lo:.4f}, {hi:.4f}] deg (no pair can reach it)")
        pairs[k] = pair
        spacing = abs(probe.angle_rad[pair[1]] - probe.angle_rad[pair[0]])
        if spacing > res:
            warnings.append(f"targets[{k}]: front ends {pair} are {np.degrees(spacing):.2f} deg "
                            f"apart, more than the RuT's angular resolution "
                            f"{np.degrees(res):.2f} deg (eq. 24): expect two peaks")
    cals: dict[tuple[int, int], Calibration] = {}
    if calibrate:
        for pair in sorted(set(pairs.values())):
            base = channel_offsets(setup.fe.count, cals)
            if calibration is not None:
                if pair not in loaded:
                    raise SceneError(f"calibration file: has no pair {pair} (it has "
                                     f"{sorted(loaded)}): run `rtsgeom calibrate SCENE --pair "
                                     f"{pair[0]} {pair[1]} --out DIR`")
                cals[pair] = loaded[pair]
                continue
            cals[pair] = calibrate_pair(setup, paths, pair, probe, (base[pair[0]], base[pair[0]]),
                                        seed)
            if progress:
                progress(f"calibrated pair {pair}: delta_tau {cals[pair].delta_tau_s * 1e12:.1f} ps")
    offsets = channel_offsets(setup.fe.count, cals)
    rows, realised = [], []
    for k, t in enumerate(scene.targets):
        i, j = pairs[k]
        probes = probe_angles(probe.angle_rad[i], probe.angle_rad[j])
        cal = cals.get((i, j))
        try:
            plan = plan_pair(setup, paths, (i, j), t, mode, probes, (offsets[i], offsets[j]),
                             probe.gain_correction[[i, j]],
                             cal.quantisation_residual_s if cal is not None else 0.0)
        except AngleUnreachable as exc:
            raise SceneError(f"{scene.source}: targets[{k}].angle_deg = "
                             f"{np.degrees(t.angle_rad):g}: {exc}") from None
        tau = float(requested_delay(scene, t.range_m))
        f_d = 2 * scene.radar.f_c_hz * t.velocity_mps / c
        rows += [(k, i, tau + offsets[i], f_d, plan.a_i), (k, j, tau + plan.offset_j_s, f_d,
                                                           plan.a_j)]
        realised.append({"target": k, "pair": [i, j], **plan.to_dict()})
        note = residual_warning(scene, k, plan)
        if note:
            warnings.append(note)
    program = RtsProgram.build(*zip(*rows)) if rows else RtsProgram.build([], [], [], [], [])
    record = {
        "mode": mode,
        "source": "file" if calibration is not None else "measured",
        "front_end_angles_deg": [float(x) for x in np.degrees(probe.angle_rad)],
        "gain_correction": [float(x) for x in probe.gain_correction],
        "channel_delay_offsets_s": [float(x) for x in offsets],
        "pairs": [cal.to_dict() for cal in cals.values()],
        "targets": realised,  # each target's J delay as realised (PairPlan.to_dict)
    }
    return program, record, warnings
