"""``python -m benchmarks.play_speed [--frames 1000] [--targets 8] [--repeat 1]``: how long
``rtsgeom play`` takes on the crossing bench with several targets.

The bundled crossing bench (``scenes/crossing.toml``: five front ends 8 deg apart) with
``--targets`` targets crossing the arc from -8.5 to +8.5 deg at 16.2 to 16.2 + 1.9 (N - 1) m,
played over its 2 s drive in ``--frames`` frames (the exact synthesis, no baseline), as a
whole process (wall and user CPU, the median of ``--repeat``, the load average before each);
writes ``benchmarks/play_speed.json``, the earlier records of that file kept under
``history`` (each with its ``label``; ``--label`` names this one). ``--chain`` passes play's
``--chain``. ``--root`` plays another checkout's code (e.g. an export of an earlier commit: the before of a change). Not part of
the test suite.
"""

from __future__ import annotations

import argparse
import json
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
CROSSING = ROOT / "scenes" / "crossing.toml"


def crossing_scene(frames: int, n_targets: int) -> str:
    """The crossing bench's TOML with ``n_targets`` crossing targets and ``frames`` frames
    over its 2 s drive (its [radar], [rts] and [sheet] kept)."""
    head = CROSSING.read_text().split("\n[scenario]\n")[0]
    out = [head, "", "[scenario]", f"frame_period_s = {2.0 / (frames - 1)!r}",
           "duration_s = 2.0", ""]
    for k in range(n_targets):
        r = 16.223748416 + 1.9 * k
        out += ["[[scenario.targets]]", "rcs_dbsm = 10.0",
                f"waypoints = [[0.0, {r:.9f}, -8.530765609], [2.0, {r:.9f}, 8.530765609]]", ""]
    return "\n".join(out)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--frames", type=int, default=1000)
    ap.add_argument("--targets", type=int, default=8)
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "play_speed.json"))
    ap.add_argument("--label", default="current", help="what this record measures")
    ap.add_argument("--root", default=str(ROOT), help="the checkout whose rtsgeom plays")
    ap.add_argument("--chain", choices=("fast", "full"), default=None,
                    help="play's --chain (default: play's own default)")
    args = ap.parse_args(argv)
    runs = []
    with tempfile.TemporaryDirectory() as tmp:
        scene = Path(tmp) / "crossing-many.toml"
        scene.write_text(crossing_scene(args.frames, args.targets))
        for r in range(args.repeat):
            load = os.getloadavg()[0]
            before = resource.getrusage(resource.RUSAGE_CHILDREN)
            t0 = time.perf_counter()
            proc = subprocess.run([sys.executable, "-m", "rtsgeom", "play", str(scene), "--out",
                                   f"{tmp}/out{r}", "--no-baseline", "--quiet"]
                                  + ([] if args.chain is None else ["--chain", args.chain]),
                                  capture_output=True, text=True, cwd=args.root,
                                  env={**os.environ, "PYTHONPATH": args.root})
            wall = time.perf_counter() - t0
            user = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime - before.ru_utime
            if proc.returncode:
                raise SystemExit(f"play: exit {proc.returncode}: {proc.stderr[-2000:]}")
            runs.append({"wall_s": wall, "user_s": user, "load_before": load})
            print(f"play {args.frames} frames x {args.targets} targets: {wall:.1f} s wall, "
                  f"{user:.1f} s user (load {load:.1f})", flush=True)
    record = {"label": args.label, "frames": args.frames, "targets": args.targets,
              "chain": args.chain or "default",
              "median_wall_s": statistics.median(x["wall_s"] for x in runs),
              "median_user_s": statistics.median(x["user_s"] for x in runs),
              "user_s_per_frame": statistics.median(x["user_s"] for x in runs) / args.frames,
              "cpus": os.cpu_count(), "runs": runs}
    history = []
    if Path(args.out).exists():
        old = json.loads(Path(args.out).read_text())
        history = old.pop("history", []) + [{"label": old.pop("label", "earlier"), **old}]
    write_json(args.out, {**record, "history": history}, newline=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
