"""What the 3D view draws, as pyvista meshes and polylines in the world frame (metres): the RuT
board scaled about its phase centre, the front-end arc, modules and antennas, the sheet's cutout
rims, the virtual targets and the propagation paths; the view's palette. Composed into a
plotter by :mod:`rtsgeom.viz.scene3d`."""

from __future__ import annotations

import numpy as np
import pyvista as pv

from .._lib.arcmath import radial_tangent, sphere_frame
from ..geometry import Setup
from ..geometry.export import COLOURS
from ..paths.table import FE_TO_RX, RUT_TO_RUT, TX_TO_FE

__all__ = ["TARGET_RADIUS_FACTOR", "rgb", "rut_scale_factor", "scaled", "board", "merge",
           "spheres", "polyline", "merge_lines", "arc_points", "angle_span", "cutout_rims",
           "modules", "target_positions", "split_paths", "hit_points",
           "undrawable_reflections", "path_polylines", "REFLECTION_BY_BOUNCES"]

TARGET_RADIUS_FACTOR = 1.5  # targets are drawn at this multiple of the arc radius

BACKGROUND = "#f4f5f7"  # light: the cutouts show as bright holes in the grey sheet
PANEL_BACKGROUND = "#e8eaee"
SHEET = "#aab1ba"
SHEET_LEGEND = "#6b7280"  # the legend writes its text in the entry colour
RIM = "#2b2f36"
ARC = "#8c564b"  # brown: blue is the RuT's Rx, green the front ends' Rx
LOS = "#00a6c8"  # cyan: distinct from every element's colour (geometry.export.COLOURS)
REFLECTION = "#d62f8c"  # a single bounce; more bounces lighter (REFLECTION_BY_BOUNCES)
#: reflections coloured by their bounce count: 1, 2, 3 or more
REFLECTION_BY_BOUNCES = (REFLECTION, "#ee8fc2", "#f6c7df")
TARGET = "#7b3fb8"
MODULE = "#5c6670"


def rgb(key: str) -> tuple[float, float, float]:
    """A colour of the mesh export (same palette in the GLB and in the 3D view)."""
    return tuple(v / 255.0 for v in COLOURS[key][:3])


def rut_scale_factor(setup: Setup) -> float:
    """How much the RuT is enlarged in the overview: a round factor (1, 2, 5, 10, 20, ...) that
    makes its board about a fifth of the arc radius wide."""
    width = np.ptp(board(setup, 1.0).points[:, 0])
    want = max(0.2 * setup.fe.arc_radius_m / width, 1.0)
    nice = 10.0 ** np.floor(np.log10(want)) * np.array([1.0, 2.0, 5.0, 10.0])
    return float(nice[np.argmin(np.abs(np.log(nice / want)))])


def scaled(points: np.ndarray, centre: np.ndarray, scale: float) -> np.ndarray:
    return centre + scale * (np.asarray(points, float) - centre)


def board(setup: Setup, scale: float):
    """The RuT board (a thin box behind the elements), as in the mesh export, scaled."""
    rut = setup.rut
    pts = np.vstack([rut.tx_world, rut.rx_world])
    lo, hi = pts.min(0), pts.max(0)
    margin = 3 * rut.wavelength_m
    box = pv.Box(bounds=(lo[0] - margin, hi[0] + margin, lo[1] - 1.8e-3, lo[1] - 0.2e-3,
                         lo[2] - margin, hi[2] + margin))
    box.points = scaled(box.points, rut.position, scale)
    return box


def merge(meshes: list):
    """One mesh of several (pyvista PolyData), so each group is a single actor."""
    return meshes[0].merge(meshes[1:]) if len(meshes) > 1 else meshes[0]


def spheres(points: np.ndarray, radius: float):
    """One mesh of a sphere at each of ``points`` (N, 3): copies of one sphere's points and
    triangles, moved (a pyvista sphere built and merged per point took 3 ms each: 0.8 s for
    the markers of a 64-front-end arc)."""
    pts = np.atleast_2d(np.asarray(points, float))
    unit = pv.Sphere(radius=radius, center=(0.0, 0.0, 0.0), theta_resolution=16,
                     phi_resolution=12)
    m = unit.n_points
    tri = unit.faces.reshape(-1, 4)  # [3, a, b, c]: the source makes triangles only
    faces = np.tile(tri, (len(pts), 1, 1))
    faces[:, :, 1:] += (np.arange(len(pts)) * m)[:, None, None]
    mesh = pv.PolyData((unit.points[None] + pts[:, None]).reshape(-1, 3), faces.ravel())
    mesh.point_data["Normals"] = np.tile(unit.point_data["Normals"], (len(pts), 1))
    mesh.point_data.active_normals_name = "Normals"
    return mesh


def polyline(points: np.ndarray):
    return pv.lines_from_points(np.asarray(points, float))


def arc_points(setup: Setup, a_min: float, a_max: float) -> np.ndarray:
    """The front-end arc (module centres at zero mounting error) between two azimuths."""
    r_hat, _ = radial_tangent(np.linspace(a_min, a_max, 181))
    return setup.fe.arc_centre + setup.fe.arc_radius_m * r_hat


def angle_span(setup: Setup) -> tuple[float, float]:
    """Azimuth span of the drawing: the sheet, or the front ends with a margin."""
    cfg = setup.scene.sheet
    if cfg.enabled:
        return cfg.angle_min_rad, cfg.angle_max_rad
    a = setup.fe.angle_rad
    return float(a.min()) - np.radians(10), float(a.max()) + np.radians(10)


def cutout_rims(setup: Setup):
    """A circle at each cutout on the sheet's inner face, to show where the holes are."""
    cfg = setup.scene.sheet
    r0 = setup.fe.arc_radius_m + cfg.radius_offset_m
    t = np.linspace(0.0, 2 * np.pi, 73)
    rims = []
    for i, ang in enumerate(setup.fe.angle_rad):
        el = None if setup.fe.elevation_rad is None else setup.fe.elevation_rad[i]
        r_hat, t_hat, up = sphere_frame(ang, el)
        circle = (setup.fe.arc_centre + (r0 - 1e-4) * r_hat
                  + 0.5 * cfg.cutout_diameter_m * (np.cos(t)[:, None] * t_hat
                                                   + np.sin(t)[:, None] * up))
        rims.append(circle)
    return merge_lines(rims)


def modules(setup: Setup):
    """Front-end module bodies: a box behind each antenna pair (radially outward)."""
    fe = setup.fe
    boxes = []
    for i in range(fe.count):
        el = None if fe.elevation_rad is None else fe.elevation_rad[i]
        r_hat, t_hat, up = sphere_frame(fe.angle_rad[i], el)
        size_t = abs(fe.separation_m[i]) + 0.012  # smaller than the cutout: the hole stays visible
        box = pv.Box(bounds=(-size_t / 2, size_t / 2, 0.012, 0.024, -0.01, 0.01))
        rot = np.stack([t_hat, r_hat, up], axis=1)  # local (t, r, up) -> world
        box.points = box.points @ rot.T + fe.module[i]
        boxes.append(box)
    return merge(boxes)


def target_positions(setup: Setup) -> tuple[np.ndarray, np.ndarray]:
    """Drawn positions (T, 3) and outward directions (T, 3) of the virtual targets."""
    rut = setup.rut
    ang = np.array([t.angle_rad for t in setup.scene.targets], float)
    el = np.array([t.elevation_rad for t in setup.scene.targets], float)
    local = sphere_frame(ang, el if np.any(el) else None)[0]
    direction = local @ rut.rotation.T
    return rut.position + TARGET_RADIUS_FACTOR * setup.fe.arc_radius_m * direction, direction


def split_paths(paths):
    """``(Paths, vertices or None)`` from a :class:`~rtsgeom.paths.Paths` table or a ray-tracing
    result (:class:`~rtsgeom.paths.raytrace.RaytraceResult`, which carries the hit points)."""
    if paths is None:
        return None, None
    if hasattr(paths, "paths") and hasattr(paths, "vertices"):
        return paths.paths, paths.vertices
    return paths, getattr(paths, "vertices", None)


def hit_points(vertices, i: int) -> np.ndarray:
    """Row ``i``'s finite hit points, (n, 3) (none without ``vertices``)."""
    v = None if vertices is None else vertices[i]
    if v is None:
        return np.zeros((0, 3))
    v = np.atleast_2d(np.asarray(v, float))
    return v[np.all(np.isfinite(v), axis=-1)] if v.size else np.zeros((0, 3))


def undrawable_reflections(paths) -> int:
    """How many reflected rows of ``paths`` carry no hit points (they cannot be drawn)."""
    table, vertices = split_paths(paths)
    if table is None:
        return 0
    refl = np.flatnonzero(np.asarray(table.bounces) > 0)
    return int(sum(len(hit_points(vertices, i)) == 0 for i in refl))


def path_polylines(setup: Setup, paths, scale: float, bounces: bool = False
                   ) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Line-of-sight and reflected path polylines; RuT ends at the drawn (scaled) elements.

    ``paths``: a :class:`Paths` table or a ray-tracing result; a reflection is drawn through
    its hit points (``vertices``, NaN rows past the last interaction are dropped).
    ``bounces``: the reflections as a dict bounce count -> polylines instead of a list."""
    rut, fe = setup.rut, setup.fe
    tx = scaled(rut.tx_world, rut.position, scale)
    rx = scaled(rut.rx_world, rut.position, scale)
    paths, vertices = split_paths(paths)
    los, refl, counts = [], [], []
    for i in range(len(paths)):
        d, f = int(paths.direction[i]), int(paths.front_end[i])
        if d == TX_TO_FE:
            start, end = tx[paths.rut_tx[i]], fe.rx[f]
        elif d == FE_TO_RX:
            start, end = fe.tx[f], rx[paths.rut_rx[i]]
        elif d == RUT_TO_RUT:
            start, end = tx[paths.rut_tx[i]], rx[paths.rut_rx[i]]
        else:
            continue
        if int(paths.bounces[i]) == 0:
            if d != RUT_TO_RUT:  # direct Tx -> Rx coupling on the board: nothing to see
                los.append(np.array([start, end]))
            continue
        v = hit_points(vertices, i)
        if len(v) == 0:
            continue  # no hit points: counted by undrawable_reflections and noted in the view
        pts = [start] + [p for p in v if not (np.allclose(p, start) or np.allclose(p, end))] + [end]
        refl.append(np.array(pts))
        counts.append(int(paths.bounces[i]))
    if bounces:
        by: dict[int, list] = {}
        for n, poly in zip(counts, refl):
            by.setdefault(n, []).append(poly)
        return los, dict(sorted(by.items()))
    return los, refl


def merge_lines(polylines: list[np.ndarray]):
    """One mesh of line segments joining each polyline's consecutive points (as
    :func:`polyline` of each, merged; built at once: the 448 paths of a 64-front-end arc
    took 0.3 s as separate meshes)."""
    lines = [np.asarray(p, float).reshape(-1, 3) for p in polylines]
    if not lines:  # nothing to draw (a sheet without cutouts has no rims)
        return pv.PolyData()
    start = np.cumsum([0] + [len(p) for p in lines[:-1]])
    seg = np.concatenate([s + np.arange(len(p) - 1) for s, p in zip(start, lines)])
    cells = np.column_stack([np.full(len(seg), 2), seg, seg + 1])
    return pv.PolyData(np.concatenate(lines), lines=cells.ravel())
