"""Registries of the named choices a scene or the CLI can make: one entry per choice.

Adding an AoA mode, a paths method, a radar preset, a window or a CFAR kind means adding ONE
entry here; the scene schema (``scene.py``), the generated ``docs/scene-format.md`` and the
CLI's ``choices=`` all read these dictionaries. This module imports only numpy so that every
stage, the scene loader included, can import it (one-way imports).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

__all__ = ["AoaMode", "AOA_MODES", "SYNTHESIS_MODES", "PATH_METHODS", "RadarPreset",
           "RADAR_PRESETS", "awr1843boost_layout", "Window", "WINDOWS", "CFAR_KINDS"]


@dataclass(frozen=True)
class AoaMode:
    """How the RTS sets a target's angle of arrival."""

    doc: str
    synthesis: bool  # True: interpolates between two front ends (amplitude ratio, eq. 18-23)


AOA_MODES: dict[str, AoaMode] = {
    "exact": AoaMode("amplitude ratio from the exact per-element model of the pair", True),
    "array-factor": AoaMode("amplitude ratio from the array factor of the RuT (closed form)", True),
    "paper": AoaMode("amplitude ratio from the paper's closed form g(theta) (eq. 23)", True),
    "nearest": AoaMode("no synthesis: each target on the nearest front end", False),
}
SYNTHESIS_MODES: tuple[str, ...] = tuple(k for k, m in AOA_MODES.items() if m.synthesis)

PATH_METHODS: dict[str, str] = {
    "exact": "exact line-of-sight distances per element",
    "raytrace": "Sionna RT ray tracing (reflections off the sheet and structures)",
}


def awr1843boost_layout(d: float) -> tuple[np.ndarray, np.ndarray]:
    """TI AWR1843BOOST antenna positions (Tx, Rx) in units of metres for element spacing ``d``.

    Rx 0..3 at lambda/2 (``d``) in azimuth; TX1 and TX3 spaced 2 lambda (``4 d``) in azimuth; TX2
    elevated by lambda/2 and offset lambda in azimuth. TX1+TX3 with the four Rx give the 8-element
    lambda/2 azimuth virtual array of the paper; TX2 adds an elevated row of four.
    The Rx row starts 3 lambda right of TX3 (assumed board gap; it only shifts the virtual array).
    """
    tx = np.array([[0.0, 0.0, 0.0], [2 * d, 0.0, d], [4 * d, 0.0, 0.0]])
    rx0 = 4 * d + 6 * d
    rx = np.array([[rx0 + k * d, 0.0, 0.0] for k in range(4)])
    return tx, rx


@dataclass(frozen=True)
class RadarPreset:
    """A RuT antenna board: its layout for element spacing ``d`` and the Tx used per mode."""

    doc: str
    layout: Callable[[float], tuple[np.ndarray, np.ndarray]]  # d -> (tx (N_tx, 3), rx (N_rx, 3))
    tx_azimuth: tuple[int, ...]  # Tx in TDM order without use_elevation_tx
    tx_elevation: tuple[int, ...]  # Tx in TDM order with use_elevation_tx

    def tx_order(self, use_elevation_tx: bool) -> tuple[int, ...]:
        return self.tx_elevation if use_elevation_tx else self.tx_azimuth

    def azimuth_elements(self, use_elevation_tx: bool) -> int:
        """Virtual elements in the azimuth row (z == 0): the aperture d_A = N_A d."""
        tx, rx = self.layout(1.0)
        az = [t for t in self.tx_order(use_elevation_tx) if abs(tx[t, 2]) < 1e-12]
        return len(az) * len(rx)


RADAR_PRESETS: dict[str, RadarPreset] = {
    "awr1843boost": RadarPreset("TI AWR1843BOOST: 3 Tx (one elevated), 4 Rx at lambda/2",
                                awr1843boost_layout, (0, 2), (0, 1, 2)),
}


@dataclass(frozen=True)
class Window:
    """A taper (scipy.signal.get_window name) and its main-lobe half width in FFT bins."""

    doc: str
    mainlobe_half_bins: int  # first null of the window's spectrum, in bins of the FFT


WINDOWS: dict[str, Window] = {
    "none": Window("rectangular", 1),
    "hann": Window("Hann", 2),
    "hamming": Window("Hamming", 2),
    "blackman": Window("Blackman", 3),
}

CFAR_KINDS: dict[str, str] = {
    "ca": "cell averaging: the mean of the training ring",
    "os": "ordered statistic: the os_rank quantile of the training ring",
}
