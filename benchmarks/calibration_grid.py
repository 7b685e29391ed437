"""``python -m benchmarks.calibration_grid [--quick]``: does the calibration land on the
phase-coherence point for every setup?

For radial mounting offsets dr from -1 to +1 mm in 0.05 mm steps on either front end of the
pair (0, 1), at arc radii R_c = 0.5, 1 and 3 m, run the full-chain calibration
(``aoa.calibration.calibrate_pair``: simulated ADC cubes, CFAR, beamforming) and report

* ``dist_closed_ps``: calibrated delay minus the closed-form coherence point, wrapped into
  (-period/2, period/2]. The closed form: the coherence point of the nominal setup (same R_c,
  no offset; phasor model, ``coherence_delay``) shifted by
  ``-(f_c + S t_mid - S tau) / (f_rts + S t_mid - S tau) * 2 dr / c0`` (sign reversed for an
  offset of front end I: the calibration delays J);
* ``dist_phasor_ps``: calibrated delay minus the phasor model's coherence point of the setup as
  built (``coherence_delay`` on the offset setup; checks the closed form);
* ``residual_deg``: the sweep's RMS probe-angle error at the chosen delay;
* ``period_s``: the sweep period the calibration reports.

Writes ``benchmarks/calibration_grid[_quick].json`` and ``.csv``; prints the worst cases.
``--quick``: 0.25 mm steps instead of 0.05 mm. ``--linearity N``: also the exact-mode
linearity (N set-points, calibrated) per case. ``--noiseless``: no receiver noise (isolates
the systematic part from the per-frame noise bias). ``--workers N``: a process pool.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
from scipy.constants import c

from benchmarks._io import csv_writer, write_json_csv

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_SCENE = ROOT / "scenes" / "diewald2022.toml"
PAIR = (0, 1)


def variant(scene, radius_m: float, fe: int | None, dr_m: float, noiseless: bool):
    """The scene at arc radius ``radius_m`` with a radial offset ``dr_m`` on front end ``fe``."""
    fes = list(scene.rts.front_ends)
    if fe is not None:
        fes[fe] = dataclasses.replace(fes[fe], radial_offset_m=float(dr_m))
    rts = dataclasses.replace(scene.rts, arc_radius_m=float(radius_m), front_ends=tuple(fes))
    radar = dataclasses.replace(scene.radar, snr_db=None) if noiseless else scene.radar
    return dataclasses.replace(scene, rts=rts, radar=radar)


def nominal_point(scene_path: str, radius_m: float, noiseless: bool) -> dict:
    """Coherence point of the nominal setup at this radius (phasor model)."""
    from rtsgeom.calibration.pair import pair_coherence
    from rtsgeom.calibration.probes import probe_angles, probe_front_ends
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.scene import load_scene
    scene = variant(load_scene(scene_path), radius_m, None, 0.0, noiseless)
    setup = build_setup(scene)
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, scene.seed)
    alphas = probe_angles(*probe.angle_rad[list(PAIR)])
    return {"radius_m": radius_m,
            "coherence_s": pair_coherence(setup, paths, PAIR, alphas=alphas,
                                          near_s=0.0).continuous_s,
            "probe_angles_rad": [float(a) for a in alphas]}


def one_case(args: tuple) -> dict:
    scene_path, radius_m, fe, dr_m, noiseless, nominal_s, lin_points = args
    from rtsgeom.calibration.probes import (air_phase_slope_hz, if_phase_slope_hz, probe_angles,
                                            probe_front_ends, probe_ranges)
    from rtsgeom.calibration.pair import calibrate_pair, pair_coherence
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.scene import load_scene
    t0 = time.perf_counter()
    scene = variant(load_scene(scene_path), radius_m, fe, dr_m, noiseless)
    setup = build_setup(scene)
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, scene.seed)
    cal = calibrate_pair(setup, paths, PAIR, probe, seed=scene.seed)
    tau = float(np.mean(2 * probe_ranges(setup, 2) / c))
    f_if = float(if_phase_slope_hz(scene, tau))
    period = 1.0 / f_if
    sign = 1.0 if fe == PAIR[1] else -1.0
    closed = nominal_s - sign * float(air_phase_slope_hz(scene, tau)) / f_if * 2 * dr_m / c
    alphas = probe_angles(*probe.angle_rad[list(PAIR)])
    phasor = pair_coherence(setup, paths, PAIR, alphas=alphas, near_s=cal.delta_tau_s).continuous_s

    def wrap(x):
        return float((x + period / 2) % period - period / 2)
    lin = {}
    if lin_points:
        from rtsgeom.analysis.linearity import linearity
        res = linearity(setup, paths, PAIR, "exact", probe, cal, lin_points, scene.seed)
        lin = {"linearity_max_abs_deg": res.max_abs_error_deg}
    return {**lin, "radius_m": radius_m, "front_end": fe, "radial_offset_mm": round(dr_m * 1e3, 6),
            "delta_tau_ps": cal.delta_tau_s * 1e12, "closed_form_ps": closed * 1e12,
            "phasor_ps": phasor * 1e12,
            "dist_closed_ps": wrap(cal.delta_tau_s - closed) * 1e12,
            "dist_phasor_ps": wrap(cal.delta_tau_s - phasor) * 1e12,
            "closed_minus_phasor_ps": wrap(closed - phasor) * 1e12,
            "residual_deg": cal.residual_error_deg, "period_s": cal.period_s,
            "exact_period_s": period, "range_offset_mm": cal.range_offset_m * 1e3,
            "frames_per_step": cal.frames_per_step,
            "one_frame_scatter_ps": cal.one_frame_scatter_ps,
            "seconds": time.perf_counter() - t0}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.calibration_grid",
                                 description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default=str(DEFAULT_SCENE))
    ap.add_argument("--quick", action="store_true", help="0.25 mm steps instead of 0.05 mm")
    ap.add_argument("--radii", type=float, nargs="+", default=[0.5, 1.0, 3.0])
    ap.add_argument("--max-mm", type=float, default=1.0)
    ap.add_argument("--step-mm", type=float, default=None)
    ap.add_argument("--noiseless", action="store_true")
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--linearity", type=int, default=0, metavar="N",
                    help="also exact-mode linearity with N set-points per case (0: off)")
    ap.add_argument("--out", type=Path, default=None, help="file stem (default benchmarks/"
                    "calibration_grid[_quick])")
    a = ap.parse_args(argv)
    step = a.step_mm or (0.25 if a.quick else 0.05)
    n = int(round(a.max_mm / step))
    offsets_m = np.arange(-n, n + 1) * step * 1e-3
    stem = a.out or ROOT / "benchmarks" / ("calibration_grid" + ("_quick" if a.quick else ""))
    pool = ProcessPoolExecutor(a.workers) if a.workers > 1 else None
    mapper = pool.map if pool else map
    t0 = time.perf_counter()
    noms = {r["radius_m"]: r["coherence_s"] for r in
            mapper(nominal_point, [a.scene] * len(a.radii), a.radii, [a.noiseless] * len(a.radii))}
    cases = [(a.scene, r, fe, float(dr), a.noiseless, noms[r], a.linearity) for r in a.radii
             for fe in PAIR for dr in offsets_m]
    rows = []
    partial = open(str(stem) + ".partial.csv", "w", newline="")  # rows as they come
    writer = None
    for row in mapper(one_case, cases):
        rows.append(row)
        if writer is None:
            writer = csv_writer(partial, row)
        writer.writerow(row)
        partial.flush()
        print(f"R_c {row['radius_m']:.2f} m  fe {row['front_end']}  dr {row['radial_offset_mm']:+.2f}"
              f" mm: delta_tau {row['delta_tau_ps']:+8.1f} ps, from coherence (closed form) "
              f"{row['dist_closed_ps']:+6.1f} ps, (phasor) {row['dist_phasor_ps']:+6.1f} ps, "
              f"residual {row['residual_deg']:.4f} deg"
              + (f", linearity {row['linearity_max_abs_deg']:.4f} deg" if a.linearity else ""),
              flush=True)
    if pool:
        pool.shutdown()
    partial.close()
    Path(str(stem) + ".partial.csv").unlink()
    d = np.array([abs(r["dist_closed_ps"]) for r in rows])
    worst = sorted(rows, key=lambda r: -abs(r["dist_closed_ps"]))[:10]
    summary = {
        "scene": Path(a.scene).name, "pair": list(PAIR), "step_mm": step, "max_mm": a.max_mm,
        "radii_m": a.radii, "noiseless": a.noiseless, "cases": len(rows),
        "max_abs_dist_closed_ps": float(d.max()),
        "p95_abs_dist_closed_ps": float(np.percentile(d, 95)),
        "within_10ps": float(np.mean(d <= 10.0)),
        "max_residual_deg": float(max(r["residual_deg"] for r in rows)),
        "max_frames_per_step": int(max(r["frames_per_step"] for r in rows)),
        "max_linearity_deg": (float(max(r["linearity_max_abs_deg"] for r in rows))
                              if a.linearity else None),
        "max_one_frame_scatter_ps": float(max(r["one_frame_scatter_ps"] for r in rows)),
        "max_abs_closed_minus_phasor_ps": float(max(abs(r["closed_minus_phasor_ps"]) for r in rows)),
        "per_radius": {str(r): {"max_abs_dist_closed_ps": float(max(
            abs(x["dist_closed_ps"]) for x in rows if x["radius_m"] == r)),
            "max_residual_deg": float(max(x["residual_deg"] for x in rows if x["radius_m"] == r))}
            for r in a.radii},
        "nominal_coherence_ps": {str(r): noms[r] * 1e12 for r in a.radii},
        "worst": worst, "seconds": time.perf_counter() - t0,
    }
    write_json_csv(stem, {"summary": summary, "rows": rows}, rows)
    print(json.dumps({k: v for k, v in summary.items() if k != "worst"}, indent=1))
    print("worst cases (|calibrated - closed-form coherence point|):")
    for r in worst:
        print(f"  R_c {r['radius_m']} m fe {r['front_end']} dr {r['radial_offset_mm']:+.2f} mm: "
              f"{r['dist_closed_ps']:+.1f} ps, residual {r['residual_deg']:.4f} deg")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
