"""``rtsgeom run``: the main job. Simulate the scene (paths, calibration, ADC cube, detection),
compare the detections with the set-points and write the output folder: detections.csv,
summary.json, the maps (PNG and arrays) and report.html."""

from __future__ import annotations

import argparse
import json

from .._lib.io import write_bytes
from ..geometry.warnings import scene_warnings
from ..pipeline.run import run_scene, summary
from ..scene.registry import ANGLE_ESTIMATORS, AOA_MODES, PATH_METHODS
from ._common import (calibration_kw, load_scene_checked, number, output_folder, output_path,
                      scene_arg, steps)
from ._maps import (MAP_FORMATS, detections_csv, map_dataset, maps_arrays, render_maps,
                    run_report_html)


def _with_estimator(scene, args):
    """The scene with ``--estimator``/``--subarray`` applied (validated again, like the file:
    e.g. smoothing needs capon or music)."""
    est, sub = getattr(args, "estimator", None), getattr(args, "subarray", None)
    if est is None and sub is None:
        return scene
    radar = scene.radar.evolve(**{k: v for k, v in (("angle_estimator", est),
                                                     ("angle_subarray", sub)) if v is not None})
    return scene.evolve(radar=radar)


def cmd_run(args) -> int:
    scene = _with_estimator(load_scene_checked(args.scene), args)
    out = args.out
    with output_folder(out, [args.scene]) as stage, steps(args.quiet) as step:
        step(f"simulating {scene.name} ({args.paths} paths, calibration, ADC cube, detection)")
        result = run_scene(scene, args.paths, args.amplitudes, progress=step,
                           **calibration_kw(args))
        step("writing detections, summary and maps")
        (stage / "detections.csv").write_text(detections_csv(result), encoding="utf-8")
        (stage / "summary.json").write_text(
            json.dumps(summary(result, args.paths), indent=2, allow_nan=False) + "\n",
            encoding="utf-8")
        ds = map_dataset(result)
        maps = render_maps(result, ds)
        for name, data in {**maps, **maps_arrays(ds, args.maps)}.items():
            write_bytes(stage / name, data)
        if not args.no_report:
            step("writing report.html (3D view, figures)")
            (stage / "report.html").write_text(
                run_report_html(result, maps, args.paths,
                                list(scene_warnings(scene)) + list(result.warnings)),
                encoding="utf-8")
    if not args.quiet:
        for m in result.matches:
            d, e = m["detection"], m["error"]
            if d is None:
                print(f"target {m['index']}: NOT DETECTED: {m['undetected']['reason']}")
                continue
            el = (f" el {d['elevation_deg']:7.3f} deg" if "elevation_deg" in d else "")
            el_e = (f", el {e['elevation_deg']:+.3f} deg" if "elevation_deg" in e else "")
            print(f"target {m['index']}: {d['range_m']:7.3f} m {d['velocity_mps']:+7.3f} m/s "
                  f"{d['angle_deg']:8.3f} deg{el}  (errors {e['range_m']:+.3f} m, "
                  f"{e['velocity_mps']:+.3f} m/s, {e['angle_deg']:+.3f} deg{el_e})")
        for w in result.warnings:
            print(f"warning: {w}")
        print(f"{len(result.detections)} detections; wrote {out}/detections.csv, summary.json, "
              "range_doppler.png, range_angle.png, "
              + ", ".join(f"maps.{f}" for f in args.maps) + ("" if args.no_report else ", report.html"))
    return 0



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
