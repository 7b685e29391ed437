"""``python -m benchmarks.cell_calibration``: the 2-D cell's channel calibration on sphere4.

Front end 1 of ``scenes/sphere4.toml`` (azimuth 3.4 deg, elevation +5 deg) with a radial
offset of 0 / 0.2 / 0.5 / 1.0 mm or a hardware phase offset of 90 / 180 deg; for each,
``run_scene`` (the calibration tree of pair sweeps, ``aoa.ncal``, then the targets):

* ``pairs``: each measured pair's calibrated delay, the continuous coherence point on the
  setup as built (``ncal.coherence_point_nd``, nearest the calibrated delay) and their
  difference ``error_ps``;
* ``loop_closure_ps`` and the calibration's ``warnings`` (closures beyond
  ``ncal.LOOP_CLOSURE_TOL_S``, failed pairs);
* ``az_err_deg`` / ``el_err_deg``: the run's detected angle errors of the four targets
  (sphere4's cell spec: |error| <= 0.03 deg), or ``error`` where the run stopped.

Writes ``benchmarks/cell_calibration.json``; prints one line per case. ``--quick``: the
0.5 mm and 90 deg cases only.
"""

from __future__ import annotations

import argparse
import copy
import time
import tomllib
from pathlib import Path

import numpy as np

from benchmarks._io import write_json

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "scenes" / "sphere4.toml"
CASES = [("radial_offset_mm", v) for v in (0.0, 0.2, 0.5, 1.0)] + [
    ("phase_offset_deg", v) for v in (90.0, 180.0)]
SPEC_DEG = 0.03


def sphere4(field: str | None = None, value: float = 0.0, fe: int = 1):
    """sphere4 with ``field = value`` on front end ``fe``."""
    from rtsgeom.scene import parse_scene
    doc = tomllib.loads(SCENE.read_text())
    doc = copy.deepcopy(doc)
    if field is not None:
        doc["rts"]["front_ends"][fe][field] = value
    return parse_scene(doc, str(SCENE))


def case(field: str, value: float) -> dict:
    from rtsgeom.calibration.probes import probe_front_ends
    from rtsgeom.calibration.pair import pair_coherence
    from rtsgeom.errors import SceneError
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.pipeline.run import run_scene
    scene = sphere4(field, value)
    out = {"field": field, "value": value}
    t0 = time.process_time()
    try:
        r = run_scene(scene)
    except SceneError as exc:
        out["error"] = str(exc)
        return out
    cal = r.calibration["channels"]
    setup = build_setup(scene)
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, scene.seed)
    rows = []
    for p in cal["pairs"]:
        cp = pair_coherence(setup, paths, tuple(p["pair"]), probe,
                            near_s=p["delta_tau_s"]).continuous_s
        rows.append({"pair": p["pair"], "delta_tau_ps": p["delta_tau_s"] * 1e12,
                     "coherence_ps": cp * 1e12, "error_ps": (p["delta_tau_s"] - cp) * 1e12})
    out.update(pairs=rows, loop_closure_ps=[x * 1e12 for x in cal["loop_closure_s"]],
               warnings=cal.get("warnings", []),
               az_err_deg=[m["error"]["angle_deg"] if m.get("error") else None
                           for m in r.matches],
               el_err_deg=[m["error"].get("elevation_deg") if m.get("error") else None
                           for m in r.matches],
               cpu_s=time.process_time() - t0)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "cell_calibration"))
    a = ap.parse_args(argv)
    cases = [c for c in CASES if not a.quick or c[1] in (0.5, 90.0)]
    res = []
    for f, v in cases:
        o = case(f, v)
        res.append(o)
        if "error" in o:
            print(f"{f}={v:g}: run failed: {o['error']}", flush=True)
            continue
        worst = max(abs(x) for x in o["az_err_deg"] + o["el_err_deg"] if x is not None)
        print(f"{f}={v:g}: pair errors (ps) "
              + ", ".join(f"{tuple(p['pair'])} {p['error_ps']:+.1f}" for p in o["pairs"])
              + f"; closures {np.round(o['loop_closure_ps'], 1).tolist()} ps; worst angle "
              f"error {worst:.4f} deg ({'within' if worst <= SPEC_DEG else 'BEYOND'} spec); "
              f"{len(o['warnings'])} warnings; {o['cpu_s']:.0f} s CPU", flush=True)
    write_json(a.out + ".json", res, default=float)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
