"""``python -m benchmarks.calibration_resolution``: the calibration on coarse RTS delay steps.

For delay resolutions ``rts.delay_resolution_s`` of 1, 5, 10, 25, 50 and 100 ps (fractional-
delay FIR steps; 100 ps does not divide the 250 ps sample) and 250 ps (whole 4 GSPS samples,
no FIR) x radial offsets of front end 1 (0, +0.3, -0.6 mm) x arc radii (1 and 3 m), on the
noiseless default scene, the pair (0, 1):

* ``staircase_ps``: what the old ``coherence_delay`` returned (Newton on the RTS's own,
  quantised, model) minus the continuous coherence point;
* ``fit_ps``: the calibration's fitted optimum (``calibrate_pair``, phasor sweep) minus the
  continuous coherence point (``coherence_point``);
* ``chosen_vs_nearest_ps``: the delay it sets minus the realisable one nearest the point;
* ``residual_deg``: the full-chain probe-angle error at the chosen delay.

Writes ``benchmarks/calibration_resolution.json`` and ``.csv``; prints one line per case.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

from benchmarks._io import write_json_csv

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_SCENE = ROOT / "scenes" / "diewald2022.toml"
PAIR = (0, 1)


def scene(res_ps: float, radius_m: float, dr_mm: float):
    import tomllib
    from rtsgeom.scene import parse_scene
    doc = tomllib.loads(DEFAULT_SCENE.read_text())
    doc["radar"].pop("snr_db", None)
    rts = doc["rts"]
    rts["arc_radius_m"] = radius_m
    rts["fractional_delay"] = res_ps < 250.0
    rts["fractional_delay_step_s"] = res_ps * 1e-12 if res_ps < 250.0 else 1e-12
    rts["calibration_step_ps"] = max(25.0, res_ps)
    rts["front_ends"][1]["radial_offset_mm"] = dr_mm
    return parse_scene(doc, str(DEFAULT_SCENE))


def staircase_point(setup, paths, alphas, near_s: float) -> float:
    """The old ``coherence_delay``: Newton on the quantised model's phase (a staircase)."""
    from rtsgeom.calibration.probes import if_phase_slope_hz, probe_ranges, probe_total_delay
    from rtsgeom.synthesis.model import ChannelModel
    from rtsgeom.scene import TargetConfig
    ranges = probe_ranges(setup, 2)
    f_if = float(if_phase_slope_hz(setup.scene, probe_total_delay(setup, ranges)))

    def phase(d):
        z = sum(np.exp(1j * ChannelModel.build(setup, paths, PAIR, TargetConfig(float(r)),
                                               (0.0, d)).pair_phase(alphas)) for r in ranges)
        return float(np.angle(z))
    d = float(near_s)
    for _ in range(2):
        for _ in range(4):
            d += phase(d) / (2 * np.pi * f_if)
        d += np.round((near_s - d) * f_if) / f_if
    return d


def run(res_ps=(1, 5, 10, 25, 50, 100, 250), radii=(1.0, 3.0), offsets_mm=(0.0, 0.3, -0.6)):
    from rtsgeom.calibration.pair import calibrate_pair, pair_coherence
    from rtsgeom.calibration.probes import probe_angles, probe_front_ends
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    s1 = build_setup(scene(1.0, 1.0, 0.0))
    probe = probe_front_ends(s1, exact_paths(s1), 1)
    alphas = probe_angles(*probe.angle_rad[[0, 1]])
    rows = []
    for radius in radii:
        for dr in offsets_mm:
            for res in res_ps:
                setup = build_setup(scene(float(res), radius, dr))
                paths = exact_paths(setup)
                t0 = time.process_time()
                cal = calibrate_pair(setup, paths, PAIR, probe, seed=1)
                cpu = time.process_time() - t0
                cp = pair_coherence(setup, paths, PAIR, alphas=alphas, near_s=cal.delta_tau_s)
                row = {"resolution_ps": float(res), "radius_m": radius, "dr_mm": dr,
                       "coherence_ps": cp.continuous_s * 1e12,
                       "staircase_ps": (staircase_point(setup, paths, alphas, cp.continuous_s)
                                        - cp.continuous_s) * 1e12,
                       "fit_ps": (cal.delta_tau_s + cal.quantisation_residual_s
                                  - cp.continuous_s) * 1e12,
                       "chosen_vs_nearest_ps": (cal.delta_tau_s - cp.delta_tau_s) * 1e12,
                       "fine_points": int(cal.refine_delta_tau_s.size),
                       "residual_deg": float(cal.residual_error_deg), "cpu_s": cpu}
                rows.append(row)
                print(f"R {radius} m, dr {dr:+.1f} mm, {res:5.0f} ps: staircase "
                      f"{row['staircase_ps']:+7.2f} ps, fit {row['fit_ps']:+7.2f} ps, chosen - "
                      f"nearest {row['chosen_vs_nearest_ps']:+5.0f} ps, {row['fine_points']} "
                      f"points, residual {row['residual_deg']:.4f} deg", flush=True)
    return {"load": os.getloadavg(), "rows": rows}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "calibration_resolution"))
    a = ap.parse_args(argv)
    out = run()
    write_json_csv(a.out, out, out["rows"])
    for res in sorted({r["resolution_ps"] for r in out["rows"]}):
        sel = [r for r in out["rows"] if r["resolution_ps"] == res]
        print(f"{res:5.0f} ps: staircase max {max(abs(r['staircase_ps']) for r in sel):6.2f} "
              f"ps, fit max {max(abs(r['fit_ps']) for r in sel):6.2f} ps, chosen = nearest "
              f"{sum(r['chosen_vs_nearest_ps'] == 0 for r in sel)}/{len(sel)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
