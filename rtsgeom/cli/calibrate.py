"""``rtsgeom calibrate``: the phase calibration sweep of a front-end pair (``--pair I J``), of
every adjacent pair of the arc (``--pair all``), or the delay predicted from an identified
scene (``--from-identified``, no sweep)."""

from __future__ import annotations

import functools

import numpy as np

from .._lib.io import write_json
from .._lib.parallel import local_map
from ..calibration.file import setup_fingerprint
from ..calibration.fir import fir_effect
from ..calibration.pair import calibrate_pair
from ..calibration.paper import calibrate_pair_paper
from ..errors import UsageError
from ..geometry import build_setup
from ..pipeline.plan import uses_cells
from ._common import (emit_result, load_scene_checked, number, output_folder, output_path,
                      pair_of, pair_options, prepare_arc, prepare_pair, print_json, steps)


def cmd_calibrate(args) -> int:
    with output_folder(args.out, [args.scene, getattr(args, "from_identified", None)]) as stage:
        if getattr(args, "from_identified", None) is not None:  # no sweep (rtsgeom.identify)
            if list(args.pair) == ["all"]:
                raise UsageError("--from-identified predicts one pair's delay: give --pair I J")
            if args.full_chain or args.procedure != "exact" or args.fir:
                raise UsageError("--from-identified predicts the delay without a sweep: "
                                 "--full-chain, --procedure and --fir do not apply")
            out = _from_identified(args)
            if stage is not None:
                write_json(stage / "calibration.json", out)
            if args.json:
                print_json(out)
            else:
                print(f"pair {tuple(out['pair'])}: delta_tau {out['delta_tau_s'] * 1e12:.1f} ps "
                      f"(predicted from {args.from_identified}, no sweep)")
            return 0
        return _calibrate(args, stage)


#: the fields ``rtsgeom identify --out`` writes into a scene (all else is SCENE's)
IDENTIFIED_FIELDS = ("radial_offset_m", "tangential_offset_m", "height_offset_m",
                     "yaw_offset_rad", "gain_offset_db", "phase_offset_rad")


def _from_identified(args) -> dict:
    """``--from-identified FILE``: the pair's delay predicted on FILE (SCENE as identified),
    as a calibration file ``run --calibration`` reads: the front ends' detected angles and
    the gain corrections of the identified channel gains. FILE must be SCENE apart from the
    fields identify writes (:data:`IDENTIFIED_FIELDS`), else it is refused."""
    from ..identify import calibrate_from_identified, detected_angles, setup_of
    scene = load_scene_checked(args.scene)
    ident = load_scene_checked(args.from_identified)
    fes, own = ident.rts.front_ends, scene.rts.front_ends
    same = len(fes) == len(own) and setup_fingerprint(ident.evolve(rts=ident.rts.evolve(
        front_ends=tuple(f.evolve(**{k: getattr(g, k) for k in IDENTIFIED_FIELDS})
                         for f, g in zip(fes, own))))) == setup_fingerprint(scene)
    if not same:
        raise UsageError(f"--from-identified {args.from_identified}: not SCENE {args.scene} "
                         "as identified (its radar, arc, front ends or RTS differ beyond the "
                         "mounting and channel fields `rtsgeom identify --out` writes)")
    pair = pair_of(build_setup(ident), args.pair)
    out = calibrate_from_identified(ident, pair).to_dict()
    gain = [10 ** (-f.gain_offset_db / 20) for f in fes]  # what the probe step would measure
    out.update({"front_end_angles_deg": [float(x) for x in
                                         np.degrees(detected_angles(setup_of(ident)))],
                "gain_correction": gain, "format": "rtsgeom-calibration",
                "setup_sha256": setup_fingerprint(ident)})
    return out


def _calibrate(args, stage) -> int:
    if list(args.pair) == ["all"]:
        return _calibrate_arc(args, stage)
    with steps(args.quiet or args.json) as step:
        step("measuring each front end alone")
        scene, setup, pair, paths, probe = prepare_pair(args, cells=True)
        if args.procedure == "paper" and uses_cells(scene):
            raise UsageError("--procedure paper: the paper's sweep is a pair on an arc (one set "
                             "angle in azimuth); this scene's front ends form 2-D cells")
        step(f"sweeping the delay of front end {pair[1]} on the simulated radar "
             f"({args.procedure} procedure)")
        if args.procedure == "paper":
            cal = calibrate_pair_paper(setup, paths, pair, probe, seed=scene.seed)
        else:
            cal = calibrate_pair(setup, paths, pair, probe, seed=scene.seed,
                                 full_chain=args.full_chain)
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
                f"{cal.residual_error_deg:.4f} deg, range offset "
                f"{cal.range_offset_m * 1e3:.2f} mm (period {cal.period_s * 1e9:.4f} ns); "
                "fractional-delay filter "
                f"{out['fractional_delay_filter']['model']}: phase ripple over the IF sweep "
                f"{out['fractional_delay_filter']['phase_ripple_deg']:.3f} deg p-p, moves the "
                f"coherence point by {out['fractional_delay_filter']['predicted_shift_ps']:+.2f} ps")
    return 0


def _calibrate_arc(args, folder) -> int:
    """``--pair all``: every adjacent pair calibrated in one run; one JSON entry per pair plus
    the arc's. ``folder``: where the ``--out`` files go (None: no ``--out``)."""
    with steps(args.quiet or args.json) as step:
        step("measuring each front end alone")
        scene, setup, pairs, paths, probe = prepare_arc(args, cells=True)
        if args.procedure == "paper" and uses_cells(scene):
            raise UsageError("--procedure paper: the paper's sweep is a pair on an arc (one set "
                             "angle in azimuth); this scene's front ends form 2-D cells")
        step(f"sweeping the delay of front end J of each of {len(pairs)} pairs")
        one = functools.partial(_calibrate_one, setup, paths, probe, scene.seed, args.procedure,
                                args.full_chain)
        cals = local_map(one, pairs, args.workers,
                         progress=lambda done, total: step.count("pairs calibrated", done, total))
    res = np.abs([c.residual_error_deg for c in cals])  # inf: a probe the chain missed
    worst = int(np.argmax(np.where(np.isnan(res), np.inf, res)))
    out = {"pairs": [dict(c.to_dict(), procedure=args.procedure) for c in cals],
           "gain_correction": [float(x) for x in probe.gain_correction],
           "front_end_angles_deg": [float(x) for x in np.degrees(probe.angle_rad)],
           "arc": {"pairs": [list(p) for p in pairs],
                   "worst_residual_error_deg": (float(res[worst]) if np.isfinite(res[worst])
                                                else None),
                   "worst_pair": list(pairs[worst]),
                   "max_abs_range_offset_mm": max(abs(c.range_offset_m) for c in cals) * 1e3},
           "format": "rtsgeom-calibration", "setup_sha256": setup_fingerprint(scene)}
    if folder is not None:
        from ..viz.figures import calibration_sweep_figure, save_figure
        for pair, cal in zip(pairs, cals):
            save_figure(calibration_sweep_figure(cal.sweep_delta_tau_s, cal.sweep_error_deg,
                                                 cal.delta_tau_s, cal.period_s),
                        folder / f"calibration_sweep_{pair[0]}_{pair[1]}.png")
        write_json(folder / "calibration.json", out)
    if args.json:
        print_json(out)
        return 0
    for pair, cal in zip(pairs, cals):
        print(f"pair {pair}: delta_tau {cal.delta_tau_s * 1e12:.1f} ps, residual angle error "
              f"{cal.residual_error_deg:.4f} deg, range offset {cal.range_offset_m * 1e3:.2f} mm")
    where = "cells" if uses_cells(scene) else "arc"
    print(f"{where} ({len(pairs)} pairs): worst residual {res[worst]:.4f} deg (pair "
          f"{tuple(out['arc']['worst_pair'])})")
    return 0


def _calibrate_one(setup, paths, probe, seed, procedure, full_chain, pair):
    """One pair of ``--pair all``: a pure function of the pair (its noise from the scene's
    seed), so the pairs may be calibrated in any process and order with the same result."""
    if procedure == "paper":
        return calibrate_pair_paper(setup, paths, pair, probe, seed=seed)
    return calibrate_pair(setup, paths, pair, probe, seed=seed, full_chain=full_chain)


def register(sub) -> None:
    p = sub.add_parser("calibrate", help="phase calibration sweep of a front-end pair")
    pair_options(p)
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
    p.add_argument("--workers", type=number(1, 1024, integer=True), default=None,
                   metavar="N", help="--pair all: calibrate the pairs in N processes (the same "
                                     "result; default: the cores this process may run on)")
    p.set_defaults(func=cmd_calibrate)
