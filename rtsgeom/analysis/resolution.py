"""Angular resolution test: can the RTS emulate two targets the RuT resolves, as real ones?

Two targets of equal RCS at ``C - s/2`` and ``C + s/2``, one range and velocity (one
range-Doppler cell), their echoes' relative phase at the RuT's phase centre set to ``phase``
(two real targets at one range are in phase there: phase 0). At every separation ``s`` and phase,
the same radar looks at them twice: as the truth twin (point targets in free space,
:mod:`rtsgeom.radar.truth`) and through the RTS (the bench calibrated once, each separation
planned like a frame of a drive). **Resolved** means two detections, each nearer its own target
than the other: both targets ``detected`` by the association
(:func:`rtsgeom.radar.association.associate`), with the radar reporting several angle peaks per
cell (``[radar] angle_peaks_max``, ``angle_peak_threshold``).

The smallest separation from which every larger one on the grid is resolved is the setup's
minimum resolvable separation, per source and phase. Where the truth resolves and the RTS does
not, the bench's near field is the usual cause: each synthesized target carries the
asymmetric phase pattern the arc's finite radius puts across the RuT's aperture.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._lib.io import write_text
from .._lib.results import Result
from ..errors import AngleUnreachable, ParameterError, SceneError
from ..geometry import Setup, build_setup
from ..paths import compute_paths
from ..pipeline.matching import match_targets
from ..radar import process
from ..radar.fmcw import beat_phase0
from ..radar.frame import noise_power, simulate
from ..radar.processing import angle_spectrum, tdm_compensate
from ..radar.steering import Steering
from ..radar.truth import simulate_truth, truth_echoes
from ..rts.channels import EchoKind, RtsProgram, build_echoes
from ..scene import Scene, TargetConfig
from ..scene.registry import AOA_MODES
from ..scene.schema import check_arg
from .playback.frames import FramePlanner

__all__ = ["ResolutionStudy", "Resolution", "resolution", "SOURCES"]

SOURCES = ("truth", "rts")
_MAX_CASES = 20_000  # separations x phases, each two frames through the radar chain


@dataclass(frozen=True)
class ResolutionStudy:
    """A configured resolution test (call it on a scene).

    Parameters
    ----------
    range_m : float, optional
        The targets' range (default: 20 m, or half the radar's range axis if shorter).
    velocity_mps : float
        Their velocity (one Doppler cell).
    centre_deg : float, optional
        C, the midpoint of the two targets (default: the middle of the arc).
    separations_deg : tuple of float
        The separations s on the grid, deg (default 2 to 30 in 1-deg steps, cut to what the
        arc reaches).
    phases_deg : tuple of float
        Relative phases of the second target's echo at the RuT's phase centre, deg.
    rcs_dbsm : float
        RCS of each target.
    amplitudes : str, optional
        The RTS's AoA mode (default the scene's ``rts.aoa_mode``).
    """

    range_m: float | None = None
    velocity_mps: float = 0.0
    centre_deg: float | None = None
    separations_deg: tuple = ()
    phases_deg: tuple = (0.0, 90.0, 180.0)
    rcs_dbsm: float = 10.0
    amplitudes: str | None = None

    def __post_init__(self):
        src, err = "resolution", ParameterError
        check_arg(self.velocity_mps, "velocity_mps", "float", src, err, lo=-1e3, hi=1e3,
                  unit="m/s")
        check_arg(self.rcs_dbsm, "rcs_dbsm", "float", src, err, lo=-100.0, hi=100.0,
                  unit="dBsm")
        if self.range_m is not None:
            check_arg(self.range_m, "range_m", "float", src, err, lo=0.1, hi=1e4, unit="m")
        if self.centre_deg is not None:
            check_arg(self.centre_deg, "centre_deg", "float", src, err, lo=-90.0, hi=90.0,
                      unit="deg")
        if self.amplitudes is not None:
            check_arg(self.amplitudes, "amplitudes", "str", src, err, choices=tuple(AOA_MODES))
        seps, phases = np.asarray(self.separations_deg, float), np.asarray(self.phases_deg,
                                                                           float)
        if seps.ndim != 1 or not np.all(np.isfinite(seps)) or np.any(seps <= 0) or np.any(
                seps > 120):
            raise err(f"resolution: separations_deg = {self.separations_deg!r}: must be "
                      "separations in (0, 120] deg")
        if phases.ndim != 1 or phases.size == 0 or not np.all(np.abs(phases) <= 360):
            raise err(f"resolution: phases_deg = {self.phases_deg!r}: must be one or more "
                      "phases in [-360, 360] deg")
        if seps.size * phases.size > _MAX_CASES:
            raise err(f"resolution: {seps.size} separations x {phases.size} phases: at most "
                      f"{_MAX_CASES} cases")

    def __call__(self, scene: Scene, progress=None) -> "Resolution":
        """Run the test on ``scene``'s bench (its targets and drive are not used)."""
        mode = self.amplitudes or scene.rts.aoa_mode
        scene = dataclasses.replace(scene, scenario=None, targets=())
        if mode != scene.rts.aoa_mode:
            scene = scene.evolve(rts=scene.rts.evolve(aoa_mode=mode))
        setup = build_setup(scene)
        paths = compute_paths(setup, "exact")
        rng = (self.range_m if self.range_m is not None
               else min(20.0, 0.5 * scene.radar.max_range_m))
        centre = self.centre_deg if self.centre_deg is not None else float(
            np.degrees(np.mean(setup.fe_azimuth_rad()[[0, -1]])))
        seps = np.asarray(self.separations_deg or _default_separations(setup, centre), float)
        if seps.size == 0:
            raise ParameterError(f"resolution: the arc reaches no separation of 2 deg or more "
                                 f"about centre_deg {centre:g}: give separations_deg")
        frames = [_pair(rng, self.velocity_mps, self.rcs_dbsm, centre, s) for s in seps]
        try:
            planner = FramePlanner(setup, paths, mode, frames, progress)
        except (SceneError, AngleUnreachable) as exc:
            raise ParameterError(f"resolution: separations_deg up to {seps.max():g} about "
                                 f"centre_deg {centre:g}: {exc}") from None
        case = _Case(setup, paths, planner, Steering.auto(setup.rut, scene.radar))
        # the figure's spectra: a few separations spread over the grid, at the first phase
        pick = set(np.linspace(0, seps.size - 1, min(4, seps.size)).round().astype(int).tolist())
        spectra = {"angle_deg": _SPECTRUM_GRID_DEG, "separation_deg": seps[sorted(pick)],
                   "phase_deg": float(self.phases_deg[0]), "truth": [], "rts": []}
        rows = []
        for f, s in enumerate(seps):
            if progress:
                progress(f"separation {s:g} deg ({f + 1}/{seps.size})")
            rows += case.rows(f, frames[f], self.phases_deg, spectra if f in pick else None)
        return Resolution(scene_name=scene.name, study=self, range_m=rng, centre_deg=centre,
                          table=_table(rows, seps, self.phases_deg), spectra=spectra)


def resolution(scene: Scene, **kwargs) -> "Resolution":
    """Run :class:`ResolutionStudy` (``kwargs`` its parameters) on ``scene``.

    Parameters
    ----------
    scene : Scene
        The setup to test.
    **kwargs
        :class:`ResolutionStudy`'s fields.

    Returns
    -------
    Resolution

    Raises
    ------
    ParameterError
        A field outside its range, naming it.
    """
    return ResolutionStudy(**kwargs)(scene)


def _default_separations(setup: Setup, centre_deg: float) -> np.ndarray:
    """2..30 deg in 1-deg steps, cut to what the arc's outer front ends reach about C (each
    front end is itself seen a little off its arc angle: one degree of margin)."""
    az = np.degrees(setup.fe_azimuth_rad())
    half = min(centre_deg - az.min(), az.max() - centre_deg) - 1.0
    return np.arange(2.0, min(30.0, 2 * half) + 1e-9, 1.0)


def _pair(range_m, velocity_mps, rcs_dbsm, centre_deg, sep_deg) -> tuple:
    return tuple(TargetConfig(range_m=float(range_m), velocity_mps=float(velocity_mps),
                              rcs_dbsm=float(rcs_dbsm),
                              angle_rad=float(np.radians(centre_deg + sgn * sep_deg / 2)),
                              elevation_rad=0.0) for sgn in (-1, 1))


def _beam_phase(setup: Setup, echoes, targets, steering) -> np.ndarray:
    """Each target's echo phase at the RuT's phase centre (T,): the beamformer's output phase
    at its own direction, from the echoes' constant beat phase (the two targets share range
    and velocity, so the rest of the beat is common)."""
    radar = setup.scene.radar
    x = echoes.amplitude * np.exp(1j * beat_phase0(echoes, radar))
    out = []
    for k, t in enumerate(targets):
        snap = x[(echoes.target == k) & (echoes.kind == EchoKind.DIRECT)].sum(axis=0)
        u = steering.directions(np.array([t.angle_rad] if steering.dims == 1
                                         else [[t.angle_rad, 0.0]]))
        out.append(np.angle(steering.beam(snap, u)[0]))
    return np.asarray(out)


#: the figure's angle axis (deg)
_SPECTRUM_GRID_DEG = np.linspace(-60.0, 60.0, 1201)


@dataclass(frozen=True)
class _Case:
    """The bench, its calibrated planner and the RuT's beamformer, for the cases of a study."""

    setup: Setup
    paths: object
    planner: FramePlanner
    steering: Steering

    def cubes(self, f: int, targets, phase_deg: float) -> list:
        """One case through the radar twice: [("truth", cube), ("rts", cube)], the second
        target's echo turned so that its phase at the RuT's phase centre leads the first's by
        ``phase_deg`` in both; the same seed and noise power in both."""
        setup, scene = self.setup, self.setup.scene
        program, _ = self.planner.program(f, dataclasses.replace(scene, targets=targets))
        d_truth = np.diff(_beam_phase(setup, truth_echoes(setup, targets), targets,
                                      self.steering))[0]
        d_rts = np.diff(_beam_phase(setup, build_echoes(setup, self.paths, program), targets,
                                    self.steering))[0]
        want = -np.radians(phase_deg)  # the beat carries the conjugate of the received phase
        turn = np.where(program.target == 1, np.exp(-1j * (want - d_rts)), 1.0)
        program = RtsProgram.build(program.target, program.front_end, program.delay_s,
                                   program.doppler_hz, program.amplitude * turn)
        echoes, cube = simulate(setup, self.paths, program, scene.seed, scene.radar.snr_db)
        noise = None if scene.radar.snr_db is None else noise_power(echoes, scene.radar.snr_db)
        _, t_cube = simulate_truth(setup, targets, scene.seed, noise, [0.0, -(want - d_truth)])
        return [("truth", t_cube), ("rts", cube)]

    def rows(self, f: int, targets, phases_deg, spectra: dict | None = None) -> list[dict]:
        """Rows of the table for one separation: per phase and source, resolved and the two
        targets' detected angles (NaN where a target has no detection of its own); with
        ``spectra``, the first phase's angle spectra appended to it (the figure's)."""
        scene = dataclasses.replace(self.setup.scene, targets=targets)
        rows = []
        for k, ph in enumerate(phases_deg):
            for source, cube in self.cubes(f, targets, ph):
                rd, det = process(cube)
                m = match_targets(scene, det, rd, steering=cube.steering,
                                  real=source == "truth")
                ang = [x["detection"]["angle_deg"] if x["status"] == "detected" else np.nan
                       for x in m]
                rows.append({"phase_deg": float(ph), "source": source,
                             "resolved": all(x["status"] == "detected" for x in m),
                             "angle_1_deg": float(ang[0]), "angle_2_deg": float(ang[1])})
                if spectra is not None and k == 0:
                    spectra[source].append(_cell_spectrum_db(rd, cube))
        return rows


def _cell_spectrum_db(rd, cube) -> np.ndarray:
    """The RuT's angle spectrum (dB, normalised) of the map's strongest cell over
    :data:`_SPECTRUM_GRID_DEG`."""
    r, d = np.unravel_index(np.argmax(rd.power), rd.power.shape)
    snap = tdm_compensate(rd.spectrum[r, d], rd.doppler_hz[d], cube.rut, cube.radar)
    p = angle_spectrum(snap, cube.steering, None, np.radians(_SPECTRUM_GRID_DEG))
    return 10 * np.log10(np.maximum(p / p.max(), 1e-12))


def _table(rows: list[dict], seps, phases_deg) -> dict:
    """The rows as columns, in the order separation, phase, source."""
    per = 2 * len(phases_deg)
    cols = {"separation_deg": np.repeat(np.asarray(seps, float), per)}
    for key in ("phase_deg", "source", "resolved", "angle_1_deg", "angle_2_deg"):
        cols[key] = np.array([r[key] for r in rows])
    return cols


def min_separation(separations, resolved) -> float | None:
    """The smallest separation from which every larger one on the grid is resolved (None:
    the largest is not)."""
    seps = np.asarray(separations, float)
    ok = np.asarray(resolved, bool)
    order = np.argsort(seps)
    seps, ok = seps[order], ok[order]
    if ok.size == 0 or not ok[-1]:
        return None
    bad = np.flatnonzero(~ok)
    return float(seps[bad[-1] + 1] if bad.size else seps[0])


@dataclass(frozen=True, repr=False)
class Resolution(Result):
    """A resolution test's result (:class:`ResolutionStudy`); :attr:`min_separation_deg` the
    headline.

    Attributes
    ----------
    scene_name : str
        The scene's name.
    study : ResolutionStudy
        The study that made it.
    range_m, centre_deg : float
        The two targets' range and the azimuth they are placed about.
    table : dict
        Columns ``separation_deg``, ``phase_deg``, ``source`` (``truth``, ``rts``),
        ``resolved``, ``angle_1_deg``, ``angle_2_deg``.
    spectra : dict
        The angle spectra of the figure.
    """

    scene_name: str
    study: ResolutionStudy
    range_m: float
    centre_deg: float
    table: dict
    spectra: dict = field(default_factory=dict)

    @property
    def min_separation_deg(self) -> dict:
        """``{source: {phase_deg: s}}``: the minimum resolvable separation (None: not
        resolved at the largest separation tried)."""
        t = self.table
        out = {}
        for source in SOURCES:
            out[source] = {}
            for ph in dict.fromkeys(t["phase_deg"].tolist()):
                sel = (t["source"] == source) & (t["phase_deg"] == ph)
                out[source][_phase_key(ph)] = min_separation(t["separation_deg"][sel],
                                                             t["resolved"][sel])
        return out

    def _columns(self) -> dict:
        return dict(self.table)

    def _summary(self):
        ms = self.min_separation_deg
        rows = [(f"{src} min separation", ", ".join(
            f"{'-' if v is None else f'{v:g}'} deg at {k} deg" for k, v in ms[src].items()))
            for src in SOURCES]
        seps = np.unique(self.table["separation_deg"])
        title = (f"{self.scene_name}: two targets at {self.centre_deg:g} ± s/2 deg, "
                 f"{self.range_m:g} m, s {seps.min():g}..{seps.max():g} deg")
        return title, rows

    def to_dict(self) -> dict:
        """The content of ``summary.json``."""
        st = self.study
        return {"scene": self.scene_name, "range_m": self.range_m,
                "velocity_mps": st.velocity_mps, "centre_deg": self.centre_deg,
                "rcs_dbsm": st.rcs_dbsm,
                "separations_deg": sorted(set(self.table["separation_deg"].tolist())),
                "phases_deg": [float(p) for p in st.phases_deg],
                "min_separation_deg": self.min_separation_deg}

    def to_csv(self, path) -> Path:
        """``resolution.csv``: one row per separation, phase and source (atomically); returns
        the path (the base's :meth:`~rtsgeom._lib.results.Result.to_csv` with six digits)."""
        write_text(Path(path), self.to_dataframe().to_csv(index=False, float_format="%.6g",
                                                         na_rep=""))
        return Path(path)

    def plot(self):
        """Upper row: the RuT's angle spectrum of the cell, truth and RTS, at a few
        separations (phase 0); lower row: resolved or not over separation x phase."""
        from ..viz.resolution import resolution_figure  # matplotlib: only for the figure
        return resolution_figure(self)

    def write(self, folder) -> list[str]:
        """``rtsgeom resolution --out``: resolution.csv, summary.json and resolution.png into
        ``folder``; returns the names."""
        from ..viz.figures import save_figure  # matplotlib: only where a figure is written
        folder = Path(folder)
        self.to_csv(folder / "resolution.csv")
        self.to_json(folder / "summary.json")
        save_figure(self.plot(), folder / "resolution.png")
        return ["resolution.csv", "summary.json", "resolution.png"]


def _phase_key(ph: float) -> str:
    return f"{ph:g}"
