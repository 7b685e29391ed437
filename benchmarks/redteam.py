"""Adversarial checks of the output promises: ``python -m benchmarks.redteam [--quick]``.

1. Interruption: ``rtsgeom run`` into a folder that holds an earlier run (of a different seed,
   so old and new differ) is sent SIGINT, SIGTERM or SIGKILL at several fractions of its
   duration; afterwards the folder must be exactly the old run or exactly the new one, and no
   staging folder may remain after the next run.
2. Concurrent runs: two ``run``s into one ``--out`` started together: one writes, the other
   stops at once with exit 2 naming the holder's pid; the folder is one complete run.
3. Special output paths: /dev/full, a FIFO, a symlink, the input scene, a directory where a
   file is expected and the reverse, '': exit 2 naming the path (or, for the symlink, written
   through), the node untouched, within seconds.
4. Memory of the largest accepted inputs, each command in a child process under an address-space
   limit (``resource.setrlimit(RLIMIT_AS)``), with its peak resident memory (ru_maxrss).

Prints one line per check and a JSON summary; exit 1 if any check failed.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import signal
import stat
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "scenes" / "diewald2022.toml"
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}
RTSGEOM = [sys.executable, "-m", "rtsgeom"]
RESULTS: list[dict] = []


def check(name: str, ok: bool, **info) -> bool:
    RESULTS.append({"check": name, "ok": bool(ok), **info})
    extra = ", ".join(f"{k} {v}" for k, v in info.items())
    print(f"{'PASS' if ok else 'FAIL'}  {name}" + (f" ({extra})" if extra else ""), flush=True)
    return ok


def snapshot(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())} if folder.is_dir() else {}


def leftovers(parent: Path) -> list[str]:
    return sorted(p.name for p in parent.iterdir() if "rtsgeom-staging" in p.name
                  or "rtsgeom-old" in p.name or p.name.endswith(".part"))


def run(args, **kw) -> subprocess.CompletedProcess:
    return subprocess.run([*RTSGEOM, *map(str, args)], env=ENV, capture_output=True, text=True,
                          **kw)


def scene_with(tmp: Path, name: str, replace: dict[str, str]) -> Path:
    text = SCENE.read_text()
    for a, b in replace.items():
        assert a in text, a
        text = text.replace(a, b)
    path = tmp / name
    path.write_text(text)
    return path


# --- 1. interruption --------------------------------------------------------------------------

def interruption(tmp: Path, quick: bool) -> None:
    old_scene = scene_with(tmp, "old.toml", {"seed = 2022": "seed = 7"})
    ref_old, ref_new = tmp / "ref_old", tmp / "ref_new"
    t0 = time.monotonic()
    assert run(["run", SCENE, "--out", ref_new, "--quiet"]).returncode == 0
    duration = time.monotonic() - t0
    assert run(["run", old_scene, "--out", ref_old, "--quiet"]).returncode == 0
    old, new = snapshot(ref_old), snapshot(ref_new)
    assert old["detections.csv"] != new["detections.csv"]
    # fractions of the reference run's duration, and "swap": the moment the last file
    # (report.html) appears in the staging folder, just before the folder is swapped in
    points = (0.1, 0.6, "swap") if quick else (0.05, 0.3, 0.6, 0.95, 1.3, "swap")
    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGKILL):
        for frac in points:
            out = tmp / "target"
            shutil.rmtree(out, ignore_errors=True)
            shutil.copytree(ref_old, out)
            proc = subprocess.Popen([*RTSGEOM, "run", SCENE, "--out", out, "--quiet"], env=ENV,
                                    stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
            if frac == "swap":
                while proc.poll() is None and not list(
                        tmp.glob(".target.rtsgeom-staging-*/report.html")):
                    time.sleep(0.002)
            else:
                time.sleep(frac * duration)
            if proc.poll() is None:
                proc.send_signal(sig)
            _, err = proc.communicate()
            now = snapshot(out)
            state = "old" if now == old else "new" if now == new else "MIXED"
            left = leftovers(tmp)
            clean = sig == signal.SIGKILL or not left
            if sig == signal.SIGKILL and left:  # the next run must clean up what KILL left
                assert run(["run", SCENE, "--out", out, "--quiet"]).returncode == 0
                clean = not leftovers(tmp) and snapshot(out) == new
            when = "the swap" if frac == "swap" else f"{frac:.0%} of {duration:.0f} s"
            check(f"interrupt run with {signal.Signals(sig).name} at {when}", state != "MIXED" and clean and "Traceback" not in err,
                  folder=state, exit=proc.returncode, leftovers=left or "none")


# --- 2. concurrent runs -------------------------------------------------------------------------

def concurrent(tmp: Path) -> None:
    out = tmp / "shared"
    procs = [subprocess.Popen([*RTSGEOM, "run", SCENE, "--out", out, "--quiet"], env=ENV,
                              stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
             for _ in range(2)]
    errs = [p.communicate()[1] for p in procs]
    codes = sorted(p.returncode for p in procs)
    refused = [e for p, e in zip(procs, errs) if p.returncode == 2]
    names = set(snapshot(out))
    check("two concurrent runs into one --out", codes == [0, 2] and refused
          and "another rtsgeom run" in refused[0] and "pid" in refused[0]
          and {"detections.csv", "summary.json", "report.html"} <= names
          and not leftovers(tmp), exits=codes, message=(refused or ["-"])[0].strip()[:120])


# --- 3. special output paths --------------------------------------------------------------------

def special_paths(tmp: Path) -> None:
    def one(name, args, node=None, expect=2, extra=lambda: True):
        before = os.lstat(node) if node and os.path.lexists(node) else None
        t0 = time.monotonic()
        r = run(args)
        dt = time.monotonic() - t0
        after = os.lstat(node) if node and os.path.lexists(node) else None
        same_node = before is None or (after is not None and after.st_ino == before.st_ino
                                       and after.st_mode == before.st_mode)
        line = r.stderr.strip()
        check(name, r.returncode == expect and same_node and "Traceback" not in r.stderr
              and ".part" not in r.stderr and (expect == 0 or line.count("\n") == 0)
              and extra(), exit=r.returncode, seconds=round(dt, 1), message=line[:110] or "-")

    dev = Path("/dev/full")
    if os.geteuid() == 0:  # as root a broken build would replace the node: use a private one
        dev = tmp / "full"
        os.mknod(dev, stat.S_IFCHR | 0o666, os.makedev(1, 7))
    one("paths --out DEVICE (/dev/full)", ["paths", SCENE, "--out", dev], dev)
    one("run --out DEVICE (/dev/full)", ["run", SCENE, "--out", dev, "--quiet"], dev)
    fifo = tmp / "fifo"
    os.mkfifo(fifo)
    one("paths --out FIFO", ["paths", SCENE, "--out", fifo], fifo)
    one("run --out FIFO", ["run", SCENE, "--out", fifo, "--quiet"], fifo)
    real = tmp / "real.csv"
    real.write_text("x")
    os.chmod(real, 0o600)
    link = tmp / "link.csv"
    link.symlink_to(real)
    one("paths --out SYMLINK (written through, link and mode kept)",
        ["paths", SCENE, "--out", link], link, expect=0,
        extra=lambda: link.is_symlink() and real.read_text().startswith("front_end")
        and (real.stat().st_mode & 0o777) == 0o600)
    scene = tmp / "my.toml"
    scene.write_bytes(SCENE.read_bytes())
    one("paths my.toml --out my.toml", ["paths", scene, "--out", scene], scene,
        extra=lambda: scene.read_bytes() == SCENE.read_bytes())
    d = tmp / "adir"
    d.mkdir()
    one("paths --out DIRECTORY", ["paths", SCENE, "--out", d], d)
    one("adc --out DIRECTORY", ["adc", SCENE, "--out", d], d)
    f = tmp / "afile"
    f.write_text("keep")
    for cmd in (["run", SCENE, "--quiet"], ["tolerance", SCENE, "--draws", "10"],
                ["calibrate", SCENE], ["nearfield", SCENE], ["ghosts", SCENE]):
        one(f"{cmd[0]} --out FILE", [*cmd, "--out", f], f, extra=lambda: f.read_text() == "keep")
    one("run --out ''", ["run", SCENE, "--out", ""])
    one("paths --out ''", ["paths", SCENE, "--out", ""])
    one("run --out /proc/x", ["run", SCENE, "--out", "/proc/rtsgeom-x", "--quiet"])
    one("show --png x.jpg", ["show", SCENE, "--png", tmp / "x.jpg"],
        extra=lambda: not (tmp / "x.jpg").exists())
    home = tmp / "home"
    home.mkdir()
    (home / "notes.txt").write_text("mine")
    one("run --out FOLDER-WITH-FOREIGN-FILES", ["run", SCENE, "--out", home, "--quiet"],
        extra=lambda: (home / "notes.txt").read_text() == "mine")


# --- 4. memory of the largest accepted inputs ----------------------------------------------------

def limited(args, limit_bytes: int, timeout: float = 1200) -> tuple[int, float, str, float]:
    """Run the CLI in a child under RLIMIT_AS; (exit code, peak RSS MiB, stderr tail, s)."""
    def preexec():
        resource.setrlimit(resource.RLIMIT_AS, (limit_bytes, limit_bytes))
    code = ("import resource, runpy, sys; sys.argv = ['rtsgeom', *sys.argv[1:]]\n"
            "try:\n    runpy.run_module('rtsgeom', run_name='__main__')\n"
            "finally:\n    print('PEAK_RSS_KIB', resource.getrusage(resource.RUSAGE_SELF)"
            ".ru_maxrss, file=sys.stderr)")
    env = {**ENV, "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}  # no per-thread arenas
    t0 = time.monotonic()
    r = subprocess.run([sys.executable, "-c", code, *map(str, args)], env=env,
                       capture_output=True, text=True, preexec_fn=preexec, timeout=timeout)
    peak = [int(line.split()[1]) for line in r.stderr.splitlines()
            if line.startswith("PEAK_RSS_KIB")]
    tail = "\n".join(line for line in r.stderr.splitlines()[-3:]
                     if not line.startswith("PEAK_RSS_KIB"))
    return r.returncode, (peak[0] / 1024 if peak else float("nan")), tail, time.monotonic() - t0


def memory(tmp: Path, quick: bool) -> None:
    limit = 3 * 2 ** 30
    big_ring = scene_with(tmp, "ring.toml", {"training_cells = [8, 4]":
                                             "training_cells = [256, 256]",
                                             "guard_cells = [2, 2]": "guard_cells = [64, 64]"})
    os_ring = scene_with(tmp, "osring.toml", {"training_cells = [8, 4]":
                                              "training_cells = [256, 256]",
                                              'kind = "ca"': 'kind = "os"'})
    cases = [
        ("run (bundled scene)", ["run", SCENE, "--out", tmp / "m1", "--quiet", "--no-report"]),
        ("run, CA-CFAR training cells [256, 256], guard [64, 64]",
         ["run", big_ring, "--out", tmp / "m2", "--quiet", "--no-report",
          "--amplitudes", "nearest"]),
        ("run, OS-CFAR training cells [256, 256]",
         ["run", os_ring, "--out", tmp / "m3", "--quiet", "--no-report",
          "--amplitudes", "nearest"]),
        ("tolerance --chunk 1000000 --points 21 --draws 200000",
         ["tolerance", SCENE, "--chunk", "1000000", "--points", "21", "--draws", "200000",
          "--quiet"]),
        ("paths", ["paths", SCENE, "--out", tmp / "p.csv"]),
    ]
    if not quick:
        cases.append(("tolerance --chunk 1000000 --points 201 --draws 20000",
                      ["tolerance", SCENE, "--chunk", "1000000", "--points", "201",
                       "--draws", "20000", "--quiet"]))
    for name, args in cases:
        code, peak, tail, dt = limited(args, limit)
        check(f"memory: {name} under a {limit >> 30} GiB address-space limit", code == 0,
              peak_rss_mib=round(peak), seconds=round(dt), exit=code,
              **({"stderr": tail[-200:]} if code else {}))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer interruption points, "
                    "no 201-point tolerance")
    ap.add_argument("--only", choices=("interrupt", "concurrent", "paths", "memory"),
                    action="append", help="run only these parts (repeatable)")
    ap.add_argument("--json", type=Path, help="also write the results here")
    args = ap.parse_args(argv)
    parts = args.only or ["paths", "concurrent", "interrupt", "memory"]
    with tempfile.TemporaryDirectory(prefix="rtsgeom-redteam-") as tmp:
        tmp = Path(tmp)
        for part in parts:
            sub = tmp / part
            sub.mkdir()
            {"interrupt": lambda: interruption(sub, args.quick),
             "concurrent": lambda: concurrent(sub),
             "paths": lambda: special_paths(sub),
             "memory": lambda: memory(sub, args.quick)}[part]()
    failed = [r for r in RESULTS if not r["ok"]]
    summary = {"checks": len(RESULTS), "failed": len(failed), "results": RESULTS}
    if args.json:
        args.json.write_text(json.dumps(summary, indent=2, default=str) + "\n")
    print(f"{len(RESULTS) - len(failed)}/{len(RESULTS)} checks passed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
