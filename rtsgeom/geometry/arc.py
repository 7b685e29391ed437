"""Front ends on the arc (paper Fig. 1 and section "Measurement": R_c, theta_q).

Each front end is a module tangent to the arc carrying an Rx antenna (towards larger azimuth)
and a Tx antenna (towards smaller azimuth). Mounting errors move the module radially,
tangentially and in height. Everything here broadcasts over leading axes so Monte-Carlo draws
of mounting errors are one call.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._util import frozen
from ..arcmath import antenna_positions, radial_tangent  # the one formula (scene uses it too)
from ..scene import Scene

__all__ = ["FrontEnds", "antenna_positions", "front_ends", "radial_tangent"]


@dataclass(frozen=True)
class FrontEnds:
    """Antenna positions of all front ends (world frame), mounting errors applied."""

    angle_rad: np.ndarray  # (F,) nominal azimuth on the arc
    rx: np.ndarray  # (F, 3)
    tx: np.ndarray  # (F, 3)
    module: np.ndarray  # (F, 3)
    separation_m: np.ndarray  # (F,)
    offsets_m: np.ndarray  # (F, 3) radial, tangential, height
    arc_centre: np.ndarray  # (3,)
    arc_radius_m: float

    @property
    def count(self) -> int:
        return int(self.angle_rad.size)


def front_ends(scene: Scene, arc_centre: np.ndarray) -> FrontEnds:
    fes = scene.rts.front_ends
    ang = np.array([f.angle_rad for f in fes])
    sep = np.array([f.rx_tx_separation_m for f in fes])
    off = np.array([[f.radial_offset_m, f.tangential_offset_m, f.height_offset_m] for f in fes])
    rx, tx, mod = antenna_positions(arc_centre, scene.rts.arc_radius_m, ang, sep, off)
    return FrontEnds(frozen(ang), frozen(rx), frozen(tx), frozen(mod), frozen(sep), frozen(off),
                     frozen(arc_centre), scene.rts.arc_radius_m)
