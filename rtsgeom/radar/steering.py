"""The RuT's beamformer (paper eq. 14): one steering model for every stage that forms a beam.

A :class:`Steering` is built once from the RuT array and the radar configuration and carried by
the ADC cube (``AdcCube.steering``) and by the channel model (``synthesis.model.ChannelModel``):

* which virtual elements take part (``mask``, (V,)), today the azimuth row;
* their positions ``positions_m`` (V_s, D) in the radar frame along the direction-cosine axes:
  D = 1 is azimuth (x, u = sin az); D = 2 adds elevation (x, z; u = (sin az cos el, sin el)).
  A custom or sparse array only changes these positions;
* the angle taper ``taper`` (V_s,) (the scene's ``radar.angle_window``);
* the direction estimator ``estimator`` (``radar.angle_estimator``: bartlett, eq. 14, capon or
  music) and its spatial smoothing ``subarray`` (``radar.angle_subarray``, 0 = none); the
  estimators and why they equal Bartlett on one unsmoothed snapshot: ``radar.estimators``.

The virtual element at ``p_v`` receives a source in direction ``u`` with phase ``-k p_v . u``;
the beamformer steers with ``+k p_v . u`` (sign conventions: ``radar.processing``).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .._lib.util import frozen, single_threaded_blas, use_kernels
from ..geometry import RutArray
from ..scene import RadarConfig
from ..errors import SceneError
from .estimators import (cell_snapshots, kernel, lag_sums, quadratic, rank_one_covariance,
                         smoothed_covariance, uniform_cells)
from .newton import lattice, newton, parabolic, peak_1d
from .windows import taper

__all__ = ["Steering", "smoothed_estimator"]

BLOCK = 4096  # snapshots per block of the Newton refinement (cache-sized)


def smoothed_estimator(estimator: str, subarray: int) -> bool:
    """Whether the direction estimator ``estimator`` (``radar.angle_estimator``) with spatial
    smoothing over ``subarray`` elements (``radar.angle_subarray``, 0 = none) peaks anywhere
    but at the beamformer's peak: Capon or MUSIC with smoothing (:attr:`Steering.smoothing`)."""
    return estimator != "bartlett" and subarray > 0


#: :meth:`Steering.build`'s last beamformers: (id(rut), id(radar), elevation) -> (rut, radar,
#: steering)
_BUILT: dict = {}
_BUILT_MAX = 8


@dataclass(frozen=True)
class Steering:
    """Virtual positions, taper and element selection of the RuT's beamformer (eq. 14).

    Directions are direction cosines ``u`` (..., D); angles (rad) only at :meth:`search` and in
    the ``radar.processing`` wrappers.

    Attributes
    ----------
    mask : (V,) bool
        The virtual elements that take part.
    positions_m : (V, D) float
    taper : (V,) float
    wavelength_m, aperture_m : float
    estimator : str
        ``bartlett``, ``capon`` or ``music``.
    subarray : int
        Spatial smoothing subarray length (0: none).
    """

    mask: np.ndarray  # (V,) virtual elements that take part
    positions_m: np.ndarray  # (V_s, D) radar frame, along the direction-cosine axes
    taper: np.ndarray  # (V_s,)
    wavelength_m: float
    aperture_m: np.ndarray  # (D,) extent of the array per axis (elements times spacing)
    estimator: str = "bartlett"  # radar.angle_estimator (registry.ANGLE_ESTIMATORS)
    subarray: int = 0  # radar.angle_subarray: smoothing subarray length, 0 = none
    pitch_m: float = 0.0  # grid pitch of the azimuth row (smoothing only)

    @classmethod
    def build(cls, rut: RutArray, radar: RadarConfig, elevation: bool = False) -> "Steering":
        """The azimuth beamformer (D = 1, the azimuth row), or with ``elevation`` the 2-D one
        over all virtual elements (D = 2: x and z), with the scene's direction estimator.

        The last few built are kept per (``rut``, ``radar``) object (both immutable): a
        drive's frames build one per cube, and each new one computed its search grid's
        steering vectors again (about 2 ms a frame of a drive's two chains)."""
        key = (id(rut), id(radar), bool(elevation))
        hit = _BUILT.get(key)
        if hit is not None and hit[0] is rut and hit[1] is radar:
            return hit[2]
        out = cls._build(rut, radar, elevation)
        if len(_BUILT) >= _BUILT_MAX:
            _BUILT.pop(next(iter(_BUILT)))
        _BUILT[key] = (rut, radar, out)  # the objects kept: their ids stay theirs
        return out

    @classmethod
    def _build(cls, rut: RutArray, radar: RadarConfig, elevation: bool) -> "Steering":
        kind = str(getattr(radar, "angle_estimator", "bartlett"))
        sub = int(getattr(radar, "angle_subarray", 0))
        if elevation:
            mask = np.ones(rut.num_virtual, bool)
            pos = rut.virtual_local[:, [0, 2]]
            n = [np.unique(np.round(pos[:, d] / rut.spacing_m, 6)).size for d in range(2)]
            aperture = np.asarray(n, float) * rut.spacing_m
        else:
            mask = np.asarray(rut.azimuth_mask, bool)
            pos = rut.virtual_local[mask][:, [0]]
            # the distinct positions' span plus one cell (duplicates and gaps counted right:
            # the cascade's 144 elements span 86 cells)
            aperture = np.array([rut.aperture_m])
        out = cls(frozen(mask), frozen(pos), frozen(taper(radar.angle_window, pos)),
                  float(rut.wavelength_m), frozen(aperture), kind, sub, float(rut.spacing_m))
        if out.smoothing:
            out._check_smoothing()
        return out

    @property
    def smoothing(self) -> bool:
        """Whether the estimator differs from Bartlett's peak: Capon or MUSIC with spatial
        smoothing. Without smoothing the covariance of one snapshot is rank 1 and both peak
        exactly where Bartlett does (``radar.estimators``): the Bartlett search is used."""
        return smoothed_estimator(self.estimator, self.subarray)

    def _check_smoothing(self) -> None:
        field = f"radar.angle_subarray = {self.subarray}"
        if self.dims != 1:
            raise SceneError(f"{field}: must be 0 with 2-D (azimuth x elevation) processing: "
                             "spatial smoothing is implemented for the 1-D azimuth row only")
        try:
            _, n = self._cells
        except ValueError as exc:
            raise SceneError(f"{field}: must be 0 for this array: {exc} (spatial smoothing "
                             "needs a filled uniform row; a sparse row has no shifted "
                             "subarrays)") from None
        if not 2 <= self.subarray <= n:
            raise SceneError(f"{field}: must be in [2, {n}] (the azimuth row has {n} distinct "
                             "positions), or 0 for no smoothing")

    @cached_property
    def _cells(self) -> tuple[np.ndarray, int]:
        """Grid cell per azimuth element and the number of cells (smoothing)."""
        return uniform_cells(self.positions_m[:, 0], self.pitch_m)

    @staticmethod
    def has_elevation(rut: RutArray) -> bool:
        """Whether the virtual array has elevation extent (more than one distinct height)."""
        z = np.round(np.asarray(rut.virtual_local)[:, 2] / rut.spacing_m, 6)
        return bool(np.unique(z).size > 1)

    @classmethod
    def auto(cls, rut: RutArray, radar: RadarConfig) -> "Steering":
        """The RuT's beamformer as it processes: 2-D (azimuth x elevation, D = 2, all virtual
        elements) when ``radar.elevation_processing`` is on and the virtual array has elevation
        extent, else the azimuth row (D = 1). (Opt-in: the pair designs of a flat arc solve on
        the azimuth row, so a 2-D RuT would see them ~0.2 deg off; see README.)"""
        on = bool(getattr(radar, "elevation_processing", False))
        return cls.build(rut, radar, elevation=on and cls.has_elevation(rut))

    @property
    def dims(self) -> int:
        return int(self.positions_m.shape[1])

    @property
    def size(self) -> int:
        return int(self.positions_m.shape[0])

    @property
    def wavevector(self) -> np.ndarray:
        """``k p_v`` (V_s, D), k = 2 pi / lambda."""
        return 2 * np.pi / self.wavelength_m * self.positions_m

    def directions(self, angle_rad) -> np.ndarray:
        """Direction cosines (..., D) of azimuth angles (...,) (D = 1) or of (az, el) pairs
        (..., 2) (D = 2)."""
        a = np.asarray(angle_rad, float)
        if self.dims == 1:
            return np.sin(a)[..., None]
        return np.stack([np.sin(a[..., 0]) * np.cos(a[..., 1]), np.sin(a[..., 1])], axis=-1)

    def weighted(self, snapshots) -> np.ndarray:
        """The elements that take part, tapered: (..., V) -> (..., V_s)."""
        return np.asarray(snapshots)[..., self.mask] * self.taper

    def steer(self, u) -> np.ndarray:
        """Steering vectors exp(+j k p_v . u) for directions ``u`` (..., D): (..., V_s)."""
        u = np.asarray(u, float)
        ph = np.sum(self.wavevector * u[..., None, :], axis=-1)
        return np.exp(1j * ph)

    def beam(self, snapshots, u) -> np.ndarray:
        """Beamformer output sum_v w_v x_v exp(j k p_v . u) of snapshots (..., V) at directions
        ``u`` (P, D): (..., P). Elementwise sums, so equal snapshots give equal bits whatever
        the batch."""
        w = self.weighted(snapshots)
        return np.sum(w[..., :, None] * self.steer(u).T, axis=-2)

    def power(self, snapshots, u) -> np.ndarray:
        """Bartlett power |sum_v w_v x_v exp(j k p_v . u)|^2 (eq. 14) of snapshots (..., V) at
        directions ``u`` (A, D): (..., A)."""
        return self._power(self.weighted(snapshots), self.steer(u))

    @staticmethod
    def _power(weighted: np.ndarray, steer: np.ndarray) -> np.ndarray:
        """|weighted @ steer.T|^2. ``einsum`` (numpy's own loops), not BLAS: these products are
        small (a few snapshots x V_s x a grid), where a multi-threaded BLAS call costs 10x
        its arithmetic in thread hand-offs on a busy machine (measured: 1.1 ms instead of
        0.1 ms per call, which made the `exact` amplitude design of `nearfield` take 20 s)."""
        return np.abs(np.einsum("...v,av->...a", weighted, steer)) ** 2

    # -- the direction estimator (radar.estimators) ------------------------------------------

    def covariance(self, snapshots) -> np.ndarray:
        """The estimator's covariance of snapshots (..., V): with smoothing the forward-backward
        smoothed (..., L, L) over the row's grid cells (untapered), else the rank-1
        x x^H (..., V_s, V_s) of the tapered snapshot."""
        if self.smoothing:
            cell, n = self._cells
            x = cell_snapshots(np.asarray(snapshots)[..., self.mask], cell, n)
            return smoothed_covariance(x, self.subarray)
        return rank_one_covariance(self.weighted(snapshots))

    def manifold(self, u) -> np.ndarray:
        """Array manifold a(u) = e^{-j k p . u} (..., L) for directions ``u`` (..., D): over
        one subarray's grid with smoothing, else over the elements that take part."""
        if self.smoothing:
            kx = 2 * np.pi / self.wavelength_m * self.pitch_m * np.arange(self.subarray)
            return np.exp(-1j * kx * np.asarray(u, float)[..., :1])
        return np.conj(self.steer(u))

    def spectrum(self, snapshots, u) -> np.ndarray:
        """The estimator's spectrum of snapshots (..., V) at directions ``u`` (A, D): (..., A).
        Bartlett: :meth:`power`; Capon, MUSIC: 1 / a^H K a (``radar.estimators``), from the
        covariance of :meth:`covariance` whether or not it is smoothed."""
        if self.estimator == "bartlett":
            return self.power(snapshots, u)
        k = kernel(self.covariance(snapshots), self.estimator)
        q = quadratic(k, self.manifold(u))
        return 1.0 / np.maximum(q, np.finfo(float).tiny)

    def _search_smoothed(self, snapshots) -> np.ndarray:
        """:meth:`search` for a smoothed Capon or MUSIC (D = 1): the largest peak of the
        estimator's spectrum (the smallest a^H K a) on the 0.25 deg grid, two zoom levels
        (0.005, 1e-4 deg) and a parabola through -a^H K a (smooth where 1 / a^H K a is
        sharp)."""
        snaps = np.atleast_2d(snapshots)
        shape = snaps.shape[:-1]
        snaps = snaps.reshape(-1, snaps.shape[-1])
        fine = np.all(np.isfinite(snaps[:, self.mask]), axis=-1)
        if not fine.all():  # a snapshot with NaN (e.g. a design that has none): NaN angle
            out = np.full(snaps.shape[0], np.nan)
            if fine.any():
                out[fine] = self._search_smoothed(snaps[fine])
            out = out.reshape(shape)
            return out if np.ndim(snapshots) > 1 else out[0]
        with single_threaded_blas():  # many small products: threads cost more than they give
            return self._search_smoothed_blocks(snaps, shape, np.ndim(snapshots))

    def _search_smoothed_blocks(self, snaps, shape, ndim) -> np.ndarray:
        """MUSIC's nulls are all unbounded peaks on noise-free data: of the coarse grid's
        local minima of a^H K a within 0.05 L of the deepest (the resolved sources), the one
        with the most power a^H R a, the strongest source, is reported (what a radar reports
        for one detection); Capon's peaks are ordered by power already."""
        cov = self.covariance(snaps)
        r = lag_sums(kernel(cov, self.estimator))  # (n, 2L - 1)
        lags = np.arange(-self.subarray + 1, self.subarray)
        kd = 2 * np.pi / self.wavelength_m * self.pitch_m

        def quad(angles, lag=r):  # a^H K a at azimuths (n, A) or (A,): Re sum r_d z^d
            z = np.exp(1j * kd * np.sin(angles))[..., None, :]  # (..., 1, A), z = e^{j k d u}
            pos = np.cumprod(np.broadcast_to(z, z.shape[:-2] + (lags.size // 2, z.shape[-1])),
                             axis=-2)  # z^1 .. z^(L-1): products, not exponentials
            e = np.concatenate([np.conj(pos[..., ::-1, :]), np.ones_like(z), pos], axis=-2)
            return np.real(lag @ e if e.ndim == 2 else np.einsum("nd,nda->na", lag, e))

        grid = self._search_grid[0]
        q = quad(grid)
        pick = np.argmin(q, axis=1)
        if self.estimator == "music":
            low = np.zeros(q.shape, bool)
            low[:, 1:-1] = (q[:, 1:-1] <= q[:, :-2]) & (q[:, 1:-1] <= q[:, 2:])
            low &= q <= q.min(axis=1, keepdims=True) + 0.05 * self.subarray
            power = quad(grid, lag_sums(cov))
            pick = np.where(low.any(axis=1), np.argmax(np.where(low, power, -np.inf), axis=1),
                            pick)
        best = grid[pick]
        for half, step in ((0.3, 0.005), (0.006, 1e-4)):
            offs = np.radians(np.arange(-half, half + step / 2, step))
            cand = np.clip(best[:, None] + offs[None, :], -np.pi / 2, np.pi / 2)
            pw = -quad(cand)
            i = np.clip(np.argmax(pw, axis=1), 1, offs.size - 2)
            rows = np.arange(pw.shape[0])
            frac = parabolic(pw[rows, i - 1], pw[rows, i], pw[rows, i + 1])
            best = cand[rows, i] + np.clip(frac, -1, 1) * np.radians(step)
        out = best.reshape(shape)
        return out if ndim > 1 else out[0]

    @cached_property
    def _search_grid(self) -> tuple[np.ndarray, np.ndarray]:
        """The coarse grid of :meth:`search` (0.25 deg over +-90 deg) and its steering vectors
        (built once per beamformer, not per call)."""
        grid = np.radians(np.arange(-90.0, 90.0001, 0.25))
        return grid, self.steer(self.directions(grid))

    @staticmethod
    def angles(u) -> np.ndarray:
        """(azimuth, elevation) (..., 2) rad of direction cosines u (..., 2):
        el = asin u_el, az = asin(u_az / cos el)."""
        u = np.asarray(u, float)
        el = np.arcsin(np.clip(u[..., 1], -1.0, 1.0))
        ce = np.cos(el)
        az = np.arcsin(np.clip(u[..., 0] / np.where(ce > 0, ce, 1.0), -1.0, 1.0))
        return np.stack([az, el], axis=-1)

    def azimuth(self, snapshots) -> np.ndarray:
        """The detected azimuth (...,) rad of snapshots (..., V), whatever D (D = 2: the
        azimuth of the 2-D peak)."""
        a = self.search(snapshots)
        return a if self.dims == 1 else a[..., 0]

    def search(self, snapshots) -> np.ndarray:
        """The estimator's peak per snapshot (..., V) -> azimuth (...,) rad (D = 1) or
        (azimuth, elevation) (..., 2) rad (D = 2). A smoothed Capon or MUSIC
        (:attr:`smoothing`) searches its own spectrum (:meth:`_search_smoothed`); every other
        case is Bartlett's peak (the same peak for all three estimators on one snapshot):

        D = 1: grid search at 0.25 deg, two zoom levels (0.005 deg, 1e-4 deg) and a final
        parabolic interpolation: precise to ~1e-6 deg on noise-free data. D = 2: the global
        maximum on the coarse 2-D grid of :meth:`grid` (lambda / (8 d_A) per axis over the
        visible region, which holds the unambiguous one), then :meth:`peak` (2-D Newton on
        log P with the global check) from there."""
        if self.smoothing:
            return self._search_smoothed(snapshots)
        if self.dims != 1:
            return self._search_2d(snapshots)
        snaps = np.atleast_2d(snapshots)
        shape = snaps.shape[:-1]
        snaps = snaps.reshape(-1, snaps.shape[-1])
        grid, steer = self._search_grid
        x = self.weighted(snaps)
        # a snapshot with a NaN has no power anywhere: its peak is the grid's first angle,
        # which the zooms below keep exactly (argmax over NaN: index 0; the parabola: 0), so
        # they run on the others only (a failed design's NaN snapshots: 4 s per Monte Carlo)
        nan = np.isnan(x).any(axis=1)
        out = np.full(x.shape[0], grid[0])
        x = x[~nan] if nan.any() else x
        p = self._power(x, steer)
        best = grid[np.argmax(p, axis=1)]
        for half, step in ((0.3, 0.005), (0.006, 1e-4)):
            offs = np.radians(np.arange(-half, half + step / 2, step))
            cand = np.clip(best[:, None] + offs[None, :], -np.pi / 2, np.pi / 2)
            pw = np.abs(np.einsum("dv,dov->do", x, self.steer(self.directions(cand)))) ** 2
            i = np.clip(np.argmax(pw, axis=1), 1, offs.size - 2)
            rows = np.arange(pw.shape[0])
            frac = parabolic(pw[rows, i - 1], pw[rows, i], pw[rows, i + 1])
            best = cand[rows, i] + np.clip(frac, -1, 1) * np.radians(step)
        out[~nan] = best
        out = out.reshape(shape)
        return out if np.ndim(snapshots) > 1 else out[0]

    def _search_2d(self, snapshots) -> np.ndarray:
        snaps = np.asarray(snapshots)
        shape = snaps.shape[:-1]
        flat = snaps.reshape(-1, snaps.shape[-1])
        grid = self.grid()
        steer = self.steer(grid).T
        start = np.empty((flat.shape[0], 2))
        for b in range(0, flat.shape[0], BLOCK):
            y = self.weighted(flat[b:b + BLOCK]) @ steer
            start[b:b + BLOCK] = grid[np.argmax(y.real ** 2 + y.imag ** 2, axis=1)]
        u, _ = self.peak(flat, start, iterations=8)
        return self.angles(u).reshape(shape + (2,))

    def grid_mesh(self) -> np.ndarray:
        """The mesh (A_0, ..., A_{D-1}, D) of :meth:`grid` before the invisible region is cut:
        steps of lambda / (8 d_A) in u per axis over [-1, 1]."""
        axes = [np.linspace(-1.0, 1.0, int(np.ceil(16 * a / self.wavelength_m)) + 1)
                for a in self.aperture_m]
        return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1)

    def grid(self) -> np.ndarray:
        """Directions (G, D) of the global check: steps of lambda / (8 d_A) in u per axis
        (at most ~1 % below the top of a lobe), inside the visible region."""
        g = self.grid_mesh().reshape(-1, self.dims)
        return g[np.sum(g ** 2, axis=-1) <= 1.0]

    def peak(self, snapshots, u0, iterations: int = 4):
        """Beamformer peak per snapshot (..., V) by Newton's method on log P(u) from ``u0``
        (..., D) (broadcast): returns (u (..., D), converged (...,)).

        Up to ``iterations`` Newton steps with P's analytic gradient and Hessian (one pass over
        the elements per step, no grid; each component of a step clipped to 0.05). A snapshot
        is accepted when its last step is below 1e-6 in u (quadratic convergence), log P is
        concave there, |u| < 1, and no point of :meth:`grid` has more power, i.e. the peak
        found is the global one. The others are restarted from the grid's maximum (with 4 more
        steps); what still fails is not converged: its u is the grid search's
        (:meth:`search`, D = 1) or the grid's maximum (D = 2). Elementwise arithmetic in
        cache-sized blocks, so equal snapshots give bit-equal results. A smoothed Capon or
        MUSIC (:attr:`smoothing`) returns its :meth:`search` (``u0`` unused), all converged."""
        snaps = np.asarray(snapshots)
        shape = snaps.shape[:-1]
        if self.smoothing:  # no Newton on Bartlett's power: the estimator's own search
            u = np.sin(self.search(snaps.reshape(-1, snaps.shape[-1])))[:, None]
            return u.reshape(shape + (1,)), np.ones(shape, bool)
        flat = snaps.reshape(-1, snaps.shape[-1])
        n_d = self.dims
        u0 = np.broadcast_to(np.asarray(u0, float), shape + (n_d,)).reshape(-1, n_d)
        ok = np.zeros(u0.shape[0], bool)
        if n_d == 1:  # compiled, snapshot by snapshot (rtsgeom.synthesis.kernels), or its definition
            k, lat, gc, gs, g1 = self._grid_1d
            x = np.ascontiguousarray(self.weighted(flat), complex)
            start = np.ascontiguousarray(u0[:, 0])
            # numpy, the same bits, while numba's set-up would cost more (~10 ns per
            # element and grid point, measured)
            if not use_kernels(x.shape[0], 1e-8 * gc.size):
                u1, ok = peak_1d(k, lat, x, start, gc, gs, g1, int(iterations))
            else:
                from .peak_kernels import peak_1d as compiled
                u1 = np.empty(u0.shape[0])
                compiled(k, lat, x, start, gc, gs, g1, int(iterations), u1, ok)
            u = u1[:, None]
        else:
            kv = self.wavevector  # (V_s, D)
            grid = self.grid()
            steer = self.steer(grid).T  # (V_s, G)
            u = np.empty_like(u0)
            best_grid = np.empty_like(u0)
            with single_threaded_blas():  # (BLOCK x V_s) @ (V_s x G) is too small to share out
                self._peak_blocks(flat, u0, u, ok, best_grid, kv, grid, steer, iterations)
        if not ok.all():
            if n_d == 1:
                u[~ok, 0] = np.sin(self.search(flat[~ok]))
            else:
                u[~ok] = best_grid[~ok]
        return u.reshape(shape + (n_d,)), ok.reshape(shape)

    @cached_property
    def _grid_1d(self) -> tuple:
        """What the compiled peak (D = 1) reads: the wavenumbers k p_v (V_s,), their lattice
        on the pitch grid (``newton.lattice``), and the global check's grid: the steering
        vectors' real and imaginary parts (V_s, G) and the grid's u (G,)."""
        k = np.ascontiguousarray(self.wavevector[:, 0])
        lat = lattice(k, 2 * np.pi / self.wavelength_m * self.pitch_m)
        grid = self.grid()
        steer = self.steer(grid).T
        return (k, lat, np.ascontiguousarray(steer.real), np.ascontiguousarray(steer.imag),
                np.ascontiguousarray(grid[:, 0]))

    def _peak_blocks(self, flat, u0, u, ok, best_grid, kv, grid, steer, iterations):
        """:meth:`peak`'s Newton steps and global check for D = 2, block by block (fills ``u``,
        ``ok`` and, where not ok, ``best_grid`` in place).

        The grid's powers are formed in single precision (6x faster than double: this was
        most of a Monte-Carlo draw's angle estimate); where that cannot decide the global check
        (the Newton peak within ``_P32_TOL`` of the grid's maximum, relative to the power
        bound (sum |w x|)^2, far above single precision's rounding) and for the snapshots
        that fail it, the grid is recomputed in double precision, so the outcome (u, ok and
        the restarts) is the double-precision check's."""
        steer32 = steer.astype(np.complex64)
        for b in range(0, u0.shape[0], BLOCK):
            blk = slice(b, b + BLOCK)
            x = self.weighted(flat[blk])
            mag = np.abs(x)
            top = mag.max(axis=1)  # scaled to |x| <= 1: no float32 overflow or underflow
            with np.errstate(divide="ignore", invalid="ignore"):
                y = (x / top[:, None]).astype(np.complex64) @ steer32
            p_max = (y.real ** 2 + y.imag ** 2).max(axis=1) * top ** 2  # (n,), NaN: undecided
            tol = _P32_TOL * np.sum(mag, axis=1) ** 2
            xr, xi = np.ascontiguousarray(x.real.T), np.ascontiguousarray(x.imag.T)
            u_b, conv, p_last = newton(kv, xr, xi, u0[blk], None, iterations)
            good = conv & (p_last >= p_max + tol)
            # undecided or failed: the double-precision grid (exact p_max, the restart point)
            redo = np.flatnonzero(~good)
            if redo.size:
                y64 = x[redo] @ steer
                p_grid = y64.real ** 2 + y64.imag ** 2
                p_max[redo] = p_grid.max(axis=1)
                best_grid[b + redo] = grid[np.argmax(p_grid, axis=1)]
                good[redo] = conv[redo] & (p_last[redo] >= p_max[redo] * (1 - 1e-9))
            u[blk], ok[blk] = u_b, good
            bad = np.flatnonzero(~good)
            if bad.size:  # restart from the grid's maximum
                u2, ok2, p2 = newton(kv, xr[:, bad], xi[:, bad], best_grid[b + bad], None,
                                      iterations + 4)
                ok2 &= p2 >= p_max[bad] * (1 - 1e-9)
                u[b + bad[ok2]] = u2[ok2]
                ok[b + bad[ok2]] = True


#: single-precision grid powers decide the global check only this far (relative to
#: (sum |w x|)^2, which bounds every power) from the Newton peak's power; their error is
#: below ~1e-6 of it (8 products and sums in float32), so the decision is exact
_P32_TOL = 1e-5
