"""The whole physical setup: RuT array + front ends + sheet, built from a :class:`Scene`."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np

from ..scene import Scene
from ..scene.rules import arc_centre_m, problems
from .frontends import FrontEnds, front_ends
from .arrays import RutArray, rut_array
from .sheet import sheet_mesh
from ..scene import FrontEndConfig, RadarConfig
from ..scene.schema import specs
from .._lib.util import warn_caller
from ..errors import NominalSetupWarning, SceneError

if TYPE_CHECKING:  # trimesh loads where the mesh is built (geometry.sheet)
    import trimesh

__all__ = ["Setup", "build_setup", "nominal_setup", "nominal_scene", "setup_errors",
           "warn_setup_errors", "DRAWS_REPLACE", "FRONT_END_ERRORS", "RUT_POSE_ERRORS"]


@dataclass(frozen=True)
class Setup:
    """Geometry of one scene (world frame, metres). The sheet mesh is built on first use.

    Attributes
    ----------
    scene : Scene
    rut : RutArray
        The RuT's Tx and Rx elements in world coordinates.
    fe : FrontEnds
        The front ends' Rx and Tx antennas and module centres.
    """

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

    def fe_direction_cosines(self, dims: int = 2) -> np.ndarray:
        """Direction cosines u = (sin az cos el, sin el) (F, 2) of each front end's module
        centre seen from the RuT phase centre, in the radar frame (``radar.steering``);
        ``dims`` 1: (F, 1) sin az, what a RuT that beamforms in azimuth only steers to."""
        if dims == 1:
            return np.sin(self.fe_azimuth_rad())[:, None]
        p = self.rut.to_local(self.fe.module)
        return p[:, [0, 2]] / np.linalg.norm(p, axis=-1, keepdims=True)


def build_setup(scene: Scene, offsets_m: np.ndarray | None = None, *, yaw_rad=None,
                pitch_rad=None, rut_offset_m=None, rut_yaw_rad=None) -> Setup:
    """Place the RuT and the front ends. ``offsets_m`` (F, 3) overrides the scene's mounting
    errors (radial, tangential, height), ``yaw_rad``/``pitch_rad`` (F,) its mounting rotations,
    ``rut_offset_m`` (3,)/``rut_yaw_rad`` the RuT's pose errors, e.g. for a tolerance draw; the
    antenna layouts (signed offsets) are kept. The arc stays centred on the RuT's nominal
    position (``radar.position_m``) when ``rts.arc_center_m`` is unset.

    Parameters
    ----------
    scene : Scene
    offsets_m : (F, 3) array, optional
        Mounting errors (radial, tangential, height) instead of the scene's.
    yaw_rad, pitch_rad : (F,) array, optional
        Mounting rotations instead of the scene's.
    rut_offset_m : (3,) array, optional
    rut_yaw_rad : float, optional
        The RuT's pose errors instead of the scene's.

    Returns
    -------
    Setup
    """
    rut = rut_array(scene.radar, position_offset_m=rut_offset_m, yaw_offset_rad=rut_yaw_rad)
    centre = np.asarray(arc_centre_m(scene), float)
    fe = front_ends(scene, centre, yaw_rad=yaw_rad, pitch_rad=pitch_rad, offsets_m=offsets_m)
    return Setup(scene, rut, fe)


#: the front-end fields that are errors of the setup as built (zero on the nominal setup)
FRONT_END_ERRORS = ("radial_offset_m", "tangential_offset_m", "height_offset_m",
                    "yaw_offset_rad", "pitch_offset_rad", "gain_offset_db", "phase_offset_rad")
#: the RuT's pose errors
RUT_POSE_ERRORS = ("position_offset_m", "yaw_offset_rad")


def setup_errors(scene: Scene) -> list[str]:
    """The scene's fields that :func:`nominal_scene` zeroes and that are not zero, as file
    keys (``rts.front_ends[1].radial_offset_mm``, ``radar.yaw_offset_deg``)."""
    fe_key, radar_key = dict(specs(FrontEndConfig)), dict(specs(RadarConfig))
    out = [f"rts.front_ends[{q}].{fe_key[name].key}" for q, fe in enumerate(scene.rts.front_ends)
           for name in FRONT_END_ERRORS if getattr(fe, name) != 0.0]
    out += [f"radar.{radar_key[name].key}" for name in _rut_pose_errors(scene.radar)]
    return out + (["radar.channels"] if _channel_errors(scene.radar) else [])


def _channel_errors(radar) -> bool:
    """Whether the RuT's own channels (``[radar.channels]``) are not ideal."""
    ch = radar.channels
    return ch is not None and not ch.ideal


#: what ``tolerance`` and ``design`` do with the scene's own errors (:func:`warn_setup_errors`)
DRAWS_REPLACE = ("draws mounting errors about the nominal setup; the scene's own errors ({}) "
                 "are not its starting point: each draw replaces them. Their effect on the "
                 "synthesized angle: `rtsgeom linearity SCENE --uncalibrated` (and without "
                 "the flag, calibrated), in Python rtsgeom.linearity(scene, calibration=False)")


def warn_setup_errors(scene: Scene, study: str, what: str = DRAWS_REPLACE) -> list[str]:
    """Warn (:class:`~rtsgeom.errors.NominalSetupWarning`, at the caller's line outside the
    package: ``_lib.util.warn_caller``) that ``study`` works on the nominal setup when the
    scene carries errors of its own (:func:`setup_errors`; ``what``: the sentence after the
    study's name, ``{}`` the fields); return those fields."""
    fields = setup_errors(scene)
    if fields:
        more = f" and {len(fields) - 3} more" if len(fields) > 3 else ""
        warn_caller(f"{study} " + what.format(", ".join(fields[:3]) + more),
                    NominalSetupWarning)
    return fields


def _rut_pose_errors(radar) -> list[str]:
    """The fields of :data:`RUT_POSE_ERRORS` that are not zero."""
    return [name for name in RUT_POSE_ERRORS if np.any(np.asarray(getattr(radar, name)) != 0.0)]


def nominal_scene(scene: Scene, validate: bool = True) -> Scene:
    """The scene as designed: every field of :data:`FRONT_END_ERRORS` and
    :data:`RUT_POSE_ERRORS` zero and the RuT's channels ideal (no ``[radar.channels]``: the
    lab does not know its radar's errors) (``scene`` itself where they already are). ``validate``
    False: not validated again (a study's internal variant, checked by its own rules: zeroing
    a radial offset lengthens the air path, which can put a valid scene's target, one the
    study drops anyway, beyond the range the rules allow)."""
    # a front end without errors is kept as it is: no copy per target and frame of a drive
    fes = tuple(f if not any(np.any(np.asarray(getattr(f, k)) != 0.0) for k in FRONT_END_ERRORS)
                else f.derive(**dict.fromkeys(FRONT_END_ERRORS, 0.0)) for f in scene.rts.front_ends)
    radar = scene.radar
    if _rut_pose_errors(radar):  # (zeroing every field of RUT_POSE_ERRORS)
        radar = radar.derive(position_offset_m=(0.0, 0.0, 0.0), yaw_offset_rad=0.0)
    if _channel_errors(radar):
        radar = radar.derive(channels=None)
    if fes == scene.rts.front_ends and radar is scene.radar:
        return scene
    # zeros within every field's range: the fields are not read through the file's schema
    # again (its errors would name a value nobody wrote); the rules between them are
    new = scene.derive(rts=scene.rts.derive(front_ends=fes), radar=radar)
    if validate:
        found = problems(new)
        if found:
            raise SceneError(found[0], found)
    return new


def nominal_setup(setup: Setup) -> Setup:
    """The setup as designed (:func:`nominal_scene`): no mounting errors, no channel
    gain/phase errors, no RuT pose errors. This is what an RTS operator knows; the AoA design
    works on it, while the simulated RuT sees the setup as built (``setup``), so calibration
    has to absorb the difference."""
    nominal = nominal_scene(setup.scene)
    return setup if nominal is setup.scene else build_setup(nominal)
