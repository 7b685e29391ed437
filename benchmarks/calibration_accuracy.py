"""``python -m benchmarks.calibration_accuracy [--quick] [--workers N]``: does the calibration
land on the coherence point for every array, radius, mounting offset, noise and dimension?

The grid (one row per calibration, ``calibration.pair.calibrate_pair``):

* arrays: every radar preset on the paper's scene (``awr1843boost``, ``iwr6843isk``,
  ``awr2944``, ``awr2243-cascade``; azimuth only), the bundled custom array (3 Tx, 12 virtual
  elements on 10 positions) and a sparse custom array (its Rx 2, 3 and 2 d apart: 12
  elements over 25 d with gaps), each pair (0, 1) on an arc; and sphere4's RuT beamforming
  in azimuth and elevation, its pair (0, 1) stacked in elevation and (0, 2) side by side;
* arc (sphere) radii 0.5, 1 and 3 m (the cascade: 3 m);
* radial offsets -1, -0.5, 0, +0.5, +1 mm on either front end of the pair (sphere4's pairs
  also tangential offsets of +-1 mm: across an elevation pair's line);
* noiseless, and with the scene's receiver noise (``snr_db``).

Per row, the calibrated delay's distance (ps, wrapped into one period) from

* ``dist_coherence_ps``: the coherence point of the setup as built (``pair_coherence``:
  Newton on the probes' phase mismatch, continuous delay; no sweep);
* ``dist_slope_ps``: the closed form, the nominal setup's coherence point shifted by the
  slope law ``-(f_c + S t_mid - S tau) / (f_rts + S t_mid - S tau) * 2 dr / c0`` (sign
  reversed for an offset of front end I: the calibration delays J; a tangential offset does
  not move it to first order);
* ``dist_dense_min_ps`` (noiseless rows; ``--dense``): the minimum of a dense noiseless sweep
  (0.5 ps steps on the arc, 1 ps in 2-D) of the probes' RMS error. Not the coherence point
  under a mounting offset: the probes' RMS minimum moves off it (``calibration.fit``).

``--arrays A B --keep benchmarks/calibration_accuracy.json``: re-measure arrays A and B, keep
the other arrays' rows as they were measured.

``--bundled``: instead of the grid, every bundled scene (``scenes/*.toml``) as shipped and
with its mounting offsets removed, every pair its calibration measures (adjacent on an arc; the
edges of the cells in 2-D), noiseless, with the distance from the coherence point and from the
dense sweep's minimum (``benchmarks/calibration_bundled.json``).

Writes ``benchmarks/calibration_accuracy[_quick].json`` and ``.csv`` and prints the worst
rows. ``--quick``: offsets 0 and +-1 mm, radius 1 m and 3 m. About 25 min on 2 cores in
full with ``--workers 2`` (the 2-D rows run the full chain at every sweep step).
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

from benchmarks._io import write_json_csv

ROOT = Path(__file__).resolve().parents[1]
SPARSE_RX_MM = [[32.3, 0.0], [36.1, 0.0], [41.8, 0.0], [45.6, 0.0]]  # gaps 2, 3, 2 x 1.9 mm
# name: (scene file, radar changes or None, pairs, front end 1's spacing from 0 (deg; None:
# the scene's), radii (None: all)). The cascade's beam (86 lambda/2 positions) is 1.2 deg
# wide: its pair 1 deg apart, which the sheet's cutouts allow from about 2 m. sphere4's sheet
# grows with the radius (its +-8.6 deg cap holds the +-5 deg front ends at every radius).
ARRAYS = {
    "awr1843boost": ("diewald2022.toml", {"antenna_preset": "awr1843boost"}, [(0, 1)], None,
                     None),
    "iwr6843isk": ("diewald2022.toml", {"antenna_preset": "iwr6843isk"}, [(0, 1)], None, None),
    "awr2944": ("diewald2022.toml", {"antenna_preset": "awr2944"}, [(0, 1)], None, None),
    "awr2243-cascade": ("diewald2022.toml", {"antenna_preset": "awr2243-cascade"}, [(0, 1)],
                        1.0, [3.0]),
    "custom": ("custom-array.toml", None, [(0, 1)], None, None),
    "custom-sparse": ("custom-array.toml", "sparse", [(0, 1)], None, None),
    "sphere4": ("sphere4.toml", None, [(0, 1), (0, 2)], None, None),
}


def variant(array: str, radius_m: float, fe: int | None, dr_m: float, noisy: bool,
            field: str = "radial_offset_m"):
    """The scene of ``array`` at radius ``radius_m``, front end ``fe`` moved by ``dr_m``
    (``field``: radially, or tangentially), with or without its receiver noise."""
    from rtsgeom.scene import load_scene
    name, change, _, spacing_deg, _ = ARRAYS[array]
    scene = load_scene(ROOT / "scenes" / name)
    radar = scene.radar
    if change == "sparse":
        radar = radar.evolve(array=radar.array.evolve(
            rx_mm=tuple(tuple(p) for p in SPARSE_RX_MM)))
    elif change:
        radar = radar.evolve(**change)
    if not noisy:
        radar = radar.evolve(snr_db=None)
    fes = list(scene.rts.front_ends)
    if spacing_deg is not None:
        fes[1] = dataclasses.replace(fes[1], angle_rad=fes[0].angle_rad
                                     + float(np.radians(spacing_deg)))
    if fe is not None:
        fes[fe] = dataclasses.replace(fes[fe], **{field: float(dr_m)})
    rts = scene.rts.evolve(arc_radius_m=float(radius_m), front_ends=tuple(fes))
    sheet = scene.sheet
    if any(f.elevation_rad for f in fes):  # the spherical cap's chord in proportion
        sheet = sheet.evolve(height_m=sheet.height_m * float(radius_m) / scene.rts.arc_radius_m)
    # no targets: the calibration programs its own probes (and a 9-Tx TDM frame's velocity
    # limit would refuse the paper scene's 4 m/s target)
    return scene.evolve(radar=radar, rts=rts, sheet=sheet, targets=())


MOUNTING = ("radial_offset_m", "tangential_offset_m", "height_offset_m", "yaw_offset_rad",
            "pitch_offset_rad")


def bundled_scene(name: str, perfect: bool):
    """A bundled scene, noiseless, no targets; ``perfect``: its front ends' mounting offsets
    removed (those :data:`MOUNTING` names that the front end has)."""
    from rtsgeom.scene import load_scene
    scene = load_scene(ROOT / "scenes" / name)
    fes = scene.rts.front_ends
    if perfect:
        fes = tuple(dataclasses.replace(f, **{k: 0.0 for k in MOUNTING if hasattr(f, k)})
                    for f in fes)
    return scene.evolve(radar=scene.radar.evolve(snr_db=None), targets=(),
                        rts=scene.rts.evolve(front_ends=fes))


def bundled_cases() -> list[tuple]:
    """(scene file, pair, perfect) for every bundled scene and measured pair."""
    from rtsgeom.geometry import build_setup
    from rtsgeom.pipeline.plan import measured_pairs
    out = []
    for path in sorted((ROOT / "scenes").glob("*.toml")):
        pairs = measured_pairs(build_setup(bundled_scene(path.name, False)))
        out += [(path.name, tuple(map(int, p)), perfect) for perfect in (False, True)
                for p in pairs]
    return out


def one_bundled(args: tuple) -> dict:
    """One bundled scene's pair (:func:`bundled_cases`): calibrated delay against the
    coherence point and the dense noiseless sweep's RMS minimum."""
    from rtsgeom.calibration.fit import rms_error_deg
    from rtsgeom.calibration.pair import calibrate_pair, pair_coherence, pair_probes
    from rtsgeom.calibration.probes import probe_front_ends
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    name, pair, perfect = args
    t0 = time.perf_counter()
    row = {"scene": name, "pair": f"{pair[0]}-{pair[1]}", "perfect": perfect}
    try:
        scene = bundled_scene(name, perfect)
        setup = build_setup(scene)
        paths = exact_paths(setup)
        probe = probe_front_ends(setup, paths, scene.seed)
        cal = calibrate_pair(setup, paths, pair, probe, seed=scene.seed)
    except Exception as exc:  # noqa: BLE001 (a benchmark row, reported below)
        return {**row, "error": f"{type(exc).__name__}: {exc}"}
    period = cal.period_s

    def wrap(x):
        return float((x + period / 2) % period - period / 2)
    point = pair_coherence(setup, paths, pair, probe, near_s=cal.delta_tau_s).continuous_s
    probes = pair_probes(setup, paths, pair, probe).placed(
        cal.coarse_minimum_s + np.arange(-period / 4, period / 4, 25e-12))
    step = 0.5e-12 if cal.dims == 1 else 1e-12
    t = point + np.arange(-30e-12, 30e-12 + 1e-15, step)
    rms = rms_error_deg(probes.measure(t))
    dense = float(t[int(np.argmin(rms))])
    return {**row, "dims": cal.dims, "delta_tau_ps": cal.delta_tau_s * 1e12,
            "fit_ps": cal.fit_s * 1e12, "coherence_ps": point * 1e12,
            "dense_min_ps": dense * 1e12,
            "dist_coherence_ps": wrap(cal.delta_tau_s - point) * 1e12,
            "dist_dense_min_ps": wrap(cal.delta_tau_s - dense) * 1e12,
            "dense_min_minus_coherence_ps": wrap(dense - point) * 1e12,
            "resolution_ps": cal.delay_resolution_s * 1e12,
            "residual_deg": cal.residual_error_deg,
            "seconds": time.perf_counter() - t0}


def run_bundled(workers: int) -> int:
    """``--bundled`` (module doc)."""
    cases = bundled_cases()
    t0 = time.perf_counter()
    with ProcessPoolExecutor(max(1, workers)) as pool:
        rows = list(pool.map(one_bundled, cases))
    for r in rows:
        print(r["scene"], r["pair"], "perfect" if r["perfect"] else "as shipped",
              r.get("error") or f"dims {r['dims']}: delta_tau {r['delta_tau_ps']:+8.1f} ps, "
              f"from the coherence point {r['dist_coherence_ps']:+5.2f} ps, from the dense "
              f"minimum {r['dist_dense_min_ps']:+5.2f} ps", flush=True)
    good = [r for r in rows if "error" not in r]
    summary = {"cases": len(rows), "failed": [r for r in rows if "error" in r],
               "seconds": time.perf_counter() - t0}
    for key in ("dist_coherence_ps", "dist_dense_min_ps"):
        w = max(good, key=lambda r: abs(r[key]))
        summary[f"max_abs_{key}"], summary[f"worst_{key}"] = abs(w[key]), w
    keys = list(dict.fromkeys(k for r in rows for k in r))
    write_json_csv(ROOT / "benchmarks" / "calibration_bundled", {"summary": summary,
                                                                "rows": rows},
                   [{k: r.get(k) for k in keys} for r in rows])
    print(json.dumps({k: v for k, v in summary.items() if "worst" not in k}, indent=1))
    return 0


def one_case(args: tuple) -> dict:
    """One calibration of the grid and its distances (module doc); a case that cannot run
    is a row with its ``error``, not the end of the grid."""
    try:
        return _case(*args)
    except Exception as exc:  # noqa: BLE001 (a benchmark row, reported below)
        array, pair, radius_m, fe, dr_m, noisy, _, _ = args
        return {"array": array, "pair": f"{pair[0]}-{pair[1]}", "radius_m": radius_m,
                "front_end": fe, "offset_mm": round(dr_m * 1e3, 6), "noisy": noisy,
                "error": f"{type(exc).__name__}: {exc}"}


def _case(array, pair, radius_m, fe, dr_m, noisy, dense, field) -> dict:
    from rtsgeom.calibration.fit import rms_error_deg
    from rtsgeom.calibration.pair import calibrate_pair, pair_coherence, pair_probes
    from rtsgeom.calibration.probes import (air_phase_slope_hz, if_phase_slope_hz,
                                            probe_front_ends, probe_ranges)
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    t0 = time.perf_counter()

    def built(scene):
        setup = build_setup(scene)
        paths = exact_paths(setup)
        return setup, paths, probe_front_ends(setup, paths, scene.seed)

    scene = variant(array, radius_m, fe, dr_m, noisy, field)
    setup, paths, probe = built(scene)
    cal = calibrate_pair(setup, paths, pair, probe, seed=scene.seed)
    period = cal.period_s

    def wrap(x):
        return float((x + period / 2) % period - period / 2)
    point = pair_coherence(setup, paths, pair, probe, near_s=cal.delta_tau_s).continuous_s
    # the closed form: the nominal setup's point (same radius, no offset, same probe angles)
    nominal = variant(array, radius_m, None, 0.0, False)
    n_setup, n_paths, _ = built(nominal)
    alphas = None if cal.dims == 2 else np.radians(cal.probe_angles_deg)
    n_point = pair_coherence(n_setup, n_paths, pair, probe, alphas=alphas).continuous_s
    tau = float(np.mean(2 * probe_ranges(setup, 2) / c))
    sign = 1.0 if fe == pair[1] else -1.0
    slope = float(air_phase_slope_hz(scene, tau)) / float(if_phase_slope_hz(scene, tau))
    # the slope law of a radial offset; a tangential one leaves the point (second order)
    closed = n_point - (sign * slope * 2 * dr_m / c if field == "radial_offset_m" else 0.0)
    row = {"array": array, "pair": f"{pair[0]}-{pair[1]}", "dims": cal.dims,
           "radius_m": radius_m, "front_end": fe, "offset": field.replace("_offset_m", ""),
           "offset_mm": round(dr_m * 1e3, 6),
           "noisy": noisy, "delta_tau_ps": cal.delta_tau_s * 1e12,
           "fit_ps": cal.fit_s * 1e12, "coherence_ps": point * 1e12,
           "closed_form_ps": closed * 1e12,
           "dist_coherence_ps": wrap(cal.delta_tau_s - point) * 1e12,
           "fit_minus_coherence_ps": wrap(cal.fit_s - point) * 1e12,
           "dist_slope_ps": wrap(cal.delta_tau_s - closed) * 1e12,
           "closed_minus_coherence_ps": wrap(closed - point) * 1e12,
           "dist_dense_min_ps": None, "residual_deg": cal.residual_error_deg,
           "frames_per_step": cal.frames_per_step,
           "one_frame_scatter_ps": cal.one_frame_scatter_ps}
    if dense and not noisy:
        probes = pair_probes(setup, paths, pair, probe).placed(
            cal.coarse_minimum_s + np.arange(-period / 4, period / 4, 25e-12))
        step = 0.5e-12 if cal.dims == 1 else 1e-12
        t = point + np.arange(-30e-12, 30e-12 + 1e-15, step)
        rms = rms_error_deg(probes.measure(t))
        row["dist_dense_min_ps"] = wrap(cal.delta_tau_s - t[int(np.argmin(rms))]) * 1e12
    row["seconds"] = time.perf_counter() - t0
    return row


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.calibration_accuracy",
                                 description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="offsets 0, +-1 mm; radii 1, 3 m")
    ap.add_argument("--arrays", nargs="+", default=list(ARRAYS), choices=list(ARRAYS))
    ap.add_argument("--dense", action="store_true",
                    help="also the dense noiseless sweep's RMS minimum (slower)")
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--keep", type=Path, default=None, metavar="JSON",
                    help="re-measure only --arrays; keep the other arrays' rows from JSON")
    ap.add_argument("--bundled", action="store_true",
                    help="every bundled scene's measured pairs instead of the grid")
    ap.add_argument("--out", type=Path, default=None,
                    help="file stem (default benchmarks/calibration_accuracy[_quick])")
    ap.add_argument("--radii", type=float, nargs="+", default=None, metavar="R",
                    help="arc radii (m) instead of the grid's (0.5 1 3; --quick: 1 3)")
    a = ap.parse_args(argv)
    if a.bundled:
        return run_bundled(a.workers)
    radii = a.radii or ([1.0, 3.0] if a.quick else [0.5, 1.0, 3.0])
    offsets = [-1e-3, 1e-3] if a.quick else [-1e-3, -0.5e-3, 0.5e-3, 1e-3]
    cases = []
    for array in a.arrays:
        for pair in ARRAYS[array][2]:
            for r in ARRAYS[array][4] or radii:
                for noisy in (False, True):
                    cases.append((array, pair, r, None, 0.0, noisy, a.dense, "radial_offset_m"))
                    cases += [(array, pair, r, fe, dr, noisy, a.dense, "radial_offset_m")
                              for fe in pair for dr in offsets]
                    if array == "sphere4":  # a 2-D pair: also off across its line
                        cases += [(array, pair, r, fe, dr, noisy, a.dense,
                                   "tangential_offset_m") for fe in pair for dr in (-1e-3, 1e-3)]
    stem = a.out or ROOT / "benchmarks" / ("calibration_accuracy"
                                           + ("_quick" if a.quick else ""))
    t0 = time.perf_counter()
    rows = []
    with ProcessPoolExecutor(max(1, a.workers)) as pool:
        for row in pool.map(one_case, cases):
            rows.append(row)
            if "error" in row:
                print(f"{row['array']:>16} {row['pair']} R {row['radius_m']:.1f} m: {row['error']}",
                      flush=True)
                continue
            print(f"{row['array']:>16} {row['pair']} R {row['radius_m']:.1f} m fe "
                  f"{row['front_end']} {row['offset']} {row['offset_mm']:+.1f} mm "
                  f"{'noisy' if row['noisy'] else 'clean'}: delta_tau "
                  f"{row['delta_tau_ps']:+8.1f} ps, from the coherence point "
                  f"{row['dist_coherence_ps']:+5.1f} ps, slope law {row['dist_slope_ps']:+5.1f} ps"
                  + ("" if row["dist_dense_min_ps"] is None
                     else f", dense minimum {row['dist_dense_min_ps']:+5.1f} ps"), flush=True)

    kept = []
    if a.keep is not None:  # the other arrays' rows as measured before
        kept = [r for r in json.loads(a.keep.read_text())["rows"] if r["array"] not in a.arrays]
        rows = kept + rows

    def worst(key, sel):
        got = [r for r in rows if "error" not in r and sel(r) and r[key] is not None]
        return max(got, key=lambda r: abs(r[key])) if got else None
    summary = {"cases": len(rows), "failed": [r for r in rows if "error" in r],
               "radii_m": radii, "offsets_mm": [x * 1e3 for x in offsets],
               "seconds": time.perf_counter() - t0, "kept_rows": len(kept)}
    for label, sel in (("noiseless", lambda r: not r["noisy"]), ("noisy", lambda r: r["noisy"])):
        for key in ("dist_coherence_ps", "dist_slope_ps", "dist_dense_min_ps"):
            for dims in (1, 2):
                w = worst(key, lambda r: sel(r) and r["dims"] == dims)
                if w is not None:
                    summary[f"{label}_{dims}d_max_abs_{key}"] = abs(w[key])
                    summary[f"{label}_{dims}d_worst_{key}"] = w
    keys = list(dict.fromkeys(k for r in rows for k in r))
    write_json_csv(stem, {"summary": summary, "rows": rows},
                   [{k: r.get(k) for k in keys} for r in rows])
    print(json.dumps({k: v for k, v in summary.items() if "worst" not in k}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
