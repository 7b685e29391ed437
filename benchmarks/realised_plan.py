"""``python -m benchmarks.realised_plan``: targets planned on realised delays (``aoa.plan.plan_pair``).

Delay resolutions 1 / 25 / 50 / 100 ps x f_s 4 and 3 GSPS (1/f_s = 250 and 333.3 ps) x set
angles 4.5 / 7 / 9.5 / 11.5 deg x 14 ranges from 8.3 to 70.1 m (several bins, ambiguous ones
among them), the default scene with a 35 deg phase offset and a 0.3 mm radial offset on
front end 1 (what the calibration absorbs): probe, calibrate and plan (``plan_targets``, the
run's planner), then each target's angle on the phasor model of the setup as built. Per
case: the largest |angle error|, the largest |quantisation_residual_s| of J's realised delay
difference and the run warnings about it. Writes ``benchmarks/realised_plan.json`` (before
the fix the same run gave max 0.16 / 0.11 deg at 100 ps: CHANGELOG).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from benchmarks._io import write_json

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_SCENE = ROOT / "scenes" / "diewald2022.toml"
RES_PS = (1.0, 25.0, 50.0, 100.0)
F_S = (4e9, 3e9)
ANGLES_DEG = (4.5, 7.0, 9.5, 11.5)
RANGES_M = tuple(float(r) for r in np.round(np.linspace(8.3, 70.1, 14), 2))


def scene(res_ps: float, f_s: float, angle_deg: float):
    import tomllib
    from rtsgeom.scene import parse_scene
    doc = tomllib.loads(DEFAULT_SCENE.read_text())
    rts = doc["rts"]
    rts["fractional_delay_step_s"] = res_ps * 1e-12
    rts["f_s_hz"] = f_s
    rts["calibration_step_ps"] = max(25.0, res_ps)
    rts["front_ends"][1]["phase_offset_deg"] = 35.0
    rts["front_ends"][1]["radial_offset_mm"] = 0.3
    doc["targets"] = [{"range_m": r, "velocity_mps": 0.0, "angle_deg": angle_deg,
                       "rcs_dbsm": 10.0} for r in RANGES_M]
    return parse_scene(doc, "realised_plan.toml")


def angle_errors_deg(setup, paths, program) -> np.ndarray:
    """Each target's detected minus set angle on the phasor model of the setup as built."""
    from rtsgeom.synthesis.model import ChannelModel
    from rtsgeom.rts.channels import requested_delay
    out = []
    for k, t in enumerate(setup.scene.targets):
        rows = np.flatnonzero(program.target == k)
        tau = float(requested_delay(setup.scene, t.range_m))
        m = ChannelModel.build(setup, paths, program.front_end[rows], t,
                               program.delay_s[rows] - tau, 3)
        out.append(np.degrees(float(m.direction(program.amplitude[rows])) - t.angle_rad))
    return np.array(out)


def main() -> None:
    from rtsgeom.pipeline.plan import plan_targets
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    rows = []
    for f_s in F_S:
        for res in RES_PS:
            t0 = time.process_time()
            err, resid, warns = [], [], 0
            for ang in ANGLES_DEG:
                setup = build_setup(scene(res, f_s, ang))
                paths = exact_paths(setup)
                program, record, warnings = plan_targets(setup, paths, "exact")
                err.extend(angle_errors_deg(setup, paths, program))
                resid.extend(t["quantisation_residual_s"] for t in record.get("targets", []))
                warns += sum("realised delay" in w for w in warnings)
            row = {"f_s_hz": f_s, "resolution_ps": res, "targets": len(err),
                   "max_abs_error_deg": float(np.max(np.abs(err))),
                   "max_abs_residual_ps": float(np.max(np.abs(resid)) * 1e12) if resid else None,
                   "warnings": warns, "cpu_s": time.process_time() - t0}
            rows.append(row)
            print(f"f_s {f_s / 1e9:g} GSPS, {res:g} ps: max |error| "
                  f"{row['max_abs_error_deg']:.4f} deg over {len(err)} targets, max |residual| "
                  f"{row['max_abs_residual_ps'] or 0:.1f} ps, {warns} warnings", flush=True)
    write_json(ROOT / "benchmarks" / "realised_plan.json", rows)


if __name__ == "__main__":
    main()
