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

Mutual coupling between neighbouring Rx antennas (``rx_coupling_db``) mixes the virtual
channels of one chirp before the chains' gains, ``x' = diag(g) M x``: an error that depends on
the direction, so a compensation measured at boresight removes it there only.

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
           "rx_coupling_matrix", "channel_coupling", "channel_gain", "received_amplitude",
           "plane_wave_errors"]


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


def compensation_vector(g_virtual, rut: RutArray, range_m: float | None,
                        coupling=None) -> np.ndarray:
    """The radar's boresight compensation (..., V): 1 / (what it measured on the boresight
    reflector), ``1 / (g_v (M h)_v)``, for virtual gains ``g_virtual`` (..., V) and the
    coupling ``M`` (V, V) (None: none)."""
    h = boresight_reference(rut, range_m)
    if coupling is not None:
        h = coupling @ h
    return 1.0 / (np.asarray(g_virtual) * h)


def rx_coupling_matrix(rut: RutArray, coefficient: complex) -> np.ndarray:
    """``C = I + c A`` (N_rx, N_rx): each Rx receives ``c`` times the signals of its
    neighbours ``A`` (the Rx one smallest spacing apart)."""
    p = np.asarray(rut.rx_local, float)
    n = p.shape[0]
    if n < 2:
        return np.eye(n, dtype=complex)
    d = np.linalg.norm(p[:, None] - p[None], axis=-1)
    near = d[~np.eye(n, dtype=bool)].min()
    adj = (d <= near * (1 + 1e-6)) & ~np.eye(n, dtype=bool)
    return np.eye(n, dtype=complex) + complex(coefficient) * adj


def channel_coupling(radar: RadarConfig, rut: RutArray) -> np.ndarray | None:
    """The virtual channels' coupling ``M`` (V, V): element (slot s, Rx r) receives
    ``sum_r' C[r, r'] x(s, r')`` (the Rx of one chirp mix, :func:`rx_coupling_matrix`), or
    None without ``rx_coupling_db``."""
    ch = getattr(radar, "channels", None)
    if ch is None or ch.rx_coupling_db is None:
        return None
    c = 10 ** (ch.rx_coupling_db / 20) * np.exp(1j * ch.rx_coupling_phase_rad)
    cr = rx_coupling_matrix(rut, c)
    same_slot = rut.virtual_slot[:, None] == rut.virtual_slot[None, :]
    return np.where(same_slot, cr[rut.virtual_rx[:, None], rut.virtual_rx[None, :]], 0.0)


def channel_gain(radar: RadarConfig, rut: RutArray) -> np.ndarray | None:
    """The net complex gain (V,) of each virtual channel as the radar processes it (errors
    times its compensation; after the coupling :func:`channel_coupling`), or None for an
    ideal radar (nothing to multiply)."""
    ch = getattr(radar, "channels", None)
    if ch is None or ch.ideal:
        return None
    n_tx, n_rx = rut.tx_local.shape[0], rut.rx_local.shape[0]
    g = virtual_gain(rut, antenna_gains(ch.tx_gain_db, ch.tx_phase_rad, n_tx),
                     antenna_gains(ch.rx_gain_db, ch.rx_phase_rad, n_rx))
    if ch.compensation == "boresight":
        g = g * compensation_vector(g, rut, ch.compensation_range_m,
                                    channel_coupling(radar, rut))
    return g


def received_amplitude(amplitude, radar: RadarConfig, rut: RutArray,
                       phase0=None) -> np.ndarray:
    """Echo amplitudes (E, V) as the radar's channels deliver them: coupled
    (:func:`channel_coupling`), then times :func:`channel_gain` (the array itself for an
    ideal radar). The coupling mixes the elements' signals, phases included: ``phase0``
    (E, V) is the beat phase the caller multiplies in afterwards (``fmcw.beat_phase0``), so
    element v gets ``sum_w M_vw a_w e^{j (phi0_w - phi0_v)}``. The neighbour's beat frequency
    (S times a delay difference of picoseconds: a milliradian over the chirp) is taken as the
    element's own."""
    g = channel_gain(radar, rut)
    if g is None:
        return amplitude
    m = channel_coupling(radar, rut)
    if m is not None:
        rot = 1.0 if phase0 is None else np.exp(1j * np.asarray(phase0))
        amplitude = ((amplitude * rot) @ m.T) / rot
    return amplitude * g


def plane_wave_errors(steering, gains, angles_rad, coupling=None) -> np.ndarray:
    """Angle errors (B, P) rad of radars of virtual gains ``gains`` (B, V) after the coupling
    ``coupling`` (V, V) (None: none) on a far-field point target at each azimuth
    ``angles_rad`` (P,): the ``steering``'s peak (``radar.steering.Steering``, D = 1) of the
    plane wave ``e^{-j k p_v u}`` less the set angle. What the radar shows on a real target,
    which no RTS calibration changes. Elements outside the beamformer's row get 1 (the
    coupling mixes a Tx slot's elements, which share a row)."""
    angles_rad = np.asarray(angles_rad, float)
    st = steering
    wave = np.ones((angles_rad.size, st.mask.size), complex)
    wave[:, st.mask] = np.conj(st.steer(st.directions(angles_rad)))  # (P, V)
    if coupling is not None:
        wave = wave @ coupling.T
    return st.search(np.asarray(gains)[:, None, :] * wave[None]) - angles_rad[None]
