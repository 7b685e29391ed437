"""``rtsgeom info | paths | export-mesh``: the setup's geometry."""

from __future__ import annotations


from ..geometry import build_setup
from ..pipeline.info import format_info, scene_info
from .._lib.io import write_text
from ..scene.registry import PATH_METHODS
from ._common import load_scene_checked, output_file, output_path, print_json, scene_arg


def cmd_info(args) -> int:
    import sys
    from ..pipeline.info import unreachable_warnings
    setup = build_setup(load_scene_checked(args.scene))
    info = scene_info(setup, reachable=True)
    from ..radar.budget import static_budget
    info["link_budget"] = static_budget(setup).to_dict()
    for w in unreachable_warnings(info, skip_outside_geometric=True):  # those: validate's
        print(f"rtsgeom: warning: {args.scene}: {w}", file=sys.stderr)
    if args.json:
        print_json(info)
    else:
        print(format_info(info))
    return 0


def cmd_paths(args) -> int:
    output_file(args.out, [args.scene])
    setup = build_setup(load_scene_checked(args.scene))
    from ..paths import compute_paths
    paths = compute_paths(setup, args.method)
    write_text(args.out, paths.to_csv())
    print(f"wrote {len(paths)} paths ({paths.method}) to {args.out}")
    return 0


def cmd_export_mesh(args) -> int:
    from ..geometry.export import export_setup
    output_file(args.out, [args.scene])
    setup = build_setup(load_scene_checked(args.scene))
    path = export_setup(setup, args.out)  # OutputError for an unknown format: exit 2
    print(f"wrote {path}")
    return 0


def register(sub) -> None:
    p = sub.add_parser("info", help="summary of a scene: elements, front ends, far-field figures")
    scene_arg(p)
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    p.set_defaults(func=cmd_info)

    p = sub.add_parser("paths", help="per-element propagation paths as CSV")
    scene_arg(p)
    p.add_argument("--out", type=output_path, required=True, help="CSV file to write")
    p.add_argument("--method", choices=tuple(PATH_METHODS), default="exact",
                   help="exact line-of-sight distances (default) or Sionna RT ray tracing")
    p.set_defaults(func=cmd_paths)

    p = sub.add_parser("export-mesh", help="export the setup as GLB/PLY/OBJ/STL")
    scene_arg(p)
    p.add_argument("--out", type=output_path, required=True, help="mesh file (.glb, .ply, .obj, .stl)")
    p.set_defaults(func=cmd_export_mesh)
