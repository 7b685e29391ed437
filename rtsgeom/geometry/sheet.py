"""The curved metal sheet in front of the front ends, with a round cutout at each of them.

The sheet is a cylindrical shell sector coaxial with the arc (vertical axis through the arc
centre): inner face at ``R_c + radius_offset_m``, ``thickness_m`` thick, ``height_m`` tall,
centred on the arc's height. With front ends on a sphere (any non-zero elevation) it is a
spherical-cap section about the arc centre instead: the same azimuth extent, elevations within
+-asin(height_m / 2 r) (``height_m`` as the chord). Cutouts are cylinders along each front end's
radial direction, subtracted with manifold3d so the result is watertight with outward normals.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..scene import SheetConfig
from .frontends import radial_tangent
from .._lib.arcmath import sphere_frame

if TYPE_CHECKING:  # trimesh itself loads where a mesh is built (1 s of imports)
    import trimesh

__all__ = ["segments_blocked", "shell_sector", "cap_sector", "sheet_mesh"]


def shell_sector(r_inner: float, thickness: float, angle_min: float, angle_max: float,
                 z_min: float, z_max: float, max_step_rad: float = np.radians(0.5)
                 ) -> trimesh.Trimesh:
    """Watertight cylindrical shell sector about the z axis (azimuth from +y towards +x)."""
    import trimesh  # here, not at the top: 1 s of imports that `rtsgeom info` does not need
    n = max(2, int(np.ceil((angle_max - angle_min) / max_step_rad)) + 1)
    a = np.linspace(angle_min, angle_max, n)
    r_hat, _ = radial_tangent(a)  # (n, 3)
    verts = []
    for r in (r_inner, r_inner + thickness):  # ring index: 0 inner, 1 outer
        for z in (z_min, z_max):  # 0 bottom, 1 top
            verts.append(r * r_hat + np.array([0.0, 0.0, z]))
    v = np.concatenate(verts)  # block k = 2*ring + level, each n vertices

    def idx(ring, level, i):
        return (2 * ring + level) * n + i

    faces = []
    i = np.arange(n - 1)
    j = i + 1
    # each quad (a, b, c, d) -> two triangles; orientation fixed afterwards by fix_normals
    quads = [
        (idx(0, 0, i), idx(0, 1, i), idx(0, 1, j), idx(0, 0, j)),  # inner face
        (idx(1, 0, i), idx(1, 0, j), idx(1, 1, j), idx(1, 1, i)),  # outer face
        (idx(0, 1, i), idx(1, 1, i), idx(1, 1, j), idx(0, 1, j)),  # top
        (idx(0, 0, i), idx(0, 0, j), idx(1, 0, j), idx(1, 0, i)),  # bottom
    ]
    for q in quads:
        q = np.stack(q, -1)
        faces.append(q[:, [0, 1, 2]])
        faces.append(q[:, [0, 2, 3]])
    for end in (0, n - 1):  # end caps
        cap = np.array([idx(0, 0, end), idx(1, 0, end), idx(1, 1, end), idx(0, 1, end)])
        faces.append(cap[None, [0, 1, 2]])
        faces.append(cap[None, [0, 2, 3]])
    mesh = trimesh.Trimesh(v, np.concatenate(faces), process=True)
    trimesh.repair.fix_normals(mesh)  # the end caps' winding is not set above
    return mesh


def cap_sector(r_inner: float, thickness: float, angle_min: float, angle_max: float,
               el_min: float, el_max: float, max_step_rad: float = np.radians(0.5)
               ) -> trimesh.Trimesh:
    """Watertight spherical shell section about the origin: azimuth in [angle_min, angle_max]
    (from +y towards +x), elevation in [el_min, el_max]; inner radius ``r_inner``.

    A grid of (azimuth, elevation) directions on two radii, closed by four side walls; the
    outline of the (n_a x n_e) grid is walked once so each wall is one strip of quads."""
    import trimesh  # here, not at the top (see shell_sector)
    n_a = max(2, int(np.ceil((angle_max - angle_min) / max_step_rad)) + 1)
    n_e = max(2, int(np.ceil((el_max - el_min) / max_step_rad)) + 1)
    az, el = np.meshgrid(np.linspace(angle_min, angle_max, n_a),
                         np.linspace(el_min, el_max, n_e), indexing="ij")
    r_hat, _, _ = sphere_frame(az, el)  # (n_a, n_e, 3)
    n = n_a * n_e
    v = np.concatenate([(r * r_hat).reshape(-1, 3) for r in (r_inner, r_inner + thickness)])
    idx = np.arange(n).reshape(n_a, n_e)
    a, b, cc, d = idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]
    quads = [np.stack([a, b, cc, d], -1).reshape(-1, 4)]  # inner face
    quads.append(quads[0][:, ::-1] + n)  # outer face
    ring = np.concatenate([idx[:, 0], idx[-1, 1:], idx[-2::-1, -1], idx[0, -2:0:-1]])
    nxt = np.roll(ring, -1)
    # side walls, wound against the faces' edges they share (consistent winding: outward()
    # then needs one global flip at most)
    quads.append(np.stack([ring, ring + n, nxt + n, nxt], -1))
    q = np.concatenate(quads)
    mesh = trimesh.Trimesh(v, np.concatenate([q[:, [0, 1, 2]], q[:, [0, 2, 3]]]), process=True)
    outward(mesh)
    return mesh


def outward(mesh) -> None:
    """Every face's normal outward, in place. A mesh wound consistently (built so, or a
    boolean's result) needs at most one global flip (``trimesh.repair.fix_inversion``);
    ``fix_normals`` walks the face adjacency in Python to re-wind, 19 of the 23 s that a
    0.5-deg spherical cap's sheet took, and is kept for a mesh that needs it."""
    import trimesh
    if mesh.is_winding_consistent:
        trimesh.repair.fix_inversion(mesh)
    else:
        trimesh.repair.fix_normals(mesh)


def sheet_mesh(cfg: SheetConfig, arc_centre: np.ndarray, arc_radius_m: float,
               cutout_angles_rad: np.ndarray, cutout_elevations_rad: np.ndarray | None = None
               ) -> trimesh.Trimesh:
    """The sheet with its cutouts, in world coordinates: a cylinder section, or a
    spherical-cap section where ``cutout_elevations_rad`` has a non-zero elevation."""
    import trimesh
    r0 = arc_radius_m + cfg.radius_offset_m
    h = 0.5 * cfg.height_m
    ang_all = np.asarray(cutout_angles_rad, float)
    cap = cutout_elevations_rad is not None and np.any(cutout_elevations_rad)
    if cap:
        top = float(np.arcsin(min(1.0, h / r0)))
        shell = cap_sector(r0, cfg.thickness_m, cfg.angle_min_rad, cfg.angle_max_rad, -top, top)
        elev = np.asarray(cutout_elevations_rad, float)
    else:
        shell = shell_sector(r0, cfg.thickness_m, cfg.angle_min_rad, cfg.angle_max_rad, -h, h)
        elev = np.zeros_like(ang_all)
    cutters = []
    length = 4.0 * cfg.thickness_m + 0.02
    for ang, el in zip(ang_all, elev):
        cyl = trimesh.creation.cylinder(radius=0.5 * cfg.cutout_diameter_m, height=length,
                                        sections=64)
        r_hat = sphere_frame(ang, el)[0] if cap else radial_tangent(ang)[0]
        align = trimesh.geometry.align_vectors([0.0, 0.0, 1.0], r_hat)
        align[:3, 3] = (r0 + 0.5 * cfg.thickness_m) * r_hat
        cyl.apply_transform(align)
        cutters.append(cyl)
    mesh = shell
    if cutters:
        mesh = trimesh.boolean.difference([shell, trimesh.util.concatenate(cutters)],
                                          engine="manifold")
    mesh.apply_translation(np.asarray(arc_centre, float))
    outward(mesh)
    return mesh


def segments_blocked(mesh: trimesh.Trimesh, start: np.ndarray, end: np.ndarray,
                     eps: float = 1e-9) -> np.ndarray:
    """Whether each segment ``start[i] -> end[i]`` crosses a triangle of ``mesh``.

    Moller-Trumbore, vectorised over segments x triangles (fine for the sheet's ~10^3 faces).
    Used to check that each antenna sees the RuT through its cutout.
    """
    p0 = np.atleast_2d(np.asarray(start, float))[:, None, :]
    d = np.atleast_2d(np.asarray(end, float))[:, None, :] - p0
    tri = mesh.triangles  # (T, 3, 3)
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    h = np.cross(d, e2)
    a = np.einsum("stk,tk->st", h, e1)
    ok = np.abs(a) > eps
    f = np.where(ok, 1.0 / np.where(ok, a, 1.0), 0.0)
    s = p0 - tri[:, 0]
    u = f * np.einsum("stk,stk->st", s, h)
    q = np.cross(s, e1)
    v = f * np.einsum("sik,stk->st", d, q)
    t = f * np.einsum("tk,stk->st", e2, q)
    hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > eps) & (t < 1 - eps)
    return hit.any(axis=1)
