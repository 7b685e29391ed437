"""``rtsgeom design``: the arc design map of a front-end pair (arc radius x front-end spacing:
worst angle error, near-field bias, range offset and the mounting tolerance for a yield), or
with ``--coverage-deg A:B`` the arc of N front ends covering A..B deg for each radius."""

from __future__ import annotations

import argparse
import re
import sys

import numpy as np

from ..analysis.coverage import best_per_radius
from ..analysis.design_study import DesignStudy
from ..analysis.tolerance import MonteCarlo
from ..analysis.tolerance.config import STUDY_ARGS
from ._common import (flagged, load_scene_checked, number, output_folder, print_json,
                      progress, study_options)


def _grid_spec(lo: float, hi: float, unit: str, max_n: int = 50):
    """argparse type for ``A:B:N``: N values from A to B (A <= B, both in [lo, hi])."""
    def parse(text: str) -> np.ndarray:
        parts = text.split(":")
        try:
            a, b, n = float(parts[0]), float(parts[1]), int(parts[2])
            if len(parts) != 3:
                raise ValueError
        except (ValueError, IndexError):
            raise argparse.ArgumentTypeError(f"{text!r} is not A:B:N (from A to B {unit}, "
                                             "N values, e.g. 0.5:2:4)") from None
        if not (lo <= a <= hi and lo <= b <= hi) or a > b:
            raise argparse.ArgumentTypeError(
                f"{text}: A and B must lie in [{lo:g}, {hi:g}] {unit} with A <= B")
        if not 1 <= n <= max_n or (n == 1 and a != b):
            raise argparse.ArgumentTypeError(
                f"{text}: N must be in [1, {max_n}] (1 only with A == B)")
        return np.linspace(a, b, n)
    return parse


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


def study_of(args, report=None) -> DesignStudy:
    """The :class:`~rtsgeom.analysis.design_study.DesignStudy` the flags ask for."""
    mc = None
    if args.draws is not None or args.seed is not None or report is not None:
        draws = args.draws or (300 if args.coverage_deg is not None else 2000)
        mc = MonteCarlo(draws, args.seed, progress=report)
    return DesignStudy(tuple(args.radius_m), tuple(args.spacing_deg), tuple(args.pair),
                       args.coverage_deg, args.spec_deg, args.yield_, mc, args.points,
                       args.workers)


def cmd_design(args) -> int:
    scene = load_scene_checked(args.scene)  # the studies warn of the scene's own errors
    with output_folder(args.out, [args.scene]) as stage:
        n = len(scene.rts.front_ends)
        i, j = sorted(args.pair)
        if args.coverage_deg is None and n > 2 and j == i + 1 < n and not args.quiet:
            others = ", ".join(f"{k} {k + 1}" for k in range(n - 1) if k != i)
            print(f"rtsgeom: note: design studies the pair {(i, j)} of the scene's {n} front "
                  f"ends (its centre angle, spacing and radius varied); --pair I J for another "
                  f"adjacent pair ({others}), --coverage-deg A:B for the whole arc",
                  file=sys.stderr)
        with progress(args.quiet) as report:
            with flagged(args):
                grid = study_of(args, report)(scene)
        if stage is not None:
            grid.write(stage)
    if args.coverage_deg is not None:
        return _print_coverage(args, grid)
    out = grid.to_dict()
    sheet_note = _sheet_note(out["designs"])
    if args.json:
        print_json(out)
        if sheet_note and not args.quiet:
            print(f"rtsgeom: {sheet_note}", file=sys.stderr)
        return 0
    print(f"pair {grid.pair}, centre {grid.centre_deg:.2f} deg, angular resolution "
          f"{grid.angular_resolution_deg:.2f} deg; tolerance: {100 * grid.target_yield:g} % "
          f"within {grid.spec_deg:g} deg ({grid.draws} draws)")
    print(f"{'R_c m':>6} {'sp deg':>7} {'worst deg':>10} {'bias deg':>9} "
          f"{'cal range offset mm':>19} "
          f"{'sigma cal mm':>13} {'sigma unc mm':>13}  note")
    for d in out["designs"]:
        def f(key, fmt):  # "-" in the column's width where there is no value
            return format(d[key], fmt) if d[key] is not None else "-".rjust(int(fmt.split(".")[0]))
        note = d["problem"] or ", ".join(
            ([] if d["sheet"] == "kept" else [f"sheet {d['sheet']}"])
            + (["> resolution"] if d["exceeds_resolution"] else []))
        print(f"{d['radius_m']:6.3g} {d['spacing_deg']:7.3g} {f('worst_error_deg', '10.4f')} "
              f"{f('near_field_bias_deg', '9.4f')} {f('range_offset_mm', '19.2f')} "
              f"{f('sigma_calibrated_mm', '13.4f')} {f('sigma_uncalibrated_mm', '13.4f')}  "
              f"{note}")
    if sheet_note:
        print(sheet_note)
    return 0


def _sheet_note(designs: list[dict]) -> str:
    """One line saying where the design disabled or widened the sheet (else empty)."""
    parts = []
    for state, why in (("disabled", "its cutouts do not fit (they would overlap or not hold "
                                    "both antennas); no sheet is modelled there"),
                       ("widened", "the front ends lie beyond it")):
        hit = [d for d in designs if d["sheet"] == state]
        if hit:
            cells = ", ".join(f"{d['radius_m']:g} m/{d['spacing_deg']:g} deg" for d in hit[:6])
            more = f" and {len(hit) - 6} more" if len(hit) > 6 else ""
            parts.append(f"sheet {state} in {len(hit)} of {len(designs)} designs "
                         f"(R_c/spacing {cells}{more}): {why}")
    return "note: " + "; ".join(parts) if parts else ""




def _print_coverage(args, grid) -> int:
    """``design --coverage-deg A:B``: N front ends per radius (``analysis.coverage``)."""
    if args.json:
        print_json(grid.to_dict())
        return 0
    draws = grid.draws
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


def register(sub) -> None:
    p = sub.add_parser("design", help="arc radius x front-end spacing design map")
    study_options(p, STUDY_ARGS, 2000)
    p.set_defaults(points=None)  # 21 for the grid, 11 per pair with --coverage-deg
    p.add_argument("--radius-m", type=_grid_spec(0.1, 100.0, "m"), default=np.linspace(0.5, 2.0, 4),
                   metavar="A:B:N", help="arc radii, N from A to B m (default 0.5:2:4)")
    p.add_argument("--spacing-deg", type=_grid_spec(0.1, 90.0, "deg"),
                   default=np.linspace(4.0, 20.0, 5), metavar="A:B:N",
                   help="front-end spacings, N from A to B deg (default 4:20:5)")
    p.add_argument("--coverage-deg", type=coverage_spec, default=None, metavar="A:B",
                   help="design an arc of N front ends covering A..B deg for each --radius-m "
                        "(number of front ends and spacing chosen; --spacing-deg and --pair "
                        "unused; --points per pair, default 11 here)")
    p.add_argument("--yield", dest="yield_", type=number(1e-6, 1.0), default=0.95, metavar="Y",
                   help="fraction of setups within the spec for the tolerance, in (0, 1] "
                        "(default 0.95)")
    p.add_argument("--workers", type=number(1, 1024, integer=True), default=None,
                   help="evaluate the grid's designs in N processes (same result; default: "
                        "the cores this process may run on)")
    # "--coverage-deg -10:10": argparse takes a word starting with "-" for an option unless it
    # looks like a negative number; teach this parser that A:B ranges are numbers too.
    p._negative_number_matcher = re.compile(r"^-\d+$|^-\d*\.\d+$|^-?[\d.]+(:-?[\d.]+)+$")
    p.set_defaults(func=cmd_design, draws=None)  # 2000 for the grid, 300 with --coverage-deg
