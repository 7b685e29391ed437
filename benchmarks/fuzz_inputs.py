"""Fuzz the inputs beside the scene: probe-capture sidecars and calibration files.

The mutators of :mod:`benchmarks.fuzz_scene` change the JSON documents that ``rtsgeom adc
--active`` and ``rtsgeom calibrate --out`` write. Every input must end in a result with finite
numbers or in the input's own error (``CaptureError`` naming the sidecar, ``SceneError``
naming the calibration file); anything else is reported and the exit code is 1.

    python -m benchmarks.fuzz_inputs --inputs 2000 --seed 0 [--kind sidecar|calibration]
"""

from __future__ import annotations

import argparse
import collections
import copy
import json
import math
import random
import sys
import tempfile
import traceback
from pathlib import Path

import numpy as np

from benchmarks.fuzz_scene import DEFAULT_SCENE, FuzzFailure, mutate_doc
from rtsgeom.calibration.file import load_calibration
from rtsgeom.errors import CaptureError, SceneError
from rtsgeom.geometry import build_setup
from rtsgeom.identify import measure, read_capture, simulate_capture, write_capture
from rtsgeom.scene import load_scene

__all__ = ["Inputs", "run_one", "main"]


class Inputs:
    """One capture of front end 0 of the bundled scene (.npy and .bin with sidecars) and a
    calibration file of the bundled scene, written once into ``folder``."""

    def __init__(self, folder: Path):
        self.folder = folder
        self.scene = load_scene(DEFAULT_SCENE)
        self.setup = build_setup(self.scene)
        cap = simulate_capture(self.setup, 0, seed=1)
        self.sidecars = {}
        for fmt, name in (("npy", "cap.npy"), ("dca1000", "cap.bin")):
            self.sidecars[name] = write_capture(cap, self.setup.rut, folder / name, fmt)
        n = self.setup.fe.count
        self.calibration = {
            "format": "rtsgeom-calibration", "pair": [0, 1], "delta_tau_s": 1.2e-10,
            "residual_error_deg": 0.01, "period_s": 1.0 / self.scene.rts.f_rts_hz,
            "probe_angles_deg": [5.0, 10.0], "front_end_angles_deg": [3.4, 12.2][:n],
            "gain_correction": [1.0] * n, "sweep": [{"delta_tau_s": 1e-10,
                                                     "angle_error_deg": 0.1}]}


def _finite(obj, where: str) -> None:
    if isinstance(obj, dict):
        for k, v in obj.items():
            _finite(v, f"{where}.{k}")
    elif isinstance(obj, (list, tuple)):
        for i, v in enumerate(obj):
            _finite(v, f"{where}[{i}]")
    elif isinstance(obj, np.ndarray):
        if obj.dtype.kind in "fc" and not np.all(np.isfinite(obj)):
            raise FuzzFailure(f"accepted input with a non-finite value in {where}")
    elif isinstance(obj, float) and not math.isfinite(obj):
        raise FuzzFailure(f"accepted input with a non-finite value: {where} = {obj}")


def run_one(inp: Inputs, kind: str, rng: random.Random) -> str:
    """One mutated input: "valid" or "rejected"; :class:`FuzzFailure` or any other exception
    when the contract is broken."""
    if kind == "sidecar":
        name = rng.choice(sorted(inp.sidecars))
        doc = mutate_doc(copy.deepcopy(inp.sidecars[name]), rng)
        side = inp.folder / (name + ".json")
        side.write_text(json.dumps(doc, allow_nan=True, default=str), encoding="utf-8")
        try:
            cap = read_capture(inp.folder / name, shape=(120, 8, 512))
            y, sigma2, _ = measure(inp.setup, cap)
        except CaptureError as exc:
            if str(inp.folder) not in str(exc) and not str(exc).startswith("capture"):
                raise FuzzFailure(f"CaptureError without the file's name: {exc}") from None
            return "rejected"
        _finite([y, sigma2, cap.range_m, cap.velocity_mps, cap.amplitude], "capture")
        return "valid"
    doc = mutate_doc(copy.deepcopy(inp.calibration), rng)
    try:
        probe, cals = load_calibration(doc, inp.setup)
    except SceneError as exc:
        if not str(exc).startswith("calibration file"):
            raise FuzzFailure(f"SceneError without the source: {exc}") from None
        return "rejected"
    _finite([probe.angle_rad, probe.gain_correction]
            + [c.delta_tau_s for c in cals.values()], "calibration")
    return "valid"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.fuzz_inputs")
    ap.add_argument("--inputs", type=int, default=1000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--kind", choices=("sidecar", "calibration", "both"), default="both")
    args = ap.parse_args(argv)
    kinds = ("sidecar", "calibration") if args.kind == "both" else (args.kind,)
    counts: collections.Counter = collections.Counter()
    failures = 0
    with tempfile.TemporaryDirectory() as tmp:
        inp = Inputs(Path(tmp))
        for i in range(args.inputs):
            kind = kinds[i % len(kinds)]
            try:
                counts[(kind, run_one(inp, kind, random.Random(f"{args.seed}:{i}")))] += 1
            except Exception as exc:  # noqa: BLE001 - every broken contract is reported
                failures += 1
                counts[(kind, "FAILED")] += 1
                print(f"input {i} ({kind}): {type(exc).__name__}: {str(exc)[:300]}")
                if not isinstance(exc, FuzzFailure):
                    traceback.print_exc(limit=3)
    for (kind, outcome), n in sorted(counts.items()):
        print(f"{kind:12s} {outcome:9s} {n}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
