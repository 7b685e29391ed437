"""Angle linearity: targets synthesized at set directions across a pair's span (an arc, a RuT
that beamforms in azimuth: paper Fig. "Amplitude attenuation and angle linearity and error") or
over a grid inside a cell of front ends (a RuT that beamforms in azimuth and elevation), each
detected on the simulated RuT output (the full ADC-cube chain)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial import Delaunay

from .._lib.results import Result
from ..calibration.channels import calibrate_channels, tree_phases
from ..calibration.sweep import Calibration
from ..calibration.probes import (FrontEndProbe, probe_angles, probe_front_ends, probe_ranges,
                                  simulate_detect)
from ..errors import ParameterError
from ..geometry import Setup
from ..paths import Paths, nominal_model
from ..calibration.phasor import PairChannels
from ..pipeline.pair import pair_design
from ..radar.processing import nearest_detection
from ..radar.steering import Steering
from ..rts.channels import RtsProgram, requested_delay
from ..scene import TargetConfig
from ..synthesis.closed_form import array_factor_args, ratio_array_factor, ratio_paper
from ..synthesis.model import ChannelModel

__all__ = ["Linearity", "linearity", "cell_grid", "error_map_figure", "END_ANGLES",
           "finite_or_none"]

END_ANGLES = ("geometric", "measured")


@dataclass(frozen=True, repr=False)
class Linearity(Result):
    """Set and detected directions (deg) of the synthesized targets: (P,) azimuths of a pair,
    or (P, 2) (azimuth, elevation) over a cell (NaN: not detected). ``print(lin)`` is a
    summary; ``to_dataframe()`` one row per set-point; ``plot()`` the figure of
    ``rtsgeom linearity --out``.

    Attributes
    ----------
    mode : str
    calibrated : bool
    set_deg, detected_deg : (P,) or (P, 2) float
    amplitude_db : (Q, P) float, optional
    channels : tuple of int
    """

    mode: str
    calibrated: bool
    set_deg: np.ndarray
    detected_deg: np.ndarray
    amplitude_db: np.ndarray | None = None  # (Q, P) programmed attenuation per channel
    end_angles: str = "geometric"  # front-end angles the closed forms used (a pair's)
    channels: tuple[int, ...] = ()

    @property
    def dims(self) -> int:
        return 1 if np.ndim(self.set_deg) == 1 else 2

    @property
    def error_deg(self) -> np.ndarray:
        return self.detected_deg - self.set_deg

    @property
    def max_abs_error_deg(self):
        """The worst |error| (deg): a pair's, or a cell's (azimuth, elevation)."""
        e = np.abs(self.error_deg)
        if self.dims == 1:
            return float(np.nanmax(e))
        return float(np.nanmax(e[:, 0])), float(np.nanmax(e[:, 1]))

    def _summary(self):
        what = "pair" if self.dims == 1 else "cell"
        title = (f"{self.mode} synthesis over {what} {tuple(self.channels)}, "
                 f"{'calibrated' if self.calibrated else 'uncalibrated'}")
        det = np.isfinite(self.detected_deg).reshape(len(self.set_deg), -1).all(axis=-1)
        mx = self.max_abs_error_deg
        rows = [("set-points", f"{len(self.set_deg)} ({int(det.sum())} detected)"),
                ("max_abs_error_deg", mx if self.dims == 1 else
                 f"azimuth {mx[0]:.4g}, elevation {mx[1]:.4g}")]
        if self.dims == 1:
            rows += [("set_deg", self.set_deg), ("error_deg", self.error_deg),
                     ("end_angles", self.end_angles)]
        else:
            rows += [("set azimuth_deg", self.set_deg[:, 0]),
                     ("set elevation_deg", self.set_deg[:, 1])]
        return title, rows

    def _columns(self) -> dict:
        if self.dims == 1:
            cols = {"set_deg": self.set_deg, "detected_deg": self.detected_deg,
                    "error_deg": self.error_deg}
            if self.amplitude_db is not None:
                for q, a in zip(self.channels or range(len(self.amplitude_db)),
                                np.asarray(self.amplitude_db)):
                    cols[f"amplitude_{q}_db"] = a
            return cols
        e = self.error_deg
        return {"set_azimuth_deg": self.set_deg[:, 0], "set_elevation_deg": self.set_deg[:, 1],
                "detected_azimuth_deg": self.detected_deg[:, 0],
                "detected_elevation_deg": self.detected_deg[:, 1],
                "azimuth_error_deg": e[:, 0], "elevation_error_deg": e[:, 1]}

    def to_dict(self) -> dict:
        if self.dims == 1:
            return {
                "mode": self.mode, "calibrated": self.calibrated, "end_angles": self.end_angles,
                "points": [{"set_deg": float(s), "detected_deg": finite_or_none(d),
                            "error_deg": finite_or_none(d - s)}
                           for s, d in zip(self.set_deg, self.detected_deg)],
                "max_abs_error_deg": finite_or_none(self.max_abs_error_deg)}
        mx = self.max_abs_error_deg
        return {"mode": self.mode, "calibrated": self.calibrated, "cell": list(self.channels),
                "points": [{"set_deg": [float(x) for x in s],
                            "detected_deg": [finite_or_none(x) for x in d],
                            "error_deg": [finite_or_none(x) for x in d - s]}
                           for s, d in zip(self.set_deg, self.detected_deg)],
                "max_abs_error_deg": {"azimuth": finite_or_none(mx[0]),
                                      "elevation": finite_or_none(mx[1])}}

    def plot(self):
        """The figure: a pair's detected against set angle and the amplitudes; a cell's
        azimuth and elevation errors over the set directions."""
        if self.dims == 2:
            return error_map_figure(self)
        from ..viz.figures import linearity_figure  # matplotlib: only for the figure
        return linearity_figure(self.set_deg, {self.mode: self.detected_deg},
                                {self.mode: self.amplitude_db}, pair=self.channels)

    def write(self, folder) -> list[str]:
        """``rtsgeom linearity --out``: linearity.png and linearity.json (a pair's), or
        linearity_grid.png and linearity_grid.json (a cell's) into ``folder``; returns the
        names."""
        from ..viz.figures import save_figure  # matplotlib: only where a figure is written
        stem = "linearity" if self.dims == 1 else "linearity_grid"
        save_figure(self.plot(), Path(folder) / f"{stem}.png")
        self.to_json(Path(folder) / f"{stem}.json")
        return [f"{stem}.png", f"{stem}.json"]


def linearity(setup: Setup, paths: Paths, channels=None, mode: str = "exact",
              probe: FrontEndProbe | None = None, calibration: Calibration | None = None,
              points: int = 21, seed: int = 0, *, end_angles: str = "geometric",
              calibrate: bool = True, progress=None) -> Linearity:
    """Synthesize targets at set directions across ``channels`` and detect each on the
    simulated RuT: for a RuT that beamforms in azimuth a pair of front ends (default (0, 1);
    ``points`` set-points across its span, ``probe``: each front end alone, measured when
    None; ``calibration``: the pair's, None: uncalibrated), for one that beamforms in azimuth
    and elevation the cell of all front ends (3 or 4; a ``points`` x ``points`` grid of set
    directions inside it; ``calibrate``: the channels calibrated first).

    A pair's span is where every mode can work: the intersection of the measured span (each
    front end alone as the RuT detects it; near field and Rx/Tx separation move it) and the
    geometric span (the closed forms only reach between the front ends' geometric angles);
    its ends are excluded, where one channel would be off. ``end_angles``: which front-end
    angles the closed forms (``paper``, ``array-factor``) use: ``geometric`` (module azimuths
    of the nominal setup) or ``measured`` (each front end alone as the RuT detects it);
    ``exact`` ignores it.
    """
    if Steering.auto(setup.rut, setup.scene.radar).dims == 2:
        return _grid(setup, paths, mode, int(points), calibrate, seed, progress)
    pair = (0, 1) if channels is None else tuple(int(q) for q in channels)
    probe = probe_front_ends(setup, paths, seed) if probe is None else probe
    if end_angles not in END_ANGLES:
        raise ParameterError(f"end_angles = {end_angles!r}: must be one of {END_ANGLES}")
    scene = setup.scene
    i, j = pair
    meas = np.sort(probe.angle_rad[[i, j]])
    geo = np.sort(setup.fe_azimuth_rad()[[i, j]])
    th = np.array([max(meas[0], geo[0]), min(meas[1], geo[1])])
    frac = np.arange(1, points + 1) / (points + 1)
    sets = th[0] + frac * (th[1] - th[0])
    off = (0.0, calibration.delta_tau_s if calibration else 0.0)
    corr = probe.gain_correction[[i, j]] if calibration else np.ones(2)
    rng = float(probe_ranges(setup, 1)[0])
    tau = float(requested_delay(scene, rng))
    det_deg = np.full(points, np.nan)
    amp = np.zeros((2, points))
    for k, a in enumerate(sets):
        t = TargetConfig(rng, 0.0, 10.0, float(a))
        if end_angles == "measured" and mode != "exact":
            a_i, a_j, _ = _closed_form_measured(setup, paths, pair, t, mode, probe, off, corr)
        else:
            a_i, a_j, _, off_j = pair_design(setup, paths, PairChannels(pair, off, corr), t,
                                             mode, probe_angles(*probe.angle_rad[[i, j]]),
                                             calibration.quantisation_residual_s
                                             if calibration else 0.0)
        amp[:, k] = a_i, a_j
        off_j = off[1] if end_angles == "measured" and mode != "exact" else off_j
        prog = RtsProgram.build([0, 0], [i, j], [tau + off[0], tau + off_j], [0.0, 0.0],
                                [a_i, a_j])
        rd, det = simulate_detect(setup, paths, prog, seed)
        n = nearest_detection(det, rd, rng)
        if n is not None:
            det_deg[k] = np.degrees(det.angle_rad[n])
    amp_db = 20 * np.log10(np.maximum(amp, 1e-300) / np.max(amp))
    return Linearity(mode, calibration is not None, np.degrees(sets), det_deg, amp_db,
                     end_angles, pair)


def _closed_form_measured(setup, paths, pair, target, mode, probe, offsets, corr):
    """``paper`` / ``array-factor`` amplitudes with the front ends' *measured* angles (each
    alone as the RuT detects it, as the paper's angles were "determined by measurement")
    in the closed form, instead of their geometric azimuths."""
    i, j = pair
    th = probe.angle_rad[[i, j]]
    alpha = target.angle_rad
    nom, nom_paths = nominal_model(setup, paths)
    model = ChannelModel.build(nom, nom_paths, pair, target, offsets)
    if mode == "paper":
        rho = float(ratio_paper(th[0], th[1], alpha))
    else:  # the RuT's own beamformer (taper, repeated elements), as the geometric reading
        rho = float(ratio_array_factor(th[0], th[1], alpha,
                                       **array_factor_args(model.steering)))
    rho = float(np.clip(rho, 0.0, 1e12))
    phase = float(model.pair_phase(probe_angles(*th)))
    a_i, a_j = model.amplitudes(model.pair_weights(rho, (0.0, phase)), np.sin([alpha]))
    return a_i * corr[0], a_j * corr[1], rho


def cell_grid(steering: Steering, u_fe, n: int) -> np.ndarray:
    """Set directions (P, 2) (azimuth, elevation) rad over a cell of front ends at direction
    cosines ``u_fe`` (Q, 2): an n x n grid at fractions (k + 1) / (n + 1) of the corners'
    extent in each angle (ends excluded), the points outside the cell's hull dropped."""
    u_fe = np.asarray(u_fe, float)
    ang_fe = steering.angles(u_fe)
    lo, hi = ang_fe.min(0), ang_fe.max(0)
    f = np.arange(1, n + 1) / (n + 1)
    grid = np.stack(np.meshgrid(lo[0] + f * (hi[0] - lo[0]), lo[1] + f * (hi[1] - lo[1]),
                                indexing="ij"), -1).reshape(-1, 2)
    return grid[Delaunay(u_fe).find_simplex(steering.directions(grid)) >= 0]


def _grid(setup: Setup, paths: Paths, mode: str, n: int, calibrate: bool, seed: int,
          progress) -> Linearity:
    """An n x n grid of set directions over the cell of all front ends (at most 4: one cell)
    in (azimuth, elevation), fractions (k + 1) / (n + 1) of the corners' extent in each axis
    (ends excluded, points outside the cell's hull dropped), each synthesized alone with
    the calibrated offsets and phases and detected by the simulated RuT."""
    if setup.fe.count > 4:
        raise ParameterError(f"linearity --grid: the scene has {setup.fe.count} front ends; the "
                         "error map covers one cell of 3 or 4")
    cell = tuple(range(setup.fe.count))
    nom, nom_paths = nominal_model(setup, paths)
    probe = probe_front_ends(setup, paths, seed)
    rng = float(probe_ranges(setup, 1)[0])
    target0 = TargetConfig(rng)
    st = Steering.auto(nom.rut, setup.scene.radar)
    offsets, tree = np.zeros(setup.fe.count), None
    if calibrate:
        cal = calibrate_channels(setup, paths, cell, probe, seed, progress)
        offsets, tree = cal.offsets_s, cal.tree
    cs = ChannelModel.build(nom, nom_paths, cell, target0, offsets[list(cell)], steering=st)
    grid = cell_grid(st, cs.fe_directions(), n)
    phases = None if tree is None else tree_phases(cs, tree)
    corr = probe.gain_correction[list(cell)] if calibrate else np.ones(len(cell))
    tau = float(requested_delay(setup.scene, rng))
    det_deg = np.full(grid.shape, np.nan)
    for k, a in enumerate(grid):
        u = st.directions(a)
        w = cs.solve(u, phases, mode)
        amps = cs.amplitudes(w, u) * corr
        prog = RtsProgram.build([0] * len(cell), list(cell), list(tau + offsets[list(cell)]),
                                [0.0] * len(cell), list(amps))
        rd, det = simulate_detect(setup, paths, prog, seed)
        j = nearest_detection(det, rd, rng)
        if j is not None:
            det_deg[k] = np.degrees([det.angle_rad[j], det.elevation_rad[j]])
        if progress:
            progress(f"set-point {k + 1}/{grid.shape[0]}")
    return Linearity(mode, calibrate, np.degrees(grid), det_deg, channels=cell)


def error_map_figure(em: Linearity):
    """Two panels over (azimuth, elevation): the azimuth and the elevation error (deg)."""
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2), constrained_layout=True)
    e = em.error_deg
    lim = max(float(np.nanmax(np.abs(e))), 1e-6)
    for ax, k, name in zip(axes, (0, 1), ("azimuth", "elevation")):
        sc = ax.scatter(em.set_deg[:, 0], em.set_deg[:, 1], c=e[:, k], cmap="coolwarm",
                        vmin=-lim, vmax=lim, s=160, marker="s", edgecolors="k")
        ax.set_xlabel("set azimuth (deg)")
        ax.set_ylabel("set elevation (deg)")
        ax.set_title(f"{name} error ({em.mode}, "
                     f"{'calibrated' if em.calibrated else 'uncalibrated'})")
        fig.colorbar(sc, ax=ax, label=f"{name} error (deg)")
    return fig


def finite_or_none(x) -> float | None:
    """A JSON value: the number, or None where it is not finite (a set-point the RuT did not
    detect), since the outputs are written with ``allow_nan=False``."""
    x = float(x)
    return x if np.isfinite(x) else None
