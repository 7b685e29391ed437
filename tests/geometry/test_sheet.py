"""Tests of ``rtsgeom.geometry.sheet``: closed forms and invariants on grids of inputs."""

from __future__ import annotations

import numpy as np
import trimesh


def test_segments_through_a_triangle_edge_are_blocked():
    """A segment through an edge of a facet counts as blocked (barycentric u or v == 0)."""
    from rtsgeom.geometry.sheet import segments_blocked
    tri = trimesh.Trimesh(vertices=[[0, 0, 0], [1, 0, 0], [0, 1, 0]], faces=[[0, 1, 2]],
                          process=False)
    for x, y in [(0.5, 0.0), (0.0, 0.5), (0.5, 0.5), (0.25, 0.25)]:
        assert segments_blocked(tri, np.array([[x, y, -1.0]]), np.array([[x, y, 1.0]]))[0]
    assert not segments_blocked(tri, np.array([[0.6, 0.6, -1.0]]), np.array([[0.6, 0.6, 1.0]]))[0]


import math

import pytest


@pytest.mark.parametrize("r, t, a0, a1, z0, z1, step", [
    (1.0, 0.002, -0.2, 0.3, -0.15, 0.15, math.radians(0.5)),
    (0.5, 0.01, 0.1, 0.1005, -0.1, 0.3, math.radians(0.5)),  # narrower than a step: 2 columns
    (2.0, 0.005, -1.0, 1.0, 0.0, 0.05, 0.3),
])
def test_a_shell_sector_is_the_polygonal_shell_in_closed_form(r, t, a0, a1, z0, z1, step):
    """n = max(2, ceil(span / step) + 1) azimuths from a0 to a1 (from +y towards +x) on the
    inner and outer radius at both heights; watertight, outward, with the volume of n - 1
    annular wedges 0.5 (r_o^2 - r_i^2) sin(span / (n - 1)) (z1 - z0)."""
    from rtsgeom.geometry.sheet import shell_sector
    mesh = shell_sector(r, t, a0, a1, z0, z1, step)
    n = max(2, math.ceil((a1 - a0) / step) + 1)
    a = np.linspace(a0, a1, n)
    want = np.array([[rr * math.sin(x), rr * math.cos(x), z] for rr in (r, r + t)
                     for z in (z0, z1) for x in a])
    assert mesh.vertices.shape == (4 * n, 3) and mesh.faces.shape == (8 * (n - 1) + 4, 3)
    got = np.array(sorted(map(tuple, np.round(mesh.vertices, 12))))
    np.testing.assert_allclose(got, np.array(sorted(map(tuple, np.round(want, 12)))),
                               atol=1e-12)
    assert mesh.is_watertight and mesh.is_winding_consistent
    vol = (n - 1) * 0.5 * ((r + t) ** 2 - r ** 2) * math.sin((a1 - a0) / (n - 1)) * (z1 - z0)
    assert mesh.volume == pytest.approx(vol, rel=1e-9)
    assert shell_sector(r, t, a0, a1, z0, z1).vertices.shape[0] == 4 * max(
        2, math.ceil((a1 - a0) / math.radians(0.5)) + 1)  # the default step: 0.5 deg


@pytest.mark.parametrize("r, t, a0, a1, e0, e1, step", [
    (1.0, 0.002, -0.2, 0.3, -0.15, 0.1, math.radians(0.5)),
    (0.8, 0.01, 0.0, 0.004, -0.004, 0.0, math.radians(0.5)),  # narrower than a step
    (1.5, 0.004, -0.5, 0.5, -0.3, 0.3, 0.2),
])
def test_a_cap_sector_is_the_spherical_shell_section(r, t, a0, a1, e0, e1, step):
    """An n_a x n_e grid of directions on both radii (n = max(2, ceil(span / step) + 1) per
    angle, azimuth from +y towards +x, elevation up), four side walls: watertight, outward,
    its volume the section's (r_o^3 - r_i^3) / 3 (a1 - a0) (sin e1 - sin e0) to the
    facets' chord error."""
    from rtsgeom.geometry.sheet import cap_sector
    mesh = cap_sector(r, t, a0, a1, e0, e1, step)
    na = max(2, math.ceil((a1 - a0) / step) + 1)
    ne = max(2, math.ceil((e1 - e0) / step) + 1)
    want = np.array([[rr * math.cos(e) * math.sin(a), rr * math.cos(e) * math.cos(a),
                      rr * math.sin(e)] for rr in (r, r + t) for a in np.linspace(a0, a1, na)
                     for e in np.linspace(e0, e1, ne)])
    assert mesh.vertices.shape == (2 * na * ne, 3)
    assert mesh.faces.shape == (4 * (na - 1) * (ne - 1) + 2 * (2 * (na - 1) + 2 * (ne - 1)), 3)
    got = np.array(sorted(map(tuple, np.round(mesh.vertices, 12))))
    np.testing.assert_allclose(got, np.array(sorted(map(tuple, np.round(want, 12)))),
                               atol=1e-12)
    assert mesh.is_watertight and mesh.is_winding_consistent
    vol = ((r + t) ** 3 - r ** 3) / 3 * (a1 - a0) * (math.sin(e1) - math.sin(e0))
    assert mesh.volume == pytest.approx(vol, rel=2 * max(a1 - a0, e1 - e0, step) ** 2)
    assert mesh.volume > 0


def _sheet_cfg(**kw):
    from rtsgeom.scene import SheetConfig
    base = dict(radius_offset_m=-0.01, thickness_m=0.004, height_m=0.2,
                angle_min_rad=math.radians(-10), angle_max_rad=math.radians(12),
                cutout_diameter_m=0.04)
    base.update(kw)
    import dataclasses
    return dataclasses.replace(SheetConfig(), **base)


@pytest.mark.parametrize("elevations", [None, (0.0, 0.0, 0.0), (0.05, -0.05, 0.0)])
def test_the_sheet_with_its_cutouts(elevations):
    """The sheet about the arc centre: a cylinder section (no elevation: |z| <= height / 2)
    or a cap (elevations: the chord height / 2 at radius R + offset); each cutout removes a
    hole of the cutout's diameter through the thickness (the volume of a 64-gon prism of
    the thickness, 0.1 %) where
    a ray from the arc centre through the front end passes, the sheet beside it blocks; the
    mesh watertight and outward."""
    from rtsgeom.geometry.sheet import segments_blocked, sheet_mesh
    cfg = _sheet_cfg()
    centre = np.array([0.3, -0.2, 0.5])
    angles = np.radians([-5.0, 0.0, 6.0])
    full = sheet_mesh(cfg, centre, 1.0, np.zeros(0),  # the same sheet without a cutout
                      None if elevations is None else np.asarray(elevations))
    mesh = sheet_mesh(cfg, centre, 1.0, angles, None if elevations is None
                      else np.asarray(elevations))
    r0 = 1.0 - 0.01
    assert mesh.is_watertight and mesh.is_winding_consistent and mesh.volume > 0
    hole = math.pi * 0.02 ** 2 * 0.004
    assert full.volume - mesh.volume == pytest.approx(3 * hole * 64 / (2 * math.pi) * math.sin(
        2 * math.pi / 64), rel=1e-3)  # the cutter a 64-gon
    cap = elevations is not None and any(elevations)
    zs = mesh.vertices[:, 2] - 0.5
    if cap:
        assert np.max(zs) == pytest.approx((r0 + 0.004) * math.sin(math.asin(0.1 / r0)),
                                           rel=1e-7)
    else:
        assert np.max(np.abs(zs)) == pytest.approx(0.1, abs=1e-7)  # manifold's float32
    radii = np.linalg.norm(mesh.vertices - centre, axis=1) if cap else np.hypot(
        *(mesh.vertices - centre)[:, :2].T)
    sag = r0 * (1 - math.cos(math.radians(0.36)))  # holes on the facets (a cap's diagonals)
    assert r0 - sag - 1e-7 <= radii.min() <= r0 + 1e-7
    assert radii.max() == pytest.approx(r0 + 0.004, abs=1e-7)
    el = np.zeros(3) if elevations is None else np.asarray(elevations)
    for a, e in zip(angles, el):
        d = np.array([math.cos(e) * math.sin(a), math.cos(e) * math.cos(a), math.sin(e)])
        assert not segments_blocked(mesh, centre, centre + 1.2 * d)[0]
        # 1.5 cutout radii beside it, along the arc: the sheet
        side = np.array([math.cos(e) * math.sin(a + 0.03 / r0), math.cos(e) * math.cos(
            a + 0.03 / r0), math.sin(e)])
        assert segments_blocked(mesh, centre, centre + 1.2 * side)[0]


def test_a_sheet_taller_than_its_sphere_reaches_the_poles():
    """A cap's chord longer than the sphere's diameter: elevations to +-90 deg."""
    from rtsgeom.geometry.sheet import sheet_mesh
    cfg = _sheet_cfg(height_m=3.0, angle_min_rad=-0.1, angle_max_rad=0.1)
    mesh = sheet_mesh(cfg, np.zeros(3), 1.0, np.zeros(0), np.array([0.1]))
    assert np.max(mesh.vertices[:, 2]) == pytest.approx(0.994, abs=1e-12)


@pytest.mark.parametrize("x, y, z0, z1, hit", [
    (0.25, 0.25, 1.0, -1.0, True), (0.25, 0.25, -1.0, 1.0, True),
    (0.0, 0.3, 1.0, -1.0, True), (-1e-6, 0.3, 1.0, -1.0, False),   # u = 0 and beyond
    (0.3, 0.0, 1.0, -1.0, True), (0.3, -1e-6, 1.0, -1.0, False),   # v = 0 and beyond
    (0.5, 0.5, 1.0, -1.0, True), (0.5, 0.5 + 1e-6, 1.0, -1.0, False),  # u + v = 1
    (0.25, 0.25, 1.0, 0.0, False), (0.25, 0.25, 1.0, -1e-6, True),  # ends on the plane
    (0.25, 0.25, 0.0, 1.0, False), (0.25, 0.25, -1e-6, 1.0, True),  # starts on it
    (0.25, 0.25, 1.0, 0.5, False), (0.25, 0.25, -0.5, -1.0, False),  # short of it
])
def test_a_segment_crosses_a_triangle_at_each_edge_of_the_test(x, y, z0, z1, hit):
    """Moller-Trumbore on the unit triangle in z = 0: inside (edges included) with the
    crossing strictly between the segment's ends (1e-9 of its length)."""
    from rtsgeom.geometry.sheet import segments_blocked
    tri = trimesh.Trimesh(vertices=[[0, 0, 0], [1, 0, 0], [0, 1, 0]], faces=[[0, 1, 2]],
                          process=False)
    got = segments_blocked(tri, np.array([[x, y, z0]]), np.array([[x, y, z1]]))
    assert got.shape == (1,) and bool(got[0]) is hit


def test_segments_in_a_batch_and_parallel_to_the_facets():
    """Each segment against every triangle (a hit on any), a segment in the plane of a
    triangle never blocked, start and end broadcast from one point."""
    from rtsgeom.geometry.sheet import segments_blocked
    two = trimesh.Trimesh(vertices=[[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 2], [1, 0, 2],
                                    [0, 1, 2]], faces=[[0, 1, 2], [3, 4, 5]], process=False)
    start = np.array([[0.2, 0.2, 1.0], [0.2, 0.2, 1.0], [0.9, 0.9, 1.0], [-1.0, 0.2, 0.0],
                      [0.2, 0.2, -1.0]])
    end = np.array([[0.2, 0.2, 3.0], [0.2, 0.2, -3.0], [0.9, 0.9, 3.0], [2.0, 0.2, 0.0],
                    [0.2, 0.2, 0.5]])
    np.testing.assert_array_equal(segments_blocked(two, start, end),
                                  [True, True, False, False, True])
    assert segments_blocked(two, [0.2, 0.2, 1.0], [0.2, 0.2, 3.0]).tolist() == [True]
