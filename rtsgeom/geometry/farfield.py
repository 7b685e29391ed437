"""Far-field figures of merit of the RuT array and how far the setup is from them.

* aperture ``d_A`` of the azimuth virtual array: the span of its distinct positions plus one
  cell ``d`` (``N_A d`` for a filled ULA: 8 x lambda/2 = 4 lambda for the AWR1843; 86 x lambda/2
  for the AWR2243 cascade, whose 144 azimuth virtual elements overlap on 86 positions),
* angular resolution ``1.22 lambda / d_A`` (paper eq. 24; 17.5 deg for the AWR1843), which for a
  sparse or non-uniform array is the main-lobe width set by its aperture (its side lobes are
  higher than a ULA's: see :func:`array_factor`),
* grating lobes: the array factor of positions on a grid of step ``g`` repeats every
  ``lambda / g`` in ``sin(alpha)``; ``g`` is the period of the virtual array (the greatest common
  divisor of its co-array, the set of position differences), at most its smallest spacing.
  A lambda/2 grid has none in the visible region,
* Fraunhofer distance ``2 d_A^2 / lambda``,
* per front end, the phase error across the virtual array: the two-way exact path of each
  azimuth virtual element minus its best linear fit over the element position (what
  beamforming cannot absorb as a steering angle), peak to peak, in radians. At R_c = 1 m it is
  almost all the *broken virtual array* (the front end's Rx/Tx split and the parallax of the
  RuT's Tx and Rx groups; 22 deg p-p), not phase-front curvature (0.35 deg p-p); see
  ``analysis.nearfield``.
"""

from __future__ import annotations

import numpy as np

from .arrays import RutArray
from .setup import Setup

__all__ = ["aperture_m", "angular_resolution_rad", "fraunhofer_distance_m", "apparent_azimuth_rad",
           "array_factor", "coarray_period_m", "curvature_phase_error_rad",
           "grating_lobe_directions_rad", "smallest_spacing_m", "two_way_lengths",
           "unambiguous_half_width_rad"]


def aperture_m(rut: RutArray) -> float:
    """Azimuth virtual aperture d_A (see :attr:`RutArray.aperture_m`)."""
    return rut.aperture_m


def smallest_spacing_m(rut: RutArray) -> float:
    """Smallest gap between two distinct azimuth virtual positions (inf for a single one)."""
    x = rut.azimuth_positions_m
    return float(np.diff(x).min()) if x.size > 1 else float("inf")


def coarray_period_m(rut: RutArray, max_divisor: int = 64, tol_m: float = 1e-9) -> float | None:
    """Period ``g`` of the azimuth virtual array: the largest step such that every distinct
    position lies on the grid ``x_0 + k g`` (the greatest common divisor of the co-array).

    Searched as ``smallest spacing / n`` for n = 1 .. ``max_divisor`` with tolerance ``tol_m``;
    ``None`` when no such grid exists (incommensurate positions: no exact grating lobe) or the
    array has a single position.
    """
    x = rut.azimuth_positions_m
    if x.size < 2:
        return None
    rel = x - x[0]
    dmin = float(np.diff(x).min())
    for n in range(1, max_divisor + 1):
        g = dmin / n
        k = rel / g
        if np.all(np.abs(k - np.round(k)) * g < tol_m):
            return g
    return None


def grating_lobe_directions_rad(rut: RutArray, steer_rad: float = 0.0) -> np.ndarray:
    """Directions (rad, ascending) of the grating lobes in the visible region when the array
    is steered to ``steer_rad``: ``sin(alpha) = sin(steer) + m lambda / g``, m != 0, |.| <= 1,
    ``g`` = :func:`coarray_period_m`. There the array factor equals its main-lobe peak, so a
    target there cannot be told from one at ``steer_rad``. Empty when there are none."""
    g = coarray_period_m(rut)
    if g is None:
        return np.empty(0)
    u0 = np.sin(steer_rad)
    step = rut.wavelength_m / g
    m = np.arange(-int(np.ceil(2 / step)) - 1, int(np.ceil(2 / step)) + 2)
    u = u0 + m[m != 0] * step
    u = u[np.abs(u) <= 1.0 + 1e-9]  # a lobe exactly at endfire (g = lambda) counts
    return np.sort(np.arcsin(np.clip(u, -1.0, 1.0)))


def unambiguous_half_width_rad(rut: RutArray) -> float:
    """Half-width of the sector ``|sin(alpha)| < lambda / (2 g)`` in which no two directions
    share an array response (pi/2 for g <= lambda/2, or for an aperiodic array)."""
    g = coarray_period_m(rut)
    if g is None:
        return float(np.pi / 2)
    return float(np.arcsin(min(1.0, rut.wavelength_m / (2.0 * g))))


def array_factor(rut: RutArray, sin_alpha, steer_sin: float = 0.0) -> np.ndarray:
    """Normalised far-field array factor ``|sum_v exp(j k x_v (u - u_0))| / V_az`` of the
    azimuth virtual array (every element, duplicates included, uniform weights), at
    ``u = sin_alpha`` (any shape)."""
    x = rut.virtual_local[rut.azimuth_mask, 0]
    k = 2 * np.pi / rut.wavelength_m
    u = np.asarray(sin_alpha, float)[..., None] - steer_sin
    return np.abs(np.exp(1j * k * u * x).sum(-1)) / x.size


def angular_resolution_rad(rut: RutArray) -> float:
    """Paper eq. (24): Delta alpha = 1.22 lambda / d_A."""
    return 1.22 * rut.wavelength_m / aperture_m(rut)


def fraunhofer_distance_m(rut: RutArray) -> float:
    return 2.0 * aperture_m(rut) ** 2 / rut.wavelength_m


def two_way_lengths(rut: RutArray, fe_rx: np.ndarray, fe_tx: np.ndarray) -> np.ndarray:
    """Exact two-way length RuT Tx -> FE Rx + FE Tx -> RuT Rx per virtual element.

    ``fe_rx``, ``fe_tx``: (..., F, 3) -> (..., F, V).
    """
    tx = rut.tx_world[rut.virtual_tx]  # (V, 3)
    rx = rut.rx_world[rut.virtual_rx]
    d_tx = np.linalg.norm(np.asarray(fe_rx)[..., :, None, :] - tx, axis=-1)
    d_rx = np.linalg.norm(np.asarray(fe_tx)[..., :, None, :] - rx, axis=-1)
    return d_tx + d_rx


def curvature_phase_error_rad(setup: Setup) -> np.ndarray:
    """Peak-to-peak phase residual (rad) across the azimuth virtual array, per front end."""
    rut = setup.rut
    m = rut.azimuth_mask
    x = rut.virtual_local[m, 0]
    lengths = two_way_lengths(rut, setup.fe.rx, setup.fe.tx)[:, m]  # (F, V_az)
    design = np.stack([np.ones_like(x), x], axis=1)
    coef, *_ = np.linalg.lstsq(design, lengths.T, rcond=None)
    resid = lengths - (design @ coef).T
    phase = 2.0 * np.pi * resid / rut.wavelength_m
    return np.ptp(phase, axis=1)


def apparent_azimuth_rad(rut: RutArray, fe_rx: np.ndarray, fe_tx: np.ndarray) -> np.ndarray:
    """Far-field closed form of the azimuth a single front end is detected at.

    The RuT's Tx elements see the front end's *Rx* antenna (azimuth theta_a) and its Rx
    elements see the *Tx* antenna (theta_b), so the virtual element v = (m, k) gets the phase
    k (x_m sin theta_a + x_k sin theta_b) instead of k x_v sin theta. The beamformer peak is the
    least-squares slope over the azimuth virtual array:

        sin alpha = sum_v (x_v - mean x)(x_m sin theta_a + x_k sin theta_b) / sum_v (x_v - mean x)^2

    which is the module's angle only when the Rx/Tx separation is zero. Shapes: (..., F, 3) ->
    (..., F).
    """
    m = rut.azimuth_mask
    xt = rut.tx_local[rut.virtual_tx[m], 0]
    xr = rut.rx_local[rut.virtual_rx[m], 0]
    xv = xt + xr
    w = (xv - xv.mean()) / np.sum((xv - xv.mean()) ** 2)
    sa = np.sin(rut.azimuth_of(fe_rx))
    sb = np.sin(rut.azimuth_of(fe_tx))
    return np.arcsin(np.clip(np.sum(w * xt) * sa + np.sum(w * xr) * sb, -1.0, 1.0))
