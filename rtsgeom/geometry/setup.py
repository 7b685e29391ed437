"""The whole physical setup: RuT array + front ends + sheet, built from a :class:`Scene`."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import trimesh

from .._util import frozen
from ..scene import Scene
from .arc import FrontEnds, antenna_positions, front_ends
from .arrays import RutArray, rut_array
from .sheet import sheet_mesh

__all__ = ["Setup", "build_setup", "nominal_setup"]


@dataclass(frozen=True)
class Setup:
    """Geometry of one scene (world frame, metres). The sheet mesh is built on first use."""

    scene: Scene
    rut: RutArray
    fe: FrontEnds

    @cached_property
    def sheet(self) -> trimesh.Trimesh | None:
        cfg = self.scene.sheet
        if not cfg.enabled:
            return None
        return sheet_mesh(cfg, self.fe.arc_centre, self.fe.arc_radius_m, self.fe.angle_rad,
                          self.fe.elevation_rad)

    def fe_azimuth_rad(self) -> np.ndarray:
        """Azimuth of each front end's module centre as seen from the RuT phase centre."""
        return self.rut.azimuth_of(self.fe.module)

    def fe_direction_cosines(self) -> np.ndarray:
        """Direction cosines u = (sin az cos el, sin el) (F, 2) of each front end's module
        centre seen from the RuT phase centre, in the radar frame (``radar.steering``)."""
        p = self.rut.to_local(self.fe.module)
        return p[:, [0, 2]] / np.linalg.norm(p, axis=-1, keepdims=True)


def build_setup(scene: Scene, offsets_m: np.ndarray | None = None) -> Setup:
    """Place the RuT and the front ends. ``offsets_m`` (F, 3) overrides the scene's mounting
    errors (radial, tangential, height), e.g. for a tolerance draw."""
    rut = rut_array(scene.radar)
    centre = (np.asarray(scene.rts.arc_center_m, float) if scene.rts.arc_center_m is not None
              else np.asarray(rut.position, float))
    fe = front_ends(scene, centre)
    if offsets_m is not None:
        rx, tx, mod = antenna_positions(centre, scene.rts.arc_radius_m, fe.angle_rad,
                                        fe.separation_m, offsets_m, elevation_rad=fe.elevation_rad)
        fe = FrontEnds(fe.angle_rad, frozen(rx), frozen(tx), frozen(mod), fe.separation_m,
                       frozen(offsets_m), fe.arc_centre, fe.arc_radius_m,
                       elevation_rad=fe.elevation_rad)
    return Setup(scene, rut, fe)


def nominal_setup(setup: Setup) -> Setup:
    """The setup as designed: no mounting errors and no channel gain/phase errors.

    This is what an RTS operator knows; the AoA design works on it, while the simulated RuT
    sees the setup as built (``setup``), so calibration has to absorb the difference.
    """
    scene = setup.scene
    fes = tuple(f.evolve(radial_offset_m=0.0, tangential_offset_m=0.0, height_offset_m=0.0,
                         gain_offset_db=0.0, phase_offset_rad=0.0) for f in scene.rts.front_ends)
    if fes == scene.rts.front_ends:
        return setup
    nominal = scene.evolve(rts=scene.rts.evolve(front_ends=fes))  # validated again
    return build_setup(nominal)
