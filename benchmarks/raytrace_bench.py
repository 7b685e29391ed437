"""Benchmark of the Sionna RT adapter on a scene: import, first solve (JIT), warm solve, memory.

Each measurement runs in a fresh process (imports and Dr.Jit's in-memory kernels are per
process); the first process compiles into an empty kernel cache ("cold"), the second reuses
it ("warm cache"). Within a process the first ``trace`` call includes the JIT compilation unless
the disk cache already holds the kernels, later calls are warm.

    python -m benchmarks.raytrace_bench                       # default scene, its [raytrace] settings
    python -m benchmarks.raytrace_bench --samples 100000 --depth 3 --repeat 5 --json out.json
    RTSGEOM_RAYTRACE_BACKEND=llvm python -m benchmarks.raytrace_bench   # CPU on a GPU machine

The variant that ran (``cuda_ad_mono_polarized`` on a GPU, else ``llvm_ad_mono_polarized``) is
reported; peak memory is the process's peak resident set size (host memory) and Dr.Jit's
allocation watermark of the backend that ran (device memory on CUDA).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_SCENE = ROOT / "scenes" / "diewald2022.toml"


def _rss_mib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # kB on Linux


def worker(scene_path: str, samples: int | None, depth: int | None, repeat: int) -> dict:
    """One process: import, then ``repeat`` full ``trace`` calls; times and memory as a dict."""
    t0 = time.perf_counter()
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import raytrace
    from rtsgeom.scene import load_scene
    t_rtsgeom = time.perf_counter() - t0
    setup = build_setup(load_scene(scene_path))
    _ = setup.sheet  # build the mesh outside the timed calls
    cfg = setup.scene.raytrace
    if samples is not None:
        cfg = cfg.evolve(samples_per_src=samples)
    if depth is not None:
        cfg = cfg.evolve(max_depth=depth)
    t0 = time.perf_counter()
    ok, msg = raytrace.preflight()
    t_pre = time.perf_counter() - t0
    if not ok:
        return {"ok": False, "error": msg}
    t0 = time.perf_counter()
    raytrace.ensure_available()
    t_import = time.perf_counter() - t0
    rss_import = _rss_mib()
    calls = []
    for _ in range(max(repeat, 1)):
        t0 = time.perf_counter()
        res = raytrace.trace(setup, cfg)
        calls.append({"total_s": time.perf_counter() - t0, **res.timings_s})
    out = {"ok": True, "variant": res.variant, "preflight_s": t_pre, "rtsgeom_import_s": t_rtsgeom,
           "sionna_import_s": t_import, "calls": calls, "rows": len(res.paths),
           "stats": res.stats, "rss_after_import_mib": rss_import, "peak_rss_mib": _rss_mib(),
           "samples_per_src": cfg.samples_per_src, "max_depth": cfg.max_depth,
           "cache_dir": os.environ.get("DRJIT_CACHE_DIR"), "threads": os.cpu_count()}
    out.update(raytrace.backend_info())  # variant, Dr.Jit threads and allocation peak
    return out


def _spawn(args, cache_dir: str) -> dict:
    env = dict(os.environ, DRJIT_CACHE_DIR=cache_dir)
    cmd = [sys.executable, "-m", "benchmarks.raytrace_bench", "--worker", "--scene", str(args.scene),
           "--repeat", str(args.repeat)]
    if args.samples is not None:
        cmd += ["--samples", str(args.samples)]
    if args.depth is not None:
        cmd += ["--depth", str(args.depth)]
    t0 = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=ROOT)
    wall = time.perf_counter() - t0
    if r.returncode != 0:
        return {"ok": False, "error": f"worker exit code {r.returncode}: {r.stderr.strip()[-500:]}"}
    out = json.loads(r.stdout.strip().splitlines()[-1])
    out["process_wall_s"] = wall
    return out


def _fmt(label: str, r: dict) -> str:
    if not r.get("ok"):
        return f"{label}: FAILED: {r.get('error')}"
    c = r["calls"]
    warm = [x["solve_s"] for x in c[1:]]
    return (f"{label}: {r['variant']}, {r['rows']} rows | preflight {r['preflight_s']:.2f} s, "
            f"import sionna {r['sionna_import_s']:.2f} s | first trace {c[0]['total_s']:.2f} s "
            f"(solve {c[0]['solve_s']:.2f} s, build {c[0]['build_s']:.2f} s) | warm solve "
            + (f"{min(warm):.3f}-{max(warm):.3f} s" if warm else "n/a")
            + f" | peak RSS {r['peak_rss_mib']:.0f} MiB"
            + (f", Dr.Jit peak {r['drjit_peak_mib']:.0f} MiB" if "drjit_peak_mib" in r else "")
            + f" | process {r.get('process_wall_s', 0):.1f} s")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.raytrace_bench", description=__doc__.split("\n")[0])
    ap.add_argument("--scene", type=Path, default=DEFAULT_SCENE)
    ap.add_argument("--samples", type=int, default=None, help="samples_per_src (default: the scene's)")
    ap.add_argument("--depth", type=int, default=None, help="max_depth (default: the scene's)")
    ap.add_argument("--repeat", type=int, default=3, help="trace calls per process (>= 2 for a warm solve)")
    ap.add_argument("--json", type=Path, default=None, help="also write the results as JSON")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:
        print(json.dumps(worker(str(args.scene), args.samples, args.depth, args.repeat)))
        return 0
    with tempfile.TemporaryDirectory(prefix="drjit_cache_") as cache:
        cold = _spawn(args, cache)
        warm = _spawn(args, cache)
    print(_fmt("cold kernel cache", cold))
    print(_fmt("warm kernel cache", warm))
    if args.json:
        args.json.write_text(json.dumps({"cold_cache": cold, "warm_cache": warm}, indent=2))
    return 0 if cold.get("ok") and warm.get("ok") else 1


if __name__ == "__main__":
    sys.exit(main())
