"""Arc design for N front ends: "a 0.5 m arc covering -10..+10 deg".

For each arc radius the design chooses the number of front ends N and their (uniform) spacing:

1. **Near-field bias.** A front end alone is detected ``bias`` off its module angle (Rx/Tx
   split, the RuT's Tx/Rx parallax, ~1/R_c; ``analysis.nearfield``). The synthesizable span
   runs between the *detected* angles of the outer front ends, so they are placed where the
   RuT detects them at A and B (``A - bias_0``, ``B - bias_last`` on an arc centred on the
   RuT: two or three passes, the bias measured on the placed arc; off-centre or with the
   RuT turned, more passes take the frames' difference out too; where they do not converge,
   the plan has no design and says why).
2. **Resolution** (paper eq. 24). Neighbouring front ends at most 1.22 lambda / d_A apart seen
   from the RuT: ``N_min = ceil(span / resolution) + 1``; the candidates are ``N_min`` and
   ``N_min + 1`` (closer spacing, more hardware).
3. **Cutout fit.** With the sheet, neighbouring cutouts must not overlap:
   ``spacing >= 2 asin(d_cutout / (2 R_sheet))``, and each must hold its antennas. Where they do
   not fit the sheet is removed (``design.fit_sheet``), widened where the front ends lie
   beyond it; the output says so.

Per design (phasor level, exact geometry, no noise; ``analysis.tolerance``, its arcs):
the worst |synthesized - set| over every pair's span (the whole coverage), calibrated and
uncalibrated, on the nominal arc and as the 95th percentile over arcs built with 0.1 mm
mounting errors (one sigma per axis; without calibration the path differences of the
errors are what the synthesis sees); the mounting tolerance (one sigma, the same on the radial, tangential and height
axes) that keeps ``target_yield`` of the *arcs* within the spec (shared per-front-end draws);
and the binding constraint: ``resolution`` (N is the fewest the resolution allows),
``near-field bias`` (the bias of the outer front ends costs a front end more than the bare
coverage would), ``cutout fit`` (the sheet had to be removed).
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._lib.parallel import local_map
from .._lib.results import Result
from ..errors import AngleUnreachable, ParameterError
from ..geometry import build_setup
from ..geometry.setup import nominal_scene, warn_setup_errors
from ..geometry.farfield import angular_resolution_rad
from ..paths import exact_paths
from ..scene import Scene
from .tolerance import (Bounds, ChannelPhasors, MonteCarlo, ToleranceModel, max_scale_for_yield,
                        monte_carlo)
from .design import build_problem, fit_sheet, import_for_workers
from ..calibration.probes import probe_ranges
from .nearfield_terms import single_front_end_angles_rad

__all__ = ["ArcPlan", "ArcDesign", "CoverageDesign", "arc_scene", "plan_arc", "evaluate_arc",
           "coverage_designs", "best_per_radius"]

MAX_BEST_ROWS = 15  # radii listed in a summary
BASE_SIGMA_M = 1e-4  # the tolerance search scales 0.1 mm sigmas
# the coverage maps (``design --coverage-deg --out``): name -> (colour label, title)
COVERAGE_MAPS = {
    "worst_calibrated_deg": ("worst |angle error| (deg)", "Calibrated, over the coverage"),
    "worst_uncalibrated_deg": ("worst |angle error| (deg)", "Uncalibrated, over the coverage"),
    "sigma_mm": ("mounting sigma (mm)", "Tolerance for the yield (whole arc)"),
    "front_ends": ("front ends", "Number of front ends"),
}


@dataclass(frozen=True)
class ArcPlan:
    """One radius's candidate arc (steps 1-3 of the module docstring)."""

    scene: Scene  # the arc as a scene: N front ends, the sheet kept, widened or removed
    radius_m: float
    front_ends: int
    angles_deg: tuple[float, ...]  # module angles, bias compensated
    spacing_deg: float
    resolution_deg: float  # 1.22 lambda / d_A (paper eq. 24)
    min_cutout_spacing_deg: float
    outer_bias_deg: tuple[float, float]  # near-field bias of the outer front ends
    sheet: str  # "kept" | "widened" | "disabled"
    sheet_change: str  # what happened to the sheet, in words
    binding: tuple[str, ...]  # the binding constraints
    extra: int  # front ends beyond the fewest the resolution allows
    problem: str | None = None  # why the placement has no design (it missed the coverage)

    def to_dict(self) -> dict:
        """The plan's JSON keys (the scene left out)."""
        return {"radius_m": self.radius_m, "front_ends": self.front_ends,
                "angles_deg": list(self.angles_deg), "spacing_deg": self.spacing_deg,
                "resolution_deg": self.resolution_deg,
                "min_cutout_spacing_deg": self.min_cutout_spacing_deg,
                "outer_bias_deg": list(self.outer_bias_deg), "sheet": self.sheet,
                "sheet_change": self.sheet_change, "binding": list(self.binding),
                "extra": self.extra}


@dataclass(frozen=True)
class ArcDesign:
    """A planned arc evaluated (:func:`evaluate_arc`); NaN and ``problem`` where it cannot be
    built or synthesize its span, the Monte-Carlo fields None then."""

    plan: ArcPlan
    worst_calibrated_deg: float = math.nan  # worst |error| over the coverage, nominal arc
    worst_uncalibrated_deg: float = math.nan
    sigma_mm: float = math.nan  # mounting sigma that keeps the target yield of whole arcs
    sigma_capped: bool = False  # the tolerance search hit its cap
    problem: str | None = None
    p95_calibrated_deg: float | None = None  # p95 over arcs with 0.1 mm sigma errors
    yield_calibrated: float | None = None  # and the fraction of them within the spec
    p95_uncalibrated_deg: float | None = None
    yield_uncalibrated: float | None = None
    tolerance_yield: float | None = None  # the yield reached at sigma_mm

    def to_dict(self) -> dict:
        """``design --coverage-deg --json``: one entry of ``designs`` (keys as before)."""
        out = self.plan.to_dict()
        out.update(worst_calibrated_deg=self.worst_calibrated_deg,
                   worst_uncalibrated_deg=self.worst_uncalibrated_deg, sigma_mm=self.sigma_mm,
                   sigma_capped=self.sigma_capped, problem=self.problem)
        if self.p95_calibrated_deg is None:  # not evaluated (see problem)
            return out
        out.update({"p95_calibrated_at_0.1mm_deg": self.p95_calibrated_deg,
                    "yield_calibrated_at_0.1mm": self.yield_calibrated,
                    "p95_uncalibrated_at_0.1mm_deg": self.p95_uncalibrated_deg,
                    "yield_uncalibrated_at_0.1mm": self.yield_uncalibrated,
                    "tolerance_yield": self.tolerance_yield})
        return out


def arc_scene(scene: Scene, radius_m: float, angles_rad) -> tuple[Scene, str]:
    """``scene`` with N front ends (copies of its first: layout, cables) at ``angles_rad`` on
    an arc of ``radius_m``, no targets, no mounting, channel or RuT pose errors
    (``geometry.setup.nominal_scene``); the sheet kept, widened or removed so its cutouts fit
    (``design.fit_sheet``). Returns the scene and the sheet's fate."""
    scene = nominal_scene(scene, validate=False)  # (the variant: its own rules below)
    tmpl = scene.rts.front_ends[0]
    fes = tuple(dataclasses.replace(tmpl, angle_rad=float(a)) for a in angles_rad)
    rts = dataclasses.replace(scene.rts, arc_radius_m=float(radius_m), front_ends=fes)
    variant = dataclasses.replace(scene, rts=rts, targets=())
    sheet, state = fit_sheet(variant)
    return dataclasses.replace(variant, sheet=sheet), state


def _min_cutout_spacing_rad(scene: Scene, radius_m: float) -> float:
    sh = scene.sheet
    if not sh.enabled:
        return 0.0
    r = radius_m + sh.radius_offset_m
    return 2 * math.asin(min(1.0, 0.5 * sh.cutout_diameter_m / r)) if r > 0 else math.inf


def _detected_rad(variant: Scene) -> tuple[np.ndarray, np.ndarray]:
    """Each front end alone as the RuT detects it and its module's geometric azimuth, both
    seen from the RuT (radians): their difference is the near-field bias."""
    setup = build_setup(variant)
    rng = float(probe_ranges(setup, 1)[0])
    return single_front_end_angles_rad(setup, exact_paths(setup), rng), setup.fe_azimuth_rad()


#: placement of the outer front ends: passes (at least two) until their detected angles miss
#: the coverage's ends by less than this; a pass moves an end by at most PLACE_STEP_RAD; more
#: than PLACE_FRONT_ENDS_MAX front ends, or ends that cross, stop it (the plan's problem)
PLACE_TOL_RAD = math.radians(1e-3)
PLACE_PASSES_MAX = 8
PLACE_STEP_RAD = math.radians(10.0)
PLACE_FRONT_ENDS_MAX = 64


def plan_arc(scene: Scene, coverage_rad: tuple[float, float], radius_m: float,
             extra: int = 0) -> ArcPlan:
    """Number of front ends and spacing for one radius (steps 1-3 of the module docstring);
    ``extra`` front ends beyond the fewest the resolution allows."""
    a, b = sorted(coverage_rad)
    rut = build_setup(scene).rut
    res = angular_resolution_rad(rut)
    n_bare = max(2, math.ceil((b - a) / res * (1 - 1e-12)) + 1)
    # the outer front ends' arc angles: start at the coverage's ends, measure where the RuT
    # detects them and move each by what it misses (its near-field bias; where the arc is not
    # centred on the RuT, or the RuT is turned, also the difference of the two frames), until
    # they miss by less than PLACE_TOL_RAD (two or three passes on an arc centred on the RuT)
    # (N from the widest gap the RuT sees between neighbours: on an arc centred on the RuT the
    # arc's spacing; off-centre the arc's span scaled by the last pass's ratio of the RuT's
    # widest gap to the arc's spacing)
    ends = np.array([a, b])
    widest = 1.0  # the RuT's widest neighbour gap over the arc's spacing (last pass)
    slope, last = np.ones(2), None  # d(detected) / d(arc angle) of each end (secant)

    def count(lo, hi):
        n = max(2, math.ceil(widest * (hi - lo) / res * (1 - 1e-12)) + 1) + extra
        return min(n, PLACE_FRONT_ENDS_MAX)

    for k in range(PLACE_PASSES_MAX):  # (at least one pass: det, bias, miss are set)
        lo, hi = ends
        n = count(lo, hi)
        variant, _ = arc_scene(scene, radius_m, np.linspace(lo, hi, n))
        det, geo = _detected_rad(variant)
        bias = (det - geo)[[0, -1]]
        if hi > lo:  # (at most 4: an arc that nearly reaches the RuT is refused
            # by the scene rules when the design is evaluated)
            ratio = float(np.max(np.abs(np.diff(geo)))) / ((hi - lo) / (n - 1))
            widest = min(max(1.0, ratio), 4.0) if math.isfinite(ratio) else widest
        if last is not None:
            step = ends - last[0]
            moved = det[[0, -1]] - last[1]
            ok = np.abs(step) > 1e-12
            slope = np.where(ok, moved / np.where(ok, step, 1.0), slope)
            slope = np.clip(slope, 0.2, 5.0)
        miss = np.array([a, b]) - det[[0, -1]]
        if k >= 1 and np.max(np.abs(miss)) < PLACE_TOL_RAD:
            break
        last = (ends.copy(), det[[0, -1]])
        new = ends + np.clip(miss / slope, -PLACE_STEP_RAD, PLACE_STEP_RAD)
        if not new[0] < new[1] or count(*new) >= PLACE_FRONT_ENDS_MAX:
            break  # (diverging: reported below)
        ends = new
    problem = None
    if not np.max(np.abs(miss)) < PLACE_TOL_RAD:
        # the detected angle of an outer front end does not follow its place smoothly here
        # (an arc far off the RuT for this radius): no design, rather than one short of
        # the coverage
        problem = (f"placement: the RuT detects the outer front ends at "
                   f"{math.degrees(det[0]):.3f} and {math.degrees(det[-1]):.3f} deg, not at the "
                   f"coverage's ends {math.degrees(a):g} and {math.degrees(b):g} deg (the arc is "
                   "too far off the RuT for this radius)")
    lo, hi = (float(x) for x in ends)
    n = count(lo, hi)
    angles = np.linspace(lo, hi, n)
    variant, sheet = arc_scene(scene, radius_m, angles)
    spacing = (hi - lo) / (n - 1)
    cut = _min_cutout_spacing_rad(scene, radius_m)
    binding = []
    if extra == 0:
        binding.append("near-field bias" if n > n_bare else "resolution")
    if scene.sheet.enabled and sheet == "disabled":
        binding.append("cutout fit")
    sheet_text = _sheet_text(scene, variant, sheet, spacing, cut)
    return ArcPlan(variant, float(radius_m), int(n), tuple(float(x) for x in np.degrees(angles)),
                   math.degrees(spacing), math.degrees(res), math.degrees(cut),
                   tuple(float(x) for x in np.degrees(bias)), sheet, sheet_text,
                   tuple(binding), extra, problem)


def _sheet_text(scene: Scene, variant: Scene, sheet: str, spacing: float, cut: float) -> str:
    """What an arc design did to the scene's sheet (``sheet``: kept, widened, disabled), in
    words."""
    sh = variant.sheet
    return {
        "kept": "sheet kept",
        "widened": f"sheet widened to [{math.degrees(sh.angle_min_rad):.2f}, "
                   f"{math.degrees(sh.angle_max_rad):.2f}] deg",
        "disabled": (f"sheet REMOVED: cutouts of {scene.sheet.cutout_diameter_m * 1e3:g} mm need "
                     f"{math.degrees(cut):.2f} deg spacing, the design has "
                     f"{math.degrees(spacing):.2f} deg" if scene.sheet.enabled and spacing < cut
                     else "sheet REMOVED (its cutouts cannot hold the antennas or it would not "
                          "enclose the RuT)" if scene.sheet.enabled else "no sheet in the scene"),
    }[sheet]


def evaluate_arc(plan: ArcPlan, spec_deg: float = 0.1, target_yield: float = 0.95,
                 draws: int = 200, seed: int = 0, points: int = 11) -> ArcDesign:
    """Worst calibrated / uncalibrated angle error over the coverage and the mounting tolerance
    for the yield of one planned arc (NaN and ``problem`` where it cannot be built)."""
    problem = plan.problem or build_problem(plan.scene)
    if problem is not None:
        return ArcDesign(plan, problem=problem)
    setup = build_setup(plan.scene)
    pairs = [(i, i + 1) for i in range(setup.fe.count - 1)]
    try:
        models = [ChannelPhasors.build(setup, p, points) for p in pairs]
    except AngleUnreachable as exc:
        return ArcDesign(plan, problem=f"synthesis failed: {exc}")
    zero = np.zeros((2, 3))
    worst = {case: max(float(np.max(np.abs(m.angle_errors(zero, case)))) for m in models)
             for case in ("calibrated", "uncalibrated")}
    arc = ToleranceModel.arc(models, setup.fe.count)
    ref = monte_carlo(arc, Bounds((BASE_SIGMA_M,) * 3), draws, seed, "normal", spec_deg)
    p95 = {case: float(np.percentile(np.abs(ref.arc_worst(case)), 95))
           for case in ("calibrated", "uncalibrated")}
    inv = max_scale_for_yield(arc, Bounds((BASE_SIGMA_M,) * 3),
                              MonteCarlo(draws=int(draws), seed=int(seed)),
                              target_yield, spec_deg, "calibrated", rel_tol=0.05)
    return ArcDesign(plan, worst["calibrated"], worst["uncalibrated"],
                     inv["factor"] * BASE_SIGMA_M * 1e3, inv["capped"], None,
                     p95["calibrated"], ref.yield_("calibrated"), p95["uncalibrated"],
                     ref.yield_("uncalibrated"), inv["yield"])


@dataclass(frozen=True, repr=False)
class CoverageDesign(Result):
    """The candidate arcs per radius. ``print(grid)`` is a summary; ``to_dataframe()`` one
    row per candidate; ``plot(name)`` one of :data:`COVERAGE_MAPS` over (radius, front ends
    beyond the fewest)."""

    coverage_deg: tuple[float, float]
    radius_m: np.ndarray
    spec_deg: float
    target_yield: float
    draws: int
    designs: tuple[ArcDesign, ...]  # radius-major, candidates N_min, N_min + 1
    scene_name: str = ""  # the template scene's, for the figures' titles

    def _summary(self):
        a, b = self.coverage_deg
        title = (f"arcs covering {a:g}..{b:g} deg: {self.radius_m.size} radii x "
                 f"{len(self.designs) // max(self.radius_m.size, 1)} candidates")
        rows = [("spec", f"{self.spec_deg:g} deg, {100 * self.target_yield:g} % of whole arcs, "
                         f"{self.draws} draws")]
        for d in best_per_radius(self)[:MAX_BEST_ROWS]:
            rows.append((f"R_c {d.plan.radius_m:g} m", (
                f"{d.plan.front_ends} front ends {d.plan.spacing_deg:.3g} deg apart, worst "
                f"{d.worst_calibrated_deg:.3g} deg calibrated "
                f"({d.worst_uncalibrated_deg:.3g} uncalibrated), sigma {d.sigma_mm:.3g} mm")))
        return title, rows

    def _columns(self) -> dict:
        rows = [d.to_dict() for d in self.designs]
        keys = ("radius_m", "front_ends", "extra", "spacing_deg", "sheet",
                "worst_calibrated_deg", "worst_uncalibrated_deg", "sigma_mm", "problem")
        return {k: [r.get(k) for r in rows] for k in keys}

    def plot(self, name: str = "worst_calibrated_deg"):
        """One of :data:`COVERAGE_MAPS` over arc radius and the front ends beyond the fewest
        (whole numbers), each cell's value written in it."""
        from ..viz.figures import design_heatmap_figure
        if name not in COVERAGE_MAPS:
            raise ParameterError(f"map {name!r}: one of {', '.join(COVERAGE_MAPS)}")
        zlabel, what = COVERAGE_MAPS[name]
        extras = sorted({d.plan.extra for d in self.designs})
        z = np.full((len(extras), self.radius_m.size), np.nan)
        for d in (design.to_dict() for design in self.designs):
            i = int(np.argmin(np.abs(self.radius_m - d["radius_m"])))
            v = d.get(name)
            z[extras.index(d["extra"]), i] = np.nan if v is None else float(v)
        a, b = self.coverage_deg
        head = f"{self.scene_name}: " if self.scene_name else ""
        return design_heatmap_figure(
            self.radius_m, np.array(extras, float), z, "arc radius R_c (m)",
            "front ends beyond the fewest", zlabel,
            f"{head}{what}\ncoverage {a:g}..{b:g} deg, spec {self.spec_deg:g} deg, "
            f"{100 * self.target_yield:g} % yield, {self.draws} draws",
            contour_floor=0.01 * self.spec_deg if name.endswith("_deg") else None,
            integer_y=True, integer_z=name == "front_ends")

    def to_dict(self) -> dict:
        def clean(v):
            return None if isinstance(v, float) and not math.isfinite(v) else v
        return {"coverage_deg": list(self.coverage_deg),
                "radius_m": [float(r) for r in self.radius_m], "spec_deg": self.spec_deg,
                "yield": self.target_yield, "draws": self.draws,
                "designs": [{k: clean(v) for k, v in d.to_dict().items()} for d in self.designs],
                "best": [{k: clean(v) for k, v in d.to_dict().items()}
                         for d in best_per_radius(self)]}

    def write(self, folder) -> list[str]:
        """``rtsgeom design --coverage-deg --out``: coverage_<map>.png per map of
        :data:`COVERAGE_MAPS` and coverage.json into ``folder``; returns the names."""
        from ..viz.figures import save_figure  # matplotlib: only where a figure is written
        names = [f"coverage_{name}.png" for name in COVERAGE_MAPS]
        for name, file in zip(COVERAGE_MAPS, names):
            save_figure(self.plot(name), Path(folder) / file)
        self.to_json(Path(folder) / "coverage.json")
        return names + ["coverage.json"]


def best_per_radius(grid: CoverageDesign) -> list[ArcDesign]:
    """Per radius: the fewest front ends meeting the spec after calibration (largest
    tolerance among equals), else the smallest worst error."""
    out = []
    for r in grid.radius_m:
        cand = [d for d in grid.designs if d.plan.radius_m == float(r) and d.problem is None
                and math.isfinite(d.worst_calibrated_deg)]
        if not cand:
            continue
        ok = [d for d in cand if d.worst_calibrated_deg <= grid.spec_deg]
        pick = (min(ok, key=lambda d: (d.plan.front_ends, -d.sigma_mm)) if ok
                else min(cand, key=lambda d: d.worst_calibrated_deg))
        out.append(pick)
    return out


def _evaluate_planned(scene: Scene, cov, spec_deg, target_yield, draws, seed, points,
                      cell) -> ArcDesign:
    """One candidate arc ``cell = (radius, extra front ends)``, planned and evaluated."""
    r, extra = cell
    return evaluate_arc(plan_arc(scene, cov, r, extra), spec_deg, target_yield, draws, seed,
                        points)


def coverage_designs(scene: Scene, coverage_deg: tuple[float, float], radius_m,
                     spec_deg: float = 0.1, target_yield: float = 0.95, draws: int = 200,
                     seed: int = 0, **options) -> CoverageDesign:
    """Plan and evaluate the candidate arcs for every radius
    (:class:`~.design_study.DesignStudy` with ``coverage_deg`` calls it).

    Parameters
    ----------
    scene : Scene
        The template scene.
    coverage_deg : (float, float)
        The azimuths to cover (deg).
    radius_m : array_like
        Arc radii (m).
    spec_deg, target_yield, draws, seed
        As :func:`~rtsgeom.analysis.design.design_grid`.
    **options
        ``points`` per pair (default 11), ``extras`` (front ends beyond the fewest, default
        (0, 1)), ``progress(done, total)``, ``workers`` as
        :func:`~rtsgeom.analysis.design.design_grid` (each arc is pure: the same result
        however they are spread).

    Returns
    -------
    CoverageDesign
    """
    points = options.pop("points", 11)
    extras = options.pop("extras", (0, 1))
    progress = options.pop("progress", None)
    workers = options.pop("workers", 1)
    if options:
        raise ParameterError(f"coverage_designs: no option {', '.join(options)} (points, "
                             "extras, progress, workers)")
    warn_setup_errors(scene, "design")
    cov = tuple(math.radians(x) for x in coverage_deg)
    radii = np.asarray(radius_m, float).ravel()
    cells = [(float(r), e) for r in radii for e in extras]
    one = functools.partial(_evaluate_planned, scene, cov, spec_deg, target_yield, draws, seed,
                            points)
    designs = local_map(one, cells, workers, progress, before_fork=import_for_workers)
    return CoverageDesign(tuple(float(x) for x in coverage_deg), radii, float(spec_deg),
                          float(target_yield), int(draws), tuple(designs), scene.name)
