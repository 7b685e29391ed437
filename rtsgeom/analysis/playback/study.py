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
from ...scene import Scene, check_scene_arg
from ...scene.schema import check_arg
from ...scene.registry import AOA_MODES, PATH_METHODS
from ...pipeline.cells import shared_cell_warnings
from ...radar.frame import CHAINS
from ...pipeline.matching import association_scale
from ..objects import cloud_rows
from .frames import FrameOptions, FramePlanner, detect_frame, frame_targets
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
    chain : {'fast', 'full'}
        ``fast``: each frame's detections near its targets from the echoes' closed-form
        spectrum (:mod:`rtsgeom.radar.windowed`; the same detections as the full chain to
        rounding, tested), the full chain for the frames outside it (counted in the summary);
        ``full``: every frame through the ADC cube, FFTs and CFAR over the whole map.
    """

    amplitudes: str | None = None
    paths: str = "exact"
    baseline: bool = True
    bins: int = 2
    workers: int = 1
    chain: str = "fast"

    def __post_init__(self):
        if self.amplitudes is not None:
            check_arg(self.amplitudes, "amplitudes", "str", "Playback", ParameterError,
                      choices=AOA_MODES)
        check_arg(self.paths, "paths", "str", "Playback", ParameterError, choices=PATH_METHODS)
        check_arg(self.baseline, "baseline", "bool", "Playback", ParameterError)
        check_arg(self.bins, "bins", "int", "Playback", ParameterError, lo=0, hi=64)
        check_arg(self.workers, "workers", "int", "Playback", ParameterError, lo=1, hi=256)
        check_arg(self.chain, "chain", "str", "Playback", ParameterError, choices=CHAINS)

    def __call__(self, scene: Scene, progress=None) -> PlaybackResult:
        check_scene_arg(scene, "Playback")
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
                       self.workers, chain=self.chain)
        if self.baseline and mode != "nearest":  # the same drive: the same truth twin
            base = _play(scene, setup, paths, "nearest", times, frames, self.bins, progress,
                         self.workers, truth=False, chain=self.chain)
            base = dataclasses.replace(base, truth=result.truth, clouds=None if base.clouds
                                       is None else (tuple(r for r in result.clouds[0] if
                                                           r[1] == "truth") + base.clouds[0],
                                                     base.clouds[1]))
            result = dataclasses.replace(result, baseline=base)
        return result


@one_blas_thread  # a frame's products are small: threads cost more than they give (play of
# 200 frames x 8 targets: 18.2 -> 9.0 s of CPU on a loaded machine)
def _play(scene, setup, paths, mode, times, frames, bins, progress, workers=1, truth=True,
          chain="full") -> PlaybackResult:
    if progress:
        progress(f"{mode}: calibrating and planning {len(frames)} frames")
    planner = FramePlanner(setup, paths, mode, frames, progress)
    shared = _shared_cells(setup, frames)
    n_f, n_t = len(frames), len(frames[0])
    shape = (n_f, n_t)
    det = {k: np.full(shape, np.nan) for k in ("range_m", "azimuth_deg", "velocity_mps")}
    tru = {k: np.full(shape, np.nan) for k in det}
    status = np.full(shape, "not_detected", dtype=object)
    split = np.zeros(shape, int)
    channels = np.empty(shape, object)
    programme, warnings = [], list(planner.warnings) + shared
    scale = association_scale(setup.scene, None)  # the clouds' cells (the association's)
    work = functools.partial(_frames, (scene, setup, paths, planner, frames, bins, truth,
                                       chain))
    chunks = np.array_split(np.arange(n_f), max(1, min(n_f, 4 * int(workers))))
    tell(progress, f"{mode}: playing {n_f} frames")
    if workers > 1 and n_f > 1:
        outs = fork_map(work, chunks, int(workers))
    else:  # frame by frame, counted (the same frames: each a pure function of its index)
        outs = []
        for f in range(n_f):
            outs.append(work(np.array([f])))
            tell(progress, None, f"{mode}: frame", f + 1, n_f)
    clouds = []
    role = np.full(shape, "", dtype=object)
    fallbacks = []
    for f, (rows, found, extra, notes, seen, stat, cloud, rl, why) in enumerate(
            o for out in outs for o in out):
        clouds += cloud
        fallbacks.append(why)
        split[f] = extra
        status[f] = stat
        role[f] = rl
        for into, got in ((det, found), (tru, seen)):
            for k, d in enumerate(got):
                if d is not None:
                    into["range_m"][f, k], into["azimuth_deg"][f, k], into["velocity_mps"][
                        f, k] = d
        for k in range(n_t):
            channels[f, k] = tuple(sorted(int(q) for q in rows[rows[:, 1] == k, 2]))
        programme.append(rows)
        warnings += [n for n in notes if n not in warnings]
    set_ = {"range_m": np.array([[t.range_m for t in tg] for tg in frames]),
            "azimuth_deg": np.degrees([[t.angle_rad for t in tg] for tg in frames]),
            "velocity_mps": np.array([[t.velocity_mps for t in tg] for tg in frames])}
    return PlaybackResult(scene=scene, mode=mode, time_s=times, set=set_, detected=det,
                          split=split, channels=channels, programme=np.concatenate(programme),
                          calibration=planner.record, warnings=tuple(warnings),
                          truth=tru if truth else None, status=status,
                          clouds=(tuple(clouds), scale) if scene.objects else None,
                          budget=tuple(b.counts for b in planner.budgets) or None,
                          role=role if planner.budgets else None,
                          object_of=np.array([t.object_index for t in frames[0]], int),
                          chain=chain, fallbacks=tuple(fallbacks))


def _shared_cells(setup, frames) -> list[str]:
    """The drive's targets that share a range-Doppler cell (:func:`shared_cell_warnings`), one
    line per situation with the frames it holds in."""
    seen: dict[str, list[int]] = {}
    for f, targets in enumerate(frames):
        for w in shared_cell_warnings(setup, targets):
            seen.setdefault(w, []).append(f)
    return [f"frames {fs[0]}..{fs[-1]} ({len(fs)} frames): {w}" if len(fs) > 1 else
            f"frame {fs[0]}: {w}" for w, fs in seen.items()]


def _frames(ctx, chunk) -> list:
    """Frames ``chunk`` (indices) played: per frame the programme rows (frame, target,
    channel, delay_s, doppler_hz, |amplitude|, phase_rad), each target's detection (range,
    azimuth, velocity) or None, its unclaimed detections nearby, the planner's notes, the
    truth twin's detection of each target (or None), each target's status, the frame's
    clouds, each target's role under the budget (:func:`_per_scatterer`) and why the full
    chain ran where the fast path was asked for.
    A pure function of the frame (its noise seeded by it): the same in a forked worker."""
    scene, setup, paths, planner, frames, bins, truth, chain = ctx
    out = []
    for f in chunk:
        scene_f = dataclasses.replace(setup.scene, targets=frames[f])  # checked on load
        program, notes = planner.program(int(f), scene_f)
        seed = (scene.seed + int(f)) % (2 ** 63)  # frame 0: the scene's own noise, as `run`
        budget = planner.budgets[f] if planner.budgets else None
        matches, extra, (det, t_det, rd, st), why = detect_frame(
            setup, paths, program, scene_f, seed, FrameOptions(bins, truth, chain),
            synthesized=None if budget is None else budget.targets)
        cloud = [] if not scene.objects else (  # in the association's gate, as the matches
            ([] if t_det is None else cloud_rows(f, "truth", scene_f, t_det, rd, frames[f], st,
                                                 bins))
            + cloud_rows(f, "rts", scene_f, det, rd, frames[f], st, bins))
        matches, extra, role = _per_scatterer(matches, extra, budget, len(frames[f]))
        found, seen = ([None if m is None or m.get(key) is None else
                        (m[key]["range_m"], m[key]["angle_deg"], m[key]["velocity_mps"])
                        for m in matches] for key in ("detection", "truth"))
        stat = [m["status"] if m is not None else f"{r}_by_rts"
                for m, r in zip(matches, role)]
        rows = np.column_stack([
            np.full(len(program), f), program.target, program.front_end, program.delay_s,
            program.doppler_hz, np.abs(program.amplitude), np.angle(program.amplitude)])
        out.append((rows, found, extra, notes, seen, stat, cloud, role, why))
    return out


def _per_scatterer(matches, extra, budget, n: int):
    """A budgeted frame's matches (one per synthesized target) per scene target: the
    synthesized target's match on its strongest member (role ``kept`` where it stands for
    itself alone, ``lead`` for a merged one: its detection against the truth twin's detection
    of the cell), None on the others (role ``merged``) and on the dropped ones (``dropped``).
    Without a budget: unchanged, every role empty."""
    if budget is None:
        return list(matches), extra, [""] * n
    per, ext, role = [None] * n, np.zeros(n, int), ["dropped"] * n
    for g, m, e in zip(budget.members, matches, extra):
        per[g[0]], ext[g[0]] = m, e
        role[g[0]] = "kept" if len(g) == 1 else "lead"
        for j in g[1:]:
            role[j] = "merged"
    return per, ext, role


def play(scene: Scene, amplitudes: str | None = None, paths: str = "exact",
         baseline: bool = True, workers: int = 1, progress=None, chain: str = "fast"
         ) -> PlaybackResult:
    """Play the scene's ``[scenario]``: :class:`Playback` configured and called once."""
    return Playback(amplitudes, paths, baseline, workers=workers, chain=chain)(scene, progress)

