"""``rtsgeom nearfield | ghosts``: setup analyses (near-field violation, cable ghosts)."""

from __future__ import annotations

import argparse
import math

import numpy as np

from ..errors import ParameterError
from ..errors import UsageError
from ._common import (load_scene_checked, number, output_folder, output_path, print_outputs,
                      scene_arg, steps, warn_scene_errors, write_outputs)


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
    from ..analysis.nearfield import default_radii, nearfield, nearfield_figure
    scene = load_scene_checked(args.scene)
    warn_scene_errors(scene, "nearfield", "analyses the arc's near field on the nominal setup: "
                      "the scene's own errors ({}) play no part")
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
        write_outputs(stage, "nearfield", out, lambda: nearfield_figure(nf))
    return print_outputs(args, "nearfield", out, _nearfield_text)


def _ghosts_text(d: dict) -> str:
    lines = [f"scene {d['scene']}: cable ghosts down to {d['floor_db']:g} dB"]
    for fe in d["front_ends"]:
        if not fe["mismatched"]:
            lines.append(f"front end {fe['index']}: matched (no return loss given): no ghosts")
            continue
        lines.append(
            f"front end {fe['index']}: cable {fe['cable_length_m']:g} m, VF "
            f"{fe['cable_velocity_factor']:g}, loss {fe['cable_loss_db']:g} dB, return loss "
            f"{fe['return_loss_fe_db']:g} dB (FE) / {fe['return_loss_be_db']:g} dB (BE): "
            f"ghosts every {fe['range_offset_per_order_m']:.4f} m at "
            + ", ".join(f"{g['level_db']:.2f}" for g in fe["ghosts"]) + " dB")
    sim = {s["index"]: s for s in (d["simulated"] or [])}
    for t in d["targets"]:
        lines.append(f"target {t['index']} ({t['range_m']:g} m, {t['velocity_mps']:+g} m/s, "
                     f"front end {t['front_end']}):")
        meas = {g["order"]: g for g in sim[t["index"]]["ghosts"]} if t["index"] in sim else {}
        for g in t["ghosts"]:
            line = f"  ghost {g['order']}: {g['range_m']:8.3f} m {g['level_db']:8.2f} dB"
            m = meas.get(g["order"])
            if m is not None and not m.get("beyond_max_range"):
                line += (f" | simulated {m['range_m']:8.3f} m ({m['offset_error_bins']:+.2f} bins)"
                         f" {m['level_db']:8.2f} dB (map cell {m['level_db_bin']:.2f} dB, "
                         f"{m['above_map_median_db']:.1f} dB above the map median"
                         f"{', in the noise' if m['predicted_above_map_median_db'] < 6 else ''}"
                         f"{', CFAR detection' if m['cfar_detected'] else ''})")
            elif m is not None:
                line += " | beyond the radar's range"
            lines.append(line)
    return "\n".join(lines)


def cmd_ghosts(args) -> int:
    from ..analysis.ghosts import ghost_analysis, ghosts_figure
    scene = load_scene_checked(args.scene)
    with output_folder(args.out, [args.scene]) as stage:
        rep = ghost_analysis(scene, args.floor_db, simulate=args.simulate)
        out = rep.to_dict()
        write_outputs(stage, "ghosts", out, lambda: ghosts_figure(rep))
    return print_outputs(args, "ghosts", out, _ghosts_text)


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

    p = sub.add_parser("ghosts", help="cable ghosts: predicted ranges and levels per front end "
                                      "and target (and simulated with --simulate)")
    scene_arg(p)
    p.add_argument("--floor-db", type=number(-300.0, -1.0), default=-80.0,
                   help="list ghost orders down to this level re the target (default -80 dB)")
    p.add_argument("--simulate", action="store_true",
                   help="run the signal chain (targets on their nearest front ends) and read "
                        "each predicted ghost in the range-Doppler map")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.add_argument("--out", type=output_path, default=None, help="folder for ghosts.json and ghosts.png")
    p.set_defaults(func=cmd_ghosts)
