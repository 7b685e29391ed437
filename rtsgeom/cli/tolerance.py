"""``rtsgeom tolerance``: the mounting-tolerance Monte Carlo of a front-end pair, a cell of front
ends or a whole arc (one engine: :mod:`rtsgeom.analysis.tolerance`), with the chain check
(``--verify``) and the yield search (``--invert-yield``)."""

from __future__ import annotations

import argparse
import time

import numpy as np

from .._lib.io import write_json
from .._lib.parallel import check_address, chunk_mapper
from ..analysis.tolerance import (AXES, CASES, DISTRIBUTIONS, NOMINAL_AMPLITUDES, Bounds,
                                  ChannelPhasors, ToleranceModel, max_scale_for_yield,
                                  max_sigma_for_yield, monte_carlo,
                                  verify_draws)
from ..analysis.tolerance.draws import MAX_SIGMA_MM, draw_offsets
from ..errors import AngleUnreachable, ClusterError, ParameterError, UsageError
from ..geometry import build_setup
from ..radar.steering import Steering
from ._common import (load_scene_checked, number, output_folder, pair_word, pairs_of, print_json,
                      progress, study_options, warn_scene_errors)

#: ``tolerance``'s ``--pair`` default, by identity: left at it, a 2-D RuT gets the cell study
DEFAULT_PAIR = [0, 1]
#: Peak memory of one Monte-Carlo chunk is at most about ``chunk * chunk_bytes_per_draw(points)``
#: (measured with tracemalloc, all three cases, the target's sub-bin position drawn per draw:
#: 17 kB/draw at 5 set-points, 40 kB at 21, 112 kB at 61; a chunk is evaluated in blocks of the
#: procedure's ``block_draws``, so past that the peak stops growing); ``--chunk`` is capped so
#: that one chunk stays within this budget. The draws do not depend on the chunk size, so the
#: cap changes no result.
CHUNK_MEMORY_BYTES = 256 * 2 ** 20


def chunk_bytes_per_draw(points: int) -> int:
    """Upper bound of the peak bytes per draw of one tolerance chunk with ``points`` set-points
    (all cases: ~1.9 kB per set-point and draw, plus a fixed part)."""
    return 2000 * int(points) + 10000


def capped_chunk(chunk: int, points: int) -> int:
    """``chunk`` bounded so that one chunk's peak stays within :data:`CHUNK_MEMORY_BYTES`."""
    return max(100, min(int(chunk), CHUNK_MEMORY_BYTES // chunk_bytes_per_draw(points)))


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


def _wants_cell(args, scene) -> bool:
    """``--cell`` given, or a RuT that beamforms in azimuth and elevation with ``--pair`` left
    at its default: the cell of all front ends (3 or 4, as ``linearity --grid``)."""
    if args.cell is not None:
        if args.pair is not DEFAULT_PAIR:
            raise UsageError(f"--cell and --pair {' '.join(map(str, args.pair))}: give one of "
                             "them (the cell study is of the --cell front ends)")
        return True
    if args.pair is not DEFAULT_PAIR:
        return False
    setup = build_setup(scene)
    return Steering.auto(setup.rut, scene.radar).dims == 2 and setup.fe.count in (3, 4)


def _cell(words) -> tuple[int, ...] | None:
    if words is None or list(words) == ["all"]:
        return None
    if "all" in words:
        raise UsageError(f"--cell {' '.join(map(str, words))}: give 3 or 4 front-end indices, "
                         "or all")
    return tuple(int(w) for w in words)


def _study(args, scene, bounds: Bounds) -> ToleranceModel:
    """The study the arguments ask for: a cell (``--cell``, or a 2-D RuT by default), a whole
    arc (``--pair all``, or rotation / RuT-pose errors: every pair on shared draws), or one
    pair."""
    setup = build_setup(scene)
    if _wants_cell(args, scene):
        if list(args.pair) == ["all"]:
            raise UsageError("--cell and --pair all: give one of them")
        if (bounds.rotations or bounds.rut_pose) and (args.verify or args.invert_yield is not None):
            raise UsageError("--verify, --invert-yield: only without rotation or RuT-pose errors "
                             "so far")
        if args.nominal_amplitudes:
            raise UsageError("--nominal-amplitudes: only for the pair study (the cell study "
                             "designs its amplitudes once, at the bin centre)")
        try:
            cell = ChannelPhasors.build(setup, _cell(args.cell), args.points, cell=True)
        except ParameterError as exc:
            raise UsageError(f"--cell: {exc}") from None
        except AngleUnreachable as exc:
            raise UsageError(f"--cell: the cell cannot synthesize its set directions ({exc})") \
                from None
        return ToleranceModel.of(cell)
    arc = list(args.pair) == ["all"] or bounds.rotations or bounds.rut_pose
    if arc and args.verify:
        raise UsageError("--verify: only for one pair with offsets (not --pair all, "
                         "rotations or RuT-pose errors)")
    pairs = pairs_of(setup, args.pair)
    try:
        models = [ChannelPhasors.build(setup, p, args.points) for p in pairs]
    except AngleUnreachable as exc:  # the composite cannot reach a set angle
        which = "--pair" if arc else f"--pair {pairs[0][0]} {pairs[0][1]}"
        raise UsageError(f"{which}: {'a' if arc else 'the'} pair cannot synthesize its span "
                         f"({exc})") from None
    return ToleranceModel.arc(models, setup.fe.count) if arc else ToleranceModel.of(models[0])


def _scene_offsets_effect(scene, model) -> dict | None:
    """The worst error the pair's own mounting offsets in the scene cause (the model's one
    setup, the target at the bin centre), uncalibrated and calibrated: what the warning about
    them means in degrees. None where the pair's front ends have no offsets (or errors the
    phasor model does not take as an offset: rotations, gain or phase)."""
    m = model.sets[0]
    fes = [scene.rts.front_ends[q] for q in m.front_ends]
    off = np.array([[f.radial_offset_m, f.tangential_offset_m, f.height_offset_m] for f in fes])
    if not off.any() or any(getattr(f, name) != 0.0 for f in fes for name in
                            ("yaw_offset_rad", "pitch_offset_rad", "gain_offset_db",
                             "phase_offset_rad")):
        return None
    worst = m.evaluate(off[None], CASES)
    keys = ("radial_offset_mm", "tangential_offset_mm", "height_offset_mm")
    return {"fields": [f"rts.front_ends[{q}].{k}" for q, o in zip(m.front_ends, off)
                       for k, v in zip(keys, o) if v != 0.0],
            "model": "phasor level, one setup with the scene's offsets, target at the bin centre",
            **{f"{case}_deg": float(np.max(np.abs(worst[case][0]))) for case in CASES}}


def cmd_tolerance(args) -> int:
    scene = load_scene_checked(args.scene)
    warn_scene_errors(scene, "tolerance")
    with output_folder(args.out, [args.scene]) as stage:
        return _tolerance(args, scene, stage)


def _tolerance(args, scene, stage) -> int:
    sigma, extra = scales(args)
    k = 1.0 / args.sigma_level if args.distribution == "normal" else 1.0
    bounds = Bounds(tuple(float(x) for x in sigma), k * extra["yaw_rad"], k * extra["pitch_rad"],
                    tuple(k * x for x in extra["rut_position_m"]), k * extra["rut_yaw_rad"])
    model = _study(args, scene, bounds)
    kind = model.kind
    seed = scene.seed if args.seed is None else args.seed
    cases = CASES + ((NOMINAL_AMPLITUDES,) if args.nominal_amplitudes else ())
    points = sum(m.set_rad.shape[0] * (1 if kind != "cell" else len(m.front_ends))
                 for m in model.sets[:1])
    chunk = args.chunk if kind == "arc" else capped_chunk(args.chunk, points)
    t0 = time.perf_counter()
    with progress(args.quiet) as report, chunk_mapper(args.dask, args.workers) as mapper:
        res = monte_carlo(model, bounds, args.draws, seed, args.distribution, args.spec_deg,
                          cases, chunk, report, "Monte Carlo (arc)" if kind == "arc"
                          else "Monte Carlo", mapper, keep_errors=stage is not None
                          and kind == "arc")
        out = res.to_dict()
        if kind == "arc":
            out["sigma_level"] = args.sigma_level if args.distribution == "normal" else None
        if args.verify:
            out["verify"] = verify_draws(model.sets[0], sigma, min(args.verify, args.draws),
                                         seed, args.distribution, cases, progress=report,
                                         all_points=args.verify_all_points).to_dict()
        if args.invert_yield is not None and kind == "arc":  # every drawn scale, one factor
            out["inversion"] = {
                case: max_scale_for_yield(model, bounds, args.draws, seed, args.invert_yield,
                                          args.spec_deg, case, args.distribution, chunk=chunk,
                                          progress=report, mapper=mapper)
                for case in CASES}
        elif args.invert_yield is not None:
            out["inversion"] = {
                case: max_sigma_for_yield(model, sigma, args.draws, seed, args.invert_yield,
                                          args.spec_deg, case, args.invert_axis,
                                          args.distribution, chunk=chunk, progress=report,
                                          mapper=mapper)
                for case in CASES}
    elapsed = time.perf_counter() - t0
    own = _scene_offsets_effect(scene, model) if kind == "pair" else None
    if own is not None:
        out["scene_offsets"] = own
    if stage is not None:
        _write(stage, args, model, res, out, cases, seed)
    if args.json:
        print_json(out)
        return 0
    scale = "sigma" if args.distribution == "normal" else "bound"
    if kind == "arc":
        _print_arc(args, model, out, cases, elapsed)
        return 0
    m = model.sets[0]
    what = (f"pair {tuple(m.front_ends)}" if kind == "pair" else f"cell {tuple(m.front_ends)}")
    print(f"{what}, {args.draws} draws ({args.distribution}, {scale} "
          + ", ".join(f"{a} {s * 1e3:g} mm" for a, s in zip(AXES, sigma))
          + (f"), {len(m.set_rad)} set-points" if kind == "pair" else
             f"), {m.set_rad.shape[0]} set directions (azimuth x elevation)")
          + f", {elapsed:.2f} s ({res.cpu_s:.2f} s CPU in the Monte Carlo)")
    if kind == "pair":
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
    else:
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
    _print_footer(out, args, scale)
    return 0


def _write(stage, args, model: ToleranceModel, res, out: dict, cases, seed: int) -> None:
    """``--out DIR``: tolerance.png, tolerance.json and tolerance_draws.npz (per-draw errors
    and worst angle errors, for sensitivity analysis)."""
    from ..viz.figures import save_figure
    m = model.sets[0]
    fig = res.plot()  # the study, the drawn scales and the spec in its title
    save_figure(fig, stage / "tolerance.png")
    write_json(stage / "tolerance.json", out)
    if model.kind == "arc":
        res.save_npz(stage / "tolerance_draws.npz")
        return
    arrays = {"offsets_m": draw_offsets(seed, res.draws, res.sigma_m, res.distribution,
                                        len(m.front_ends))}
    if model.kind == "pair":
        arrays.update({"pairs": np.array([m.front_ends]), "delay_s": res.delay_s[:, None],
                       "range_offset_m": res.range_offset_m[:, None]})
        arrays.update({f"{case}_deg": v[:, None] for case, v in res.worst_error_deg.items()})
    else:
        arrays.update({"cell": np.array(m.front_ends), "delay_s": res.delay_s,
                       "range_offset_m": res.range_offset_m,
                       "subbin_steps": (np.zeros(res.draws, int) if res.subbin_steps is None
                                        else np.asarray(res.subbin_steps))})
        arrays.update({f"{case}_deg": v for case, v in res.worst_error_deg.items()})
    path = stage / "tolerance_draws.npz"
    tmp = path.with_name(path.name + ".part")
    with open(tmp, "wb") as fh:
        np.savez_compressed(fh, **arrays)
    tmp.replace(path)


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
    study_options(p, 10_000, allow_all=True)
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
    p.add_argument("--distribution", choices=DISTRIBUTIONS, default="normal",
                   help="error distribution (default normal)")
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
    p.add_argument("--chunk", type=number(100, 1_000_000, integer=True), default=10_000,
                   help="draws per chunk (memory), in [100, 1000000] (default 10000); capped "
                        f"so that one chunk needs at most {CHUNK_MEMORY_BYTES >> 20} MiB "
                        "(results do not depend on it)")
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
