"""Several angles per range-Doppler detection: every local peak of the cell's angle spectrum.

A radar's firmware reports more than one direction for a range-Doppler cell when its angle
spectrum has a second peak within a set fraction of the strongest: TI's mmWave SDK calls it
``multiObjBeamForming`` and enables it with a threshold of 0.5 of the peak's amplitude in its
example profiles. Without it no radar modelled here could resolve two targets in one cell, real
or emulated. The scene's ``[radar] angle_peaks_max`` (peaks per cell, 1 = the global peak only)
and ``angle_peak_threshold`` (a further peak's *amplitude* relative to the strongest's) set it.

The strongest peak is :meth:`Steering.search`'s, bit for bit, so a cell with one peak reports
exactly what it reported before. The further peaks are the coarse search grid's other local
maxima (the grid of :meth:`Steering.search`: 0.25 deg in azimuth, lambda / (8 d_A) per axis in
2-D), refined like the strongest: zooms with a parabola in 1-D, Newton steps on log P without
the global check in 2-D (which would pull every start onto the strongest peak).
"""

from __future__ import annotations

import functools

import numpy as np
from scipy import ndimage

from .newton import newton, parabolic
from .steering import Steering

__all__ = ["angle_peaks"]

#: refined peaks closer than this (direction cosine) are one peak
_SAME_PEAK_U = 1e-3


def angle_peaks(steering: Steering, snapshots: np.ndarray, max_peaks: int,
                threshold: float) -> tuple[np.ndarray, np.ndarray]:
    """Up to ``max_peaks`` local peaks of the estimator's spectrum per snapshot, strongest first.

    Parameters
    ----------
    steering : Steering
        The RuT's beamformer and direction estimator.
    snapshots : ndarray, shape (n, V)
        One snapshot per detection over all virtual channels (TDM-compensated).
    max_peaks : int
        Peaks per snapshot at most (1: :meth:`Steering.search` alone).
    threshold : float
        A further peak is reported where its amplitude (the square root of the spectrum) is at
        least ``threshold`` times the strongest peak's.

    Returns
    -------
    angles : ndarray, shape (n, max_peaks) or (n, max_peaks, 2)
        Azimuth (rad), or (azimuth, elevation) (rad) for a 2-D beamformer; NaN where a snapshot
        has fewer peaks. Column 0 is :meth:`Steering.search`.
    level_db : ndarray, shape (n, max_peaks)
        Each peak's spectrum relative to the snapshot's strongest (0 dB for column 0), NaN
        where absent.
    """
    snaps = np.asarray(snapshots)
    n = snaps.shape[0]
    first = steering.search(snaps) if n else np.zeros((0, 2) if steering.dims == 2 else 0)
    shape = (n, max_peaks) + ((2,) if steering.dims == 2 else ())
    angles = np.full(shape, np.nan)
    level = np.full((n, max_peaks), np.nan)
    angles[:, 0], level[:, 0] = first, 0.0
    if max_peaks <= 1 or n == 0:
        return angles, level
    if steering.dims == 1:
        u1 = np.sin(first)[:, None]
        p1 = _value(steering, snaps, u1)
        cand, val = _candidates_1d(steering, snaps)
        if not steering.smoothing:
            cand = np.where(_may_pass(steering, snaps, val, threshold ** 2 * p1), cand, np.nan)
        u_sec, p_sec = _refine_1d(steering, snaps, cand)
    else:
        u1 = steering.directions(first)
        cand, val = _candidates_2d(steering, snaps)
        u_sec, p_sec = _refine_2d(steering, snaps, cand)
        p1 = _value(steering, snaps, u1)
    keep = (np.isfinite(p_sec) & (p_sec >= threshold ** 2 * p1[:, None])
            & (np.linalg.norm(u_sec - u1[:, None, :], axis=-1) > _SAME_PEAK_U))
    for i in range(n):  # a few candidates per detection: distinct peaks, strongest first
        got = []
        for j in np.argsort(-np.where(keep[i], p_sec[i], -np.inf)):
            if not keep[i, j] or len(got) == max_peaks - 1:
                break
            if all(np.linalg.norm(u_sec[i, j] - u_sec[i, g]) > _SAME_PEAK_U for g in got):
                got.append(j)
        for r, j in enumerate(got, start=1):
            angles[i, r] = (np.arcsin(np.clip(u_sec[i, j, 0], -1, 1)) if steering.dims == 1
                            else steering.angles(u_sec[i, j]))
            level[i, r] = 10 * np.log10(p_sec[i, j] / p1[i])
    return angles, level


#: how far (rad) :func:`_refine_1d`'s zooms may move from a grid candidate: 0.3 + 0.005 deg,
#: then 0.006 + 1e-4 deg (with margin)
_REFINE_REACH_RAD = np.radians(0.32)


def _may_pass(steering: Steering, snaps: np.ndarray, val: np.ndarray, floor: np.ndarray
              ) -> np.ndarray:
    """Which grid candidates (n, G) of Bartlett's spectrum ``val`` may refine to a peak of at
    least ``floor`` (n,): a bound, so the others are skipped without changing a result. The
    beam b(u) = sum_v w_v x_v e^{j k p_v u} moves at most sum_v |k p_v| |w_v x_v| per unit
    of u, and the zooms move at most :data:`_REFINE_REACH_RAD` in angle (less in u), so
    |b| there is at most sqrt(val) plus that times the reach."""
    w = np.abs(steering.weighted(snaps))  # (n, V_s)
    slope = w @ np.abs(steering.wavevector[:, 0])  # (n,)
    bound = np.sqrt(np.where(np.isfinite(val), val, 0.0)) + (slope * _REFINE_REACH_RAD)[:, None]
    return bound ** 2 * (1 + 1e-6) >= floor[:, None]


def _value(steering: Steering, snaps: np.ndarray, u: np.ndarray) -> np.ndarray:
    """The estimator's spectrum of each snapshot (n, V) at its own direction u (n, D): (n,)."""
    if steering.estimator == "bartlett" or not steering.smoothing:
        y = np.einsum("nv,nv->n", steering.weighted(snaps), steering.steer(u))
        return np.abs(y) ** 2
    return np.array([steering.spectrum(snaps[i], u[i][None])[0] for i in range(len(u))])


def _local_maxima(spec: np.ndarray, footprint_dims: int) -> np.ndarray:
    """Boolean mask of strict-or-plateau local maxima of ``spec`` along its last
    ``footprint_dims`` axes (a cell is one when no neighbour is larger)."""
    size = (1,) + (3,) * footprint_dims
    return (spec == ndimage.maximum_filter(spec, size=size, mode="constant",
                                           cval=-np.inf)) & np.isfinite(spec)


def _candidates_1d(steering: Steering, snaps: np.ndarray):
    grid = steering._search_grid[0]
    if steering.smoothing:
        spec = steering.spectrum(snaps, steering.directions(grid))
    else:
        spec = steering._power(steering.weighted(snaps), steering._search_grid[1])
    spec = spec.copy()
    spec[:, [0, -1]] = -np.inf  # endfire is no peak
    peak = _local_maxima(spec, 1)
    return np.where(peak, grid, np.nan), np.where(peak, spec, np.nan)


def _refine_1d(steering: Steering, snaps: np.ndarray, cand: np.ndarray):
    """Zoom (0.005, then 1e-4 deg) and a parabola around each candidate (n, G): the refined
    u (n, G, 1) and spectrum (n, G), NaN where no candidate."""
    rows, cols = np.nonzero(np.isfinite(cand))
    u = np.full(cand.shape + (1,), np.nan)
    val = np.full(cand.shape, np.nan)
    best = cand[rows, cols]
    pw = np.zeros((best.size, 1))
    for half, step in ((0.3, 0.005), (0.006, 1e-4)):
        offs = np.radians(np.arange(-half, half + step / 2, step))
        c = np.clip(best[:, None] + offs[None, :], -np.pi / 2, np.pi / 2)
        pw = _spectrum_rows(steering, snaps[rows], c)
        i = np.clip(np.argmax(pw, axis=1), 1, offs.size - 2)
        r = np.arange(pw.shape[0])
        frac = parabolic(pw[r, i - 1], pw[r, i], pw[r, i + 1])
        best = c[r, i] + np.clip(frac, -1, 1) * np.radians(step)
    u[rows, cols, 0] = np.sin(best)
    val[rows, cols] = pw.max(axis=1) if best.size else val[rows, cols]
    return u, val


def _spectrum_rows(steering: Steering, snaps: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """The spectrum of each snapshot (m, V) at its own azimuths (m, O): (m, O)."""
    if not steering.smoothing:
        st = steering.steer(steering.directions(angles))  # (m, O, V_s)
        return np.abs(np.einsum("mv,mov->mo", steering.weighted(snaps), st)) ** 2
    return np.stack([steering.spectrum(snaps[i], steering.directions(angles[i]))
                     for i in range(snaps.shape[0])]) if snaps.shape[0] else angles * 0


def _candidates_2d(steering: Steering, snaps: np.ndarray):
    """The 2-D grid's local maxima (on the meshgrid of :meth:`Steering.grid`, the invisible
    region excluded): candidate u (n, G, 2) (NaN elsewhere) and their power (n, G)."""
    mesh = steering.grid_mesh()  # (A0, A1, 2)
    visible = np.sum(mesh ** 2, axis=-1) <= 1.0
    grid = mesh[visible]
    y = steering.weighted(snaps) @ steering.steer(grid).T
    img = np.full((snaps.shape[0],) + visible.shape, -np.inf)
    img[:, visible] = y.real ** 2 + y.imag ** 2
    peak = _local_maxima(img, 2)[:, visible]  # (n, G)
    cand = np.where(peak[..., None], grid[None], np.nan)
    return cand, np.where(peak, img[:, visible], np.nan)


def _refine_2d(steering: Steering, snaps: np.ndarray, cand: np.ndarray):
    """Newton steps on log P from each 2-D candidate, no global check: u (n, G, 2), P (n, G)."""
    rows, cols = np.nonzero(np.isfinite(cand[..., 0]))
    u = np.full(cand.shape, np.nan)
    val = np.full(cand.shape[:2], np.nan)
    if rows.size:
        x = steering.weighted(snaps[rows])
        xr, xi = np.ascontiguousarray(x.real.T), np.ascontiguousarray(x.imag.T)
        u_r, conv, _ = newton(steering.wavevector, xr, xi, cand[rows, cols], None, 8)
        u_r = np.where(conv[:, None], u_r, cand[rows, cols])
        u[rows, cols] = u_r
        val[rows, cols] = np.abs(np.einsum("mv,mv->m", x, steering.steer(u_r))) ** 2
    return u, val


def two_target_resolution(steering: Steering) -> np.ndarray:
    """The beamformer's two-target resolution per direction-cosine axis (D,): the smallest
    separation ``s`` in u from which two equal, in-phase sources at ``-s/2`` and ``+s/2``
    (about boresight, along that axis) give two peaks of the spectrum, for every larger
    separation up to 1.

    For a uniform line of N elements at lambda/2, unweighted, this is about 1.35 lambda / d_A
    (N = 8: 0.337, two sources 19.4 deg apart); a taper widens it. Evaluated numerically on the
    array's own positions and taper (u steps of 1e-3), so sparse and custom arrays are right
    too. The association of detections with targets uses it as the angular resolution cell.
    """
    pos = np.ascontiguousarray(steering.positions_m, float)
    taper = np.ascontiguousarray(steering.taper, float)
    return np.array(_resolution(pos.tobytes(), pos.shape, taper.tobytes(),
                                float(steering.wavelength_m)))


@functools.lru_cache(maxsize=32)  # one array per scene: a frame's association reuses it
def _resolution(pos: bytes, shape: tuple, taper: bytes, wavelength_m: float) -> tuple:
    p = np.frombuffer(pos).reshape(shape)
    w = np.frombuffer(taper)
    return tuple(_resolution_axis(2 * np.pi / wavelength_m * p[:, a], w)
                 for a in range(shape[1]))


def _resolution_axis(k: np.ndarray, w: np.ndarray) -> float:
    """:func:`two_target_resolution` along one axis: wavenumbers times positions ``k`` (V_s,)
    and the taper ``w`` (V_s,)."""
    seps = np.arange(0.002, 1.0 + 1e-9, 0.001)  # (S,)
    u = np.linspace(-1.0, 1.0, 2001)  # (U,) 1e-3 steps, u = 0 on the grid
    # snapshot of two in-phase sources at +-s/2: x_v = 2 cos(k_v s / 2); beam at u:
    # sum_v w_v x_v e^{j k_v u}
    x = 2 * np.cos(0.5 * k[None, :] * seps[:, None]) * w  # (S, V_s)
    p = np.abs(x @ np.exp(1j * k[:, None] * u[None, :])) ** 2  # (S, U)
    mid = u.size // 2
    # resolved: the strongest peaks lie off the midpoint, one on either side (by symmetry)
    unresolved = np.flatnonzero(p[:, mid] >= p.max(axis=1) * (1 - 1e-9))
    if unresolved.size == 0:
        return float(seps[0])
    if unresolved[-1] == seps.size - 1:
        return float("inf")
    return float(seps[unresolved[-1] + 1])
