"""Front ends on the arc (paper Fig. 1 and section "Measurement": R_c, theta_q).

Each front end is a module on the arc carrying an Rx and a Tx antenna. In the module's frame
an antenna sits at a signed offset ``(t, h)``: ``t`` along the arc's tangent, positive towards
larger azimuth, and ``h`` up. The default layout (``separation_m = s``) is ``rx = (+s/2, 0)``,
``tx = (-s/2, 0)``: Rx towards larger azimuth; a mirrored module has ``rx = (-s/2, 0)``. The
module's boresight points at the arc centre. Mounting errors move the module radially,
tangentially and in height, and turn it about its centre: ``yaw`` about the vertical (in the
azimuth sense, from +y towards +x seen from above) and ``pitch`` about its tangential axis
(positive: boresight up); the rotations move the antenna offsets with the module.
Everything here broadcasts over leading axes so Monte-Carlo draws of mounting errors are one call.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._lib.util import frozen
from .._lib.arcmath import (ModuleLayout, antenna_positions, layout_offsets, module_axes,
                           radial_tangent)
from ..scene import Scene

__all__ = ["FrontEnds", "ModuleLayout", "antenna_positions", "front_ends", "layout_offsets",
           "module_axes", "radial_tangent"]


@dataclass(frozen=True)
class FrontEnds:
    """Antenna positions of all front ends (world frame), mounting errors applied.

    ``separation_m`` is the signed tangential Rx - Tx offset (``s`` of the shorthand layout);
    the layout itself is ``rx_offset_m`` / ``tx_offset_m`` (None: the shorthand), the mounting
    rotations ``yaw_rad`` / ``pitch_rad`` (None: none).
    """

    angle_rad: np.ndarray  # (F,) nominal azimuth on the arc
    rx: np.ndarray  # (F, 3)
    tx: np.ndarray  # (F, 3)
    module: np.ndarray  # (F, 3)
    separation_m: np.ndarray  # (F,)
    offsets_m: np.ndarray  # (F, 3) radial, tangential, height
    arc_centre: np.ndarray  # (3,)
    arc_radius_m: float
    rx_offset_m: np.ndarray | None = None  # (F, 2) signed (t, h)
    tx_offset_m: np.ndarray | None = None  # (F, 2)
    yaw_rad: np.ndarray | None = None  # (F,)
    pitch_rad: np.ndarray | None = None  # (F,)
    elevation_rad: np.ndarray | None = None  # (F,) on the sphere; None: all on the arc

    @property
    def count(self) -> int:
        return int(self.angle_rad.size)

    def axes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(tangent, up, boresight) unit vectors per module, (F, 3) each (:func:`module_axes`)."""
        return module_axes(self.angle_rad, self.yaw_rad, self.pitch_rad, self.elevation_rad)

    def antenna_frame(self) -> np.ndarray:
        """Rotation antenna frame -> world per module, (F, 3, 3), columns (x, y, z): ``y`` the
        boresight, ``z`` up, ``x = y x z`` (right-handed; the tangent towards *smaller* azimuth),
        the same convention as the RuT's frame (for antenna patterns)."""
        _, up, b = self.axes()
        up, b = np.broadcast_arrays(up, b)
        return np.stack([np.cross(b, up), b, up], axis=-1)


def front_ends(scene: Scene, arc_centre: np.ndarray, *, rx_offset_m=None, tx_offset_m=None,
               yaw_rad=None, pitch_rad=None, offsets_m=None) -> FrontEnds:
    """The front ends of ``scene`` around ``arc_centre``.

    The layout and rotations come from the explicit arguments ((F, 2) and (F,) arrays), else
    from the front-end configs' ``rx_offset_m``/``tx_offset_m`` ((t, h) pairs) and
    ``yaw_offset_rad``/``pitch_offset_rad`` fields where set, else the
    shorthand ``rx_tx_separation_m`` with no rotation. ``offsets_m`` (F, 3) overrides the
    mounting errors (radial, tangential, height), e.g. for a tolerance draw.
    """
    fes = scene.rts.front_ends
    ang = np.array([f.angle_rad for f in fes])
    elev = np.array([f.elevation_rad for f in fes], float)
    elev = elev if np.any(elev) else None  # all on the arc: the arc's arithmetic
    sep = np.array([f.rx_tx_separation_m for f in fes])
    off = (np.array([[f.radial_offset_m, f.tangential_offset_m, f.height_offset_m] for f in fes])
           if offsets_m is None else np.asarray(offsets_m, float))

    def field(explicit, name, shape):
        if explicit is not None:
            a = np.asarray(explicit, float)
        else:
            vals = [getattr(f, name, None) for f in fes]
            if all(v is None for v in vals):
                return None
            default = np.zeros(shape[1:])
            a = np.array([default if v is None else v for v in vals], float)
        if a.shape != shape:
            raise ValueError(f"front ends: {name} must have shape {shape}, got {a.shape}")
        return a

    n = len(fes)
    ro = field(rx_offset_m, "rx_offset_m", (n, 2))
    to = field(tx_offset_m, "tx_offset_m", (n, 2))
    yaw = field(yaw_rad, "yaw_offset_rad", (n,))
    pitch = field(pitch_rad, "pitch_offset_rad", (n,))
    # no rotation at all: the positions without the rotation terms
    yaw = None if yaw is not None and yaw_rad is None and not np.any(yaw) else yaw
    pitch = None if pitch is not None and pitch_rad is None and not np.any(pitch) else pitch
    if ro is not None or to is not None:
        rs, ts = layout_offsets(sep)
        ro = rs if ro is None else ro
        to = ts if to is None else to
        sep = ro[:, 0] - to[:, 0]
    rx, tx, mod = antenna_positions(arc_centre, scene.rts.arc_radius_m, ang, sep, off,
                                    layout=ModuleLayout(ro, to, yaw, pitch), elevation_rad=elev)
    opt = [None if a is None else frozen(a) for a in (ro, to, yaw, pitch, elev)]
    return FrontEnds(frozen(ang), frozen(rx), frozen(tx), frozen(mod), frozen(sep), frozen(off),
                     frozen(arc_centre), scene.rts.arc_radius_m, *opt)
