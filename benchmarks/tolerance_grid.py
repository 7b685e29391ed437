"""``python -m benchmarks.tolerance_grid [--draws N] [--verify N]``: the mounting-tolerance study
across arc radii and the target's sub-bin position.

For R_c = 0.5, 1 and 3 m (the default scene otherwise, pair (0, 1), 21 set-points, 0.1 mm
sigma on every axis, seed 1), with the target at the range-bin centre (the study's earlier
model) and at a sub-bin position drawn per draw (uniform over one bin), report per case the worst
|error| p50/p95/p99/max and the yield within 0.1 deg; the calibrated sigma that keeps 95 % of
the setups within 0.1 deg (all axes scaled together, and the radial axis alone); the
calibrated p99 per sub-bin band (|offset| in tenths of a bin); and the largest difference of
the fast model from the ADC-cube chain on the first ``--verify`` draws.

Writes ``benchmarks/tolerance_grid.json`` and ``.csv``; prints a table.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from benchmarks._io import write_json_csv

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_SCENE = ROOT / "scenes" / "diewald2022.toml"
RADII_M = (0.5, 1.0, 3.0)
SIGMA_M = 1e-4
SEED = 1
SPEC_DEG = 0.1


def _scene(radius_m: float):
    from rtsgeom.scene import load_scene
    scene = load_scene(DEFAULT_SCENE)
    return scene.evolve(rts=scene.rts.evolve(arc_radius_m=radius_m))


def run(draws: int, verify: int, inversion_draws: int) -> list[dict]:
    from rtsgeom.analysis.tolerance.phasors import ChannelPhasors
    from rtsgeom.analysis.tolerance.search import max_sigma_for_yield
    from rtsgeom.analysis.tolerance.montecarlo import monte_carlo
    from rtsgeom.analysis.tolerance.config import MonteCarlo
    from rtsgeom.analysis.tolerance.verify import verify_draws
    from rtsgeom.geometry import build_setup
    rows = []
    for radius in RADII_M:
        t0 = time.process_time()
        model = ChannelPhasors.build(build_setup(_scene(radius)), (0, 1))
        build_s = time.process_time() - t0
        for subbin in (False, True):
            t0 = time.process_time()
            res = monte_carlo(model, [SIGMA_M] * 3, draws, SEED, spec_deg=SPEC_DEG,
                              subbin=subbin)
            mc_s = time.process_time() - t0
            row = {"radius_m": radius, "subbin": "drawn" if subbin else "bin centre",
                   "draws": draws, "sigma_mm": SIGMA_M * 1e3, "build_cpu_s": build_s,
                   "monte_carlo_cpu_s": mc_s}
            for case in ("uncalibrated", "calibrated"):
                st = res.stats(case)
                for k, v in st["angle_error_deg"].items():
                    row[f"{case}_{k}_deg"] = v
                row[f"{case}_yield"] = st["yield"]
            for axis in ("all", "radial"):
                base = [SIGMA_M] * 3 if axis == "all" else [0.0, 0.0, 0.0]
                inv = _inversion(max_sigma_for_yield, model, base, inversion_draws, axis,
                                 subbin)
                row[f"calibrated_sigma95_{axis}_mm"] = inv["sigma_mm"]["radial"]
                row[f"calibrated_sigma95_{axis}_capped"] = inv["capped"]
            if subbin:
                u = np.abs(res.subbin_steps) / model.subbin_steps.size  # |offset| in bins
                e = np.abs(res.worst_error_deg["calibrated"])
                for b in range(5):
                    sel = (u >= b / 10) & (u < (b + 1) / 10 + (b == 4))
                    row[f"calibrated_p99_offset_{b / 10:.1f}_{(b + 1) / 10:.1f}_bin_deg"] = (
                        float(np.percentile(e[sel], 99)) if sel.any() else None)
                if verify:
                    v = verify_draws(model, [SIGMA_M] * 3, MonteCarlo(draws=verify, seed=SEED))
                    row["verify_draws"] = verify
                    row["verify_max_abs_difference_deg"] = v.max_difference_deg
            rows.append(row)
            print(json.dumps(row), flush=True)
    return rows


def _inversion(max_sigma_for_yield, model, base, draws, axis, subbin):
    from rtsgeom.analysis.tolerance.config import MonteCarlo
    return max_sigma_for_yield(model, base, MonteCarlo(draws=draws, seed=SEED, subbin=subbin),
                               0.95, SPEC_DEG, "calibrated", axis)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m benchmarks.tolerance_grid", description=__doc__)
    p.add_argument("--draws", type=int, default=100_000)
    p.add_argument("--inversion-draws", type=int, default=20_000)
    p.add_argument("--verify", type=int, default=20)
    a = p.parse_args(argv)
    rows = run(a.draws, a.verify, a.inversion_draws)
    out = ROOT / "benchmarks" / "tolerance_grid"
    write_json_csv(out, rows, rows, newline=True, fieldnames=sorted({k for r in rows for k in r}))
    print(f"{'R_c m':>6} {'sub-bin':>10} {'cal p99':>8} {'cal max':>8} {'cal yield':>9} "
          f"{'sig95 all':>9} {'sig95 rad':>9}")
    for r in rows:
        print(f"{r['radius_m']:6.2g} {r['subbin']:>10} {r['calibrated_p99_deg']:8.4f} "
              f"{r['calibrated_max_deg']:8.4f} {100 * r['calibrated_yield']:8.2f}% "
              f"{r['calibrated_sigma95_all_mm']:9.4g} {r['calibrated_sigma95_radial_mm']:9.4g}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
