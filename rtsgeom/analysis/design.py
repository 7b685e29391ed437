"""Arc design: how arc radius and front-end spacing trade synthesis accuracy, near-field bias,
calibration cost and mounting tolerance.

For each (arc radius R_c, front-end spacing) a two-front-end variant of a scene is built: the
pair's two front ends (their antenna separation, cables and so on kept, mounting and channel
errors dropped) placed symmetrically about the pair's centre angle, targets dropped, the sheet
kept, widened, or disabled where its cutouts would not fit. Per design, at phasor level
(:class:`~rtsgeom.analysis.tolerance.ChannelPhasors`: exact geometry, exact amplitudes, no noise):

``worst_error_deg``
    worst |synthesized - set| angle over the span after the delay calibration, nominal setup;
``near_field_bias_deg``
    a single front end's detected minus geometric angle (module centre seen from the RuT), the
    mean of the two (Rx/Tx separation and the RuT's Tx/Rx parallax, ~1/R_c);
``range_offset_mm``
    the calibration's range offset, c0/2 times the delay mismatch it leaves between the two
    channels (nominal setup);
``sigma_calibrated_mm``, ``sigma_uncalibrated_mm``
    the mounting tolerance (one sigma, the same on the radial, tangential and height axes) that
    keeps ``target_yield`` of the setups within ``spec_deg``: a small Monte Carlo
    (:func:`~rtsgeom.analysis.tolerance.max_sigma_for_yield`);

and ``exceeds_resolution``: the spacing seen from the RuT is larger than its angular
resolution 1.22 lambda / d_A (paper eq. 24), where the composite splits into two peaks.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._lib.results import Result
from .._lib.util import frozen
from ..errors import AngleUnreachable
from ..geometry import build_setup
from ..geometry.setup import nominal_scene, warn_setup_errors
from ..geometry.farfield import angular_resolution_rad
from .._lib.parallel import local_map
from ..scene import Scene, SheetConfig
from ..scene.rules import arc_centre_m, problems
from .tolerance import CASES, ChannelPhasors, MonteCarlo, max_sigma_for_yield, monte_carlo
from .tolerance.search import critical_ratio, largest_passing_scale
from ..errors import ParameterError
from ..pipeline.plan import uses_cells

__all__ = ["METRICS", "DesignGrid", "two_front_end_scene", "DesignSpec", "evaluate_design",
           "design_grid", "check_azimuth_arc"]

# name -> (heat-map colour label, title)
METRICS = {
    "worst_error_deg": ("worst |angle error| (deg)", "Synthesized angle after calibration"),
    "near_field_bias_deg": ("detected - geometric (deg)", "Near-field bias of one front end"),
    "range_offset_mm": ("range offset (mm)", "Calibration range offset"),
    "sigma_calibrated_mm": ("mounting sigma (mm)", "Tolerance for the spec, calibrated"),
    "sigma_uncalibrated_mm": ("mounting sigma (mm)", "Tolerance for the spec, uncalibrated"),
}
# a design map's lowest contour level: below it differences are the evaluation's noise
# (~1e-5 deg of a closed form that is exact to that) or too small to build to
CONTOUR_FLOOR = {
    "worst_error_deg": lambda g: 0.01 * g.spec_deg,
    "near_field_bias_deg": lambda g: 0.01 * g.spec_deg,
    "range_offset_mm": lambda g: 0.01,
    "sigma_calibrated_mm": lambda g: 0.001,
    "sigma_uncalibrated_mm": lambda g: 0.001,
}
SHEET_MARGIN_RAD = math.radians(2.0)  # sheet beyond the outer cutouts when it is widened


def check_azimuth_arc(scene: Scene, name: str = "design") -> None:
    """Raise :class:`~rtsgeom.errors.ParameterError` (its message naming what to use instead)
    where the scene's front ends form 2-D cells (a front end or a target off elevation 0,
    :func:`rtsgeom.pipeline.plan.uses_cells`): the design varies a pair's azimuth spacing on an arc
    and synthesizes in azimuth only, so on a sphere it would silently design one plane of the
    cell and report that as the cell's design."""
    if uses_cells(scene):
        raise ParameterError(
            f"{name}: this scene's front ends form 2-D cells (azimuth and elevation); the arc "
            "design varies the azimuth spacing of front ends on an arc and synthesizes in "
            "azimuth only, it has no design for a cell: use `tolerance SCENE --cell all` (the "
            "cell's mounting tolerance), `linearity SCENE --grid N` and `nearfield SCENE` for "
            "the cell")


def two_front_end_scene(scene: Scene, pair: tuple[int, int], radius_m: float,
                        spacing_rad: float) -> tuple[Scene, str, str | None]:
    """The scene with only the pair's front ends, ``spacing_rad`` apart on an arc of
    ``radius_m`` symmetric about their centre angle; no targets, no mounting, channel or RuT
    pose errors (``geometry.setup.nominal_scene``: the design's geometric reference, the
    front ends' angles seen from the RuT, is the nominal one its model is built on).

    Returns the scene, what happened to the sheet (``kept``, ``widened``, ``disabled``) and why
    the design cannot be built (None when it can)."""
    scene = nominal_scene(scene, validate=False)  # (the variant: its own rules below)
    fes = scene.rts.front_ends
    lo, hi = sorted((fes[pair[0]], fes[pair[1]]), key=lambda f: f.angle_rad)
    centre = 0.5 * (lo.angle_rad + hi.angle_rad)
    new = (dataclasses.replace(lo, angle_rad=centre - 0.5 * spacing_rad),
           dataclasses.replace(hi, angle_rad=centre + 0.5 * spacing_rad))
    rts = dataclasses.replace(scene.rts, arc_radius_m=float(radius_m), front_ends=new)
    variant = dataclasses.replace(scene, rts=rts, targets=())
    sheet, state = fit_sheet(variant)
    variant = dataclasses.replace(variant, sheet=sheet)
    return variant, state, build_problem(variant)


def fit_sheet(scene: Scene) -> tuple[SheetConfig, str]:
    """The scene's sheet for the variant: kept if the cutouts fit, widened if the front ends
    lie beyond it, disabled if cutouts would overlap, not hold both antennas, cut the sheet in
    two, or the RuT would sit outside it."""
    sheet, rts = scene.sheet, scene.rts
    if not sheet.enabled:
        return sheet, "disabled"
    off = dataclasses.replace(sheet, enabled=False)
    r_sheet = rts.arc_radius_m + sheet.radius_offset_m
    d = sheet.cutout_diameter_m
    a = [f.angle_rad for f in rts.front_ends]
    dist = math.dist(scene.radar.position_m, arc_centre_m(scene))
    if (r_sheet <= max(0.05, dist) or d >= sheet.height_m or d >= 2 * r_sheet
            or any(max(math.hypot(*o) for o in f.antenna_offsets_m()) >= 0.5 * d
                   for f in rts.front_ends)
            or 2 * r_sheet * math.sin(0.5 * abs(a[1] - a[0])) < d):
        return off, "disabled"
    half = math.asin(0.5 * d / r_sheet)
    lo, hi = min(a) - half, max(a) + half
    if lo >= sheet.angle_min_rad and hi <= sheet.angle_max_rad:
        return sheet, "kept"
    wide = dataclasses.replace(sheet, angle_min_rad=min(sheet.angle_min_rad, lo - SHEET_MARGIN_RAD),
                               angle_max_rad=max(sheet.angle_max_rad, hi + SHEET_MARGIN_RAD))
    return wide, "widened"


def build_problem(scene: Scene) -> str | None:
    """Why the variant cannot be built: the first rule of the scene schema it violates."""
    found = problems(scene)
    return found[0] if found else None


@dataclass(frozen=True)
class DesignSpec:
    """How each design of :func:`design_grid` is judged.

    Parameters
    ----------
    spec_deg : float
        The angle error a setup may have (deg).
    target_yield : float
        The share of the setups within ``spec_deg`` the design's tolerance keeps.
    draws, seed : int
        Monte-Carlo draws per tolerance search and their seed.
    points : int
        Set-points across the pair's span per design.
    rel_tol : float
        The tolerance search's relative tolerance.
    """

    spec_deg: float = 0.1
    target_yield: float = 0.95
    draws: int = 2000
    seed: int = 0
    points: int = 21
    rel_tol: float = 0.02


def evaluate_design(scene: Scene, pair: tuple[int, int], radius_m: float, spacing_rad: float,
                    spec: DesignSpec = DesignSpec()) -> dict:
    """All metrics of one design (NaN where it cannot be built; ``problem`` says why), judged
    by ``spec``."""
    spec_deg, target_yield, draws = spec.spec_deg, spec.target_yield, spec.draws
    seed, points, rel_tol = spec.seed, spec.points, spec.rel_tol
    variant, sheet_state, problem = two_front_end_scene(scene, pair, radius_m, spacing_rad)
    out = {"radius_m": float(radius_m), "spacing_deg": round(math.degrees(spacing_rad), 9),
           "sheet": sheet_state, "problem": problem, "exceeds_resolution": None}
    out.update({name: float("nan") for name in METRICS})
    if problem is not None:
        return out
    setup = build_setup(variant)
    gap = abs(float(np.diff(setup.fe_azimuth_rad())[0]))
    out["exceeds_resolution"] = bool(gap > angular_resolution_rad(setup.rut))
    zero = np.zeros((2, 3))
    try:
        # the calibrated plan first (it does not depend on the bin-centre designs that
        # solved() adds with a root finder per set-point, most of a split design's build)
        model = ChannelPhasors.build(setup, (0, 1), points, solve_bin_centre=False)
        d = model.draw(zero[None], None, ("calibrated",))["calibrated"]
        split = not np.all(np.isfinite(d["amplitudes"]))
        if not split:
            model = model.procedure.solved(model)
    except AngleUnreachable as exc:  # no ratio reaches a set angle: the composite has split
        out["problem"] = f"synthesis failed: {exc}"
        return out
    bias = np.degrees(model.procedure.fe_angle_rad - setup.fe_azimuth_rad())
    out["near_field_bias_deg"] = float(np.mean(bias))
    steps = model.calibration_steps(model.x_nominal)  # (2,): I at 0, J calibrated
    out["range_offset_mm"] = float(model.range_offsets_m(zero[None], steps[None])[0, 1]) * 1e3
    out["delta_tau_ps"] = float(steps[1] * model.delay_resolution_s * 1e12)
    if split:
        # no ratio puts the composite at some set angle (its closed-form design has no root:
        # the beams are too far apart and the composite splits): an error in degrees would
        # only be the distance to wherever the estimator lands on an undefined snapshot
        out["problem"] = ("synthesis failed: no amplitude ratio places the target at every "
                          "set angle (the composite splits)")
        return out
    out["worst_error_deg"] = float(np.degrees(np.max(np.abs(d["error_rad"]))))
    for case in CASES:
        inv = tolerance_search(model, case, draws, seed, target_yield, spec_deg, rel_tol)
        out[f"sigma_{case}_mm"] = inv["sigma_mm"]["radial"]
        out[f"sigma_{case}_capped"] = inv["capped"]
    return out


#: draws of the pilot search that places the full search's first evaluation (a prefix of
#: the full draws) and its relative tolerance
PILOT_DRAWS = 250
PILOT_REL_TOL = 0.05
PILOT_EVALUATIONS = 3


def tolerance_search(model: ChannelPhasors, case: str, draws: int, seed: int,
                     target_yield: float, spec_deg: float, rel_tol: float) -> dict:
    """:func:`~rtsgeom.analysis.tolerance.max_sigma_for_yield` of ``draws`` draws (all three
    axes scaled together), started where a pilot search on the first :data:`PILOT_DRAWS` of
    the same draws (the same seed and stream) puts the tolerance, with the power law of the
    deciding draw's error in the scale that the pilot measured (:func:`pilot_estimate`): the
    full search's secant then closes its bracket in two or three evaluations instead of about
    five from a fixed 0.1 mm with an assumed power 1 (the full Monte Carlos were half of
    ``design``'s time). The pilot only places the start: the result is the full search's, to
    its ``rel_tol``. Fewer than 4 x :data:`PILOT_DRAWS` draws: no pilot."""
    start, slope = 1e-4, 1.0
    if draws >= 4 * PILOT_DRAWS:
        start, slope = pilot_estimate(model, case, seed, target_yield, spec_deg)
    return max_sigma_for_yield(model, [start] * 3, MonteCarlo(draws=int(draws), seed=int(seed)),
                               target_yield, spec_deg, case, rel_tol=rel_tol, slope=slope)


def pilot_estimate(model: ChannelPhasors, case: str, seed: int, target_yield: float,
                   spec_deg: float, draws: int = PILOT_DRAWS,
                   cap_m: float = 0.01) -> tuple[float, float]:
    """Where the deciding draw's error over the spec (:func:`critical_ratio`) reaches 1 on
    ``draws`` draws, and its power of the scale there: the secant through the two pilot
    evaluations nearest to r = 1 (log r against log t). Returns (scale m, power); (1e-4, 1)
    where the pilot finds nothing to interpolate."""
    pts: dict[float, float] = {}

    def evaluate(t: float) -> tuple[float, float]:
        res = monte_carlo(model, [t] * 3, draws, seed, spec_deg=spec_deg, cases=(case,))
        worst = res.worst_error_deg[case]
        r = critical_ratio(worst, spec_deg, target_yield)
        if 0 < r < math.inf:
            pts[t] = math.log(r)
        return float(np.mean(np.abs(worst) <= spec_deg)), r

    # a few evaluations: past them the pilot's own sampling error (~5 % on 250 draws at a 95 %
    # yield) exceeds what a tighter bracket would add
    largest_passing_scale(evaluate, 1.0, target_yield, 1e-4, cap_m, PILOT_REL_TOL,
                          max_evaluations=PILOT_EVALUATIONS)
    near = sorted(pts.items(), key=lambda p: abs(p[1]))[:2]
    if len(near) < 2:
        return 1e-4, 1.0
    (t1, v1), (t2, v2) = near
    slope = (v2 - v1) / (math.log(t2) - math.log(t1))
    if not (0.2 < slope < 20):  # not a power law there (a step): the plain search
        return 1e-4, 1.0
    return min(t1 * math.exp(-v1 / slope), cap_m), slope


def _evaluate_cell(scene, pair, spec: DesignSpec, cell) -> dict:
    """:func:`evaluate_design` of one (radius, spacing) cell (a picklable task for a pool)."""
    return evaluate_design(scene, pair, cell[0], cell[1], spec)


@dataclass(frozen=True, repr=False)
class DesignGrid(Result):
    """Metrics over radius (columns) x spacing (rows): each grid has shape (spacings, radii).

    ``print(grid)`` is a summary; ``to_dataframe()`` one row per design (``radius_m``,
    ``spacing_deg``, the metrics, ``exceeds_resolution``); ``plot(metric)`` one metric's map,
    the figures of ``rtsgeom design --out``.

    Attributes
    ----------
    pair : (int, int)
    radius_m, spacing_deg : arrays
    metrics : dict
        Name -> (spacings, radii) array, one per :data:`METRICS`.
    exceeds_resolution : (spacings, radii) bool
    designs : tuple of dict
    """

    pair: tuple[int, int]
    centre_deg: float
    radius_m: np.ndarray
    spacing_deg: np.ndarray
    angular_resolution_deg: float
    spec_deg: float
    target_yield: float
    draws: int
    seed: int
    metrics: dict  # name -> (S, R)
    exceeds_resolution: np.ndarray  # (S, R) bool
    designs: tuple  # per cell, row-major: evaluate_design's dict
    scene_name: str = ""  # the template scene's, for the figures' titles

    def _summary(self):
        title = (f"arc design of pair {self.pair} (centre {self.centre_deg:.2f} deg): "
                 f"{self.spacing_deg.size} spacings x {self.radius_m.size} radii")
        rows = [("radius_m", self.radius_m), ("spacing_deg", self.spacing_deg),
                ("tolerance", f"{100 * self.target_yield:g} % within {self.spec_deg:g} deg, "
                              f"{self.draws} draws, seed {self.seed}"),
                ("exceeds_resolution", f"{int(np.sum(self.exceeds_resolution))} of "
                                       f"{self.exceeds_resolution.size} designs (spacing > "
                                       f"{self.angular_resolution_deg:.2f} deg, eq. 24)")]
        rows += [(name, self.metrics[name]) for name in METRICS]
        sigma = np.where(np.isfinite(self.metrics["sigma_calibrated_mm"]),
                         self.metrics["sigma_calibrated_mm"], -np.inf)
        if np.isfinite(sigma).any():
            j, i = np.unravel_index(int(np.argmax(sigma)), sigma.shape)
            rows.append(("widest tolerance", f"{sigma[j, i]:.3g} mm calibrated at R_c "
                                             f"{self.radius_m[i]:g} m, spacing "
                                             f"{self.spacing_deg[j]:g} deg"))
        return title, rows

    def _columns(self) -> dict:
        s, r = np.meshgrid(self.spacing_deg, self.radius_m, indexing="ij")
        cols = {"radius_m": r.ravel(), "spacing_deg": s.ravel()}
        cols.update({name: np.ravel(v) for name, v in self.metrics.items()})
        cols["exceeds_resolution"] = np.ravel(self.exceeds_resolution)
        return cols

    def plot(self, metric: str = "sigma_calibrated_mm"):
        """One metric's map over (radius, spacing) (lines when one of them is a single value);
        the title names the scene, the pair, the spec and the yield. By default the map a
        designer reads: the calibrated mounting tolerance for the spec (``worst_error_deg``
        is the exact synthesis's residual, about 1e-5 deg everywhere)."""
        from ..viz.figures import design_heatmap_figure, design_lines_figure
        if metric not in METRICS:
            raise ParameterError(f"metric {metric!r}: one of {', '.join(METRICS)}")
        zlabel, what = METRICS[metric]
        mask = np.asarray(self.exceeds_resolution, bool)
        lines = min(self.radius_m.size, self.spacing_deg.size) == 1
        head = f"{self.scene_name}: " if self.scene_name else ""
        title = (f"{head}{what}\npair {self.pair}, spec {self.spec_deg:g} deg, "
                 f"{100 * self.target_yield:g} % yield, {self.draws} draws")
        floor = CONTOUR_FLOOR[metric](self)
        z = np.asarray(self.metrics[metric], float)
        notes = []
        if np.isfinite(z).any() and np.nanmax(np.abs(z)) < floor:
            notes.append(f"every value below {floor:g} (colours 0..{floor:g})")
        if mask.any():
            notes.append(f"{'hollow' if lines else 'hatched'}: spacing > "
                         f"{self.angular_resolution_deg:.1f} deg (eq. 24)")
        if notes:
            title += "\n" + "; ".join(notes)
        args = (self.radius_m, self.spacing_deg, self.metrics[metric], "arc radius R_c (m)",
                "front-end spacing (deg)", zlabel, title)
        if lines:
            return design_lines_figure(*args, mask=mask)
        return design_heatmap_figure(*args, mask=mask, contour_floor=floor)

    def to_dict(self) -> dict:
        def clean(v):
            if isinstance(v, float) and not math.isfinite(v):
                return None
            return v
        return {
            "pair": list(self.pair),
            "centre_deg": self.centre_deg,
            "radius_m": [round(float(r), 9) for r in self.radius_m],
            "spacing_deg": [round(float(s), 9) for s in self.spacing_deg],
            "angular_resolution_deg": self.angular_resolution_deg,
            "spec_deg": self.spec_deg,
            "yield": self.target_yield,
            "draws": self.draws,
            "seed": self.seed,
            "designs": [{k: clean(v) for k, v in d.items()} for d in self.designs],
        }

    def write(self, folder) -> list[str]:
        """``rtsgeom design --out``: design_<metric>.png per metric of :data:`METRICS` and
        design.json into ``folder``; returns the names."""
        from ..viz.figures import save_figure  # matplotlib: only where a figure is written
        names = [f"design_{name}.png" for name in METRICS]
        for name, file in zip(METRICS, names):
            save_figure(self.plot(name), Path(folder) / file)
        self.to_json(Path(folder) / "design.json")
        return names + ["design.json"]


def import_for_workers() -> None:
    """Import here what every design imports on its first use (the compiled kernels: numba),
    so that the pool's forked workers inherit the modules instead of each importing them
    again (~0.15 s CPU per worker; loading each kernel's compiled code from numba's cache,
    ~0.3 s more, still happens per worker, on its first call)."""
    from ..radar import peak_kernels  # noqa: F401
    from .tolerance import kernels  # noqa: F401


def design_grid(scene: Scene, pair: tuple[int, int], radius_m, spacing_deg,
                spec: DesignSpec = DesignSpec(), **options) -> DesignGrid:
    """Evaluate every (spacing, radius) design (:class:`~.design_study.DesignStudy` calls it).

    Parameters
    ----------
    scene : Scene
        The template (radar, sheet, RTS); the pair's centre angle is kept.
    pair : tuple of 2 int
    radius_m, spacing_deg : array_like
        Arc radii (m) and front-end spacings (deg).
    spec : DesignSpec
        How each design is judged: the tolerance keeps ``target_yield`` of the setups within
        ``spec_deg``, searched on ``draws`` Monte-Carlo draws of ``seed`` over ``points``
        set-points per design.
    **options
        ``progress(done, total)`` after each design, ``workers`` (default 1).

    Returns
    -------
    DesignGrid

    Raises
    ------
    ParameterError
        A scene of 2-D cells (:func:`check_azimuth_arc`).

    Notes
    -----
    ``workers`` > 1: the designs in a pool of that many processes (each design is pure: the
    same result, in the same order, however they are spread); None: as many as this process
    may run on (``parallel.available_cores``; ``rtsgeom design``'s default; one process on one
    core). A design's time is about a sixth its ``ChannelPhasors.build`` (the delay tables:
    ``bin_response`` of ~5000 delays through the FIR's whole-sample taps, ``rts.fir_taps``;
    the beam responses at the set angles) and five sixths its two tolerance searches
    (:func:`tolerance_search`: a 250-draw pilot, then ~3 Monte Carlos of ``draws`` draws x
    ``points`` set-points, and the one without errors per sub-bin position drawn); a design
    whose composite splits costs one build. The forked workers each load the compiled
    kernels once (~0.3 s CPU each) and keep the memory they free
    (``parallel.retain_freed_memory``)."""
    spec_deg, target_yield, draws, seed = (spec.spec_deg, spec.target_yield, spec.draws,
                                           spec.seed)
    progress = options.pop("progress", None)
    workers = options.pop("workers", 1)
    if options:
        raise ParameterError(f"design_grid: no option {', '.join(options)} (progress, "
                             "workers; the rest is the DesignSpec)")
    check_azimuth_arc(scene)
    warn_setup_errors(scene, "design")
    radii = np.asarray(radius_m, float).ravel()
    spacings = np.asarray(spacing_deg, float).ravel()
    fes = scene.rts.front_ends
    centre = 0.5 * (fes[pair[0]].angle_rad + fes[pair[1]].angle_rad)
    cells = [(float(r), math.radians(s)) for s in spacings for r in radii]
    one = functools.partial(_evaluate_cell, scene, pair, spec)
    # the studies' own pool (parallel.chunk_mapper: forked workers inheriting the scene, one
    # BLAS thread each; results in order, so the same bits however they are spread)
    designs = local_map(one, cells, workers, progress, before_fork=import_for_workers)
    shape = (spacings.size, radii.size)
    metrics = {name: frozen(np.array([d[name] for d in designs], float).reshape(shape))
               for name in METRICS}
    exceeds = np.array([bool(d["exceeds_resolution"]) for d in designs]).reshape(shape)
    res = math.degrees(angular_resolution_rad(build_setup(scene).rut))
    return DesignGrid((int(pair[0]), int(pair[1])), math.degrees(centre), frozen(radii),
                      frozen(spacings), res, float(spec_deg), float(target_yield), int(draws),
                      int(seed), metrics, frozen(exceeds), tuple(designs), scene.name)
