"""A mesh object's physical optics (rtsgeom.scene.mesh) against closed forms over grids.

Far field: a flat perfectly conducting a x b plate's monostatic PO cross-section is
``4 pi A^2 / lambda^2 cos^2(theta) sinc^2(k a sin(theta) cos(phi)) sinc^2(k b sin(theta) sin(phi))``
(``sinc x = sin x / x``; theta off the normal, phi from side a; Balanis, Advanced Engineering
Electromagnetics, 2nd ed., sec. 11.3.2; Mahafza, Radar Systems Analysis and Design Using MATLAB,
ch. on RCS of simple objects), whatever its triangulation. Near field at normal incidence
(Fresnel approximation of the two-way phase, ``2 k R(r) ~ 2 k R + k (x^2 + y^2) / R``):
``sigma = 4 pi / lambda^2 |F(a) F(b)|^2`` with ``F(a) = int_{-a/2}^{a/2} exp(-j k x^2 / R) dx``,
which is ``4 pi A^2 / lambda^2`` for a plate small against its Fresnel zone sqrt(lambda R) and
``pi R^2`` (a mirror) for a large one.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh
from scipy.special import fresnel
from scipy.spatial import Delaunay

import rtsgeom.scene.mesh as mesh_mod
from rtsgeom.scene.mesh import face_rcs, flat_faces, mesh_scatterers, triangle_integrals

LAM = 299792458.0 / 77e9
K = 2.0 * math.pi / LAM


def plate(a: float, b: float, subdivide: int = 0, random_points: int = 0, seed: int = 0
          ) -> trimesh.Trimesh:
    """An a (along x) x b (along z) plate in the plane y = 0, normal -y (towards a radar at
    -y); two triangles, each split into four ``subdivide`` times, or a Delaunay triangulation
    with ``random_points`` inner points (triangles of every size and shape)."""
    xz = np.array([[-a / 2, -b / 2], [a / 2, -b / 2], [a / 2, b / 2], [-a / 2, b / 2]])
    if random_points:
        rng = np.random.default_rng(seed)
        xz = np.r_[xz, (rng.random((random_points, 2)) - 0.5) * [a * 0.98, b * 0.98]]
    f = Delaunay(xz).simplices
    v = np.c_[xz[:, 0], np.zeros(len(xz)), xz[:, 1]]
    n_y = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])[:, 1]
    f[n_y > 0] = f[n_y > 0][:, ::-1]
    m = trimesh.Trimesh(v, f, process=False)
    for _ in range(subdivide):
        m = m.subdivide()
    return m


TRIANGULATIONS = [dict(), dict(subdivide=1), dict(subdivide=2), dict(subdivide=3),
                  dict(random_points=25, seed=1), dict(random_points=60, seed=2)]


def sinc(x):
    return np.sinc(np.asarray(x) / np.pi)


def fresnel_sigma(a: float, b: float, r: float) -> float:
    def f(w):
        t = w / 2 * math.sqrt(2 * K / (math.pi * r))
        s, c = fresnel(t)
        return math.sqrt(math.pi * r / (2 * K)) * 2 * (c - 1j * s)
    return 4 * math.pi / LAM ** 2 * abs(f(a) * f(b)) ** 2


def test_plate_triangulations_are_what_they_claim():
    counts = [len(plate(0.2, 0.2, **t).faces) for t in TRIANGULATIONS]
    assert counts[:4] == [2, 8, 32, 128] and min(counts[4:]) > 40
    for t in TRIANGULATIONS:
        m = plate(0.3, 0.1, **t)
        assert np.allclose(m.face_normals, [0, -1, 0]) and math.isclose(m.area, 0.03)


def test_flat_faces_group_coplanar_triangles():
    box = trimesh.creation.box([0.3, 0.2, 0.1])
    ff = flat_faces(box.vertices, box.faces)
    assert len(ff.area) == 6 and np.allclose(np.sort(ff.area), [.02, .02, .03, .03, .06, .06])
    for t in TRIANGULATIONS:
        m = plate(0.3, 0.1, **t)
        ff = flat_faces(m.vertices, m.faces)
        assert len(ff.area) == 1 and math.isclose(ff.area[0], 0.03)
        assert np.allclose(ff.normal[0], [0, -1, 0]) and np.allclose(ff.centroid[0], 0, atol=1e-12)
    ico = trimesh.creation.icosphere(subdivisions=1)  # no two triangles coplanar
    assert len(flat_faces(ico.vertices, ico.faces).area) == len(ico.faces)


@pytest.mark.parametrize("t", TRIANGULATIONS)
@pytest.mark.parametrize("a, b", [(0.05, 0.05), (0.2, 0.2), (0.3, 0.1), (0.5, 0.25)])
def test_plate_normal_incidence_is_area_squared(a, b, t):
    m = plate(a, b, **t)
    _, sigma = face_rcs(m.vertices, m.faces, [0, -1, 0], LAM)
    assert sigma.sum() == pytest.approx(4 * math.pi * (a * b) ** 2 / LAM ** 2, rel=1e-9)


@pytest.mark.parametrize("t", TRIANGULATIONS)
@pytest.mark.parametrize("a, b", [(0.2, 0.2), (0.3, 0.1), (0.1, 0.4)])
def test_tilted_plate_is_the_sinc_squared_lobe(a, b, t):
    """Turned by theta about its side b (and about a): the principal-plane lobe
    ``4 pi A^2 / lambda^2 cos^2 theta sinc^2(k a sin theta)``, nulls and side lobes included;
    checked on the field (sqrt sigma) against the peak's, so the nulls count too."""
    m = plate(a, b, **t)
    peak = math.sqrt(4 * math.pi) * a * b / LAM
    th = np.radians([0.05, 0.3, 1.0, 2.0, 5.0, 10.0, 30.0, 60.0, 85.0])
    for side, d in ((a, np.c_[np.sin(th), -np.cos(th), 0 * th]),
                    (b, np.c_[0 * th, -np.cos(th), np.sin(th)])):
        got = np.array([math.sqrt(face_rcs(m.vertices, m.faces, di, LAM)[1].sum()) for di in d])
        want = peak * np.cos(th) * np.abs(sinc(K * side * np.sin(th)))
        assert np.allclose(got, want, rtol=1e-7, atol=1e-9 * peak)


def test_plate_off_the_principal_planes_is_the_product_of_sincs():
    a, b = 0.3, 0.12
    m = plate(a, b, random_points=30, seed=3)
    peak = math.sqrt(4 * math.pi) * a * b / LAM
    for th_deg in (0.5, 3.0, 20.0):
        for ph_deg in (10.0, 45.0, 130.0):
            th, ph = math.radians(th_deg), math.radians(ph_deg)
            d = [math.sin(th) * math.cos(ph), -math.cos(th), math.sin(th) * math.sin(ph)]
            got = math.sqrt(face_rcs(m.vertices, m.faces, d, LAM)[1].sum())
            want = peak * math.cos(th) * abs(sinc(K * a * math.sin(th) * math.cos(ph))
                                             * sinc(K * b * math.sin(th) * math.sin(ph)))
            assert got == pytest.approx(want, rel=1e-7, abs=1e-9 * peak)


def test_triangle_integral_against_quadrature():
    """One triangle's integral, Taylor and edge-sum branches both, against a dense midpoint
    rule on its 400^2 sub-triangles."""
    rng = np.random.default_rng(5)
    for _ in range(4):
        tri = rng.normal(size=(1, 3, 3)) * 0.02
        g = mesh_mod._grid(400) / 400.0
        sub = np.einsum("gvw,wk->gvk", g, tri[0])
        c, area = sub.mean(axis=1), 0.5 * np.linalg.norm(
            np.cross(tri[0, 1] - tri[0, 0], tri[0, 2] - tri[0, 0]))
        for scale in (1e-3, 1.0, 30.0, 300.0):  # |p_t| x size from 1e-5 to ~10
            p = rng.normal(size=3) * scale
            want = area / len(sub) * np.exp(1j * (c - tri[0].mean(axis=0)) @ p).sum()
            got = triangle_integrals(tri, p)[0]
            assert abs(got - want) <= 2e-4 * area


@pytest.mark.parametrize("size", [(0.3, 0.2, 0.1), (0.5, 0.5, 0.05)])
def test_box_face_alone_returns(size):
    """A box seen along each face's normal: that face's 4 pi A^2 / lambda^2; the four faces at
    grazing and the far one return nothing; far away through mesh_scatterers too (one cell)."""
    box = trimesh.creation.box(size)
    for axis in range(3):
        for sign in (-1.0, 1.0):
            d = np.zeros(3)
            d[axis] = sign
            ff, sigma = face_rcs(box.vertices, box.faces, d, LAM)
            area = np.prod(np.delete(size, axis))
            lit = np.isclose(ff.normal @ d, 1.0)
            assert lit.sum() == 1 and sigma[lit][0] == pytest.approx(
                4 * math.pi * area ** 2 / LAM ** 2, rel=1e-9)
            assert np.all(sigma[~lit] <= 1e-20 * sigma[lit][0])
            _, rcs = mesh_scatterers(box.vertices, box.faces, 1e5 * d, LAM, 1e3, 10.0)
            assert len(rcs) == 1 and rcs[0] == pytest.approx(
                10 * math.log10(4 * math.pi * area ** 2 / LAM ** 2), abs=0.01)


@pytest.mark.parametrize("t", TRIANGULATIONS)
@pytest.mark.parametrize("a, b, r", [(0.2, 0.2, 15.0), (0.6, 0.3, 10.0), (1.2, 1.2, 20.0),
                                     (0.1, 0.05, 3.0)])
def test_near_field_plate_is_the_fresnel_closed_form(a, b, r, t):
    """Normal incidence from r: the Fresnel closed form, whatever the triangulation (a 0.2 m
    plate 15 m away: 30.33 dBsm; summed per triangle in power it was 25.1 dBsm with 2 triangles
    and 10.0 dBsm with 128); from a small plate's far field (4 pi A^2 / lambda^2) to a large
    plate's mirror (pi R^2)."""
    m = plate(a, b, **t)
    _, rcs = mesh_scatterers(m.vertices, m.faces, np.array([0.0, -r, 0.0]), LAM, 1e3, 10.0)
    assert len(rcs) == 1
    assert rcs[0] == pytest.approx(10 * math.log10(fresnel_sigma(a, b, r)), abs=0.1)


def test_near_field_limits_of_the_closed_form():
    """The closed form the near-field test uses has the two limits it claims."""
    assert 10 * math.log10(fresnel_sigma(0.05, 0.05, 100.0)) == pytest.approx(
        10 * math.log10(4 * math.pi * 0.05 ** 4 / LAM ** 2), abs=0.01)
    assert 10 * math.log10(fresnel_sigma(40.0, 40.0, 20.0)) == pytest.approx(
        10 * math.log10(math.pi * 20.0 ** 2), abs=0.2)


@pytest.mark.parametrize("x0", [-0.4, 0.0, 0.3])
def test_a_face_larger_than_a_cell_is_split_and_returns_from_its_specular_spot(x0):
    """A 1.6 m plate 5 m ahead, the RuT in front of x0, cells of 0.1 in direction cosine
    (0.5 m, 3.6 Fresnel lengths): the plate spans several cells; the strongest is at the foot
    of the perpendicular (within a Fresnel length) and returns what the mirror does, pi R^2,
    within the Fresnel ripple of the cell's edges; with the RuT in front of the plate's middle
    that cell is a 0.5 m x 0.8 m plate (the Fresnel closed form); the others are weaker."""
    m = plate(1.6, 0.8, subdivide=1)
    r = 5.0
    pts, rcs = mesh_scatterers(m.vertices, m.faces, np.array([x0, -r, 0.0]), LAM, 0.15, 0.1)
    assert len(rcs) >= 3
    assert np.all(np.abs(pts[:, 0]) <= 0.8) and np.allclose(pts[:, 1], 0.0)
    assert abs(pts[0, 0] - x0) <= math.sqrt(LAM * r) and abs(pts[0, 2]) <= math.sqrt(LAM * r)
    assert rcs[0] == pytest.approx(10 * math.log10(math.pi * r ** 2), abs=1.5)
    if x0 == 0.0:
        assert rcs[0] == pytest.approx(10 * math.log10(fresnel_sigma(0.5, 0.8, r)), abs=0.1)
    assert np.all(rcs[1:] <= rcs[0] - 10.0)


def test_tiles_are_bounded_in_memory():
    """A 100 m^2 face 1 m away would want 10^6 tiles: at most MAX_MESH_TILES are made."""
    m = plate(10.0, 10.0)
    tri = m.vertices[m.faces]
    tiles, owner, phase = mesh_mod._tiles(tri, mesh_mod._edge_cuts(m.faces), lambda p: 0 * p[..., 0],
                                          math.sqrt(LAM * 1.0) / mesh_mod.TILE_PER_FRESNEL)
    assert 0 < len(tiles) <= mesh_mod.MAX_MESH_TILES and len(owner) == len(phase) == len(tiles)
    area = 0.5 * np.linalg.norm(np.cross(tiles[:, 1] - tiles[:, 0], tiles[:, 2] - tiles[:, 0]),
                                axis=1)
    assert area.sum() == pytest.approx(100.0)


@pytest.mark.parametrize("heading_deg, side", [(0.0, 0.2), (0.0, 0.05), (3.0, 0.05),
                                               (-10.0, 0.05)])
def test_a_plate_mesh_in_a_scene_is_the_closed_form(tmp_path, heading_deg, side):
    """Through the scene file: a square plate mesh 15 m ahead (its normal towards the RuT at
    heading 0) is one target at 15 m with the closed form's RCS at the radar's wavelength,
    the Fresnel one at normal incidence, the far-field sinc^2 lobe turned (a 5 cm plate is
    in its far field beyond 1.3 m)."""
    from .test_objects import bench_doc, with_object
    from rtsgeom.scene import parse_scene
    plate(side, side).export(tmp_path / "plate.stl")
    s = parse_scene(with_object(bench_doc(), mesh="plate.stl", heading_deg=heading_deg),
                    "p.toml", base_dir=tmp_path)
    lam = s.radar.wavelength_m
    k = 2 * math.pi / lam
    if heading_deg == 0.0:
        def f(w):
            sn, cs = fresnel(w / 2 * math.sqrt(2 * k / (math.pi * 15.0)))
            return math.sqrt(math.pi * 15.0 / (2 * k)) * 2 * (cs - 1j * sn)
        want = 4 * math.pi / lam ** 2 * abs(f(side)) ** 4
    else:
        th = math.radians(heading_deg)
        want = (4 * math.pi * side ** 4 / lam ** 2 * math.cos(th) ** 2
                * sinc(k * side * math.sin(th)) ** 2)
    assert len(s.targets) == 1 and s.targets[0].range_m == pytest.approx(15.0, abs=1e-3)
    assert s.targets[0].rcs_dbsm == pytest.approx(10 * math.log10(want), abs=0.1)
