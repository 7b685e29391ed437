"""``rtsgeom resolution``: can the bench emulate two targets the radar resolves, as real ones?
Two targets at ``C +- s/2`` in one range-Doppler cell, over separation x relative phase, through
the truth twin and the RTS (``analysis.resolution``); writes resolution.csv, summary.json and
resolution.png."""

from __future__ import annotations

import argparse

import numpy as np

from ..analysis.resolution import ResolutionStudy
from ._common import (load_scene_checked, number, output_folder, print_json, scene_arg, steps,
                      write_json)

_MAX_SEPARATIONS = 1000


def _grid(text: str) -> tuple[float, ...]:
    """``--separations-deg START:STOP:STEP`` (STOP included) in (0, 120] deg."""
    try:
        start, stop, step = (float(x) for x in text.split(":"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: must be START:STOP:STEP in deg, e.g. "
                                         "2:30:1") from None
    if not (0 < start <= stop <= 120 and step > 0 and np.isfinite([start, stop, step]).all()):
        raise argparse.ArgumentTypeError(f"{text!r}: must satisfy 0 < START <= STOP <= 120 "
                                         "and STEP > 0 (deg)")
    n = int(np.floor((stop - start) / step + 1e-9)) + 1
    if n > _MAX_SEPARATIONS:
        raise argparse.ArgumentTypeError(f"{text!r}: {n} separations; at most "
                                         f"{_MAX_SEPARATIONS}")
    return tuple(float(x) for x in start + step * np.arange(n))


def _phases(text: str) -> tuple[float, ...]:
    """``--phases-deg`` a comma-separated list in [-360, 360] deg."""
    try:
        got = tuple(float(x) for x in text.split(",") if x.strip())
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: must be comma-separated phases in deg, "
                                         "e.g. 0,90,180") from None
    if not got or len(got) > 36 or not all(np.isfinite(g) and abs(g) <= 360 for g in got):
        raise argparse.ArgumentTypeError(f"{text!r}: must be 1 to 36 phases in [-360, 360] deg")
    return got


def cmd_resolution(args) -> int:
    scene = load_scene_checked(args.scene)
    study = ResolutionStudy(range_m=args.range_m, velocity_mps=args.velocity_mps,
                            centre_deg=args.centre_deg,
                            separations_deg=args.separations_deg or (),
                            phases_deg=args.phases_deg, amplitudes=args.amplitudes)
    with output_folder(args.out, [args.scene]) as stage:
        with steps(args.quiet or args.json) as step:
            res = study(scene, progress=step)
        if stage is not None:
            from ..viz.figures import save_figure
            (stage / "resolution.csv").write_text(res.to_csv(), encoding="utf-8")
            write_json(stage / "summary.json", res.to_dict())
            save_figure(res.plot(), stage / "resolution.png")
    if args.json:
        print_json(res.to_dict())
    elif not args.quiet:
        print(res)
        if args.out is not None:
            print(f"wrote {args.out}/resolution.csv, summary.json, resolution.png")
    return 0


def register(sub) -> None:
    p = sub.add_parser("resolution", help="angular resolution test: two targets in one cell, "
                                          "the truth twin beside the RTS over separation x "
                                          "phase")
    scene_arg(p)
    p.add_argument("--out", type=str, default=None, help="output folder (resolution.csv, "
                   "summary.json, resolution.png)")
    p.add_argument("--range-m", type=number(0.1, 1e4), default=None,
                   help="the targets' range, m (default 20, or half the range axis)")
    p.add_argument("--velocity-mps", type=number(-1e3, 1e3), default=0.0,
                   help="their velocity, m/s (default 0)")
    p.add_argument("--centre-deg", type=number(-90.0, 90.0), default=None,
                   help="C, the targets' midpoint, deg (default: the middle of the arc)")
    p.add_argument("--separations-deg", type=_grid, default=None,
                   help="START:STOP:STEP separations s, deg (default 2:30:1, cut to the arc)")
    p.add_argument("--phases-deg", type=_phases, default=(0.0, 90.0, 180.0),
                   help="relative phases of the targets' echoes at the RuT's phase centre, deg "
                        "(default 0,90,180; two real targets at one range are in phase)")
    p.add_argument("--amplitudes", choices=["exact", "array-factor", "paper"], default=None,
                   help="the RTS's AoA mode (default: the scene's rts.aoa_mode)")
    p.add_argument("--json", action="store_true", help="print summary.json to stdout")
    p.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors")
    p.set_defaults(func=cmd_resolution)
