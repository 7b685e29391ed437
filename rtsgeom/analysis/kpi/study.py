"""The datasheet study: :class:`KpiStudy` (a frozen config) called on a scene returns a
:class:`Datasheet` (the shared ``Result``: ``repr``, ``to_dataframe()``, ``plot()``), with
``to_dict()`` the JSON contract of ``rtsgeom kpi`` and its HTML and PDF views
(:mod:`.report`).

What a lab hands over after building an RTS setup: which angles, ranges and velocities it
emulates, how accurately and with what uncertainty (:mod:`.accuracy`, :mod:`.budget`), how many
targets at once, what ghosts it makes, what the near field costs (:mod:`.sections`), and
whether that meets the spec of the tests it was built for (:mod:`.spec`).
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from ..._lib.results import Result
from ...errors import ParameterError
from ...geometry import build_setup
from ...paths import exact_paths
from ...scene import Scene, check_scene_arg
from ..tolerance import MAX_SIGMA_MM
from ..tolerance.args import STUDY_ARGS, Arg
from ..transfer import ideal_radar, set_angles
from .accuracy import AccuracyInputs, AnglePoint, effective_snr, pair_accuracy
from .headline import headline
from .sections import (field_of_view, ghosts_section, nearfield_section, range_velocity,
                       resolution_section, targets_section, uncovered_deg)
from .spec import KpiSpec, SpecCheck, check_spec

__all__ = ["KpiStudy", "Datasheet", "DEFAULT_SIGMA_MM"]

DEFAULT_SIGMA_MM = 0.1  # the mounting sigma per axis without --sigma-mm (as `tolerance`'s)
SCHEMA_VERSION = 1


@dataclass(frozen=True)
class KpiStudy:
    """The datasheet of a scene (module doc): ``KpiStudy(...)(scene)`` is a :class:`Datasheet`.

    Parameters
    ----------
    sigma_mm : float or (float, float, float), optional
        The mounting offsets' standard deviation per axis (radial, tangential, height; one
        number for all three), in [0, 10] mm; default 0.1 mm.
    sigma_phase_deg : float, optional
        Each RuT antenna's phase spread over radars of the type, in [0, 90] deg; default the
        RMS of the scene's ``[radar.channels]`` phases, 0 without them.
    points : int
        Set angles across each pair's span, in [1, 201].
    draws : int
        The Monte Carlo's draws, in [100, 1 000 000].
    seed : int, optional
        Its seed; default the scene's.
    spec : KpiSpec, optional
        The requirements to check (:func:`~.spec.load_spec`).

    Raises
    ------
    ParameterError
        A value outside its range, naming it.
    """

    #: the arguments declared once: each field's kind, range and help, checked here and the
    #: options of ``rtsgeom kpi`` made from them (``cli._common.declared_option``); the
    #: Monte-Carlo's as every study declares them, the draws within the datasheet's bounds
    ARGS: ClassVar[dict[str, Arg]] = {
        "sigma_mm": Arg("float", "mounting offsets' sigma in mm: one number, or radial "
                                 "tangential height", 0.0, MAX_SIGMA_MM, unit="mm"),
        "sigma_phase_deg": Arg("float", "each RuT antenna's phase spread over radars of the "
                                        "type, deg", 0.0, 90.0, unit="deg"),
        "points": Arg("int", "set angles across each pair's span, ends excluded", 1, 201),
        "draws": dataclasses.replace(STUDY_ARGS["draws"], help="Monte Carlo draws per set "
                                                               "angle", lo=100, hi=1_000_000),
        "seed": dataclasses.replace(STUDY_ARGS["seed"], help="the Monte Carlo's seed"),
    }

    sigma_mm: float | tuple[float, float, float] | None = None
    sigma_phase_deg: float | None = None
    points: int = 11
    draws: int = 2000
    seed: int | None = None
    spec: KpiSpec | None = None

    def __post_init__(self):
        s, lo, hi = self.sigma_mm, self.ARGS["sigma_mm"].lo, self.ARGS["sigma_mm"].hi
        vals = () if s is None else (s,) * 3 if np.isscalar(s) else tuple(s)
        if s is not None and (len(vals) != 3 or not all(
                isinstance(v, (int, float)) and not isinstance(v, bool) and lo <= v <= hi
                for v in vals)):  # a bool is an int to Python, never a sigma
            raise ParameterError(f"KpiStudy: sigma_mm = {s}: must be one number or three "
                                 f"(radial, tangential, height) in [{lo:g}, {hi:g}] mm")
        for name in ("sigma_phase_deg", "points", "draws", "seed"):
            value = getattr(self, name)
            if value is not None or name in ("points", "draws"):  # the others: None, default
                self.ARGS[name].check(value, name, "KpiStudy")
        if self.spec is not None and not isinstance(self.spec, KpiSpec):
            raise ParameterError(f"KpiStudy: spec = {self.spec!r}: must be a KpiSpec "
                                 "(rtsgeom.analysis.kpi.load_spec)")

    def __repr__(self) -> str:
        return (f"KpiStudy(sigma_mm={self.sigma_mm}, sigma_phase_deg={self.sigma_phase_deg}, "
                f"points={self.points}, draws={self.draws}, "
                f"spec={'yes' if self.spec else 'none'})")

    # -- the inputs ------------------------------------------------------------------------

    def mounting_sigma_mm(self) -> tuple[float, float, float]:
        s = DEFAULT_SIGMA_MM if self.sigma_mm is None else self.sigma_mm
        return (float(s),) * 3 if np.isscalar(s) else tuple(float(v) for v in s)

    def phase_sigma_deg(self, scene: Scene) -> tuple[float, str]:
        """The antenna phase spread (deg) and where it comes from."""
        if self.sigma_phase_deg is not None:
            return float(self.sigma_phase_deg), "sigma_phase_deg"
        ch = scene.radar.channels
        phases = [] if ch is None else [*ch.tx_phase_rad, *ch.rx_phase_rad]
        if phases and any(phases):
            rms = math.degrees(math.sqrt(float(np.mean(np.square(phases)))))
            return rms, "the RMS of [radar.channels]' antenna phases"
        return 0.0, "an ideal radar (no [radar.channels], no sigma_phase_deg)"

    # -- the study -------------------------------------------------------------------------

    def __call__(self, scene: Scene, progress=None) -> "Datasheet":
        """The datasheet of ``scene``; ``progress(label, done, total)`` per step."""
        check_scene_arg(scene, "kpi")
        t0 = time.perf_counter()
        step = _Steps(progress)
        setup = build_setup(scene)
        paths = exact_paths(setup)
        step("field of view")
        fov = field_of_view(setup, paths)
        step(None)
        sigma_mm = self.mounting_sigma_mm()
        phase_deg, phase_from = self.phase_sigma_deg(scene)
        seed = scene.seed if self.seed is None else self.seed
        inputs = AccuracyInputs(tuple(s * 1e-3 for s in sigma_mm), math.radians(phase_deg),
                                effective_snr(scene.radar), self.draws, seed)
        points, accuracy_note = self._accuracy(setup, paths, fov, inputs, progress)
        step("the signal chain on the scene's targets (rtsgeom run)")
        run = None
        if scene.targets:
            from ...pipeline.run import run_scene  # the whole chain: only where there are targets
            say = None if progress is None else (lambda label, *_: progress(label, 0, 1))
            run = run_scene(scene, progress=say, truth=False)
        step("range, velocity, targets, ghosts, near field")
        rv = range_velocity(setup, run)
        tg = targets_section(setup, run, fov)
        step("resolution (two targets, truth beside RTS)")
        tg["resolution"] = resolution_section(setup, progress) if not fov["cells"] else {
            "min_separation_deg": None, "rts_deg": None, "truth_deg": None,
            "note": "a scene of 2-D cells: the resolution test covers an arc"}
        gh = ghosts_section(scene, run)
        nf, nf_result = nearfield_section(setup)
        step(None)
        sheet = Datasheet(
            scene_name=scene.name, study=self, fov=fov, accuracy=tuple(points),
            accuracy_note=accuracy_note,
            inputs={"sigma_mm": dict(zip(("radial", "tangential", "height"), sigma_mm)),
                    "sigma_mm_from": ("sigma_mm" if self.sigma_mm is not None else
                                      f"the default {DEFAULT_SIGMA_MM:g} mm (the scene declares "
                                      "no tolerance)"),
                    "sigma_phase_deg": phase_deg, "sigma_phase_from": phase_from,
                    "snr_db": scene.radar.snr_db, **_snr_inputs(scene, inputs, points),
                    "draws": self.draws, "seed": seed, "points_per_pair": self.points,
                    "delay_resolution_ps": scene.rts.delay_resolution_s * 1e12},
            range_velocity=rv, targets=tg, ghosts=gh, nearfield=nf, nearfield_result=nf_result,
            spec=self.spec, elapsed_s=time.perf_counter() - t0)
        return sheet

    def _accuracy(self, setup, paths, fov, inputs, progress) -> tuple[list, str]:
        if fov["cells"]:
            return [], ("a scene of 2-D cells: the budget covers pairs on an arc (azimuth); "
                        "rtsgeom tolerance --cell gives a cell's Monte Carlo")
        pairs = [tuple(p["pair"]) for p in fov["pairs"] if p["synthesizable"]]
        if not pairs:
            return [], f"no synthesizable pair in the {fov['mode']} mode"
        from ...calibration.probes import probe_front_ends
        probe = probe_front_ends(setup, paths, setup.scene.seed)
        ideal = ideal_radar(setup)
        points = []
        for pair in pairs:
            pair = tuple(sorted(pair))
            angles = set_angles(setup, probe, pair, self.points)
            points += pair_accuracy(setup, ideal, paths, pair, probe, angles, inputs, progress)
        return points, ("the synthesized angle after the pair's calibration on the setup as "
                        "built, planned as rtsgeom run plans it; U (k = 2) from the GUM budget, "
                        "validated by a Monte Carlo of every input (JCGM 101)")


def _snr_inputs(scene, inputs: AccuracyInputs, points) -> dict:
    """The budget's SNR at the detection (the lowest over the set angles where it varies
    with them: the link budget's) and where it comes from."""
    if inputs.snr_effective is not None:
        return {"snr_effective_db": 10 * math.log10(inputs.snr_effective),
                "snr_from": "radar.snr_db per sample, after the FFTs' coherent gain"}
    if scene.radar.link is not None:
        snr = [p.snr_effective_db for p in points if p.snr_effective_db is not None]
        return {"snr_effective_db": min(snr, default=None),
                "snr_from": "the link budget ([radar.link]) per set angle, the lowest"}
    return {"snr_effective_db": None, "snr_from": "noiseless (no radar.snr_db, no [radar.link])"}


class _Steps:
    """Progress of the study's steps without counts: each step as (label, 0, 1) and its end
    as (label, 1, 1)."""

    def __init__(self, progress):
        self.progress, self.label = progress, None

    def __call__(self, label):
        if self.progress and self.label:
            self.progress(self.label, 1, 1)
        self.label = label
        if self.progress and label:
            self.progress(label, 0, 1)


@dataclass(frozen=True, repr=False)
class Datasheet(Result):
    """The setup's datasheet (module doc): ``to_dict()`` the JSON, ``plot()`` the angle
    accuracy, ``figures()`` every figure of the report.

    Attributes
    ----------
    scene_name : str
        The scene's name.
    study : KpiStudy
        The study that made it.
    fov : dict
        The field of view the arc covers.
    accuracy : tuple of AnglePoint
        The angle accuracy per set angle; ``accuracy_note`` how it was evaluated.
    inputs : dict
        The uncertainty budget's inputs (sigmas, SNR, draws, seed).
    range_velocity, targets, ghosts, nearfield : dict
        The other sections, as plain dicts.
    spec : KpiSpec or None
        The requirements checked; ``checks`` the verdict per requirement.
    elapsed_s : float
        The study's wall time.
    """

    scene_name: str
    study: KpiStudy
    fov: dict
    accuracy: tuple[AnglePoint, ...]
    accuracy_note: str
    inputs: dict
    range_velocity: dict
    targets: dict
    ghosts: dict
    nearfield: dict
    nearfield_result: object = None
    spec: KpiSpec | None = None
    elapsed_s: float = 0.0
    checks: tuple[SpecCheck, ...] = field(default=(), init=False)

    def __post_init__(self):
        if self.spec is not None:
            object.__setattr__(self, "checks", tuple(check_spec(self.spec, self.spec_values())))

    # -- the KPIs --------------------------------------------------------------------------

    def worst_accuracy_deg(self, span=None) -> float | None:
        """The worst |error| + U (or the Monte Carlo's interval) over the set angles within
        ``span`` (deg; None: all)."""
        pts = [p for p in self.accuracy if span is None or span[0] <= p.set_deg <= span[1]]
        return max((p.accuracy_deg for p in pts), default=None)

    def spec_values(self) -> dict:
        """The datasheet's value per spec key (:func:`~.spec.check_spec`)."""
        span = None if self.spec is None else self.spec.azimuth_deg
        rv = self.range_velocity
        v = {"angle_accuracy_deg": self.worst_accuracy_deg(span),
             "azimuth_deg": None if span is None else uncovered_deg(self.fov, span),
             "min_range_m": rv["min_range_m"], "max_range_m": rv["max_range_m"],
             "max_velocity_mps": rv["max_velocity_mps"],
             "range_accuracy_m": rv["range_accuracy_m"],
             "velocity_accuracy_mps": rv["velocity_accuracy_mps"],
             "targets": self.targets["total"],
             "resolution_deg": (self.targets["resolution"] or {}).get("rts_deg"),
             "ghost_suppression_db": self.ghosts["ghost_suppression_db"]}
        if v["angle_accuracy_deg"] is None:
            v["angle_accuracy_deg_note"] = self.accuracy_note if not self.accuracy else \
                "no set angle within azimuth_deg"
        if v["resolution_deg"] is None:
            v["resolution_deg_note"] = self.targets["resolution"]["note"]
        if rv["range_accuracy_m"] is None:
            v["range_accuracy_m_note"] = v["velocity_accuracy_mps_note"] = rv["accuracy_note"]
        return v

    @property
    def passed(self) -> bool | None:
        """Every checked KPI met (None without a spec; a KPI without a value fails)."""
        if self.spec is None:
            return None
        return all(c.passed is True for c in self.checks)

    @property
    def exit_code(self) -> int:
        """0: every KPI of the spec met (or no spec), 1: one or more missed."""
        return 0 if self.passed in (None, True) else 1

    # -- views -----------------------------------------------------------------------------

    def to_dict(self) -> dict:
        acc = [p.to_dict() for p in self.accuracy]
        not_validated = [p.set_deg for p in self.accuracy if not p.validated]
        return {
            "schema_version": SCHEMA_VERSION, "scene": self.scene_name,
            "inputs": self.inputs,
            "field_of_view": self.fov,
            "angle_accuracy": acc,
            "angle_accuracy_summary": {
                "note": self.accuracy_note,
                "worst_accuracy_deg": self.worst_accuracy_deg(),
                "worst_abs_error_deg": max((abs(p.error_deg) for p in self.accuracy),
                                           default=None),
                "max_expanded_uncertainty_deg": max((p.expanded_deg for p in self.accuracy),
                                                    default=None),
                "gum_not_validated_at_deg": not_validated,
                "gum_validation": ("the GUM interval agrees with the Monte Carlo's within 10 % "
                                   "of U at every set angle" if not not_validated else
                                   "the GUM interval differs from the Monte Carlo's by more "
                                   "than 10 % of U (nonlinear in an input): the Monte Carlo's "
                                   "95 % interval is quoted there")},
            "range_velocity": self.range_velocity,
            "targets": self.targets,
            "ghosts_leakage": self.ghosts,
            "near_field": self.nearfield,
            "spec": [c.to_dict() for c in self.checks],
            "passed": self.passed,
            "elapsed_s": self.elapsed_s,
        }

    def _summary(self):
        rows = headline(self.to_dict())
        rows += [(f"spec {c.kpi}", "no value" if c.passed is None else
                  f"{'pass' if c.passed else 'FAIL'} (margin {c.margin:.4g})")
                 for c in self.checks]
        return f"{self.scene_name}: datasheet", rows

    def _columns(self) -> dict:
        return {"pair": [f"{p.pair[0]}-{p.pair[1]}" for p in self.accuracy],
                "set_angle_deg": np.array([p.set_deg for p in self.accuracy]),
                "error_deg": np.array([p.error_deg for p in self.accuracy]),
                "expanded_uncertainty_deg": np.array([p.expanded_deg for p in self.accuracy]),
                "monte_carlo_half_width_deg": np.array([p.mc_half_width_deg
                                                        for p in self.accuracy]),
                "gum_validated": np.array([p.validated for p in self.accuracy]),
                "accuracy_deg": np.array([p.accuracy_deg for p in self.accuracy])}

    def plot(self):
        """The angle accuracy over the field of view (error, U, the Monte Carlo's interval,
        the spec)."""
        from .report import accuracy_figure  # matplotlib: only for the figure
        return accuracy_figure(self)

    def figures(self) -> dict:
        """Every figure of the report, by name (matplotlib figures)."""
        from .report import figures
        return figures(self)
