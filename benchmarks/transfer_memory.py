"""Peak memory (max RSS) and time of ``rtsgeom transfer`` / ``rtsgeom.transfer`` at the
documented maximum: 100 000 radars x 201 set-points (one pair: diewald2022).

    python -m benchmarks.transfer_memory [--radars 100000] [--points 201] [--entry cli python]
        [--stub-search] [--out benchmarks/transfer_memory.json]

Each case runs in its own process (its own peak), under ``/usr/bin/time -f %M`` where that
exists (else ``getrusage``).

``--stub-search`` replaces the beamformer's peak search (``Steering.search``) by zeros: the
search is nearly all of the study's time (about 2.3 CPU hours at the maximum on the 2-core
machine), while its memory is one chunk of ``CHUNK_SNAPSHOTS`` snapshots whatever the number of
radars. A stubbed run at the maximum measures everything that grows with radars x set-points
(the drawn gains, the (1 + 2B, P) errors, the results and their percentiles); the search's
own chunk is measured by a real run at fewer radars (the same chunk size) and the difference
of that run and its stubbed twin bounds it. ``summary`` in the JSON adds the two.
"""

from __future__ import annotations

import argparse
import json
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCENE = "scenes/diewald2022.toml"

CHILD = """
import json, resource, sys, time
import numpy as np
if {stub}:  # the study's searches (not the calibration's, nor the probes') return zeros
    import rtsgeom.analysis.transfer as T
    from rtsgeom.radar.steering import Steering
    real, on = Steering.search, [True]
    Steering.search = lambda self, s: np.zeros(np.shape(s)[:-1]) if on[0] else real(self, s)
    def off(f):
        def g(*a, **k):
            on[0] = False
            try:
                return f(*a, **k)
            finally:
                on[0] = True
        return g
    T.calibrate_pair, T._probe = off(T.calibrate_pair), off(T._probe)
t0 = time.perf_counter()
if "{entry}" == "cli":
    from rtsgeom.cli import main
    rc = main(["transfer", "{scene}", "--radars", "{radars}", "--points", "{points}", "--json",
               "--quiet"])
    p95 = None
else:
    import rtsgeom
    res = rtsgeom.transfer(rtsgeom.load_scene("{scene}"), radars={radars}, points={points})
    rc, p95 = 0, res.to_dict()["angle_error_deg"]["p95"]
print("RESULT " + json.dumps({{"rc": rc, "seconds": time.perf_counter() - t0,
                  "cpu_s": time.process_time(), "p95_deg": p95,
                  "ru_maxrss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}}))
"""


def run_case(entry: str, radars: int, points: int, stub: bool) -> dict:
    code = CHILD.format(entry=entry, radars=radars, points=points, stub=stub, scene=SCENE)
    cmd = [sys.executable, "-c", code]
    timer = shutil.which("time") or ("/usr/bin/time" if Path("/usr/bin/time").exists() else None)
    if timer:
        cmd = [timer, "-f", "MAXRSS_KB %M", *cmd]
    out = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)
    res = {"entry": entry, "radars": radars, "points": points, "search_stubbed": stub,
           "returncode": out.returncode}
    line = [x for x in out.stdout.splitlines() if x.startswith("RESULT ")]
    if line:
        res.update(json.loads(line[-1][7:]))
    m = re.search(r"MAXRSS_KB (\d+)", out.stderr)
    if m:
        res["max_rss_mb"] = int(m.group(1)) / 1024
    if out.returncode:
        res["stderr_tail"] = out.stderr[-400:]
    return res


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.transfer_memory")
    ap.add_argument("--radars", type=int, default=100_000)
    ap.add_argument("--points", type=int, default=201)
    ap.add_argument("--entry", nargs="+", choices=("cli", "python"), default=["cli", "python"])
    ap.add_argument("--stub-search", action="store_true")
    ap.add_argument("--chunk-radars", type=int, default=2000,
                    help="radars of the real run and its stubbed twin that bound the search's "
                         "chunk (with --stub-search)")
    ap.add_argument("--out", type=Path, default=None)
    args = ap.parse_args(argv)
    cases = []
    for entry in args.entry:
        cases.append(run_case(entry, args.radars, args.points, args.stub_search))
        print(json.dumps(cases[-1]), flush=True)
    summary = {}
    if args.stub_search:
        small = [run_case("python", args.chunk_radars, args.points, s) for s in (False, True)]
        for c in small:
            print(json.dumps(c), flush=True)
        cases += small
        chunk = small[0]["max_rss_mb"] - small[1]["max_rss_mb"]
        worst = max(c["max_rss_mb"] for c in cases[:len(args.entry)])
        summary = {"search_chunk_mb": chunk, "bound_at_maximum_mb": worst + max(chunk, 0.0),
                   "limit_mb": 2048, "under_limit": worst + max(chunk, 0.0) < 2048}
        print(json.dumps(summary))
    if args.out:
        args.out.write_text(json.dumps({"scene": SCENE, "when": time.strftime("%Y-%m-%d"),
                                        "cases": cases, "summary": summary}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
