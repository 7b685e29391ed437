"""``rtsgeom run | adc``: the signal chain from scene to detections."""

from __future__ import annotations

import csv
import io
import tempfile
from pathlib import Path

import numpy as np

from ..io import atomic_path, write_bytes, write_json, write_text
from ..run import RunResult, run_scene, summary
from ._common import UsageError, load_scene_checked, scene_arg, steps


def detections_csv(result: RunResult) -> str:
    det = result.detections
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["range_m", "velocity_mps", "angle_deg", "power_db", "snr_db"])
    order = np.lexsort((det.velocity_mps, det.range_m))
    for i in order:
        w.writerow([f"{det.range_m[i]:.4f}", f"{det.velocity_mps[i]:.4f}",
                    f"{det.angle_deg[i]:.4f}", f"{det.power_db[i]:.2f}", f"{det.snr_db[i]:.2f}"])
    return buf.getvalue()


def write_maps(result: RunResult, out: Path) -> list[Path]:
    """Range-Doppler and range-angle maps as PNG (paper Figs. "Range-Doppler map ..." and
    "Range angle detections ...")."""
    from ..radar.processing import range_angle_map
    from ..viz.figures import range_angle_figure, range_doppler_figure, save_figure
    rd, det, scene = result.rd, result.detections, result.scene
    f1 = range_doppler_figure(rd.power_db, rd.range_m, rd.velocity_mps,
                              detections=np.c_[det.range_m, det.velocity_mps],
                              title=f"{scene.name}: range-Doppler map")
    angles = np.radians(np.arange(-60.0, 60.01, 0.25))
    ra = range_angle_map(rd, result.cube, angles)
    sets = np.array([[t.range_m, np.degrees(t.angle_rad)] for t in scene.targets]).reshape(-1, 2)
    f2 = range_angle_figure(10 * np.log10(np.maximum(ra, 1e-30)), rd.range_m,
                            np.degrees(angles), detections=np.c_[det.range_m, det.angle_deg],
                            set_points=sets)
    paths = [out / "range_doppler.png", out / "range_angle.png"]
    save_figure(f1, paths[0])
    save_figure(f2, paths[1])
    return paths


def _calibration_figures(result: RunResult, folder: Path) -> list[Path]:
    from ..viz.figures import calibration_sweep_figure, save_figure
    out = []
    for k, cal in enumerate(result.calibration.get("pairs", [])):
        t = np.array([p["delta_tau_s"] for p in cal["sweep"]])
        e = np.array([np.nan if p["angle_error_deg"] is None else p["angle_error_deg"]
                      for p in cal["sweep"]])
        rf = cal.get("refinement", [])
        fig = calibration_sweep_figure(
            t, e, cal["delta_tau_s"], cal["period_s"],
            residual_error_deg=cal.get("residual_error_deg"),
            refine_delta_tau_s=[p["delta_tau_s"] for p in rf],
            refine_error_deg=[np.nan if p["angle_error_deg"] is None else p["angle_error_deg"]
                              for p in rf])
        path = folder / f"calibration_{k}.png"
        save_figure(fig, path)
        out.append(path)
    return out


def write_run_report(result: RunResult, out: Path, maps: list[Path], paths_method: str,
                     warnings: list[str]) -> Path:
    """``DIR/report.html``: scene summary, 3D view, figures, detections vs set-points,
    calibration, warnings; self-contained (images embedded)."""
    from ..info import scene_info
    from ..viz.report import write_report
    from ..viz.scene3d import render_setup_png
    sections = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        images = []
        try:
            images.append(render_setup_png(result.setup, tmp / "setup.png", paths=result.paths))
        except Exception as exc:  # no off-screen OpenGL: the report still has everything else
            warnings = warnings + [f"3D view not rendered: {exc}"]
        sections.append({"heading": "Setup", "images": images,
                         "text": f"Paths: {paths_method} ({len(result.paths)} rows)."})
        rows = []
        for m in result.matches:
            s, d, e = m["set"], m["detection"], m["error"]
            rows.append([m["index"], s["range_m"], s["velocity_mps"], s["angle_deg"],
                         *(("-",) * 6 if d is None else
                           (d["range_m"], d["velocity_mps"], d["angle_deg"], e["range_m"],
                            e["velocity_mps"], e["angle_deg"]))])
        sections.append({"heading": "Targets: set-points and detections",
                         "table": {"columns": ["target", "set range m", "set velocity m/s",
                                               "set angle deg", "range m", "velocity m/s",
                                               "angle deg", "range error m",
                                               "velocity error m/s", "angle error deg"],
                                   "rows": rows},
                         "images": [p.read_bytes() for p in maps]})
        cal = result.calibration
        if cal:
            rows = [[str(tuple(p["pair"])), p["delta_tau_s"] * 1e12, p["residual_error_deg"],
                     p["range_offset_m"] * 1e3] for p in cal["pairs"]]
            sections.append({
                "heading": "Calibration",
                "text": (f"Amplitude mode {cal['mode']}. Front ends alone are detected at "
                         + ", ".join(f"{a:.3f}" for a in cal["front_end_angles_deg"])
                         + " deg; gain corrections "
                         + ", ".join(f"{g:.4f}" for g in cal["gain_correction"]) + "."),
                "table": {"columns": ["pair", "delta tau ps", "residual error deg",
                                      "range offset mm"], "rows": rows},
                "images": [p.read_bytes() for p in _calibration_figures(result, tmp)]})
        det = result.detections
        sections.append({"heading": "All detections",
                         "table": {"columns": ["range m", "velocity m/s", "angle deg",
                                               "power dB", "SNR dB"],
                                   "rows": [[f"{a:.3f}", f"{b:.3f}", f"{c:.3f}", f"{d:.1f}",
                                             f"{e:.1f}"] for a, b, c, d, e in
                                            zip(det.range_m, det.velocity_mps, det.angle_deg,
                                                det.power_db, det.snr_db)]}})
        if warnings:
            sections.append({"heading": "Warnings", "warnings": warnings})
        return write_report(out / "report.html", f"rtsgeom run: {result.scene.name}",
                            scene_info(result.setup), sections)


def cmd_run(args) -> int:
    from ..validate import scene_warnings
    scene = load_scene_checked(args.scene)
    out = args.out
    with steps(args.quiet) as step:
        step(f"simulating {scene.name} ({args.paths} paths, calibration, ADC cube, detection)")
        result = run_scene(scene, args.paths, args.amplitudes)
        step("writing detections, summary and maps")
        write_text(out / "detections.csv", detections_csv(result))
        write_json(out / "summary.json", summary(result, args.paths))
        maps = write_maps(result, out)
        if not args.no_report:
            step("writing report.html (3D view, figures)")
            write_run_report(result, out, maps, args.paths,
                             list(scene_warnings(scene)) + list(result.warnings))
    if not args.quiet:
        for m in result.matches:
            d, e = m["detection"], m["error"]
            if d is None:
                print(f"target {m['index']}: NOT DETECTED")
                continue
            print(f"target {m['index']}: {d['range_m']:7.3f} m {d['velocity_mps']:+7.3f} m/s "
                  f"{d['angle_deg']:8.3f} deg  (errors {e['range_m']:+.3f} m, "
                  f"{e['velocity_mps']:+.3f} m/s, {e['angle_deg']:+.3f} deg)")
        for w in result.warnings:
            print(f"warning: {w}")
        print(f"{len(result.detections)} detections; wrote {out}/detections.csv, summary.json, "
              "range_doppler.png, range_angle.png" + ("" if args.no_report else ", report.html"))
    return 0


def cmd_adc(args) -> int:
    scene = load_scene_checked(args.scene)
    with steps(args.quiet) as step:  # the calibration sweeps take about a minute
        step(f"simulating {scene.name} (calibration, ADC cube)")
        cube = run_scene(scene, "exact", args.amplitudes).cube
    if args.format == "npy":
        with atomic_path(args.out) as tmp:
            with open(tmp, "wb") as fh:
                np.save(fh, cube.data)
        print(f"wrote {args.out}: complex64 {list(cube.shape)} "
              "[chirp_loop, virtual_channel, sample]")
    else:
        from ..radar.dca1000 import to_dca1000
        try:
            raw, scale = to_dca1000(cube)
        except ValueError as exc:
            raise UsageError(str(exc)) from None
        write_bytes(args.out, raw)
        n_l, n_v, n_s = cube.shape
        meta = {"format": "dca1000-xwr18xx-complex-2lane", "scale": scale,
                "chirps": n_l * len(cube.rut.tx_order), "tx_order": list(cube.rut.tx_order),
                "num_rx": cube.rut.num_rx, "samples_per_chirp": n_s, "dtype": "int16 (<i2)",
                "order": "chirp (transmit order) > rx > sample pairs I0 I1 Q0 Q1"}
        write_json(Path(str(args.out) + ".json"), meta)
        print(f"wrote {args.out} ({len(raw)} bytes, scale {scale:.6g}) and {args.out}.json")
    return 0


def register(sub) -> None:
    modes = ("exact", "array-factor", "paper", "nearest")
    p = sub.add_parser("run", help="the main job: simulate the scene, detect, compare with set-points")
    scene_arg(p)
    p.add_argument("--out", type=Path, required=True, help="output folder")
    p.add_argument("--paths", choices=("exact", "raytrace"), default="exact",
                   help="exact line-of-sight paths (default) or Sionna RT ray tracing")
    p.add_argument("--amplitudes", choices=modes, default=None,
                   help="AoA amplitude mode (default: the scene's rts.aoa_mode)")
    p.add_argument("--no-report", action="store_true", help="skip report.html")
    p.add_argument("--quiet", action="store_true", help="print nothing but errors")
    p.set_defaults(func=cmd_run)

    p = sub.add_parser("adc", help="save the raw ADC cube (.npy) or a DCA1000 capture")
    scene_arg(p)
    p.add_argument("--out", type=Path, required=True, help="output file")
    p.add_argument("--format", choices=("npy", "dca1000"), default="npy")
    p.add_argument("--amplitudes", choices=modes, default=None,
                   help="AoA amplitude mode (default: the scene's rts.aoa_mode)")
    p.add_argument("--quiet", action="store_true", help="no progress output on stderr")
    p.set_defaults(func=cmd_adc)
