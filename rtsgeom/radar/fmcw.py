"""The RuT's FMCW TDM-MIMO receiver: echoes -> complex IF ADC cube (stage 4).

For echo e on virtual channel v = (Tx slot s, Rx k), chirp loop l and fast-time sample n the
beat signal is (paper eq. 8, with the RTS Doppler mixer added)::

    x[l, v, n] = sum_e a[e, v] g[e, n] exp{ j 2 pi [ f_c tau_c[e, v] + f_if[e] tau_if[e]
                                            + S tau[e, v] t_n - S tau[e, v]^2 / 2
                                            + f_D[e] (t_c[l, s] + t_n) ] }

with ``tau = tau_c + tau_if``, ``t_n = t_adc + n / f_adc`` (time since ramp start),
``t_c = (l N_tx + s) T_rep``, ``g`` the fractional-delay FIR's gain along the chirp
(``Echoes.fast_gain``, 1 for an ideal delay) (TDM: the Tx take turns chirp by chirp, so a moving target carries
the Tx-switching phase 2 pi f_D s T_rep) and ``S = B / T``.

``f_D`` is the RTS's frequency shift (2 f_c v / c0 with f_c the start frequency,
:class:`rtsgeom.rts.channels.RtsProgram`), so the slow-time frequency at the target's range bin is f_D
exactly. A delay that moves at 2 v / c0 instead (a real target, :func:`synthesize_exact` with
``delay_rate``) gives 2 v f_mid / c0 with f_mid = f_c + S (t_mid - tau), t_mid the middle of
the ADC window (README "Velocity and the carrier frequency"; tests/radar/test_velocity_frequency.py).

Every echo is separable into a slow-time factor and a fast-time factor, so for each virtual
channel the cube is a complex matrix product ``X_v = A_v @ F_v`` with ``A_v`` (loops x echoes)
and ``F_v`` (echoes x samples): one batched GEMM instead of one ``exp`` over the full cube per
echo. Phases are formed in float64; the cube is complex64.

Same seed, same bytes, whatever the thread count: a multi-threaded BLAS splits the GEMM's sum
over echoes differently with ``OMP_NUM_THREADS=1`` and ``=2`` (6 % of the samples differed, at
4e-7 relative), so the GEMM runs single-threaded (``threadpoolctl``), which fixes its reduction
order; it is small (8 matrices of 120 x E x 512), so this costs ~1 ms.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .._lib.util import single_threaded_blas
from ..geometry import RutArray
from ..rts.channels import Echoes
from .channels import received_amplitude
from ..scene import RadarConfig
from .steering import Steering

__all__ = ["AdcCube", "fast_time_s", "chirp_start_s", "beat_phase0", "synthesize",
           "synthesize_each",
           "synthesize_exact", "add_noise", "noise_cube"]


@dataclass(frozen=True)
class AdcCube:
    """Complex IF samples ``data[loop, virtual_channel, sample]`` (complex64).

    Attributes
    ----------
    data : (loops, V, samples) complex64
        The IF samples per chirp loop, virtual channel and fast-time sample.
    radar : RadarConfig
    rut : RutArray
    clipped : int
        Samples the ADC clipped (with [radar.link]).
    """

    data: np.ndarray
    radar: RadarConfig
    rut: RutArray
    clipped: int = 0  # samples the ADC clipped (with [radar.link]; rtsgeom.radar.link.adc_convert)

    @property
    def shape(self) -> tuple[int, int, int]:
        return self.data.shape

    @cached_property
    def steering(self) -> Steering:
        """The RuT's beamformer (built once per cube): 2-D when the virtual array has
        elevation extent (:meth:`Steering.auto`)."""
        return Steering.auto(self.rut, self.radar)

    def to_xarray(self):
        """The cube as an ``xarray.DataArray`` with dims ``chirp_loop``, ``virtual_channel``
        and ``sample``; coordinates ``fast_time_s`` (since ramp start) on the samples and
        ``tx_slot``, ``rx`` on the virtual channels (v = tx_slot * num_rx + rx)."""
        import xarray as xr
        n_l, n_v, _ = self.data.shape
        v = np.arange(n_v)
        return xr.DataArray(self.data, dims=("chirp_loop", "virtual_channel", "sample"),
                            coords={"chirp_loop": np.arange(n_l), "virtual_channel": v,
                                    "tx_slot": ("virtual_channel", v // self.rut.num_rx),
                                    "rx": ("virtual_channel", v % self.rut.num_rx),
                                    "fast_time_s": ("sample", fast_time_s(self.radar))},
                            name="adc", attrs={"long_name": "complex IF samples"})


def fast_time_s(radar: RadarConfig) -> np.ndarray:
    """Sample instants since the start of the ramp, (N,)."""
    return radar.adc_start_s + np.arange(radar.samples_per_chirp) / radar.adc_rate_hz


def chirp_start_s(radar: RadarConfig, rut: RutArray) -> np.ndarray:
    """Start time of the chirp that feeds each (loop, virtual channel), (L, V)."""
    n_tx = len(rut.tx_order)
    loops = np.arange(radar.chirps_per_tx)[:, None]
    return (loops * n_tx + rut.virtual_slot[None, :]) * radar.chirp_repetition_s


def beat_phase0(echoes: Echoes, radar: RadarConfig) -> np.ndarray:
    """The part of the beat phase (eq. 8) that varies neither with fast nor slow time, (E, V):
    ``2 pi [f_c tau_c + f_if tau_if - S tau^2 / 2]``."""
    tau = echoes.tau_s
    return 2 * np.pi * (radar.f_c_hz * echoes.tau_air_s
                        + (echoes.f_if_hz * echoes.tau_if_s)[:, None]
                        - 0.5 * radar.slope_hz_per_s * tau ** 2)


def _single_threaded_blas():
    """BLAS limited to one thread (:func:`rtsgeom._lib.util.single_threaded_blas`)."""
    return single_threaded_blas()


def synthesize(echoes: Echoes, radar: RadarConfig, rut: RutArray) -> AdcCube:
    """Noise-free ADC cube of all echoes (batched GEMM over virtual channels)."""
    a, f = _slow_fast(echoes, radar, rut)
    with _single_threaded_blas():  # fixed reduction order: bytes independent of thread count
        data = np.matmul(a, f)  # (V, L, N)
    return AdcCube(np.ascontiguousarray(data.transpose(1, 0, 2)), radar, rut)


def synthesize_each(echoes: Echoes, radar: RadarConfig, rut: RutArray) -> np.ndarray:
    """Each echo's own noise-free ADC cube (E, L, V, N), complex64: the terms
    :func:`synthesize` sums (for E small: E times a cube's memory)."""
    a, f = _slow_fast(echoes, radar, rut)
    return np.einsum("vle,ven->elvn", a, f)


def _slow_fast(echoes: Echoes, radar: RadarConfig, rut: RutArray):
    """The separable factors of the echoes' beat (eq. 8): slow time A (V, L, E) and fast
    time F (V, E, N), complex64; the cube is their product summed over the echoes."""
    s = radar.slope_hz_per_s
    t_n = fast_time_s(radar)  # (N,)
    t_c = chirp_start_s(radar, rut)  # (L, V)
    tau = echoes.tau_s  # (E, V)
    f_d = echoes.doppler_hz  # (E,)
    phi0 = beat_phase0(echoes, radar)
    # slow time: A[v, l, e] = a[e, v] exp(j (phi0[e, v] + 2 pi f_D[e] t_c[l, v]))
    slow = phi0.T[:, None, :] + 2 * np.pi * f_d[None, None, :] * t_c.T[:, :, None]
    amp = received_amplitude(echoes.amplitude, radar, rut, phi0)  # the RuT's own channels
    a = (amp.T[:, None, :] * np.exp(1j * slow)).astype(np.complex64)
    # fast time: F[v, e, n] = exp(j 2 pi (S tau[e, v] + f_D[e]) t_n)
    beat = s * tau.T + f_d[None, :]  # (V, E)
    f = np.exp(2j * np.pi * beat[:, :, None] * t_n[None, None, :])
    if echoes.fast_gain is not None:  # the fractional-delay FIR's ripple along the chirp
        f = f * echoes.fast_gain[None]
    return a, f.astype(np.complex64)


def synthesize_exact(echoes: Echoes, radar: RadarConfig, rut: RutArray,
                     delay_rate=None) -> AdcCube:
    """Reference synthesis: the full beat phase of every echo at every sample, one echo at a
    time, optionally with range migration within the frame.

    ``delay_rate`` (E,) in s/s lets each echo's IF delay drift, ``tau_if(t) = tau_if +
    delay_rate * t`` with ``t`` the time since the frame start (an RTS that updates its delay
    buffer continuously, 2 v / c0 for a target at v), which breaks the separability that
    :func:`synthesize` relies on. With ``delay_rate = 0`` both agree to complex64 precision
    (tested). Cost: one ``exp`` over the whole cube per echo; use it to validate, not to run.
    """
    s = radar.slope_hz_per_s
    t_n = fast_time_s(radar)[None, None, :]  # (1, 1, N)
    t_c = chirp_start_s(radar, rut)[:, :, None]  # (L, V, 1)
    rate = np.zeros(len(echoes)) if delay_rate is None else np.asarray(delay_rate, float)
    out = np.zeros((radar.chirps_per_tx, rut.num_virtual, radar.samples_per_chirp), np.complex64)
    # the RuT's own channels
    amp = received_amplitude(echoes.amplitude, radar, rut, beat_phase0(echoes, radar))
    for e in range(len(echoes)):
        tau_air = echoes.tau_air_s[e][None, :, None]  # (1, V, 1)
        tau_if = echoes.tau_if_s[e] + rate[e] * (t_c + t_n)
        tau = tau_air + tau_if
        phase = 2 * np.pi * (radar.f_c_hz * tau_air + echoes.f_if_hz[e] * tau_if
                             + s * tau * t_n - 0.5 * s * tau ** 2
                             + echoes.doppler_hz[e] * (t_c + t_n))
        g = 1.0 if echoes.fast_gain is None else echoes.fast_gain[e][None, None, :]
        out += (amp[e][None, :, None] * g * np.exp(1j * phase)).astype(np.complex64)
    return AdcCube(out, radar, rut)


def add_noise(cube: AdcCube, noise_power: float, rng: np.random.Generator) -> AdcCube:
    """Add circular complex white Gaussian receiver noise of the given power per sample."""
    if noise_power <= 0:
        return cube
    return AdcCube(cube.data + noise_cube(cube.data.shape, noise_power, rng), cube.radar,
                   cube.rut)


def noise_cube(shape, noise_power: float, rng: np.random.Generator) -> np.ndarray:
    """Circular complex white Gaussian noise (complex64) of the given power per sample: the
    draws :func:`add_noise` adds (the same generator calls, the same values)."""
    n = rng.standard_normal(tuple(shape) + (2,), dtype=np.float32)
    n *= np.float32(np.sqrt(noise_power / 2))
    return n.view(np.complex64)[..., 0]
