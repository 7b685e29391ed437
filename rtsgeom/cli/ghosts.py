"""``rtsgeom ghosts``: the ghost targets that mismatched front-end <-> back-end cables add (the
n-th: n extra round trips in the cable), their predicted ranges and levels per front end and
target, and with ``--simulate`` each ghost as the simulated range-Doppler map shows it."""

from __future__ import annotations

from ..analysis.ghosts import ghost_analysis
from ._common import (load_scene_checked, number, output_folder, output_path, print_outputs,
                      scene_arg)


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
    scene = load_scene_checked(args.scene)
    with output_folder(args.out, [args.scene]) as stage:
        rep = ghost_analysis(scene, args.floor_db, simulate=args.simulate)
        out = rep.to_dict()
        if stage is not None:
            rep.write(stage)
    return print_outputs(args, "ghosts", out, _ghosts_text)


def register(sub) -> None:
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
