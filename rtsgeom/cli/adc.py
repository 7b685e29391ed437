"""``rtsgeom adc``: the raw ADC cube of a scene (``.npy``) or a DCA1000 capture with its JSON
sidecar; with ``--active I``, front end I alone on a probe target, the capture
``rtsgeom identify`` reads."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .._lib.io import atomic_path, write_bytes, write_json
from ..errors import CaptureError, ParameterError, UsageError
from ..pipeline.run import run_scene
from ..radar.dca1000 import capture_layout, dca1000_meta, to_dca1000
from ..scene.registry import AOA_MODES
from ._common import (calibration_kw, load_scene_checked, number, output_file, output_file_path,
                      scene_arg, steps)


def cmd_adc(args) -> int:
    if args.format is None:  # from the file name: a .bin is a DCA1000 capture, else .npy
        args.format = "dca1000" if args.out.suffix.lower() == ".bin" else "npy"
    output_file(args.out, [args.scene])
    if args.format == "dca1000" or args.active is not None:
        output_file(Path(str(args.out) + ".json"), [args.scene])
    scene = load_scene_checked(args.scene)
    if args.active is not None:  # one front end alone on a probe target (rtsgeom identify)
        return _probe_capture(scene, args)
    with steps(args.quiet) as step:  # the calibration sweeps take about a minute
        step(f"simulating {scene.name} (calibration, ADC cube)")
        cube = run_scene(scene, "exact", args.amplitudes, **calibration_kw(args)).cube
    if args.format == "npy":
        with atomic_path(args.out) as tmp:
            with open(tmp, "wb") as fh:
                np.save(fh, cube.data)
        print(f"wrote {args.out}: complex64 {list(cube.shape)} "
              "[chirp_loop, virtual_channel, sample]")
    else:
        layout = capture_layout(scene.radar)
        try:
            raw, scale = to_dca1000(cube, layout)
        except ParameterError as exc:
            raise UsageError(f"--format dca1000: {exc}") from None
        write_bytes(args.out, raw)
        n_l, n_v, n_s = cube.shape
        meta = dca1000_meta(layout, scale, n_l * len(cube.rut.tx_order), cube.rut, n_s)
        write_json(Path(str(args.out) + ".json"), meta)
        print(f"wrote {args.out} ({len(raw)} bytes, {layout.name}, scale {scale:.6g}) and "
              f"{args.out}.json")
    return 0


def _probe_capture(scene, args) -> int:
    """``rtsgeom adc SCENE --active I``: front end I alone with a probe target, on the setup as
    built (the scene's mounting errors), receiver noise at the scene's SNR."""
    from ..identify import setup_of, simulate_capture, write_capture  # only for --active
    for flag, given in (("--amplitudes", args.amplitudes), ("--calibration", args.calibration)):
        if given is not None:  # a probe capture has one front end: nothing to synthesize
            raise UsageError(f"{flag} {given}: not with --active (front end {args.active} "
                             "alone on a probe target: no pair, no calibration)")
    setup = setup_of(scene)
    seed = (scene.seed or 0) + args.active if args.seed is None else args.seed
    try:
        with steps(args.quiet) as step:
            step(f"simulating front end {args.active} alone with a probe target")
            cap = simulate_capture(setup, args.active, args.probe_range_m,
                                   args.probe_velocity_mps, seed)
            meta = write_capture(cap, setup.rut, args.out, args.format,
                                 capture_layout(scene.radar))
    except CaptureError as exc:
        raise UsageError(f"--active/--probe-range-m: {exc}") from None
    except ParameterError as exc:
        raise UsageError(f"--format {args.format}: {exc}") from None
    if not args.quiet:
        print(f"wrote {args.out} and {args.out}.json: front end {cap.active} alone, probe at "
              f"{cap.range_m:.3f} m, {cap.velocity_mps:+.3f} m/s ({meta['format']})")
    return 0


def register(sub) -> None:
    p = sub.add_parser("adc", help="save the raw ADC cube (.npy) or a DCA1000 capture")
    scene_arg(p)
    p.add_argument("--out", type=output_file_path, required=True, help="output file")
    p.add_argument("--format", choices=("npy", "dca1000"), default=None,
                   help="npy (complex64 cube) or dca1000 (TI's raw int16 capture + sidecar "
                        "JSON); default: dca1000 for a .bin file, else npy")
    p.add_argument("--amplitudes", choices=tuple(AOA_MODES), default=None,
                   help="AoA amplitude mode (default: the scene's rts.aoa_mode)")
    p.add_argument("--quiet", action="store_true", help="print nothing but errors")
    p.add_argument("--active", type=number(0, 10_000, integer=True), default=None, metavar="I",
                   help="capture front end I alone with a probe target (for rtsgeom identify; "
                        "the sidecar OUT.json records the probe)")
    p.add_argument("--probe-range-m", type=number(0.01, 1e4), default=None, metavar="R",
                   help="probe range with --active (default: the calibration's probe range)")
    p.add_argument("--probe-velocity-mps", type=number(-1e3, 1e3), default=0.0,
                   help="probe velocity with --active (default 0)")
    p.add_argument("--seed", type=number(0, 2**32 - 1, integer=True), default=None,
                   help="receiver-noise seed with --active (default: the scene's seed + I)")
    p.add_argument("--calibration", default=None, metavar="FILE",
                   help="use this calibration (DIR/calibration.json from `rtsgeom calibrate "
                        "--out DIR`) instead of calibrating again")
    p.set_defaults(func=cmd_adc)
