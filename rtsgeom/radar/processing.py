"""RuT signal processing as a real radar does it (stage 5).

ADC cube -> windowed range FFT (eq. 10) -> windowed Doppler FFT -> non-coherent integration over
the virtual channels -> 2D CFAR (CA or OS) -> local maxima -> per detection: TDM-MIMO Doppler
compensation and beamforming over the azimuth virtual array (eq. 14) with a zoomed grid search
and parabolic refinement to well below 0.01 deg.

Sign conventions: the beat signal is ``exp(+j phi_b)`` (eq. 8), so a delay tau gives a positive
beat frequency ``S tau`` and a receding target (velocity > 0, tau growing) a positive slow-time
frequency. The virtual element at ``x_v`` (``p_tx + p_rx`` in the radar frame) receives a source
at azimuth theta with phase ``-k x_v sin theta``; the beamformer steers with ``+k x_v sin alpha``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage, signal
from scipy.constants import c

from .._util import frozen
from ..geometry import RutArray
from ..scene import CfarConfig, RadarConfig
from .fmcw import AdcCube

__all__ = ["RangeDoppler", "Detections", "range_doppler", "cfar_mask", "detect",
           "nearest_detection",
           "angle_spectrum", "estimate_angles", "range_angle_map", "process", "window"]


def window(name: str, n: int) -> np.ndarray:
    if name == "none":
        return np.ones(n)
    return signal.get_window(name, n, fftbins=False)


@dataclass(frozen=True)
class RangeDoppler:
    """Range-Doppler spectrum per virtual channel and its integrated power map."""

    spectrum: np.ndarray  # (R, D, V) complex64, Doppler axis fftshifted
    power: np.ndarray  # (R, D) sum over virtual channels of |X|^2
    range_m: np.ndarray  # (R,)
    velocity_mps: np.ndarray  # (D,)
    doppler_hz: np.ndarray  # (D,) slow-time frequency per TDM cycle

    @property
    def power_db(self) -> np.ndarray:
        return 10 * np.log10(np.maximum(self.power, 1e-30))

    def to_xarray(self):
        """The integrated power map as an ``xarray.DataArray`` (linear power, dims ``range_m``
        and ``velocity_mps``, with ``doppler_hz`` as a second coordinate on the Doppler axis).

        ``10 * numpy.log10(da)`` gives dB; ``da.sel(range_m=33.5, method="nearest")`` a cut.
        """
        import xarray as xr
        return xr.DataArray(self.power, dims=("range_m", "velocity_mps"),
                            coords={"range_m": self.range_m, "velocity_mps": self.velocity_mps,
                                    "doppler_hz": ("velocity_mps", self.doppler_hz)},
                            name="power", attrs={"long_name": "range-Doppler power",
                                                 "description": "sum over virtual channels of "
                                                                "|X|^2"})

    def range_angle_to_xarray(self, cube: AdcCube, angle_deg=None):
        """The range-angle map (:func:`range_angle_map`, each range bin at its strongest
        Doppler bin) as an ``xarray.DataArray`` with dims ``range_m`` and ``angle_deg``.

        ``angle_deg`` defaults to -60..60 deg in 0.25 deg steps.
        """
        import xarray as xr
        angle_deg = np.arange(-60.0, 60.0 + 1e-9, 0.25) if angle_deg is None else (
            np.asarray(angle_deg, float))
        power = range_angle_map(self, cube, np.radians(angle_deg))
        return xr.DataArray(power, dims=("range_m", "angle_deg"),
                            coords={"range_m": self.range_m, "angle_deg": angle_deg},
                            name="power", attrs={"long_name": "beamformer power"})


@dataclass(frozen=True)
class Detections:
    """Detection list (SI units; ``angle_rad`` in the radar frame, from boresight to +x)."""

    range_m: np.ndarray
    velocity_mps: np.ndarray
    angle_rad: np.ndarray
    power_db: np.ndarray  # integrated range-Doppler power at the peak
    snr_db: np.ndarray  # peak over the CFAR noise estimate
    range_bin: np.ndarray
    doppler_bin: np.ndarray

    def __len__(self) -> int:
        return int(self.range_m.size)

    @property
    def angle_deg(self) -> np.ndarray:
        return np.degrees(self.angle_rad)

    def to_dataframe(self):
        """One row per detection as a ``pandas.DataFrame`` (columns ``range_m``,
        ``velocity_mps``, ``angle_deg``, ``power_db``, ``snr_db``, ``range_bin``,
        ``doppler_bin``)."""
        import pandas as pd
        return pd.DataFrame({"range_m": self.range_m, "velocity_mps": self.velocity_mps,
                             "angle_deg": self.angle_deg, "power_db": self.power_db,
                             "snr_db": self.snr_db, "range_bin": self.range_bin,
                             "doppler_bin": self.doppler_bin})


def range_doppler(cube: AdcCube) -> RangeDoppler:
    radar = cube.radar
    n_l, _, n_s = cube.data.shape
    w_r = window(radar.range_window, n_s).astype(np.float32)
    w_d = window(radar.doppler_window, n_l).astype(np.float32)
    x = np.fft.fft(cube.data * w_r, axis=2)
    x = np.fft.fftshift(np.fft.fft(x * w_d[:, None, None], axis=0), axes=0)
    spec = np.ascontiguousarray(x.transpose(2, 0, 1)).astype(np.complex64)  # (R, D, V)
    power = np.sum(spec.real ** 2 + spec.imag ** 2, axis=2, dtype=np.float64)
    f_beat = np.arange(n_s) * radar.adc_rate_hz / n_s
    rng = f_beat * c / (2 * radar.slope_hz_per_s)
    nu = np.fft.fftshift(np.fft.fftfreq(n_l, d=radar.tdm_cycle_s))
    vel = nu * c / (2 * radar.f_c_hz)
    return RangeDoppler(spec, power, frozen(rng), frozen(vel), frozen(nu))


def cfar_mask(power: np.ndarray, cfg: CfarConfig) -> tuple[np.ndarray, np.ndarray]:
    """2D CFAR on a (range, Doppler) power map: returns (detected mask, noise estimate).

    Training cells form a ring around each cell under test (guard cells excluded); the range
    axis is cyclic too: with a complex ADC the beat frequencies wrap at f_adc, so the top
    range bins neighbour the bottom ones.
    CA averages the ring, OS takes its ``os_rank`` quantile.
    """
    gr, gd = cfg.guard_cells
    tr, td = cfg.training_cells
    ring = np.ones((2 * (gr + tr) + 1, 2 * (gd + td) + 1), bool)
    ring[tr:tr + 2 * gr + 1, td:td + 2 * gd + 1] = False
    pr, pd = gr + tr, gd + td
    padded = np.pad(power, ((pr, pr), (pd, pd)), mode="wrap")  # both axes are cyclic
    crop = (slice(pr, pr + power.shape[0]), slice(pd, pd + power.shape[1]))
    if cfg.kind == "ca":
        k = ring.astype(float)
        total = ndimage.convolve(padded, k, mode="constant")[crop]
        count = ndimage.convolve(np.ones_like(padded), k, mode="constant")[crop]
        noise = total / np.maximum(count, 1)
    else:
        noise = ndimage.percentile_filter(padded, 100 * cfg.os_rank, footprint=ring,
                                          mode="nearest")[crop]
    thr = noise * 10 ** (cfg.threshold_db / 10)
    peak = power == ndimage.maximum_filter(power, size=3, mode="wrap")
    return (power > thr) & peak, noise


def _steering(rut: RutArray, sin_alpha: np.ndarray) -> np.ndarray:
    """Beamformer weights exp(+j k x_v sin alpha) for the azimuth virtual array, (..., V_az)."""
    x = rut.virtual_local[rut.azimuth_mask, 0]
    k = 2 * np.pi / rut.wavelength_m
    return np.exp(1j * k * np.asarray(sin_alpha)[..., None] * x)


def _angle_taper(radar: RadarConfig, rut: RutArray) -> np.ndarray:
    x = rut.virtual_local[rut.azimuth_mask, 0]
    w = np.empty_like(x)
    w[np.argsort(x)] = window(radar.angle_window, x.size)
    return w


def angle_spectrum(snapshots: np.ndarray, rut: RutArray, radar: RadarConfig,
                   angles_rad: np.ndarray) -> np.ndarray:
    """Beamformer power |sum_v w_v x_v exp(j k x_v sin alpha)|^2 (eq. 14).

    ``snapshots`` (..., V) over all virtual channels (the azimuth row is selected here);
    returns (..., A).
    """
    x = snapshots[..., rut.azimuth_mask] * _angle_taper(radar, rut)
    steer = _steering(rut, np.sin(angles_rad))  # (A, V_az)
    return np.abs(x @ steer.T) ** 2


def estimate_angles(snapshots: np.ndarray, rut: RutArray, radar: RadarConfig) -> np.ndarray:
    """Peak of the beamformer per snapshot (..., V) -> (...,) radians.

    Grid search at 0.25 deg, then two zoom levels (0.005 deg, 1e-4 deg) and a final parabolic
    interpolation: precise to ~1e-6 deg on noise-free data, vectorised over snapshots.
    """
    snaps = np.atleast_2d(snapshots)
    shape = snaps.shape[:-1]
    snaps = snaps.reshape(-1, snaps.shape[-1])
    grid = np.radians(np.arange(-90.0, 90.0001, 0.25))
    p = angle_spectrum(snaps, rut, radar, grid)
    best = grid[np.argmax(p, axis=1)]
    for half, step in ((0.3, 0.005), (0.006, 1e-4)):
        offs = np.radians(np.arange(-half, half + step / 2, step))
        cand = np.clip(best[:, None] + offs[None, :], -np.pi / 2, np.pi / 2)
        x = snaps[:, rut.azimuth_mask] * _angle_taper(radar, rut)
        steer = _steering(rut, np.sin(cand))  # (D, O, V_az)
        pw = np.abs(np.einsum("dv,dov->do", x, steer)) ** 2
        i = np.clip(np.argmax(pw, axis=1), 1, offs.size - 2)
        rows = np.arange(pw.shape[0])
        frac = _parabolic(pw[rows, i - 1], pw[rows, i], pw[rows, i + 1])
        best = cand[rows, i] + np.clip(frac, -1, 1) * np.radians(step)
    out = best.reshape(shape)
    return out if np.ndim(snapshots) > 1 else out[0]


def _parabolic(y0, y1, y2) -> np.ndarray:
    """Sub-bin offset of a peak from three log-power samples."""
    den = y0 - 2 * y1 + y2
    return np.where(den < 0, 0.5 * (y0 - y2) / np.where(den == 0, -1, den), 0.0)


def tdm_compensate(snapshots: np.ndarray, doppler_hz, rut: RutArray,
                   radar: RadarConfig) -> np.ndarray:
    """Remove the Tx-switching phase 2 pi f_D s T_rep of TDM slot s (snapshots (..., V))."""
    ph = -2j * np.pi * np.asarray(doppler_hz)[..., None] * rut.virtual_slot * radar.chirp_repetition_s
    return snapshots * np.exp(ph)


def detect(rd: RangeDoppler, cube: AdcCube) -> Detections:
    """CFAR detections with sub-bin range/velocity and a refined angle per detection."""
    radar, rut = cube.radar, cube.rut
    mask, noise = cfar_mask(rd.power, radar.cfar)
    r_i, d_i = np.nonzero(mask)
    n_r, n_d = rd.power.shape
    logp = np.log(np.maximum(rd.power, 1e-300))
    dr = _parabolic(logp[(r_i - 1) % n_r, d_i], logp[r_i, d_i], logp[(r_i + 1) % n_r, d_i])
    dd = _parabolic(logp[r_i, (d_i - 1) % n_d], logp[r_i, d_i], logp[r_i, (d_i + 1) % n_d])
    range_step = rd.range_m[1] - rd.range_m[0]
    nu_step = rd.doppler_hz[1] - rd.doppler_hz[0]
    nu = rd.doppler_hz[d_i] + dd * nu_step
    snaps = tdm_compensate(rd.spectrum[r_i, d_i, :], nu, rut, radar)
    ang = estimate_angles(snaps, rut, radar) if r_i.size else np.zeros(0)
    return Detections(
        range_m=frozen(rd.range_m[r_i] + dr * range_step),
        velocity_mps=frozen(nu * c / (2 * radar.f_c_hz)),
        angle_rad=frozen(ang),
        power_db=frozen(10 * np.log10(rd.power[r_i, d_i])),
        snr_db=frozen(10 * np.log10(rd.power[r_i, d_i] / noise[r_i, d_i])),
        range_bin=frozen(r_i), doppler_bin=frozen(d_i),
    )


def nearest_detection(det: Detections, rd: RangeDoppler, range_m: float,
                      velocity_mps: float = 0.0, bins: int = 2) -> int | None:
    """Index of the strongest detection within ``bins`` range and Doppler bins of a set-point,
    or None."""
    dr = rd.range_m[1] - rd.range_m[0]
    dv = rd.velocity_mps[1] - rd.velocity_mps[0]
    near = ((np.abs(det.range_m - range_m) <= bins * dr)
            & (np.abs(det.velocity_mps - velocity_mps) <= bins * dv))
    if not np.any(near):
        return None
    return int(np.flatnonzero(near)[np.argmax(det.power_db[near])])


def range_angle_map(rd: RangeDoppler, cube: AdcCube, angles_rad: np.ndarray) -> np.ndarray:
    """Beamformer power over (range, angle), each range bin at its strongest Doppler bin."""
    d_best = np.argmax(rd.power, axis=1)
    r = np.arange(rd.power.shape[0])
    snaps = tdm_compensate(rd.spectrum[r, d_best, :], rd.doppler_hz[d_best], cube.rut, cube.radar)
    return angle_spectrum(snaps, cube.rut, cube.radar, angles_rad)


def process(cube: AdcCube) -> tuple[RangeDoppler, Detections]:
    rd = range_doppler(cube)
    return rd, detect(rd, cube)


def refine_angles(snapshots: np.ndarray, rut: RutArray, radar: RadarConfig, start_rad,
                  iterations: int = 4, *, return_converged: bool = False):
    """Beamformer peak per snapshot (..., V) -> (...,) radians, by Newton's method from
    ``start_rad`` (broadcast to the snapshots): the fast path of :func:`estimate_angles` when
    the peak is known to lie near the start (e.g. a synthesized target near its set angle).

    Up to ``iterations`` Newton steps on log P(u), u = sin(alpha), with P the beamformer power
    of eq. (14) and its analytic derivatives (one pass over the elements per step, no grid).
    A snapshot is accepted when its last step is below 1e-6 in u (quadratic convergence: the
    next one would be ~1e-11), log P is concave there, and no point of a coarse grid over the
    visible region (steps of lambda / (8 d_A) in u, at most ~1 % below the top of a lobe) has
    more power, i.e. the peak found is the global one. The others are restarted from that
    grid's maximum; what still fails goes to :func:`estimate_angles`. Elementwise arithmetic
    in cache-sized blocks, so equal snapshots give bit-equal angles. ``return_converged`` also
    returns a mask, False where :func:`estimate_angles` was used.
    """
    snaps = np.asarray(snapshots)
    shape = snaps.shape[:-1]
    flat = snaps.reshape(-1, snaps.shape[-1])
    az = rut.azimuth_mask
    kx = 2 * np.pi / rut.wavelength_m * rut.virtual_local[az, 0]
    kx2 = kx ** 2
    taper = _angle_taper(radar, rut)
    grid = np.linspace(-1.0, 1.0, int(np.ceil(16 * kx.size * rut.spacing_m / rut.wavelength_m)) + 1)
    steer = np.exp(1j * kx[:, None] * grid[None, :])  # (V, G)
    u0 = np.sin(np.broadcast_to(np.asarray(start_rad, float), shape)).ravel()
    u = np.empty(u0.size)
    ok = np.zeros(u0.size, bool)

    def newton(xr, xi, u, p_max, steps):
        """Newton steps from ``u`` on snapshots (V, n) split in real and imaginary parts:
        (u, accepted); accepted needs the power at the peak >= ``p_max`` (the grid's)."""
        u = np.array(u, float)
        ok = np.zeros(u.size, bool)
        p_last = np.zeros(u.size)
        act = np.arange(u.size)
        for _ in range(steps):
            if act.size == 0:
                break
            ar, ai, ua = xr[:, act], xi[:, act], u[act]
            ph = kx[:, None] * ua
            co, si = np.cos(ph), np.sin(ph)
            y = np.stack([ar * co - ai * si, ar * si + ai * co])  # (2, V, n): Re, Im
            # Re, Im of B = sum y, C = sum kx y, D = sum kx^2 y (row sums: bit-stable)
            m = np.concatenate([y.sum(axis=1), (y * kx[:, None]).sum(axis=1),
                                (y * kx2[:, None]).sum(axis=1)])
            p = m[0] ** 2 + m[1] ** 2  # P = |B|^2 with B' = j C, B'' = -D
            with np.errstate(divide="ignore", invalid="ignore"):
                f1 = 2 * (m[1] * m[2] - m[0] * m[3]) / p
                f2 = 2 * (m[2] ** 2 + m[3] ** 2 - m[0] * m[4] - m[1] * m[5]) / p - f1 ** 2
                step = np.where(f2 < 0, -f1 / f2, np.nan)
            fine = np.isfinite(step)
            u[act] = ua + np.clip(np.where(fine, step, 0.0), -0.05, 0.05)
            p_last[act] = p  # within ~1e-10 (relative) of the power at the final u
            done = np.abs(step) < 1e-6
            ok[act[done]] = True
            act = act[fine & ~done]
        return u, ok & (np.abs(u) < 1) & (p_last >= p_max * (1 - 1e-9))

    for b in range(0, u0.size, 4096):
        blk = slice(b, b + 4096)
        x = flat[blk][:, az] * taper
        y = x @ steer
        p_grid = y.real ** 2 + y.imag ** 2  # (n, G)
        p_max = p_grid.max(axis=1)
        xr, xi = np.ascontiguousarray(x.real.T), np.ascontiguousarray(x.imag.T)
        u[blk], ok[blk] = newton(xr, xi, u0[blk], p_max, iterations)
        bad = np.flatnonzero(~ok[blk])
        if bad.size:  # restart from the grid's maximum
            u2, ok2 = newton(xr[:, bad], xi[:, bad], grid[np.argmax(p_grid[bad], axis=1)],
                             p_max[bad], iterations + 4)
            u[b + bad[ok2]] = u2[ok2]
            ok[b + bad[ok2]] = True
    out = np.arcsin(np.clip(u, -1.0, 1.0))
    if not ok.all():
        out[~ok] = estimate_angles(flat[~ok], rut, radar)
    out = out.reshape(shape)
    return (out, ok.reshape(shape)) if return_converged else out
