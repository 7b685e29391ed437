"""Front-end positions on an arc: the one formula, shared by the scene's rules and ``geometry``.

Each front end is a module tangent to the arc carrying an Rx antenna (towards larger azimuth)
and a Tx antenna (towards smaller azimuth). Mounting errors move the module radially,
tangentially and in height. Everything broadcasts over leading axes so Monte-Carlo draws of
mounting errors are one call. This module imports only numpy so that both ``scene`` (which
cannot import ``geometry``) and ``geometry.arc`` use it.
"""

from __future__ import annotations

import numpy as np

__all__ = ["radial_tangent", "antenna_positions"]


def radial_tangent(angle_rad: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit radial (outward) and tangential (towards larger azimuth) vectors, shape (..., 3)."""
    a = np.asarray(angle_rad, dtype=float)
    s, co, z = np.sin(a), np.cos(a), np.zeros_like(a)
    return np.stack([s, co, z], -1), np.stack([co, -s, z], -1)


def antenna_positions(centre: np.ndarray, radius_m: float, angle_rad: np.ndarray,
                      separation_m: np.ndarray, offsets_m: np.ndarray | None = None
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rx, Tx and module-centre positions of front ends on an arc.

    Parameters
    ----------
    centre : (3,) arc centre (world).
    radius_m : arc radius R_c.
    angle_rad : (F,) nominal azimuths theta_q.
    separation_m : (F,) Rx/Tx antenna separation along the tangent.
    offsets_m : (..., F, 3) mounting errors (radial, tangential, height); broadcast over draws.

    Returns
    -------
    rx, tx, module_centre : (..., F, 3)
    """
    r_hat, t_hat = radial_tangent(angle_rad)
    z_hat = np.array([0.0, 0.0, 1.0])
    nominal = np.asarray(centre, float) + radius_m * r_hat
    if offsets_m is None:
        offsets_m = np.zeros_like(nominal)
    off = np.asarray(offsets_m, float)
    mod = (nominal + off[..., 0:1] * r_hat + off[..., 1:2] * t_hat + off[..., 2:3] * z_hat)
    half = 0.5 * np.asarray(separation_m, float)[..., None] * t_hat
    return mod + half, mod - half, mod
