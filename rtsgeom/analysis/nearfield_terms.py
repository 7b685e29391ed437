"""The terms of the near-field analysis at one arc radius (:mod:`.nearfield` sweeps them
over radii; paper section "Disadvantages": "the far-field condition is not met, and the virtual
array assumption is not fully accurate").

* Each front end alone as the RuT detects it, at phasor level through the exact paths
  (:func:`single_front_end_angles_rad`: azimuth, or (azimuth, elevation) through a 2-D
  beamformer), and the closed forms of the parts of its bias: the Rx/Tx separation
  (``geometry.farfield.apparent_azimuth_rad``), the RuT's Tx/Rx group parallax
  (:func:`group_azimuth_rad`) and the beat frequency's range-angle coupling
  (:func:`beat_frequency_azimuth_rad`).
* The phase error across the virtual array: exact two-way phase minus its best-fit plane wave
  (:func:`phase_error_deg`).
* The synthesized direction's worst error over a pair's span (D = 1,
  :func:`synthesis_worst_errors_deg`) or a cell's set directions (D = 2,
  :func:`cell_synthesis_errors_deg`), with ``array-factor`` (far field) against ``exact``
  amplitudes; :func:`synthesis_errors` picks by the beamformer's dimension.
"""

from __future__ import annotations

import numpy as np
from scipy.constants import c
from scipy.spatial import Delaunay

from ..calibration.probes import probe_angles
from ..errors import AngleUnreachable
from ..geometry import RutArray, Setup
from ..geometry.farfield import two_way_lengths
from ..paths import Paths, nominal_model
from ..radar.steering import Steering
from ..rts.channels import requested_delay
from ..scene import TargetConfig
from ..synthesis.model import ChannelModel

__all__ = ["group_azimuth_rad", "beat_frequency_azimuth_rad", "phase_error_deg",
           "single_front_end_angles_rad", "echo_delay_s", "synthesis_worst_errors_deg",
           "cell_synthesis_errors_deg", "synthesis_errors", "cells_of"]


# -- closed forms of the parts of the bias -------------------------------------------------


def _azimuth_from(rut: RutArray, points: np.ndarray, origin: np.ndarray) -> np.ndarray:
    """Azimuth (rad) of world ``points`` seen from world ``origin``, in the radar frame."""
    p = (np.asarray(points) - origin) @ rut.rotation
    return np.arctan2(p[..., 0], p[..., 1])


def _slope_shares(rut: RutArray, mask=None) -> tuple[float, float]:
    """Shares of the Tx and of the Rx positions in the beamformer's least-squares slope over the
    azimuth virtual array: ``sum_v w_v x_tx(v)`` and ``sum_v w_v x_rx(v)`` (they add up to 1).
    ``mask``: the elements of a 2-D beamformer (all); the slope in x is then the x coefficient
    of the least-squares plane over (x, z)."""
    m = rut.azimuth_mask if mask is None else np.asarray(mask, bool)
    xt = rut.tx_local[rut.virtual_tx[m], 0]
    xr = rut.rx_local[rut.virtual_rx[m], 0]
    xv = xt + xr
    if mask is None:
        w = (xv - xv.mean()) / np.sum((xv - xv.mean()) ** 2)
    else:
        zv = rut.tx_local[rut.virtual_tx[m], 2] + rut.rx_local[rut.virtual_rx[m], 2]
        w = np.linalg.pinv(np.stack([np.ones_like(xv), xv, zv], axis=1))[1]
    return float(np.sum(w * xt)), float(np.sum(w * xr))


def group_azimuth_rad(rut: RutArray, fe_rx: np.ndarray, fe_tx: np.ndarray,
                      mask=None) -> np.ndarray:
    """Far-field closed form of the detected azimuth with the RuT's Tx/Rx group parallax.

    Like ``apparent_azimuth_rad`` (the Tx see the front end's Rx antenna at theta_a, the Rx its
    Tx antenna at theta_b), but each angle is taken from the centroid of the RuT's azimuth Tx
    (resp. Rx) group instead of the virtual phase centre: each group gets a locally plane wave
    from its own direction. For the AWR1843BOOST the groups' centroids are -4.75 d and +4.75 d
    from the phase centre and carry 0.76 and 0.24 of the beamformer slope, which adds
    ~ 2.5 d cos^2(theta) / R to sin(alpha): as large as the Rx/Tx-separation term at R_c = 1 m
    and of the same order in 1/R. Shapes (..., F, 3) -> (..., F). ``mask``: the elements of
    a 2-D beamformer (``Steering.mask``), whose groups and slope are taken over them.
    """
    m = rut.azimuth_mask if mask is None else np.asarray(mask, bool)
    c_tx = rut.tx_world[rut.virtual_tx[m]].mean(axis=0)
    c_rx = rut.rx_world[rut.virtual_rx[m]].mean(axis=0)
    share_tx, share_rx = _slope_shares(rut, mask)
    s = (share_tx * np.sin(_azimuth_from(rut, fe_rx, c_tx))
         + share_rx * np.sin(_azimuth_from(rut, fe_tx, c_rx)))
    return np.arcsin(np.clip(s, -1.0, 1.0))


def beat_frequency_azimuth_rad(angle_rad, radar, tau_s) -> np.ndarray:
    """The azimuth the beamformer reads for a plane wave from ``angle_rad`` when the echo's
    total delay is ``tau_s``: the air-path phase acts at ``f_c + B/2 - S tau`` (the frequency
    the echo has in the middle of the ADC window, eq. 8), the steering vector at ``f_c + B/2``."""
    scale = 1.0 - radar.slope_hz_per_s * np.asarray(tau_s) / radar.f_center_hz
    return np.arcsin(np.clip(np.sin(angle_rad) * scale, -1.0, 1.0))


def _residual_deg(steering: Steering, lengths: np.ndarray) -> np.ndarray:
    """Phase (deg) of path lengths (F, V_s) of the beamformer's elements minus their best
    linear fit over the positions (azimuth: a line in x_v; D = 2: a plane in (x_v, z_v))."""
    pos = steering.positions_m
    if pos.shape[1] == 1:
        x = pos[:, 0]
        fit = np.polynomial.polynomial.polyfit(x, lengths.T, 1)  # (2, F)
        resid = lengths - np.polynomial.polynomial.polyval(x, fit)
    else:  # the same least squares with one slope per axis
        design = np.concatenate([np.ones((pos.shape[0], 1)), pos], axis=1)
        coef, *_ = np.linalg.lstsq(design, lengths.T, rcond=None)
        resid = lengths - (design @ coef).T
    return np.degrees(2 * np.pi * resid / steering.wavelength_m)


def phase_error_deg(setup: Setup, steering: Steering | None = None) -> dict[str, np.ndarray]:
    """Per front end, the exact two-way phase across the beamformer's virtual array (default
    the azimuth row; a 2-D ``steering``: all elements, fit over x and z) minus the best-fit
    plane wave: ``pp`` and ``rms`` (deg). ``curvature_pp``: the same for what is left after
    each RuT group's locally plane wave to the antenna it sees (pure phase-front curvature,
    what the Fraunhofer criterion is about)."""
    rut, fe = setup.rut, setup.fe
    steering = steering or Steering.build(rut, setup.scene.radar)
    m = steering.mask
    exact = two_way_lengths(rut, fe.rx, fe.tx)[:, m]  # (F, V_az)
    total = _residual_deg(steering, exact)
    # locally plane waves per group: |p - s| ~ |c - s| - (p - c) . u, u = (s - c)/|s - c|
    tx, rx = rut.tx_world[rut.virtual_tx[m]], rut.rx_world[rut.virtual_rx[m]]
    planar = np.zeros_like(exact)
    for pts, src in ((tx, fe.rx), (rx, fe.tx)):
        centre = pts.mean(axis=0)
        d = src - centre  # (F, 3)
        dist = np.linalg.norm(d, axis=-1)
        planar += dist[:, None] - ((pts - centre) @ (d / dist[:, None]).T).T
    curv = _residual_deg(steering, exact - planar)
    return {"pp": np.ptp(total, axis=1), "rms": np.sqrt(np.mean(total ** 2, axis=1)),
            "curvature_pp": np.ptp(curv, axis=1)}


# -- phasor-level detection ------------------------------------------------------------------


def single_front_end_angles_rad(setup: Setup, paths: Paths, range_m: float,
                                steering: Steering | None = None) -> np.ndarray:
    """Detected direction of each front end alone (unit amplitude, zero Doppler) at
    ``range_m``: phasor level through the exact paths, TDM compensation and the RuT's
    beamformer ``steering`` (default the azimuth row: (F,) azimuth; a 2-D one: (F, 2)
    (azimuth, elevation)), the :class:`~rtsgeom.synthesis.model.ChannelModel` of all front
    ends, each alone."""
    n = setup.fe.count
    model = ChannelModel.build(setup, paths, range(n), TargetConfig(float(range_m)),
                               steering=steering)
    return model.direction(np.eye(n))


def echo_delay_s(setup: Setup, range_m: float) -> np.ndarray:
    """Mean total delay (air + RTS) of each front end's echo over the virtual array."""
    air = two_way_lengths(setup.rut, setup.fe.rx, setup.fe.tx).mean(axis=1) / c
    return air + float(requested_delay(setup.scene, range_m))


# -- the synthesized direction -----------------------------------------------------------------


def synthesis_worst_errors_deg(setup: Setup, paths: Paths, pair: tuple[int, int],
                               range_m: float, single_rad: np.ndarray, points: int = 11
                               ) -> dict:
    """Worst |detected - set| (deg) of a pair's synthesized target, ``array-factor`` vs
    ``exact`` amplitudes, phasor level, phase-coherent channels.

    The set-points span the intersection of the pair's measured span (``single_rad``: each
    front end alone as detected) and its geometric span, ends excluded (as
    the linearity study). The design (ratio) is made on the nominal setup, the detection on the
    setup as built; each channel pair is made coherent at the set angle.
    """
    i, j = pair
    target = TargetConfig(float(range_m))
    nom, nom_paths = nominal_model(setup, paths)
    design = ChannelModel.build(nom, nom_paths, pair, target)
    actual = design if nom is setup else ChannelModel.build(setup, paths, pair, target)
    geo = nom.fe_azimuth_rad()[[i, j]]
    meas = np.sort(single_rad[[i, j]])
    lo, hi = max(meas[0], np.min(geo)), min(meas[1], np.max(geo))
    out = {"pair": [i, j], "span_deg": [float(np.degrees(lo)), float(np.degrees(hi))],
           "points": points}
    if not hi > lo:
        out.update({"array_factor_max_abs_error_deg": None, "exact_max_abs_error_deg": None,
                    "note": "the measured and geometric spans do not overlap"})
        return out
    sets = lo + np.arange(1, points + 1) / (points + 1) * (hi - lo)
    err = {"array-factor": [], "exact": []}
    probes = probe_angles(*single_rad[[i, j]])
    design_phase, phase = float(design.pair_phase(probes)), float(actual.pair_phase(probes))
    for a in sets:
        rho_af = design.pair_ratio(a, (0.0, design_phase), "array-factor")
        try:
            rho_ex = design.pair_ratio(a, (0.0, design_phase))
        except AngleUnreachable:
            rho_ex = np.nan
        for mode, rho in (("array-factor", rho_af), ("exact", rho_ex)):
            det = (float(actual.direction(actual.pair_weights(rho, (0.0, phase))))
                   if np.isfinite(rho) else np.nan)
            err[mode].append(np.degrees(det - a))
    worst = {m: float(np.nanmax(np.abs(e))) if np.any(np.isfinite(e)) else None
             for m, e in err.items()}
    out["array_factor_max_abs_error_deg"] = worst["array-factor"]
    out["exact_max_abs_error_deg"] = worst["exact"]
    return out


def cells_of(u_fe: np.ndarray) -> list[tuple[int, ...]]:
    """The cells of (c) in 2-D: all front ends when there are 3 or 4 (one cell, as
    ``linearity --grid``), else the Delaunay triangles of their direction cosines."""
    if u_fe.shape[0] <= 4:
        return [tuple(range(u_fe.shape[0]))]
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


def synthesis_errors(setup: Setup, paths: Paths, steering: Steering, range_m: float,
                     single_rad: np.ndarray, points: int = 11) -> list[dict]:
    """The synthesized direction's worst errors at one radius: every adjacent pair of an arc
    (D = 1, :func:`synthesis_worst_errors_deg`) or every cell of front ends (D = 2,
    :func:`cell_synthesis_errors_deg`)."""
    if steering.dims == 2:
        return [cell_synthesis_errors_deg(setup, paths, cell, range_m, points)
                for cell in cells_of(setup.fe_direction_cosines())]
    return [synthesis_worst_errors_deg(setup, paths, (k, k + 1), range_m, single_rad, points)
            for k in range(setup.fe.count - 1)]
