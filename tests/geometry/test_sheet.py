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
