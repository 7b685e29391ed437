"""``rtsgeom paths``: the per-element propagation paths of a scene as CSV."""

from __future__ import annotations

from .._lib.io import write_text
from ..geometry import build_setup
from ..paths import compute_paths
from ..scene.registry import PATH_METHODS
from ._common import load_scene_checked, output_file, output_file_path, scene_arg


def cmd_paths(args) -> int:
    output_file(args.out, [args.scene])
    setup = build_setup(load_scene_checked(args.scene))
    paths = compute_paths(setup, args.method)
    write_text(args.out, paths.to_csv())
    print(f"wrote {len(paths)} paths ({paths.method}) to {args.out}")
    return 0


def register(sub) -> None:
    p = sub.add_parser("paths", help="per-element propagation paths as CSV")
    scene_arg(p)
    p.add_argument("--out", type=output_file_path, required=True, help="CSV file to write")
    p.add_argument("--method", choices=tuple(PATH_METHODS), default="exact",
                   help="exact line-of-sight distances (default) or Sionna RT ray tracing")
    p.set_defaults(func=cmd_paths)
