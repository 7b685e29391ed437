"""TI DCA1000 raw capture layouts: each radar preset's own (``ArrayPreset.capture``).

Source: TI SWRA581B, "Mmwave Radar Device ADC Raw Data Capture": section 6 (xWR16xx/xWR18xx,
IWR6843; also the AWR2944, whose datasheet SWRS273A gives the same two LVDS data lanes) and
section 5 (xWR12xx/xWR14xx, four lanes; the AWR2243's layout), with the MATLAB readers of its
section 9. The file is a flat little-endian int16 stream, chirps in transmit order (loop 0 Tx
slot 0, loop 0 Tx slot 1, ..., loop 1 Tx slot 0, ...). Within a chirp:

* 2 lanes, complex: Rx 0..3 one after the other; within an Rx the samples in pairs,
  ``I0 I1 Q0 Q1 I2 I3 Q2 Q3 ...`` (lane 1 carries the I pair, lane 2 the Q pair).
* 2 lanes, real-only (the AWR2944's receiver): Rx 0..3 one after the other, the samples in
  order (the lanes carry alternate samples; readDCA1000's ``isReal`` branch reads them as
  ``reshape(adcData, numADCSamples*numRX, numChirps)``).
* 4 lanes, complex: one Rx per lane; per sample the four lanes' I, then their Q
  (``reshape(adcData, numLanes*2, [])``, rows 1-4 I, rows 5-8 Q); real-only: the four
  lanes' samples in turn. Unused lanes carry zeros (SWRA581: "number of lanes is always 4");
  more than four Rx (the cascade) are written as groups of four, one after the other per
  chirp (an assumption stated in that preset's layout).

A real-only capture holds ``Re`` of the complex-baseband model (the real IF signal the ADC
samples): its spectrum is conjugate-symmetric, the echo's amplitude and phase are in the
positive-frequency half at half the complex amplitude.

Scaling: the cube is multiplied by ``scale = 32767 / max(|Re|, |Im|)`` (``max |Re|`` for a
real-only layout) so the largest component maps to full scale and nothing clips; the scale is
returned (and written beside the file by the CLI) so absolute levels can be recovered.
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from ..scene.presets import LAYOUT_DEFAULT, PRESETS, CaptureLayout
from .fmcw import AdcCube

__all__ = ["to_dca1000", "from_dca1000", "capture_layout", "dca1000_bytes", "dca1000_meta"]


def capture_layout(radar) -> CaptureLayout:
    """The DCA1000 layout of the board a scene's ``[radar]`` names (``antenna_preset``; a
    custom ``[radar.array]`` keeps the preset's chip and so its layout)."""
    p = PRESETS.get(getattr(radar, "antenna_preset", None))
    return LAYOUT_DEFAULT if p is None else p.capture


def dca1000_bytes(chirps: int, num_rx: int, samples: int, layout: CaptureLayout) -> int:
    """The file size of a capture of this shape in ``layout``."""
    lanes_rx = num_rx if layout.lanes == 2 else -(-num_rx // 4) * 4  # 4 lanes: padded
    return chirps * lanes_rx * samples * (4 if layout.complex else 2)


def dca1000_meta(layout: CaptureLayout, scale: float, chirps: int, rut, samples: int) -> dict:
    """The sidecar fields of a DCA1000 capture: its layout and shape."""
    order = {(True, 2): "chirp (transmit order) > rx > sample pairs I0 I1 Q0 Q1",
             (False, 2): "chirp (transmit order) > rx > sample",
             (True, 4): "chirp (transmit order) > group of 4 rx > sample > I of rx 0-3, "
                        "Q of rx 0-3",
             (False, 4): "chirp (transmit order) > group of 4 rx > sample > rx 0-3"}
    return {"format": layout.name, "adc": layout.adc, "lvds_lanes": layout.lanes,
            "scale": scale, "chirps": chirps, "tx_order": list(rut.tx_order),
            "num_rx": rut.num_rx, "samples_per_chirp": samples, "dtype": "int16 (<i2)",
            "order": order[(layout.complex, layout.lanes)]}


def _check(n_rx: int, n_s: int, layout: CaptureLayout) -> None:
    if layout.lanes == 2 and n_s % 2:
        raise ParameterError(f"radar.samples_per_chirp = {n_s}: must be even for the DCA1000 "
                             f"format {layout.name} (2-lane sample pairs)")


def to_dca1000(cube: AdcCube, layout: CaptureLayout | None = None) -> tuple[bytes, float]:
    """Encode a cube as DCA1000 bytes; returns (bytes, scale).

    Parameters
    ----------
    cube : AdcCube
    layout : CaptureLayout, optional
        The board's layout (default: that of the cube's radar preset, :func:`capture_layout`).

    Returns
    -------
    bytes
        The capture, as the DCA1000 writes it.
    float
        The scale applied (32767 over the largest written component) to fit 16-bit samples.
    """
    layout = capture_layout(cube.radar) if layout is None else layout
    data = cube.data
    n_l, n_v, n_s = data.shape
    n_rx = cube.rut.num_rx
    n_tx = n_v // n_rx
    _check(n_rx, n_s, layout)
    parts = (data.real, data.imag) if layout.complex else (data.real,)
    peak = float(max(max(np.max(np.abs(p)) for p in parts), 1e-30))
    scale = 32767.0 / peak
    # virtual v = slot * n_rx + rx -> transmit order, (chirp, rx, sample) per rail
    rails = [np.round(p.reshape(n_l * n_tx, n_rx, n_s) * scale).astype("<i2") for p in parts]
    if layout.lanes == 2:
        if layout.complex:  # (..., pair, [I0 I1 Q0 Q1])
            out = np.concatenate([r.reshape(n_l * n_tx, n_rx, n_s // 2, 2) for r in rails],
                                 axis=-1)
        else:
            out = rails[0]
    else:
        n_dev = -(-n_rx // 4)
        pad = [np.zeros((n_l * n_tx, n_dev * 4, n_s), "<i2") for _ in rails]
        for p, r in zip(pad, rails):
            p[:, :n_rx] = r
        # (chirp, device, lane, sample) -> (chirp, device, sample, [lanes' I, lanes' Q])
        out = np.concatenate([p.reshape(n_l * n_tx, n_dev, 4, n_s).transpose(0, 1, 3, 2)
                              for p in pad], axis=-1)
    return np.ascontiguousarray(out, dtype="<i2").tobytes(), scale


def from_dca1000(raw: bytes, chirps: int, num_rx: int, samples: int,
                 layout: CaptureLayout = LAYOUT_DEFAULT) -> np.ndarray:
    """Decode DCA1000 bytes to samples ``[chirp (transmit order), rx, sample]``.

    Parameters
    ----------
    raw : bytes
    chirps, num_rx, samples : int
        The capture's shape.
    layout : CaptureLayout
        The layout it was written in (the sidecar's ``format``, ``adc`` and ``lvds_lanes``).

    Returns
    -------
    numpy.ndarray
        (chirps, num_rx, samples) complex64; a real-only capture's imaginary part is 0.
    """
    _check(num_rx, samples, layout)
    a = np.frombuffer(raw, dtype="<i2").astype(np.float32)
    if layout.lanes == 2:
        if layout.complex:
            a = a.reshape(chirps, num_rx, samples // 2, 4)
            i = a[..., 0:2].reshape(chirps, num_rx, samples)
            q = a[..., 2:4].reshape(chirps, num_rx, samples)
            return (i + 1j * q).astype(np.complex64)
        return a.reshape(chirps, num_rx, samples).astype(np.complex64)
    n_dev = -(-num_rx // 4)
    rails = 2 if layout.complex else 1
    a = a.reshape(chirps, n_dev, samples, rails, 4)  # (chirp, device, sample, rail, lane)
    x = a.transpose(0, 1, 4, 2, 3).reshape(chirps, n_dev * 4, samples, rails)[:, :num_rx]
    out = x[..., 0] + 1j * x[..., 1] if layout.complex else x[..., 0]
    return np.asarray(out, dtype=np.complex64)
