"""The RuT's MIMO antenna array (paper section "Signal Model": N_A = N_tx * N_rx virtual elements).

Local radar frame: ``x`` lateral, ``y`` boresight, ``z`` up; the origin is the phase centre of the
virtual array (the mean of the Tx-Rx midpoints of all active virtual elements), so a radar placed
at ``position_m`` has its phase centre there.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.constants import c

from .._util import frozen
from ..registry import RADAR_PRESETS, awr1843boost_layout  # noqa: F401 (re-exported)
from ..scene import RadarConfig

__all__ = ["RutArray", "awr1843boost_layout", "rut_array", "yaw_matrix"]


def yaw_matrix(yaw_rad: float) -> np.ndarray:
    """Rotation local -> world for a yaw measured like azimuth (from +y towards +x)."""
    cy, sy = np.cos(yaw_rad), np.sin(yaw_rad)
    return np.array([[cy, sy, 0.0], [-sy, cy, 0.0], [0.0, 0.0, 1.0]])


@dataclass(frozen=True)
class RutArray:
    """Positions of the RuT's antennas (world frame, metres) and its virtual array.

    Virtual element ``v`` pairs Tx ``virtual_tx[v]`` (transmitting in TDM slot ``virtual_slot[v]``)
    with Rx ``virtual_rx[v]``; ``virtual_local`` is ``p_tx + p_rx`` in the radar frame, the
    position whose projection on the arrival direction gives the two-way far-field phase.
    """

    tx_world: np.ndarray  # (N_tx, 3) all physical Tx
    rx_world: np.ndarray  # (N_rx, 3)
    tx_local: np.ndarray
    rx_local: np.ndarray
    tx_order: tuple[int, ...]  # Tx index per TDM slot
    virtual_tx: np.ndarray  # (V,)
    virtual_rx: np.ndarray  # (V,)
    virtual_slot: np.ndarray  # (V,)
    virtual_local: np.ndarray  # (V, 3)
    azimuth_mask: np.ndarray  # (V,) virtual elements in the azimuth row (z == 0)
    position: np.ndarray  # (3,) phase centre, world
    rotation: np.ndarray  # (3, 3) local -> world
    wavelength_m: float
    spacing_m: float

    @property
    def num_virtual(self) -> int:
        return int(self.virtual_tx.size)

    @property
    def num_rx(self) -> int:
        return int(self.rx_world.shape[0])

    def to_local(self, points: np.ndarray) -> np.ndarray:
        """World -> radar frame, for points of shape (..., 3)."""
        return (np.asarray(points) - self.position) @ self.rotation

    def azimuth_of(self, points: np.ndarray) -> np.ndarray:
        """Azimuth (rad) of world points as seen from the phase centre, in the radar frame."""
        p = self.to_local(points)
        return np.arctan2(p[..., 0], p[..., 1])


def rut_array(radar: RadarConfig) -> RutArray:
    """Build the RuT array of ``radar`` (preset layout, active Tx, pose)."""
    lam = c / radar.f_center_hz
    d = radar.element_spacing_m or lam / 2.0
    preset = RADAR_PRESETS[radar.antenna_preset]
    tx, rx = preset.layout(d)
    order = preset.tx_order(radar.use_elevation_tx)
    slot, vt, vr = np.meshgrid(np.arange(len(order)), 0, np.arange(len(rx)), indexing="ij")
    slot = slot.ravel()
    vt = np.asarray(order)[slot]
    vr = vr.ravel()
    az = np.abs(tx[vt, 2]) < 1e-12  # virtual elements of the azimuth (non-elevated) Tx
    centre = 0.5 * (tx[vt[az]] + rx[vr[az]]).mean(axis=0)
    tx_l, rx_l = tx - centre, rx - centre
    rot = yaw_matrix(radar.yaw_rad)
    pos = np.asarray(radar.position_m, dtype=float)
    virt = tx_l[vt] + rx_l[vr]
    return RutArray(
        tx_world=frozen(tx_l @ rot.T + pos), rx_world=frozen(rx_l @ rot.T + pos),
        tx_local=frozen(tx_l), rx_local=frozen(rx_l), tx_order=order,
        virtual_tx=frozen(vt), virtual_rx=frozen(vr), virtual_slot=frozen(slot),
        virtual_local=frozen(virt), azimuth_mask=frozen(az),
        position=frozen(pos), rotation=frozen(rot), wavelength_m=lam, spacing_m=d,
    )
