"""``rtsgeom run``: the main job. Simulate the scene (paths, calibration, ADC cube, detection),
compare the detections with the set-points and write the output folder: detections.csv,
summary.json, the maps (PNG and arrays) and report.html."""

from __future__ import annotations

import argparse
import json

from ..geometry.warnings import scene_warnings
from ..pipeline.view import start_setup_view
from ..scene.objects import target_labels
from ..scene.registry import ANGLE_ESTIMATORS, AOA_MODES, MAP_FORMATS, PATH_METHODS
from ._common import (calibration_kw, load_scene_checked, number, output_folder, output_path,
                      scene_arg, steps)


def _with_estimator(scene, args):
    """The scene with ``--estimator``/``--subarray`` applied (validated again, like the file:
    e.g. smoothing needs capon or music)."""
    est, sub = getattr(args, "estimator", None), getattr(args, "subarray", None)
    if est is None and sub is None:
        return scene
    radar = scene.radar.evolve(**{k: v for k, v in (("angle_estimator", est),
                                                     ("angle_subarray", sub)) if v is not None})
    return scene.evolve(radar=radar)


def run_scene(*args, **kwargs):
    """:func:`rtsgeom.pipeline.run.run_scene`, its module imported on the first call: ``run``
    forks the report's 3D view before it imports the simulation's modules, which the view's
    process does not need (0.3 s of imports beside the view instead of before it)."""
    from ..pipeline.run import run_scene as run
    return run(*args, **kwargs)


def cmd_run(args) -> int:
    scene = _with_estimator(load_scene_checked(args.scene), args)
    out = args.out
    with output_folder(out, [args.scene]) as stage, steps(args.quiet) as step:
        # the report's 3D view depends on the geometry alone: rendered beside the run
        view = (start_setup_view(scene) if not args.no_report and args.paths == "exact"
                else None)
        from ..pipeline.output import write_run  # after the fork (see run_scene)
        step(f"simulating {scene.name} ({args.paths} paths, calibration, ADC cube, detection)")
        result = run_scene(scene, args.paths, args.amplitudes, progress=step,
                           **calibration_kw(args))
        step("writing detections, summary, maps" + ("" if args.no_report else
                                                      " and report.html (3D view, figures)"))
        write_run(result, stage, args.paths, args.maps, not args.no_report,
                  scene_warnings(scene), view)
        objects_lines = []
        if scene.objects:  # extended objects: what the radar sees of them, truth and RTS
            from ..analysis.objects import objects_lines as lines_of, run_objects
            rows, section = run_objects(result)
            write_objects(stage, scene, rows, section)
            objects_lines = lines_of(section)
    if not args.quiet:
        names = target_labels(scene) if scene.objects else None
        roles = budget_roles(result.calibration.get("budget"), names)
        for m in result.matches:
            k = m["index"]
            print(roles[k] if k in roles else
                  target_line(m, None if names is None else names[k]))
        for line in objects_lines:
            print(line)
        for w in result.warnings:
            print(f"warning: {w}")
        print(f"{len(result.detections)} detections; wrote {out}/detections.csv, summary.json, "
              "range_doppler.png, range_angle.png, "
              + ", ".join(f"maps.{f}" for f in args.maps) + ("" if args.no_report else ", report.html"))
    return 0


def write_objects(stage, scene, rows, section: dict) -> None:
    """clouds.csv, objects.json and objects.png of a scene with extended objects."""
    from ..analysis.objects import clouds_csv, objects_figure
    from ..viz.figures import save_figure
    (stage / "clouds.csv").write_text(clouds_csv(rows), encoding="utf-8")
    (stage / "objects.json").write_text(json.dumps(section, indent=2, allow_nan=False) + "\n",
                                        encoding="utf-8")
    save_figure(objects_figure(scene, rows, section), stage / "objects.png")


def budget_roles(budget: dict | None, names) -> dict:
    """Under ``[rts] max_targets_per_channel``: the printed line of each scatterer the RTS
    does not synthesize as itself (merged into another's target, carrying a merged target,
    dropped), by its index; the others print :func:`target_line`. Their comparison with the
    truth is the object's (``objects.json``: each RTS detection against the truth twin's
    detection of its cell)."""
    if budget is None:
        return {}
    name = (lambda k: f"target {k}") if names is None else names.__getitem__
    out = {}
    for t in budget["targets"]:
        m = t["members"]
        if len(m) > 1:
            out[m[0]] = (f"{name(m[0])}: carries the RTS's merged target of "
                         f"{', '.join(name(j) for j in m)} at {t['range_m']:.3f} m "
                         f"{t['azimuth_deg']:.3f} deg (the truth twin's detection of their cell"
                         + (")" if t["from_truth_twin"] else ": none, its strongest member)"))
            out.update({j: f"{name(j)}: merged into {name(m[0])}'s target (budget)"
                        for j in m[1:]})
    out.update({j: f"{name(j)}: dropped (budget)" for j in budget["dropped_targets"]})
    return out


def target_line(m: dict, name: str | None = None) -> str:
    """One printed line per target (``name``: as the file names it, default ``target k``):
    the RTS's detection and its errors against the set-point, then the truth twin's
    detection and the RTS's difference from it."""
    d, e = m["detection"], m["error"]
    name = name or f"target {m['index']}"
    if d is None:
        line = f"{name}: NOT DETECTED: {m['undetected']['reason']}"
    else:
        el = (f" el {d['elevation_deg']:7.3f} deg" if "elevation_deg" in d else "")
        el_e = (f", el {e['elevation_deg']:+.3f} deg" if "elevation_deg" in e else "")
        merged = (f" MERGED with target {', '.join(map(str, m['merged_with']))}:"
                  if m.get("status") == "merged" else "")
        line = (f"{name}:{merged} {d['range_m']:7.3f} m {d['velocity_mps']:+7.3f} "
                f"m/s {d['angle_deg']:8.3f} deg{el}  (errors {e['range_m']:+.3f} m, "
                f"{e['velocity_mps']:+.3f} m/s, {e['angle_deg']:+.3f} deg{el_e})")
    if "truth_status" not in m:
        return line
    t, vs = m["truth"], m["vs_truth"]
    if t is None:
        return line + f"; truth twin: {m['truth_status'].replace('_', ' ')}"
    line += f"; truth {t['angle_deg']:8.3f} deg"
    if vs is not None:
        line += (f" (RTS - truth {vs['range_m']:+.3f} m, {vs['velocity_mps']:+.3f} m/s, "
                 f"{vs['angle_deg']:+.3f} deg)")
    return line


def _map_formats(text: str) -> tuple[str, ...]:
    """``--maps``: a comma-separated subset of :data:`MAP_FORMATS`."""
    got = tuple(dict.fromkeys(x.strip().lower() for x in text.split(",") if x.strip()))
    bad = [x for x in got if x not in MAP_FORMATS]
    if not got or bad:
        raise argparse.ArgumentTypeError(f"{text!r}: must be one or more of "
                                         f"{', '.join(MAP_FORMATS)}, comma-separated")
    return got


def register(sub) -> None:
    p = sub.add_parser("run", help="the main job: simulate the scene, detect, compare with set-points")
    scene_arg(p)
    p.add_argument("--out", type=output_path, required=True, help="output folder")
    p.add_argument("--paths", choices=tuple(PATH_METHODS), default="exact",
                   help="exact line-of-sight paths (default) or Sionna RT ray tracing")
    p.add_argument("--amplitudes", choices=tuple(AOA_MODES), default=None,
                   help="AoA amplitude mode (default: the scene's rts.aoa_mode)")
    p.add_argument("--estimator", choices=tuple(ANGLE_ESTIMATORS), default=None,
                   help="the RuT's direction estimator (default: the scene's "
                        "radar.angle_estimator); `exact` designs against it")
    p.add_argument("--subarray", type=number(0, 4096, integer=True), default=None,
                   metavar="L", help="spatial smoothing subarray length for capon/music "
                                     "(default: the scene's radar.angle_subarray; 0 = none)")
    p.add_argument("--maps", type=_map_formats, default=("npz",), metavar="npz,mat,nc",
                   help="the maps' array formats, comma-separated: npz (numpy), mat (MATLAB), "
                        "nc (NetCDF); default npz")
    p.add_argument("--no-report", action="store_true", help="skip report.html")
    p.add_argument("--quiet", action="store_true", help="print nothing but errors")
    p.add_argument("--calibration", default=None, metavar="FILE",
                   help="use this calibration (DIR/calibration.json from `rtsgeom calibrate "
                        "--out DIR`) instead of calibrating again")
    p.set_defaults(func=cmd_run)
