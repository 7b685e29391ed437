"""``rtsgeom play``: a scene's ``[scenario]`` played frame by frame. Writes the output folder
(one whole run or nothing): programme.csv (what the RTS is told per frame, target and
channel), tracks.csv (set-points and what the RuT detected), summary.json and playback.png
(docs/scenario.md)."""

from __future__ import annotations

import json

from ..analysis.tolerance.draws import MAX_SIGMA_MM
from ..errors import ParameterError, UsageError
from ..radar.frame import CHAINS
from ..scene.registry import AOA_MODES, PATH_METHODS
from ._common import (load_scene_checked, number, output_folder, output_path, scene_arg,
                      steps)


def cmd_play(args) -> int:
    from ..analysis.playback import Playback
    from ..viz.figures import save_figure
    if not args.tolerance_draws:
        for flag, value in (("--sigma-mm", args.sigma_mm), ("--spec-deg", args.spec_deg)):
            if value is not None:
                raise UsageError(f"{flag}: only with --tolerance-draws N (it sets the "
                                 "mounting-tolerance study over the drive, which runs only "
                                 "then)")
    args.sigma_mm = (0.1, 0.1, 0.1) if args.sigma_mm is None else tuple(args.sigma_mm)
    args.spec_deg = 0.1 if args.spec_deg is None else args.spec_deg
    scene = load_scene_checked(args.scene)
    if scene.scenario is None:
        raise UsageError(f"{args.scene}: has no [scenario] to play (add [scenario] with "
                         "[[scenario.targets]], docs/scenario.md)")
    study = Playback(args.amplitudes, args.paths, baseline=not args.no_baseline,
                     workers=args.workers, chain=args.chain)
    with output_folder(args.out, [args.scene]) as stage, steps(args.quiet) as step:
        if not args.quiet:
            step(_estimate(scene, study))
        step(f"playing {scene.name} (calibration once, then every frame through the chain)")
        try:
            result = study(scene, progress=step)
        except ParameterError as exc:
            raise UsageError(str(exc)) from None
        summary = result.summary_json()
        if args.tolerance_draws:
            step(f"mounting tolerance over the drive ({args.tolerance_draws} setups)")
            summary["tolerance"] = _tolerance(scene, args)
        step("writing programme.csv, tracks.csv, summary.json, playback.png")
        (stage / "programme.csv").write_text(result.programme_csv(), encoding="utf-8")
        (stage / "tracks.csv").write_text(result.tracks_csv(), encoding="utf-8")
        (stage / "summary.json").write_text(
            json.dumps(summary, indent=2, allow_nan=False) + "\n", encoding="utf-8")
        save_figure(result.plot(), stage / "playback.png")
        objects_lines = []
        if result.clouds is not None:  # extended objects: clouds.csv, objects.json/png
            from ..analysis.objects import objects_lines as lines_of, play_objects
            from .run import write_objects
            rows, section = play_objects(result)
            write_objects(stage, scene, rows, section)
            objects_lines = [f"{result.mode}: {x}" for x in lines_of(section)]
            if result.baseline is not None and result.baseline.clouds is not None:
                objects_lines += [f"baseline {result.baseline.mode}: {x}" for x in
                                  lines_of(play_objects(result.baseline)[1])]
        if args.gif:
            step("writing playback.gif")
            result.animate(stage / "playback.gif")
    if not args.quiet:
        _print_result(result, summary, objects_lines, args)
    return 0


def _print_result(result, summary: dict, objects_lines, args) -> None:
    """The drive's lines on stdout: per mode the errors, losses, splits and hand-overs, the
    budget, the frames left to the full chain, the objects, the tolerance and warnings."""
    from ..analysis.playback.result import budget_line
    s = summary  # summary.json's content: the result's summary() and its context
    for r, v in (("", s), ("baseline ", s.get("baseline"))):
        if v is None:
            continue
        e = v["angle_error_deg"]
        worst = "n/a" if e["max"] is None else f"{e['max']:.4f} deg (p95 {e['p95']:.4f})"
        jump = ("n/a" if v["handover_jump_deg"] is None
                else f"{v['handover_jump_deg']:.4f} deg")
        if v["point_targets"]:
            print(f"{r}{v['mode']}: {v['frames']} frames, {v['point_targets']} point "
                  f"target(s): max |angle error| {worst}, {v['lost_frames']} lost, "
                  f"{v['split_frames']} split, {v['handovers']} hand-overs (largest jump "
                  f"{jump})")
        if "budget" in v:
            print(f"{r}{v['mode']}: budget {budget_line(v['budget'])}")
        ch = v["chain"]
        if ch["full_chain_frames"]:
            why = "; ".join(f"{k}: {n}" for k, n in ch["reasons"].items())
            print(f"{r}{v['mode']}: {ch['full_chain_frames']} of {v['frames']} frames on "
                  f"the full chain ({why})")
    for line in objects_lines:
        print(line)
    if "tolerance" in summary:
        t = summary["tolerance"]
        print(f"tolerance over the drive ({t['draws']} setups, sigma {t['sigma_mm']} mm, "
              f"spec {t['spec_deg']:g} deg): yield calibrated "
              f"{t['yield']['calibrated']:.3f}, uncalibrated "
              f"{t['yield']['uncalibrated']:.3f}")
    for w in result.warnings:
        print(f"warning: {w}")
    print(f"wrote {args.out}/programme.csv, tracks.csv, summary.json, playback.png"
          + (", playback.gif" if args.gif else ""))


def _estimate(scene, study) -> str:
    """What the drive will play, before it starts, without running any of it: the frames,
    modes and targets (``frame_targets``: the set-points alone). The time left shows in the
    per-frame count as the frames play (the first frames' rate: a frame measured alone before
    the drive carried the process's one-time costs, and cost as much as the first frames)."""
    from ..analysis.playback.frames import frame_targets
    _, frames = frame_targets(scene)
    modes = 1 if (not study.baseline or (study.amplitudes or scene.rts.aoa_mode) == "nearest") \
        else 2
    return (f"{len(frames)} frames x {modes} mode(s) of {len(frames[0])} targets, "
            f"{study.workers} worker(s): the calibration first, then the time left per frame")


def _tolerance(scene, args) -> dict:
    """summary.json's ``tolerance``: the drive's yield and worst errors over the setups."""
    import numpy as np
    from ..analysis.playback import drive_tolerance
    try:
        res = drive_tolerance(scene, args.sigma_mm, args.tolerance_draws,
                              spec_deg=args.spec_deg)
    except ParameterError as exc:
        raise UsageError(f"--tolerance-draws: {exc}") from None
    worst = {case: np.abs(res.arc_worst(case)) for case in ("uncalibrated", "calibrated")}
    return {"draws": args.tolerance_draws, "sigma_mm": list(args.sigma_mm),
            "spec_deg": args.spec_deg, "distribution": "normal",
            "pairs": [list(m.front_ends) for m in res.model.sets],
            "yield": {k: res.yield_(k) for k in worst},
            "worst_error_deg": {k: {"p50": float(np.percentile(w, 50)),
                                    "p95": float(np.percentile(w, 95)),
                                    "max": float(w.max())} for k, w in worst.items()}}


def register(sub) -> None:
    p = sub.add_parser("play", help="play the scene's [scenario]: programme, tracks per frame")
    scene_arg(p)
    p.add_argument("--out", type=output_path, required=True, help="output folder")
    p.add_argument("--amplitudes", choices=tuple(AOA_MODES), default=None,
                   help="AoA amplitude mode (default: the scene's rts.aoa_mode); nearest: the "
                        "switched baseline, each target on its nearest front end")
    p.add_argument("--paths", choices=tuple(PATH_METHODS), default="exact",
                   help="exact line-of-sight paths (default) or Sionna RT ray tracing")
    p.add_argument("--no-baseline", action="store_true",
                   help="do not also play the switched baseline for the figure")
    p.add_argument("--gif", action="store_true",
                   help="also write playback.gif: the arc from above, frame by frame")
    p.add_argument("--tolerance-draws", type=number(0, 10_000_000, integer=True), default=0,
                   metavar="N", help="also the mounting-tolerance yield over the drive: N "
                   "drawn setups (summary.json's tolerance)")
    p.add_argument("--sigma-mm", type=number(0, MAX_SIGMA_MM), nargs=3, default=None,
                   metavar=("RADIAL", "TANGENTIAL", "HEIGHT"),
                   help="with --tolerance-draws: mounting error per front end, standard "
                        f"deviation in [0, {MAX_SIGMA_MM:g}] mm (default 0.1 each)")
    p.add_argument("--spec-deg", type=number(1e-6, 90), default=None,
                   help="with --tolerance-draws: angle-error spec of the tolerance yield "
                        "(default 0.1 deg)")
    p.add_argument("--workers", type=number(1, 256, integer=True), default=1, metavar="N",
                   help="play the frames in N forked processes (the same result)")
    p.add_argument("--chain", choices=CHAINS, default="fast",
                   help="fast (default): each frame's detections near its targets from the "
                        "echoes' closed-form spectrum, the full chain for frames outside it "
                        "(counted in summary.json's chain); full: every frame through the ADC "
                        "cube, FFTs and CFAR over the whole map")
    p.add_argument("--quiet", action="store_true", help="print nothing but errors")
    p.set_defaults(func=cmd_play)
