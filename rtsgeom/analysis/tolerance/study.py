"""The mounting-tolerance study as a configured callable: ``ToleranceStudy(...)(scene)``.

One config says what is drawn (:class:`~.draws.Bounds`), how (:class:`~.config.MonteCarlo`),
which channels (a pair, every pair of the arc, or a cell of 3 or 4 front ends) and what else is
asked: the chain check of the first draws (``verify``) and the yield search
(``invert_yield``). Its call on a scene returns a :class:`ToleranceReport` on the shared
:class:`~rtsgeom._lib.results.Result` base, which writes itself (``write(folder)``,
``to_json``, ``to_csv``); ``rtsgeom tolerance`` parses its flags into this config, calls it and
prints the report.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..._lib.results import Result
from ...errors import AngleUnreachable, ParameterError
from ...geometry import build_setup
from ...geometry.setup import warn_setup_errors
from ...radar.steering import Steering
from ...scene import Scene, check_scene_arg
from ...scene.schema import check_arg
from ..pairs import is_all, study_pairs
from .config import MonteCarlo, check_study_args
from .draws import AXES, Bounds, draw_offsets
from .montecarlo import ToleranceModel, ToleranceResult, simulate
from .phasors import CASES, NOMINAL_AMPLITUDES, ChannelPhasors
from .search import YieldSearch
from .verify import VerifyResult, verify_draws

__all__ = ["ToleranceStudy", "ToleranceReport", "CHUNK_MEMORY_BYTES", "capped_chunk",
           "chunk_bytes_per_draw", "scene_offsets_effect"]

#: Peak memory of one Monte-Carlo chunk is at most about ``chunk * chunk_bytes_per_draw(points)``
#: (measured with tracemalloc, all three cases, the target's sub-bin position drawn per draw:
#: 17 kB/draw at 5 set-points, 40 kB at 21, 112 kB at 61; a chunk is evaluated in blocks of the
#: procedure's ``block_draws``, so past that the peak stops growing); a pair's or a cell's chunk
#: is capped so that one chunk stays within this budget. The draws do not depend on the chunk
#: size, so the cap changes no result.
CHUNK_MEMORY_BYTES = 256 * 2 ** 20


def chunk_bytes_per_draw(points: int) -> int:
    """Upper bound of the peak bytes per draw of one tolerance chunk with ``points`` set-points
    (all cases: ~1.9 kB per set-point and draw, plus a fixed part)."""
    return 2000 * int(points) + 10000


def capped_chunk(chunk: int, points: int) -> int:
    """``chunk`` bounded so that one chunk's peak stays within :data:`CHUNK_MEMORY_BYTES`."""
    return max(100, min(int(chunk), CHUNK_MEMORY_BYTES // chunk_bytes_per_draw(points)))


@dataclass(frozen=True)
class ToleranceStudy:
    """A configured mounting-tolerance study (phasor level).

    Parameters
    ----------
    bounds : Bounds
        The error scales (SI): offsets (radial, tangential, height) per front end, its yaw
        and pitch, the RuT's position and yaw; standard deviations (normal) or bounds.
    pair : tuple of 2 int, 'all' or None
        One front-end pair; ``'all'``: every adjacent pair on shared per-front-end draws (the
        study of a whole arc; rotation or RuT-pose errors make any study one). None: the pair
        (0, 1), or the cell of all front ends where the RuT beamforms in azimuth and
        elevation and there are 3 or 4 of them.
    cell : tuple of int, 'all' or None
        The study of a 2-D cell: 3 or 4 front-end indices, or all of them.
    mc : MonteCarlo
        How the setups are drawn (seed None: the scene's).
    spec_deg : float
        Angle-error spec (deg) of the yield, in [1e-6, 90].
    points : int
        Set-points across a pair's span, ends excluded (a cell: about this many set
        directions), in [3, 201].
    nominal_amplitudes : bool
        Add the case ``nominal amplitudes`` (a pair only).
    verify : int
        Push the first N draws through the full ADC-cube chain (one pair or cell, offsets
        only).
    verify_all_points : bool
        With ``verify``: every set-point of each draw, not only its worst.
    invert_yield : float, optional
        Also search the largest scale keeping this fraction of the setups within the spec.
    invert_axis : {'all', 'radial', 'tangential', 'height'}
        The search's line: the three sigmas together, or one axis alone (pair and cell).
    sigma_level : float, optional
        What the tolerances were given at (recorded in an arc's report).
    keep_draws : bool
        Keep an arc's per-draw errors (for :meth:`ToleranceReport.write`'s npz).

    Raises
    ------
    ParameterError
        A field outside its range or a combination the study does not model.

    Examples
    --------
    >>> study = ToleranceStudy(Bounds((1e-4,) * 3), pair=(0, 1), mc=MonteCarlo(2000))
    >>> report = study(scene)                       # doctest: +SKIP
    >>> report.run.yield_("calibrated")             # doctest: +SKIP
    """

    bounds: Bounds = Bounds((1e-4,) * 3)
    pair: tuple | str | None = None
    cell: tuple | str | None = None
    mc: MonteCarlo = MonteCarlo()
    spec_deg: float = 0.1
    points: int = 21
    nominal_amplitudes: bool = False
    verify: int = 0
    verify_all_points: bool = False
    invert_yield: float | None = None
    invert_axis: str = "all"
    sigma_level: float | None = None
    keep_draws: bool = False

    def __post_init__(self):
        fn = "ToleranceStudy"
        if not isinstance(self.bounds, Bounds):
            raise ParameterError(f"{fn}: bounds must be a Bounds (the error scales, SI)")
        self.bounds.check()
        if not isinstance(self.mc, MonteCarlo):
            raise ParameterError(f"{fn}: mc must be a MonteCarlo")
        # a study draws at least one setup (the engine alone takes 0: a yield of no draws)
        check_study_args(fn, draws=self.mc.draws, spec_deg=self.spec_deg, points=self.points)
        check_arg(self.verify, "verify", "int", fn, ParameterError, lo=0, hi=10_000)
        if self.invert_yield is not None:
            check_arg(self.invert_yield, "invert_yield", "float", fn, ParameterError, lo=0.0,
                      hi=1.0, lo_open=True)
        check_arg(self.invert_axis, "invert_axis", "str", fn, ParameterError,
                  choices=("all",) + AXES)
        if self.cell is not None and self.pair is not None:
            raise ParameterError(f"{fn}: cell and pair: give one of them (the cell study is "
                                 "of the cell's front ends)")

    @property
    def cases(self) -> tuple[str, ...]:
        return CASES + ((NOMINAL_AMPLITUDES,) if self.nominal_amplitudes else ())

    def wants_cell(self, scene: Scene) -> bool:
        """``cell`` given, or neither it nor ``pair`` with a RuT that beamforms in azimuth and
        elevation and 3 or 4 front ends: the cell of all of them."""
        if self.cell is not None:
            return True
        if self.pair is not None:
            return False
        setup = build_setup(scene)
        return Steering.auto(setup.rut, scene.radar).dims == 2 and setup.fe.count in (3, 4)

    def model(self, scene: Scene) -> ToleranceModel:
        """The channel sets the study draws: a cell, a whole arc (``pair='all'``, or rotation
        or RuT-pose errors: every pair on shared draws), or one pair."""
        setup = build_setup(scene)
        b = self.bounds
        if self.wants_cell(scene):
            if (b.rotations or b.rut_pose) and (self.verify or self.invert_yield is not None):
                raise ParameterError("verify, invert_yield: only without rotation or RuT-pose "
                                     "errors so far")
            if self.nominal_amplitudes:
                raise ParameterError("nominal_amplitudes: only for the pair study (the cell "
                                     "study designs its amplitudes once, at the bin centre)")
            cell = None if self.cell is None or is_all(self.cell) else tuple(self.cell)
            try:
                model = ChannelPhasors.build(setup, cell, self.points, cell=True)
            except AngleUnreachable as exc:
                raise ParameterError(f"cell: the cell cannot synthesize its set directions "
                                     f"({exc})") from None
            except ParameterError as exc:
                raise ParameterError(f"cell: {exc}") from None
            return ToleranceModel.of(model)
        pair = (0, 1) if self.pair is None else self.pair
        arc = is_all(pair) or b.rotations or b.rut_pose
        if arc and self.verify:
            raise ParameterError("verify: only for one pair with offsets (not pair='all', "
                                 "rotations or RuT-pose errors)")
        pairs = study_pairs(setup, "all" if arc else pair)
        try:
            models = [ChannelPhasors.build(setup, p, self.points) for p in pairs]
        except AngleUnreachable as exc:  # the composite cannot reach a set angle
            which = "pair" if arc else f"pair {pairs[0][0]} {pairs[0][1]}"
            raise ParameterError(f"{which}: {'a' if arc else 'the'} pair cannot synthesize its "
                                 f"span ({exc})") from None
        return ToleranceModel.arc(models, setup.fe.count) if arc else ToleranceModel.of(models[0])

    def __call__(self, scene: Scene) -> "ToleranceReport":
        check_scene_arg(scene, "tolerance")
        warn_setup_errors(scene, "tolerance")  # NominalSetupWarning
        model = self.model(scene)
        if model.kind == "arc" and self.invert_yield is not None and self.invert_axis != "all":
            raise ParameterError(f"ToleranceStudy: invert_axis = {self.invert_axis!r}: must be "
                                 "'all' for an arc (its inversion scales every error together)")
        mc = self.mc.seeded(scene.seed)
        if model.kind != "arc":
            m = model.sets[0]
            points = m.set_rad.shape[0] * (1 if model.kind != "cell" else len(m.front_ends))
            mc = mc.evolve(chunk=capped_chunk(mc.chunk, points))
        t0 = time.perf_counter()
        res = simulate(model, self.bounds, mc, self.spec_deg, self.cases,
                       "Monte Carlo (arc)" if model.kind == "arc" else "Monte Carlo",
                       keep_errors=self.keep_draws and model.kind == "arc")
        verify = None
        if self.verify:
            # the study's first draws: its mounting errors and target positions (sub-bin,
            # or the bin centre without mc.subbin)
            verify = verify_draws(model.sets[0], self.bounds.offsets_m,
                                  mc.evolve(draws=min(self.verify, mc.draws)),
                                  cases=self.cases, all_points=self.verify_all_points)
        inversion = None
        if self.invert_yield is not None:
            inversion = {}
            for case in CASES:
                search = YieldSearch(self.invert_yield, self.spec_deg, case)
                inversion[case] = (search.scale(model, self.bounds, mc) if model.kind == "arc"
                                   else search.sigma(model, self.bounds.offsets_m, mc,
                                                     self.invert_axis))
        elapsed = time.perf_counter() - t0
        own = scene_offsets_effect(scene, model) if model.kind == "pair" else None
        return ToleranceReport(self, res, verify, inversion, own, elapsed)


def scene_offsets_effect(scene: Scene, model: ToleranceModel) -> dict | None:
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


@dataclass(frozen=True, repr=False)
class ToleranceReport(Result):
    """What a :class:`ToleranceStudy` found: the Monte-Carlo run (``run``, a
    :class:`~.montecarlo.ToleranceResult`), the chain check (``verify``), the yield search
    (``inversion``, per case) and the effect of the scene's own offsets (``scene_offsets``, a
    pair only).

    ``to_dict()`` is the JSON of ``rtsgeom tolerance``; ``write(folder)`` its ``--out`` files
    (tolerance.json, tolerance.png, tolerance_draws.npz); ``to_dataframe()`` one row per
    draw; ``plot()`` the CDF of each draw's worst error.

    Attributes
    ----------
    study : ToleranceStudy
    run : ToleranceResult
    verify : VerifyResult or None
    inversion : dict or None
    scene_offsets : dict or None
    elapsed_s : float
    """

    study: ToleranceStudy
    run: ToleranceResult
    verify: VerifyResult | None = None
    inversion: dict | None = None
    scene_offsets: dict | None = None
    elapsed_s: float = 0.0

    @property
    def kind(self) -> str:
        return self.run.model.kind

    def _summary(self):
        title, rows = self.run._summary()
        if self.verify is not None:
            rows.append(("verify |chain - model| (deg)", self.verify.max_difference_deg))
        for case, inv in (self.inversion or {}).items():
            rows.append((f"search ({case})", inv.get("factor", inv.get("sigma_mm"))))
        return title, rows

    def _columns(self) -> dict:
        return self.run._columns()

    def plot(self, title: str = ""):
        """The run's figure: the study, the drawn scales and the spec in its title."""
        return self.run.plot(title)

    def to_dict(self) -> dict:
        out = self.run.to_dict()
        if self.kind == "arc":
            out["sigma_level"] = (self.study.sigma_level if self.run.distribution == "normal"
                                  else None)
        if self.verify is not None:
            out["verify"] = self.verify.to_dict()
        if self.inversion is not None:
            out["inversion"] = self.inversion
        if self.scene_offsets is not None:
            out["scene_offsets"] = self.scene_offsets
        return out

    def draw_arrays(self) -> dict:
        """The per-draw arrays of tolerance_draws.npz: an arc's errors as kept
        (:meth:`~.montecarlo.ToleranceResult.save_npz`), a pair's or a cell's offsets, delays,
        range offsets and worst errors per case."""
        res, m = self.run, self.run.model.sets[0]
        arrays = {"offsets_m": draw_offsets(res.seed, res.draws, res.sigma_m, res.distribution,
                                            len(m.front_ends))}
        if self.kind == "pair":
            arrays.update({"pairs": np.array([m.front_ends]), "delay_s": res.delay_s[:, None],
                           "range_offset_m": res.range_offset_m[:, None]})
            arrays.update({f"{case}_deg": v[:, None] for case, v in res.worst_error_deg.items()})
        else:
            arrays.update({"cell": np.array(m.front_ends), "delay_s": res.delay_s,
                           "range_offset_m": res.range_offset_m,
                           "subbin_steps": (np.zeros(res.draws, int) if res.subbin_steps is None
                                            else np.asarray(res.subbin_steps))})
            arrays.update({f"{case}_deg": v for case, v in res.worst_error_deg.items()})
        return arrays

    def write(self, folder: str | Path) -> list[str]:
        """tolerance.png, tolerance.json and tolerance_draws.npz (per-draw errors and worst
        angle errors, for sensitivity analysis) into ``folder``; returns the names."""
        from ...viz.figures import save_figure  # matplotlib: only where a figure is written
        folder = Path(folder)
        save_figure(self.plot(), folder / "tolerance.png")
        self.to_json(folder / "tolerance.json")
        path = folder / "tolerance_draws.npz"
        if self.kind == "arc":
            self.run.save_npz(path)
        else:
            tmp = path.with_name(path.name + ".part")
            with open(tmp, "wb") as fh:
                np.savez_compressed(fh, **self.draw_arrays())
            tmp.replace(path)
        return ["tolerance.png", "tolerance.json", "tolerance_draws.npz"]

