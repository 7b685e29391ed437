"""``python -m benchmarks``: performance of the heavy stages and of every command, as absolute
times (wall and CPU) and as ratios to a reference measured in the same run, so a noisy machine
matters less. Not part of the test suite.

* Every command (``commands``): the simulation phase of ``run`` (``run_scene`` on
  the default scene), one full-chain frame (synthesis + range-Doppler + CFAR + angle),
  ``calibrate --pair 0 1``, ``adc --format dca1000``, ``design`` (default grid; also with
  ``--workers 2``, and its CPU split into model builds and tolerance searches),
  ``nearfield``, ``tolerance`` (1e6 draws x 21 set-points; 1e5 with ``--quick``; also with
  ``--workers 2``, forked processes, and on a warm Dask LocalCluster of 1 and 2 workers),
  ``info`` and ``--help``. Each: wall time, CPU time (this
  process's ``time.process_time`` in process, the child's user + system time for a
  subprocess) and wall / reference, the reference being the per-echo ADC synthesis
  (``synthesize_exact``) of the default scene timed in the same run: a machine-speed unit.
  ``--help`` and ``info`` are also compared with importing every command group (what the CLI
  did before it imported lazily).

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
    from rtsgeom.pipeline.run import run_scene
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
    from rtsgeom.analysis.tolerance.phasors import ChannelPhasors
    from rtsgeom.analysis.tolerance.montecarlo import monte_carlo
    from rtsgeom.geometry import build_setup
    from rtsgeom.scene import load_scene
    model = ChannelPhasors.build(build_setup(load_scene(scene_path)), (0, 1), points=21)
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


def _cpu_children() -> float:
    import resource
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _time_cli(args: list[str], repeat: int = 1, python_args: tuple = ()) -> dict:
    """Best wall time of ``python -m rtsgeom ARGS`` in a subprocess, and its CPU time."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    best = {"wall_s": np.inf, "cpu_s": np.inf}
    for _ in range(repeat):
        c0, t0 = _cpu_children(), time.perf_counter()
        r = subprocess.run([sys.executable, *python_args, "-m", "rtsgeom", *args], cwd=ROOT,
                           env=env, capture_output=True, text=True)
        wall, cpu = time.perf_counter() - t0, _cpu_children() - c0
        if r.returncode != 0:
            return {"failed": f"exit {r.returncode}: {r.stderr.strip()[-300:]}"}
        best = {"wall_s": min(best["wall_s"], wall), "cpu_s": min(best["cpu_s"], cpu)}
    return best


def _time_python(code: str, repeat: int = 1) -> dict:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    best = {"wall_s": np.inf, "cpu_s": np.inf}
    for _ in range(repeat):
        c0, t0 = _cpu_children(), time.perf_counter()
        subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, check=True)
        best = {"wall_s": min(best["wall_s"], time.perf_counter() - t0),
                "cpu_s": min(best["cpu_s"], _cpu_children() - c0)}
    return best


def _time_inproc(f, repeat: int = 1) -> tuple[dict, object]:
    best, out = {"wall_s": np.inf, "cpu_s": np.inf}, None
    for _ in range(repeat):
        c0, t0 = time.process_time(), time.perf_counter()
        out = f()
        best = {"wall_s": min(best["wall_s"], time.perf_counter() - t0),
                "cpu_s": min(best["cpu_s"], time.process_time() - c0)}
    return best, out


#: wall-time targets per command (quiet 2-core machine), seconds
TARGETS = {"run_simulation": 1.0, "frame": 0.030, "calibrate": 1.0, "adc_dca1000": 2.0,
           "design_default_grid": 5.0, "design_default_grid_2_workers": 5.0, "nearfield": 2.0,
           "tolerance": 20.0, "tolerance_2_workers": 20.0, "help": 0.5}


def bench_commands(scene_path: Path, quick: bool, repeat: int, workers: int) -> dict:
    """Every command: wall, CPU and wall / reference."""
    import tempfile
    from rtsgeom.radar.fmcw import synthesize, synthesize_exact
    from rtsgeom.radar.processing import cfar_mask, detect, range_doppler
    from rtsgeom.pipeline.run import run_scene
    from rtsgeom.scene import load_scene
    scene_arg = str(scene_path)
    scene = load_scene(scene_path)
    out: dict = {}
    t_sim, result = _time_inproc(lambda: run_scene(scene), 1 if quick else 2)
    out["run_simulation"] = t_sim
    ech, radar, rut = result.echoes, result.scene.radar, result.setup.rut
    ref, _ = _time_inproc(lambda: synthesize_exact(ech, radar, rut), max(1, repeat // 2))
    reference = {"what": "per-echo ADC synthesis (synthesize_exact) of the default scene, "
                         f"{len(ech)} echoes, exact paths", **ref}

    def frame():
        cube = synthesize(ech, radar, rut)
        rd = range_doppler(cube)
        return detect(rd, cube)
    out["frame"], _ = _time_inproc(frame, 5 * repeat)
    rd = range_doppler(result.cube)
    out["frame"]["parts"] = {
        "synthesis": _time_inproc(lambda: synthesize(ech, radar, rut), 5 * repeat)[0],
        "range_doppler": _time_inproc(lambda: range_doppler(result.cube), 5 * repeat)[0],
        "cfar": _time_inproc(lambda: cfar_mask(rd.power, radar.cfar), 5 * repeat)[0],
        "detect": _time_inproc(lambda: detect(rd, result.cube), 5 * repeat)[0]}
    out["help"] = _time_cli(["--help"], 3)
    out["help_all_groups_imported"] = _time_python(
        "from rtsgeom.cli import build_parser; build_parser()", 3)
    out["info"] = _time_cli(["info", scene_arg], 3)
    out["calibrate"] = _time_cli(["calibrate", scene_arg, "--pair", "0", "1", "--json",
                                  "--quiet"])
    with tempfile.TemporaryDirectory() as tmp:
        out["adc_dca1000"] = _time_cli(["adc", scene_arg, "--format", "dca1000", "--out",
                                        str(Path(tmp) / "adc.bin"), "--quiet"])
    design = ["design", scene_arg, "--json", "--quiet"]
    if quick:  # a 2 x 2 corner of the default 4 x 5 grid
        design += ["--radius-m", "0.5:2:2", "--spacing-deg", "4:20:2"]
    name = "design_default_grid" if not quick else "design_2x2"
    out[name] = _time_cli(design)
    out[name + "_2_workers"] = _time_cli(design + ["--workers", "2"])
    out[name + "_parts"] = bench_design_parts(scene, quick)
    out["nearfield"] = _time_cli(["nearfield", scene_arg, "--json", "--quiet"])
    draws = 100_000 if quick else 1_000_000
    tol = ["tolerance", scene_arg, "--pair", "0", "1", "--sigma-radial-mm", "0.1",
           "--sigma-tangential-mm", "0.1", "--sigma-height-mm", "0.1", "--seed", "1",
           "--json", "--quiet"]
    out["tolerance"] = {"draws": draws, **_time_cli(tol + ["--draws", str(draws)])}
    # "on one machine": both cores, the chunks in 2 forked worker processes (parallel.fork_map)
    out["tolerance_2_workers"] = {"draws": draws, **_time_cli(
        tol + ["--draws", str(draws), "--workers", "2"])}
    dask_draws = 100_000 if quick else 400_000
    out["tolerance_dask"] = bench_dask_scaling(scene_path, dask_draws, workers)
    for name, v in out.items():
        if isinstance(v, dict) and "wall_s" in v:
            v["over_reference"] = v["wall_s"] / reference["wall_s"]
            if name in TARGETS:
                v["target_s"] = TARGETS[name]
    out["reference"] = reference
    return out


def bench_design_parts(scene, quick: bool) -> dict:
    """What ``design`` spends its CPU on, design by design as ``evaluate_design`` does it: the
    pair model (``ChannelPhasors.build``) and the two tolerance searches
    (``max_sigma_for_yield``, uncalibrated and calibrated: Monte Carlos of 2000 draws x 21
    set-points each, counted)."""
    import math
    from rtsgeom.analysis.design import two_front_end_scene
    from rtsgeom.analysis.tolerance.phasors import CASES, ChannelPhasors
    from rtsgeom.analysis.tolerance.config import MonteCarlo
    from rtsgeom.analysis.tolerance.search import max_sigma_for_yield
    from rtsgeom.geometry import build_setup
    radii = np.linspace(0.5, 2.0, 2 if quick else 4)
    spacings = np.linspace(4.0, 20.0, 2 if quick else 5)
    cpu = {"build_s": 0.0, **{f"tolerance_{c}_s": 0.0 for c in CASES}}
    evaluations, designs = 0, 0
    c_all = time.process_time()
    for sp in spacings:
        for r in radii:
            variant, _, problem = two_front_end_scene(scene, (0, 1), float(r), math.radians(sp))
            if problem is not None:
                continue
            setup = build_setup(variant)
            c0 = time.process_time()
            try:
                model = ChannelPhasors.build(setup, (0, 1), 21)
            except ValueError:
                continue
            cpu["build_s"] += time.process_time() - c0
            designs += 1
            for case in CASES:
                c0 = time.process_time()
                res = max_sigma_for_yield(model, [1e-4] * 3,
                                          MonteCarlo(draws=2000, seed=scene.seed), 0.95, 0.1,
                                          case, rel_tol=0.02)
                cpu[f"tolerance_{case}_s"] += time.process_time() - c0
                evaluations += len(res["evaluations"])
    total = time.process_time() - c_all
    tol = sum(cpu[f"tolerance_{c}_s"] for c in CASES)
    return {**cpu, "designs": designs, "total_cpu_s": total, "tolerance_share": tol / total,
            "monte_carlos": evaluations, "cpu_s_per_monte_carlo": tol / max(evaluations, 1)}


def bench_dask_scaling(scene_path: Path, draws: int, workers: int) -> dict:
    """Tolerance draws on a warm LocalCluster of 1 and of ``workers`` single-threaded worker
    processes (cluster start and a first study of 40 000 draws excluded, which also ships the
    model to the workers, once per client: the scaling of the study itself).
    (The CLI's ``--workers N`` forks a process pool instead, with no cluster to start; ``--dask
    ADDRESS`` runs on a cluster like this one, sent per chunk the draw streams' states.)"""
    from rtsgeom.analysis.tolerance.phasors import ChannelPhasors
    from rtsgeom.analysis.tolerance.montecarlo import monte_carlo
    from rtsgeom.geometry import build_setup
    from rtsgeom._lib.parallel import dask_client, map_chunks
    from rtsgeom.scene import load_scene
    model = ChannelPhasors.build(build_setup(load_scene(scene_path)), (0, 1), points=21)
    sigma = [1e-4, 1e-4, 1e-4]
    out = {"draws": draws, "workers": workers}
    p95 = {}
    for n in (1, workers):
        with dask_client(workers=n) as client:
            def mapper(func, chunks):
                return map_chunks(func, chunks, client)
            t0 = time.perf_counter()
            monte_carlo(model, sigma, 4 * 10_000, 0, mapper=mapper)  # warm: imports, model
            first = time.perf_counter() - t0  # (the model is shipped once per client)
            c0, t0 = time.process_time(), time.perf_counter()
            res = monte_carlo(model, sigma, draws, 0, mapper=mapper)
            out[f"{n}_workers"] = {"wall_s": time.perf_counter() - t0,
                                   "client_cpu_s": time.process_time() - c0,
                                   "warm_up_40k_draws_wall_s": first}
            p95[n] = res.worst_error_deg["calibrated"]
    out["speedup"] = out["1_workers"]["wall_s"] / out[f"{workers}_workers"]["wall_s"]
    out["bit_identical"] = bool(np.array_equal(p95[1], p95[workers]))
    return out


def _print_commands(cmds: dict) -> None:
    ref = cmds["reference"]
    print(f"commands (reference: {ref['what']}: {ref['wall_s']:.3f} s wall, "
          f"{ref['cpu_s']:.3f} s CPU)")
    print(f"  {'what':28s} {'wall':>10s} {'CPU':>10s} {'/ ref':>8s} {'target':>8s}")
    for name, v in cmds.items():
        if name == "reference" or not isinstance(v, dict):
            continue
        if "failed" in v:
            print(f"  {name:28s} failed: {v['failed']}")
            continue
        if "wall_s" not in v:
            continue
        tgt = f"{v['target_s']:.3g} s" if "target_s" in v else ""
        print(f"  {name:28s} {v['wall_s']:9.3f}s {v['cpu_s']:9.3f}s {v['over_reference']:8.3f} "
              f"{tgt:>8s}")
    for name, v in cmds.items():
        if name.endswith("_parts"):
            print(f"  {name}: {v['designs']} designs, {v['total_cpu_s']:.2f} s CPU: model "
                  f"builds {v['build_s']:.2f} s, tolerance searches {v['tolerance_share']:.0%} "
                  f"({v['monte_carlos']} Monte Carlos, {v['cpu_s_per_monte_carlo'] * 1e3:.1f} ms "
                  "each)")
    d = cmds["tolerance_dask"]
    print(f"  tolerance {d['draws']} draws on a warm LocalCluster: 1 worker "
          f"{d['1_workers']['wall_s']:.2f} s, {d['workers']} workers "
          f"{d[str(d['workers']) + '_workers']['wall_s']:.2f} s: {d['speedup']:.2f}x "
          f"(results bit-identical: {d['bit_identical']})")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks", description=__doc__.split("\n")[0])
    ap.add_argument("--scene", type=Path, default=DEFAULT_SCENE)
    ap.add_argument("--draws", type=int, default=100_000, help="tolerance draws (default 1e5)")
    ap.add_argument("--repeat", type=int, default=5, help="timing repeats (best of)")
    ap.add_argument("--skip", nargs="*", default=[],
                    choices=["synthesis", "tolerance", "raytrace", "commands"])
    ap.add_argument("--quick", action="store_true",
                    help="fewer repeats and draws, a 2 x 2 design grid, no ray tracing")
    ap.add_argument("--workers", type=int, default=2, help="Dask workers to compare with one")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results.json")
    args = ap.parse_args(argv)
    if args.quick:
        args.repeat = min(args.repeat, 2)
        args.draws = min(args.draws, 20_000)
        args.skip = sorted(set(args.skip) | {"raytrace"})

    results = {"machine": {"cpus": os.cpu_count(), "python": platform.python_version(),
                           "numpy": np.__version__, "platform": platform.platform(),
                           "load_average_before": list(os.getloadavg())},
               "quick": bool(args.quick)}
    rt_ok = "raytrace" not in args.skip
    if "raytrace" not in args.skip:
        results["raytrace"] = bench_raytrace(args.scene)
        rt_ok = "skipped" not in results["raytrace"]
    if "synthesis" not in args.skip:
        results["synthesis"] = bench_synthesis(args.scene, "raytrace" if rt_ok else "exact",
                                               args.repeat)
    if "tolerance" not in args.skip:
        results["tolerance"] = bench_tolerance(args.scene, args.draws)
    if "commands" not in args.skip:
        results["commands"] = bench_commands(args.scene, args.quick, args.repeat, args.workers)
    results["machine"]["load_average_after"] = list(os.getloadavg())

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
    if "commands" in results:
        _print_commands(results["commands"])
    m = results["machine"]
    print(f"load average before/after: {m['load_average_before'][0]:.1f} / "
          f"{m['load_average_after'][0]:.1f} on {m['cpus']} CPUs")
    from rtsgeom._lib.io import write_json
    write_json(args.out, results)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
