"""The linearity study as a configured callable: ``LinearityStudy(...)(scene)``.

The synthesized angle against the set angle across a front-end pair's span (``pair=(i, j)``),
for every adjacent pair of the arc (``pair="all"``), or as an azimuth x elevation error map over
a cell of 3 or 4 front ends (``grid=N``), each pair calibrated first unless ``calibrated`` is
False. A pair's or a cell's call returns a :class:`~.linearity.Linearity`, the arc's an
:class:`ArcLinearity` (on the shared :class:`~rtsgeom._lib.results.Result` base, each with
``write(folder)``); ``rtsgeom linearity`` parses its flags into this config, calls it and prints
the result.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from .._lib.results import Result
from ..calibration.pair import calibrate_pair
from ..calibration.probes import probe_front_ends
from ..errors import AngleUnreachable, ParameterError
from ..geometry import build_setup
from ..paths import exact_paths
from ..radar.steering import Steering
from ..scene import Scene, check_scene_arg
from ..scene.registry import SYNTHESIS_MODES
from ..scene.schema import check_arg
from .calibration_study import with_fir
from .linearity import END_ANGLES, Linearity, finite_or_none, linearity
from .pairs import is_all, study_pairs

__all__ = ["LinearityStudy", "ArcLinearity"]


@dataclass(frozen=True)
class LinearityStudy:
    """A configured linearity study on the simulated radar.

    Parameters
    ----------
    pair : tuple of 2 int, or 'all'
        One pair of adjacent front ends, or every one of the arc.
    amplitudes : str
        How the amplitude ratio is designed: one of ``SYNTHESIS_MODES`` (``exact``,
        ``array-factor``, ``paper``: eqs. 21-23).
    calibrated : bool
        Calibrate each pair (or the cell's channels) first; False: delay offset 0.
    points : int
        Set-points across a pair's span, ends excluded, in [3, 1001].
    end_angles : {'geometric', 'measured'}
        Front-end angles in the paper/array-factor closed forms.
    grid : int, optional
        A 2-D RuT: an N x N azimuth/elevation error map over the cell of the scene's 3 or 4
        front ends, N in [2, 50] (instead of a pair).
    fir : {'windowed-sinc', 'ideal'}, optional
        The fractional-delay filter model (default: the scene's).
    steps : callable, optional
        ``steps(label)`` at the start of each step.

    Raises
    ------
    ParameterError
        A field outside its range; on the call, a pair that is not one, or ``grid`` on a RuT
        without elevation.

    Examples
    --------
    >>> lin = LinearityStudy(amplitudes="paper")(scene)  # doctest: +SKIP
    >>> lin.max_abs_error_deg                            # doctest: +SKIP
    """

    pair: tuple | str = (0, 1)
    amplitudes: str = "exact"
    calibrated: bool = True
    points: int = 21
    end_angles: str = "geometric"
    grid: int | None = None
    fir: str | None = None
    steps: Callable[[str], None] | None = field(default=None, compare=False, repr=False)

    def __post_init__(self):
        fn = "LinearityStudy"
        check_arg(self.amplitudes, "amplitudes", "str", fn, ParameterError,
                  choices=SYNTHESIS_MODES)
        check_arg(self.points, "points", "int", fn, ParameterError, lo=3, hi=1001)
        check_arg(self.end_angles, "end_angles", "str", fn, ParameterError, choices=END_ANGLES)
        if self.grid is not None:
            check_arg(self.grid, "grid", "int", fn, ParameterError, lo=2, hi=50)
            if is_all(self.pair):
                raise ParameterError(f"{fn}: grid: must be unset with pair 'all' (a grid "
                                     "measures one cell; 'all' the arc's pairs)")

    def _step(self, label: str) -> None:
        if self.steps is not None:
            self.steps(label)

    def __call__(self, scene: Scene) -> "Linearity | ArcLinearity":
        check_scene_arg(scene, "linearity")
        scene = with_fir(scene, self.fir)
        if is_all(self.pair):
            return self._arc(scene)
        if self.grid:
            return self._grid(scene)
        self._step("measuring each front end alone")
        setup = build_setup(scene)
        pair = study_pairs(setup, self.pair)[0]
        paths = exact_paths(setup)
        probe = probe_front_ends(setup, paths, scene.seed)
        cal = None
        if self.calibrated:
            self._step("calibrating the pair")
            cal = calibrate_pair(setup, paths, pair, probe, seed=scene.seed)
        self._step(f"sweeping {self.points} set-points ({self.amplitudes} amplitudes)")
        return linearity(setup, paths, pair, self.amplitudes, probe, cal, self.points,
                         scene.seed, end_angles=self.end_angles)

    def _grid(self, scene: Scene) -> Linearity:
        self._step("measuring each front end alone")
        setup = build_setup(scene)
        if Steering.auto(setup.rut, scene.radar).dims != 2:
            raise ParameterError("grid: needs a RuT with elevation (an array with elevation "
                                 "extent, e.g. radar.use_elevation_tx = true)")
        paths = exact_paths(setup)
        self._step(f"{'calibrating the channels, then ' if self.calibrated else ''}"
                   f"synthesizing a {self.grid} x {self.grid} grid ({self.amplitudes} "
                   "amplitudes)")
        try:
            return linearity(setup, paths, mode=self.amplitudes, points=self.grid,
                             seed=scene.seed, calibrate=self.calibrated)
        except (ParameterError, AngleUnreachable) as exc:
            raise ParameterError(f"{scene.source}: {exc}") from None

    def _arc(self, scene: Scene) -> "ArcLinearity":
        self._step("measuring each front end alone")
        setup = build_setup(scene)
        pairs = study_pairs(setup, "all")
        paths = exact_paths(setup)
        probe = probe_front_ends(setup, paths, scene.seed)
        lins = []
        for pair in pairs:
            cal = None
            if self.calibrated:
                self._step(f"calibrating pair {pair}")
                cal = calibrate_pair(setup, paths, pair, probe, seed=scene.seed)
            self._step(f"pair {pair}: sweeping {self.points} set-points ({self.amplitudes} "
                       "amplitudes)")
            lins.append(linearity(setup, paths, pair, self.amplitudes, probe, cal, self.points,
                                  scene.seed, end_angles=self.end_angles))
        return ArcLinearity(tuple(pairs), tuple(lins), self.calibrated, self.amplitudes)


@dataclass(frozen=True, repr=False)
class ArcLinearity(Result):
    """Every adjacent pair's :class:`~.linearity.Linearity` of one arc. ``to_dict()`` one
    entry per pair plus the arc's; ``to_dataframe()`` one row per (pair, set-point);
    ``write(folder)`` linearity.json and linearity_I_J.png per pair.

    Attributes
    ----------
    pairs : tuple of (int, int)
    linearities : tuple of Linearity
    calibrated : bool
    amplitudes : str
    """

    pairs: tuple[tuple[int, int], ...]
    linearities: tuple[Linearity, ...]
    calibrated: bool
    amplitudes: str

    @property
    def worst_deg(self) -> list[float]:
        """Each pair's max |error| (deg)."""
        return [lin.max_abs_error_deg for lin in self.linearities]

    @property
    def worst_pair(self) -> tuple[int, int]:
        return tuple(self.pairs[int(np.argmax(self.worst_deg))])

    def _summary(self):
        title = (f"{self.amplitudes} synthesis over {len(self.pairs)} pairs, "
                 f"{'calibrated' if self.calibrated else 'uncalibrated'}")
        rows = [(f"pair {p}", f"max |error| {w:.4f} deg")
                for p, w in zip(self.pairs, self.worst_deg)]
        return title, rows

    def _columns(self) -> dict:
        cols: dict = {"i": [], "j": [], "set_deg": [], "detected_deg": [], "error_deg": []}
        for (i, j), lin in zip(self.pairs, self.linearities):
            n = len(lin.set_deg)
            cols["i"] += [i] * n
            cols["j"] += [j] * n
            cols["set_deg"] += list(lin.set_deg)
            cols["detected_deg"] += list(lin.detected_deg)
            cols["error_deg"] += list(lin.error_deg)
        return cols

    def plot(self):
        """The worst pair's figure (:meth:`~.linearity.Linearity.plot`)."""
        return self.linearities[int(np.argmax(self.worst_deg))].plot()

    def to_dict(self) -> dict:
        return {"pairs": [lin.to_dict() for lin in self.linearities],
                "arc": {"pairs": [list(p) for p in self.pairs],
                        # a pair with an undetected point is the worst (NaN as inf): null
                        "max_abs_error_deg": finite_or_none(np.max(np.where(
                            np.isfinite(self.worst_deg), self.worst_deg, np.inf))),
                        "worst_pair": list(self.worst_pair),
                        "calibrated": self.calibrated, "amplitudes": self.amplitudes}}

    def write(self, folder: str | Path) -> list[str]:
        """linearity_I_J.png per pair and linearity.json into ``folder``; returns the names."""
        from ..viz.figures import linearity_figure, save_figure  # matplotlib
        names = []
        for pair, lin in zip(self.pairs, self.linearities):
            names.append(f"linearity_{pair[0]}_{pair[1]}.png")
            save_figure(linearity_figure(lin.set_deg, {self.amplitudes: lin.detected_deg},
                                         {self.amplitudes: lin.amplitude_db}),
                        Path(folder) / names[-1])
        self.to_json(Path(folder) / "linearity.json")
        return names + ["linearity.json"]
