"""Fuzz the inputs beside the scene: probe-capture sidecars and calibration files, and the
arguments of the newer entry points (``transfer``, ``drive_tolerance``, ``Playback``,
``identify(radar_channels=True)``).

The mutators of :mod:`benchmarks.fuzz_scene` change the JSON documents that ``rtsgeom adc
--active`` and ``rtsgeom calibrate --out`` write. Every input must end in a result with finite
numbers or in the input's own error (``CaptureError`` naming the sidecar, ``SceneError``
naming the calibration file); anything else is reported and the exit code is 1.

The entry points get one argument replaced by a hostile value (:data:`HOSTILE`: wrong types,
NaN, infinities, -0, huge and negative numbers, arrays, strings), the others small and valid;
each call must return a result whose numbers are finite or raise an ``RtsgeomError`` (any other
exception is a failure). ``identify-joint`` fits both front ends' captures with the radar's
channels after mutating one sidecar, or (one in four) captures of a 1.2 m arc against the 1 m
scene, which must be refused.

    python -m benchmarks.fuzz_inputs --inputs 2000 --seed 0 [--kind sidecar|calibration|
        transfer|drive_tolerance|play|identify-joint|both|entry|all]
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
import warnings
from pathlib import Path

import numpy as np

from benchmarks.fuzz_scene import DEFAULT_SCENE, FuzzFailure, mutate_doc
from rtsgeom.calibration.file import load_calibration
from rtsgeom.errors import CaptureError, RtsgeomError, SceneError
from rtsgeom.geometry import build_setup
from rtsgeom.identify import measure, read_capture, simulate_capture, write_capture
from rtsgeom.scene import load_scene

__all__ = ["Inputs", "run_one", "run_entry", "main", "HOSTILE", "ENTRY_KINDS"]

#: values an argument of an entry point is replaced by (one per call)
HOSTILE = (None, True, False, -1, 0, 1, 2, 2.5, -0.0, math.nan, math.inf, -math.inf, 1e12,
           10 ** 30, -5, "x", "5", "", [], (0.1,), (0.1, 0.1), (0.1, 0.1, 0.1), (1e6, 0, 0),
           [0.1, 0.1, 0.1], np.array([1.0, 2.0]), np.float64(0.5), np.int64(3), 1j, {}, "exact",
           "nearest", "normal")
#: the entry points: name -> (arguments with small valid values)
ENTRY_ARGS = {
    "transfer": {"radars": 3, "sigma_phase_deg": 5.0, "sigma_gain_db": 0.5, "points": 3,
                 "spec_deg": 0.1, "seed": 1},
    "drive_tolerance": {"sigma_mm": (0.1, 0.1, 0.1), "draws": 50, "seed": 1,
                        "distribution": "normal", "spec_deg": 0.1},
    "play": {"amplitudes": "nearest", "paths": "exact", "baseline": False, "bins": 2,
             "workers": 1},
}
ENTRY_KINDS = (*ENTRY_ARGS, "identify-joint")


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


def _entry_scenes(inp: Inputs):
    if not hasattr(inp, "drive"):
        inp.drive = load_scene(Path(DEFAULT_SCENE).parent / "crossing.toml")
        # a short drive: three frames
        inp.drive = inp.drive.evolve(scenario=inp.drive.scenario.evolve(
            duration_s=2 * inp.drive.scenario.frame_period_s))
        sim = build_setup(inp.scene)
        inp.joint = {}
        for q in range(sim.fe.count):
            name = f"joint{q}.npy"
            inp.joint[name] = write_capture(simulate_capture(sim, q, seed=10 + q), sim.rut,
                                            inp.folder / name, "npy")
        # captures of another arc (1.2 m, the scene's is 1 m): must be refused, not fitted
        wide = build_setup(inp.scene.evolve(rts=inp.scene.rts.evolve(arc_radius_m=1.2)))
        inp.arc = []
        for q in range(wide.fe.count):
            f = inp.folder / f"arc{q}.npy"
            write_capture(simulate_capture(wide, q, seed=20 + q), wide.rut, f, "npy")
            inp.arc.append(f)
    return inp


def run_entry(inp: Inputs, kind: str, rng: random.Random) -> str:
    """One call of an entry point with one argument hostile: "valid" or "rejected";
    :class:`FuzzFailure` or any other exception when the contract is broken."""
    import rtsgeom
    from rtsgeom.identify import identify
    inp = _entry_scenes(inp)
    if kind == "identify-joint" and rng.random() < 0.25:
        try:
            res = identify(inp.scene, [read_capture(f) for f in inp.arc], radar_channels=True)
        except RtsgeomError:
            return "rejected"
        raise FuzzFailure("accepted captures of a 1.2 m arc against the 1 m scene "
                          f"(residual {res.to_dict()['residual_rms']:.3g})")
    if kind == "identify-joint":
        name = rng.choice(sorted(inp.joint))
        doc = mutate_doc(copy.deepcopy(inp.joint[name]), rng)
        (inp.folder / (name + ".json")).write_text(json.dumps(doc, allow_nan=True, default=str),
                                                   encoding="utf-8")
        try:
            caps = [read_capture(inp.folder / n, shape=(120, 8, 512)) for n in sorted(inp.joint)]
            res = identify(inp.scene, caps, radar_channels=True)
        except RtsgeomError:
            return "rejected"
        finally:  # the next input starts from the written sidecar
            (inp.folder / (name + ".json")).write_text(json.dumps(inp.joint[name]),
                                                       encoding="utf-8")
        _finite(res.to_dict(), "identify")
        return "valid"
    args = dict(ENTRY_ARGS[kind])
    key = rng.choice(sorted(args) + ["scene"])
    value = rng.choice(HOSTILE + ((inp.scene, "scenes/crossing.toml") if key == "scene" else ()))
    scene = value if key == "scene" else (inp.scene if kind == "transfer" else inp.drive)
    if key != "scene":
        args[key] = value
    try:
        if kind == "transfer":
            res = rtsgeom.transfer(scene, **args)
        elif kind == "drive_tolerance":
            res = rtsgeom.drive_tolerance(scene, **args)
        else:
            res = rtsgeom.Playback(**args)(scene)
    except RtsgeomError:
        return "rejected"
    out = res.summary_json() if kind == "play" else res.to_dict()
    _finite(out, kind)
    return "valid"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.fuzz_inputs")
    ap.add_argument("--inputs", type=int, default=1000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--kind", choices=("sidecar", "calibration", "both", "entry", "all",
                                       *ENTRY_KINDS), default="both")
    args = ap.parse_args(argv)
    kinds = {"both": ("sidecar", "calibration"), "entry": ENTRY_KINDS,
             "all": ("sidecar", "calibration", *ENTRY_KINDS)}.get(args.kind, (args.kind,))
    counts: collections.Counter = collections.Counter()
    failures = 0
    with tempfile.TemporaryDirectory() as tmp:
        inp = Inputs(Path(tmp))
        for i in range(args.inputs):
            kind = kinds[i % len(kinds)]
            try:
                run = run_entry if kind in ENTRY_KINDS else run_one
                with warnings.catch_warnings():  # the studies' own notes are not failures
                    warnings.simplefilter("ignore")
                    counts[(kind, run(inp, kind, random.Random(f"{args.seed}:{i}")))] += 1
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
