"""TI DCA1000 raw capture layout for xWR16xx/xWR18xx complex output over 2 LVDS lanes.

The file is a flat little-endian int16 stream: chirps in transmit order (loop 0 Tx slot 0,
loop 0 Tx slot 1, ..., loop 1 Tx slot 0, ...); within a chirp the Rx channels 0..3 one after
the other; within an Rx the complex samples in pairs, stored as ``I0 I1 Q0 Q1 I2 I3 Q2 Q3 ...``
(the 2-lane interleaving that TI's mmWave Studio and its readers expect).

Scaling: the cube is multiplied by ``scale = 32767 / max(|Re|, |Im|)`` so the largest component
maps to full scale and nothing clips; the scale is returned (and written beside the file by the
CLI) so absolute levels can be recovered.
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from .fmcw import AdcCube

__all__ = ["to_dca1000", "from_dca1000"]


def to_dca1000(cube: AdcCube) -> tuple[bytes, float]:
    """Encode a cube as DCA1000 bytes; returns (bytes, scale).

    Parameters
    ----------
    cube : AdcCube

    Returns
    -------
    bytes
        The capture, as the DCA1000 writes it.
    float
        The scale applied (32767 over the largest |I| or |Q|) to fit the 16-bit samples.
    """
    data = cube.data
    n_l, n_v, n_s = data.shape
    if n_s % 2:
        raise ParameterError(f"radar.samples_per_chirp = {n_s}: must be even for the DCA1000 "
                             "format (2-lane I/Q pair layout)")
    n_rx = cube.rut.num_rx
    n_tx = n_v // n_rx
    peak = float(max(np.max(np.abs(data.real)), np.max(np.abs(data.imag)), 1e-30))
    scale = 32767.0 / peak
    raw = data.reshape(n_l, n_tx, n_rx, n_s)  # virtual v = slot * n_rx + rx -> transmit order
    i = np.round(raw.real * scale).astype(np.int16).reshape(n_l, n_tx, n_rx, n_s // 2, 2)
    q = np.round(raw.imag * scale).astype(np.int16).reshape(n_l, n_tx, n_rx, n_s // 2, 2)
    out = np.concatenate([i, q], axis=-1)  # (..., pair, [I0 I1 Q0 Q1])
    return out.astype("<i2").tobytes(), scale


def from_dca1000(raw: bytes, chirps: int, num_rx: int, samples: int) -> np.ndarray:
    """Decode DCA1000 bytes to complex samples ``[chirp (transmit order), rx, sample]``.

    Parameters
    ----------
    raw : bytes
    chirps, num_rx, samples : int
        The capture's shape.

    Returns
    -------
    numpy.ndarray
        (chirps, num_rx, samples) complex.
    """
    a = np.frombuffer(raw, dtype="<i2").astype(np.float32)
    a = a.reshape(chirps, num_rx, samples // 2, 4)
    i = a[..., 0:2].reshape(chirps, num_rx, samples)
    q = a[..., 2:4].reshape(chirps, num_rx, samples)
    return (i + 1j * q).astype(np.complex64)
