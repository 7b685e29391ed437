"""Targets in azimuth and elevation: pick the enclosing cell of front ends, calibrate its
channels, solve one weight per channel (issue 15): the cell branch of the one planner,
``aoa.plan.plan_targets``.

Taken when any front end or target has a non-zero elevation (``plan.uses_cells``). The cells come from the front
ends' geometric direction cosines seen from the RuT (``aoa.cells``); the weights from
:class:`~rtsgeom.synthesis.model.ChannelModel` on the nominal setup with the channels' calibrated
delay offsets and their natural phases (what the RuT sees of a nominal setup) when
uncalibrated, or the phases the calibration establishes (each measured pair
coherent where its probes sat, ``ncal.tree_phases``), amplitudes times each channel's measured
gain correction.
"""

from __future__ import annotations

import numpy as np
from scipy.constants import c

from ..geometry import Setup
from ..paths import Paths
from ..radar.steering import Steering
from ..rts.channels import RtsProgram, requested_delay
from ..errors import SceneError
from ..errors import CellUnreachable
from ..synthesis.cells import enclosing_cell
from ..errors import AngleUnreachable
from ..synthesis.model import ChannelModel, target_direction
from .plan import uses_cells  # noqa: F401  (re-exported: the planner decides with it)

__all__ = ["plan_cells", "target_cells", "uses_cells"]


def target_cells(setup: Setup) -> tuple[Steering, np.ndarray, list]:
    """Each target's enclosing cell of front ends (``aoa.cells.enclosing_cell`` on the front
    ends' geometric direction cosines seen from the RuT, 1-D where the RuT beamforms in
    azimuth only): the RuT's steering, the front ends' direction cosines (F, D) and per
    target ``(cell, None)`` or ``(None, why)`` (the field and the reason it is unreachable).
    Shared by the planner and ``rtsgeom info``."""
    scene = setup.scene
    st = Steering.auto(setup.rut, scene.radar)  # the beamformer the RuT runs
    u_fe = setup.fe_direction_cosines(st.dims)
    out: list = []
    for k, t in enumerate(scene.targets):
        if st.dims == 1 and getattr(t, "elevation_rad", 0.0):
            out.append((None, f"targets[{k}].elevation_deg = {np.degrees(t.elevation_rad):g}: "
                              f"must be 0: the RuT's array ({scene.radar.antenna_preset}, "
                              "use_elevation_tx = "
                              f"{str(scene.radar.use_elevation_tx).lower()}) has no elevation "
                              "extent, it cannot see a target's elevation"))
            continue
        try:
            out.append((enclosing_cell(target_direction(st, t), u_fe), None))
        except CellUnreachable as exc:
            out.append((None, f"targets[{k}] (angle_deg = {np.degrees(t.angle_rad):g}, "
                              f"elevation_deg = {np.degrees(getattr(t, 'elevation_rad', 0.0)):g})"
                              f": unreachable: {exc}"))
    return st, u_fe, out


def plan_cells(setup: Setup, paths: Paths, mode: str, calibrate: bool = True, progress=None
               ) -> tuple[RtsProgram, dict, list[str]]:
    """The RTS program for the scene's targets at their set (azimuth, elevation).

    Returns the program, the calibration record (for summary.json) and warnings."""
    from ..paths import nominal_model
    from ..calibration.probes import probe_front_ends
    from ..errors import CalibrationFailed
    from ..calibration.channels import calibrate_channels, tree_phases
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
                raise SceneError(f"{scene.source}: targets[{k}]: the channel calibration "
                                 f"failed ({'; '.join(cal.warnings)}), and with its offsets "
                                 f"{exc}") from None
            cal_note = ("" if tree is None else " (with the channel calibration's delay "
                        f"offsets {np.round(offsets[list(cell)] * 1e12, 1).tolist()} ps)")
            raise SceneError(f"{scene.source}: targets[{k}]: {exc}{cal_note}") from None
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
