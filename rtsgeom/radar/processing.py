"""RuT signal processing as a real radar does it (stage 5).

ADC cube -> windowed range FFT (eq. 10) -> windowed Doppler FFT -> non-coherent integration over
the virtual channels -> 2D CFAR (CA or OS) -> local maxima -> per detection: TDM-MIMO Doppler
compensation and beamforming over the azimuth virtual array (eq. 14) with a zoomed grid search
and parabolic refinement to well below 0.01 deg. The beamformer itself (positions, taper, which
elements take part; power, grid search, Newton peak) is the one :class:`~.steering.Steering`
the cube carries (``AdcCube.steering``); the functions here are its angle-valued wrappers.

Sign conventions: the beat signal is ``exp(+j phi_b)`` (eq. 8), so a delay tau gives a positive
beat frequency ``S tau`` and a receding target (velocity > 0, tau growing) a positive slow-time
frequency. The virtual element at ``x_v`` (``p_tx + p_rx`` in the radar frame) receives a source
at azimuth theta with phase ``-k x_v sin theta``; the beamformer steers with ``+k x_v sin alpha``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.constants import c

from .._lib.util import frozen
from ..geometry import RutArray
from ..scene import RadarConfig
from .cfar import cfar_mask
from .fmcw import AdcCube
from .newton import parabolic as _parabolic
from .peaks import angle_peaks
from .steering import Steering
from .windows import window

__all__ = ["RangeDoppler", "Detections", "range_doppler", "range_doppler_power", "cfar_mask",
           "detect", "detections_at", "PeakCells", "spectrum_axes",
           "nearest_detection",
           "angle_spectrum", "estimate_angles", "range_angle_map", "process"]


@dataclass(frozen=True)
class RangeDoppler:
    """Range-Doppler spectrum per virtual channel and its integrated power map.

    Attributes
    ----------
    spectrum : ndarray, (R, D, V) complex64
        The 2-D FFT per virtual channel, the Doppler axis fftshifted.
    power : ndarray, (R, D)
        ``sum_v |spectrum|^2``, the map CFAR runs on; :attr:`power_db` in dB.
    range_m : ndarray, (R,)
        Each range bin's range.
    velocity_mps : ndarray, (D,)
        Each Doppler bin's radial velocity.
    doppler_hz : ndarray, (D,)
        Each Doppler bin's slow-time frequency per TDM cycle.
    """

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
    """Detection list (SI units; ``angle_rad`` in the radar frame, from boresight to +x).

    Attributes
    ----------
    range_m, velocity_mps, angle_rad : ndarray, (N,)
        Each detection's range, radial velocity and azimuth.
    power_db : ndarray, (N,)
        The integrated range-Doppler power at the peak.
    snr_db : ndarray, (N,)
        The peak over the CFAR noise estimate.
    range_bin, doppler_bin : ndarray, (N,)
        The peak's cell in the range-Doppler map.
    elevation_rad : ndarray or None
        The 2-D beamformer's elevation (arrays with elevation extent); None: azimuth only.
    angle_peak, angle_level_db : ndarray or None
        The direction's rank among its cell's angle peaks (0: the strongest; ``radar.peaks``)
        and its spectrum's level relative to the strongest; None: one direction per cell.
    """

    range_m: np.ndarray
    velocity_mps: np.ndarray
    angle_rad: np.ndarray
    power_db: np.ndarray  # integrated range-Doppler power at the peak
    snr_db: np.ndarray  # peak over the CFAR noise estimate
    range_bin: np.ndarray
    doppler_bin: np.ndarray
    # elevation of the 2-D beamformer's peak (arrays with elevation extent); None: azimuth-only
    elevation_rad: np.ndarray | None = None
    # rank of the direction among its cell's angle peaks (0: the strongest; radar.peaks) and
    # its spectrum relative to the strongest (dB); None: one direction per cell
    angle_peak: np.ndarray | None = None
    angle_level_db: np.ndarray | None = None

    def __len__(self) -> int:
        return int(self.range_m.size)

    @property
    def angle_deg(self) -> np.ndarray:
        return np.degrees(self.angle_rad)

    @property
    def elevation_deg(self) -> np.ndarray:
        """Elevation (deg) per detection; 0 for an azimuth-only array."""
        if self.elevation_rad is None:
            return np.zeros_like(np.asarray(self.range_m, float))
        return np.degrees(self.elevation_rad)

    def to_dataframe(self):
        """One row per detection as a ``pandas.DataFrame`` (columns ``range_m``,
        ``velocity_mps``, ``angle_deg``, ``elevation_deg``, ``power_db``, ``snr_db``,
        ``range_bin``, ``doppler_bin``, ``angle_peak``)."""
        import pandas as pd
        return pd.DataFrame({"range_m": self.range_m, "velocity_mps": self.velocity_mps,
                             "angle_deg": self.angle_deg, "elevation_deg": self.elevation_deg,
                             "power_db": self.power_db,
                             "snr_db": self.snr_db, "range_bin": self.range_bin,
                             "doppler_bin": self.doppler_bin, "angle_peak": self.peak_rank})

    @property
    def peak_rank(self) -> np.ndarray:
        """Rank of each detection's direction among its cell's angle peaks (0: strongest)."""
        if self.angle_peak is None:
            return np.zeros(len(self), int)
        return np.asarray(self.angle_peak)

    @property
    def primary(self) -> np.ndarray:
        """Mask of the detections that are their cell's strongest angle peak."""
        return self.peak_rank == 0


def range_doppler(cube: AdcCube) -> RangeDoppler:
    """Windowed range and Doppler FFTs of the cube and the power map.

    ``scipy.fft`` on the cube viewed as (sample, loop, channel): the FFTs write the (R, D, V)
    layout the detections read, so no transposing copy. One thread (``workers=1``): pocketfft's
    thread pool joins its threads before every ``fork`` and could hang there, and the
    commands fork (the design's and calibration's pools, the report's 3D view); a second
    thread saved under 1 ms a frame. The transforms run in double precision (the spectrum is stored as complex64):
    single-precision FFTs leave rounding spurs about 150 dB below a noise-free target that
    CFAR detects against the even lower rounding floor around them. The power sums |X|^2
    of the stored spectrum over the channels in float64."""
    import scipy.fft as sfft  # here: `rtsgeom info` imports this module but needs no FFT
    radar = cube.radar
    n_l, _, n_s = cube.data.shape
    w_r = window(radar.range_window, n_s)
    w_d = window(radar.doppler_window, n_l)
    x = sfft.fft((cube.data * w_r).transpose(2, 0, 1), axis=0, workers=1)  # (R, L, V)
    x *= w_d[None, :, None]
    x = sfft.fft(x, axis=1, workers=1, overwrite_x=True)
    spec = np.ascontiguousarray(np.fft.fftshift(x, axes=1), dtype=np.complex64)  # (R, D, V)
    re_im = spec.view(np.float32)
    power = np.einsum("rdk,rdk->rd", re_im, re_im, dtype=np.float64)
    return RangeDoppler(spec, power, *spectrum_axes(radar))


def spectrum_axes(radar: RadarConfig) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The range-Doppler map's axes: range (R,) m, radial velocity (D,) m/s and slow-time
    frequency per TDM cycle (D,) Hz, the Doppler axis fftshifted (read-only arrays)."""
    n_s, n_l = radar.samples_per_chirp, radar.chirps_per_tx
    f_beat = np.arange(n_s) * radar.adc_rate_hz / n_s
    rng = f_beat * c / (2 * radar.slope_hz_per_s)
    nu = np.fft.fftshift(np.fft.fftfreq(n_l, d=radar.tdm_cycle_s))
    vel = nu * c / (2 * radar.f_c_hz)
    return frozen(rng), frozen(vel), frozen(nu)


def range_doppler_power(data: np.ndarray, radar: RadarConfig) -> np.ndarray:
    """The power maps (..., R, D) of a batch of ADC cubes (..., L, V, N): the windows, FFTs
    (double precision), complex64 spectrum and channel sum of :func:`range_doppler`, over
    any leading axes (e.g. one cube per echo, :func:`rtsgeom.radar.fmcw.synthesize_each`)."""
    import scipy.fft as sfft
    n_l, n_s = data.shape[-3], data.shape[-1]
    w_r = window(radar.range_window, n_s)
    w_d = window(radar.doppler_window, n_l)
    x = sfft.fft(data * w_r, axis=-1)  # (..., L, V, R)
    x *= w_d[:, None, None]
    x = sfft.fft(x, axis=-3, overwrite_x=True)  # (..., D, V, R)
    spec = np.fft.fftshift(x, axes=-3).astype(np.complex64)  # stored as range_doppler's
    power = (spec.real.astype(np.float64) ** 2 + spec.imag.astype(np.float64) ** 2).sum(-2)
    return np.swapaxes(power, -1, -2)  # (..., R, D)


def _steering_of(rut: RutArray | Steering, radar: RadarConfig | None) -> Steering:
    return rut if isinstance(rut, Steering) else Steering.build(rut, radar)


def angle_spectrum(snapshots: np.ndarray, rut: RutArray | Steering, radar: RadarConfig | None,
                   angles_rad: np.ndarray) -> np.ndarray:
    """Beamformer power |sum_v w_v x_v exp(j k x_v sin alpha)|^2 (eq. 14):
    :meth:`Steering.power` at azimuths ``angles_rad`` (A,).

    ``snapshots`` (..., V) over all virtual channels (the azimuth row is selected here);
    returns (..., A). ``rut``: the RuT array (with ``radar``) or its :class:`Steering`. A 2-D
    steering (D = 2) is cut at elevation 0.
    """
    st = _steering_of(rut, radar)
    a = np.asarray(angles_rad, float)
    if st.dims == 2:
        a = np.stack([a, np.zeros_like(a)], axis=-1)
    return st.power(snapshots, st.directions(a))


def estimate_angles(snapshots: np.ndarray, rut: RutArray | Steering,
                    radar: RadarConfig | None = None) -> np.ndarray:
    """Peak of the beamformer per snapshot (..., V) -> (...,) radians (:meth:`Steering.search`:
    grid search, zoom, parabolic interpolation; ~1e-6 deg on noise-free data)."""
    return _steering_of(rut, radar).search(snapshots)


def tdm_compensate(snapshots: np.ndarray, doppler_hz, rut: RutArray,
                   radar: RadarConfig) -> np.ndarray:
    """Remove the Tx-switching phase 2 pi f_D s T_rep of TDM slot s (snapshots (..., V))."""
    ph = -2j * np.pi * np.asarray(doppler_hz)[..., None] * rut.virtual_slot * radar.chirp_repetition_s
    return snapshots * np.exp(ph)


def detect(rd: RangeDoppler, cube: AdcCube) -> Detections:
    """CFAR detections with sub-bin range/velocity and a refined angle per detection."""
    mask, noise = cfar_mask(rd.power, cube.radar.cfar)
    r_i, d_i = np.nonzero(mask)
    n_r, n_d = rd.power.shape
    logp = np.log(np.maximum(rd.power, 1e-300))
    cells = PeakCells(
        (logp[(r_i - 1) % n_r, d_i], logp[r_i, d_i], logp[(r_i + 1) % n_r, d_i]),
        (logp[r_i, (d_i - 1) % n_d], logp[r_i, d_i], logp[r_i, (d_i + 1) % n_d]),
        rd.spectrum[r_i, d_i, :], rd.power[r_i, d_i], noise[r_i, d_i], r_i, d_i)
    return detections_at(cells, (rd.range_m, rd.velocity_mps, rd.doppler_hz), cube.radar,
                         cube.rut, cube.steering)


@dataclass(frozen=True)
class PeakCells:
    """The cells CFAR passed, as :func:`detections_at` reads them.

    Attributes
    ----------
    range_logp, doppler_logp : tuple of three ndarray, (n,)
        The log power of each cell's lower neighbour, itself and its upper neighbour along
        the range and the Doppler axis.
    snapshots : ndarray, (n, V)
        The cells' spectrum over the virtual channels.
    power, noise : ndarray, (n,)
        The cells' power and CFAR noise estimate.
    range_bin, doppler_bin : ndarray, (n,) int
        The cells' indices in the map (Doppler fftshifted).
    """

    range_logp: tuple
    doppler_logp: tuple
    snapshots: np.ndarray
    power: np.ndarray
    noise: np.ndarray
    range_bin: np.ndarray
    doppler_bin: np.ndarray


def detections_at(cells: PeakCells, axes, radar: RadarConfig, rut: RutArray,
                  steering: Steering) -> Detections:
    """The detections of the cells CFAR passed (:class:`PeakCells`): sub-bin range and velocity
    by a parabola through the log power of each cell and its two neighbours along the axis,
    the TDM-compensated snapshots beamformed (:func:`~rtsgeom.radar.peaks.angle_peaks`: one
    row per direction, each cell's rows together, strongest first); ``axes`` the map's
    (:func:`spectrum_axes`). The arithmetic of :func:`detect`, whatever holds the cells (a
    whole map, or the windows of :func:`rtsgeom.radar.windowed.detect_near`)."""
    r_i, d_i, power, noise = cells.range_bin, cells.doppler_bin, cells.power, cells.noise
    range_logp, doppler_logp, snapshots = cells.range_logp, cells.doppler_logp, cells.snapshots
    range_m, _, doppler_hz = axes
    dr = _parabolic(*range_logp)
    dd = _parabolic(*doppler_logp)
    range_step = range_m[1] - range_m[0]
    nu_step = doppler_hz[1] - doppler_hz[0]
    nu = doppler_hz[d_i] + dd * nu_step
    snaps = tdm_compensate(snapshots, nu, rut, radar)
    st = steering
    k_max = int(radar.angle_peaks_max)
    ang, level = angle_peaks(st, snaps, k_max, float(radar.angle_peak_threshold))
    # one row per direction, each cell's rows together, strongest first
    cell, rank = np.nonzero(np.isfinite(level))
    ang = ang[cell, rank]
    elev = None
    if st.dims == 2:  # 2-D beamforming (array with elevation extent)
        ang, elev = ang[..., 0], frozen(ang[..., 1])
    r_i, d_i = r_i[cell], d_i[cell]
    return Detections(
        range_m=frozen(range_m[r_i] + dr[cell] * range_step),
        velocity_mps=frozen(nu[cell] * c / (2 * radar.f_c_hz)),
        angle_rad=frozen(ang),
        power_db=frozen(10 * np.log10(power[cell])),
        snr_db=frozen(10 * np.log10(power[cell] / noise[cell])),
        range_bin=frozen(r_i), doppler_bin=frozen(d_i), elevation_rad=elev,
        angle_peak=frozen(rank) if k_max > 1 else None,
        angle_level_db=frozen(level[cell, rank]) if k_max > 1 else None,
    )


def nearest_detection(det: Detections, rd: RangeDoppler, range_m: float,
                      velocity_mps: float = 0.0, bins: int = 2) -> int | None:
    """Index of the strongest detection within ``bins`` range and Doppler bins of a set-point
    (its cell's strongest direction), or None."""
    dr = rd.range_m[1] - rd.range_m[0]
    dv = rd.velocity_mps[1] - rd.velocity_mps[0]
    near = ((np.abs(det.range_m - range_m) <= bins * dr)
            & (np.abs(det.velocity_mps - velocity_mps) <= bins * dv) & det.primary)
    if not np.any(near):
        return None
    return int(np.flatnonzero(near)[np.argmax(det.power_db[near])])


def range_angle_map(rd: RangeDoppler, cube: AdcCube, angles_rad: np.ndarray) -> np.ndarray:
    """Beamformer power over (range, angle), each range bin at its strongest Doppler bin.

    Parameters
    ----------
    rd : RangeDoppler
        The frame's range-Doppler spectrum.
    cube : AdcCube
        The ADC cube it came from (its RuT, radar and steering: the beamformer).
    angles_rad : ndarray, (A,)
        The azimuths to evaluate, radar frame.

    Returns
    -------
    ndarray, (R, A)
        The angle spectrum's power per range bin and azimuth, TDM motion compensated at
        the bin's strongest Doppler bin.
    """
    d_best = np.argmax(rd.power, axis=1)
    r = np.arange(rd.power.shape[0])
    snaps = tdm_compensate(rd.spectrum[r, d_best, :], rd.doppler_hz[d_best], cube.rut, cube.radar)
    return angle_spectrum(snaps, cube.steering, None, angles_rad)


def process(cube: AdcCube) -> tuple[RangeDoppler, Detections]:
    rd = range_doppler(cube)
    return rd, detect(rd, cube)


def refine_angles(snapshots: np.ndarray, rut: RutArray | Steering, radar: RadarConfig | None,
                  start_rad, iterations: int = 4, *, return_converged: bool = False):
    """Beamformer peak per snapshot (..., V) -> (...,) radians, by Newton's method from
    ``start_rad`` (broadcast to the snapshots): the fast path of :func:`estimate_angles` when
    the peak is known to lie near the start (e.g. a synthesized target near its set angle).
    :meth:`Steering.peak` in azimuth (u = sin alpha): global check on a grid, restart from the
    grid's maximum, and what still fails from :func:`estimate_angles`. ``return_converged``
    also returns a mask, False where :func:`estimate_angles` was used.
    """
    st = _steering_of(rut, radar)
    u, ok = st.peak(snapshots, st.directions(start_rad), iterations)
    out = np.arcsin(np.clip(u[..., 0], -1.0, 1.0))
    return (out, ok) if return_converged else out
