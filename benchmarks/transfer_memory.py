"""Peak memory (max RSS) and time of ``rtsgeom.transfer`` at the documented maximum: 100 000
radars, and 100 000 radars with 201 set-points (one pair: diewald2022).

    python -m benchmarks.transfer_memory [--radars 100000] [--points 11 201]
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import time

CHILD = """
import json, resource, sys, time
import rtsgeom
s = rtsgeom.load_scene("scenes/diewald2022.toml")
t0 = time.perf_counter()
res = rtsgeom.transfer(s, radars={radars}, points={points})
print(json.dumps({{"radars": {radars}, "points": {points}, "seconds": time.perf_counter() - t0,
                  "max_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
                  "p95_deg": res.to_dict()["angle_error_deg"]["p95"]}}))
"""


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.transfer_memory")
    ap.add_argument("--radars", type=int, default=100_000)
    ap.add_argument("--points", type=int, nargs="+", default=[11, 201])
    args = ap.parse_args(argv)
    for p in args.points:  # each in its own process: its own peak
        out = subprocess.run([sys.executable, "-c", CHILD.format(radars=args.radars, points=p)],
                             capture_output=True, text=True, check=True)
        print(out.stdout.strip().splitlines()[-1])
    return 0


if __name__ == "__main__":
    sys.exit(main())
