"""``rtsgeom show``: the setup in 3D, as a PNG, an interactive HTML file or a window."""

from __future__ import annotations

import argparse
import os

from ..errors import UsageError
from ..geometry import build_setup
from ..scene.registry import PATH_METHODS
from ._common import load_scene_checked, output_file, output_path, scene_arg


def _window_size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not WIDTHxHEIGHT, e.g. 1600x1000") from None
    if not (64 <= w <= 8192 and 64 <= h <= 8192):
        raise argparse.ArgumentTypeError(f"{text}: width and height must be in [64, 8192] pixels")
    return w, h


def _load_paths(setup, method: str | None):
    if method is None:
        return None
    from ..paths import compute_paths
    try:  # for ray tracing: the table plus each reflection's hit points, which the view draws
        return compute_paths(setup, method, for_drawing=True)
    except ModuleNotFoundError as exc:
        if exc.name not in ("rtsgeom.paths.raytrace", "sionna", "sionna.rt"):
            raise
        raise UsageError(f"--paths {method} is not available here ({exc})") from None


def cmd_show(args) -> int:
    if not (args.png or args.html) and not os.environ.get("DISPLAY"):
        raise UsageError("no display to open a window on (DISPLAY is not set): write a file "
                         "with --png FILE and/or --html FILE")
    if args.png and args.png.suffix.lower() != ".png":
        raise UsageError(f"--png {args.png}: the file name must end in .png (the rendering is "
                         "written as PNG)")
    if args.html and args.html.suffix.lower() not in (".html", ".htm"):
        raise UsageError(f"--html {args.html}: the file name must end in .html")
    for out in (args.png, args.html):
        if out is not None:
            output_file(out, [args.scene])
    setup = build_setup(load_scene_checked(args.scene))
    paths = _load_paths(setup, args.paths)
    from ..viz.scene3d import VizError, export_setup_html, render_setup_png, show_setup
    try:
        if args.png:
            render_setup_png(setup, args.png, paths=paths, window_size=args.size)
            if not args.quiet:
                print(f"wrote {args.png}")
        if args.html:
            export_setup_html(setup, args.html, paths=paths)
            if not args.quiet:
                print(f"wrote {args.html}")
        if not (args.png or args.html):
            show_setup(setup, paths=paths, interactive=True, window_size=args.size)
    except VizError as exc:
        raise UsageError(str(exc)) from None
    return 0


def register(sub) -> None:
    p = sub.add_parser("show", help="3D view of the setup: PNG, interactive HTML or a window",
                       description="Draw the RuT, the front-end arc and antennas, the metal sheet "
                                   "with its cutouts and the virtual targets. Without --png or "
                                   "--html a window opens (needs a display).")
    scene_arg(p)
    p.add_argument("--paths", choices=tuple(PATH_METHODS), default=None,
                   help="also draw propagation paths: exact line of sight, or Sionna RT rays")
    p.add_argument("--png", type=output_path, metavar="FILE", help="write an off-screen rendering (PNG)")
    p.add_argument("--html", type=output_path, metavar="FILE",
                   help="write an interactive HTML view (needs trame-pyvista, nest-asyncio2)")
    p.add_argument("--size", type=_window_size, default=(1600, 1000), metavar="WxH",
                   help="image / window size in pixels (default 1600x1000)")
    p.add_argument("--quiet", action="store_true", help="print nothing on success")
    p.set_defaults(func=cmd_show)
