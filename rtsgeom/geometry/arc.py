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

from .._util import frozen
from ..scene import Scene

__all__ = ["FrontEnds", "antenna_positions", "front_ends", "layout_offsets", "module_axes",
           "radial_tangent"]


def radial_tangent(angle_rad: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit radial (outward) and tangential (towards larger azimuth) vectors, shape (..., 3)."""
    a = np.asarray(angle_rad, dtype=float)
    s, co, z = np.sin(a), np.cos(a), np.zeros_like(a)
    return np.stack([s, co, z], -1), np.stack([co, -s, z], -1)


def layout_offsets(separation_m) -> tuple[np.ndarray, np.ndarray]:
    """The shorthand ``separation_m`` s (..., F) as signed offsets: rx (s/2, 0), tx (-s/2, 0)."""
    half = 0.5 * np.asarray(separation_m, float)
    z = np.zeros_like(half)
    return np.stack([half, z], -1), np.stack([-half, z], -1)


def module_axes(angle_rad, yaw_rad=None, pitch_rad=None
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit axes of each front-end module after its mounting rotations, (..., F, 3) each.

    ``tangent`` (towards larger azimuth when not yawed), ``up`` and ``boresight`` (towards the arc
    centre when not rotated). Pitch turns (boresight, up) about the tangent, then yaw turns all
    three about the world vertical. ``yaw_rad``, ``pitch_rad``: (..., F), broadcast.
    """
    r_hat, t_hat = radial_tangent(angle_rad)
    z_hat = np.array([0.0, 0.0, 1.0])
    b, up, t = -r_hat, z_hat, t_hat
    if pitch_rad is not None:
        p = np.asarray(pitch_rad, float)[..., None]
        b, up = np.cos(p) * b + np.sin(p) * z_hat, np.cos(p) * z_hat + np.sin(p) * r_hat
    t, up, b = np.broadcast_arrays(t, up, b)
    if yaw_rad is not None:
        y = np.asarray(yaw_rad, float)
        cy, sy = np.cos(y), np.sin(y)

        def turn(v):
            x = cy * v[..., 0] + sy * v[..., 1]
            return np.stack([x, -sy * v[..., 0] + cy * v[..., 1],
                             np.broadcast_to(v[..., 2], x.shape)], -1)

        t, up, b = turn(t), turn(up), turn(b)
    return t, up, b


def antenna_positions(centre: np.ndarray, radius_m: float, angle_rad: np.ndarray,
                      separation_m: np.ndarray | None = None,
                      offsets_m: np.ndarray | None = None, *,
                      rx_offset_m: np.ndarray | None = None,
                      tx_offset_m: np.ndarray | None = None,
                      yaw_rad: np.ndarray | None = None,
                      pitch_rad: np.ndarray | None = None,
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rx, Tx and module-centre positions of front ends on an arc.

    Parameters
    ----------
    centre : (3,) arc centre (world).
    radius_m : arc radius R_c.
    angle_rad : (F,) nominal azimuths theta_q.
    separation_m : (F,) shorthand for ``rx_offset_m = (s/2, 0)``, ``tx_offset_m = (-s/2, 0)``;
        ignored where the offsets are given.
    offsets_m : (..., F, 3) mounting errors (radial, tangential, height); broadcast over draws.
    rx_offset_m, tx_offset_m : (..., F, 2) signed antenna offsets ``(t, h)`` in the module frame
        (tangential, positive towards larger azimuth; height).
    yaw_rad, pitch_rad : (..., F) mounting rotations of the module about its centre.

    Returns
    -------
    rx, tx, module_centre : (..., F, 3)
    """
    r_hat, t_hat = radial_tangent(angle_rad)
    z_hat = np.array([0.0, 0.0, 1.0])
    nominal = np.asarray(centre, float) + radius_m * r_hat
    if offsets_m is None:
        offsets_m = np.zeros_like(nominal)
    off = np.asarray(offsets_m, float)
    mod = (nominal + off[..., 0:1] * r_hat + off[..., 1:2] * t_hat + off[..., 2:3] * z_hat)
    simple = rx_offset_m is None and tx_offset_m is None and yaw_rad is None and pitch_rad is None
    if simple:  # today's layout, same arithmetic (results stay bit-identical)
        half = 0.5 * np.asarray(separation_m, float)[..., None] * t_hat
        return mod + half, mod - half, mod
    if rx_offset_m is None or tx_offset_m is None:
        if separation_m is None:
            raise ValueError("antenna_positions: give separation_m or both rx_offset_m and "
                             "tx_offset_m")
        rx_s, tx_s = layout_offsets(separation_m)
        rx_offset_m = rx_s if rx_offset_m is None else rx_offset_m
        tx_offset_m = tx_s if tx_offset_m is None else tx_offset_m
    t, up, _ = module_axes(angle_rad, yaw_rad, pitch_rad)
    ro, to = np.asarray(rx_offset_m, float), np.asarray(tx_offset_m, float)
    rx = mod + ro[..., 0:1] * t + ro[..., 1:2] * up
    tx = mod + to[..., 0:1] * t + to[..., 1:2] * up
    return rx, tx, mod


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

    @property
    def count(self) -> int:
        return int(self.angle_rad.size)

    def axes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(tangent, up, boresight) unit vectors per module, (F, 3) each (:func:`module_axes`)."""
        return module_axes(self.angle_rad, self.yaw_rad, self.pitch_rad)

    def antenna_frame(self) -> np.ndarray:
        """Rotation antenna frame -> world per module, (F, 3, 3), columns (x, y, z): ``y`` the
        boresight, ``z`` up, ``x = y x z`` (right-handed; the tangent towards *smaller* azimuth),
        the same convention as the RuT's frame (for antenna patterns)."""
        _, up, b = self.axes()
        up, b = np.broadcast_arrays(up, b)
        return np.stack([np.cross(b, up), b, up], axis=-1)


def front_ends(scene: Scene, arc_centre: np.ndarray, *, rx_offset_m=None, tx_offset_m=None,
               yaw_rad=None, pitch_rad=None) -> FrontEnds:
    """The front ends of ``scene`` around ``arc_centre``.

    The layout and rotations come from the explicit arguments ((F, 2) and (F,) arrays), else
    from the front-end configs' ``rx_offset_m``/``tx_offset_m`` ((t, h) pairs) and
    ``yaw_offset_rad``/``pitch_offset_rad`` fields where the scene has them, else today's
    shorthand ``rx_tx_separation_m`` with no rotation.
    """
    fes = scene.rts.front_ends
    ang = np.array([f.angle_rad for f in fes])
    sep = np.array([f.rx_tx_separation_m for f in fes])
    off = np.array([[f.radial_offset_m, f.tangential_offset_m, f.height_offset_m] for f in fes])

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
    if ro is not None or to is not None:
        rs, ts = layout_offsets(sep)
        ro = rs if ro is None else ro
        to = ts if to is None else to
        sep = ro[:, 0] - to[:, 0]
    rx, tx, mod = antenna_positions(arc_centre, scene.rts.arc_radius_m, ang, sep, off,
                                    rx_offset_m=ro, tx_offset_m=to, yaw_rad=yaw, pitch_rad=pitch)
    opt = [None if a is None else frozen(a) for a in (ro, to, yaw, pitch)]
    return FrontEnds(frozen(ang), frozen(rx), frozen(tx), frozen(mod), frozen(sep), frozen(off),
                     frozen(arc_centre), scene.rts.arc_radius_m, *opt)
