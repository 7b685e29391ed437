"""One simulated radar frame of a programmed RTS: echoes -> ADC cube (+ receiver noise), and
what the RuT detects in it (:func:`observe`: the full chain, or the fast path of
:mod:`.windowed` where it holds)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry import Setup
from ..paths import Paths
from ..rts.channels import EchoKind, Echoes, RtsProgram, build_echoes
from . import link as lk
from .fmcw import AdcCube, add_noise, noise_cube, synthesize
from .processing import Detections, RangeDoppler, process
from .steering import Steering
from .windowed import MapAxes, detect_near, noise_spectrum

__all__ = ["CHAINS", "FrameView", "noise_power", "simulate", "observe", "observe_fast"]

#: the chains a frame can run through: ``fast`` (:mod:`.windowed`, the full chain where a frame
#: is outside it) and ``full`` (ADC cube, FFTs, CFAR over the whole map)
CHAINS = ("fast", "full")


@dataclass(frozen=True)
class FrameView:
    """What the RuT detected in one frame.

    Attributes
    ----------
    echoes : Echoes
        The frame's echoes.
    detections : Detections or None
        The RuT's detections (on the fast path: those near the centres asked for; None where
        :func:`observe_fast` found the frame outside it).
    rd : RangeDoppler or MapAxes
        The range-Doppler map (full chain) or its axes only (fast path).
    steering : Steering
        The RuT's beamformer.
    fallback : str or None
        Why the full chain ran where the fast path was asked for; None otherwise.
    noise : ndarray or None
        The frame's noise spectrum (R, D, V) on the fast path of a noisy frame (a second look
        with the same seed and power, the truth twin's, shares it), else None.
    chain : str
        The chain asked for (:data:`CHAINS`).
    """

    echoes: Echoes
    detections: Detections | None
    rd: RangeDoppler | MapAxes
    steering: Steering
    fallback: str | None = None
    noise: np.ndarray | None = None
    chain: str = "full"


def observe(setup: Setup, paths: Paths, program: RtsProgram, seed: int | None = None,
            snr_db: float | None = None, centres=None, gate: int = 2,
            chain: str = "full") -> FrameView:
    """The RTS's frame as the RuT sees it: :func:`simulate` and
    :func:`~.processing.process` (``chain`` ``full``), or :func:`observe_fast` near
    ``centres`` (``fast``; the full chain where the frame is outside it, the reason in
    :attr:`FrameView.fallback`)."""
    echoes = build_echoes(setup, paths, program)
    why = None
    if chain == "fast":
        view = observe_fast(setup, echoes, centres, gate, seed,
                            0.0 if snr_db is None else noise_power(echoes, snr_db))
        if view.fallback is None:
            return view
        why = view.fallback
    cube = _cube(setup, echoes, program, seed, snr_db)
    rd, det = process(cube)
    return FrameView(echoes, det, rd, cube.steering, why, chain=chain)


def observe_fast(setup: Setup, echoes: Echoes, centres, gate: int = 2, seed: int | None = None,
                 noise_w: float = 0.0, noise: np.ndarray | None = None) -> FrameView:
    """The fast path (:func:`.windowed.detect_near`) of a frame of ``echoes``: the detections
    near ``centres`` (T, 2) fractional (range bin, Doppler bin) (:func:`.windowed.cell_centres`)
    that a detection within ``gate`` bins can sit in, with the full chain's noise (power
    ``noise_w`` per sample from ``seed``'s generator, or its spectrum ``noise`` where an earlier
    look of the same seed and power formed it). Where the frame is outside the fast path,
    :attr:`FrameView.fallback` says why and ``detections`` is None."""
    scene = setup.scene
    radar = scene.radar
    st = Steering.auto(setup.rut, radar)
    why = fast_path_excluded(scene)
    if why is not None:
        return FrameView(echoes, None, MapAxes.of(radar), st, why, chain="fast")
    if noise is None and noise_w > 0:
        shape = (radar.chirps_per_tx, setup.rut.num_virtual, radar.samples_per_chirp)
        noise = noise_spectrum(noise_cube(shape, noise_w, np.random.default_rng(seed)), radar,
                               setup.rut)
    det, why = detect_near(echoes, radar, setup.rut, st, centres, gate, noise)
    return FrameView(echoes, det, MapAxes.of(radar), st, why, noise, "fast")


def fast_path_excluded(scene) -> str | None:
    """Why a scene's frames cannot take the fast path (None: they can, frame by frame)."""
    if scene.radar.link is not None:
        return "[radar.link]: the ADC's clipping and quantisation are not linear"
    return None


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
    return echoes, _cube(setup, echoes, program, seed, snr_db, noise_frames)


def _cube(setup: Setup, echoes: Echoes, program: RtsProgram, seed, snr_db, noise_frames=1
          ) -> AdcCube:
    if setup.scene.radar.link is not None:
        return _simulate_linked(setup, echoes, program, seed, snr_db, noise_frames)[1]
    cube = synthesize(echoes, setup.scene.radar, setup.rut)
    if snr_db is not None:
        rng = np.random.default_rng(seed)
        cube = add_noise(cube, noise_power(echoes, snr_db), rng)
    return cube


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
