"""Tests of ``rtsgeom.analysis.nearfield_terms``: closed forms and invariants on grids of inputs."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import make_scene

from rtsgeom.geometry import build_setup


def test_phase_residual_of_a_plane_wave_is_zero():
    """The residual after the best linear fit over the element positions vanishes for path
    lengths linear in the position (a plane wave), and is the curvature otherwise."""
    from rtsgeom.analysis.nearfield_terms import _residual_deg
    from rtsgeom.radar.steering import Steering
    s = make_scene()
    st = Steering.build(build_setup(s).rut, s.radar)
    x = st.positions_m[:, 0]
    lengths = np.stack([2.0 + 0.3 * x, 1.0 - 0.1 * x])
    assert np.max(np.abs(_residual_deg(st, lengths))) < 1e-9
    bent = lengths + 1e-3 * (x - x.mean()) ** 2 / np.ptp(x) ** 2
    r = _residual_deg(st, bent)
    assert np.max(np.abs(r)) > 1e-3 and np.allclose(r.sum(axis=1), 0, atol=1e-9)


def test_the_cells_of_two_d_front_ends():
    """3 or 4 front ends are one cell; more are the Delaunay triangles of their direction
    cosines (each a sorted tuple): a square with its centre is four triangles through it."""
    from rtsgeom.analysis.nearfield_terms import cells_of
    sq = np.array([[-0.1, -0.1], [0.1, -0.1], [0.1, 0.1], [-0.1, 0.1]])
    assert cells_of(sq[:3]) == [(0, 1, 2)] and cells_of(sq) == [(0, 1, 2, 3)]
    five = np.r_[sq, [[0.0, 0.0]]]
    assert sorted(cells_of(five)) == [(0, 1, 4), (0, 3, 4), (1, 2, 4), (2, 3, 4)]


@pytest.mark.parametrize("shift_deg", [-20.0, 20.0])
def test_spans_that_do_not_overlap_have_no_synthesis_errors(default_scene, shift_deg):
    """Front ends measured entirely beside their geometric span: no set-point, both worst
    errors None with the reason; overlapping spans give both."""
    from rtsgeom.analysis.nearfield_terms import synthesis_worst_errors_deg
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    setup = build_setup(default_scene)
    paths = exact_paths(setup)
    geo = setup.fe_azimuth_rad()
    out = synthesis_worst_errors_deg(setup, paths, (0, 1), 15.0,
                                     geo + np.radians(shift_deg), points=3)
    lo, hi = out.pop("span_deg")
    assert hi <= lo
    assert out == {"pair": [0, 1], "points": 3, "array_factor_max_abs_error_deg": None,
                   "exact_max_abs_error_deg": None,
                   "note": "the measured and geometric spans do not overlap"}
    ok = synthesis_worst_errors_deg(setup, paths, (0, 1), 15.0, geo, points=3)
    assert ok["span_deg"] == pytest.approx(list(np.degrees(geo)), abs=1e-9)
    assert ok["array_factor_max_abs_error_deg"] >= 0 and ok["exact_max_abs_error_deg"] >= 0
    assert "note" not in ok
