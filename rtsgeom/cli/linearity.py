"""``rtsgeom linearity``: the synthesized angle against the set angle across a front-end pair's
span (``--pair I J``), for every adjacent pair of the arc (``--pair all``), or as an azimuth x
elevation error map over a cell of 3 or 4 front ends (``--grid N``)."""

from __future__ import annotations

from ..analysis.linearity import END_ANGLES
from ..analysis.linearity_study import LinearityStudy
from ..scene.registry import SYNTHESIS_MODES
from ._common import (flagged, load_scene_checked, number, output_folder, pair_options,
                      print_json, steps)


def study_of(args, step=None) -> LinearityStudy:
    """The :class:`~rtsgeom.analysis.linearity_study.LinearityStudy` the flags ask for."""
    pair = "all" if list(args.pair) == ["all"] else tuple(args.pair)
    return LinearityStudy(pair, args.amplitudes, not args.uncalibrated, args.points,
                          args.end_angles, args.grid, args.fir, step)


def cmd_linearity(args) -> int:
    with output_folder(args.out, [args.scene]) as stage:
        with steps(args.quiet or args.json) as step:
            scene = load_scene_checked(args.scene)
            with flagged(args):
                result = study_of(args, step)(scene)
        if stage is not None:
            result.write(stage)
        _print(args, result)
    return 0


def _print(args, result) -> None:
    if args.json:
        print_json(result.to_dict())
        return
    state = "calibrated" if result.calibrated else "uncalibrated"
    if list(args.pair) == ["all"]:
        for pair, lin in zip(result.pairs, result.linearities):
            print(f"pair {pair}: {args.amplitudes} ({state}): max |error| "
                  f"{lin.max_abs_error_deg:.4f} deg over {len(lin.set_deg)} set-points")
        print(f"arc ({len(result.pairs)} pairs): max |error| {max(result.worst_deg):.4f} deg "
              f"(pair {result.worst_pair})")
    elif result.dims == 2:
        mx = result.max_abs_error_deg
        print(f"{args.amplitudes} ({state}): max |error| azimuth {mx[0]:.4f} deg, elevation "
              f"{mx[1]:.4f} deg over {result.set_deg.shape[0]} set-points")
    else:
        print(f"{args.amplitudes} ({state}, {args.end_angles} end angles): max |error| "
              f"{result.max_abs_error_deg:.4f} deg over {len(result.set_deg)} set-points")


def register(sub) -> None:
    p = sub.add_parser("linearity", help="synthesized-angle linearity across a pair's span")
    pair_options(p)
    p.add_argument("--end-angles", choices=END_ANGLES,
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
