"""``rtsgeom run | adc``: the signal chain from scene to detections."""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np

from ..io import atomic_path, write_bytes, write_json, write_text
from ..run import RunResult, run_scene, summary
from ..scene import load_scene
from ._common import UsageError, scene_arg


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


def cmd_run(args) -> int:
    scene = load_scene(args.scene)
    result = run_scene(scene, args.paths, args.amplitudes)
    out = args.out
    write_text(out / "detections.csv", detections_csv(result))
    write_json(out / "summary.json", summary(result, args.paths))
    write_maps(result, out)
    if not args.quiet:
        for m in result.matches:
            d, e = m["detection"], m["error"]
            if d is None:
                print(f"target {m['index']}: NOT DETECTED")
                continue
            print(f"target {m['index']}: {d['range_m']:7.3f} m {d['velocity_mps']:+7.3f} m/s "
                  f"{d['angle_deg']:8.3f} deg  (errors {e['range_m']:+.3f} m, "
                  f"{e['velocity_mps']:+.3f} m/s, {e['angle_deg']:+.3f} deg)")
        print(f"{len(result.detections)} detections; wrote {out}/detections.csv, summary.json, "
              "range_doppler.png, range_angle.png")
    return 0


def cmd_adc(args) -> int:
    from ..rts import program_nearest
    from ..run import simulate
    from ..geometry import build_setup
    from ..paths import exact_paths
    scene = load_scene(args.scene)
    result = run_scene(scene, "exact", args.amplitudes) if scene.targets else None
    if result is None:
        setup = build_setup(scene)
        _, cube = simulate(setup, exact_paths(setup), program_nearest(scene, setup),
                           scene.seed, scene.radar.snr_db)
    else:
        cube = result.cube
    if args.format == "npy":
        with atomic_path(args.out) as tmp:
            with open(tmp, "wb") as fh:
                np.save(fh, cube.data)
        print(f"wrote {args.out}: complex64 {list(cube.shape)} [chirp_loop, virtual_channel, sample]")
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
                "num_rx": cube.rut.num_rx, "samples_per_chirp": n_s, "dtype": "int16 (<i2)"}
        write_json(Path(str(args.out) + ".json"), meta)
        print(f"wrote {args.out} ({len(raw)} bytes, scale {scale:.6g}) and {args.out}.json")
    return 0


def register(sub) -> None:
    p = sub.add_parser("run", help="the main job: simulate the scene, detect, compare with set-points")
    scene_arg(p)
    p.add_argument("--out", type=Path, required=True, help="output folder")
    p.add_argument("--paths", choices=("exact", "raytrace"), default="exact",
                   help="exact line-of-sight paths (default) or Sionna RT ray tracing")
    p.add_argument("--amplitudes", choices=("exact", "array-factor", "paper", "nearest"),
                   default=None, help="AoA amplitude mode (default: the scene's rts.aoa_mode)")
    p.add_argument("--quiet", action="store_true", help="print nothing but errors")
    p.set_defaults(func=cmd_run)

    p = sub.add_parser("adc", help="save the raw ADC cube (.npy) or a DCA1000 capture")
    scene_arg(p)
    p.add_argument("--out", type=Path, required=True, help="output file")
    p.add_argument("--format", choices=("npy", "dca1000"), default="npy")
    p.add_argument("--amplitudes", choices=("exact", "array-factor", "paper", "nearest"),
                   default=None)
    p.set_defaults(func=cmd_adc)
