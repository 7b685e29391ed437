"""``python -m benchmarks.main_job [--repeat 3] [--against DIR]``: how long the README's first
command takes, ``rtsgeom run scenes/diewald2022.toml --out DIR``, with its report and with
``--no-report``, as whole processes (wall, user + system CPU of the process and its forked
children, the median of ``--repeat``), with the machine's load average before each run.

The runs are timed as a user's Python makes them (its ``__pycache__`` written by a first,
untimed run) and, once more, as a Python that never writes bytecode
(``PYTHONDONTWRITEBYTECODE=1``, as this project's sandbox and some CI images set).

``--against DIR``: also time another checkout of rtsgeom (e.g. ``git worktree add DIR
COMMIT``), its runs interleaved with this tree's (A, B, A, B, ..., the cases in turn too) so that both see the same
load on a shared machine, and check that both wrote the same ``summary.json``,
``detections.csv`` and ``maps.npz``. Writes ``benchmarks/main_job.json``. Not part of the test
suite.
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
from pathlib import Path

from benchmarks._io import timed_rtsgeom, write_json

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "scenes" / "diewald2022.toml"
COMPARED = ("summary.json", "detections.csv", "maps.npz")



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
    # (extra arguments, bytecode): as a user's Python runs it, rtsgeom's modules compiled once
    # (a first run, untimed, writes their __pycache__), and as a Python that never writes
    # bytecode (PYTHONDONTWRITEBYTECODE=1: this sandbox, some CI images) compiles them at
    # every start (about 0.2 s of CPU in the run's process)
    cases = {"run": ([], True), "run --no-report": (["--no-report"], True),
             "run, no bytecode cache": ([], False)}
    rows = {t: {c: [] for c in cases} for t in trees}
    with tempfile.TemporaryDirectory() as tmp:
        for tree, root in trees.items():  # the first run: bytecode, caches (not timed)
            timed_rtsgeom(["run", str(SCENE), "--out", str(Path(tmp) / f"{tree}-first"), "--quiet"],
                  root, bytecode=True)
        # every case and tree in turn within each repeat (not case after case): a shared
        # machine's slow minute then falls on all of them alike
        for r in range(args.repeat):
            for case, (extra, bytecode) in cases.items():
                for tree, root in trees.items():
                    out = Path(tmp) / f"{tree}-{case.replace(' ', '').replace(',', '')}-{r}"
                    rows[tree][case].append(timed_rtsgeom(["run", str(SCENE), "--out", str(out),
                                                   "--quiet", *extra], root, bytecode))
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
