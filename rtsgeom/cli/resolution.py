"""``rtsgeom resolution``: can the bench emulate two targets the radar resolves, as real ones?
Two targets at ``C +- s/2`` in one range-Doppler cell, over separation x relative phase, through
the truth twin and the RTS (``analysis.resolution``); writes resolution.csv, summary.json and
resolution.png."""

from __future__ import annotations

from ..analysis.resolution import ResolutionStudy
from ._common import (load_scene_checked, number, numbers, output_folder, output_path,
                      print_outputs, scene_arg, steps)


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
            res.write(stage)
    return print_outputs(args, "resolution", res.to_dict(), lambda _: str(res),
                         ("resolution.csv", "summary.json", "resolution.png"))


def register(sub) -> None:
    p = sub.add_parser("resolution", help="angular resolution test: two targets in one cell, "
                                          "the truth twin beside the RTS over separation x "
                                          "phase")
    scene_arg(p)
    p.add_argument("--out", type=output_path, default=None,
                   help="output folder (resolution.csv, summary.json, resolution.png)")
    p.add_argument("--range-m", type=number(0.1, 1e4), default=None,
                   help="the targets' range, m (default 20, or half the range axis)")
    p.add_argument("--velocity-mps", type=number(-1e3, 1e3), default=0.0,
                   help="their velocity, m/s (default 0)")
    p.add_argument("--centre-deg", type=number(-90.0, 90.0), default=None,
                   help="C, the targets' midpoint, deg (default: the middle of the arc)")
    p.add_argument("--separations-deg", type=numbers(1e-3, 120.0, 1000, "deg", "10,20,30"),
                   default=None,
                   help="START:STOP:STEP separations s, deg (default 2:30:1, cut to the arc)")
    p.add_argument("--phases-deg", type=numbers(-360.0, 360.0, 36, "deg", "0,90,180"),
                   default=(0.0, 90.0, 180.0),
                   help="relative phases of the targets' echoes at the RuT's phase centre, deg "
                        "(default 0,90,180; two real targets at one range are in phase)")
    p.add_argument("--amplitudes", choices=["exact", "array-factor", "paper"], default=None,
                   help="the RTS's AoA mode (default: the scene's rts.aoa_mode)")
    p.add_argument("--json", action="store_true", help="print summary.json to stdout")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress output")
    p.set_defaults(func=cmd_resolution)
