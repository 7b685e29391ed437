"""The RuT's direction estimators beside eq. (14)'s Bartlett beamformer: Capon (MVDR) and MUSIC,
with forward-backward spatial smoothing (``radar.angle_estimator``, ``radar.angle_subarray``).

Used only through :class:`~rtsgeom.radar.steering.Steering` (``spectrum``, ``search``,
``peak``), so the detections (``radar.processing``), the ``exact`` synthesis
(``synthesis.model.ChannelModel.solve``), the calibration sweep and the
analyses all see the estimator the scene names.

Physics
-------
All three are quadratic forms on a covariance estimate R of the element signals and the array
manifold a(u) = e^{-j k p . u} (what a plane wave from direction cosines u gives the elements):

* Bartlett: P_B(u) = a^H R a (eq. 14 with R = x x^H and the taper in x);
* Capon: P_C(u) = 1 / a^H (R + delta I)^{-1} a, diagonal loading
  delta = ``CAPON_LOADING`` tr(R) / L;
* MUSIC: P_M(u) = 1 / a^H E_n E_n^H a, E_n the eigenvectors of R outside the signal
  subspace (the eigenvalues within ``SIGNAL_EIGEN_DB`` of the largest: the source count a
  radar estimates from the eigenvalues, here noise-free-safe).

**One snapshot** (one detection's virtual-array vector x, no smoothing): R = x x^H is rank 1.
With |a|^2 = L for every u, Sherman-Morrison gives
a^H (x x^H + delta I)^{-1} a = (L - |a^H x|^2 / (delta + |x|^2)) / delta, and the noise
projector is I - x x^H / |x|^2, so a^H E_n E_n^H a = L - |a^H x|^2 / |x|^2: both are smallest
exactly where the Bartlett power |a^H x|^2 is largest. Capon and MUSIC then detect the same
angle as Bartlett (the taper included, since x is the tapered snapshot), and every synthesis
result of eq. 14 holds for them unchanged. ``Steering.search`` uses Bartlett's search there.

**Spatial smoothing** (``angle_subarray`` = L >= 2; what radars running Capon or MUSIC on one
snapshot do, since a coherent scene is rank 1): the azimuth row's N distinct positions (on a
uniform grid of pitch d; duplicate virtual elements averaged) give M = N - L + 1 subarrays of L
elements; R = (R_f + J conj(R_f) J) / 2, R_f = (1/M) sum_m x_m x_m^H (forward-backward
averaging). A plane wave is the same steering vector on every subarray, up to a phase, so
sources with different directions lose their coherence in R: the two RTS channels of a
synthesized target become two sources, and a super-resolution estimator may resolve the two
front ends instead of the one synthesized direction. The taper is not applied with smoothing
(a tapered subarray does not see a plane wave as a shifted copy; Capon and MUSIC need no
side-lobe taper). Only 1-D uniform rows: a row with gaps (a sparse or minimum-redundancy
array) or a 2-D array raises :class:`~rtsgeom.scene.scene.SceneError` naming
``radar.angle_subarray`` (no silent fallback).

Snapshot averaging over a target's neighbouring range or Doppler bins does not decorrelate the
RTS channels: all of them carry the same delay and Doppler, so every bin holds the same mixture
(up to a common factor) and R stays rank 1. Smoothing over the array is the decorrelating step.
"""

from __future__ import annotations

import numpy as np

__all__ = ["CAPON_LOADING", "SIGNAL_EIGEN_DB", "KERNELS", "smoothed_covariance", "rank_one_covariance",
           "kernel", "quadratic", "lag_sums", "uniform_cells"]

#: Capon's diagonal loading relative to the mean eigenvalue tr(R)/L (-30 dB: a noise-free
#: rank-deficient R stays invertible; much smaller than any source's share of the power).
CAPON_LOADING = 1e-3
#: MUSIC's signal subspace: eigenvalues within this many dB of the largest.
SIGNAL_EIGEN_DB = 30.0


def uniform_cells(x_m: np.ndarray, pitch_m: float) -> tuple[np.ndarray, int]:
    """The grid cell (0..N-1) of each azimuth element at positions ``x_m`` (V_s,) on a grid of
    pitch ``pitch_m``, and N. Raises ValueError when the distinct positions are not a filled
    uniform grid (gaps) -- the caller names the scene field."""
    cell = np.round((x_m - x_m.min()) / pitch_m).astype(int)
    if not np.allclose(cell * pitch_m, x_m - x_m.min(), rtol=0, atol=1e-6 * pitch_m):
        raise ValueError("the azimuth row's elements are not on a uniform grid")
    n = int(cell.max()) + 1
    if np.unique(cell).size != n:
        raise ValueError(f"the azimuth row has gaps ({np.unique(cell).size} of {n} grid "
                         "positions filled)")
    return cell, n


def cell_snapshots(snapshots, cell: np.ndarray, n: int) -> np.ndarray:
    """Per grid cell the mean of its elements (duplicate virtual elements): (..., V_s) ->
    (..., N)."""
    x = np.asarray(snapshots)
    onehot = np.zeros((cell.size, n))
    onehot[np.arange(cell.size), cell] = 1.0
    return (x @ onehot) / onehot.sum(0)


def smoothed_covariance(cells, length: int) -> np.ndarray:
    """Forward-backward spatially smoothed covariance (..., L, L) of snapshots on a filled
    uniform grid (..., N) with subarrays of ``length`` L elements (module doc)."""
    x = np.asarray(cells)
    sub = np.lib.stride_tricks.sliding_window_view(x, length, axis=-1)  # (..., M, L)
    r_f = np.einsum("...ml,...mk->...lk", sub, np.conj(sub)) / sub.shape[-2]
    r_b = np.conj(r_f[..., ::-1, ::-1])  # J conj(R_f) J
    return 0.5 * (r_f + r_b)


def rank_one_covariance(x) -> np.ndarray:
    """x x^H (..., V, V) of one snapshot per row (the covariance without smoothing)."""
    x = np.asarray(x)
    return x[..., :, None] * np.conj(x[..., None, :])


def _bartlett(r: np.ndarray) -> np.ndarray:
    """Bartlett's kernel: -R (its power a^H R a is largest at its peak)."""
    return -r


def _capon(r: np.ndarray) -> np.ndarray:
    """Capon's kernel (R + delta I)^{-1}, delta = ``CAPON_LOADING`` tr(R) / L."""
    n = r.shape[-1]
    tr = np.real(np.einsum("...ii->...", r))[..., None, None] / n
    return np.linalg.inv(r + CAPON_LOADING * tr * np.eye(n))


def _music(r: np.ndarray) -> np.ndarray:
    """MUSIC's kernel E_n E_n^H on the noise subspace (module doc)."""
    n = r.shape[-1]
    lam, vec = np.linalg.eigh(r)  # ascending
    signal = lam > lam[..., -1:] * 10 ** (-SIGNAL_EIGEN_DB / 10)
    k = np.clip(signal.sum(-1), 1, n - 1)  # (...,) sources
    noise = np.arange(n) < (n - k)[..., None]  # the n - k smallest eigenvectors
    en = vec * noise[..., None, :]
    return en @ np.conj(np.swapaxes(en, -1, -2))


#: Each estimator of ``scene.registry.ANGLE_ESTIMATORS`` (the names a scene may give) with its
#: kernel: the registry's names, each with its callable (a test keeps the two in step).
KERNELS = {"bartlett": _bartlett, "capon": _capon, "music": _music}


def kernel(cov, estimator: str) -> np.ndarray:
    """The matrix K (..., L, L) whose quadratic form a^H K a the estimator makes *smallest* at
    its peak: Capon (R + delta I)^{-1}, MUSIC E_n E_n^H (module doc). Bartlett is -R."""
    if estimator not in KERNELS:
        raise ValueError(f"radar.angle_estimator = {estimator!r}: must be one of "
                         f"{', '.join(KERNELS)}")
    return KERNELS[estimator](np.asarray(cov))


def quadratic(k, a) -> np.ndarray:
    """Re(a^H K a) for kernels K (..., L, L) and manifold vectors a (..., A, L): (..., A)."""
    return np.real(np.einsum("...al,...lm,...am->...a", np.conj(a), k, a))


def lag_sums(k) -> np.ndarray:
    """On a uniform subarray (a_l = e^{-j l phi}) a^H K a = Re sum_delta r_delta e^{j delta
    phi} with r_delta = sum_m K_{m + delta, m}: the 2L - 1 lag sums (..., 2L - 1), delta =
    -(L-1) .. L-1, so a direction costs 2L - 1 products instead of L^2."""
    k = np.asarray(k)
    n = k.shape[-1]
    return np.stack([np.trace(k, offset=-d, axis1=-2, axis2=-1) for d in range(-n + 1, n)],
                    axis=-1)
