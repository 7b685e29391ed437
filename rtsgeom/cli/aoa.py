"""``rtsgeom calibrate | linearity``: the arbitrary-angle synthesis of a front-end pair."""

from __future__ import annotations


import numpy as np

from ..calibration.pair import calibrate_pair, calibrate_pair_paper
from ..calibration.fir import fir_effect
from ..analysis.linearity import linearity
from ..errors import AngleUnreachable
from ..errors import ParameterError
from ..geometry import build_setup
from .._lib.io import write_json
from ..paths import exact_paths

from ..scene.registry import SYNTHESIS_MODES
from ..errors import UsageError
from ._common import (emit_result, load_scene_checked, number, output_folder, output_path, pair_of,
                      pair_word, prepare_pair, print_json, scene_arg, steps)


def cmd_calibrate(args) -> int:
    with output_folder(args.out, [args.scene, getattr(args, "from_identified", None)]) as stage:
        if getattr(args, "from_identified", None) is not None:  # no sweep (rtsgeom.identify)
            if list(args.pair) == ["all"]:
                raise UsageError("--from-identified predicts one pair's delay: give --pair I J")
            from ..identify import calibrate_from_identified
            scene = load_scene_checked(args.from_identified)
            out = calibrate_from_identified(scene, pair_of(build_setup(scene), args.pair)).to_dict()
            if stage is not None:
                write_json(stage / "calibration.json", out)
            if args.json:
                print_json(out)
            else:
                print(f"pair {tuple(out['pair'])}: delta_tau {out['delta_tau_s'] * 1e12:.1f} ps "
                      f"(predicted from {args.from_identified}, no sweep)")
            return 0
        return _calibrate(args, stage)


def _calibrate(args, stage) -> int:
    if list(args.pair) == ["all"]:
        from .arc import calibrate_all
        return calibrate_all(args, stage)
    with steps(args.quiet or args.json) as step:
        step("measuring each front end alone")
        scene, setup, pair, paths, probe = prepare_pair(args)
        step(f"sweeping the delay of front end {pair[1]} on the simulated radar "
             f"({args.procedure} procedure)")
        if args.procedure == "paper":
            cal = calibrate_pair_paper(setup, paths, pair, probe, seed=scene.seed)
        else:
            cal = calibrate_pair(setup, paths, pair, probe, seed=scene.seed,
                                 full_chain=args.full_chain)
    from ..calibration.file import setup_fingerprint
    out = cal.to_dict()
    out["procedure"] = args.procedure
    out["front_end_angles_deg"] = [float(x) for x in np.degrees(probe.angle_rad)]
    out["gain_correction"] = [float(x) for x in probe.gain_correction]
    out["format"] = "rtsgeom-calibration"  # `run/adc --calibration DIR/calibration.json`
    out["setup_sha256"] = setup_fingerprint(scene)  # run/adc warn when used on another setup
    out["fractional_delay_filter"] = fir_effect(setup, cal.delta_tau_s,
                                                ranges=cal.probe_ranges_m)

    def figure():
        from ..viz.figures import calibration_sweep_figure
        return calibration_sweep_figure(cal.sweep_delta_tau_s, cal.sweep_error_deg,
                                        cal.delta_tau_s, cal.period_s,
                                        residual_error_deg=cal.residual_error_deg,
                                        refine_delta_tau_s=cal.refine_delta_tau_s,
                                        refine_error_deg=cal.refine_error_deg)
    emit_result(args, stage, "calibration_sweep.png", "calibration", out, figure,
          f"pair {pair}: delta_tau {cal.delta_tau_s * 1e12:.1f} ps (set in "
          f"{cal.delay_resolution_s * 1e12:g} ps steps; the fit's optimum "
          f"{cal.quantisation_residual_s * 1e12:+.2f} ps from it), residual angle error "
          f"{cal.residual_error_deg:.4f} deg, range offset {cal.range_offset_m * 1e3:.2f} mm "
          f"(period {cal.period_s * 1e9:.4f} ns); fractional-delay filter "
          f"{out['fractional_delay_filter']['model']}: phase ripple over the IF sweep "
          f"{out['fractional_delay_filter']['phase_ripple_deg']:.3f} deg p-p, moves the "
          f"coherence point by {out['fractional_delay_filter']['predicted_shift_ps']:+.2f} ps")
    return 0


def cmd_linearity(args) -> int:
    with output_folder(args.out, [args.scene]) as stage:
        return _linearity(args, stage)


def _linearity(args, stage) -> int:
    if list(args.pair) == ["all"]:
        from .arc import linearity_all
        return linearity_all(args, stage)
    if getattr(args, "grid", None):  # 2-D: an error map over one cell (issue 15)
        return _linearity_grid(args, stage)
    with steps(args.quiet or args.json) as step:
        step("measuring each front end alone")
        scene, setup, pair, paths, probe = prepare_pair(args)
        cal = None
        if not args.uncalibrated:
            step("calibrating the pair")
            cal = calibrate_pair(setup, paths, pair, probe, seed=scene.seed)
        step(f"sweeping {args.points} set-points ({args.amplitudes} amplitudes)")
        lin = linearity(setup, paths, pair, args.amplitudes, probe, cal, args.points, scene.seed,
                        args.end_angles)
    def figure():
        from ..viz.figures import linearity_figure
        return linearity_figure(lin.set_deg, {args.amplitudes: lin.detected_deg},
                                {args.amplitudes: lin.amplitude_db}, pair=pair)
    emit_result(args, stage, "linearity.png", "linearity", lin.to_dict(), figure,
          f"{args.amplitudes} ({'calibrated' if cal else 'uncalibrated'}, "
          f"{args.end_angles} end angles): max |error| "
          f"{lin.max_abs_error_deg:.4f} deg over {len(lin.set_deg)} set-points")
    return 0


def _linearity_grid(args, stage) -> int:
    from ..analysis.linearity2d import error_map_figure, linearity_grid
    with steps(args.quiet or args.json) as step:
        step("measuring each front end alone")
        scene = load_scene_checked(args.scene)
        setup = build_setup(scene)
        paths = exact_paths(setup)
        step(f"{'calibrating the channels, then ' if not args.uncalibrated else ''}"
             f"synthesizing a {args.grid} x {args.grid} grid ({args.amplitudes} amplitudes)")
        try:
            em = linearity_grid(setup, paths, args.amplitudes, args.grid,
                                not args.uncalibrated, scene.seed)
        except (ParameterError, AngleUnreachable) as exc:
            raise UsageError(f"{args.scene}: {exc}") from None
    mx = em.max_abs_error_deg()
    emit_result(args, stage, "linearity_grid.png", "linearity_grid", em.to_dict(),
          lambda: error_map_figure(em),
          f"{args.amplitudes} ({'calibrated' if em.calibrated else 'uncalibrated'}): max "
          f"|error| azimuth {mx[0]:.4f} deg, elevation {mx[1]:.4f} deg over "
          f"{em.set_deg.shape[0]} set-points")
    return 0


def register(sub) -> None:
    for name, func, helptext in (
            ("calibrate", cmd_calibrate, "phase calibration sweep of a front-end pair"),
            ("linearity", cmd_linearity, "synthesized-angle linearity across a pair's span")):
        p = sub.add_parser(name, help=helptext)
        scene_arg(p)
        p.add_argument("--pair", nargs="+", type=pair_word, metavar="I J | all",
                       default=[0, 1], help="adjacent front ends (default 0 1), or all: every "
                                            "adjacent pair of the arc in one run")
        p.add_argument("--json", action="store_true", help="print the result as JSON")
        p.add_argument("--out", type=output_path, default=None, help="folder for the plot and JSON")
        p.add_argument("--quiet", action="store_true", help="no progress output")
        p.add_argument("--fir", choices=("windowed-sinc", "ideal"), default=None,
                       help="fractional-delay filter model (default: the scene's "
                            "rts.fractional_delay_filter)")
        if name == "calibrate":
            p.add_argument("--procedure", choices=("exact", "paper"), default="exact",
                           help="exact: two probes, amplitudes re-designed at every step, "
                                "refined to the delay resolution (default); paper: the "
                                "paper's sweep as written (fixed eq. 23 amplitudes, one set "
                                "angle, 25 ps steps)")
            p.add_argument("--from-identified", type=output_path, default=None, metavar="FILE",
                           help="no sweep: predict the delay from a scene as identified "
                                "(rtsgeom identify --out DIR writes DIR/identified.toml)")
            p.add_argument("--full-chain", action="store_true",
                           help="evaluate every sweep step through the full ADC-cube chain "
                                "instead of the phasor model (validation; about a minute)")
        if name == "linearity":
            p.add_argument("--end-angles", choices=("geometric", "measured"),
                           default="geometric",
                           help="front-end angles in the paper/array-factor closed forms: "
                                "geometric (default) or measured (each alone, as the RuT "
                                "detects it)")
            p.add_argument("--amplitudes", choices=SYNTHESIS_MODES,
                           default="exact", help="amplitude-ratio mode (default exact)")
            p.add_argument("--uncalibrated", action="store_true",
                           help="no phase/amplitude calibration (delay offset 0)")
            p.add_argument("--grid", type=number(2, 50, integer=True), default=None,
                           metavar="N", help="2-D: an N x N azimuth/elevation error map over "
                                             "the cell of the scene's 3 or 4 front ends "
                                             "(writes linearity_grid.png and .json)")
            p.add_argument("--points", type=number(3, 1001, integer=True), default=21,
                           help="set-points across the span (default 21)")
        p.set_defaults(func=func)
