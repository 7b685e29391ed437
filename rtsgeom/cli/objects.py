"""``rtsgeom objects``: the design question for an extended object -- the smallest number of
front ends (spacing) and targets per channel that reproduce what the radar sees of the scene's
first object over its ranges (``analysis.object_design``, docs/objects.md)."""

from __future__ import annotations

import argparse

from ..errors import ParameterError, UsageError
from .._lib.io import write_json
from ._common import (load_scene_checked, number, numbers, output_folder, output_path,
                      print_outputs,
                      scene_arg, steps)


def _budgets(text: str) -> tuple:
    out = []
    for x in text.split(","):
        x = x.strip()
        if x == "none":
            out.append(None)
        elif x.isdigit() and int(x) >= 1:
            out.append(int(x))
        else:
            raise argparse.ArgumentTypeError(f"{text!r}: must be integers >= 1 or 'none' "
                                             "(no limit), comma-separated")
    return tuple(out)


def cmd_objects(args) -> int:
    from ..analysis.object_design import ObjectDesign
    scene = load_scene_checked(args.scene)
    try:
        study = ObjectDesign(args.ranges, args.spacings, args.budgets, args.min_share,
                             args.max_centroid_deg)
    except ParameterError as exc:
        raise UsageError(str(exc)) from None
    with output_folder(args.out, [args.scene]) as stage, steps(args.quiet or args.json) as step:
        try:
            res = study(scene, progress=step)
        except ParameterError as exc:
            raise UsageError(str(exc)) from None
        out = res.to_dict()
        if stage is not None:
            from ..viz.figures import save_figure
            write_json(stage / "objects.json", out)
            save_figure(res.plot(), stage / "objects.png")
    return print_outputs(args, "objects", out, lambda o: repr(res))


def register(sub) -> None:
    p = sub.add_parser("objects", help="extended object: the smallest front-end arc and "
                                       "per-channel budget that reproduce it over its ranges")
    scene_arg(p)
    p.add_argument("--ranges", type=numbers(0.1, 1e4, 64, "m", "5,10,20"),
                   default=(5.0, 10.0, 15.0, 20.0, 25.0, 30.0),
                   metavar="START:STOP:STEP", help="the object's ranges in m (default 5:30:5)")
    p.add_argument("--spacings", type=number(0.5, 60.0), nargs="+", default=(8.0, 16.0),
                   metavar="DEG", help="front-end spacings (default 8 16)")
    p.add_argument("--budgets", type=_budgets, default=(None, 2), metavar="N,none",
                   help="targets per channel, comma-separated; none = no limit "
                        "(default none,2)")
    p.add_argument("--min-share", type=number(0.0, 1.0), default=0.9,
                   help="share of the truth twin's detections reproduced (default 0.9)")
    p.add_argument("--max-centroid-deg", type=number(0.0, 90.0), default=0.5,
                   help="largest centroid azimuth difference (default 0.5 deg)")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.add_argument("--out", type=output_path, default=None, help="folder for the plot and JSON")
    p.add_argument("--quiet", action="store_true", help="no progress output")
    p.set_defaults(func=cmd_objects)
