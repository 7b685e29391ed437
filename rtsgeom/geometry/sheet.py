"""The curved metal sheet in front of the front ends, with a round cutout at each of them.

The sheet is a cylindrical shell sector coaxial with the arc (vertical axis through the arc
centre): inner face at ``R_c + radius_offset_m``, ``thickness_m`` thick, ``height_m`` tall,
centred on the arc's height. Cutouts are cylinders along each front end's radial direction,
subtracted with manifold3d so the result is watertight with outward normals.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..scene import SheetConfig
from .arc import radial_tangent

if TYPE_CHECKING:  # trimesh itself loads where a mesh is built (1 s of imports)
    import trimesh

__all__ = ["segments_blocked", "shell_sector", "sheet_mesh"]


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
    trimesh.repair.fix_normals(mesh)
    return mesh


def sheet_mesh(cfg: SheetConfig, arc_centre: np.ndarray, arc_radius_m: float,
               cutout_angles_rad: np.ndarray) -> trimesh.Trimesh:
    """The sheet with its cutouts, in world coordinates."""
    import trimesh
    r0 = arc_radius_m + cfg.radius_offset_m
    h = 0.5 * cfg.height_m
    shell = shell_sector(r0, cfg.thickness_m, cfg.angle_min_rad, cfg.angle_max_rad, -h, h)
    cutters = []
    length = 4.0 * cfg.thickness_m + 0.02
    for ang in np.asarray(cutout_angles_rad, float):
        cyl = trimesh.creation.cylinder(radius=0.5 * cfg.cutout_diameter_m, height=length,
                                        sections=64)
        r_hat, _ = radial_tangent(ang)
        align = trimesh.geometry.align_vectors([0.0, 0.0, 1.0], r_hat)
        align[:3, 3] = (r0 + 0.5 * cfg.thickness_m) * r_hat
        cyl.apply_transform(align)
        cutters.append(cyl)
    mesh = shell
    if cutters:
        mesh = trimesh.boolean.difference([shell, trimesh.util.concatenate(cutters)],
                                          engine="manifold")
    mesh.apply_translation(np.asarray(arc_centre, float))
    trimesh.repair.fix_normals(mesh)
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
