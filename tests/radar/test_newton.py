"""Tests of ``rtsgeom.radar.newton``: closed forms and invariants on grids of inputs."""

from __future__ import annotations

import numpy as np
import pytest

from rtsgeom.radar.newton import parabolic


@pytest.mark.parametrize("vertex", [-0.49, -0.2, 0.0, 0.13, 0.4])
@pytest.mark.parametrize("curv", [-0.3, -2.0, -40.0])
def test_parabolic_offset_is_the_vertex_of_the_parabola(vertex, curv):
    y = curv * (np.array([-1.0, 0.0, 1.0]) - vertex) ** 2 + 5.0
    assert float(parabolic(*y)) == pytest.approx(vertex, abs=1e-12)


@pytest.mark.parametrize("y", [(1.0, 0.8, 1.1), (1.0, 0.5, 0.9), (0.0, 0.0, 0.0), (2.0, 1.0, 0.0)])
def test_parabolic_is_zero_where_the_middle_sample_is_no_peak(y):
    """Convex or flat samples (y0 - 2 y1 + y2 >= 0) have no vertex to move to: offset 0."""
    assert float(parabolic(*y)) == 0.0
