"""The arc design as a configured callable: ``DesignStudy(...)(scene)``.

One config says which designs (arc radii x front-end spacings of a pair, or with
``coverage_deg`` the arc of N front ends covering an azimuth span for each radius), what the
tolerance asks (the spec and the yield) and how the setups are drawn
(:class:`~.tolerance.config.MonteCarlo`). Its call on a scene returns a
:class:`~.design.DesignGrid` or a :class:`~.coverage.CoverageDesign` (both on the shared
:class:`~rtsgeom._lib.results.Result` base, each with ``write(folder)``); ``rtsgeom design``
parses its flags into this config, calls it and prints the result.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..geometry import build_setup
from ..scene import Scene, check_scene_arg
from ..scene.schema import check_arg
from .coverage import CoverageDesign, coverage_designs
from .design import DesignGrid, DesignSpec, check_azimuth_arc, design_grid
from .pairs import study_pairs
from .tolerance.config import MonteCarlo, check_study_args

__all__ = ["DesignStudy"]

#: (draws, points) when ``mc``/``points`` are not given: the grid's, the coverage's
GRID_DEFAULTS, COVERAGE_DEFAULTS = (2000, 21), (300, 11)


@dataclass(frozen=True)
class DesignStudy:
    """A configured arc design.

    Parameters
    ----------
    radius_m : sequence of float
        Arc radii (m), each in [0.1, 100].
    spacing_deg : sequence of float
        Front-end spacings (deg), each in [0.1, 90] (the grid; unused with ``coverage_deg``).
    pair : tuple of 2 int
        The adjacent front ends whose centre angle the designs keep (the grid).
    coverage_deg : (float, float), optional
        Design the arc of N front ends covering A..B deg (-80 <= A < B <= 80) for each radius
        instead of the grid.
    spec_deg : float
        Angle-error spec (deg), in [1e-6, 90].
    target_yield : float
        Fraction of setups within the spec that the tolerance keeps, in (0, 1].
    mc : MonteCarlo, optional
        The tolerance searches' draws (its ``progress`` is told ``('designs', done, total)``);
        default 2000 draws for the grid, 300 for the coverage, the scene's seed.
    points : int, optional
        Set-points per pair, in [3, 201] (default 21 for the grid, 11 with ``coverage_deg``).
    workers : int, optional
        Designs evaluated in this many processes (None: the cores this process may use); the
        same result for any number.

    Raises
    ------
    ParameterError
        A field outside its range; on the call, a scene whose front ends form 2-D cells.

    Examples
    --------
    >>> grid = DesignStudy(radius_m=(0.5, 1.0), spacing_deg=(8.0, 12.0))(scene)  # doctest: +SKIP
    >>> grid.write("design_out")                                                # doctest: +SKIP
    """

    radius_m: tuple = (0.5, 1.0, 1.5, 2.0)
    spacing_deg: tuple = (4.0, 8.0, 12.0, 16.0, 20.0)
    pair: tuple = (0, 1)
    coverage_deg: tuple | None = None
    spec_deg: float = 0.1
    target_yield: float = 0.95
    mc: MonteCarlo | None = None
    points: int | None = None
    workers: int | None = 1

    def __post_init__(self):
        fn = "DesignStudy"
        for name, hi in (("radius_m", 100.0), ("spacing_deg", 90.0)):
            values = tuple(float(v) for v in np.atleast_1d(np.asarray(getattr(self, name),
                                                                      float)).ravel())
            if not values or not all(0.1 <= v <= hi for v in values):
                raise ParameterError(f"{fn}: {name} = {list(values)}: must be one or more "
                                     f"values in [0.1, {hi:g}]")
            object.__setattr__(self, name, values)
        if self.coverage_deg is not None:
            a, b = (float(x) for x in self.coverage_deg)
            if not -80.0 <= a < b <= 80.0:
                raise ParameterError(f"{fn}: coverage_deg = ({a:g}, {b:g}): need -80 <= A < B "
                                     "<= 80 deg")
            object.__setattr__(self, "coverage_deg", (a, b))
        if self.mc is not None and not isinstance(self.mc, MonteCarlo):
            raise ParameterError(f"{fn}: mc must be a MonteCarlo")
        check_study_args(fn, draws=None if self.mc is None else self.mc.draws,
                         spec_deg=self.spec_deg, points=self.points)
        check_arg(self.target_yield, "target_yield", "float", fn, ParameterError, lo=0.0,
                  hi=1.0, lo_open=True)
        if self.workers is not None:
            check_arg(self.workers, "workers", "int", fn, ParameterError, lo=1, hi=1024)

    def draws_config(self, scene: Scene) -> tuple[MonteCarlo, int]:
        """The Monte-Carlo config (seeded with the scene's seed) and the set-points per pair
        this study uses."""
        draws, points = COVERAGE_DEFAULTS if self.coverage_deg is not None else GRID_DEFAULTS
        mc = (MonteCarlo(draws) if self.mc is None else self.mc).seeded(scene.seed)
        return mc, points if self.points is None else self.points

    def __call__(self, scene: Scene) -> DesignGrid | CoverageDesign:
        check_scene_arg(scene, "design")
        # an arc of pairs in azimuth only (the grid and the coverage alike)
        check_azimuth_arc(scene, f"design {scene.source}")
        mc, points = self.draws_config(scene)
        n = len(self.radius_m) * (2 if self.coverage_deg is not None
                                  else len(self.spacing_deg))
        report = mc.progress
        if report is not None:  # the bar from the start, labelled with the count to come
            report("designs", 0, n)
        kw = dict(workers=self.workers,
                  progress=None if report is None else
                  (lambda done, total: report("designs", done, total)))
        if self.coverage_deg is not None:
            return coverage_designs(scene, self.coverage_deg, self.radius_m, self.spec_deg,
                                    self.target_yield, mc.draws, mc.seed, points=points, **kw)
        pair = study_pairs(build_setup(scene), self.pair)[0]
        return design_grid(scene, pair, self.radius_m, self.spacing_deg,
                           DesignSpec(self.spec_deg, self.target_yield, mc.draws, mc.seed,
                                      points), **kw)

    def evolve(self, **changes) -> "DesignStudy":
        """A copy with ``changes`` (checked again)."""
        return dataclasses.replace(self, **changes)
