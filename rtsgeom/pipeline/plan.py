"""The one planner: the RTS programme for the scene's targets at their set directions.

Each target is synthesized by the cell of front ends that encloses its direction: on an arc
(every front end and target at elevation 0) the adjacent pair whose *measured* span holds it
(each front end alone as the simulated RuT detects it: the Rx/Tx separation and the near field
bias a single front end's angle), calibrated pair by pair along the arc and programmed on the
delays the RTS realises (:mod:`.pair`); on a sphere (front ends or targets in elevation) the
enclosing cell of 3 or 4 front ends by their direction cosines (:mod:`rtsgeom.synthesis.cells`),
its channels calibrated along a spanning tree of pairs (:mod:`rtsgeom.calibration.channels`),
one weight per channel (:meth:`ChannelModel.solve <rtsgeom.synthesis.model.ChannelModel.solve>`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from scipy.constants import c

from ..calibration.chains import calibrate_chained
from ..calibration.channels import calibrate_channels, channel_offsets, pair_edges, tree_phases
from ..calibration.file import calibration_mismatch, load_calibration
from ..calibration.phasor import PairChannels
from ..calibration.sweep import Calibration
from ..calibration.probes import FrontEndProbe, front_end_models, probe_angles, probe_front_ends
from ..errors import (AngleUnreachable, CalibrationFailed, CellUnreachable, ParameterError,
                      SceneError)
from ..geometry import Setup
from ..geometry.farfield import angular_resolution_rad
from ..paths import Paths, nominal_model
from ..radar.steering import Steering
from ..rts.channels import RtsProgram, requested_delay
from ..scene.objects import target_field, target_labels
from ..synthesis.cells import enclosing_cell
from ..synthesis.model import ChannelModel, target_direction
from .merge import budget_targets
from .pair import plan_pair, plan_pairs, residual_warning

__all__ = ["bracketing_pair", "modelled_pair", "probe_pair", "check_pair", "measured_pairs",
           "uses_cells", "target_cells", "plan_targets", "target_pairs", "calibrate_pairs",
           "FixedCalibration",
           "program_pairs", "program_frames"]


def bracketing_pair(angle_rad: float, fe_angles_rad: np.ndarray) -> tuple[int, int] | None:
    """Adjacent front ends (by measured angle) whose span contains ``angle_rad``."""
    order = np.argsort(fe_angles_rad)
    a = fe_angles_rad[order]
    for k in range(len(a) - 1):
        if a[k] <= angle_rad <= a[k + 1]:
            return int(order[k]), int(order[k + 1])
    return None


def modelled_pair(angle_rad: float, probe) -> tuple[int, int] | None:
    """The pair of :func:`bracketing_pair` on the front ends' *measured* angles, or, where the
    planner's model puts the target in the pair beside it, that one.

    The exact design (:func:`~.pair.plan_pair`) works on the nominal model and reaches the
    angles between its two front ends as that model reads them
    (``FrontEndProbe.model_angle_rad``). The measured angles differ from those by the probe
    frame's noise (at the template's 10 dB SNR up to 0.18 deg on an arc of 1 deg steps) and
    by the bench's unknown mounting errors; a target between the measured and the modelled
    angle of the front end two pairs share lies outside the measured pair's modelled span,
    where no design of that pair reaches it (J alone reads the modelled angle), and inside
    the neighbour's, whose design reaches it exactly. No tolerance: the neighbour is taken
    wherever the model brackets the target with it (and the two are neighbours in measured
    angle as well)."""
    pair = bracketing_pair(angle_rad, probe.angle_rad)
    model = getattr(probe, "model_angle_rad", None)
    if pair is None or model is None or not np.all(np.isfinite(model)):
        return pair
    alt = bracketing_pair(angle_rad, np.asarray(model, float))
    if alt is None or len(set(alt) & set(pair)) != 1:
        return pair
    rank = np.argsort(np.argsort(probe.angle_rad))  # alt adjacent in measured angle too
    return alt if abs(int(rank[alt[0]]) - int(rank[alt[1]])) == 1 else pair


def probe_pair(probe):
    """:func:`modelled_pair` of ``probe`` as a budget's ``pair_of(angle_rad, angles_rad)``
    (``merge.budget_targets``: the channels a target loads are the pair it is planned on)."""
    return lambda angle_rad, _angles=None: modelled_pair(angle_rad, probe)


def check_pair(setup: Setup, i: int, j: int, name: str, cells: bool = False
               ) -> tuple[int, int]:
    """A front-end pair in canonical order (the lower index first: I keeps its delay, J is
    swept); ``name`` labels the argument in the error (``--pair 0 1``).

    Pairs synthesize along the arc's azimuth: two adjacent front ends of an arc. A scene of
    2-D cells (front ends off elevation 0, :func:`uses_cells`) has no such pair: the error
    points to the commands that handle its cells; with ``cells`` (what is measured pair by
    pair there, the calibration) the pairs are its cells' edges (:func:`measured_pairs`)."""
    n = setup.fe.count
    if not (0 <= i < n and 0 <= j < n):
        raise ParameterError(f"{name}: must be two {'neighbouring' if cells else 'adjacent'} "
                             f"front-end indices in [0, {n - 1}]")
    if uses_cells(setup.scene):
        if not cells:
            raise ParameterError(
                f"{name}: this scene's front ends form 2-D cells (azimuth and elevation), not "
                "pairs on an arc: use `run`, `linearity --grid N`, `nearfield` and `tolerance "
                "--cell` for the cell")
        edges = measured_pairs(setup)
        if (min(i, j), max(i, j)) not in edges:
            raise ParameterError(f"{name}: not neighbours in this scene's cells; its pairs "
                                 f"are {', '.join(f'{a} {b}' for a, b in edges)}")
    elif abs(i - j) != 1:
        raise ParameterError(f"{name}: must be two adjacent front-end indices in [0, {n - 1}]")
    return (min(i, j), max(i, j))


def measured_pairs(setup: Setup) -> list[tuple[int, int]]:
    """The pairs a channel calibration measures: adjacent front ends on an arc, the edges
    between neighbouring front ends (side by side, stacked in elevation or across a cell's
    diagonal; ``calibration.channels.pair_edges``) in a 2-D beamformer."""
    st = Steering.auto(setup.rut, setup.scene.radar)
    return pair_edges(setup.fe_direction_cosines(st.dims), range(setup.fe.count))


def uses_cells(scene) -> bool:
    """Whether the scene needs cells of N front ends in (azimuth, elevation): a front end off
    the arc, or a target with an elevation. Otherwise the cells are pairs on the arc."""
    return (any(fe.elevation_rad for fe in scene.rts.front_ends)
            or any(getattr(t, "elevation_rad", 0.0) for t in scene.targets))


def target_cells(setup: Setup) -> tuple[Steering, np.ndarray, list]:
    """Each target's enclosing cell of front ends (``synthesis.cells.enclosing_cell`` on the front
    ends' geometric direction cosines seen from the RuT, 1-D where the RuT beamforms in
    azimuth only): the RuT's steering, the front ends' direction cosines (F, D) and per
    target ``(cell, None)`` or ``(None, why)`` (the field and the reason it is unreachable).
    Shared by the planner and ``rtsgeom info``."""
    scene = setup.scene
    st = Steering.auto(setup.rut, scene.radar)  # the beamformer the RuT runs
    u_fe = setup.fe_direction_cosines(st.dims)
    out: list = []
    names = target_labels(scene)
    for k, t in enumerate(scene.targets):
        if st.dims == 1 and getattr(t, "elevation_rad", 0.0):
            out.append((None, f"{target_field(names[k], 'elevation_deg')} = "
                              f"{np.degrees(t.elevation_rad):g}: "
                              f"must be 0: the RuT's array ({scene.radar.antenna_preset}, "
                              "use_elevation_tx = "
                              f"{str(scene.radar.use_elevation_tx).lower()}) has no elevation "
                              "extent, it cannot see a target's elevation"))
            continue
        try:
            out.append((enclosing_cell(target_direction(st, t), u_fe), None))
        except CellUnreachable as exc:
            out.append((None, f"{names[k]} (angle_deg = {np.degrees(t.angle_rad):g}, "
                              f"elevation_deg = {np.degrees(getattr(t, 'elevation_rad', 0.0)):g})"
                              f": unreachable: {exc}"))
    return st, u_fe, out


def plan_targets(setup: Setup, paths: Paths, mode: str, calibrate: bool = True, progress=None,
                 calibration: dict | None = None) -> tuple[RtsProgram, dict, list[str]]:
    """The RTS program for the scene's targets at their set directions: the one planner.

    Targets on an arc (every elevation 0): each in the pair of front ends whose *measured*
    span holds it (the N = 2, D = 1 cell), the pairs calibrated along the arc
    (``calibrate_pair``), the ratio by :func:`~.pair.plan_pair`. Front ends on a sphere or targets
    in elevation: the enclosing cell of 3 or 4 front ends and one weight per channel
    (a calibration file, which holds pair calibrations, is refused there).

    ``calibration``: a calibration file's content (:func:`load_calibration`): its front-end
    angles, gain corrections and pair delays are used instead of measuring them again.
    Returns the program, the calibration record (for summary.json) and warnings.
    """
    scene = setup.scene
    if uses_cells(scene):
        if scene.rts.max_targets_per_channel is not None:
            raise SceneError(f"{scene.source}: rts.max_targets_per_channel = "
                             f"{scene.rts.max_targets_per_channel}: must be left out for "
                             "front ends on a sphere or targets in elevation (the budget "
                             "merges targets on an arc's pairs)")
        if calibration is not None:
            raise SceneError(f"{scene.source}: --calibration: a calibration file holds pair "
                             "calibrations; front ends on a sphere are calibrated per channel "
                             "by the run itself")
        return _plan_cells(setup, paths, mode, calibrate, progress)
    n_az = setup.rut.azimuth_positions_m.size
    if n_az < 2 and not scene.radar.elevation_processing:  # no azimuth aperture to measure
        raise SceneError(f"{scene.source}: radar.array: the azimuth row of the virtual array "
                         f"(its row with the most elements) has {n_az} distinct position: must "
                         "have at least 2 for the RuT to measure an azimuth (put Tx and Rx "
                         "elements side by side at one height, or set "
                         "radar.elevation_processing = true)")
    loaded: dict = {}
    if calibration is not None:  # the file's measured angles, the model's beside them
        probe, loaded = load_calibration(calibration, setup)
        probe = dataclasses.replace(probe, model_angle_rad=front_end_models(setup, paths)[2])
    else:
        probe = probe_front_ends(setup, paths, scene.seed)
    warnings = []
    if calibration is not None and (mismatch := calibration_mismatch(calibration, scene)):
        warnings.append(mismatch)
    targets, budget = scene.targets, None
    if scene.rts.max_targets_per_channel is not None:  # dynamic resolution (.merge)
        budget = budget_targets(setup, scene.targets, probe, probe_pair(probe))
        targets = budget.targets
    where = target_namer(scene, budget=budget)  # as the file names them
    pairs, notes = target_pairs(setup, probe, targets, where)
    warnings += notes
    cals = (calibrate_pairs(setup, paths, sorted(set(pairs)), probe,
                            loaded if calibration is not None else None, progress)
            if calibrate else {})
    offsets = channel_offsets(setup.fe.count, cals)
    program, realised, notes = program_pairs(setup, paths, mode, targets, pairs,
                                             FixedCalibration(probe, cals, offsets),
                                             where=where)
    warnings += notes
    if budget is not None:
        program = lead_program(program, budget)
    record = {
        "mode": mode,
        "source": "file" if calibration is not None else "measured",
        "front_end_angles_deg": [float(x) for x in np.degrees(probe.angle_rad)],
        "gain_correction": [float(x) for x in probe.gain_correction],
        "channel_delay_offsets_s": [float(x) for x in offsets],
        "pairs": [cal.to_dict() for cal in cals.values()],
        "targets": realised,  # each target's J delay as realised (PairPlan.to_dict)
    }
    if budget is not None:
        record["budget"] = budget.to_dict()
    return program, record, warnings


def lead_program(program: RtsProgram, budget) -> RtsProgram:
    """A budgeted programme's rows labelled with the scene's target each synthesized target
    stands for (its strongest member, :meth:`~.merge.Budgeted.lead`)."""
    return RtsProgram.build(budget.lead()[program.target], program.front_end, program.delay_s,
                            program.doppler_hz, program.amplitude)


def target_name(where, k: int) -> str:
    """Target ``k`` as messages name it: ``where[k]`` for a prefix (``targets``), or
    ``where(k)`` (a drive's frames name static and moving targets apart; an object's
    scatterers as the file writes them, :func:`target_namer`)."""
    return where(k) if callable(where) else f"{where}[{k}]"


def target_namer(scene, targets=None, budget=None, moving_from: int | None = None):
    """``k -> name`` of ``targets`` (default the scene's) as the file writes them
    (:func:`rtsgeom.scene.objects.target_labels`); under a ``budget`` (``targets`` the
    scatterers, ``k`` a synthesized target) its strongest member, and how many it merges."""
    names = target_labels(scene, targets, moving_from)
    if budget is None:
        return names.__getitem__
    lead = budget.lead()
    return lambda k: names[lead[k]] + (f" (merged target of {len(budget.members[k])} "
                                       "scatterers)" if len(budget.members[k]) > 1 else "")


def target_pairs(setup: Setup, probe, targets, where: str = "targets"
                 ) -> tuple[list[tuple[int, int]], list[str]]:
    """Each target's pair of front ends: the adjacent pair whose *measured* span (``probe``,
    each front end alone as the RuT detects it) holds its angle, or the one beside it where
    the planner's model brackets it there (:func:`modelled_pair`), and a warning per pair wider
    than the RuT's angular resolution (eq. 24). ``where`` names the targets in messages.
    Raises ``SceneError`` for a front end the RuT does not detect or a target outside the
    measured span."""
    scene = setup.scene
    lost = np.flatnonzero(~np.isfinite(probe.angle_rad))
    if lost.size:
        raise SceneError(f"{scene.source}: rts.front_ends[{lost[0]}]: the RuT does not detect "
                         "this front end alone (blocked line of sight, or an echo far weaker "
                         "than the noise" + probe.clipping_note() + "): cannot synthesize "
                         "angles with it")
    res = angular_resolution_rad(setup.rut)
    pairs, warnings = [], []
    for k, t in enumerate(targets):
        pair = modelled_pair(t.angle_rad, probe)
        if pair is None:
            lo, hi = np.degrees(np.nanmin(probe.angle_rad)), np.degrees(np.nanmax(probe.angle_rad))
            raise SceneError(f"{scene.source}: "
                             f"{target_field(target_name(where, k), 'angle_deg')} = "
                             f"{np.degrees(t.angle_rad):g}: must be within the measured span of "
                             f"the front ends [{lo:.4f}, {hi:.4f}] deg (no pair can reach it)")
        pairs.append(pair)
        spacing = abs(probe.angle_rad[pair[1]] - probe.angle_rad[pair[0]])
        if spacing > res:
            warnings.append(f"{target_name(where, k)}: front ends {pair} are {np.degrees(spacing):.2f} deg "
                            f"apart, more than the RuT's angular resolution "
                            f"{np.degrees(res):.2f} deg (eq. 24): expect two peaks")
    return pairs, warnings


def calibrate_pairs(setup: Setup, paths: Paths, pairs, probe, loaded: dict | None = None,
                    progress=None) -> dict[tuple[int, int], Calibration]:
    """The pairs' calibrations, in the given order, each with channel I at the delay offset
    the pairs before it chained (``channel_offsets``); taken from ``loaded`` (a calibration
    file's pairs) where it is given."""
    if loaded is None:  # measured: independent chains side by side, the same calibrations
        return calibrate_chained(setup, paths, pairs, probe, progress)
    missing = [pair for pair in pairs if pair not in loaded]
    if missing:
        raise SceneError(f"calibration file: has no pair {missing[0]} (it has "
                         f"{sorted(loaded)}): run `rtsgeom calibrate SCENE --pair "
                         f"{missing[0][0]} {missing[0][1]} --out DIR`")
    return {pair: loaded[pair] for pair in pairs}


@dataclass(frozen=True)
class FixedCalibration:
    """The calibration a programme is planned with, fixed: the front ends' ``probe``
    (measured angles, gain corrections), the pairs' calibrations ``cals`` ((i, j) ->
    :class:`~rtsgeom.calibration.sweep.Calibration`) and the channels' delay offsets
    ``offsets`` (F,) s (:func:`~rtsgeom.calibration.channels.channel_offsets`)."""

    probe: FrontEndProbe
    cals: dict
    offsets: np.ndarray


def program_pairs(setup: Setup, paths: Paths, mode: str, targets, pairs,
                  fixed: FixedCalibration, *, where: str = "targets"
                  ) -> tuple[RtsProgram, list[dict], list[str]]:
    """The RTS programme of ``targets`` on their ``pairs`` with the calibration ``fixed``:
    per target channel I at the target's delay plus its offset, channel J at the delay
    :func:`~.pair.plan_pair` chose, both amplitudes from it. Returns the programme, each
    target's realised plan (for summary.json) and warnings; ``SceneError`` for an angle the
    pair cannot reach."""
    return program_frames(setup, paths, mode, [targets], [pairs], fixed, [where])[0]


def program_frames(setup: Setup, paths: Paths, mode: str, frames, pairs,
                   fixed: FixedCalibration, wheres
                   ) -> list[tuple[RtsProgram, list[dict], list[str]]]:
    """:func:`program_pairs` of several frames (``frames``: each frame's targets, ``pairs``
    and ``wheres`` per frame) at once: every target's design at the calibrated offset in one
    batch (:func:`~.pair.plan_pairs`), the few it leaves open by :func:`~.pair.plan_pair`;
    the same programmes as frame by frame."""
    rows = [[_pair_row(fixed.probe, fixed.cals, fixed.offsets, pr, t)
             for t, pr in zip(tg, ps)] for tg, ps in zip(frames, pairs)]
    plans = iter(plan_pairs(setup, paths, mode, [r for fr in rows for r in fr]))
    return [_frame_programme(setup, paths, mode, tg, fr, [next(plans) for _ in fr], where)
            for tg, fr, where in zip(frames, rows, wheres)]


def _pair_row(probe, cals, offsets, pair, target) -> tuple:
    """:func:`~.pair.plan_pairs`' row of a target on ``pair`` with the calibration fixed."""
    i, j = pair
    cal = cals.get((i, j))
    return ((i, j), target, probe_angles(probe.angle_rad[i], probe.angle_rad[j]),
            (offsets[i], offsets[j]), probe.gain_correction[[i, j]],
            cal.quantisation_residual_s if cal is not None else 0.0)


def _frame_programme(setup, paths, mode, targets, rows, plans, where):
    """One frame's programme from its rows and the batch's plans (None: planned here)."""
    scene = setup.scene
    out, realised, warnings = [], [], []
    for k, (t, row, plan) in enumerate(zip(targets, rows, plans)):
        (i, j), offs = row[0], row[3]
        if plan is None:
            try:
                plan = plan_pair(setup, paths, PairChannels(row[0], row[3], row[4]), t, mode,
                                 row[2], row[5])
            except AngleUnreachable as exc:
                raise SceneError(f"{scene.source}: "
                                 f"{target_field(target_name(where, k), 'angle_deg')} = "
                                 f"{np.degrees(t.angle_rad):g}: {exc}") from None
        tau = float(requested_delay(scene, t.range_m))
        f_d = 2 * scene.radar.f_c_hz * t.velocity_mps / c
        out += [(k, i, tau + offs[0], f_d, plan.a_i), (k, j, tau + plan.offset_j_s, f_d,
                                                       plan.a_j)]
        realised.append({"target": k, "pair": [i, j], **plan.to_dict()})
        note = residual_warning(scene, k, plan, target_name(where, k))
        if note:
            warnings.append(note)
    program = RtsProgram.build(*zip(*out)) if out else RtsProgram.build([], [], [], [], [])
    return program, realised, warnings


def _plan_cells(setup: Setup, paths: Paths, mode: str, calibrate: bool = True, progress=None
               ) -> tuple[RtsProgram, dict, list[str]]:
    """The RTS program for the scene's targets at their set (azimuth, elevation).

    Returns the program, the calibration record (for summary.json) and warnings."""
    scene = setup.scene
    nom, nom_paths = nominal_model(setup, paths)
    probe = probe_front_ends(setup, paths, scene.seed)
    warnings: list[str] = []
    st, u_fe, found = target_cells(nom)
    cells = {}
    for k, (cell, why) in enumerate(found):
        if cell is None:
            raise SceneError(f"{scene.source}: {why}")
        cells[k] = cell
    offsets = np.zeros(setup.fe.count)
    cal_record: dict = {}
    used = sorted({q for cell in cells.values() for q in cell})
    tree = None
    if calibrate:
        try:
            cal = calibrate_channels(setup, paths, used, probe, progress=progress)
        except CalibrationFailed as exc:
            raise SceneError(f"{scene.source}: the channel calibration failed: {exc}") from None
        offsets, tree = cal.offsets_s, cal.tree
        cal_record = cal.to_dict()
        warnings += list(cal.warnings)
    rows = []
    for k, t in enumerate(scene.targets):
        cell = cells[k]
        u = target_direction(st, t)
        phases = None  # uncalibrated: the phases the channels' delays give
        if tree is not None:  # calibrated: coherent pairwise where the probes sat
            cs_all = ChannelModel.build(nom, nom_paths, used, t, offsets[used], steering=st)
            phases = tree_phases(cs_all, tree)[[used.index(q) for q in cell]]
        cs = ChannelModel.build(nom, nom_paths, cell, t, offsets[list(cell)], steering=st)
        try:
            w = cs.solve(u, phases, mode=mode)
        except AngleUnreachable as exc:
            if tree is not None and cal.failed:  # inside the cell: the calibration is why
                raise SceneError(f"{scene.source}: {target_labels(scene)[k]}: the channel "
                                 "calibration "
                                 f"failed ({'; '.join(cal.warnings)}), and with its offsets "
                                 f"{exc}") from None
            cal_note = ("" if tree is None else " (with the channel calibration's delay "
                        f"offsets {np.round(offsets[list(cell)] * 1e12, 1).tolist()} ps)")
            raise SceneError(f"{scene.source}: {target_labels(scene)[k]}: {exc}{cal_note}"
                             ) from None
        amps = cs.amplitudes(w, u) * probe.gain_correction[list(cell)]
        tau = float(requested_delay(scene, t.range_m))
        f_d = 2 * scene.radar.f_c_hz * t.velocity_mps / c
        rows += [(k, q, tau + offsets[q], f_d, float(a)) for q, a in zip(cell, amps)]
    program = RtsProgram.build(*zip(*rows)) if rows else RtsProgram.build([], [], [], [], [])
    record = {
        "mode": mode,
        "cells": {str(k): list(v) for k, v in cells.items()},
        "front_end_angles_deg": [float(x) for x in np.degrees(probe.angle_rad)],
        "front_end_direction_cosines": [[float(x) for x in row] for row in u_fe],
        "gain_correction": [float(x) for x in probe.gain_correction],
        "channel_delay_offsets_s": [float(x) for x in offsets],
        "pairs": cal_record.get("pairs", []),
        "channels": cal_record,
    }
    return program, record, warnings
