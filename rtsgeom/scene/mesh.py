"""A mesh object's scatterers by physical optics: flat faces, coherent returns, resolution cells.

A ``mesh = "car.ply"`` object (:mod:`rtsgeom.scene.objects` places it) is a perfectly conducting
surface. Its monostatic return is the physical-optics (PO) integral over the lit surface,

    sqrt(sigma) = sqrt(4 pi) / lambda * sum over lit surface of (n . d) exp(-j 2 k R(r)) dS,

(Knott, Shaeffer & Tuley, *Radar Cross Section*, 2nd ed., SciTech 2004, ch. 5; Balanis,
*Advanced Engineering Electromagnetics*, 2nd ed., Wiley 2012, sec. 11.3), ``d`` the unit
vector from the surface towards the RuT, ``n`` the outward normal, ``R(r)`` the distance of the
surface point ``r`` from the RuT, ``k = 2 pi / lambda``.

Far field (:func:`face_rcs`)
    Linearising ``R(r)`` about a point ``c``, ``R ~ R(c) - d . (r - c)``, a flat face's
    integral is ``I = int exp(j p . (r - c)) dS`` with ``p = 2 k d``; over a planar polygon it is
    a sum over its edges (Gordon, IEEE Trans. Antennas Propag. 23 (1975) 590): with ``p_t`` the
    part of ``p`` in the plane and ``a -> b`` an edge counter-clockwise about ``n``,
    ``I = sum_edges p_t . ((b - a) x n) / (j |p_t|^2) exp(j p_t . ((a + b)/2 - c))
    sinc(p_t . (b - a) / 2)`` (``sinc x = sin x / x``), and near normal incidence its Taylor
    series about the centroid. Each triangle's integral is summed coherently over the flat face
    it belongs to (coplanar adjacent triangles: trimesh's ``facets``; a triangle in no facet is
    a face of its own), so the face's ``sigma = 4 pi / lambda^2 (n . d)^2 |I|^2`` does not
    depend on its triangulation: ``4 pi A^2 / lambda^2`` at normal incidence, and for an
    ``a x b`` rectangle turned by ``theta`` about its side ``b``
    ``4 pi A^2 / lambda^2 cos^2(theta) sinc^2(k a sin theta)``.

Near field (:func:`mesh_scatterers`)
    A face larger than its Fresnel zone ``sqrt(lambda R)`` is not in its own far field: a car's
    flank 15 m away (4.5 m long, far field beyond 2 D^2 / lambda ~ 10 km) returns what a mirror
    does, ``pi R^2`` (28.5 dBsm), not ``4 pi A^2 / lambda^2`` (68 dBsm). Each lit triangle is
    therefore cut into n x n equal tiles (n a power of two) no longer than
    ``sqrt(lambda R_min) /`` :data:`TILE_PER_FRESNEL`, the two-way phase ``-2 k R`` taken
    exactly at the tiles' vertices and interpolated linearly over each tile (its integral the
    far-field one above, with the phase's gradient in the tile's plane; the mean departure of
    the exact phase from the interpolation, its bend, as a phase factor). The interpolated
    phase is continuous across every shared edge (where the triangle beside cuts an edge more
    coarsely, the tiles' vertices on it take the phase interpolated along the coarser cuts), so
    the tiles add without spurious edge terms, and are summed coherently per resolution cell
    of the RuT (its range resolution
    and the virtual aperture's Rayleigh cell ``2 / N_virtual`` in direction cosine, the grid
    centred where the whole return comes from, so a plate smaller than a cell is one; a cell
    never narrower than the Fresnel zone ``sqrt(lambda / R)``, whose return is one). Each cell
    is one scatterer with ``sigma = |sum|^2``, placed at the centroid of its tiles weighted by
    their share in phase with the cell's sum (the part of the surface that makes the return:
    a flank's specular spot, not its middle); a face larger than a cell is thereby split into
    the cells it spans, and faces within one cell add as the RuT sees them, with their
    interference. The strongest :data:`MAX_MESH_SCATTERERS` cells within
    :data:`MESH_DYNAMIC_DB` of the strongest are kept. A triangle is lit where it faces the RuT
    and no other triangle crosses the segment from its centre to the RuT.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import SceneError
from .schema import fmt

__all__ = ["FlatFaces", "flat_faces", "triangle_integrals", "face_rcs", "load_mesh",
           "mesh_scatterers", "MAX_MESH_FACETS", "MAX_MESH_BYTES", "MAX_MESH_SCATTERERS",
           "MAX_MESH_TILES", "MESH_DYNAMIC_DB", "TILE_PER_FRESNEL"]

MAX_MESH_FACETS = 4096  # triangles of one mesh (a car's outline needs a few hundred)
MAX_MESH_BYTES = 4 << 20  # a mesh file's size (read before it is parsed: memory bounded)
MAX_MESH_SCATTERERS = 32  # scatterers kept from a mesh per pose
MESH_DYNAMIC_DB = 40.0  # a mesh's scatterers within this of its strongest
TILE_PER_FRESNEL = 4.0  # a tile's longest edge: the Fresnel length sqrt(lambda R) over this
MAX_MESH_TILES = 1 << 17  # tiles of one pose (memory); beyond it the tiles grow
_RAY_CHUNK = 256  # facets per block of the visibility test (memory: chunk x facets)
_TAYLOR = 0.05  # |p_t| times the triangle's size below which its integral is a Taylor series


@dataclass(frozen=True, eq=False)  # numpy fields
class FlatFaces:
    """The flat faces of a triangle mesh: ``face_of`` (T,) the face of each triangle,
    ``normal`` (F, 3), ``area`` (F,) m^2 and ``centroid`` (F, 3) of each face."""

    face_of: np.ndarray
    normal: np.ndarray
    area: np.ndarray
    centroid: np.ndarray

    def __repr__(self) -> str:
        return f"FlatFaces({len(self.area)} faces of {len(self.face_of)} triangles)"


def flat_faces(vertices: np.ndarray, faces: np.ndarray) -> FlatFaces:
    """Group a mesh's triangles into flat faces: trimesh's ``facets`` (adjacent coplanar
    triangles), every other triangle a face of its own."""
    import trimesh  # only for a scene with a mesh
    m = trimesh.Trimesh(np.asarray(vertices, float), np.asarray(faces, np.int64), process=False)
    face_of = np.full(len(m.faces), -1, np.int64)
    for i, group in enumerate(m.facets):
        face_of[group] = i
    alone = np.flatnonzero(face_of < 0)
    face_of[alone] = len(m.facets) + np.arange(len(alone))
    tri = m.triangles
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    a_t = 0.5 * np.linalg.norm(cross, axis=1)
    n_faces = int(face_of.max()) + 1
    area = np.bincount(face_of, a_t, n_faces)
    cen = np.stack([np.bincount(face_of, a_t * tri.mean(axis=1)[:, j], n_faces)
                    for j in range(3)], axis=1) / np.maximum(area, 1e-300)[:, None]
    nrm = np.stack([np.bincount(face_of, cross[:, j], n_faces) for j in range(3)], axis=1)
    nrm = nrm / np.maximum(np.linalg.norm(nrm, axis=1), 1e-300)[:, None]
    return FlatFaces(face_of, nrm, area, cen)


def triangle_integrals(tri: np.ndarray, p: np.ndarray) -> np.ndarray:
    """``int_T exp(j p . (r - c_T)) dS`` (m^2, complex) over each triangle ``tri`` (T, 3, 3)
    about its centroid ``c_T``, for wave vectors ``p`` (T, 3) or (3,) in rad/m (module
    docstring: Gordon's edge sum, a third-order Taylor series where ``|p_t| size < 0.05``)."""
    tri = np.asarray(tri, float)
    c = tri.mean(axis=1)
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    two_a = np.linalg.norm(cross, axis=1)
    n = cross / np.maximum(two_a, 1e-300)[:, None]
    p = np.broadcast_to(np.asarray(p, float), c.shape)
    pt = p - np.einsum("tk,tk->t", p, n)[:, None] * n
    pt2 = np.einsum("tk,tk->t", pt, pt)
    rho = tri - c[:, None, :]  # (T, 3, 3) vertices about the centroid
    x = np.einsum("tvk,tk->tv", rho, pt)  # p_t . rho_v
    size = np.sqrt(pt2) * np.linalg.norm(rho, axis=2).max(axis=1)
    # Taylor about the centroid: E[x] = 0, E[x^2] = sum x_v^2 / 12, E[x^3] = sum x_v^3 / 30
    out = 0.5 * two_a * (1.0 - (x ** 2).sum(axis=1) / 24.0 - 1j * (x ** 3).sum(axis=1) / 180.0)
    far = size >= _TAYLOR
    if far.any():
        a, b, pf, nf = rho[far], np.roll(rho[far], -1, axis=1), pt[far], n[far]
        edge = b - a  # (T', 3 edges, 3): a -> b in the winding, counter-clockwise about n
        half = np.einsum("tek,tk->te", edge, pf) / 2.0
        weight = np.einsum("tek,tk->te", np.cross(edge, nf[:, None, :]), pf)
        phase = np.exp(1j * np.einsum("tek,tk->te", (a + b) / 2.0, pf))
        out[far] = (weight * phase * np.sinc(half / np.pi)).sum(axis=1) / (1j * pt2[far])
    return out


def face_rcs(vertices: np.ndarray, faces: np.ndarray, direction: np.ndarray,
             wavelength_m: float) -> tuple[FlatFaces, np.ndarray]:
    """Each flat face's far-field monostatic PO cross-section (m^2) seen from ``direction``
    (3,) (towards the RuT, any length): ``4 pi / lambda^2 (n . d)^2 |I|^2``, ``I`` the
    coherent sum of its triangles' integrals about the face's centroid; 0 for a face turned
    away. No shadowing: each face alone (:func:`mesh_scatterers` shadows and adds the near
    field)."""
    v = np.asarray(vertices, float)
    f = np.asarray(faces, np.int64)
    ff = flat_faces(v, f)
    d = np.asarray(direction, float)
    d = d / np.linalg.norm(d)
    k = 2.0 * math.pi / wavelength_m
    tri = v[f]
    c_t = tri.mean(axis=1)
    i_t = triangle_integrals(tri, 2.0 * k * d)
    i_t = i_t * np.exp(2j * k * (c_t - ff.centroid[ff.face_of]) @ d)
    i_f = (np.bincount(ff.face_of, i_t.real, len(ff.area))
           + 1j * np.bincount(ff.face_of, i_t.imag, len(ff.area)))
    cos_t = np.clip(ff.normal @ d, 0.0, None)
    return ff, 4.0 * math.pi / wavelength_m ** 2 * cos_t ** 2 * np.abs(i_f) ** 2


def load_mesh(path: str, where: str, source: str) -> tuple[np.ndarray, np.ndarray]:
    """A mesh file's vertices (V, 3) and triangular faces (F, 3), at most
    :data:`MAX_MESH_FACETS` facets in a file of at most :data:`MAX_MESH_BYTES`; every failure
    one ``SceneError`` naming ``where``."""
    p = Path(path)
    shown = fmt(p.name)
    size = p.stat().st_size
    if size > MAX_MESH_BYTES:
        raise SceneError(f"{source}: {where} = {shown}: must be a mesh file of at most "
                         f"{MAX_MESH_BYTES >> 20} MiB and {MAX_MESH_FACETS} facets (it has "
                         f"{size} bytes): decimate it (a car's outline needs a few hundred "
                         "facets)")
    import trimesh  # only for a scene with a mesh
    try:
        m = trimesh.load(str(p), force="mesh", process=True)
        v = np.asarray(m.vertices, float)
        f = np.asarray(m.faces, np.int64)
    except Exception as exc:  # trimesh raises many kinds for a file it cannot read
        raise SceneError(f"{source}: {where} = {shown}: must be a mesh file trimesh reads "
                         f"(PLY, STL, OBJ, GLB ...): {type(exc).__name__}: "
                         f"{str(exc)[:120]}") from None
    if f.ndim != 2 or f.shape[1] != 3 or not len(f):
        raise SceneError(f"{source}: {where} = {shown}: must be a mesh of triangles (it has "
                         "no facets)")
    if len(f) > MAX_MESH_FACETS:
        raise SceneError(f"{source}: {where} = {shown}: must be a mesh of at most "
                         f"{MAX_MESH_FACETS} facets (it has {len(f)}): decimate it")
    if not np.all(np.isfinite(v)) or np.abs(v).max() > 50.0:
        raise SceneError(f"{source}: {where} = {shown}: must have finite vertices within "
                         "50 m of the object's origin (metres)")
    return v, f


def _visible(centres: np.ndarray, tri: np.ndarray, radar: np.ndarray) -> np.ndarray:
    """Whether the RuT sees each facet's centre: no other facet crosses the segment from the
    centre to the RuT (Moeller-Trumbore, vectorised in blocks of facets)."""
    a, b, cc = tri[:, 0], tri[:, 1], tri[:, 2]
    e1, e2 = b - a, cc - a
    out = np.ones(len(centres), bool)
    for s in range(0, len(centres), _RAY_CHUNK):
        o = centres[s:s + _RAY_CHUNK]  # (R, 3)
        d = radar[None] - o  # segment to the RuT, t in (0, 1)
        pv = np.cross(d[:, None, :], e2[None])  # (R, F, 3)
        det = np.einsum("fk,rfk->rf", e1, pv)
        ok = np.abs(det) > 1e-12
        inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
        tv = o[:, None, :] - a[None]
        u = np.einsum("rfk,rfk->rf", tv, pv) * inv
        qv = np.cross(tv, e1[None])
        v = np.einsum("rk,rfk->rf", d, qv) * inv
        t = np.einsum("fk,rfk->rf", e2, qv) * inv
        hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 1e-6) & (t < 1.0)
        own = np.arange(s, s + len(o))
        hit[np.arange(len(o)), own] = False
        out[s:s + len(o)] = ~hit.any(axis=1)
    return out


def _grid(n: int) -> np.ndarray:
    """Integer barycentric coordinates (n^2, 3, 3) of the n x n uniform subdivision of a
    triangle (each row sums to n): tile t's vertex v is ``g[t, v] @ (r0, r1, r2) / n``;
    neighbouring tiles share their vertices."""
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    keep = i + j < n
    i, j = i[keep], j[keep]
    up = np.stack([np.c_[i, j], np.c_[i + 1, j], np.c_[i, j + 1]], 1)  # (n(n+1)/2, 3, 2)
    keep = i + j < n - 1
    down = np.stack([np.c_[i + 1, j], np.c_[i + 1, j + 1], np.c_[i, j + 1]], 1)[keep]
    ij = np.concatenate([up, down])
    return np.concatenate([n - ij.sum(axis=2, keepdims=True), ij], axis=2)


def _tiles(tri: np.ndarray, edge_n: np.ndarray, phase_of, max_edge_m: float
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each triangle (T, 3, 3) cut into n^2 equal tiles, n the smallest power of two that makes
    every edge at most ``max_edge_m`` (fewer where that makes more than
    :data:`MAX_MESH_TILES` tiles). ``edge_n(n)`` (T, 3): the fewest cuts of each triangle's
    edge v -> v+1 among the triangles that share it. A tile vertex on an edge its neighbour
    cuts more coarsely takes the phase interpolated along the neighbour's cuts (a hanging
    node), so the phase is continuous across every shared edge. Returns the tiles (N, 3, 3),
    each one's triangle (N,) and its vertices' phase (N, 3) from ``phase_of`` (points -> rad)."""
    longest = np.linalg.norm(tri - np.roll(tri, -1, axis=1), axis=2).max(axis=1)
    n = 2 ** np.ceil(np.log2(np.maximum(longest / max_edge_m, 1.0))).astype(np.int64)
    while (n ** 2).sum() > MAX_MESH_TILES:
        n = np.maximum(n // 2, 1)
    nb = edge_n(n)
    tiles, owner, phase = [], [], []
    for m in np.unique(n):
        sel = np.flatnonzero(n == m)
        g = _grid(int(m))  # (G, 3, 3) integer
        t = tri[sel]
        pts = np.einsum("gvw,twk->tgvk", g / m, t)
        ph = phase_of(pts)
        for e in range(3):  # edge e -> e+1: the vertices with no weight on e+2
            on = g[:, :, (e + 2) % 3] == 0  # (G, 3)
            coarse = nb[sel, e] < m
            if not (on.any() and coarse.any()):
                continue
            nc = nb[sel, e][:, None, None]  # (T', 1, 1)
            tc = g[None, :, :, (e + 1) % 3] / m * nc  # position along the edge in its cuts
            i0 = np.minimum(np.floor(tc), nc - 1)
            frac = tc - i0
            a, b = t[:, e][:, None, None, :], t[:, (e + 1) % 3][:, None, None, :]
            p0 = a + (i0 / nc)[..., None] * (b - a)
            p1 = a + ((i0 + 1) / nc)[..., None] * (b - a)
            hang = (1 - frac) * phase_of(p0) + frac * phase_of(p1)
            ph = np.where(on[None] & coarse[:, None, None], hang, ph)
        tiles.append(pts.reshape(-1, 3, 3))
        owner.append(np.repeat(sel, len(g)))
        phase.append(ph.reshape(-1, 3))
    return np.concatenate(tiles), np.concatenate(owner), np.concatenate(phase)


def _lin_integrals(tiles: np.ndarray, phase: np.ndarray) -> np.ndarray:
    """``int_T exp(j phi) dS`` over each tile (N, 3, 3), ``phi`` the linear interpolation of its
    vertices' ``phase`` (N, 3): continuous across shared edges, so tiles add without the
    spurious edge terms a per-tile linearisation leaves."""
    e = np.roll(tiles, -1, axis=1) - tiles  # edge v -> v + 1
    n2 = np.cross(e[:, 0], -e[:, 2])  # 2 A n
    two_a2 = np.einsum("tk,tk->t", n2, n2)
    # grad of barycentric lambda_v: n x (r_{v+2} - r_{v+1}) / (2A) = (2A n) x e_{v+1} / (2A)^2
    grad = np.cross(n2[:, None, :], np.roll(e, -1, axis=1)) / two_a2[:, None, None]
    g = np.einsum("tv,tvk->tk", phase, grad)
    return np.exp(1j * phase.mean(axis=1)) * triangle_integrals(tiles, g)


def _edge_cuts(faces: np.ndarray):
    """For triangles ``faces`` (T, 3) (vertex indices): a function of their cuts n (T,) giving,
    per triangle and edge v -> v+1 (T, 3), the fewest cuts among the triangles sharing it."""
    e = np.stack([faces, np.roll(faces, -1, axis=1)], axis=2)  # (T, 3, 2)
    _, key = np.unique(np.sort(e, axis=2).reshape(-1, 2), axis=0, return_inverse=True)
    key = key.ravel()

    def edge_n(n: np.ndarray) -> np.ndarray:
        fewest = np.full(key.max() + 1, np.iinfo(np.int64).max)
        np.minimum.at(fewest, key, np.repeat(n, 3))
        return fewest[key].reshape(-1, 3)
    return edge_n


def mesh_scatterers(vertices: np.ndarray, faces: np.ndarray, radar_obj: np.ndarray,
                    wavelength_m: float, cell_m: float, cell_u: float
                    ) -> tuple[np.ndarray, np.ndarray]:
    """A mesh's scatterers seen from ``radar_obj`` (the RuT in the object's frame): points
    (N, 3) in the object's frame and their RCS (N,) in dBsm (module docstring: near-field
    physical optics, coherent per resolution cell of ``cell_m`` in range and ``cell_u`` in
    direction cosine). An empty result: no facet faces the RuT."""
    tri = np.asarray(vertices, float)[np.asarray(faces, np.int64)]  # (F, 3, 3)
    cen = tri.mean(axis=1)
    nrm = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    area = 0.5 * np.linalg.norm(nrm, axis=1)
    los = radar_obj[None] - cen
    facing = (np.einsum("fk,fk->f", nrm, los) > 1e-6 * np.linalg.norm(los, axis=1)
              * 2.0 * area) & (area > 0)
    idx = np.flatnonzero(facing)
    if idx.size:
        idx = idx[_visible(cen[idx], tri, radar_obj)]
    if not idx.size:  # nothing faces the RuT, or every facing facet hidden
        return np.zeros((0, 3)), np.zeros(0)
    r_min = np.linalg.norm(tri[idx] - radar_obj, axis=2).min()
    k = 2.0 * math.pi / wavelength_m
    tiles, owner, phase = _tiles(
        tri[idx], _edge_cuts(np.asarray(faces, np.int64)[idx]),
        lambda pts: -2.0 * k * np.linalg.norm(pts - radar_obj, axis=-1),  # exp(-j 2 k R)
        math.sqrt(wavelength_m * r_min) / TILE_PER_FRESNEL)
    c = tiles.mean(axis=1)
    rel = radar_obj[None] - c
    r = np.linalg.norm(rel, axis=1)
    n = nrm[idx][owner] / (2.0 * area[idx][owner])[:, None]
    mid = 0.5 * (tiles + np.roll(tiles, -1, axis=1))  # the phase's mean departure from its
    bend = (-2.0 * k * np.linalg.norm(mid - radar_obj, axis=-1)  # linear interpolation over a
            - 0.5 * (phase + np.roll(phase, -1, axis=1))).sum(axis=1) / 3.0  # tile (its bend)
    amp = (math.sqrt(4.0 * math.pi) / wavelength_m * np.einsum("tk,tk->t", n, rel) / r
           * _lin_integrals(tiles, phase) * np.exp(1j * bend))
    # cells of range and direction cosine seen from the RuT (its lateral axis: the object
    # frame's x turned with the RuT's line of sight to the object's origin)
    axis = np.cross(-radar_obj, [0.0, 0.0, 1.0])
    axis = axis / max(np.linalg.norm(axis), 1e-12)
    u = -(rel @ axis) / r
    w = np.clip((amp * np.conj(amp.sum())).real, 0.0, None)  # the grid's centre: where the
    if not w.sum() > 0:  # whole return comes from (an object of one face: in one cell)
        w = np.abs(amp)
    r0, u0 = np.average(r, weights=w), np.average(u, weights=w)
    cell_u = max(cell_u, math.sqrt(wavelength_m / r_min))  # never below the Fresnel zone
    ir = np.round((r - r0) / cell_m).astype(np.int64)
    iu = np.round((u - u0) / cell_u).astype(np.int64)
    iu -= iu.min()
    _, cell = np.unique((ir - ir.min()) * (iu.max() + 1) + iu, return_inverse=True)
    total = np.bincount(cell, amp.real) + 1j * np.bincount(cell, amp.imag)
    w = np.clip((amp * np.conj(total[cell])).real, 0.0, None)  # in phase with the cell's sum
    wsum = np.bincount(cell, w, len(total))
    pos = np.stack([np.bincount(cell, w * c[:, j], len(total)) for j in range(3)], axis=1)
    power = np.abs(total) ** 2
    keep = (power > 0) & (wsum > 0)
    pos, power = pos[keep] / wsum[keep, None], power[keep]
    if not len(power):
        return np.zeros((0, 3)), np.zeros(0)
    order = np.argsort(power)[::-1][:MAX_MESH_SCATTERERS]
    order = order[power[order] >= power[order[0]] * 10 ** (-MESH_DYNAMIC_DB / 10)]
    return pos[order], 10.0 * np.log10(power[order])
