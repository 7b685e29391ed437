"""``python -m benchmarks.dense_arc [--front-ends 64] [--step-deg 1] [--targets 32] [--repeat 3]``:
how long the CLI takes on an arc of many front ends; ``--scaling 16 32 64``: the same commands
on arcs of those many front ends (the same targets), each command's CPU per front end, written
to ``benchmarks/dense_arc_scaling.json``.

The template's bench (``scenes/template.toml``: AWR1843BOOST, 1.5 m arc, noise at 10 dB) with
``--front-ends`` front ends ``--step-deg`` apart (12 mm Rx/Tx modules in 24 mm cutouts so that
neighbours fit) and ``--targets`` targets spread over the arc at 10 to 63 m and -3.3 to 3.3
m/s. Times ``info``, ``run`` (with and without its report) and ``calibrate --pair all`` as
whole processes (wall, user CPU and user + system CPU of the process and its forked
children, the median of ``--repeat``), with the machine's load average before each, checks
that every target is detected, and writes ``benchmarks/dense_arc.json`` (the record it
replaces kept under ``before``). ``--against DIR``: also time another checkout of rtsgeom
(e.g. ``git worktree add DIR COMMIT``), its runs interleaved with this tree's so that both see
the same load on a shared machine (``against`` in the record). Not part of the test suite.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import tempfile
from pathlib import Path

from benchmarks._io import timed_rtsgeom, write_json

ROOT = Path(__file__).resolve().parents[1]
TEMPLATE = ROOT / "scenes" / "template.toml"


def arc_scene(n: int, step_deg: float, n_targets: int) -> str:
    """The template's bench with ``n`` front ends ``step_deg`` apart and ``n_targets``
    targets, as TOML text (the template's [radar] and [rts] kept, its front ends, sheet and
    targets replaced)."""
    head = TEMPLATE.read_text().split("\n[[rts.front_ends]]\n")[0]
    head = head.replace("five RTS front ends", f"{n} RTS front ends {step_deg:g} deg apart")
    a0 = -step_deg * (n - 1) / 2
    span = (n - 1) * step_deg
    out = [head, ""]
    for k in range(n):
        out += ["[[rts.front_ends]]", f"angle_deg = {a0 + k * step_deg:.6f}",
                "rx_tx_separation_m = 0.012", "cable_length_m = 1.0", ""]
    out += ["[sheet]", "height_m = 0.3", f"angle_min_deg = {a0 - 4:.6f}",
            f"angle_max_deg = {-a0 + 4:.6f}", "cutout_diameter_m = 0.024",
            "thickness_m = 0.002", ""]
    for k in range(n_targets):
        ang = a0 + step_deg / 2 + span * (k + 0.37) / (n_targets + 0.2)
        ang = min(max(ang, a0 + 0.2 * step_deg), -a0 - 0.2 * step_deg)
        out += ["[[targets]]", f"range_m = {10 + 1.7 * k:.3f}",
                f"velocity_mps = {((k % 7) - 3) * 1.1:.3f}", f"angle_deg = {ang:.4f}", ""]
    return "\n".join(out)


def timed(argv: list[str], root: Path = ROOT) -> dict:
    """:func:`benchmarks._io.timed_rtsgeom` (this checkout by default)."""
    return timed_rtsgeom(argv, root)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--front-ends", type=int, default=64)
    ap.add_argument("--step-deg", type=float, default=1.0)
    ap.add_argument("--targets", type=int, default=32)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--out", default=None)
    ap.add_argument("--scaling", type=int, nargs="+", default=None, metavar="N")
    ap.add_argument("--against", default=None, metavar="DIR")
    args = ap.parse_args(argv)
    if args.scaling:
        return scaling(args)
    out = args.out or str(ROOT / "benchmarks" / "dense_arc.json")
    record = measure(args.front_ends, args)
    old = json.loads(Path(out).read_text()) if Path(out).exists() else {}
    if "commands" in old:  # the record this run replaces, kept beside it
        record["before"] = {k: old[k] for k in ("commands", "accuracy") if k in old}
    write_json(out, record, newline=True)
    return 0


def scaling(args) -> int:
    """Each command on arcs of ``args.scaling`` front ends: medians, and CPU per front end."""
    rows = {}
    for n in args.scaling:
        rec = measure(n, args)
        rows[str(n)] = {"commands": {k: {"median_wall_s": v["median_wall_s"],
                                         "median_user_s": v["median_user_s"],
                                         "user_s_per_front_end": v["median_user_s"] / n}
                                     for k, v in rec["commands"].items()},
                        "accuracy": rec["accuracy"]}
    write_json(args.out or str(ROOT / "benchmarks" / "dense_arc_scaling.json"),
               {"front_ends": args.scaling, "step_deg": args.step_deg,
                "targets": args.targets, "repeat": args.repeat, "cpus": os.cpu_count(),
                "scaling": rows}, newline=True)
    return 0


def _median(runs: list[dict]) -> dict:
    return {"median_wall_s": statistics.median(x["wall_s"] for x in runs),
            "median_user_s": statistics.median(x["user_s"] for x in runs),
            "median_cpu_s": statistics.median(x["cpu_s"] for x in runs), "runs": runs}


def measure(n_fe: int, args) -> dict:
    """The four commands on an arc of ``n_fe`` front ends (module doc)."""
    trees = ({"against ": Path(args.against).resolve()}  # first: this tree's files stay
             if getattr(args, "against", None) else {}) | {"": ROOT}
    rows, other = {}, {}
    with tempfile.TemporaryDirectory() as tmp:
        scene = Path(tmp) / f"arc{n_fe}.toml"
        scene.write_text(arc_scene(n_fe, args.step_deg, args.targets))
        cases = {"info": ["info", str(scene)],
                 "run --no-report": ["run", str(scene), "--out", f"{tmp}/a", "--no-report"],
                 "run": ["run", str(scene), "--out", f"{tmp}/b"],
                 "calibrate --pair all": ["calibrate", str(scene), "--pair", "all"]}
        for name, cmd in cases.items():
            runs = {tree: [] for tree in trees}
            for r in range(args.repeat):
                for tree, root in trees.items():  # interleaved: the same load for both
                    if "--out" in cmd:  # a new folder each time (this tree's last run stays)
                        shutil.rmtree(cmd[cmd.index("--out") + 1], ignore_errors=True)
                    runs[tree].append(timed(cmd, root))
                    x = runs[tree][-1]
                    print(f"{tree}{n_fe} front ends, {name}: {x['wall_s']:.1f} s wall, "
                          f"{x['user_s']:.1f} s user, {x['cpu_s']:.1f} s CPU "
                          f"(load {x['load_before']:.1f})", flush=True)
            rows[name] = _median(runs[""])
            if len(trees) > 1:
                other[name] = _median(runs["against "])
        summary = json.loads((Path(tmp) / "b" / "summary.json").read_text())
    errs = [t["error"] for t in summary["targets"] if t["detection"] is not None]
    accuracy = {"targets": len(summary["targets"]), "detected": len(errs),
                **{f"max_abs_{k}": max(abs(e[k]) for e in errs)
                   for k in ("range_m", "velocity_mps", "angle_deg")}}
    print(accuracy)
    out = {"front_ends": n_fe, "step_deg": args.step_deg, "targets": args.targets,
           "repeat": args.repeat, "cpus": os.cpu_count(), "commands": rows,
           "accuracy": accuracy}
    if other:
        out["against"] = {"tree": str(trees["against "]), "commands": other}
    return out


if __name__ == "__main__":
    raise SystemExit(main())
