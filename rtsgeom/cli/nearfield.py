"""``rtsgeom nearfield``: the near-field violation of the arc against its radius: each front
end's angle bias alone (separation, parallax, beat frequency, curvature), the phase error
across the RuT's virtual array, and the synthesized-angle error of each pair (or cell)."""

from __future__ import annotations

import argparse
import math

import numpy as np

from ..analysis.nearfield import default_radii, nearfield
from ..errors import ParameterError, UsageError
from ._common import (load_scene_checked, number, output_folder, output_path, print_outputs,
                      scene_arg, steps)


def radius_sweep(text: str) -> tuple[float, float, int]:
    """argparse type of ``--radius-m A:B:N``: N log-spaced radii from A to B metres."""
    parts = text.split(":")
    try:
        if len(parts) != 3:
            raise ValueError
        a, b, n = float(parts[0]), float(parts[1]), int(parts[2])
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r} is not A:B:N (start and stop radius in m, number of radii)") from None
    if not (math.isfinite(a) and math.isfinite(b) and 0 < a < b) or not 2 <= n <= 200:
        raise argparse.ArgumentTypeError(
            f"{text}: needs 0 < A < B (m) and N in [2, 200]")
    return a, b, n


def _nearfield_text(d: dict) -> str:
    lines = [f"scene {d['scene']}: arc radius {d['scene_arc_radius_m']:g} m; azimuth virtual "
             f"aperture d_A {d['aperture_m'] * 1e3:.2f} mm, Fraunhofer distance 2 d_A^2/lambda "
             f"{d['fraunhofer_distance_m']:.3f} m",
             "single front end alone (phasor level, exact geometry), deg; phase error across the "
             "virtual array, deg; worst synthesized |error| over the pair's span, deg",
             "  R (m)  FE  geometric   bias   = separation + parallax + beat-f + curvature"
             "   phase p-p   rms  | pair  array-factor  exact"]
    for row in d["radii"]:
        syn = {s["pair"][0]: s for s in row["synthesis"] if "pair" in s}
        for fe in row["front_ends"]:
            s = syn.get(fe["index"])
            tail = ""
            if s is not None:
                af, ex = s["array_factor_max_abs_error_deg"], s["exact_max_abs_error_deg"]
                tail = (f" | {s['pair'][0]}-{s['pair'][1]}  "
                        f"{'n/a' if af is None else f'{af:11.4f}'}  "
                        f"{'n/a' if ex is None else f'{ex:.1e}'}")
            if "elevation_bias_deg" in fe:
                tail += (f" | el {fe['geometric_elevation_deg']:+.3f} bias "
                         f"{fe['elevation_bias_deg']:+.4f}")
            lines.append(
                f"{row['radius_m']:7.3f} {fe['index']:3d} {fe['geometric_deg']:9.4f} "
                f"{fe['bias_deg']:+8.4f}   {fe['separation_part_deg']:+9.4f}  "
                f"{fe['parallax_part_deg']:+8.4f}  {fe['beat_frequency_part_deg']:+7.4f}  "
                f"{fe['curvature_part_deg']:+9.5f}  {fe['phase_error_pp_deg']:9.3f} "
                f"{fe['phase_error_rms_deg']:6.3f}{tail}")
        for s in row["synthesis"]:
            if "cell" not in s:
                continue
            fmt2 = lambda v: "n/a" if v is None else f"{v:.4f}"  # noqa: E731
            lines.append(
                f"{row['radius_m']:7.3f} cell {'-'.join(str(q) for q in s['cell'])} "
                f"({s['points']} set directions): worst |error| az / el, deg: array-factor "
                f"{fmt2(s['array_factor_max_abs_error_azimuth_deg'])} / "
                f"{fmt2(s['array_factor_max_abs_error_elevation_deg'])}, exact "
                f"{fmt2(s['exact_max_abs_error_azimuth_deg'])} / "
                f"{fmt2(s['exact_max_abs_error_elevation_deg'])}")
    coef = ", ".join(f"{x:.4f}" for x in d["bias_1_over_r_coefficient_deg_m"])
    need = ", ".join(f"{x:.2f}" for x in d["radius_for_bias_below_deg"]["0.1"])
    lines.append(f"bias x R (deg m) per front end: {coef}; bias < 0.1 deg needs R >= {need} m")
    return "\n".join(lines)


def cmd_nearfield(args) -> int:
    scene = load_scene_checked(args.scene)
    if args.radius_m is None:
        radii = default_radii(scene)
    else:  # log-spaced with the ends exactly as given (logspace put 0.05 at 0.04999...)
        radii = np.geomspace(*args.radius_m)
        radii[[0, -1]] = args.radius_m[:2]
    with output_folder(args.out, [args.scene]) as stage:
        try:
            with steps(args.quiet or args.json) as step:
                step(f"near field at {len(radii)} arc radii ({radii[0]:.3g} to {radii[-1]:.3g} m)")
                nf = nearfield(scene, radii, points=args.points)
        except ParameterError as exc:
            raise UsageError(f"--radius-m: {exc}") from None
        out = nf.to_dict()
        if stage is not None:
            nf.write(stage)
    return print_outputs(args, "nearfield", out, _nearfield_text)


def register(sub) -> None:
    p = sub.add_parser("nearfield", help="near-field violation: single front-end bias, phase "
                                         "error and synthesized-angle error vs arc radius")
    scene_arg(p)
    p.add_argument("--radius-m", type=radius_sweep, default=None, metavar="A:B:N",
                   help="N log-spaced arc radii from A to B m (default: 13 radii from "
                        "R_c/sqrt(10) to 10 sqrt(10) R_c, R_c included)")
    p.add_argument("--points", type=number(1, 201, integer=True), default=11,
                   help="synthesized set-points per pair (default 11)")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.add_argument("--out", type=output_path, default=None,
                   help="folder for nearfield.json and nearfield.png")
    p.add_argument("--quiet", action="store_true", help="no progress output on stderr")
    p.set_defaults(func=cmd_nearfield)
