"""Targets at arbitrary angles: pick the bracketing front-end pair, calibrate, set amplitudes.

The reachable span of a pair is *measured* (each front end alone, detected by the simulated
RuT), not assumed: the Rx/Tx separation and the near field bias a single front end's angle.
"""

from __future__ import annotations

import numpy as np

from ..geometry import Setup
from ..geometry.farfield import angular_resolution_rad
from ..paths import Paths
from ..rts import RtsProgram, requested_delay
from ..scene import SceneError, TargetConfig
from scipy.constants import c
from .calibration import (Calibration, FrontEndProbe, calibrate_pair, probe_angles,
                          probe_front_ends)
from .model import AngleUnreachable, ChannelModel
from .sweep import HALF_BINS
from .synthesis import PairModel

__all__ = ["bracketing_pair", "pair_amplitudes", "plan_targets", "uses_cells", "channel_offsets",
           "load_calibration", "CALIBRATION_FORMAT"]

CALIBRATION_FORMAT = "rtsgeom-calibration"


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
    from .calibration import nominal_model
    nom, nom_paths = nominal_model(setup, paths)
    model = PairModel.build(nom, nom_paths, pair, target, offsets)
    alpha = target.angle_rad
    phase = model.coherent_phase(probes_rad)  # the phase the calibration establishes
    rho = model.solve(alpha, phase, mode=mode)  # exact: root finder; else closed forms
    a_i, a_j = model.amplitudes(rho, alpha, phase)
    return a_i * gain_correction[0], a_j * gain_correction[1], rho


MIN_BIN_MARGIN = 1.2  # detected bin's power over the next strongest that counts as unambiguous


def pair_design(setup: Setup, paths: Paths, pair, target: TargetConfig, mode: str, probes_rad,
                offsets=(0.0, 0.0), gain_correction=(1.0, 1.0), period_s: float | None = None
                ) -> tuple[float, float, float, float]:
    """:func:`pair_amplitudes` with channel J's delay offset chosen among the calibrated one
    and one period of the target's IF phase either side (``offsets[1] + m period``,
    m = 0, -1, 1: the same phase, J's echo a period's range further): the first whose exact
    design the RuT detects at the bin it was designed for, with the largest power margin.
    Where J's echo straddles a range-bin boundary no design is consistent (each moves the
    peak to the other bin) and the angle misses by up to a degree (issue 13 item 1).
    Returns (A_I, A_J, rho, offset of J)."""
    from .calibration import if_phase_slope_hz, nominal_model
    if mode != "exact":
        return (*pair_amplitudes(setup, paths, pair, target, mode, probes_rad, offsets,
                                 gain_correction), float(offsets[1]))
    scene = setup.scene
    nom, nom_paths = nominal_model(setup, paths)
    period = period_s or 1.0 / float(if_phase_slope_hz(scene, 2 * target.range_m / c))
    best = None
    fir = scene.rts.fractional_delay and scene.rts.fractional_delay_filter != "ideal"
    for m in (0, -1, 1):
        off = (offsets[0], offsets[1] + m * period)
        # candidate bins +-3: a period moves J's echo by about a bin
        model = PairModel(ChannelModel.build(nom, nom_paths, pair, target, off, HALF_BINS))
        phase = model.coherent_phase(probes_rad)
        if m == 0:
            phase0 = phase
        for _ in range(2 if m and fir else 0):
            # the fractional-delay FIR's response cycles with its setting every 1/f_s: a
            # period later J's phase at the bin is not the calibrated one (up to 4 deg with 5
            # taps, 0.003 deg of angle); Newton on the modelled phase back to it
            miss = np.angle(np.exp(1j * (phase - phase0)))
            off = (off[0], off[1] + miss / (2 * np.pi) * period)
            model = PairModel(ChannelModel.build(nom, nom_paths, pair, target, off, HALF_BINS))
            phase = model.coherent_phase(probes_rad)
        rho, ok, margin = model.model.solve_checked(target.angle_rad, (0.0, phase))
        if rho is None:
            continue
        score = (ok, margin if ok else 0.0, -abs(m))
        if best is None or score > best[0]:
            best = (score, model, rho, phase, off)
        if ok and margin > MIN_BIN_MARGIN:  # the calibrated offset unless it is ambiguous
            break
    if best is None:
        return (*pair_amplitudes(setup, paths, pair, target, mode, probes_rad, offsets,
                                 gain_correction), float(offsets[1]))
    _, model, rho, phase, off = best
    a_i, a_j = model.amplitudes(rho, target.angle_rad, phase)
    return (a_i * gain_correction[0], a_j * gain_correction[1], float(rho), float(off[1]))


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
    rows = []
    for k, t in enumerate(scene.targets):
        i, j = pairs[k]
        probes = probe_angles(probe.angle_rad[i], probe.angle_rad[j])
        try:
            a_i, a_j, _, off_j = pair_design(setup, paths, (i, j), t, mode, probes,
                                             (offsets[i], offsets[j]),
                                             probe.gain_correction[[i, j]])
        except AngleUnreachable as exc:
            raise SceneError(f"{scene.source}: targets[{k}].angle_deg = "
                             f"{np.degrees(t.angle_rad):g}: {exc}") from None
        tau = float(requested_delay(scene, t.range_m))
        f_d = 2 * scene.radar.f_c_hz * t.velocity_mps / c
        rows += [(k, i, tau + offsets[i], f_d, a_i), (k, j, tau + off_j, f_d, a_j)]
    program = RtsProgram.build(*zip(*rows)) if rows else RtsProgram.build([], [], [], [], [])
    record = {
        "mode": mode,
        "source": "file" if calibration is not None else "measured",
        "front_end_angles_deg": [float(x) for x in np.degrees(probe.angle_rad)],
        "gain_correction": [float(x) for x in probe.gain_correction],
        "channel_delay_offsets_s": [float(x) for x in offsets],
        "pairs": [cal.to_dict() for cal in cals.values()],
    }
    return program, record, warnings
