"""What the 3D view draws (``rtsgeom.viz.meshes``): the markers and line sets built at once are
the meshes built one by one and merged (same points, triangles, segments and normals)."""

from __future__ import annotations

import numpy as np
import pytest
import pyvista as pv

from rtsgeom.viz.meshes import merge, merge_lines, polyline, spheres


@pytest.mark.parametrize("n", [1, 2, 7, 64])
def test_spheres_are_the_merged_spheres(n):
    rng = np.random.default_rng(n)
    pts = rng.uniform(-2, 2, (n, 3))
    r = rng.uniform(1e-3, 0.1)
    got = spheres(pts, r)
    ref = merge([pv.Sphere(radius=r, center=p, theta_resolution=16, phi_resolution=12)
                 for p in pts])
    assert (got.n_points, got.n_cells) == (ref.n_points, ref.n_cells)
    np.testing.assert_allclose(got.points, ref.points, atol=1e-6 * (1 + np.abs(pts).max()))
    np.testing.assert_array_equal(got.faces, ref.faces)
    np.testing.assert_allclose(got.point_normals, ref.point_normals, atol=1e-6)
    for p, sphere in zip(pts, np.split(np.asarray(got.points), n)):  # each about its point
        np.testing.assert_allclose(np.linalg.norm(sphere - p, axis=1), r, rtol=1e-5)


@pytest.mark.parametrize("lengths", [[2], [2, 3, 5], [73] * 64, [1, 4, 2]])
def test_merged_lines_are_the_merged_polylines(lengths):
    rng = np.random.default_rng(len(lengths))
    lines = [rng.uniform(-1, 1, (k, 3)) for k in lengths]
    got = merge_lines(lines)
    ref = merge([polyline(p) for p in lines])
    assert got.n_cells == sum(k - 1 for k in lengths) == ref.n_cells
    np.testing.assert_array_equal(got.points, ref.points)
    np.testing.assert_array_equal(got.lines, ref.lines)
