"""``python -m benchmarks.scenario_speed [--frames N]``: how long a drive takes to play.

Four targets moving across the default scene's pair (``scenes/diewald2022.toml``: the default
radar, 512 samples x 120 chirp loops x 8 virtual elements, noise at 10 dB, cable ghosts), for
1000 frames of 50 ms (``--frames`` fewer over the same 50 s for a quick look), played with the exact synthesis and
no baseline: the calibration once, then per frame the programme (the run's planner, every
target) and the full chain (ADC cube, range-Doppler, CFAR, angles, matching). Prints the time
of each phase and per frame, and writes ``benchmarks/scenario_speed.json``. Not part of the
test suite.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import time
import tomllib
from pathlib import Path

from benchmarks._io import write_json

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_SCENE = ROOT / "scenes" / "diewald2022.toml"
# [t_s, range_m, azimuth_deg] at the start and the end: crossing, cut-in, overtaking, receding
PATHS = (((12.0, 4.2), (14.0, 11.5)), ((30.0, 11.4), (24.0, 5.0)),
         ((40.0, 6.0), (46.0, 9.0)), ((55.0, 10.5), (50.0, 4.5)))


def drive(frames: int, duration: float = 49.95):
    """The drive of 49.95 s in ``frames`` frames (1000: 50 ms apart)."""
    from rtsgeom.scene import parse_scene
    doc = tomllib.loads(DEFAULT_SCENE.read_text())
    doc.pop("targets", None)
    period_s = duration / (frames - 1)
    doc["scenario"] = {"frame_period_s": period_s, "duration_s": duration, "targets": [
        {"rcs_dbsm": 10.0, "waypoints": [[0.0, r0, a0], [duration, r1, a1]]}
        for (r0, a0), (r1, a1) in PATHS]}
    return parse_scene(doc, str(DEFAULT_SCENE))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--frames", type=int, default=1000)
    ap.add_argument("--workers", type=int, default=1,
                    help="play the frames in this many forked processes (the whole call timed)")
    args = ap.parse_args(argv)
    if args.workers > 1:
        return _pooled(args)
    from rtsgeom.analysis.playback.frames import FramePlanner, detect_frame, frame_targets
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import compute_paths

    t0 = time.perf_counter()
    scene = drive(args.frames)
    setup = build_setup(dataclasses.replace(scene, scenario=None))  # as Playback does
    paths = compute_paths(setup, "exact")
    times, frames = frame_targets(scene)
    t_set = time.perf_counter()
    planner = FramePlanner(setup, paths, "exact", frames)
    t_cal = time.perf_counter()
    plan_s = chain_s = 0.0
    worst = 0.0
    for f, targets in enumerate(frames):
        a = time.perf_counter()
        scene_f = dataclasses.replace(setup.scene, targets=targets)
        program, _ = planner.program(f, scene_f)
        b = time.perf_counter()
        matches, _, _, _ = detect_frame(setup, paths, program, scene_f, scene.seed + f)
        chain_s += time.perf_counter() - b
        plan_s += b - a
        for m in matches:
            if m["error"] is not None:
                worst = max(worst, abs(m["error"]["angle_deg"]))
    total = time.perf_counter() - t0
    out = {"frames": len(frames), "targets": len(frames[0]), "cpus": os.cpu_count(),
           "setup_and_set_points_s": t_set - t0, "calibration_s": t_cal - t_set,
           "planning_s": plan_s, "chain_s": chain_s, "total_s": total,
           "per_frame_planning_ms": 1e3 * plan_s / len(frames),
           "per_frame_chain_ms": 1e3 * chain_s / len(frames),
           "max_abs_angle_error_deg": worst}
    for k, v in out.items():
        print(f"{k:>26}: {v:.4g}" if isinstance(v, float) else f"{k:>26}: {v}")
    if args.frames == 1000:
        write_json(Path(__file__).with_name("scenario_speed.json"), out, newline=True)
    return 0


def _pooled(args) -> int:
    from rtsgeom.analysis.playback import Playback
    t0 = time.perf_counter()
    scene = drive(args.frames)
    res = Playback(baseline=False, workers=args.workers)(scene)
    total = time.perf_counter() - t0
    out = {"frames": len(res.time_s), "targets": res.num_targets, "workers": args.workers,
           "cpus": os.cpu_count(), "total_s": total,
           "max_abs_angle_error_deg": res.summary()["angle_error_deg"]["max"]}
    for k, v in out.items():
        print(f"{k:>26}: {v:.4g}" if isinstance(v, float) else f"{k:>26}: {v}")
    if args.frames == 1000:
        write_json(Path(__file__).with_name(f"scenario_speed_workers{args.workers}.json"), out,
                   newline=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
