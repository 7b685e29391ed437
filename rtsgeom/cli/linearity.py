"""``rtsgeom linearity``: the synthesized angle against the set angle across a front-end pair's
span (``--pair I J``), for every adjacent pair of the arc (``--pair all``), or as an azimuth x
elevation error map over a cell of 3 or 4 front ends (``--grid N``)."""

from __future__ import annotations

import numpy as np

from .._lib.io import write_json
from ..analysis.linearity import linearity
from ..calibration.pair import calibrate_pair
from ..errors import AngleUnreachable, ParameterError, UsageError
from ..geometry import build_setup
from ..paths import exact_paths
from ..radar.steering import Steering
from ..scene.registry import SYNTHESIS_MODES
from ._common import (emit_result, load_scene_checked, number, output_folder, pair_options,
                      prepare_arc, prepare_pair, print_json, steps)


def cmd_linearity(args) -> int:
    with output_folder(args.out, [args.scene]) as stage:
        return _linearity(args, stage)


def _linearity(args, stage) -> int:
    if list(args.pair) == ["all"]:
        return _linearity_arc(args, stage)
    if getattr(args, "grid", None):  # 2-D: an azimuth x elevation error map over one cell
        return _linearity_grid(args, stage)
    with steps(args.quiet or args.json) as step:
        step("measuring each front end alone")
        scene, setup, pair, paths, probe = prepare_pair(args)
        cal = None
        if not args.uncalibrated:
            step("calibrating the pair")
            cal = calibrate_pair(setup, paths, pair, probe, seed=scene.seed)
        step(f"sweeping {args.points} set-points ({args.amplitudes} amplitudes)")
        lin = linearity(setup, paths, pair, args.amplitudes, probe, cal, args.points, scene.seed,
                        args.end_angles)

    def figure():
        from ..viz.figures import linearity_figure
        return linearity_figure(lin.set_deg, {args.amplitudes: lin.detected_deg},
                                {args.amplitudes: lin.amplitude_db}, pair=pair)
    emit_result(args, stage, "linearity.png", "linearity", lin.to_dict(), figure,
                f"{args.amplitudes} ({'calibrated' if cal else 'uncalibrated'}, "
                f"{args.end_angles} end angles): max |error| "
                f"{lin.max_abs_error_deg:.4f} deg over {len(lin.set_deg)} set-points")
    return 0


def _linearity_grid(args, stage) -> int:
    with steps(args.quiet or args.json) as step:
        step("measuring each front end alone")
        scene = load_scene_checked(args.scene)
        setup = build_setup(scene)
        if Steering.auto(setup.rut, scene.radar).dims != 2:
            raise UsageError("linearity --grid needs a RuT with elevation (an array with "
                             "elevation extent, e.g. radar.use_elevation_tx = true)")
        paths = exact_paths(setup)
        step(f"{'calibrating the channels, then ' if not args.uncalibrated else ''}"
             f"synthesizing a {args.grid} x {args.grid} grid ({args.amplitudes} amplitudes)")
        try:
            em = linearity(setup, paths, mode=args.amplitudes, points=args.grid,
                           seed=scene.seed, calibrate=not args.uncalibrated)
        except (ParameterError, AngleUnreachable) as exc:
            raise UsageError(f"{args.scene}: {exc}") from None
    mx = em.max_abs_error_deg
    emit_result(args, stage, "linearity_grid.png", "linearity_grid", em.to_dict(), em.plot,
                f"{args.amplitudes} ({'calibrated' if em.calibrated else 'uncalibrated'}): max "
                f"|error| azimuth {mx[0]:.4f} deg, elevation {mx[1]:.4f} deg over "
                f"{em.set_deg.shape[0]} set-points")
    return 0


def _linearity_arc(args, folder) -> int:
    """``--pair all``: every adjacent pair's linearity in one run; one JSON entry per pair plus
    the arc's. ``folder``: where the ``--out`` files go (None: no ``--out``)."""
    with steps(args.quiet or args.json) as step:
        step("measuring each front end alone")
        scene, setup, pairs, paths, probe = prepare_arc(args)
        lins = []
        for pair in pairs:
            cal = None
            if not args.uncalibrated:
                step(f"calibrating pair {pair}")
                cal = calibrate_pair(setup, paths, pair, probe, seed=scene.seed)
            step(f"pair {pair}: sweeping {args.points} set-points ({args.amplitudes} amplitudes)")
            lins.append(linearity(setup, paths, pair, args.amplitudes, probe, cal, args.points,
                                  scene.seed, args.end_angles))
    worst = [lin.max_abs_error_deg for lin in lins]
    out = {"pairs": [lin.to_dict() for lin in lins],
           "arc": {"pairs": [list(p) for p in pairs], "max_abs_error_deg": max(worst),
                   "worst_pair": list(pairs[int(np.argmax(worst))]),
                   "calibrated": not args.uncalibrated, "amplitudes": args.amplitudes}}
    if folder is not None:
        from ..viz.figures import linearity_figure, save_figure
        for pair, lin in zip(pairs, lins):
            save_figure(linearity_figure(lin.set_deg, {args.amplitudes: lin.detected_deg},
                                         {args.amplitudes: lin.amplitude_db}),
                        folder / f"linearity_{pair[0]}_{pair[1]}.png")
        write_json(folder / "linearity.json", out)
    if args.json:
        print_json(out)
        return 0
    state = "uncalibrated" if args.uncalibrated else "calibrated"
    for pair, lin in zip(pairs, lins):
        print(f"pair {pair}: {args.amplitudes} ({state}): max |error| "
              f"{lin.max_abs_error_deg:.4f} deg over {len(lin.set_deg)} set-points")
    print(f"arc ({len(pairs)} pairs): max |error| {max(worst):.4f} deg (pair "
          f"{tuple(out['arc']['worst_pair'])})")
    return 0


def register(sub) -> None:
    p = sub.add_parser("linearity", help="synthesized-angle linearity across a pair's span")
    pair_options(p)
    p.add_argument("--end-angles", choices=("geometric", "measured"),
                   default="geometric",
                   help="front-end angles in the paper/array-factor closed forms: "
                        "geometric (default) or measured (each alone, as the RuT "
                        "detects it)")
    p.add_argument("--amplitudes", choices=SYNTHESIS_MODES,
                   default="exact", help="amplitude-ratio mode (default exact)")
    p.add_argument("--uncalibrated", action="store_true",
                   help="no phase/amplitude calibration (delay offset 0)")
    p.add_argument("--grid", type=number(2, 50, integer=True), default=None,
                   metavar="N", help="2-D: an N x N azimuth/elevation error map over "
                                     "the cell of the scene's 3 or 4 front ends "
                                     "(writes linearity_grid.png and .json)")
    p.add_argument("--points", type=number(3, 1001, integer=True), default=21,
                   help="set-points across the span (default 21)")
    p.set_defaults(func=cmd_linearity)
