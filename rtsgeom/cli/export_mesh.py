"""``rtsgeom export-mesh``: the setup as a mesh file (GLB, PLY, OBJ, STL)."""

from __future__ import annotations

from ..geometry import build_setup
from ._common import load_scene_checked, output_file, output_path, scene_arg


def cmd_export_mesh(args) -> int:
    from ..geometry.export import export_setup  # trimesh
    output_file(args.out, [args.scene])
    setup = build_setup(load_scene_checked(args.scene))
    path = export_setup(setup, args.out)  # OutputError for an unknown format: exit 2
    print(f"wrote {path}")
    return 0


def register(sub) -> None:
    p = sub.add_parser("export-mesh", help="export the setup as GLB/PLY/OBJ/STL")
    scene_arg(p)
    p.add_argument("--out", type=output_path, required=True, help="mesh file (.glb, .ply, .obj, .stl)")
    p.set_defaults(func=cmd_export_mesh)
