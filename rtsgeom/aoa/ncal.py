"""Calibration of N channels (placeholder: no calibration yet, zero offsets)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["ChannelCalibration", "calibrate_channels"]


@dataclass(frozen=True)
class ChannelCalibration:
    offsets_s: np.ndarray

    def to_dict(self) -> dict:
        return {"delay_offsets_s": [float(x) for x in self.offsets_s]}


def calibrate_channels(setup, paths, channels, probe, progress=None) -> ChannelCalibration:
    return ChannelCalibration(np.zeros(setup.fe.count))
