"""``rtsgeom transfer``: does an RTS calibration made with one radar (the scene's own
``[radar.channels]``) hold for other radars of the type? Calibrates every adjacent pair with the
scene's radar, then measures the synthesized angles over the arc with ``--radars`` drawn radars
(``analysis.transfer``)."""

from __future__ import annotations

from ..analysis.transfer import TransferStudy
from ..errors import AngleUnreachable, ParameterError, UsageError
from ..geometry import build_setup
from ..paths import exact_paths
from ._common import (load_scene_checked, number, output_folder, output_path, print_outputs,
                      scene_arg, steps)


def cmd_transfer(args) -> int:
    with output_folder(args.out, [args.scene]) as stage:
        out = _transfer(args, stage)
    return print_outputs(args, "transfer", out, _summary)


def _transfer(args, stage) -> dict:
    scene = load_scene_checked(args.scene)
    seed = scene.seed if args.seed is None else args.seed
    study = TransferStudy(radars=args.radars, sigma_phase_deg=args.sigma_phase_deg,
                          sigma_gain_db=args.sigma_gain_db, points=args.points,
                          spec_deg=args.spec_deg, seed=seed)
    with steps(args.quiet or args.json) as step:
        setup = build_setup(scene)
        paths = exact_paths(setup)
        try:
            res = study(setup, paths, progress=step)
        except (ParameterError, AngleUnreachable) as exc:
            raise UsageError(f"{args.scene}: {exc}") from None
    out = res.to_dict()
    if stage is not None:
        res.write(stage)
    return out


#: what each verdict asks of the lab (``Transfer.verdict``)
VERDICTS = {
    "transfers": "the golden radar's RTS calibration serves every radar of the type",
    "boresight": "each radar needs its own boresight channel compensation to meet the spec",
    "recalibrate": "the RTS must be calibrated again with each radar",
    "radar": "the radars miss the spec on real targets too: their channels need calibrating",
}


def _summary(out: dict) -> str:
    e, c, own = (out["angle_error_deg"], out["compensated_angle_error_deg"],
                 out["own_angle_error_deg"])
    lines = [f"{out['radars']} radars (antenna phase sigma {out['sigma_phase_deg']:g} deg, "
             f"gain sigma {out['sigma_gain_db']:g} dB) x {out['set_points']} set-points, RTS "
             "calibrated with the scene's radar:",
             f"  |angle error|       p50 {e['p50']:.4f}  p95 {e['p95']:.4f}  max "
             f"{e['max']:.4f} deg",
             f"  with boresight comp p50 {c['p50']:.4f}  p95 {c['p95']:.4f}  max "
             f"{c['max']:.4f} deg",
             f"  on a real target    p50 {own['p50']:.4f}  p95 {own['p95']:.4f}  max "
             f"{own['max']:.4f} deg (each radar's own error)",
             f"  absorbed by the golden radar's calibration: max "
             f"{out['absorbed_deg']['max']:.2g} deg, offsets "
             + ", ".join(f"{x:+.1f}" for x in out["absorbed_offset_ps"]) + " ps"]
    if out["verdict"] is not None:
        lines.append(f"  spec {out['spec_deg']:g} deg (p95): {out['verdict']} -- "
                     + VERDICTS.get(out["verdict"], ""))
    return "\n".join(lines)


def register(sub) -> None:
    p = sub.add_parser("transfer", help="calibration transfer: an RTS calibrated with one radar, "
                                        "tested with drawn radars of the type")
    scene_arg(p)
    p.add_argument("--radars", type=number(1, 100_000, integer=True), default=100,
                   help="radars drawn, in [1, 100000] (default 100)")
    p.add_argument("--sigma-phase-deg", type=number(0.0, 90.0), default=5.0,
                   help="spread of each Tx and Rx antenna's phase error, deg, in [0, 90] "
                        "(default 5)")
    p.add_argument("--sigma-gain-db", type=number(0.0, 6.0), default=0.0,
                   help="spread of each antenna's gain error, dB, in [0, 6] (default 0)")
    p.add_argument("--spec-deg", type=number(1e-6, 90.0), default=None,
                   help="angle-error spec in deg (p95): adds the verdict")
    p.add_argument("--points", type=number(1, 201, integer=True), default=11,
                   help="set-points across each pair's span, ends excluded (default 11)")
    p.add_argument("--seed", type=number(0, 2 ** 63 - 1, integer=True), default=None,
                   help="random seed (default: the scene's seed)")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.add_argument("--out", type=output_path, default=None, help="folder for the plot and JSON")
    p.add_argument("--quiet", action="store_true", help="no progress output")
    p.set_defaults(func=cmd_transfer)
