"""The benchmarks' result files: one JSON writer and one CSV writer for all of them.

Standard library ``json`` and ``csv`` rather than pandas: the rows are lists of flat dicts
that are already in memory, ``csv.DictWriter`` writes them as they are (pandas would format
floats and missing keys its own way and change the committed files' bytes), and a
benchmark should not need pandas to be imported just to write a few hundred lines.
"""

from __future__ import annotations

import csv
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

__all__ = ["write_json", "write_csv", "csv_writer", "write_json_csv", "timed_rtsgeom"]


def timed_rtsgeom(argv: list[str], root: Path, bytecode: bool | None = None) -> dict:
    """One whole process ``python -m rtsgeom argv`` importing rtsgeom from ``root``
    (run in ``root``: ``python -m`` puts the working directory first on the path): wall,
    user and user + system CPU (s, its forked children included), the load average before,
    its lines on stderr. A non-zero exit ends the benchmark with its stderr's tail.

    ``bytecode``: None, Python as this environment sets it; True, as a user's Python (it
    reads and writes ``__pycache__``: rtsgeom's modules are compiled on the first run only);
    False, never writing it (``PYTHONDONTWRITEBYTECODE=1``, as some sandboxes and CI images
    set: rtsgeom's modules, installed editable, are compiled at every start)."""
    env = {**os.environ, "PYTHONPATH": str(root)}
    if bytecode is not None:
        env.pop("PYTHONDONTWRITEBYTECODE", None)
        if not bytecode:
            env["PYTHONDONTWRITEBYTECODE"] = "1"
    load = os.getloadavg()[0]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "rtsgeom", *argv], capture_output=True,
                          text=True, cwd=root, env=env)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode:
        raise SystemExit(f"{root}: rtsgeom {' '.join(argv)}: exit {proc.returncode}: "
                         f"{proc.stderr[-2000:]}")
    user = after.ru_utime - before.ru_utime
    return {"wall_s": wall, "user_s": user, "cpu_s": user + after.ru_stime - before.ru_stime,
            "load_before": load, "stderr_lines": len(proc.stderr.splitlines())}


def write_json(path, obj, *, indent: int = 1, newline: bool = False, default=None) -> Path:
    """``obj`` as JSON at ``path`` (``indent`` spaces; a final ``\\n`` when ``newline``;
    ``default`` as in :func:`json.dumps`, for values JSON cannot hold)."""
    path = Path(path)
    path.write_text(json.dumps(obj, indent=indent, default=default) + ("\n" if newline else ""))
    return path


def csv_writer(fh, fieldnames) -> csv.DictWriter:
    """A :class:`csv.DictWriter` on the open file ``fh`` with its header written."""
    w = csv.DictWriter(fh, fieldnames=list(fieldnames))
    w.writeheader()
    return w


def write_csv(path, rows: list[dict], fieldnames=None) -> Path:
    """``rows`` as CSV at ``path``; columns ``fieldnames``, else the first row's keys in order."""
    path = Path(path)
    with open(path, "w", newline="") as fh:
        csv_writer(fh, list(rows[0]) if fieldnames is None else fieldnames).writerows(rows)
    return path


def write_json_csv(stem, obj, rows: list[dict], *, newline: bool = False,
                   fieldnames=None) -> tuple[Path, Path]:
    """``obj`` to ``stem.json`` and ``rows`` to ``stem.csv`` (the usual pair of a benchmark;
    ``stem`` gets the suffixes appended, it is not treated as having one)."""
    return (write_json(str(stem) + ".json", obj, newline=newline),
            write_csv(str(stem) + ".csv", rows, fieldnames))
