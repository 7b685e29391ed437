"""Azimuth/elevation error map of targets synthesized inside one cell of front ends (issue 15:
the 2-D counterpart of ``aoa.linearity``), on the simulated RuT output."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import Delaunay

from ..errors import ParameterError
from ..geometry import Setup
from ..paths import Paths
from ..radar.processing import nearest_detection
from ..radar.steering import Steering
from ..rts.channels import RtsProgram, requested_delay
from ..scene import TargetConfig
from ..calibration.probes import simulate_detect, probe_front_ends, probe_ranges
from ..paths import nominal_model
from ..synthesis.model import ChannelModel

__all__ = ["ErrorMap", "cell_grid", "linearity_grid"]


@dataclass(frozen=True)
class ErrorMap:
    mode: str
    calibrated: bool
    cell: tuple[int, ...]
    set_deg: np.ndarray  # (P, 2) azimuth, elevation
    detected_deg: np.ndarray  # (P, 2); NaN: not detected

    @property
    def error_deg(self) -> np.ndarray:
        return self.detected_deg - self.set_deg

    def max_abs_error_deg(self) -> tuple[float, float]:
        e = np.abs(self.error_deg)
        return float(np.nanmax(e[:, 0])), float(np.nanmax(e[:, 1]))

    def to_dict(self) -> dict:
        mx = self.max_abs_error_deg()
        return {"mode": self.mode, "calibrated": self.calibrated, "cell": list(self.cell),
                "points": [{"set_deg": [float(x) for x in s],
                            "detected_deg": [None if not np.isfinite(x) else float(x)
                                             for x in d],
                            "error_deg": [None if not np.isfinite(x) else float(x)
                                          for x in d - s]}
                           for s, d in zip(self.set_deg, self.detected_deg)],
                "max_abs_error_deg": {"azimuth": mx[0], "elevation": mx[1]}}


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


def linearity_grid(setup: Setup, paths: Paths, mode: str = "exact", n: int = 5,
                   calibrate: bool = True, seed: int = 0, progress=None) -> ErrorMap:
    """An n x n grid of set directions over the cell of all front ends (at most 4: one cell)
    in (azimuth, elevation), fractions (k + 1) / (n + 1) of the corners' extent in each axis
    (ends excluded, points outside the cell's hull dropped), each synthesized alone with
    the calibrated offsets and phases and detected by the simulated RuT."""
    from ..calibration.channels import calibrate_channels, tree_phases
    if setup.fe.count > 4:
        raise ParameterError(f"linearity --grid: the scene has {setup.fe.count} front ends; the "
                         "error map covers one cell of 3 or 4")
    cell = tuple(range(setup.fe.count))
    nom, nom_paths = nominal_model(setup, paths)
    probe = probe_front_ends(setup, paths, seed)
    rng = float(probe_ranges(setup, 1)[0])
    target0 = TargetConfig(rng)
    st = Steering.auto(nom.rut, setup.scene.radar)
    if st.dims != 2:
        raise ParameterError("linearity --grid needs a RuT with elevation (an array with "
                         "elevation extent, e.g. radar.use_elevation_tx = true)")
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
    return ErrorMap(mode, calibrate, cell, np.degrees(grid), det_deg)


def error_map_figure(em: ErrorMap):
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
