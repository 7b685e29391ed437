"""The near-field analysis for a RuT that beamforms in azimuth and elevation (D = 2; issue 15):
each front end alone through the 2-D beamformer, and the synthesized direction over cells of
front ends (``analysis.nearfield``, whose 1-D pairs are the D = 1 case)."""

from __future__ import annotations

import dataclasses

import numpy as np

from ..paths import nominal_model
from ..errors import AngleUnreachable
from ..synthesis.model import ChannelModel
from ..geometry import Setup
from ..paths import Paths
from ..radar.steering import Steering
from ..scene import TargetConfig

__all__ = ["single_front_end_directions_rad", "cell_synthesis_errors_deg"]


def single_front_end_directions_rad(setup: Setup, paths: Paths, range_m: float,
                                    steering: Steering) -> np.ndarray:
    """:func:`single_front_end_angles_rad` through ``steering``: (F,) azimuth (D = 1) or
    (F, 2) (azimuth, elevation) (D = 2)."""
    n = setup.fe.count
    model = ChannelModel.build(setup, paths, range(n), TargetConfig(float(range_m)))
    return dataclasses.replace(model, steering=steering).direction(np.eye(n))


def _cells(u_fe: np.ndarray) -> list[tuple[int, ...]]:
    """The cells of (c) in 2-D: all front ends when there are 3 or 4 (one cell, as
    ``linearity --grid``), else the Delaunay triangles of their direction cosines."""
    if u_fe.shape[0] <= 4:
        return [tuple(range(u_fe.shape[0]))]
    from scipy.spatial import Delaunay
    return [tuple(sorted(int(q) for q in t)) for t in Delaunay(u_fe).simplices]


def cell_synthesis_errors_deg(setup: Setup, paths: Paths, cell, range_m: float,
                              points: int = 11) -> dict:
    """:func:`synthesis_worst_errors_deg` for a cell of front ends in 2-D: worst |detected -
    set| in azimuth and in elevation (deg) of targets synthesized by all the cell's channels
    at a grid of set directions inside it, ``array-factor`` (2-D closed form) vs ``exact``
    (peak matching), phasor level, channels coherent at each set direction (what the
    calibration establishes). The grid: n x n fractions (k + 1) / (n + 1) of the corners'
    (azimuth, elevation) extent, n = round(sqrt(points)) >= 2, points outside the cell's hull
    dropped (as ``linearity --grid``). Design on the nominal setup, detection on the setup as
    built."""
    from scipy.spatial import Delaunay
    target = TargetConfig(float(range_m))
    nom, nom_paths = nominal_model(setup, paths)
    st = Steering.auto(nom.rut, setup.scene.radar)
    design = ChannelModel.build(nom, nom_paths, cell, target, steering=st)
    actual = (design if nom is setup
              else ChannelModel.build(setup, paths, cell, target, steering=st))
    st = design.steering
    u_fe = design.fe_directions()
    ang = st.angles(u_fe)
    lo, hi = ang.min(0), ang.max(0)
    n = max(2, int(round(np.sqrt(points))))
    f = np.arange(1, n + 1) / (n + 1)
    grid = np.stack(np.meshgrid(lo[0] + f * (hi[0] - lo[0]), lo[1] + f * (hi[1] - lo[1]),
                                indexing="ij"), -1).reshape(-1, 2)
    inside = Delaunay(u_fe).find_simplex(st.directions(grid)) >= 0
    grid = grid[inside]
    err = {m: [] for m in ("array-factor", "exact")}
    for a in grid:
        u = st.directions(a)
        ph_design = design.coherent_phases(u[None])
        ph_actual = actual.coherent_phases(u[None])
        for mode in err:
            try:
                w = design.solve(u, ph_design, mode=mode)
            except AngleUnreachable:
                err[mode].append((np.nan, np.nan))
                continue
            got = actual.direction(np.abs(w) * np.exp(1j * ph_actual))
            err[mode].append(tuple(np.degrees(got - a)))
    out = {"cell": [int(q) for q in cell],
           "span_deg": {"azimuth": [float(np.degrees(lo[0])), float(np.degrees(hi[0]))],
                        "elevation": [float(np.degrees(lo[1])), float(np.degrees(hi[1]))]},
           "points": int(grid.shape[0])}
    for mode, key in (("array-factor", "array_factor"), ("exact", "exact")):
        e = np.abs(np.array(err[mode], float).reshape(-1, 2))
        fin = np.isfinite(e)
        worst = [float(np.nanmax(e[:, k])) if fin[:, k].any() else None for k in range(2)]
        out[f"{key}_max_abs_error_azimuth_deg"] = worst[0]
        out[f"{key}_max_abs_error_elevation_deg"] = worst[1]
        out[f"{key}_max_abs_error_deg"] = (None if None in worst else max(worst))
    return out
