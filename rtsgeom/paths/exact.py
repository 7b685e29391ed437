"""Exact line-of-sight path lengths between every RuT element and every front-end antenna.

No far-field approximation: each leg is the Euclidean distance between the two antenna phase
centres, ``tau = |p_a - p_b| / c0`` (the paper's tau_tx and tau_rx, eq. 8, per element; eq. 13 is
its far-field limit). Amplitudes are free-space ``lambda / (4 pi d)`` at the radar's centre
frequency with isotropic antennas.
"""

from __future__ import annotations

import numpy as np
from scipy.constants import c

from ..geometry import Setup
from .table import FE_TO_RX, TX_TO_FE, Paths

__all__ = ["distances", "exact_paths", "leg_delays"]


def distances(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Pairwise distances between points ``a`` (..., A, 3) and ``b`` (..., B, 3) -> (..., A, B)."""
    return np.linalg.norm(np.asarray(a)[..., :, None, :] - np.asarray(b)[..., None, :, :], axis=-1)


def leg_delays(rut_tx: np.ndarray, rut_rx: np.ndarray, fe_rx: np.ndarray, fe_tx: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray]:
    """Line-of-sight delays of both legs, broadcast over leading (draw) axes.

    Returns ``tau_tx`` (..., F, N_tx): RuT Tx -> FE Rx, and ``tau_rx`` (..., F, N_rx): FE Tx ->
    RuT Rx.
    """
    return distances(fe_rx, rut_tx) / c, distances(fe_tx, rut_rx) / c


def exact_paths(setup: Setup) -> Paths:
    """Line-of-sight :class:`Paths` of a setup: one row per (front end, direction, element)."""
    rut, fe = setup.rut, setup.fe
    tau_tx, tau_rx = leg_delays(rut.tx_world, rut.rx_world, fe.rx, fe.tx)
    lam = rut.wavelength_m
    n_f, n_t = tau_tx.shape
    n_r = tau_rx.shape[1]
    f_tx, t_idx = np.meshgrid(np.arange(n_f), np.arange(n_t), indexing="ij")
    f_rx, r_idx = np.meshgrid(np.arange(n_f), np.arange(n_r), indexing="ij")
    delay = np.concatenate([tau_tx.ravel(), tau_rx.ravel()])
    return Paths.build(
        front_end=np.concatenate([f_tx.ravel(), f_rx.ravel()]),
        direction=np.r_[np.full(tau_tx.size, TX_TO_FE), np.full(tau_rx.size, FE_TO_RX)],
        rut_tx=np.r_[t_idx.ravel(), np.full(tau_rx.size, -1)],
        rut_rx=np.r_[np.full(tau_tx.size, -1), r_idx.ravel()],
        delay_s=delay,
        gain=lam / (4.0 * np.pi * delay * c),
        method="exact",
    )
