"""Front-end positions on an arc or a sphere: the one formula, shared by the scene's rules and
``geometry``.

A front end sits at azimuth theta and elevation epsilon (default 0: on the arc) on the sphere of
radius R_c about the arc centre, radial unit vector ``(sin th cos el, cos th cos el, sin el)``
(its x and z components are the direction cosines ``u`` of ``radar.steering``). Elevation 0 (or
None) takes the arc's own arithmetic (no elevation terms), so positions on the arc are exact.

Each front end is a module tangent to the arc carrying an Rx and a Tx antenna at signed offsets
(by default the Rx towards larger azimuth, the Tx towards smaller). Mounting errors move the
module radially, tangentially and in height and turn it (yaw, pitch). Everything broadcasts over leading axes so Monte-Carlo draws of
mounting errors are one call. This module imports only numpy so that both ``scene`` (which
cannot import ``geometry``) and ``geometry.arc`` use it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["radial_tangent", "sphere_frame", "layout_offsets", "module_axes",
           "ModuleLayout", "antenna_positions"]


def radial_tangent(angle_rad: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit radial (outward) and tangential (towards larger azimuth) vectors, shape (..., 3)."""
    a = np.asarray(angle_rad, dtype=float)
    s, co, z = np.sin(a), np.cos(a), np.zeros_like(a)
    return np.stack([s, co, z], -1), np.stack([co, -s, z], -1)


def sphere_frame(angle_rad, elevation_rad=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Radial (outward), tangential (towards larger azimuth, horizontal) and up (towards larger
    elevation) unit vectors at (azimuth, elevation) on the sphere, (..., 3) each. Without an
    elevation (None): :func:`radial_tangent` and the world vertical, the same bits."""
    r_hat, t_hat = radial_tangent(angle_rad)
    if elevation_rad is None:
        return r_hat, t_hat, np.broadcast_to(np.array([0.0, 0.0, 1.0]), r_hat.shape)
    e = np.asarray(elevation_rad, float)[..., None]
    z_hat = np.array([0.0, 0.0, 1.0])
    horiz = r_hat  # (sin th, cos th, 0)
    r = np.cos(e) * horiz + np.sin(e) * z_hat
    up = np.cos(e) * z_hat - np.sin(e) * horiz
    r, t_hat, up = np.broadcast_arrays(r, t_hat, up)
    return r, t_hat, up


def layout_offsets(separation_m) -> tuple[np.ndarray, np.ndarray]:
    """The shorthand ``separation_m`` s (..., F) as signed offsets: rx (s/2, 0), tx (-s/2, 0)."""
    half = 0.5 * np.asarray(separation_m, float)
    z = np.zeros_like(half)
    return np.stack([half, z], -1), np.stack([-half, z], -1)


def module_axes(angle_rad, yaw_rad=None, pitch_rad=None, elevation_rad=None
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit axes of each front-end module after its mounting rotations, (..., F, 3) each.

    ``tangent`` (towards larger azimuth when not yawed), ``up`` and ``boresight`` (towards the arc
    centre when not rotated). Pitch turns (boresight, up) about the tangent, then yaw turns all
    three about the world vertical. ``yaw_rad``, ``pitch_rad``: (..., F), broadcast. A module at
    ``elevation_rad`` (..., F) looks down/up at the centre: its ``up`` is the sphere's
    elevation direction (:func:`sphere_frame`).
    """
    if elevation_rad is None:
        r_hat, t_hat = radial_tangent(angle_rad)
        z_hat = np.array([0.0, 0.0, 1.0])
    else:
        r_hat, t_hat, z_hat = sphere_frame(angle_rad, elevation_rad)
    b, up, t = -r_hat, z_hat, t_hat
    if pitch_rad is not None:
        p = np.asarray(pitch_rad, float)[..., None]
        b, up = np.cos(p) * b + np.sin(p) * z_hat, np.cos(p) * z_hat + np.sin(p) * r_hat
    t, up, b = np.broadcast_arrays(t, up, b)
    if yaw_rad is not None:
        y = np.asarray(yaw_rad, float)
        cy, sy = np.cos(y), np.sin(y)

        def turn(v):
            x = cy * v[..., 0] + sy * v[..., 1]
            return np.stack([x, -sy * v[..., 0] + cy * v[..., 1],
                             np.broadcast_to(v[..., 2], x.shape)], -1)

        t, up, b = turn(t), turn(up), turn(b)
    return t, up, b


@dataclass(frozen=True)
class ModuleLayout:
    """Where the antennas sit on each front-end module and how it is turned on its mount:
    ``rx_offset_m``, ``tx_offset_m`` (..., F, 2) signed antenna offsets ``(t, h)`` in the
    module frame (tangential, positive towards larger azimuth; height), ``yaw_rad``,
    ``pitch_rad`` (..., F) mounting rotations about the module's centre. None: the
    symmetric layout of the separation, no rotation."""

    rx_offset_m: np.ndarray | None = None
    tx_offset_m: np.ndarray | None = None
    yaw_rad: np.ndarray | None = None
    pitch_rad: np.ndarray | None = None


def antenna_positions(centre: np.ndarray, radius_m: float, angle_rad: np.ndarray,
                      separation_m: np.ndarray | None = None,
                      offsets_m: np.ndarray | None = None, *,
                      layout: ModuleLayout = ModuleLayout(),
                      elevation_rad: np.ndarray | None = None,
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rx, Tx and module-centre positions of front ends on an arc (or a sphere).

    Parameters
    ----------
    centre : (3,) arc centre (world).
    radius_m : arc radius R_c.
    angle_rad : (F,) nominal azimuths theta_q.
    separation_m : (F,) shorthand for ``rx_offset_m = (s/2, 0)``, ``tx_offset_m = (-s/2, 0)``;
        ignored where the offsets are given.
    offsets_m : (..., F, 3) mounting errors (radial, tangential, height); broadcast over draws.
    layout : ModuleLayout
        The antennas' offsets on the module and its mounting rotations.
    elevation_rad : (F,) nominal elevations epsilon_q on the sphere (None or all 0: the arc,
        the arc's arithmetic). The height offset and the antennas' ``h`` then run along the
        sphere's elevation direction, the radial offset along the sphere's radius.

    Returns
    -------
    rx, tx, module_centre : (..., F, 3)
    """
    rx_offset_m, tx_offset_m = layout.rx_offset_m, layout.tx_offset_m
    yaw_rad, pitch_rad = layout.yaw_rad, layout.pitch_rad
    if elevation_rad is not None and not np.any(np.asarray(elevation_rad, float)):
        elevation_rad = None  # all on the arc: the arc's arithmetic, no elevation terms
    if elevation_rad is None:
        r_hat, t_hat = radial_tangent(angle_rad)
        z_hat = np.array([0.0, 0.0, 1.0])
    else:
        r_hat, t_hat, z_hat = sphere_frame(angle_rad, elevation_rad)
    nominal = np.asarray(centre, float) + radius_m * r_hat
    if offsets_m is None:
        offsets_m = np.zeros_like(nominal)
    off = np.asarray(offsets_m, float)
    mod = (nominal + off[..., 0:1] * r_hat + off[..., 1:2] * t_hat + off[..., 2:3] * z_hat)
    simple = (rx_offset_m is None and tx_offset_m is None and yaw_rad is None
              and pitch_rad is None)
    if simple:  # the symmetric layout: each antenna half the separation from the centre
        half = 0.5 * np.asarray(separation_m, float)[..., None] * t_hat
        return mod + half, mod - half, mod
    if rx_offset_m is None or tx_offset_m is None:
        if separation_m is None:
            raise ValueError("antenna_positions: give separation_m or both rx_offset_m and "
                             "tx_offset_m")
        rx_s, tx_s = layout_offsets(separation_m)
        rx_offset_m = rx_s if rx_offset_m is None else rx_offset_m
        tx_offset_m = tx_s if tx_offset_m is None else tx_offset_m
    t, up, _ = module_axes(angle_rad, yaw_rad, pitch_rad, elevation_rad)
    ro, to = np.asarray(rx_offset_m, float), np.asarray(tx_offset_m, float)
    rx = mod + ro[..., 0:1] * t + ro[..., 1:2] * up
    tx = mod + to[..., 0:1] * t + to[..., 1:2] * up
    return rx, tx, mod
