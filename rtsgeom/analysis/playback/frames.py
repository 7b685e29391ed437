"""A drive frame by frame: the set-points, the RTS programme and the RuT's detections.

The setup is calibrated once, as a lab does (every pair the drive visits, in order along the
arc, :func:`rtsgeom.pipeline.plan.calibrate_pairs`); each frame is then one static scene (the
``[[targets]]`` and the moving targets at their set-points at the frame's time) planned with that
calibration by the planner of ``rtsgeom run`` (:func:`~rtsgeom.pipeline.plan.program_pairs`,
or ``program_nearest`` for the switched baseline) and run through the full signal chain
(ADC cube, range-Doppler, CFAR, the RuT's angle estimate). Within a frame the target is
static in range (its Doppler is programmed): the range it moves in one frame (v T_frame) is
what the frame period resolves.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import ParameterError
from ...geometry import Setup
from ...paths import Paths
from ...pipeline.merge import budget_targets
from ...pipeline.plan import (FixedCalibration, calibrate_pairs, lead_program,
                              probe_pair, program_frames, target_namer, target_pairs,
                              uses_cells)
from ...pipeline.matching import in_gate, match_targets, truth_twin
from ...radar.frame import observe
from ...radar.windowed import cell_centres
from ...calibration.channels import channel_offsets
from ...calibration.probes import probe_front_ends
from ...rts.channels import RtsProgram, apparent_range, program_nearest
from ...scene import Scene, TargetConfig
from ...scene.objects import frame_objects
from ...scene.scenario import trajectory

__all__ = ["frame_targets", "frame_target_names", "FramePlanner", "detect_frame", "PLAN_BLOCK"]

#: frames planned in one batch (:meth:`FramePlanner.program`)
PLAN_BLOCK = 16


def frame_targets(scene: Scene) -> tuple[np.ndarray, list[tuple[TargetConfig, ...]]]:
    """The frames' times and each frame's targets: the scene's ``[[targets]]`` (indices 0..S-1)
    then the ``[[scenario.targets]]`` at their set-points (S..), as ``TargetConfig``, then the
    moving objects' scatterers (:func:`rtsgeom.scene.objects.frame_objects`)."""
    sc = scene.scenario
    times = sc.frame_times()
    sps = {i: trajectory(t.waypoints, times) for i, t in enumerate(sc.targets)}
    moving = [(sps[i], t.rcs_dbsm) for i, t in enumerate(sc.targets)
              if t.scatterers is None and t.mesh is None]
    objects = frame_objects(scene, sps, times.size)  # an object's scatterers, each frame
    static = tuple(scene.targets)
    frames = []
    for f in range(times.size):
        frames.append(static + tuple(
            TargetConfig(range_m=float(sp.range_m[f]), velocity_mps=float(sp.velocity_mps[f]),
                         rcs_dbsm=rcs, angle_rad=float(sp.azimuth_rad[f]),
                         elevation_rad=float(sp.elevation_rad[f]))
            for sp, rcs in moving) + tuple(objects[f]))
    return times, frames


def frame_target_names(scene: Scene, f: int, static: int | None = None, targets=None,
                       budget=None):
    """Frame ``f``'s target ``k`` as the scene file names it (``frame_targets`` puts the
    ``[[targets]]`` first): ``frame f: targets[k]`` or ``frame f: scenario.targets[i]``, an
    object's scatterer ``frame f: scenario.targets[0].scatterers[3]`` (``static``: S, default
    the scene's own count; ``targets``: the frame's, for the objects' scatterers;
    ``budget``: ``k`` a synthesized target, named by its strongest member,
    :func:`rtsgeom.pipeline.plan.target_namer`)."""
    s = len(scene.targets) if static is None else static
    if targets is None and budget is None:
        return lambda k: (f"frame {f}: targets[{k}]" if k < s
                          else f"frame {f}: scenario.targets[{k - s}]")
    name = target_namer(scene, targets, budget, moving_from=s)
    return lambda k: f"frame {f}: {name(k)}"


class FramePlanner:
    """The RTS programme per frame with the setup calibrated once.

    ``mode`` ``nearest``: each target on its nearest front end (no calibration); a synthesis
    mode: the probe of every front end and the calibration of every pair any frame visits,
    once; then :meth:`program` per frame."""

    def __init__(self, setup: Setup, paths: Paths, mode: str, frames, progress=None):
        self.setup, self.paths, self.mode = setup, paths, mode
        scene = setup.scene
        self.record: dict = {"mode": mode}
        self.warnings: list[str] = []
        self.budgets: list = []  # per frame the Budgeted targets (pipeline.merge), if any
        self.frames = frames
        self._block: tuple = (None, None)  # the block of frames planned last, its programmes
        if mode == "nearest":
            return
        if uses_cells(scene) or any(t.elevation_rad for tg in frames for t in tg):
            raise ParameterError(
                "play: targets in elevation or front ends off the arc need cells of front ends "
                "calibrated per channel; playing a drive on cells is not implemented (use "
                "--amplitudes nearest, or targets at elevation 0 on an arc)")
        self.probe = probe_front_ends(setup, paths, scene.seed)
        if scene.rts.max_targets_per_channel is not None:  # each frame's merged targets
            self.budgets = [budget_targets(setup, tg, self.probe, probe_pair(self.probe))
                            for tg in frames]
        self.pairs, seen = [], set()
        for f, scatterers in enumerate(frames):
            budget = self.budgets[f] if self.budgets else None
            targets = budget.targets if budget else scatterers
            pairs, notes = target_pairs(setup, self.probe, targets, where=frame_target_names(
                scene, f, targets=scatterers, budget=budget))
            self.pairs.append(pairs)
            for n in notes:  # a pair too wide: once, at the first frame it is used
                key = n[n.find(": front ends"):]
                if key not in seen:
                    seen.add(key)
                    self.warnings.append(n)
        used = sorted({p for pairs in self.pairs for p in pairs})
        self.cals = calibrate_pairs(setup, paths, used, self.probe, progress=progress)
        self.offsets = channel_offsets(setup.fe.count, self.cals)
        self.record.update({
            "source": "measured",
            "front_end_angles_deg": [float(x) for x in np.degrees(self.probe.angle_rad)],
            "gain_correction": [float(x) for x in self.probe.gain_correction],
            "channel_delay_offsets_s": [float(x) for x in self.offsets],
            "pairs": [cal.to_dict() for cal in self.cals.values()]})

    def program(self, f: int, scene_f: Scene) -> tuple[RtsProgram, list[str]]:
        """Frame ``f``'s programme for ``scene_f`` (the scene with the frame's targets) and
        the planner's warnings about it. Planned with the frames of its block of
        :data:`PLAN_BLOCK` (aligned: the same blocks in any worker) in one batch
        (:func:`~rtsgeom.pipeline.plan.program_frames`)."""
        if self.mode == "nearest":
            return program_nearest(scene_f, self.setup), []
        b = f // PLAN_BLOCK
        if self._block[0] != b:
            self._block = (b, self._plan_block(b))
        program, _, notes = self._block[1][f - b * PLAN_BLOCK]
        budget = self.budgets[f] if self.budgets else None
        return (lead_program(program, budget) if budget else program), notes

    def _plan_block(self, b: int) -> list:
        fs = range(b * PLAN_BLOCK, min((b + 1) * PLAN_BLOCK, len(self.frames)))
        scene, static = self.setup.scene, len(self.setup.scene.targets)
        return program_frames(
            self.setup, self.paths, self.mode,
            [self.budgets[f].targets if self.budgets else self.frames[f] for f in fs],
            [self.pairs[f] for f in fs],
            FixedCalibration(self.probe, self.cals, self.offsets),
            [frame_target_names(scene, f, static, self.frames[f],
                                self.budgets[f] if self.budgets else None) for f in fs])


@dataclass(frozen=True)
class FrameOptions:
    """How :func:`detect_frame` looks at a frame: the association's gate ``bins`` (range and
    Doppler bins), whether the truth twin looks too, and the ``chain`` (``fast``, ``full``:
    :data:`rtsgeom.radar.frame.CHAINS`)."""

    bins: int = 2
    truth: bool = True
    chain: str = "full"


def detect_frame(setup: Setup, paths: Paths, program: RtsProgram, scene_f: Scene, seed: int,
                 options: FrameOptions = FrameOptions(), synthesized=None) -> tuple:
    """One frame through the chain: the matches of ``match_targets`` (with the truth
    twin's detections where ``truth``: :func:`rtsgeom.pipeline.matching.truth_twin`, same seed)
    and, per target, the number of other detections within ``bins`` range and Doppler bins of
    its set-point where the radar sees it (:func:`~rtsgeom.rts.channels.apparent_range`, as
    the association) that no target claimed (a split: the RuT sees the target twice),
    ``(detections, truth twin's detections or None, map or its axes, steering)`` (the frame's
    clouds, :mod:`rtsgeom.analysis.objects`) and why the full chain ran where ``chain`` asked
    for the fast path (:mod:`rtsgeom.radar.windowed`; one reason per look: the RTS's, the truth
    twin's; empty where none did).

    ``synthesized``: the targets the RTS synthesizes where they are not ``scene_f``'s (a
    budget's, :mod:`rtsgeom.pipeline.merge`): the matches are theirs, each against the truth
    twin's detection of its cell (the truth twin still looks at ``scene_f``'s real targets)."""
    bins, truth, chain = options.bins, options.truth, options.chain
    compare = tuple(scene_f.targets if synthesized is None else synthesized)
    look = tuple(scene_f.targets) + (() if synthesized is None else compare)
    centres = cell_centres(scene_f.radar, apparent_range(scene_f, [t.range_m for t in look]),
                           [t.velocity_mps for t in look])
    view = observe(setup, paths, program, seed, scene_f.radar.snr_db, centres, bins, chain)
    det, rd = view.detections, view.rd
    fallbacks = [] if view.fallback is None else [view.fallback]
    matches = match_targets(scene_f, det, rd, bins=bins, steering=view.steering,
                            targets=compare)
    t_det = None
    if truth and scene_f.targets:
        t_det, matches, why = truth_twin(
            setup, scene_f.targets, view.echoes, matches, bins, seed,
            compare=None if synthesized is None else compare, look=view)
        fallbacks += [] if why is None else [why]
    claimed = {m.get("detection_index") for m in matches}
    seen_at = apparent_range(scene_f, [t.range_m for t in compare])  # as the association
    extra = np.zeros(len(matches), int)
    for k, t in enumerate(compare):
        near = np.flatnonzero(in_gate(det, rd, seen_at[k], t.velocity_mps, bins))
        extra[k] = sum(1 for j in near if j not in claimed)
    return matches, extra, (det, t_det, rd, view.steering), tuple(fallbacks)
