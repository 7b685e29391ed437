"""``rtsgeom tolerance``: the mounting-tolerance Monte Carlo of a front-end pair, a cell of front
ends or a whole arc (one engine: :mod:`rtsgeom.analysis.tolerance`), with the chain check
(``--verify``) and the yield search (``--invert-yield``)."""

from __future__ import annotations

import argparse

import numpy as np

from .._lib.parallel import check_address, chunk_mapper
from ..analysis.tolerance import (AXES, NOMINAL_AMPLITUDES, Bounds, MonteCarlo,
                                  ToleranceStudy)
from ..analysis.tolerance.config import STUDY_ARGS
from ..analysis.tolerance.draws import MAX_SIGMA_MM
from ..analysis.tolerance.study import CHUNK_MEMORY_BYTES, capped_chunk, chunk_bytes_per_draw
from ..errors import ClusterError, UsageError
from ._common import (declared_option, flagged, load_scene_checked, number, output_folder,
                      pair_word, print_json, progress, study_options)

__all__ = ["cmd_tolerance", "register", "scales", "study_of", "CHUNK_MEMORY_BYTES",
           "capped_chunk", "chunk_bytes_per_draw"]

#: ``tolerance``'s ``--pair`` default, by identity: left at it, a 2-D RuT gets the cell study
DEFAULT_PAIR = [0, 1]
def _dask_address(text: str) -> str:
    try:
        return check_address(text)
    except ClusterError as exc:
        raise argparse.ArgumentTypeError(str(exc).split(": ", 1)[1]) from None


def scales(args) -> tuple[np.ndarray, dict]:
    """The per-axis scales (m: the sigma, or the uniform bound) from the scale flags
    ``--sigma-*-mm`` or the tolerance flags (``--radial-mm 0.2 --sigma-level 3``: +-0.2 mm at 3
    sigma), and the rotation / RuT-pose tolerances (SI) of the tolerance flags."""
    k = 1.0 / args.sigma_level if args.distribution == "normal" else 1.0
    sigma = []
    for axis in AXES:
        old, new = getattr(args, f"sigma_{axis}_mm"), getattr(args, f"{axis}_mm")
        if old is not None and new is not None:
            raise UsageError(f"--sigma-{axis}-mm and --{axis}-mm: give one of them (the first is "
                             "the scale itself, the second a tolerance at --sigma-level)")
        sigma.append(old if old is not None else (k * new if new is not None else 0.1))
    extra = {"yaw_rad": np.radians(args.yaw_deg), "pitch_rad": np.radians(args.pitch_deg),
             "rut_position_m": (args.rut_position_mm * 1e-3,) * 3,
             "rut_yaw_rad": np.radians(args.rut_yaw_deg)}
    return np.array(sigma) * 1e-3, extra


def _cell(words) -> tuple[int, ...] | str | None:
    if words is None:
        return None
    if list(words) == ["all"]:
        return "all"
    if "all" in words:
        raise UsageError(f"--cell {' '.join(map(str, words))}: give 3 or 4 front-end indices, "
                         "or all")
    return tuple(int(w) for w in words)


def study_of(args, mapper=None, report=None) -> ToleranceStudy:
    """The :class:`~rtsgeom.analysis.tolerance.ToleranceStudy` the flags ask for."""
    sigma, extra = scales(args)
    k = 1.0 / args.sigma_level if args.distribution == "normal" else 1.0
    bounds = Bounds(tuple(float(x) for x in sigma), k * extra["yaw_rad"], k * extra["pitch_rad"],
                    tuple(k * x for x in extra["rut_position_m"]), k * extra["rut_yaw_rad"])
    if args.cell is not None and args.pair is not DEFAULT_PAIR:
        what = "all" if list(args.pair) == ["all"] else " ".join(map(str, args.pair))
        raise UsageError(f"--cell and --pair {what}: give one of them (the cell study is of "
                         "the --cell front ends)")
    pair = None if args.pair is DEFAULT_PAIR else (
        "all" if list(args.pair) == ["all"] else tuple(args.pair))
    mc = MonteCarlo(args.draws, args.seed, args.distribution, args.chunk, mapper, report)
    return ToleranceStudy(bounds, pair, _cell(args.cell), mc, args.spec_deg, args.points,
                          args.nominal_amplitudes, args.verify, args.verify_all_points,
                          args.invert_yield, args.invert_axis, args.sigma_level,
                          keep_draws=args.out is not None)


def cmd_tolerance(args) -> int:
    scene = load_scene_checked(args.scene)
    with output_folder(args.out, [args.scene]) as stage:
        with progress(args.quiet) as report, chunk_mapper(args.dask, args.workers) as mapper:
            with flagged(args):
                report_ = study_of(args, mapper, report)(scene)
        if stage is not None:
            report_.write(stage)
    _print(args, report_)
    return 0


def _print(args, report) -> None:
    out, res, kind = report.to_dict(), report.run, report.kind
    if args.json:
        print_json(out)
        return
    scale = "sigma" if res.distribution == "normal" else "bound"
    if kind == "arc":
        _print_arc(args, res.model, out, report.study.cases, report.elapsed_s)
        return
    m = res.model.sets[0]
    what = (f"pair {tuple(m.front_ends)}" if kind == "pair" else f"cell {tuple(m.front_ends)}")
    print(f"{what}, {res.draws} draws ({res.distribution}, {scale} "
          + ", ".join(f"{a} {s * 1e3:g} mm" for a, s in zip(AXES, res.sigma_m))
          + (f"), {len(m.set_rad)} set-points" if kind == "pair" else
             f"), {m.set_rad.shape[0]} set directions (azimuth x elevation)")
          + f", {report.elapsed_s:.2f} s ({res.cpu_s:.2f} s CPU in the Monte Carlo)")
    if kind == "pair":
        _print_pair(args, out, report.study.cases, report.scene_offsets)
    else:
        _print_cell(args, out, report.study.cases)
    _print_footer(out, args, scale)


def _print_pair(args, out, cases, own) -> None:
    for case in cases:
        st = out[case]
        p = st["angle_error_deg"]
        print(f"  {case:>30}: |error| p50 {p['p50']:.4f}, p95 {p['p95']:.4f}, p99 "
              f"{p['p99']:.4f}, max {p['max']:.4f} deg; yield {100 * st['yield']:.2f} % "
              f"within {args.spec_deg:g} deg")
    if own is not None:
        print(f"  the scene's own offsets ({', '.join(own['fields'])}), one setup at the bin "
              f"centre: worst |error| uncalibrated {own['uncalibrated_deg']:.4f}, "
              f"calibrated {own['calibrated_deg']:.4f} deg")


def _print_cell(args, out, cases) -> None:
    print(f"  target at a sub-bin position drawn per draw, uniform over one range bin "
          f"({out['subbin']['positions']} positions); the RuT's bin: set-points detected "
          "off the set range's bin " + ", ".join(f"{case} {out[case]['detected_off_bin']}"
                                                for case in cases))
    for case in cases:
        st = out[case]
        parts = []
        for key, name in (("azimuth_error_deg", "az"), ("elevation_error_deg", "el"),
                          ("angular_distance_deg", "distance")):
            p = st[key]
            parts.append(f"{name} p95 {p['p95']:.4f} p99 {p['p99']:.4f} max {p['max']:.4f}")
        print(f"  {case:>12}: |error| " + "; ".join(parts) + f" deg; yield "
              f"{100 * st['yield']:.2f} % within {args.spec_deg:g} deg in both angles")


def _print_arc(args, model, out, cases, elapsed) -> None:
    sc = out["scales"]
    kind = "sigma" if args.distribution == "normal" else "bound"
    print(f"arc of {model.count} front ends, {len(model.sets)} pair(s), {args.draws} draws "
          f"({args.distribution}, {kind}: radial {sc['radial_mm']:.4g}, tangential "
          f"{sc['tangential_mm']:.4g}, height {sc['height_mm']:.4g} mm, yaw {sc['yaw_deg']:.4g}, "
          f"pitch {sc['pitch_deg']:.4g} deg per front end; RuT position "
          f"{sc['rut_position_mm'][0]:.4g} mm, yaw {sc['rut_yaw_deg']:.4g} deg), "
          f"{elapsed:.2f} s")
    print(f"  target: one per draw, at a sub-bin position drawn uniform over one range bin "
          f"({out['subbin']['positions']} positions), the same for every pair")
    for entry in out["pairs"]:
        print(f"  pair {tuple(entry['pair'])}: " + "; ".join(
            f"{case} p95 {entry[case]['angle_error_deg']['p95']:.4f} deg, yield "
            f"{100 * entry[case]['yield']:.2f} %" for case in cases))
    for case in cases:
        a = out["arc"][case]
        print(f"  ARC {case:>28}: |worst error| p50 {a['angle_error_deg']['p50']:.4f}, p95 "
              f"{a['angle_error_deg']['p95']:.4f}, max {a['angle_error_deg']['max']:.4f} deg; "
              f"yield {100 * a['yield']:.2f} % (every pair within {args.spec_deg:g} deg)")
    for case, inv in out.get("inversion", {}).items():
        s = inv["scales"]
        print(f"  {100 * args.invert_yield:g} % of arcs within {args.spec_deg:g} deg, {case}: "
              f"the drawn scales x {inv['factor']:.4g}{' (search cap)' if inv['capped'] else ''}"
              f" = {kind} radial {s['radial_mm']:.4g}, tangential {s['tangential_mm']:.4g}, "
              f"height {s['height_mm']:.4g} mm, yaw {s['yaw_deg']:.4g}, pitch "
              f"{s['pitch_deg']:.4g} deg")


def _print_footer(out: dict, args, scale: str) -> None:
    """The lines a pair study and a cell study print alike: the chain check (``--verify``),
    the calibration's delays and range offsets, and the yield search (``--invert-yield``)."""
    if "verify" in out:
        v = out["verify"]
        print(f"  verify: {v['draws']} draws through the ADC-cube chain, largest |chain - model| "
              f"{v['max_abs_difference_deg']:.2e} deg (at {v['set_point']})")
    cal = out["calibration"]
    print(f"  calibration |delta tau| p95 {cal['abs_delta_tau_ps']['p95']:.0f} ps, range offset "
          f"p95 {cal['abs_range_offset_mm']['p95']:.1f} mm")
    for case, inv in out.get("inversion", {}).items():
        sig = ", ".join(f"{a} {inv['sigma_mm'][a]:.4g}" for a in AXES)
        print(f"  {100 * args.invert_yield:g} % within {args.spec_deg:g} deg, {case}: {scale} "
              f"{sig} mm{' (search cap)' if inv['capped'] else ''}")


def register(sub) -> None:
    p = sub.add_parser("tolerance", help="mounting-tolerance Monte Carlo of a front-end pair "
                                         "or a whole arc")
    study_options(p, STUDY_ARGS, 10_000, allow_all=True)
    mm = number(0.0, MAX_SIGMA_MM)
    for axis in AXES:
        p.add_argument(f"--sigma-{axis}-mm", type=mm, default=None,
                       help=f"{axis} mounting error per front end in mm, in [0, {MAX_SIGMA_MM:g}]: "
                            "the standard deviation (normal) or the bound (uniform) (default 0.1)")
    for axis in AXES:
        p.add_argument(f"--{axis}-mm", type=mm, default=None, metavar="TOL",
                       help=f"{axis} mounting tolerance +-TOL mm at --sigma-level sigmas (normal; "
                            "uniform: the bound), instead of --sigma-" + axis + "-mm")
    deg = number(0.0, 10.0)
    p.add_argument("--yaw-deg", type=deg, default=0.0, metavar="TOL",
                   help="front-end yaw tolerance, deg, in [0, 10], drawn per front end (default 0)")
    p.add_argument("--pitch-deg", type=deg, default=0.0, metavar="TOL",
                   help="front-end pitch tolerance, deg, in [0, 10] (default 0)")
    p.add_argument("--rut-position-mm", type=mm, default=0.0, metavar="TOL",
                   help="RuT position tolerance (each of x, y, z), mm (default 0)")
    p.add_argument("--rut-yaw-deg", type=deg, default=0.0, metavar="TOL",
                   help="RuT yaw tolerance, deg (default 0)")
    p.add_argument("--sigma-level", type=number(0.1, 10.0), default=3.0,
                   help="the tolerances above are this many sigmas of a normal distribution "
                        "(default 3: '+-0.2 mm at 3 sigma'); ignored for uniform")
    declared_option(p, "distribution", STUDY_ARGS["distribution"], "normal")
    p.add_argument("--invert-yield", type=number(1e-6, 1.0), default=None, metavar="Y",
                   help="also find the largest sigma keeping the fraction Y, in (0, 1], of the "
                        "setups within the spec (secant search on the scale, same seed)")
    p.add_argument("--invert-axis", choices=("all",) + AXES, default="all",
                   help="with --invert-yield: scale all three sigmas together (default) or vary "
                        "one axis, the others held")
    p.add_argument("--nominal-amplitudes", action="store_true",
                   help=f"add the case '{NOMINAL_AMPLITUDES}': calibrated, but the amplitudes "
                        "not designed for the calibration delay's range offset")
    p.add_argument("--verify", type=number(0, 10_000, integer=True), default=0, metavar="N",
                   help="push the first N draws (same seed) through the full ADC-cube chain "
                        "(synthesis, range-Doppler, CFAR, angle) and report the largest "
                        "difference from the fast model, in [0, 10000] (default 0)")
    p.add_argument("--verify-all-points", action="store_true",
                   help="with --verify: every set-point of each draw through the chain, not "
                        "only its worst (--points times the frames)")
    declared_option(p, "chunk", STUDY_ARGS["chunk"], 10_000,
                    f"10000; capped so that one chunk needs at most {CHUNK_MEMORY_BYTES >> 20} "
                    "MiB; results do not depend on it")
    p.add_argument("--dask", metavar="ADDRESS", default=None, type=_dask_address,
                   help="run the chunks on an existing Dask scheduler (tcp://host:8786)")
    p.add_argument("--workers", type=number(1, 1024, integer=True), default=None,
                   help="run the chunks in N local worker processes (forked; a local Dask "
                        "cluster where the platform cannot fork); results identical")
    p.add_argument("--cell", nargs="+", type=pair_word, metavar="Q | all", default=None,
                   help="the study for a 2-D cell: 3 or 4 front-end indices, or all (a RuT "
                        "beamforming in azimuth and elevation; its default there when --pair "
                        "is not given); --points N gives about N set directions (a "
                        "round(sqrt N)^2 azimuth x elevation grid, those inside the cell)")
    p.set_defaults(func=cmd_tolerance, pair=DEFAULT_PAIR)
