"""The phase calibration as a configured callable: ``CalibrationStudy(...)(scene)``.

One config says which pairs (one, or every pair of the arc: ``pair="all"``; a 2-D scene's
neighbouring front ends are pairs too), which procedure (``exact``: two probes, amplitudes
re-designed at every step, refined to the delay resolution; ``paper``: the paper's sweep as
written) and whether every sweep step goes through the full ADC-cube chain. Its call on a scene
measures each front end alone, sweeps each pair's delay and returns a
:class:`CalibrationReport` on the shared :class:`~rtsgeom._lib.results.Result` base: the
calibration file ``run --calibration`` reads (``to_dict()``), written with its sweep figures by
``write(folder)``. ``rtsgeom calibrate`` parses its flags into this config, calls it and prints
the report.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from .._lib.parallel import available_cores, local_map
from .._lib.results import Result
from .._lib.util import tell
from ..calibration.file import setup_fingerprint
from ..calibration.fir import fir_effect
from ..calibration.pair import calibrate_pair
from ..calibration.paper import calibrate_pair_paper
from ..calibration.probes import FrontEndProbe, probe_front_ends
from ..errors import ParameterError
from ..geometry import build_setup
from ..paths import exact_paths
from ..pipeline.plan import uses_cells
from ..scene import Scene, check_scene_arg
from ..scene.schema import check_arg
from .pairs import is_all, study_pairs

__all__ = ["CalibrationStudy", "CalibrationReport", "PROCEDURES", "with_fir"]

#: the sweep procedures
PROCEDURES = ("exact", "paper")


def with_fir(scene: Scene, fir: str | None) -> Scene:
    """The scene with the fractional-delay filter model ``fir`` (None: as it is)."""
    if fir:
        scene = scene.evolve(rts=scene.rts.evolve(fractional_delay_filter=fir))
    return scene


@dataclass(frozen=True)
class CalibrationStudy:
    """A configured phase calibration.

    Parameters
    ----------
    pair : tuple of 2 int, or 'all'
        One pair of adjacent (on a 2-D scene: neighbouring) front ends, or every one.
    procedure : {'exact', 'paper'}
        ``exact``: two probes, amplitudes re-designed at every step, refined to the delay
        resolution; ``paper``: the paper's sweep as written (fixed eq. 23 amplitudes, one set
        angle, 25 ps steps; pairs on an arc only).
    full_chain : bool
        Every sweep step through the full ADC-cube chain instead of the phasor model.
    fir : {'windowed-sinc', 'ideal'}, optional
        The fractional-delay filter model (default: the scene's ``rts.fractional_delay_filter``,
        checked there).
    steps : callable, optional
        ``steps(label)`` at the start of each step (measuring, each sweep); a ``steps``
        with a ``count(stage, done, total)`` (the CLI's) is told the pairs calibrated.
    workers : int, optional
        Pairs calibrated in this many processes, in [1, 1024] (None: the cores this
        process may use). Each pair is a pure function of the scene (its noise from the
        scene's seed), so the report is the same for any number.

    Raises
    ------
    ParameterError
        A field outside its choices; on the call, a pair that is not one, or the paper's
        procedure on a scene of 2-D cells.

    Examples
    --------
    >>> report = CalibrationStudy(pair="all")(scene)     # doctest: +SKIP
    >>> report.write("cal")                              # doctest: +SKIP
    """

    pair: tuple | str = (0, 1)
    procedure: str = "exact"
    full_chain: bool = False
    fir: str | None = None
    steps: Callable[[str], None] | None = field(default=None, compare=False, repr=False)
    workers: int | None = None

    def __post_init__(self):
        if self.workers is not None:
            check_arg(self.workers, "workers", "int", "CalibrationStudy", ParameterError,
                      lo=1, hi=1024)
        if self.procedure not in PROCEDURES:
            raise ParameterError(f"CalibrationStudy: procedure = {self.procedure!r}: must be "
                                 f"one of {', '.join(PROCEDURES)}")
        if self.full_chain and self.procedure == "paper":
            raise ParameterError("CalibrationStudy: full_chain: must be false with procedure "
                                 "'paper' (the paper's sweep runs the full chain already)")

    def _step(self, label: str) -> None:
        if self.steps is not None:
            self.steps(label)

    def __call__(self, scene: Scene) -> "CalibrationReport":
        check_scene_arg(scene, "calibrate")
        arc = is_all(self.pair)
        self._step("measuring each front end alone")
        scene = with_fir(scene, self.fir)
        setup = build_setup(scene)
        pairs = study_pairs(setup, self.pair, cells=True)
        paths = exact_paths(setup)
        probe = probe_front_ends(setup, paths, scene.seed)
        if self.procedure == "paper" and uses_cells(scene):
            raise ParameterError("procedure paper: the paper's sweep is a pair on an arc (one "
                                 "set angle in azimuth); this scene's front ends form 2-D cells")
        one = functools.partial(_calibrate_one, setup, paths, probe, scene.seed,
                                self.procedure, self.full_chain)
        workers = available_cores() if self.workers is None else self.workers
        if len(pairs) > 1 and workers > 1:  # side by side: the same calibrations
            self._step(f"sweeping the delay of front end J of each of {len(pairs)} pairs "
                       f"({min(workers, len(pairs))} processes)")
            cals = local_map(one, pairs, workers, progress=lambda done, total: tell(
                self.steps, None, "pairs calibrated", done, total))
        else:
            cals = []
            for pair in pairs:
                self._step(f"sweeping the delay of front end {pair[1]} (pair {pair})" if arc
                           else f"sweeping the delay of front end {pair[1]} on the simulated "
                                f"radar ({self.procedure} procedure)")
                cals.append(one(pair))
        fir = None if arc else fir_effect(setup, cals[0].delta_tau_s,
                                          ranges=cals[0].probe_ranges_m)
        return CalibrationReport(tuple(pairs), tuple(cals), probe, self.procedure,
                                 setup_fingerprint(scene), arc, uses_cells(scene), fir,
                                 scene.name)


def _calibrate_one(setup, paths, probe, seed, procedure, full_chain, pair):
    """One pair's calibration: a pure function of its arguments (its noise from ``seed``),
    so that pairs may be calibrated in any process and order with the same result."""
    if procedure == "paper":
        return calibrate_pair_paper(setup, paths, pair, probe, seed=seed)
    return calibrate_pair(setup, paths, pair, probe, seed=seed, full_chain=full_chain)


@dataclass(frozen=True, repr=False)
class CalibrationReport(Result):
    """The calibrations of a :class:`CalibrationStudy`: per pair a
    :class:`~rtsgeom.calibration.sweep.Calibration`, each front end alone as the RuT detected
    it (``probe``), and what a calibration file records (``setup_sha256``, the fractional-delay
    filter's effect of one pair).

    ``to_dict()`` is the calibration file (``calibrate --out DIR`` writes it as
    DIR/calibration.json; ``run --calibration`` reads it); ``write(folder)`` that file and
    the sweep figures; ``to_dataframe()`` one row per pair; ``plot()`` the first pair's
    sweep.

    Attributes
    ----------
    pairs : tuple of (int, int)
    calibrations : tuple of Calibration
    probe : FrontEndProbe
    procedure : str
    setup_sha256 : str
    """

    pairs: tuple[tuple[int, int], ...]
    calibrations: tuple
    probe: FrontEndProbe
    procedure: str
    setup_sha256: str
    arc: bool = False  # the study of every pair (its file lists them)
    cells: bool = False  # the scene's front ends form 2-D cells
    fir: dict | None = None  # one pair's fractional-delay filter effect
    scene_name: str = ""  # the figures' titles

    @property
    def calibration(self):
        """The first (a one-pair study's only) calibration."""
        return self.calibrations[0]

    def residuals_deg(self) -> np.ndarray:
        """|residual angle error| per pair (inf where the chain missed a probe)."""
        return np.abs([c.residual_error_deg for c in self.calibrations])

    def worst(self) -> int:
        """The index of the pair with the largest residual (NaN counted as the largest)."""
        res = self.residuals_deg()
        return int(np.argmax(np.where(np.isnan(res), np.inf, res)))

    def _summary(self):
        title = (f"{'arc' if self.arc else 'pair'} calibration ({self.procedure}), "
                 f"{len(self.pairs)} pair(s)")
        rows = [(f"pair {p}", f"delta_tau {c.delta_tau_s * 1e12:.1f} ps, residual "
                              f"{c.residual_error_deg:.4f} deg")
                for p, c in zip(self.pairs, self.calibrations)]
        return title, rows

    def _columns(self) -> dict:
        cals = self.calibrations
        return {"i": [p[0] for p in self.pairs], "j": [p[1] for p in self.pairs],
                "delta_tau_ps": [c.delta_tau_s * 1e12 for c in cals],
                "residual_error_deg": [c.residual_error_deg for c in cals],
                "range_offset_mm": [c.range_offset_m * 1e3 for c in cals]}

    def plot(self, title: str = ""):
        """The first pair's sweep (:meth:`~rtsgeom.calibration.sweep.Calibration.plot`)."""
        return self.calibration.plot(title)

    def to_dict(self) -> dict:
        probe = self.probe
        if not self.arc:
            out = self.calibration.to_dict()
            out["procedure"] = self.procedure
            out["front_end_angles_deg"] = [float(x) for x in np.degrees(probe.angle_rad)]
            out["gain_correction"] = [float(x) for x in probe.gain_correction]
            out["format"] = "rtsgeom-calibration"  # `run/adc --calibration DIR/calibration.json`
            out["setup_sha256"] = self.setup_sha256  # run/adc warn when used on another setup
            out["fractional_delay_filter"] = self.fir
            return out
        res, worst, cals = self.residuals_deg(), self.worst(), self.calibrations
        return {"pairs": [dict(c.to_dict(), procedure=self.procedure) for c in cals],
                "gain_correction": [float(x) for x in probe.gain_correction],
                "front_end_angles_deg": [float(x) for x in np.degrees(probe.angle_rad)],
                "arc": {"pairs": [list(p) for p in self.pairs],
                        "worst_residual_error_deg": (float(res[worst]) if np.isfinite(res[worst])
                                                     else None),
                        "worst_pair": list(self.pairs[worst]),
                        "max_abs_range_offset_mm": max(abs(c.range_offset_m) for c in cals) * 1e3},
                "format": "rtsgeom-calibration", "setup_sha256": self.setup_sha256}

    def write(self, folder: str | Path) -> list[str]:
        """calibration.json and the sweep figure(s) into ``folder``: calibration_sweep.png of
        one pair, calibration_sweep_I_J.png per pair of the arc; returns the names."""
        from ..viz.figures import save_figure  # matplotlib
        folder, names = Path(folder), []
        for pair, cal in zip(self.pairs, self.calibrations):
            name = (f"calibration_sweep_{pair[0]}_{pair[1]}.png" if self.arc
                    else "calibration_sweep.png")
            # titled with the scene and the pair; the residual marked as stdout gives it
            fig = cal.plot(f"{self.scene_name}: phase coherency calibration, front ends "
                           f"{pair[0]}-{pair[1]}" if self.scene_name else "")
            save_figure(fig, folder / name)
            names.append(name)
        self.to_json(folder / "calibration.json")
        return names + ["calibration.json"]
