"""The RuT's MIMO antenna array (paper section "Signal Model": N_A = N_tx * N_rx virtual elements).

Local radar frame: ``x`` lateral, ``y`` boresight, ``z`` up; the origin is the phase centre of the
virtual array (the mean of the Tx-Rx midpoints of the azimuth virtual elements), so a radar placed
at ``position_m`` has its phase centre there.

Every array, preset or custom, is an :class:`~rtsgeom.scene.presets.ArraySpec` (board positions in
metres and the TDM order) built by the one function :func:`array_from_spec`; :func:`rut_array` is
the preset/scene path (spec lookup + :func:`array_from_spec`). Sparse and non-uniform virtual arrays
work: the beamformer steers on ``virtual_local``, and :attr:`RutArray.virtual_unique` maps
virtual elements that share a position (e.g. the cascade's 144 azimuth elements on 86 positions)
onto one, so they can be combined.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.constants import c

from .._lib.util import frozen
from ..scene.presets import PRESETS, ArrayPreset, ArraySpec, preset
from ..scene import RadarConfig

__all__ = ["ArraySpec", "ArrayPreset", "PRESETS", "RutArray", "array_from_spec", "array_spec",
           "awr1843boost_layout", "posed_positions", "rut_array", "yaw_matrix"]

_NM = 1e9  # positions are compared on a 1 nm grid (duplicates, rows)


def yaw_matrix(yaw_rad: float) -> np.ndarray:
    """Rotation local -> world for a yaw measured like azimuth (from +y towards +x)."""
    cy, sy = np.cos(yaw_rad), np.sin(yaw_rad)
    return np.array([[cy, sy, 0.0], [-sy, cy, 0.0], [0.0, 0.0, 1.0]])


def awr1843boost_layout(d: float, board_gap_m: float | None = None
                        ) -> tuple[np.ndarray, np.ndarray]:
    """TI AWR1843BOOST antenna positions (Tx, Rx), (N, 3) metres ``[x, 0, z]``, for spacing ``d``.

    Rx 0..3 at lambda/2 (``d``) in azimuth; TX1 and TX3 spaced 2 lambda (``4 d``) in azimuth; TX2
    elevated by lambda/2 and offset lambda in azimuth. TX1+TX3 with the four Rx give the 8-element
    lambda/2 azimuth virtual array of the paper; TX2 adds an elevated row of four. The Rx row
    starts ``board_gap_m`` (default 3 lambda, an assumption: the board's real gap is not
    documented) right of TX3. The gap does not change the virtual array, but it is *not* only a
    shift: the Tx group sees a front end's Rx antenna and the Rx group its Tx antenna from
    different places, a near-field parallax of +0.27 deg at R_c = 1 m (``analysis.nearfield``).
    See :data:`~rtsgeom.scene.presets.PRESETS` ``["awr1843boost"]`` for the source.
    """
    tx, rx = PRESETS["awr1843boost"].positions_m(d, board_gap_m)
    return _to3(tx), _to3(rx)


def _to3(xz: np.ndarray) -> np.ndarray:
    xz = np.asarray(xz, float)
    return np.stack([xz[:, 0], np.zeros(len(xz)), xz[:, 1]], axis=1)


@dataclass(frozen=True)
class RutArray:
    """Positions of the RuT's antennas (world frame, metres) and its virtual array.

    Virtual element ``v`` pairs Tx ``virtual_tx[v]`` (transmitting in TDM slot ``virtual_slot[v]``)
    with Rx ``virtual_rx[v]``; ``virtual_local`` is ``p_tx + p_rx`` in the radar frame, the
    position whose projection on the arrival direction gives the two-way far-field phase.
    ``azimuth_mask`` selects the azimuth row (the virtual row with the most elements; for the
    presets, the non-elevated Tx). ``virtual_unique[v]`` indexes ``unique_local``, the distinct
    virtual positions: elements with the same index see the same far-field phase.
    ``spacing_m`` is the array's grid unit ``d`` (lambda/2 for the presets).
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
    azimuth_mask: np.ndarray  # (V,) virtual elements in the azimuth row
    position: np.ndarray  # (3,) phase centre, world
    rotation: np.ndarray  # (3, 3) local -> world
    wavelength_m: float
    spacing_m: float
    virtual_unique: np.ndarray | None = None  # (V,) index into unique_local
    unique_local: np.ndarray | None = None  # (U, 3) distinct virtual positions
    name: str = "custom"

    @property
    def num_virtual(self) -> int:
        return int(self.virtual_tx.size)

    @property
    def num_rx(self) -> int:
        return int(self.rx_world.shape[0])

    @property
    def azimuth_unique(self) -> np.ndarray:
        """Indices into ``unique_local`` of the distinct azimuth virtual positions, by x."""
        idx = np.unique(self.virtual_unique[self.azimuth_mask])
        return idx[np.argsort(self.unique_local[idx, 0], kind="stable")]

    @property
    def azimuth_positions_m(self) -> np.ndarray:
        """Distinct azimuth virtual positions x (radar frame, metres), ascending."""
        return self.unique_local[self.azimuth_unique, 0]

    @property
    def num_azimuth_unique(self) -> int:
        return int(self.azimuth_unique.size)

    @property
    def aperture_m(self) -> float:
        """Azimuth virtual aperture ``d_A``: span of the distinct positions plus one cell ``d``
        (``N d`` for a filled N-element ULA, the paper's eq. 24 convention)."""
        x = self.azimuth_positions_m
        cells = float(np.ptp(x)) / self.spacing_m
        n = round(cells)
        if abs(cells - n) < 1e-6:  # on the grid: exactly (N_cells + 1) d
            return float((n + 1) * self.spacing_m)
        return float(np.ptp(x) + self.spacing_m)

    def to_local(self, points: np.ndarray) -> np.ndarray:
        """World -> radar frame, for points of shape (..., 3)."""
        return (np.asarray(points) - self.position) @ self.rotation

    def azimuth_of(self, points: np.ndarray) -> np.ndarray:
        """Azimuth (rad) of world points as seen from the phase centre, in the radar frame."""
        p = self.to_local(points)
        return np.arctan2(p[..., 0], p[..., 1])


def array_spec(radar: RadarConfig, *, array: ArraySpec | None = None,
               board_gap_m: float | None = None) -> ArraySpec:
    """The :class:`ArraySpec` of ``radar``: ``array`` (or ``radar.array``: an ArraySpec, or a
    config with ``tx_mm``, ``rx_mm``, ``tx_order``) if given, else
    its preset (``radar.antenna_preset``) at ``d = radar.element_spacing_m`` or lambda/2 at the
    centre frequency, azimuth Tx only unless ``radar.use_elevation_tx``; ``board_gap_m`` (or
    ``radar.board_gap_m``) overrides the preset's board gap."""
    custom = array if array is not None else radar.array
    if custom is not None and not isinstance(custom, ArraySpec):  # a config with mm fields
        custom = ArraySpec.from_mm(custom.tx_mm, custom.rx_mm, custom.tx_order)
    if custom is not None:
        return custom
    lam = c / radar.f_center_hz
    d = radar.element_spacing_m or lam / 2.0
    gap = board_gap_m if board_gap_m is not None else radar.board_gap_m
    return preset(radar.antenna_preset).spec(d, radar.use_elevation_tx, gap)


def _grid_unit(x: np.ndarray, lam: float) -> float:
    """Smallest gap between distinct positions ``x``; lambda/2 for a single position."""
    x = np.asarray(x, float)
    _, first = np.unique(np.round(x * _NM).astype(np.int64), return_index=True)
    gaps = np.diff(np.sort(x[first]))
    return float(gaps.min()) if gaps.size else lam / 2.0


def array_from_spec(spec: ArraySpec, wavelength_m: float, position_m=(0.0, 0.0, 0.0),
                    yaw_rad: float = 0.0) -> RutArray:
    """Build the :class:`RutArray` of ``spec`` (the one implementation, presets included).

    ``wavelength_m``: the beamformer's wavelength (centre of the ADC window); ``position_m``
    (world) is where the phase centre goes; ``yaw_rad`` turns the radar like an azimuth.
    """
    tx, rx = _to3(spec.tx_m), _to3(spec.rx_m)
    order = spec.tx_order
    slot, vt, vr = np.meshgrid(np.arange(len(order)), 0, np.arange(len(rx)), indexing="ij")
    slot = slot.ravel()
    vt = np.asarray(order)[slot]
    vr = vr.ravel()
    zq = np.round((tx[vt, 2] + rx[vr, 2]) * _NM).astype(np.int64)  # virtual row heights
    rows, counts = np.unique(zq, return_counts=True)
    best = rows[counts == counts.max()]
    az = zq == best[np.argmin(np.abs(best))]  # the fullest row; ties: the lowest |z|
    centre = 0.5 * (tx[vt[az]] + rx[vr[az]]).mean(axis=0)
    tx_l, rx_l = tx - centre, rx - centre
    rot = yaw_matrix(yaw_rad)
    pos = np.asarray(position_m, dtype=float)
    virt = tx_l[vt] + rx_l[vr]
    key = np.round(virt[:, [0, 2]] * _NM).astype(np.int64)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    d = float(spec.spacing_m) if spec.spacing_m else _grid_unit(virt[az, 0], wavelength_m)
    return RutArray(
        tx_world=frozen(tx_l @ rot.T + pos), rx_world=frozen(rx_l @ rot.T + pos),
        tx_local=frozen(tx_l), rx_local=frozen(rx_l), tx_order=tuple(order),
        virtual_tx=frozen(vt), virtual_rx=frozen(vr), virtual_slot=frozen(slot),
        virtual_local=frozen(virt), azimuth_mask=frozen(az),
        position=frozen(pos), rotation=frozen(rot), wavelength_m=wavelength_m, spacing_m=d,
        virtual_unique=frozen(inverse.ravel()), unique_local=frozen(virt[first]), name=spec.name,
    )


def rut_array(radar: RadarConfig, spec: ArraySpec | None = None, *,
              position_offset_m=None, yaw_offset_rad: float | None = None) -> RutArray:
    """Build the RuT array of ``radar`` (its :func:`array_spec` unless ``spec`` is given) at its
    pose plus the pose errors ``position_offset_m`` (world, metres) and ``yaw_offset_rad``
    (default: ``radar.position_offset_m`` / ``radar.yaw_offset_rad``). The RuT measures in its
    own (erroneous) frame."""
    spec = array_spec(radar) if spec is None else spec
    off = position_offset_m if position_offset_m is not None else radar.position_offset_m
    dyaw = yaw_offset_rad if yaw_offset_rad is not None else radar.yaw_offset_rad
    pos = np.asarray(radar.position_m, dtype=float)
    if off is not None:
        pos = pos + np.asarray(off, float)
    yaw = radar.yaw_rad + float(dyaw or 0.0)
    return array_from_spec(spec, c / radar.f_center_hz, pos, yaw)


def posed_positions(rut: RutArray, position_offset_m=None, yaw_offset_rad=None
                    ) -> tuple[np.ndarray, np.ndarray]:
    """World positions of the RuT's Tx and Rx under pose errors, broadcast over draws.

    The whole array is turned by ``yaw_offset_rad`` (..., ) about its phase centre (in the azimuth
    sense) and moved by ``position_offset_m`` (..., 3). Returns ``tx`` (..., N_tx, 3) and ``rx``
    (..., N_rx, 3), e.g. for ``paths.exact.leg_delays``. With no errors: ``rut.tx_world``,
    ``rut.rx_world``.
    """
    yaw = np.asarray(0.0 if yaw_offset_rad is None else yaw_offset_rad, float)
    off = np.zeros(3) if position_offset_m is None else np.asarray(position_offset_m, float)
    cy, sy = np.cos(yaw)[..., None], np.sin(yaw)[..., None]

    def turn(p):
        r = p - rut.position  # (N, 3)
        x = cy * r[:, 0] + sy * r[:, 1]
        y = -sy * r[:, 0] + cy * r[:, 1]
        z = np.broadcast_to(r[:, 2], x.shape)
        return np.stack([x, y, z], -1) + rut.position + off[..., None, :]

    return turn(rut.tx_world), turn(rut.rx_world)
