"""``design --coverage-deg``: whole arcs; ``folder`` is where ``--out`` files go (None: no
``--out``)."""

from __future__ import annotations

import argparse

import numpy as np

from .._lib.io import write_json
from ._common import print_json, progress

__all__ = ["coverage_spec", "design_coverage"]


def coverage_spec(text: str) -> tuple[float, float]:
    """argparse type for ``--coverage-deg A:B`` (A < B, both in [-80, 80] deg)."""
    try:
        a, b = (float(x) for x in text.split(":"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not A:B (azimuths in deg, e.g. "
                                         "-10:10)") from None
    if not (-80.0 <= a < b <= 80.0):
        raise argparse.ArgumentTypeError(f"{text}: need -80 <= A < B <= 80 deg")
    return a, b


COVERAGE_MAPS = {
    "worst_calibrated_deg": ("worst |angle error| (deg)", "Calibrated, over the coverage"),
    "worst_uncalibrated_deg": ("worst |angle error| (deg)", "Uncalibrated, over the coverage"),
    "sigma_mm": ("mounting sigma (mm)", "Tolerance for the yield (whole arc)"),
    "front_ends": ("front ends", "Number of front ends"),
}


def design_coverage(args, scene, folder) -> int:
    """``design --coverage-deg A:B``: N front ends per radius (``analysis.coverage``)."""
    from ..analysis.coverage import best_per_radius, coverage_designs
    seed = scene.seed if args.seed is None else args.seed
    draws = args.draws if args.draws is not None else 300
    with progress(args.quiet) as report:
        grid = coverage_designs(scene, args.coverage_deg, args.radius_m, args.spec_deg,
                                args.yield_, draws, seed, min(args.points, 11),
                                progress=None if report is None else
                                (lambda done, total: report("designs", done, total)))
    out = grid.to_dict()
    if folder is not None:
        from ..viz.figures import design_heatmap_figure, save_figure
        extras = sorted({d.plan.extra for d in grid.designs})
        for name, (zlabel, title) in COVERAGE_MAPS.items():
            z = np.full((len(extras), grid.radius_m.size), np.nan)
            for d in (design.to_dict() for design in grid.designs):
                i = int(np.argmin(np.abs(grid.radius_m - d["radius_m"])))
                v = d.get(name)
                z[extras.index(d["extra"]), i] = np.nan if v is None else float(v)
            fig = design_heatmap_figure(
                grid.radius_m, np.array(extras, float), z, "arc radius R_c (m)",
                "front ends beyond the fewest", zlabel,
                f"{title}, coverage {args.coverage_deg[0]:g}..{args.coverage_deg[1]:g} deg")
            save_figure(fig, folder / f"coverage_{name}.png")
        write_json(folder / "coverage.json", out)
    if args.json:
        print_json(out)
        return 0
    a, b = args.coverage_deg
    print(f"coverage {a:g}..{b:g} deg; spec {grid.spec_deg:g} deg; tolerance: "
          f"{100 * grid.target_yield:g} % of whole arcs within the spec ({draws} draws)")
    print("worst |angle error| over the coverage (deg): on the nominal arc, and p95 over arcs "
          "with 0.1 mm sigma mounting errors")
    print(f"{'R_c m':>6} {'N':>3} {'sp deg':>7} {'res deg':>8} {'cal':>7} {'uncal':>7} "
          f"{'cal p95':>8} {'unc p95':>8} {'sigma mm':>9}  binding; sheet")
    best = {id(d) for d in best_per_radius(grid)}
    for design in grid.designs:
        d = design.to_dict()

        def f(key, fmt):
            v = d.get(key)
            return format(v, fmt) if v is not None and np.isfinite(v) else "-"
        mark = "*" if id(design) in best else " "
        why = ", ".join(d["binding"]) or "-"
        print(f"{d['radius_m']:6.3g}{mark}{d['front_ends']:3d} {d['spacing_deg']:7.3f} "
              f"{d['resolution_deg']:8.3f} {f('worst_calibrated_deg', '7.4f')} "
              f"{f('worst_uncalibrated_deg', '7.4f')} {f('p95_calibrated_at_0.1mm_deg', '8.4f')} "
              f"{f('p95_uncalibrated_at_0.1mm_deg', '8.4f')} {f('sigma_mm', '9.4f')}"
              f"{'+' if d.get('sigma_capped') else ' '} {why}; {d['sheet_change']}"
              + (f"; PROBLEM: {d['problem']}" if d["problem"] else ""))
    print("best per radius (*): the fewest front ends within the spec after calibration")
    for p in (d.plan for d in best_per_radius(grid)):
        print(f"  R_c {p.radius_m:g} m: {p.front_ends} front ends at "
              + ", ".join(f"{x:.2f}" for x in p.angles_deg) + f" deg; {p.sheet_change}")
    return 0
