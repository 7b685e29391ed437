"""``rtsgeom tolerance --cell``: the mounting-tolerance Monte Carlo of a 2-D cell of front ends
(``analysis.tolerance_cell``; issue 15), in the pair study's JSON and text style."""

from __future__ import annotations

import time

import numpy as np

from ..analysis.tolerance.driver import AXES, CASES
from ..errors import AngleUnreachable
from ..errors import ParameterError
from ..geometry import build_setup
from .._lib.io import write_json
from ..errors import UsageError
from ._common import print_json

__all__ = ["wants_cell", "tolerance_cell"]


def wants_cell(args, scene, default_pair) -> bool:
    """``--cell`` given, or a RuT that beamforms in azimuth and elevation with ``--pair`` left
    at its default: the cell of all front ends (3 or 4, as ``linearity --grid``)."""
    if args.cell is not None:
        return True
    if args.pair is not default_pair:
        return False
    from ..radar.steering import Steering
    setup = build_setup(scene)
    return (Steering.auto(setup.rut, scene.radar).dims == 2
            and setup.fe.count in (3, 4))


def _cell(setup, words) -> tuple[int, ...] | None:
    if words is None or list(words) == ["all"]:
        return None
    if "all" in words:
        raise UsageError(f"--cell {' '.join(map(str, words))}: give 3 or 4 front-end indices, "
                         "or all")
    return tuple(int(w) for w in words)


def tolerance_cell(args, scene, sigma, extra, stage) -> int:
    from ..analysis.tolerance.cell import (CellPhasors, max_sigma_for_yield_cell, monte_carlo_cell,
                                           verify_cell_draws)
    from .._lib.parallel import chunk_mapper
    from .tolerance import _progress, capped_chunk
    from ..analysis.tolerance.arc import Bounds
    if list(args.pair) == ["all"]:
        raise UsageError("--cell and --pair all: give one of them")
    k = 1.0 / args.sigma_level if args.distribution == "normal" else 1.0
    bounds = Bounds(tuple(float(x) for x in sigma), k * extra["yaw_rad"],
                    k * extra["pitch_rad"], tuple(k * x for x in extra["rut_position_m"]),
                    k * extra["rut_yaw_rad"])
    if (bounds.rotations or bounds.rut_pose) and (args.verify or args.invert_yield is not None):
        raise UsageError("--verify, --invert-yield: only without rotation or RuT-pose errors "
                         "so far")
    if args.nominal_amplitudes:
        raise UsageError("--nominal-amplitudes: only for the pair study (the cell study "
                         "designs its amplitudes once, at the bin centre)")
    setup = build_setup(scene)
    n = max(2, int(round(np.sqrt(args.points))))
    try:
        model = CellPhasors.build(setup, _cell(setup, args.cell), n)
    except ParameterError as exc:
        raise UsageError(f"--cell: {exc}") from None
    except AngleUnreachable as exc:
        raise UsageError(f"--cell: the cell cannot synthesize its set directions ({exc})") \
            from None
    chunk = capped_chunk(args.chunk, model.set_rad.shape[0] * len(model.cell))
    seed = scene.seed if args.seed is None else args.seed
    t0 = time.perf_counter()
    with _progress(args.quiet) as progress, chunk_mapper(args.dask, args.workers) as mapper:
        res = monte_carlo_cell(model, sigma, args.draws, seed, args.distribution,
                               args.spec_deg, CASES, chunk, progress, "Monte Carlo", mapper,
                               bounds)
        out = res.to_dict()
        if args.verify:
            v = verify_cell_draws(model, sigma, min(args.verify, args.draws), seed,
                                  args.distribution, CASES, args.verify_all_points, progress)
            v.pop("detail")
            out["verify"] = v
        if args.invert_yield is not None:
            out["inversion"] = {
                case: max_sigma_for_yield_cell(model, sigma, args.draws, seed,
                                               args.invert_yield, args.spec_deg, case,
                                               args.invert_axis, args.distribution,
                                               chunk=chunk, progress=progress, mapper=mapper)
                for case in CASES}
    elapsed = time.perf_counter() - t0
    if stage is not None:
        from ..viz.figures import save_figure, tolerance_cdf_figure
        fig = tolerance_cdf_figure({case: res.worst_error_deg[case][:, 2] for case in CASES},
                                   args.spec_deg, "Worst angular distance per setup, cell "
                                   f"{tuple(model.cell)}")
        save_figure(fig, stage / "tolerance.png")
        write_json(stage / "tolerance.json", out)
        from ..analysis.tolerance.driver import draw_offsets
        arrays = {"offsets_m": draw_offsets(seed, res.draws, res.sigma_m, res.distribution,
                                            len(model.cell)),
                  "cell": np.array(model.cell), "delay_s": res.delay_s,
                  "range_offset_m": res.range_offset_m,
                  "subbin_steps": (np.zeros(res.draws, int) if res.subbin_steps is None
                                   else np.asarray(res.subbin_steps))}
        arrays.update({f"{case}_deg": v for case, v in res.worst_error_deg.items()})
        np.savez_compressed(stage / "tolerance_draws.npz", **arrays)
    if args.json:
        print_json(out)
        return 0
    scale = "sigma" if args.distribution == "normal" else "bound"
    print(f"cell {tuple(model.cell)}, {args.draws} draws ({args.distribution}, {scale} "
          + ", ".join(f"{a} {s * 1e3:g} mm" for a, s in zip(AXES, sigma))
          + f"), {model.set_rad.shape[0]} set directions (azimuth x elevation), "
            f"{elapsed:.2f} s ({res.cpu_s:.2f} s CPU in the Monte Carlo)")
    print(f"  target at a sub-bin position drawn per draw, uniform over one range bin "
          f"({out['subbin']['positions']} positions); the RuT's bin: set-points detected off "
          "the set range's bin " + ", ".join(f"{case} {out[case]['detected_off_bin']}"
                                               for case in CASES))
    for case in CASES:
        st = out[case]
        parts = []
        for key, name in (("azimuth_error_deg", "az"), ("elevation_error_deg", "el"),
                          ("angular_distance_deg", "distance")):
            p = st[key]
            parts.append(f"{name} p95 {p['p95']:.4f} p99 {p['p99']:.4f} max {p['max']:.4f}")
        print(f"  {case:>12}: |error| " + "; ".join(parts) + f" deg; yield "
              f"{100 * st['yield']:.2f} % within {args.spec_deg:g} deg in both angles")
    print_study_footer(out, args, scale)
    return 0


def print_study_footer(out: dict, args, scale: str) -> None:
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
