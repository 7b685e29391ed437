"""``rtsgeom info``: a summary of the scene's setup (elements, front ends, far-field figures,
the static link budget) as text or JSON."""

from __future__ import annotations

import sys

from ..geometry import build_setup
from ..pipeline.cells import shared_cell_warnings
from ..pipeline.info import format_info, scene_info, unreachable_warnings
from ..radar.budget import static_budget
from ._common import load_scene_checked, print_json, scene_arg


def cmd_info(args) -> int:
    setup = build_setup(load_scene_checked(args.scene))
    info = scene_info(setup, reachable=True)
    info["link_budget"] = static_budget(setup).to_dict()
    info["shared_cells"] = shared_cell_warnings(setup, setup.scene.targets)
    for w in (unreachable_warnings(info, skip_outside_geometric=True)  # others: validate's
              + info["shared_cells"]):
        print(f"rtsgeom: warning: {args.scene}: {w}", file=sys.stderr)
    if args.json:
        print_json(info)
    else:
        print(format_info(info))
    return 0


def register(sub) -> None:
    p = sub.add_parser("info", help="summary of a scene: elements, front ends, far-field figures")
    scene_arg(p)
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    p.set_defaults(func=cmd_info)
