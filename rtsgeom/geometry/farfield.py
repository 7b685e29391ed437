"""Far-field figures of merit of the RuT array and how far the setup is from them.

* aperture ``d_A = N_A * d`` of the azimuth virtual array (8 x lambda/2 = 4 lambda),
* angular resolution ``1.22 lambda / d_A`` (paper eq. 24; 17.5 deg for the AWR1843),
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
           "curvature_phase_error_rad", "two_way_lengths"]


def aperture_m(rut: RutArray) -> float:
    return float(np.count_nonzero(rut.azimuth_mask) * rut.spacing_m)


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
