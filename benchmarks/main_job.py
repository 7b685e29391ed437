"""``python -m benchmarks.main_job [--repeat 3] [--against DIR]``: how long the README's first
command takes, ``rtsgeom run scenes/diewald2022.toml --out DIR``, with its report and with
``--no-report``, as whole processes (wall, user + system CPU of the process and its forked
children, the median of ``--repeat``), with the machine's load average before each run.

``--against DIR``: also time another checkout of rtsgeom (e.g. ``git worktree add DIR
COMMIT``), its runs interleaved with this tree's (A, B, A, B, ...) so that both see the same
load on a shared machine, and check that both wrote the same ``summary.json``,
``detections.csv`` and ``maps.npz``. Writes ``benchmarks/main_job.json``. Not part of the test
suite.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from benchmarks._io import write_json

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "scenes" / "diewald2022.toml"
COMPARED = ("summary.json", "detections.csv", "maps.npz")


def timed(argv: list[str], root: Path) -> dict:
    """One whole process ``python -m rtsgeom argv`` importing rtsgeom from ``root``
    (run in ``root``: ``python -m`` puts the working directory first on the path): wall,
    user and system CPU (s, its forked children included), load average before."""
    load = os.getloadavg()[0]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "rtsgeom", *argv], capture_output=True,
                          text=True, cwd=root, env={**os.environ, "PYTHONPATH": str(root)})
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode:
        raise SystemExit(f"{root}: rtsgeom {' '.join(argv)}: exit {proc.returncode}: "
                         f"{proc.stderr[-2000:]}")
    user, system = after.ru_utime - before.ru_utime, after.ru_stime - before.ru_stime
    return {"wall_s": wall, "user_s": user, "cpu_s": user + system, "load_before": load}


def summary(runs: list[dict]) -> dict:
    return {f"median_{k}": statistics.median(r[k] for r in runs)
            for k in ("wall_s", "user_s", "cpu_s", "load_before")} | {"runs": runs}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--against", default=None, metavar="DIR")
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "main_job.json"))
    args = ap.parse_args(argv)
    trees = {"this": ROOT} | ({"against": Path(args.against).resolve()} if args.against else {})
    cases = {"run": [], "run --no-report": ["--no-report"]}
    rows = {t: {c: [] for c in cases} for t in trees}
    with tempfile.TemporaryDirectory() as tmp:
        for case, extra in cases.items():
            for r in range(args.repeat):
                for tree, root in trees.items():
                    out = Path(tmp) / f"{tree}-{case.replace(' ', '')}-{r}"
                    rows[tree][case].append(timed(["run", str(SCENE), "--out", str(out),
                                                   "--quiet", *extra], root))
                    x = rows[tree][case][-1]
                    print(f"{tree} {case}: {x['wall_s']:.2f} s wall, {x['cpu_s']:.2f} s CPU "
                          f"(load {x['load_before']:.1f})", flush=True)
        same = {name: len({(p / name).read_bytes() for p in Path(tmp).iterdir()}) == 1
                for name in COMPARED}
    record = {"scene": "scenes/diewald2022.toml", "repeat": args.repeat,
              "cpus": os.cpu_count(), "trees": {t: str(p) for t, p in trees.items()},
              "outputs_identical": same,
              "commands": {t: {c: summary(v) for c, v in rows[t].items()} for t in trees}}
    write_json(args.out, record, newline=True)
    print(same)
    return 0 if all(same.values()) else 1


if __name__ == "__main__":
    raise SystemExit(main())
