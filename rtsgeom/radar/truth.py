"""The truth twin: the same radar looking at the real scene instead of the RTS.

Every target becomes a point scatterer at its set position in free space (its set range and
direction from the nominal pose of the RuT: ``radar.position_m`` and ``radar.yaw_deg``; the
RuT itself keeps its pose errors, as it would on the road), observed by the same array, chirp,
channel errors, windows, estimator and CFAR, with the same noise realisation (seed) and noise
power as the RTS's frame. No front ends, no sheet, no cables: what the radar would detect from
the real targets. The emulation's fidelity is judged against it.

Per virtual element v = (Tx m, Rx k) the echo's over-the-air delay is the exact two-way
distance ``(|P - p_tx,m| + |P - p_rx,k|) / c0`` (the near field of the RuT's own aperture
included), its amplitude the radar equation's ``sqrt(sigma) lambda / ((4 pi)^(3/2) R^2)`` times
the RuT's element patterns towards the target. Its Doppler is a real target's: the phase across
chirps follows the carrier at the middle of the ADC window, ``f_D = 2 v f_mid / c0`` with
``f_mid = f_c + S (t_adc + (N - 1) / (2 f_adc) - tau)`` (the RTS is told ``2 v f_c / c0``, eq. 2;
the processing converts with f_c, so a real target reads ``f_mid / f_c`` fast: 0.65 % on the
bundled radar, docs/signal-model.md).
"""

from __future__ import annotations

import numpy as np
from scipy.constants import c

from ..geometry import Setup
from ..geometry.arrays import yaw_matrix
from ..geometry.patterns import scene_patterns
from ..rts.channels import EchoKind, Echoes, target_amplitude
from . import link as lk
from .fmcw import AdcCube, add_noise, synthesize

__all__ = ["target_positions", "truth_echoes", "simulate_truth"]


def target_positions(setup: Setup, targets) -> np.ndarray:
    """World positions (T, 3) of point targets at their set range, azimuth and elevation from
    the RuT's nominal pose (``radar.position_m``, ``radar.yaw_deg``)."""
    radar = setup.scene.radar
    t = list(targets)
    az = np.array([x.angle_rad for x in t], float)
    el = np.array([x.elevation_rad for x in t], float)
    r = np.array([x.range_m for x in t], float)
    local = np.c_[np.sin(az) * np.cos(el), np.cos(az) * np.cos(el), np.sin(el)] * r[:, None]
    return np.asarray(radar.position_m, float) + local.reshape(-1, 3) @ yaw_matrix(
        radar.yaw_rad).T


def truth_echoes(setup: Setup, targets, phase_rad=None) -> Echoes:
    """The echoes (T echoes x V virtual channels) of point targets at their set positions;
    ``phase_rad`` (T,), optional: an extra reflection phase per target (two real targets at
    one range are in phase at the RuT's phase centre; a scatterer's own phase moves that)."""
    scene, rut = setup.scene, setup.rut
    radar = scene.radar
    t = list(targets)
    p = target_positions(setup, t)  # (T, 3)
    d_tx = p[:, None, :] - rut.tx_world[None]  # (T, N_tx, 3) element -> target
    d_rx = p[:, None, :] - rut.rx_world[None]
    r_tx, r_rx = np.linalg.norm(d_tx, axis=-1), np.linalg.norm(d_rx, axis=-1)
    path = r_tx[:, rut.virtual_tx] + r_rx[:, rut.virtual_rx]  # (T, V) two-way distance
    rcs = np.array([x.rcs_m2 for x in t], float)
    amp = target_amplitude(0.5 * path, rcs[:, None], rut.wavelength_m).astype(complex)
    pat = scene_patterns(scene)
    if not pat.isotropic:
        g_tx = pat.rut_tx.field(d_tx @ rut.rotation)  # (T, N_tx), radar frame
        g_rx = pat.rut_rx.field(d_rx @ rut.rotation)
        amp = amp * np.conj(g_tx[:, rut.virtual_tx] * g_rx[:, rut.virtual_rx])
    if phase_rad is not None:
        amp = amp * np.exp(-1j * np.asarray(phase_rad, float))[:, None]  # beat: conjugate
    tau = path / c
    vel = np.array([x.velocity_mps for x in t], float)
    t_mid = radar.adc_start_s + 0.5 * (radar.samples_per_chirp - 1) / radar.adc_rate_hz
    f_mid = radar.f_c_hz + radar.slope_hz_per_s * (t_mid - tau.mean(axis=1))
    return Echoes.build(tau_air_s=tau, amplitude=amp, doppler_hz=2.0 * vel * f_mid / c,
                        target=np.arange(len(t)), kind=EchoKind.DIRECT)


def simulate_truth(setup: Setup, targets, seed: int | None = None,
                   noise_w: float | None = None, phase_rad=None) -> tuple[Echoes, AdcCube]:
    """Echoes and ADC cube of the real targets (:func:`truth_echoes`).

    Parameters
    ----------
    setup : Setup
        The setup whose RuT (array, pose, radar configuration) looks.
    targets : sequence of TargetConfig
        The point targets.
    seed : int, optional
        The noise seed: the RTS frame's, so both frames carry the same noise realisation.
    noise_w : float, optional
        Noise power per complex sample in the cube's units (the RTS frame's); None: the
        radar's thermal noise with ``[radar.link]``, else noiseless.
    phase_rad : array_like, optional
        An extra reflection phase per target (:func:`truth_echoes`).

    Returns
    -------
    echoes, cube
    """
    scene = setup.scene
    echoes = truth_echoes(setup, targets, phase_rad)
    rng = np.random.default_rng(seed)
    if scene.radar.link is None:
        cube = synthesize(echoes, scene.radar, setup.rut)
        return echoes, (add_noise(cube, noise_w, rng) if noise_w else cube)

    rl = lk.radar_link(scene.radar)
    echoes = lk.apply_radar_link(echoes, scene, rl)
    cube = synthesize(echoes, scene.radar, setup.rut)
    if noise_w is not None:
        cube = add_noise(cube, noise_w, rng)
    else:
        cube = AdcCube(cube.data + lk.shaped_noise(cube.shape, lk.thermal_noise_w(
            scene.radar, rl), rl, scene.radar, rng), cube.radar, cube.rut)
    data, clipped = lk.adc_convert(cube.data, rl)
    return echoes, AdcCube(data, cube.radar, cube.rut, clipped)
