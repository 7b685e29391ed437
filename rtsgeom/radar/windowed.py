"""A frame's detections near given cells, without the full range-Doppler map: the fast path.

The chain is linear up to the CFAR, so the spectrum of a frame is the sum over its echoes of
separable products (eq. 15/16 with the exact geometry): per virtual channel v and echo e the
windowed Doppler DFT of its slow-time phasors (TDM slot timing included) times the windowed
range DFT of its beat tone (the fractional-delay FIR's ripple included), with the same factors
:func:`~rtsgeom.radar.fmcw.synthesize` multiplies into the cube. Only the cells a frame's
verdicts depend on are formed: around each target, the cells a detection within the gate can
sit in, their CFAR training rings and the neighbours of the local-maximum test and of the
parabolic interpolation. On those windows: the CFAR (CA's ring mean at the cells under test
from a summed-area table of each window, :func:`_ca_noise`; OS by the map's own filter on the
windows side by side), the local-maximum test, and the per-detection arithmetic of
:func:`~rtsgeom.radar.processing.detect` (:func:`~rtsgeom.radar.processing.detections_at`).

Noise, where the frame has it, is the full chain's realisation (the same generator and
draws), transformed by the same FFTs and added on the windows; the range-Doppler map of the
echoes is never formed.

A frame is outside the fast path (``reason`` is returned and the caller runs the full chain)
where a cell under test lies within :data:`MARGIN_DB` of its CFAR threshold or within
:data:`TIE` of a neighbour's power (rounding decides those in either chain), and where its
targets' windows together hold more cells than the map (many targets: the full chain is then
cheaper, and the windows' memory stays below the map's).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.constants import c as c0

from ..geometry import RutArray
from ..scene import RadarConfig
from ..rts.channels import Echoes
from .._lib.util import tones
from .channels import received_amplitude
from .fmcw import AdcCube, beat_phase0, chirp_start_s
from .cfar import cfar_mask
from .processing import Detections, PeakCells, detections_at, range_doppler, spectrum_axes
from .steering import Steering
from .windows import window

__all__ = ["MARGIN_DB", "TIE", "MapAxes", "cell_centres", "detect_near", "noise_spectrum"]

#: a cell under test this close to its CFAR threshold (dB) is left to the full chain
MARGIN_DB = 0.01
#: a local-maximum test this close (relative power) is left to the full chain
TIE = 1e-6
#: complex elements of the windows' range and Doppler factors formed at once (a block of
#: targets; 2**22: 64 MiB)
BLOCK_ELEMENTS = 2 ** 22


@dataclass(frozen=True)
class MapAxes:
    """The range-Doppler map's axes without the map (what the association measures its cells
    in where the fast path formed no map): range (R,) m, velocity (D,) m/s, slow-time
    frequency (D,) Hz, the Doppler axis fftshifted."""

    range_m: np.ndarray
    velocity_mps: np.ndarray
    doppler_hz: np.ndarray

    @classmethod
    def of(cls, radar: RadarConfig) -> "MapAxes":
        return cls(*spectrum_axes(radar))


def cell_centres(radar: RadarConfig, range_m, velocity_mps) -> np.ndarray:
    """Fractional (range bin, Doppler bin) (T, 2) of ranges and radial velocities (T,) in the
    map's indices (Doppler fftshifted; cyclic, as the map)."""
    r = np.asarray(range_m, float).ravel()
    v = np.asarray(velocity_mps, float).ravel()
    n_s, n_l = radar.samples_per_chirp, radar.chirps_per_tx
    range_step = c0 * radar.adc_rate_hz / (2 * radar.slope_hz_per_s * n_s)
    nu = 2 * v * radar.f_c_hz / c0
    return np.c_[(r / range_step) % n_s, (nu * n_l * radar.tdm_cycle_s + n_l // 2) % n_l]


def noise_spectrum(noise: np.ndarray, radar: RadarConfig, rut: RutArray) -> np.ndarray:
    """The range-Doppler spectrum (R, D, V) of a noise cube (L, V, N), through
    :func:`~rtsgeom.radar.processing.range_doppler`'s windows and FFTs."""
    return range_doppler(AdcCube(noise, radar, rut)).spectrum


def _axis_window(centres: np.ndarray, half: int, n: int) -> np.ndarray:
    """Map indices (T, W) of windows of ``2 half + 1`` cells around the rounded ``centres``
    (cyclic), or the whole axis in its order where that is shorter."""
    if 2 * half + 1 >= n:
        return np.broadcast_to(np.arange(n), (centres.size, n))
    c = np.rint(centres).astype(int)
    return (c[:, None] + np.arange(-half, half + 1)[None, :]) % n


def detect_near(echoes: Echoes, radar: RadarConfig, rut: RutArray, steering: Steering,
                centres, gate: int, noise_spec: np.ndarray | None = None
                ) -> tuple[Detections | None, str | None]:
    """The detections of the full chain whose cell lies within ``gate + 1`` range and Doppler
    bins of a centre.

    Parameters
    ----------
    echoes : Echoes
        Every echo of the frame (targets, setup reflections, ghosts).
    radar, rut : RadarConfig, RutArray
        The radar and its array.
    steering : Steering
        The RuT's beamformer (the cube's).
    centres : array_like, shape (T, 2)
        Each target's (range bin, Doppler bin) in the map's indices (Doppler fftshifted),
        fractional.
    gate : int
        The association's gate in bins: every detection that can be within it of a centre is
        found.
    noise_spec : ndarray, shape (R, D, V), optional
        The frame's noise spectrum (:func:`noise_spectrum`); None: noise-free.

    Returns
    -------
    detections : Detections or None
        In the full chain's order (range bin, then Doppler bin); None where outside the fast
        path.
    reason : str or None
        Why the frame is outside the fast path (None: inside).
    """
    n_s, n_l = radar.samples_per_chirp, radar.chirps_per_tx
    c = np.asarray(centres, float).reshape(-1, 2)
    gr, gd = radar.cfar.guard_cells
    tr, td = radar.cfar.training_cells
    k = int(gate) + 1  # cells under test: every cell a detection within the gate can sit in
    rows = _axis_window(c[:, 0], k + max(gr + tr, 1), n_s)  # (T, Rw)
    cols = _axis_window(c[:, 1], k + max(gd + td, 1), n_l)  # (T, Dw)
    if rows.size * cols.shape[1] > n_s * n_l:  # many targets: windows past the map's size
        return None, ("the targets' windows hold more cells than the map (the full chain is "
                      "cheaper)")
    spec = _window_spectrum(echoes, radar, rut, rows, cols)  # (T, Rw, Dw, V)
    if noise_spec is not None:
        spec = spec + noise_spec[rows[:, :, None], cols[:, None, :]]
    spec = np.ascontiguousarray(spec, dtype=np.complex64)
    re_im = spec.view(np.float32)
    power = np.einsum("trdk,trdk->trd", re_im, re_im, dtype=np.float64)
    cut = ((_distance(rows, c[:, 0], n_s) <= k)[:, :, None]
           & (_distance(cols, c[:, 1], n_l) <= k)[:, None, :])
    nb = _neighbour_max(power)
    if radar.cfar.kind == "ca" and rows.shape[1] < n_s and cols.shape[1] < n_l:
        noise = _ca_noise(power, k, radar.cfar)
        thr = noise * 10 ** (radar.cfar.threshold_db / 10)
        mask = cut & (power > thr) & (power >= nb)
    else:  # the map's own CFAR on the windows side by side
        stacked = np.moveaxis(power, 0, -1)  # (Rw, Dw, T): the map's axes first
        mask, noise = cfar_mask(stacked, radar.cfar, map_shape=(n_s, n_l))
        mask, noise = np.moveaxis(mask, -1, 0), np.moveaxis(noise, -1, 0)
    reason = _marginal(power, noise, nb, cut, radar.cfar.threshold_db)
    if reason is not None:
        return None, reason
    t_i, r_w, d_w = np.nonzero(mask & cut)
    r_i, d_i = rows[t_i, r_w], cols[t_i, d_w]
    # one detection per map cell (windows overlap), in the map's row-major order
    _, first = np.unique(r_i * n_l + d_i, return_index=True)
    t_i, r_w, d_w, r_i, d_i = (a[first] for a in (t_i, r_w, d_w, r_i, d_i))
    logp = np.log(np.maximum(power, 1e-300))
    nr, nd = rows.shape[1], cols.shape[1]
    triple = lambda dr, dd: logp[t_i, (r_w + dr) % nr, (d_w + dd) % nd]  # noqa: E731
    axes = spectrum_axes(radar)
    cells = PeakCells(
        (triple(-1, 0), triple(0, 0), triple(1, 0)), (triple(0, -1), triple(0, 0), triple(0, 1)),
        spec[t_i, r_w, d_w], power[t_i, r_w, d_w], noise[t_i, r_w, d_w], r_i, d_i)
    det = detections_at(cells, axes, radar, rut, steering)
    return det, None


def _distance(idx: np.ndarray, centre: np.ndarray, n: int) -> np.ndarray:
    """Cyclic distance (T, W) of window cells ``idx`` from each rounded centre (T,)."""
    d = np.abs(idx - np.rint(centre).astype(int)[:, None]) % n
    return np.minimum(d, n - d)


def _window_spectrum(echoes: Echoes, radar: RadarConfig, rut: RutArray, rows: np.ndarray,
                     cols: np.ndarray) -> np.ndarray:
    """The echoes' spectrum (T, Rw, Dw, V) complex128 on the windows: per channel the product
    of each echo's windowed range DFT (its fast-time factor's FFT) and windowed Doppler DFT (its
    slow-time factor's FFT, fftshifted), summed over the echoes (one batched product)."""
    import scipy.fft as sfft  # as processing.range_doppler (one thread: the commands fork)
    n_v = rut.num_virtual
    if len(echoes) == 0:
        return np.zeros(rows.shape + cols.shape[1:] + (n_v,), complex)
    n_s = radar.samples_per_chirp
    phi0 = beat_phase0(echoes, radar)  # (E, V)
    amp = received_amplitude(echoes.amplitude, radar, rut, phi0) * np.exp(1j * phi0)
    # slow time: the chirps' start times (TDM slots) -> A[v, l, e]
    t_c = chirp_start_s(radar, rut)  # (L, V)
    a = amp.T[:, None, :] * np.exp(2j * np.pi * echoes.doppler_hz[None, None, :]
                                    * t_c.T[:, :, None])
    # fast time: each echo's beat tone at the ADC's instants (and the FIR's ripple)
    beat = radar.slope_hz_per_s * echoes.tau_s.T + echoes.doppler_hz[None, :]  # (V, E)
    f = tones(beat, radar.adc_start_s, 1.0 / radar.adc_rate_hz, n_s)  # (V, E, N)
    w_r = window(radar.range_window, n_s)
    if echoes.fast_gain is not None:
        f *= echoes.fast_gain[None] * w_r
    else:
        f *= w_r
    w_d = window(radar.doppler_window, radar.chirps_per_tx)
    fr = sfft.fft(f, axis=2, workers=1, overwrite_x=True)  # (V, E, R)
    ad = np.fft.fftshift(sfft.fft(a * w_d[None, :, None], axis=1, workers=1), axes=1)
    n_t, n_rw, n_dw = rows.shape[0], rows.shape[1], cols.shape[1]
    x = np.empty((n_t, n_v, n_rw, n_dw), complex)
    # the windows' factors in blocks of targets: at most ~BLOCK_ELEMENTS each (memory)
    step = max(1, BLOCK_ELEMENTS // (n_v * len(echoes) * (n_rw + n_dw)))
    for t0 in range(0, n_t, step):
        t = slice(t0, t0 + step)
        fr_w = np.moveaxis(fr[:, :, rows[t]], 2, 0)  # (t, V, E, Rw)
        ad_w = np.moveaxis(ad[:, cols[t], :], 1, 0)  # (t, V, Dw, E)
        np.matmul(np.swapaxes(fr_w, -1, -2), np.swapaxes(ad_w, -1, -2), out=x[t])
    return np.moveaxis(x, 1, -1)  # (T, Rw, Dw, V)


def _neighbour_max(power: np.ndarray) -> np.ndarray:
    """The largest of each window cell's eight neighbours (T, Rw, Dw) (cyclic in the window:
    the cells under test have theirs inside it)."""
    nb = np.full(power.shape, -np.inf)
    for dr in (-1, 0, 1):
        for dd in (-1, 0, 1):
            if dr or dd:
                np.maximum(nb, np.roll(power, (dr, dd), axis=(1, 2)), out=nb)
    return nb


def _ca_noise(power: np.ndarray, k: int, cfar) -> np.ndarray:
    """CA-CFAR's noise estimate at the central (2k + 1)^2 cells of each window (T, Rw, Dw),
    +inf elsewhere: the training ring's mean, its sum as the outer rectangle's less the guard
    rectangle's from a summed-area table of the window. The window holds the target's main lobe
    and its ring's sidelobes, so the table's differences lose at most ~1e-16 of the window's
    power, below 1e-6 of any ring sum (the map's CFAR sums without differences, over a whole
    map whose quiet cells a difference would drown); a cell that close to its threshold is left
    to the full chain (:data:`MARGIN_DB`)."""
    gr, gd = cfar.guard_cells
    tr, td = cfar.training_cells
    hr, hd = gr + tr, gd + td
    n_t, n_r, n_d = power.shape
    sat = np.zeros((n_t, n_r + 1, n_d + 1))
    np.cumsum(np.cumsum(power, axis=1), axis=2, out=sat[:, 1:, 1:])
    i = (n_r - 1) // 2 + np.arange(-k, k + 1)  # the windows' centres +- k
    j = (n_d - 1) // 2 + np.arange(-k, k + 1)

    def box(a: int, b: int) -> np.ndarray:  # sums over rows i +- a, columns j +- b
        r0, r1, c0, c1 = i - a, i + a + 1, j - b, j + b + 1
        return ((sat[:, r1[:, None], c1] - sat[:, r0[:, None], c1])
                - (sat[:, r1[:, None], c0] - sat[:, r0[:, None], c0]))

    count = (2 * hr + 1) * (2 * hd + 1) - (2 * gr + 1) * (2 * gd + 1)
    noise = np.full(power.shape, np.inf)
    noise[:, i[:, None], j] = (box(hr, hd) - box(gr, gd)) / count
    return noise


def _marginal(power, noise, nb, cut, threshold_db: float) -> str | None:
    """Why a window's verdicts are left to the full chain: a cell under test within
    :data:`MARGIN_DB` of the CFAR threshold, or a local maximum decided by a tie (``nb`` each
    cell's largest neighbour)."""
    p = power[cut]
    margin = 10 * np.log10(np.maximum(p, 1e-300) / np.maximum(noise[cut], 1e-300)) - threshold_db
    nb = nb[cut]
    tie = np.abs(p - nb) <= TIE * np.maximum(p, nb)
    peak = p >= nb * (1 - TIE)
    if np.any(peak & (np.abs(margin) < MARGIN_DB)):
        return f"a cell within {MARGIN_DB:g} dB of the CFAR threshold"
    if np.any(tie & (margin > -MARGIN_DB)):
        return "a local maximum decided by rounding (two equal cells)"
    return None
