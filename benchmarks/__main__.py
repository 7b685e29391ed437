"""``python -m benchmarks``: performance of the heavy stages, as ratios so a noisy machine does
not matter. Not part of the test suite.

* ADC-cube synthesis of the default scene (targets on two channels each, cable ghosts and, when
  Sionna RT works here, the ray-traced reflections): the batched-GEMM path against the
  per-echo reference (``radar.fmcw.synthesize_exact``: one ``exp`` over the full cube per echo,
  the yardstick) and against the time to write the cube once (the memory floor).
* Monte-Carlo tolerance draws per second (phasor level, 21 set-points per draw).
* One Sionna RT solve of the default scene (first, with kernel compilation, and warm).
* Peak memory of each (tracemalloc for numpy; peak RSS of the ray-tracing process).

Prints a table and writes ``benchmarks/results.json``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time
import tracemalloc
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_SCENE = ROOT / "scenes" / "diewald2022.toml"


def _best(f, repeat: int) -> tuple[float, object]:
    best, out = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = f()
        best = min(best, time.perf_counter() - t0)
    return best, out


def _peak_mib(f) -> float:
    tracemalloc.start()
    try:
        f()
        return tracemalloc.get_traced_memory()[1] / 2 ** 20
    finally:
        tracemalloc.stop()


def bench_synthesis(scene_path: Path, paths_method: str, repeat: int) -> dict:
    from rtsgeom.radar.fmcw import synthesize, synthesize_exact
    from rtsgeom.run import run_scene
    from rtsgeom.scene import load_scene
    result = run_scene(load_scene(scene_path), paths_method)
    ech, radar, rut = result.echoes, result.scene.radar, result.setup.rut
    t_fast, fast = _best(lambda: synthesize(ech, radar, rut), repeat)
    t_ref, ref = _best(lambda: synthesize_exact(ech, radar, rut), max(1, repeat // 3))
    shape = fast.data.shape

    def write_once():
        out = np.empty(shape, np.complex64)
        out[...] = 1.0
        return out
    t_floor, _ = _best(write_once, repeat)
    err = float(np.max(np.abs(fast.data - ref.data)) / np.max(np.abs(ref.data)))
    echo_samples = len(ech) * fast.data.size
    return {
        "paths": result.paths.method, "echoes": len(ech), "cube_shape": list(shape),
        "fast_s": t_fast, "reference_s": t_ref, "write_floor_s": t_floor,
        "fast_echo_samples_per_s": echo_samples / t_fast,
        "reference_echo_samples_per_s": echo_samples / t_ref,
        "speedup_vs_reference": t_ref / t_fast, "fast_over_write_floor": t_fast / t_floor,
        "max_rel_difference": err,
        "fast_peak_mib": _peak_mib(lambda: synthesize(ech, radar, rut)),
        "reference_peak_mib": _peak_mib(lambda: synthesize_exact(ech, radar, rut)),
    }


def bench_tolerance(scene_path: Path, draws: int) -> dict:
    """Monte-Carlo tolerance draws (phasor level, 21 set-points, uncalibrated + calibrated)."""
    from rtsgeom.analysis.tolerance import PairPhasors, monte_carlo
    from rtsgeom.geometry import build_setup
    from rtsgeom.scene import load_scene
    model = PairPhasors.build(build_setup(load_scene(scene_path)), (0, 1), points=21)
    sigma = [1e-4, 1e-4, 1e-4]
    monte_carlo(model, sigma, 1000, 0)  # warm-up
    t0 = time.perf_counter()
    res = monte_carlo(model, sigma, draws, 0)
    wall = time.perf_counter() - t0
    peak = _peak_mib(lambda: monte_carlo(model, sigma, min(draws, 20_000), 0))
    return {"draws": draws, "set_points": int(model.set_rad.size), "wall_s": wall,
            "draws_per_s": draws / wall, "peak_mib_per_20k_draws": peak,
            "p95_calibrated_deg": float(res.stats("calibrated")["angle_error_deg"]["p95"])}


def bench_raytrace(scene_path: Path) -> dict:
    cmd = [sys.executable, "-m", "benchmarks.raytrace_bench", "--worker", "--scene",
           str(scene_path), "--repeat", "3"]
    t0 = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)
    if r.returncode != 0:
        return {"skipped": f"ray tracing failed: {r.stderr.strip()[-300:]}"}
    out = json.loads(r.stdout.strip().splitlines()[-1])
    if not out.get("ok"):
        return {"skipped": out.get("error", "ray tracing unavailable")}
    calls = out["calls"]
    return {"variant": out["variant"], "rows": out["rows"], "first_solve_s": calls[0]["solve_s"],
            "warm_solve_s": min(c["solve_s"] for c in calls[1:]),
            "first_trace_total_s": calls[0]["total_s"], "peak_rss_mib": out["peak_rss_mib"],
            "process_wall_s": time.perf_counter() - t0}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks", description=__doc__.split("\n")[0])
    ap.add_argument("--scene", type=Path, default=DEFAULT_SCENE)
    ap.add_argument("--draws", type=int, default=100_000, help="tolerance draws (default 1e5)")
    ap.add_argument("--repeat", type=int, default=5, help="timing repeats (best of)")
    ap.add_argument("--skip", nargs="*", default=[], choices=["synthesis", "tolerance", "raytrace"])
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results.json")
    args = ap.parse_args(argv)

    results = {"machine": {"cpus": os.cpu_count(), "python": platform.python_version(),
                           "numpy": np.__version__, "platform": platform.platform()}}
    rt_ok = "raytrace" not in args.skip
    if "raytrace" not in args.skip:
        results["raytrace"] = bench_raytrace(args.scene)
        rt_ok = "skipped" not in results["raytrace"]
    if "synthesis" not in args.skip:
        results["synthesis"] = bench_synthesis(args.scene, "raytrace" if rt_ok else "exact",
                                               args.repeat)
    if "tolerance" not in args.skip:
        results["tolerance"] = bench_tolerance(args.scene, args.draws)

    print("benchmark                     result")
    s = results.get("synthesis")
    if s:
        print(f"ADC synthesis ({s['echoes']} echoes, {s['paths']} paths, cube {s['cube_shape']}):")
        print(f"  fast (GEMM)                 {s['fast_s'] * 1e3:9.2f} ms  "
              f"{s['fast_echo_samples_per_s'] / 1e9:7.2f} G echo-samples/s  peak {s['fast_peak_mib']:.1f} MiB")
        print(f"  per-echo reference          {s['reference_s'] * 1e3:9.2f} ms  "
              f"{s['reference_echo_samples_per_s'] / 1e9:7.2f} G echo-samples/s  peak {s['reference_peak_mib']:.1f} MiB")
        print(f"  write the cube once         {s['write_floor_s'] * 1e3:9.2f} ms")
        print(f"  speed-up vs reference       {s['speedup_vs_reference']:9.1f} x   "
              f"fast / write floor {s['fast_over_write_floor']:.1f} x   "
              f"max rel. difference {s['max_rel_difference']:.1e}")
    t = results.get("tolerance")
    if t:
        if "skipped" in t:
            print(f"tolerance: skipped ({t['skipped']})")
        else:
            print(f"tolerance ({t['draws']} draws x {t['set_points']} set-points): "
                  f"{t['wall_s']:.2f} s, {t['draws_per_s']:.0f} draws/s, peak "
                  f"{t['peak_mib_per_20k_draws']:.0f} MiB per 20k draws")
    r = results.get("raytrace")
    if r:
        if "skipped" in r:
            print(f"ray tracing: skipped ({r['skipped']})")
        else:
            print(f"ray tracing ({r['variant']}, {r['rows']} rows): first solve "
                  f"{r['first_solve_s']:.2f} s, warm {r['warm_solve_s']:.3f} s, peak RSS "
                  f"{r['peak_rss_mib']:.0f} MiB")
    from rtsgeom.io import write_json
    write_json(args.out, results)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
