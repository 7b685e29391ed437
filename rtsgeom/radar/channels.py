"""The RuT's own channels: per-antenna complex gain errors and the radar's compensation.

A real MIMO radar's transmit and receive chains differ in gain and phase; virtual element
``v = (Tx t, Rx r)`` then delivers ``g_v = g_tx[t] g_rx[r]`` times what an ideal radar would
(``g = 10^(gain_db / 20) e^(j phase)``, the scene's ``[radar.channels]``). The radar's
processing beamforms as if the array were ideal (``radar.steering``), so the errors bend its
beams and move its detections.

``compensation = "boresight"`` is what the radar's SDK does (TI's
``compRangeBiasAndRxChanPhase``): a reflector at boresight is measured once, the measured
virtual-channel values ``m_v = g_v h_v`` (``h_v``: the reflector's own phase at the element,
1 in the far field, the wavefront's curvature at ``compensation_range_m``) are stored, and every
frame is multiplied by ``c_v = 1 / m_v``. The net per-channel gain is ``g_v c_v``: 1 for a
far-field measurement of angle-independent errors, ``1 / h_v`` (the curvature taken for an error)
for a near one.

Applied at one place, :func:`received_amplitude`, which every engine that turns echoes into
per-virtual-channel data goes through (the ADC-cube chain ``radar.fmcw.synthesize`` and
``synthesize_exact``, the phasor model ``radar.phasors.bin_response``): the ChannelModel, the
calibration, the tolerance tables and the identification all see the same radar. Receiver noise
is added after it at the nominal level per channel (a channel 1 dB low has a 1 dB lower SNR on a
real radar; not modelled). Without ``[radar.channels]`` (or with every value zero and no
compensation that could add an error) nothing is multiplied: outputs stay bit-identical.
"""

from __future__ import annotations

import numpy as np

from ..geometry import RutArray
from ..scene import RadarConfig

__all__ = ["antenna_gains", "virtual_gain", "boresight_reference", "compensation_vector",
           "channel_gain", "received_amplitude"]


def antenna_gains(gain_db, phase_rad, n: int) -> np.ndarray:
    """Complex gains (..., n) of ``gain_db`` / ``phase_rad`` (..., n), empty = ideal."""
    g = np.zeros(n) if np.size(gain_db) == 0 else np.asarray(gain_db, float)
    p = np.zeros(n) if np.size(phase_rad) == 0 else np.asarray(phase_rad, float)
    return 10 ** (g / 20) * np.exp(1j * p)


def virtual_gain(rut: RutArray, g_tx, g_rx) -> np.ndarray:
    """Per-virtual-element gain ``g_tx[t] g_rx[r]`` (..., V) of per-antenna gains
    ``g_tx`` (..., N_tx), ``g_rx`` (..., N_rx) (leading axes: radar draws)."""
    g_tx, g_rx = np.asarray(g_tx), np.asarray(g_rx)
    return g_tx[..., rut.virtual_tx] * g_rx[..., rut.virtual_rx]


def boresight_reference(rut: RutArray, range_m: float | None) -> np.ndarray:
    """What an ideal radar measures per virtual element (V,) on a point reflector at boresight
    at ``range_m`` (radar frame, +y forward), relative to its phase centre: ``e^{j k (|p_t -
    r| + |p_r - r| - 2 R)}`` (the beat phase grows with the path, ``radar.processing``); 1 in
    the far field (``range_m`` None)."""
    if range_m is None:
        return np.ones(rut.num_virtual, complex)
    r = np.array([0.0, float(range_m), 0.0])
    d_t = np.linalg.norm(rut.tx_local - r, axis=1)[rut.virtual_tx]
    d_r = np.linalg.norm(rut.rx_local - r, axis=1)[rut.virtual_rx]
    return np.exp(2j * np.pi / rut.wavelength_m * (d_t + d_r - 2 * float(range_m)))


def compensation_vector(g_virtual, rut: RutArray, range_m: float | None) -> np.ndarray:
    """The radar's boresight compensation (..., V): 1 / (what it measured on the boresight
    reflector), ``1 / (g_v h_v)``, for virtual gains ``g_virtual`` (..., V)."""
    return 1.0 / (np.asarray(g_virtual) * boresight_reference(rut, range_m))


def channel_gain(radar: RadarConfig, rut: RutArray) -> np.ndarray | None:
    """The net complex gain (V,) of each virtual channel as the radar processes it (errors
    times its compensation), or None for an ideal radar (nothing to multiply)."""
    ch = getattr(radar, "channels", None)
    if ch is None or ch.ideal:
        return None
    n_tx, n_rx = rut.tx_local.shape[0], rut.rx_local.shape[0]
    g = virtual_gain(rut, antenna_gains(ch.tx_gain_db, ch.tx_phase_rad, n_tx),
                     antenna_gains(ch.rx_gain_db, ch.rx_phase_rad, n_rx))
    if ch.compensation == "boresight":
        g = g * compensation_vector(g, rut, ch.compensation_range_m)
    return g


def received_amplitude(amplitude, radar: RadarConfig, rut: RutArray) -> np.ndarray:
    """Echo amplitudes (E, V) as the radar's channels deliver them: times
    :func:`channel_gain` (the array itself for an ideal radar)."""
    g = channel_gain(radar, rut)
    return amplitude if g is None else amplitude * g
