"""Exact line-of-sight path lengths between every RuT element and every front-end antenna.

No far-field approximation: each leg is the Euclidean distance between the two antenna phase
centres, ``tau = |p_a - p_b| / c0`` (the paper's tau_tx and tau_rx, eq. 8, per element; eq. 13 is
its far-field limit). Amplitudes are free-space ``lambda / (4 pi d)`` at the radar's centre
frequency, times the field gains of both antennas of the leg (``geometry.patterns``), each
taken towards the other antenna in its own frame: the RuT's elements in the radar frame, a front
end's antennas in its module frame (boresight at the arc centre, mounting rotations applied).
With isotropic patterns (the default) nothing is multiplied, so the numbers are unchanged.
"""

from __future__ import annotations

import numpy as np
from scipy.constants import c

from ..geometry import Setup
from ..geometry.patterns import AntennaPatterns, Pattern
from .table import FE_TO_RX, TX_TO_FE, Paths
from ..geometry.patterns import scene_patterns

__all__ = ["distances", "exact_paths", "leg_delays", "leg_pattern_gains"]


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


def _fe_gain(pattern: Pattern | tuple[Pattern, ...], local: np.ndarray) -> np.ndarray:
    """Field gain of front-end antennas towards ``local`` (F, N, 3) directions (antenna frame)."""
    if isinstance(pattern, tuple):
        if len(pattern) != local.shape[0]:
            raise ValueError(f"patterns: {len(pattern)} front-end patterns for "
                             f"{local.shape[0]} front ends")
        return np.stack([p.field(local[q]) for q, p in enumerate(pattern)])
    return pattern.field(local)


def leg_pattern_gains(setup: Setup, patterns: AntennaPatterns) -> tuple[np.ndarray, np.ndarray]:
    """Product of both antennas' field gains per leg: ``g_tx`` (F, N_tx) for RuT Tx -> FE Rx and
    ``g_rx`` (F, N_rx) for FE Tx -> RuT Rx (each antenna towards the other, in its own frame)."""
    rut, fe = setup.rut, setup.fe
    frame = fe.antenna_frame()  # (F, 3, 3) antenna -> world, columns x, y, z

    def leg(rut_pts, fe_pts, rut_pat, fe_pat):
        d = np.asarray(fe_pts)[:, None, :] - rut_pts[None, :, :]  # (F, N, 3) RuT -> FE
        g_rut = rut_pat.field(d @ rut.rotation)  # world -> radar frame
        g_fe = _fe_gain(fe_pat, np.einsum("fnk,fkj->fnj", -d, frame))  # world -> FE frame
        return g_rut * g_fe

    return (leg(rut.tx_world, fe.rx, patterns.rut_tx, patterns.fe_rx),
            leg(rut.rx_world, fe.tx, patterns.rut_rx, patterns.fe_tx))


def exact_paths(setup: Setup, patterns: AntennaPatterns | None = None) -> Paths:
    """Line-of-sight :class:`Paths` of a setup: one row per (front end, direction, element).

    ``patterns``: antenna patterns of the RuT's elements and the front ends' antennas (default:
    the scene's ``[radar.pattern]`` / ``[rts.pattern]``, isotropic where unset, which is
    bit-identical to the pattern-free model). Every caller (the run, the calibration, the
    synthesis design, the tolerance model) takes its paths from here, so the patterns reach
    the amplitude calibration and the synthesis.

    Parameters
    ----------
    setup : Setup
    patterns : AntennaPatterns, optional
        The antennas' patterns (default: the scene's).

    Returns
    -------
    Paths
        One line-of-sight row per element pair.
    """
    if patterns is None:
        patterns = scene_patterns(setup.scene)
    rut, fe = setup.rut, setup.fe
    tau_tx, tau_rx = leg_delays(rut.tx_world, rut.rx_world, fe.rx, fe.tx)
    lam = rut.wavelength_m
    n_f, n_t = tau_tx.shape
    n_r = tau_rx.shape[1]
    f_tx, t_idx = np.meshgrid(np.arange(n_f), np.arange(n_t), indexing="ij")
    f_rx, r_idx = np.meshgrid(np.arange(n_f), np.arange(n_r), indexing="ij")
    delay = np.concatenate([tau_tx.ravel(), tau_rx.ravel()])
    gain = lam / (4.0 * np.pi * delay * c)
    if patterns is not None and not patterns.isotropic:
        g_tx, g_rx = leg_pattern_gains(setup, patterns)
        gain = gain * np.concatenate([g_tx.ravel(), g_rx.ravel()])
    return Paths.build(
        front_end=np.concatenate([f_tx.ravel(), f_rx.ravel()]),
        direction=np.r_[np.full(tau_tx.size, TX_TO_FE), np.full(tau_rx.size, FE_TO_RX)],
        rut_tx=np.r_[t_idx.ravel(), np.full(tau_rx.size, -1)],
        rut_rx=np.r_[np.full(tau_tx.size, -1), r_idx.ravel()],
        delay_s=delay,
        gain=gain,
        method="exact",
    )
