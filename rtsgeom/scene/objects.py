"""Extended objects: a car is many scatterers.

A ``[[targets]]`` or ``[[scenario.targets]]`` entry with ``scatterers`` (points in the object's
own frame: x right, y away from the RuT, z up, at heading 0) or ``mesh`` (a mesh file in that
frame) is an object. It is placed with its origin at the entry's range and azimuth (a moving
one on its waypoints) and turned by its heading about the vertical in the sense of azimuth
(+y towards +x); a moving object with ``heading = "velocity"`` is turned along its motion.

The scene expands every object into point targets (:class:`~rtsgeom.scene.sections.TargetConfig`,
one per scatterer, ``object_index`` naming the object): the planner, the truth twin and the
association then work per scatterer, as for any point target. A static object is expanded on
load (``Scene.targets``); a moving one per frame (:func:`place`, by the playback).

A mesh's scatterers come from its geometry as the RuT sees it, by physical optics
(:mod:`rtsgeom.scene.mesh`).

An RuT that beamforms in azimuth only sees no elevation: a scatterer off the horizontal plane
keeps its 3-D range and azimuth and is placed at elevation 0.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from ..errors import SceneError
from .mesh import MAX_MESH_SCATTERERS, load_mesh, mesh_scatterers
from .schema import fmt
from .sections import MAX_TARGETS, TargetConfig

__all__ = ["ObjectModel", "place", "expand_objects", "frame_objects", "object_paths",
           "target_labels", "target_field", "check_moving_objects", "check_static_objects",
           "targets_per_frame"]


@dataclass(frozen=True, eq=False)  # numpy fields: identity, not an ambiguous array ==
class ObjectModel:
    """One extended object of a scene.

    ``where`` names its entry (``targets[2]``, ``scenario.targets[0]``); ``points`` (N, 3)
    and ``rcs_dbsm`` (N,) its scatterers in its own frame (a mesh: None, derived per pose);
    ``vertices`` (V, 3) and ``faces`` (F, 3) its mesh or None; ``outline`` (K, 2) its
    footprint's convex hull in its own frame (x, y); ``heading_rad`` its fixed heading;
    ``along_velocity`` turns it along its motion; ``moving``: a scenario target."""

    where: str
    points: np.ndarray | None
    rcs_dbsm: np.ndarray | None
    vertices: np.ndarray | None
    faces: np.ndarray | None
    outline: np.ndarray
    heading_rad: float = 0.0
    along_velocity: bool = False
    moving: bool = False
    origin: tuple[float, float, float] | None = None  # a static object's origin (radar frame)

    def __repr__(self) -> str:
        what = (f"{len(self.points)} scatterers" if self.points is not None
                else f"mesh of {len(self.faces)} facets")
        return f"ObjectModel({self.where}: {what}{', moving' if self.moving else ''})"

    def outline_at(self, origin, velocity_vec=None) -> np.ndarray:
        """The footprint (K, 2) in the radar frame's (x, y) with the origin at ``origin``."""
        turn = _turn(self.heading(None if velocity_vec is None else np.asarray(velocity_vec)))
        xy = np.c_[self.outline, np.zeros(len(self.outline))] @ turn.T
        return xy[:, :2] + np.asarray(origin, float)[None, :2]

    def pose(self, scene, f: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """The origin (3,) and velocity (3,) in the radar frame at frame ``f`` (a static
        object: its origin, at rest)."""
        if not self.moving:
            return np.asarray(self.origin, float), np.zeros(3)
        from .scenario import trajectory
        i = int(self.where.split("[")[1].rstrip("]"))
        sp = trajectory(scene.scenario.targets[i].waypoints, scene.scenario.frame_times())
        return sp.position_m[f], sp.velocity_vec_mps[f]

    def heading(self, velocity_vec=None) -> float:
        """The heading (rad) in a pose: along ``velocity_vec`` (the radar frame's x, y) where
        the object turns with its motion and moves, else the fixed one."""
        if self.along_velocity and velocity_vec is not None and np.hypot(*velocity_vec[:2]) > 0:
            return float(math.atan2(velocity_vec[0], velocity_vec[1]))
        return self.heading_rad


def _turn(heading_rad: float) -> np.ndarray:
    """Rotation about z in the sense of azimuth: the object's +y goes to (sin h, cos h)."""
    ch, sh = math.cos(heading_rad), math.sin(heading_rad)
    return np.array([[ch, sh, 0.0], [-sh, ch, 0.0], [0.0, 0.0, 1.0]])


def _hull(xy: np.ndarray) -> np.ndarray:
    """Convex hull (K, 2) of points in the plane (a point or a segment: themselves)."""
    from scipy.spatial import ConvexHull, QhullError
    pts = np.unique(np.round(xy, 9), axis=0)
    if len(pts) < 3:
        return pts
    try:
        return pts[ConvexHull(pts).vertices]
    except QhullError:  # collinear
        return pts[[np.argmin(pts[:, 0] + pts[:, 1]), np.argmax(pts[:, 0] + pts[:, 1])]]


def place(model: ObjectModel, origin: np.ndarray, velocity_vec, radar, index: int,
          ) -> list[TargetConfig]:
    """The object's scatterers as point targets with the origin at ``origin`` (3,) and moving
    at ``velocity_vec`` (3,) (the radar frame: x right, y boresight, z up; m, m/s), each
    ``TargetConfig`` carrying ``object_index = index``. ``radar``: the RadarConfig (its
    wavelength and resolution shape a mesh's scatterers; without elevation processing the
    scatterers lie at elevation 0). Raises ``SceneError`` for a mesh with no facet facing the
    RuT, or a scatterer at the RuT."""
    origin = np.asarray(origin, float)
    vel = np.zeros(3) if velocity_vec is None else np.asarray(velocity_vec, float)
    turn = _turn(model.heading(vel))
    if model.points is not None:
        pts, rcs = model.points, model.rcs_dbsm
    else:
        n_virtual = radar.num_tx_active * radar.num_rx
        pts, rcs = mesh_scatterers(model.vertices, model.faces, turn.T @ (-origin),
                                   radar.wavelength_m, radar.range_resolution_m,
                                   2.0 / max(n_virtual, 1))
        if not len(pts):
            raise SceneError(f"{model.where}.mesh: no facet faces the RuT from "
                             f"{np.linalg.norm(origin):.3g} m (are its normals pointing "
                             "inwards, or is it open towards the RuT?)")
    p = origin[None] + pts @ turn.T  # (N, 3) radar frame
    rng = np.linalg.norm(p, axis=1)
    if np.any(rng <= 1e-3):
        raise SceneError(f"{model.where}.scatterers[{int(np.argmin(rng))}]: lies at the RuT "
                         "(range 0): move the object or its scatterer")
    az = np.arctan2(p[:, 0], p[:, 1])
    el = np.arcsin(np.clip(p[:, 2] / rng, -1, 1)) if radar.elevation_processing else 0 * rng
    v_r = p @ vel / rng
    return [TargetConfig(range_m=float(r), velocity_mps=float(v), rcs_dbsm=float(s),
                         angle_rad=float(a), elevation_rad=float(e), object_index=index)
            for r, v, s, a, e in zip(rng, v_r, rcs, az, el)]


def _model(entry, where: str, mesh_path: str | None, source: str, moving: bool
           ) -> ObjectModel:
    """An entry's object (its scatterers or its mesh), checked."""
    along = getattr(entry, "heading", "fixed") == "velocity"
    if entry.scatterers is not None and entry.mesh is not None:
        raise SceneError(f"{source}: {where}.mesh = {fmt(entry.mesh)}: must be left out where "
                         f"{where}.scatterers is given (an object is one or the other)")
    if entry.scatterers is not None:
        s = np.asarray(entry.scatterers, float).reshape(-1, 4)
        return ObjectModel(where, s[:, :3], s[:, 3], None, None, _hull(s[:, :2]),
                           entry.heading_rad, along, moving)
    v, f = load_mesh(mesh_path, f"{where}.mesh", source)
    return ObjectModel(where, None, None, v, f, _hull(v[:, :2]), entry.heading_rad, along,
                       moving)


def object_paths(scene, source: str, base_dir, allow_external: bool) -> dict[str, str]:
    """Each object entry with a mesh (``targets[1]``) -> its path, resolved like a
    ``[[structure]]``'s (inside the scene's folder unless ``allow_external``)."""
    from .file import resolve_mesh
    entries = [(f"targets[{i}]", t) for i, t in enumerate(scene.targets)]
    if scene.scenario is not None:
        entries += [(f"scenario.targets[{i}]", t) for i, t in enumerate(scene.scenario.targets)]
    return {w: resolve_mesh(t.mesh, f"{w}.mesh", source, base_dir, allow_external)
            for w, t in entries if t.mesh is not None and t.scatterers is None}


def expand_objects(scene, mesh_paths: dict[str, str]):
    """The scene with every static object expanded into its scatterers (``targets``, each
    ``object_index`` into ``objects``) and every object's model in ``objects`` (static ones
    first, in file order, then the scenario's). ``mesh_paths``: each ``where`` (``targets[1]``)
    with a mesh -> its resolved path."""
    src = scene.source or "<scene>"
    models, targets = [], []
    for i, t in enumerate(scene.targets):
        where = f"targets[{i}]"
        if t.scatterers is None and t.mesh is None:
            targets.append(t)
            continue
        m = _model(t, where, mesh_paths.get(where), src, False)
        u = np.array([math.sin(t.angle_rad) * math.cos(t.elevation_rad),
                      math.cos(t.angle_rad) * math.cos(t.elevation_rad),
                      math.sin(t.elevation_rad)])
        try:
            pts = place(m, t.range_m * u, t.velocity_mps * u, scene.radar, len(models))
        except SceneError as exc:
            raise SceneError(f"{src}: {exc}") from None
        models.append(dataclasses.replace(m, origin=tuple(t.range_m * u)))
        targets += pts
    sc = scene.scenario
    if sc is not None:
        for i, t in enumerate(sc.targets):
            where = f"scenario.targets[{i}]"
            if t.scatterers is not None or t.mesh is not None:
                models.append(_model(t, where, mesh_paths.get(where), src, True))
    if not models:
        return scene
    if len(targets) > MAX_TARGETS:
        raise SceneError(f"{src}: targets: must expand to at most {MAX_TARGETS} point targets "
                         f"(its objects' scatterers make {len(targets)})")
    return dataclasses.replace(scene, targets=tuple(targets), objects=tuple(models))


def frame_objects(scene, sp_by_target: dict, num_frames: int) -> list[list[TargetConfig]]:
    """Each frame's scatterers of the scenario's objects: ``sp_by_target`` maps a scenario
    target's index to its :class:`~rtsgeom.scene.scenario.SetPoints`. A mesh's scatterers
    are derived once, at the drive's first frame, and move with the object (so a frame's
    targets are the same scatterers throughout the drive); the positions are
    :func:`object_set_points`' (checked on load by :func:`check_moving_objects`)."""
    out: list[list[TargetConfig]] = [[] for _ in range(num_frames)]
    radar = scene.radar
    for k, m in enumerate(scene.objects):
        if not m.moving:
            continue
        sp = sp_by_target[int(m.where.split("[")[1].rstrip("]"))]
        try:
            if m.points is None:
                m = _mesh_frozen(m, sp, radar)
            pos, vel = object_set_points(m, sp, radar)
        except SceneError as exc:
            raise SceneError(f"{scene.source}: {exc}") from None
        rng = np.linalg.norm(pos, axis=-1)  # (F, N)
        az = np.arctan2(pos[..., 0], pos[..., 1])
        el = (np.arcsin(np.clip(pos[..., 2] / rng, -1, 1)) if radar.elevation_processing
              else np.zeros_like(rng))
        v_r = np.einsum("fnk,fk->fn", pos, vel) / rng
        for f in range(num_frames):
            out[f] += [TargetConfig(range_m=float(r), velocity_mps=float(v), rcs_dbsm=float(s),
                                    angle_rad=float(a), elevation_rad=float(e), object_index=k)
                       for r, v, s, a, e in zip(rng[f], v_r[f], m.rcs_dbsm, az[f], el[f])]
    return out


def target_labels(scene, targets=None, moving_from: int | None = None) -> list[str]:
    """Each of ``targets`` (default the scene's, objects expanded) named as the scene file
    writes it: a point target ``targets[i]`` (its entry's index in the file, the objects'
    entries counted as one each), an object's scatterer ``targets[1].scatterers[2]`` (a
    mesh's: ``targets[1].mesh (scatterer 2)``). A drive's frame (``moving_from``: the index of
    its first moving target, :func:`rtsgeom.analysis.playback.frames.frame_targets`) names
    its moving point targets ``scenario.targets[i]``."""
    tg = tuple(scene.targets if targets is None else targets)
    moving = [] if scene.scenario is None else [
        i for i, t in enumerate(scene.scenario.targets) if t.scatterers is None and t.mesh is None]
    out, seen, per_obj, n_point = [], set(), {}, 0
    for k, t in enumerate(tg):
        o = t.object_index
        if 0 <= o < len(scene.objects):
            m = scene.objects[o]
            j = per_obj.get(o, 0)
            per_obj[o] = j + 1
            seen.add(o)
            out.append(f"{m.where}.scatterers[{j}]" if m.points is not None
                       else f"{m.where}.mesh (scatterer {j})")
        elif moving_from is not None and k >= moving_from and k - moving_from < len(moving):
            out.append(f"scenario.targets[{moving[k - moving_from]}]")
        else:
            static = sum(1 for x in seen if not scene.objects[x].moving)
            out.append(f"targets[{n_point + static}]")
            n_point += 1
    return out


def target_field(label: str, field: str) -> str:
    """A field of a target named by :func:`target_labels`: ``targets[2].range_m``; an object's
    scatterer has no such field in the file: ``targets[1].scatterers[2] (its range_m)``."""
    return f"{label} (its {field})" if ".scatterers[" in label or ".mesh" in label \
        else f"{label}.{field}"


def object_set_points(model: ObjectModel, sp, radar) -> tuple[np.ndarray, np.ndarray]:
    """A moving object's scatterers over its drive, vectorised over frames: their positions
    (F, N, 3) in the radar frame and velocities (F, 3) (``sp``: the object's
    :class:`~rtsgeom.scene.scenario.SetPoints`). A mesh's scatterers are derived at the first
    frame (:func:`place`) and move with the object, as :func:`frame_objects` plays them."""
    if model.points is None:  # the mesh as the RuT sees it at the first frame
        model = _mesh_frozen(model, sp, radar)
    vel = sp.velocity_vec_mps
    moves = np.hypot(vel[:, 0], vel[:, 1]) > 0  # as ObjectModel.heading, every frame at once
    h = np.where(model.along_velocity & moves, np.arctan2(vel[:, 0], vel[:, 1]),
                 model.heading_rad)  # (F,)
    ch, sh = np.cos(h), np.sin(h)
    x, y, z = model.points[:, 0], model.points[:, 1], model.points[:, 2]
    pos = np.stack([ch[:, None] * x + sh[:, None] * y, -sh[:, None] * x + ch[:, None] * y,
                    np.broadcast_to(z, (len(h), len(z)))], axis=-1)
    return sp.position_m[:, None, :] + pos, vel


def _mesh_frozen(model: ObjectModel, sp, radar) -> ObjectModel:
    """The mesh object with the scatterers the RuT sees at the drive's first frame, in its
    own frame."""
    first = place(model, sp.position_m[0], sp.velocity_vec_mps[0], radar, 0)
    turn = _turn(model.heading(sp.velocity_vec_mps[0]))
    local = np.array([[math.sin(t.angle_rad), math.cos(t.angle_rad), 0.0]
                      for t in first]) * np.array([t.range_m for t in first])[:, None]
    pts = (local - sp.position_m[0][None]) @ turn
    return dataclasses.replace(model, points=pts, rcs_dbsm=np.array([t.rcs_dbsm for t in first]))


def check_moving_objects(scene, fail, limits, air_extra_m: float, sps: dict) -> None:
    """Every moving object's scatterers in every frame within what the processing resolves,
    as a ``[[targets]]`` point target or a static object's scatterer is checked (range below
    the radar's range axis less the air path the RTS does not subtract, above the arc's radius
    where it subtracts it; radial velocity within the unambiguous one; azimuth within +-90 deg
    and elevation within +-60 deg): one message each, naming the scatterer as written
    (``scenario.targets[0].scatterers[3]``) with the time of its first frame outside.
    ``sps``: each moving object's scenario index -> its SetPoints."""
    r_lim, v_lim, why_r, why_v = limits
    r_max = r_lim - air_extra_m
    rts = scene.rts
    times = scene.scenario.frame_times()
    for m in scene.objects:
        if not m.moving:
            continue
        i = int(m.where.split("[")[1].rstrip("]"))
        if i not in sps:  # its waypoints are refused already
            continue
        try:
            pos, vel = object_set_points(m, sps[i], scene.radar)
        except SceneError as exc:  # a mesh with no facet facing the RuT at the first frame
            fail(f"{m.where}.mesh", scene.scenario.targets[i].mesh, str(exc).split(": ", 1)[-1])
            continue
        rng = np.linalg.norm(pos, axis=-1)  # (F, N)
        v_r = np.einsum("fnk,fk->fn", pos, vel) / np.maximum(rng, 1e-12)
        az = np.degrees(np.arctan2(pos[..., 0], pos[..., 1]))
        el = np.degrees(np.arcsin(np.clip(pos[..., 2] / np.maximum(rng, 1e-12), -1, 1)))
        if not scene.radar.elevation_processing:
            el = np.zeros_like(el)  # placed at elevation 0 (module docstring)
        low = rts.arc_radius_m if rts.compensate_air_path else 1e-3
        checks = ((rng >= r_max, rng, "range", "m",
                   f"< {r_max:.4g} m, {why_r}" + (f" minus the air path {air_extra_m:.4g} m "
                                                  "the RTS does not subtract"
                                                  if air_extra_m > 1e-9 else "")),
                  (rng <= low, rng, "range", "m",
                   f"> rts.arc_radius_m ({rts.arc_radius_m:g} m): the RTS cannot emit before "
                   "the radar signal reached it" if rts.compensate_air_path else "> 0 m"),
                  (np.abs(v_r) >= v_lim, v_r, "radial velocity", "m/s",
                   f"in (-{v_lim:.4g}, {v_lim:.4g}) m/s, {why_v}"),
                  (np.abs(az) > 90.0, az, "azimuth", "deg", "in [-90, 90] deg (in front of "
                   "the RuT)"),
                  (np.abs(el) > 60.0, el, "elevation", "deg", "in [-60, 60] deg"))
        for bad, val, what, unit, allowed in checks:
            if bad.any():
                f = int(np.flatnonzero(bad.any(axis=1))[0])
                n = int(np.flatnonzero(bad[f])[0])
                row = ([round(float(x), 6) for x in m.points[n]] + [float(m.rcs_dbsm[n])]
                       if m.points is not None else None)
                name = (f"{m.where}.scatterers[{n}]" if m.points is not None
                        else f"{m.where}.mesh")
                fail(name, row if row is not None else scene.scenario.targets[i].mesh,
                     f"a scatterer whose {what} stays {allowed} (at t = {times[f]:g} s it is "
                     f"{val[f, n]:.4g} {unit})")


def targets_per_frame(scene) -> int:
    """A drive's point targets in one frame: the ``[[targets]]`` (objects expanded) and each
    ``[[scenario.targets]]`` entry's scatterers (a mesh: at most :data:`MAX_MESH_SCATTERERS`;
    a point target: one)."""
    return len(scene.targets) + sum(
        len(t.scatterers) if t.scatterers is not None else
        MAX_MESH_SCATTERERS if t.mesh is not None else 1 for t in scene.scenario.targets)


def check_static_objects(scene, fail, names) -> None:
    """A static object's scatterers in front of the RuT as a point target's ``angle_deg`` and
    ``elevation_deg`` are (+-90 deg, +-60 deg); ``names``: :func:`target_labels`."""
    for i, tg in enumerate(scene.targets):
        if tg.object_index < 0:
            continue
        if abs(tg.angle_rad) > math.pi / 2 + 1e-12:
            fail(target_field(names[i], "azimuth_deg"), round(math.degrees(tg.angle_rad), 6),
                 "in [-90, 90] deg, in front of the RuT (as a point target's angle_deg): move "
                 "the object or its scatterer")
        if abs(tg.elevation_rad) > math.radians(60.0) + 1e-12:
            fail(target_field(names[i], "elevation_deg"),
                 round(math.degrees(tg.elevation_rad), 6),
                 "in [-60, 60] deg (as a point target's elevation_deg)")
