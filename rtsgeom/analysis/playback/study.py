"""Scenario playback: a drive's set-points, RTS programme and the RuT's tracks, frame by frame.

``Playback(amplitudes=None)(scene)`` plays the scene's ``[scenario]`` (see
:mod:`.frames` for what one frame is) and returns a :class:`PlaybackResult`; with ``baseline``
(default) the switched baseline (each target on its nearest front end) is played on the same
drive beside it.
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass

import numpy as np

from ..._lib.util import one_blas_thread, tell
from ..._lib.parallel import fork_map
from ...errors import ParameterError
from ...geometry import build_setup
from ...paths import compute_paths
from ...scene import Scene
from ...scene.registry import AOA_MODES, PATH_METHODS
from .frames import FramePlanner, detect_frame, frame_targets
from .result import PlaybackResult

__all__ = ["Playback", "play"]


@dataclass(frozen=True)
class Playback:
    """A configured playback study.

    Parameters
    ----------
    amplitudes : str, optional
        The AoA mode (``rts.aoa_mode`` by default); ``nearest`` plays the switched baseline.
    paths : {'exact', 'raytrace'}
        Propagation paths (computed once: the setup does not move).
    baseline : bool
        Also play the switched baseline (``nearest``) on the same drive, for the comparison
        (ignored when ``amplitudes`` is ``nearest``).
    bins : int
        Range and Doppler bins around a set-point within which a detection is the target's.
    workers : int
        Forked processes that play the frames after the calibration (``_lib.parallel``;
        every frame is a pure function of its index: the same result for any number).
    """

    amplitudes: str | None = None
    paths: str = "exact"
    baseline: bool = True
    bins: int = 2
    workers: int = 1

    def __post_init__(self):
        if self.amplitudes is not None and self.amplitudes not in AOA_MODES:
            raise ParameterError(f"amplitudes = {self.amplitudes!r}: must be one of "
                                 f"{', '.join(AOA_MODES)}")
        if self.paths not in PATH_METHODS:
            raise ParameterError(f"paths = {self.paths!r}: must be one of "
                                 f"{', '.join(PATH_METHODS)}")
        if not (isinstance(self.bins, (int, np.integer)) and 0 <= self.bins <= 64):
            raise ParameterError(f"bins = {self.bins!r}: must be an integer in [0, 64]")
        if not (isinstance(self.workers, (int, np.integer)) and 1 <= self.workers <= 256):
            raise ParameterError(f"workers = {self.workers!r}: must be an integer in [1, 256]")

    def __call__(self, scene: Scene, progress=None) -> PlaybackResult:
        if scene.scenario is None:
            raise ParameterError(f"{scene.source}: has no [scenario] to play (add "
                                 "[scenario] with [[scenario.targets]], docs/scenario.md)")
        mode = self.amplitudes or scene.rts.aoa_mode
        if mode != scene.rts.aoa_mode:  # validated like the file's own mode (Scene.evolve)
            scene = scene.evolve(rts=scene.rts.evolve(aoa_mode=mode))
        # the bench without the drive: the planner re-validates variants of it (Scene.evolve),
        # which would check every frame of the scenario again each time
        setup = build_setup(dataclasses.replace(scene, scenario=None))
        paths = compute_paths(setup, self.paths)
        times, frames = frame_targets(scene)
        result = _play(scene, setup, paths, mode, times, frames, self.bins, progress,
                       self.workers)
        if self.baseline and mode != "nearest":
            base = _play(scene, setup, paths, "nearest", times, frames, self.bins, progress,
                         self.workers)
            result = dataclasses.replace(result, baseline=base)
        return result


@one_blas_thread  # a frame's products are small: threads cost more than they give (play of
# 200 frames x 8 targets: 18.2 -> 9.0 s of CPU on a loaded machine)
def _play(scene, setup, paths, mode, times, frames, bins, progress, workers=1
          ) -> PlaybackResult:
    if progress:
        progress(f"{mode}: calibrating and planning {len(frames)} frames")
    planner = FramePlanner(setup, paths, mode, frames, progress)
    n_f, n_t = len(frames), len(frames[0])
    shape = (n_f, n_t)
    det = {k: np.full(shape, np.nan) for k in ("range_m", "azimuth_deg", "velocity_mps")}
    split = np.zeros(shape, int)
    channels = np.empty(shape, object)
    programme, warnings = [], list(planner.warnings)
    work = functools.partial(_frames, (scene, setup, paths, planner, frames, bins))
    chunks = np.array_split(np.arange(n_f), max(1, min(n_f, 4 * int(workers))))
    tell(progress, f"{mode}: playing {n_f} frames")
    if workers > 1 and n_f > 1:
        outs = fork_map(work, chunks, int(workers))
    else:  # frame by frame, counted (the same frames: each a pure function of its index)
        outs = []
        for f in range(n_f):
            outs.append(work(np.array([f])))
            tell(progress, None, f"{mode}: frame", f + 1, n_f)
    for f, (rows, found, extra, notes) in enumerate(o for out in outs for o in out):
        split[f] = extra
        for k, d in enumerate(found):
            if d is not None:
                det["range_m"][f, k], det["azimuth_deg"][f, k], det["velocity_mps"][f, k] = d
        for k in range(n_t):
            channels[f, k] = tuple(sorted(int(q) for q in rows[rows[:, 1] == k, 2]))
        programme.append(rows)
        warnings += [n for n in notes if n not in warnings]
    set_ = {"range_m": np.array([[t.range_m for t in tg] for tg in frames]),
            "azimuth_deg": np.degrees([[t.angle_rad for t in tg] for tg in frames]),
            "velocity_mps": np.array([[t.velocity_mps for t in tg] for tg in frames])}
    return PlaybackResult(scene=scene, mode=mode, time_s=times, set=set_, detected=det,
                          split=split, channels=channels, programme=np.concatenate(programme),
                          calibration=planner.record, warnings=tuple(warnings))


def _frames(ctx, chunk) -> list:
    """Frames ``chunk`` (indices) played: per frame the programme rows (frame, target,
    channel, delay_s, doppler_hz, |amplitude|, phase_rad), each target's detection (range,
    azimuth, velocity) or None, its unclaimed detections nearby and the planner's notes.
    A pure function of the frame (its noise seeded by it): the same in a forked worker."""
    scene, setup, paths, planner, frames, bins = ctx
    out = []
    for f in chunk:
        scene_f = dataclasses.replace(setup.scene, targets=frames[f])  # checked on load
        program, notes = planner.program(int(f), scene_f)
        seed = (scene.seed + int(f)) % (2 ** 63)  # frame 0: the scene's own noise, as `run`
        matches, extra = detect_frame(setup, paths, program, scene_f, seed, bins)
        found = [None if m["detection"] is None else
                 (m["detection"]["range_m"], m["detection"]["angle_deg"],
                  m["detection"]["velocity_mps"]) for m in matches]
        rows = np.column_stack([
            np.full(len(program), f), program.target, program.front_end, program.delay_s,
            program.doppler_hz, np.abs(program.amplitude), np.angle(program.amplitude)])
        out.append((rows, found, extra, notes))
    return out


def play(scene: Scene, amplitudes: str | None = None, paths: str = "exact",
         baseline: bool = True, workers: int = 1, progress=None) -> PlaybackResult:
    """Play the scene's ``[scenario]``: :class:`Playback` configured and called once."""
    return Playback(amplitudes, paths, baseline, workers=workers)(scene, progress)

