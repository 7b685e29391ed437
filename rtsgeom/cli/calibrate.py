"""``rtsgeom calibrate``: the phase calibration sweep of a front-end pair (``--pair I J``), of
every adjacent pair of the arc (``--pair all``), or the delay predicted from an identified
scene (``--from-identified``, no sweep)."""

from __future__ import annotations

import numpy as np

from .._lib.io import write_json
from ..analysis.calibration_study import PROCEDURES, CalibrationStudy
from ..calibration.file import setup_fingerprint
from ..errors import UsageError
from ..geometry import build_setup
from ._common import (flagged, load_scene_checked, number, output_folder, output_path,
                      pair_of, pair_options, print_json, steps)


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


def study_of(args, step=None) -> CalibrationStudy:
    """The :class:`~rtsgeom.analysis.calibration_study.CalibrationStudy` the flags ask for."""
    pair = "all" if list(args.pair) == ["all"] else tuple(args.pair)
    return CalibrationStudy(pair, args.procedure, args.full_chain, args.fir, step, args.workers)


def _calibrate(args, stage) -> int:
    with steps(args.quiet or args.json) as step:
        with flagged(args):
            report = study_of(args, step)(load_scene_checked(args.scene))
    if stage is not None:
        report.write(stage)
    out = report.to_dict()
    if args.json:
        print_json(out)
    elif report.arc:
        _print_arc(report)
    else:
        cal, fir = report.calibration, out["fractional_delay_filter"]
        print(f"pair {report.pairs[0]}: delta_tau {cal.delta_tau_s * 1e12:.1f} ps (set in "
              f"{cal.delay_resolution_s * 1e12:g} ps steps; the fit's optimum "
              f"{cal.quantisation_residual_s * 1e12:+.2f} ps from it), residual angle error "
              f"{cal.residual_error_deg:.4f} deg, range offset "
              f"{cal.range_offset_m * 1e3:.2f} mm (period {cal.period_s * 1e9:.4f} ns); "
              f"fractional-delay filter {fir['model']}: phase ripple over the IF sweep "
              f"{fir['phase_ripple_deg']:.3f} deg p-p, moves the coherence point by "
              f"{fir['predicted_shift_ps']:+.2f} ps")
    return 0


def _print_arc(report) -> None:
    """``--pair all``: one line per pair, then the worst."""
    for pair, cal in zip(report.pairs, report.calibrations):
        print(f"pair {pair}: delta_tau {cal.delta_tau_s * 1e12:.1f} ps, residual angle error "
              f"{cal.residual_error_deg:.4f} deg, range offset {cal.range_offset_m * 1e3:.2f} mm")
    worst = report.worst()
    print(f"{'cells' if report.cells else 'arc'} ({len(report.pairs)} pairs): worst residual "
          f"{report.residuals_deg()[worst]:.4f} deg (pair {tuple(report.pairs[worst])})")


def register(sub) -> None:
    p = sub.add_parser("calibrate", help="phase calibration sweep of a front-end pair")
    pair_options(p)
    p.add_argument("--procedure", choices=PROCEDURES, default="exact",
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
