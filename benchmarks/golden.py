"""Golden outputs: every command's JSON/CSV output on the three bundled scenes, recorded before a
restructuring and compared after it.

``python -m benchmarks.golden record DIR`` runs each case of :data:`CASES` as a user would (the
``rtsgeom`` console script in a subprocess, two at a time) and keeps, per case, its exit code,
its standard output (parsed as JSON where it is JSON), the last line of its standard error, and
every JSON/CSV file it wrote (other files by their SHA-256). ``python -m benchmarks.golden
compare OLD NEW`` reports each case as byte-identical, equal within a relative tolerance (the
largest relative difference of any number, and where it is), or different.

The cases are what a lab runs: the main job, the raw cube, calibration (phasor, paper, full
chain, every pair), linearity, tolerance (pair, whole arc, cell, yield search, full-chain
verification), design (map and coverage), near field, ghosts and identification.
"""

from __future__ import annotations

import argparse
import csv
import hashlib
import io
import json
import math
import re
import shutil
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
D, C, S = ("scenes/diewald2022.toml", "scenes/custom-array.toml", "scenes/sphere4.toml")

#: name -> command line after ``rtsgeom`` ({out}: a fresh folder for the case's files)
CASES: dict[str, list[str]] = {}
for _tag, _scene in (("d", D), ("c", C), ("s", S)):
    CASES.update({
        f"{_tag}-info": ["info", _scene, "--json"],
        f"{_tag}-paths": ["paths", _scene, "--out", "{out}/paths.csv"],
        f"{_tag}-run": ["run", _scene, "--out", "{out}/run", "--quiet", "--no-report"],
        f"{_tag}-adc": ["adc", _scene, "--out", "{out}/cube.npy", "--quiet"],
        f"{_tag}-nearfield": ["nearfield", _scene, "--json", "--quiet"],
        f"{_tag}-ghosts": ["ghosts", _scene, "--json"],
        f"{_tag}-calibrate": ["calibrate", _scene, "--json", "--quiet"],
        f"{_tag}-tolerance": ["tolerance", _scene, "--draws", "1000", "--json", "--quiet"],
    })
for _tag, _scene in (("d", D), ("c", C)):
    CASES.update({
        f"{_tag}-linearity": ["linearity", _scene, "--json", "--quiet"],
        f"{_tag}-calibrate-all": ["calibrate", _scene, "--pair", "all", "--json", "--quiet"],
        f"{_tag}-calibrate-12": ["calibrate", _scene, "--pair", "1", "2", "--json", "--quiet"],
        f"{_tag}-tolerance-all": ["tolerance", _scene, "--pair", "all", "--draws", "500",
                                  "--yaw-deg", "0.5", "--rut-position-mm", "0.2", "--json",
                                  "--quiet"],
        f"{_tag}-design": ["design", _scene, "--radius-m", "0.5:1.5:2", "--spacing-deg",
                           "4:12:2", "--draws", "300", "--json", "--quiet"],
    })
CASES.update({
    "d-run-nearest": ["run", D, "--out", "{out}/run", "--quiet", "--no-report",
                      "--amplitudes", "nearest"],
    "d-run-capon": ["run", D, "--out", "{out}/run", "--quiet", "--no-report",
                    "--estimator", "capon"],
    "d-calibrate-paper": ["calibrate", D, "--procedure", "paper", "--json", "--quiet"],
    "d-calibrate-ideal": ["calibrate", D, "--fir", "ideal", "--json", "--quiet"],
    "c-calibrate-full": ["calibrate", C, "--full-chain", "--json", "--quiet"],
    "d-calibrate-out": ["calibrate", D, "--out", "{out}/cal", "--quiet"],
    "d-linearity-uncal": ["linearity", D, "--uncalibrated", "--json", "--quiet"],
    "d-linearity-paper": ["linearity", D, "--amplitudes", "paper", "--json", "--quiet"],
    "s-linearity-grid": ["linearity", S, "--grid", "3", "--json", "--quiet"],
    "s-calibrate-cells": ["calibrate", S, "--pair", "all", "--json", "--quiet"],
    "s-tolerance-cell": ["tolerance", S, "--cell", "all", "--draws", "300", "--json",
                         "--quiet"],
    "d-tolerance-uniform": ["tolerance", D, "--draws", "1000", "--distribution", "uniform",
                            "--radial-mm", "0.3", "--json", "--quiet"],
    "d-tolerance-invert": ["tolerance", D, "--draws", "500", "--invert-yield", "0.9",
                           "--json", "--quiet"],
    "d-tolerance-verify": ["tolerance", D, "--draws", "200", "--verify", "3", "--json",
                           "--quiet"],
    "d-tolerance-nominal": ["tolerance", D, "--draws", "500", "--nominal-amplitudes", "--json",
                            "--quiet"],
    "d-tolerance-out": ["tolerance", D, "--draws", "500", "--out", "{out}/tol", "--quiet"],
    "d-design-coverage": ["design", D, "--coverage-deg", "-10:10", "--radius-m", "0.5:1:2",
                          "--draws", "200", "--json", "--quiet"],
    "d-ghosts-sim": ["ghosts", D, "--simulate", "--json"],
    "d-nearfield-radii": ["nearfield", D, "--radius-m", "0.3:3:4", "--json", "--quiet"],
    "d-adc-dca": ["adc", D, "--format", "dca1000", "--out", "{out}/adc.bin", "--quiet"],
    "d-adc-active": ["adc", D, "--active", "1", "--out", "{out}/cap1.npy", "--quiet"],
    "d-identify": ["identify", D, "{golden}/d-adc-active/files/cap1.npy", "--json", "--quiet"],
})
#: cases that read another case's files (run after it)
AFTER = {"d-identify": "d-adc-active"}


def _run(name: str, dest: Path, golden: Path) -> dict:
    case = dest / name
    if case.exists():
        shutil.rmtree(case)
    files = case / "files"
    files.mkdir(parents=True)
    argv = [a.format(out=str(files), golden=str(golden)) for a in CASES[name]]
    t0 = time.perf_counter()
    exe = Path(sys.executable).with_name("rtsgeom")
    p = subprocess.run([str(exe), *argv], cwd=ROOT, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    try:
        out = json.loads(p.stdout)
    except json.JSONDecodeError:
        out = p.stdout
    err = p.stderr.strip().splitlines()
    rec = {"argv": argv, "returncode": p.returncode, "stdout": out,
           "stderr_last": err[-1] if err and p.returncode else ""}
    (case / "result.json").write_text(json.dumps(rec, indent=1, sort_keys=True) + "\n")
    for f in sorted(files.rglob("*")):
        if f.is_file() and f.suffix not in (".json", ".csv"):
            digest = hashlib.sha256(f.read_bytes()).hexdigest()
            f.with_name(f.name + ".sha256").write_text(digest + "\n")
            if f.stat().st_size > 256 * 1024 and name not in AFTER.values():
                f.unlink()
    return {"name": name, "returncode": p.returncode, "wall_s": round(wall, 2)}


def record(dest: Path, names=None, jobs: int = 2) -> None:
    dest = Path(dest).resolve()
    dest.mkdir(parents=True, exist_ok=True)
    names = list(CASES) if not names else list(names)
    first = [n for n in names if n not in AFTER]
    with ThreadPoolExecutor(jobs) as pool:
        done = list(pool.map(lambda n: _run(n, dest, dest), first))
    done += [_run(n, dest, dest) for n in names if n in AFTER]
    for d in done:
        print(f"{d['name']:24s} rc {d['returncode']}  {d['wall_s']:7.2f} s", flush=True)
    # the capture read by identify is kept only for that; not part of the record
    for n in AFTER.values():
        for f in (dest / n / "files").glob("*.npy"):
            f.unlink()


# -- comparison ------------------------------------------------------------------------------

def _numbers(a, b, where, out):
    """Walk two parsed values side by side; out collects (rel diff, where) and mismatches."""
    if isinstance(a, dict) and isinstance(b, dict):
        if set(a) != set(b):
            out["struct"].append(f"{where}: keys {sorted(set(a) ^ set(b))}")
        for k in set(a) & set(b):
            _numbers(a[k], b[k], f"{where}.{k}", out)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            out["struct"].append(f"{where}: length {len(a)} != {len(b)}")
        for k, (x, y) in enumerate(zip(a, b)):
            _numbers(x, y, f"{where}[{k}]", out)
    elif isinstance(a, (int, float)) and isinstance(b, (int, float)) and not isinstance(
            a, bool):
        if a == b or (isinstance(a, float) and isinstance(b, float) and math.isnan(a)
                      and math.isnan(b)):
            return
        rel = abs(a - b) / max(abs(a), abs(b), 1e-300)
        out["diffs"].append((rel, abs(a - b), where, a, b))
    elif a != b:
        out["struct"].append(f"{where}: {str(a)[:60]!r} != {str(b)[:60]!r}")


def _parse(path: Path, root: Path | None = None):
    try:
        text = path.read_text()
    except UnicodeDecodeError:  # a binary output: its bytes are the comparison
        return hashlib.sha256(path.read_bytes()).hexdigest()
    if root is not None:  # where the record was written, and timings, are not outputs
        text = text.replace(str(root.resolve()), "<record>")
        text = re.sub(r"\b\d+\.\d+ s\b", "<seconds> s", text)
    if path.suffix == ".json":
        return json.loads(text)
    if path.suffix == ".csv":
        rows = list(csv.reader(io.StringIO(text)))

        def num(v):
            try:
                return float(v)
            except ValueError:
                return v
        return [[num(v) for v in r] for r in rows]
    return text


def compare(old: Path, new: Path, rtol: float = 1e-9, show: int = 3) -> int:
    """Print one line per case (identical / within rtol / differs, with the largest
    differences); returns the number of cases that differ beyond ``rtol``."""
    bad = 0
    for case in sorted(p for p in Path(old).iterdir() if p.is_dir()):
        other = Path(new) / case.name
        if not other.exists():
            print(f"{case.name:24s} MISSING")
            bad += 1
            continue
        files = sorted(p.relative_to(case) for p in case.rglob("*") if p.is_file())
        files2 = sorted(p.relative_to(other) for p in other.rglob("*") if p.is_file())
        if files != files2:
            print(f"{case.name:24s} FILES {sorted(set(map(str, files)) ^ set(map(str, files2)))}")
        out = {"diffs": [], "struct": []}
        identical = True
        for f in files:
            if not (other / f).exists():
                continue
            if (case / f).read_bytes() == (other / f).read_bytes():
                continue
            identical = False
            a, b = _parse(case / f, Path(old)), _parse(other / f, Path(new))
            if a == b:
                continue
            if f.name == "result.json":  # timings and progress are not outputs
                for rec in (a, b):
                    rec.pop("argv", None)
            _numbers(a, b, str(f), out)
        if identical or (not out["diffs"] and not out["struct"]):
            print(f"{case.name:24s} identical" + ("" if identical else
                                                    " (but where it was written, timings)"))
            continue
        worst = sorted(out["diffs"], reverse=True)
        timing = [d for d in worst if "elapsed" in d[2] or "cpu_s" in d[2] or "wall" in d[2]]
        worst = [d for d in worst if d not in timing]
        if not worst and not out["struct"]:
            print(f"{case.name:24s} identical (but timings)")
            continue
        status = ("within" if not out["struct"] and (not worst or worst[0][0] <= rtol)
                  else "DIFFERS")
        bad += status == "DIFFERS"
        top = worst[0][0] if worst else 0.0
        print(f"{case.name:24s} {status} rtol {top:.3g}; {len(worst)} numbers, "
              f"{len(out['struct'])} structural")
        for rel, ab, where, a, b in worst[:show]:
            print(f"    {where}: {a!r} -> {b!r} (rel {rel:.3g}, abs {ab:.3g})")
        for s in out["struct"][:show]:
            print(f"    {s}")
    return bad


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.golden", description=__doc__)
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("record")
    r.add_argument("dest")
    r.add_argument("names", nargs="*")
    r.add_argument("--jobs", type=int, default=2)
    c = sub.add_parser("compare")
    c.add_argument("old")
    c.add_argument("new")
    c.add_argument("--rtol", type=float, default=1e-9)
    c.add_argument("--show", type=int, default=3)
    a = ap.parse_args(argv)
    if a.cmd == "record":
        record(Path(a.dest), a.names, a.jobs)
        return 0
    return 1 if compare(Path(a.old), Path(a.new), a.rtol, a.show) else 0


if __name__ == "__main__":
    sys.exit(main())
