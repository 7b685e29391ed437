"""One simulated radar frame of a programmed RTS: echoes -> ADC cube (+ receiver noise)."""

from __future__ import annotations

import numpy as np

from ..geometry import Setup
from ..paths import Paths
from ..rts.channels import EchoKind, Echoes, RtsProgram, build_echoes
from . import link as lk
from .fmcw import AdcCube, add_noise, synthesize

__all__ = ["noise_power", "simulate"]


def noise_power(echoes: Echoes, snr_db: float | None) -> float:
    """Noise power per complex sample for a per-sample SNR of the strongest target echo.

    The reference is the RTS's direct echoes (not the setup's static reflections, which can be
    far stronger than any target), so the targets keep their SNR whatever the paths method.
    """
    if snr_db is None or len(echoes) == 0:
        return 0.0
    direct = echoes.kind == EchoKind.DIRECT
    ref = echoes.amplitude[direct] if np.any(direct) else echoes.amplitude
    return float(np.max(np.abs(ref)) ** 2 / 10 ** (snr_db / 10))


def simulate(setup: Setup, paths: Paths, program: RtsProgram, seed: int | None = None,
             snr_db: float | None = None, noise_frames: int = 1) -> tuple[Echoes, AdcCube]:
    """Echoes and ADC cube of a programmed RTS (noise from ``seed`` when ``snr_db`` is set).

    With ``[radar.link]`` the chain is physical (:mod:`rtsgeom.radar.link`): echoes in sqrt(W) at the
    receiver input through the IF chain, thermal + RTS channel noise shaped by it (``snr_db``,
    when given, overrides that noise), then the ADC's clipping and quantisation.
    ``noise_frames`` K: the coherent average of K frames of a static program, simulated as
    one frame with the link's noise power / K (the quantisation, once, is not divided: a
    slight overestimate of the average's noise); ignored without ``[radar.link]`` or with
    ``snr_db`` (the caller raises ``snr_db`` by 10 log10 K)."""
    echoes = build_echoes(setup, paths, program)
    if setup.scene.radar.link is not None:
        return _simulate_linked(setup, echoes, program, seed, snr_db, noise_frames)
    cube = synthesize(echoes, setup.scene.radar, setup.rut)
    if snr_db is not None:
        rng = np.random.default_rng(seed)
        cube = add_noise(cube, noise_power(echoes, snr_db), rng)
    return echoes, cube


def _simulate_linked(setup: Setup, echoes: Echoes, program: RtsProgram, seed, snr_db,
                     noise_frames: int = 1):
    scene = setup.scene
    rl = lk.radar_link(scene.radar)
    lk.check_channels(scene, program, rl, setup)
    echoes = lk.apply_radar_link(echoes, scene, rl)
    cube = synthesize(echoes, scene.radar, setup.rut)
    rng = np.random.default_rng(seed)
    if snr_db is not None:
        cube = add_noise(cube, noise_power(echoes, snr_db), rng)
    else:
        p = (lk.thermal_noise_w(scene.radar, rl)
             + lk.channel_noise_w(scene, program, rl, setup)) / max(1, int(noise_frames))
        cube = AdcCube(cube.data + lk.shaped_noise(cube.shape, p, rl, scene.radar, rng),
                       cube.radar, cube.rut)
    data, clipped = lk.adc_convert(cube.data, rl)
    return echoes, AdcCube(data, cube.radar, cube.rut, clipped)
