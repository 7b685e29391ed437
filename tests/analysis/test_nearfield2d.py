"""The near-field analysis of a 2-D cell: ``rtsgeom nearfield`` on a RuT that
beamforms in azimuth and elevation (``scenes/sphere4.toml``) generalises the 1-D one."""

from __future__ import annotations

import json

import numpy as np
import pytest

from conftest import ROOT
from rtsgeom.analysis.nearfield_terms import _residual_deg
from rtsgeom.analysis.nearfield import nearfield
from rtsgeom.geometry import build_setup
from rtsgeom.radar.steering import Steering
from rtsgeom.scene import load_scene

SPHERE = ROOT / "scenes" / "sphere4.toml"


@pytest.fixture(scope="module")
def sphere_nf():
    return nearfield(load_scene(SPHERE), [0.5, 1.0, 2.0, 4.0], points=4)


def test_2d_bias_in_both_angles_falls_like_one_over_r(sphere_nf):
    """Each front end alone, through the 2-D beamformer: the bias in azimuth and in elevation
    falls like 1/R (bias x R within 6 % over 0.5 to 4 m) and vanishes towards the far field."""
    nf = sphere_nf
    assert nf.elevation_bias_deg is not None and nf.elevation_bias_deg.shape == (4, 4)
    for b in (nf.bias_deg, nf.elevation_bias_deg):
        br = b * nf.radius_m[:, None]
        assert np.all(np.abs(br - br[-1]) <= 0.06 * np.abs(br[-1]))
        assert np.all(np.abs(b[-1]) < np.abs(b[0]) / 7)


def test_2d_azimuth_decomposition_closes(sphere_nf):
    """The azimuth closed forms taken over the 2-D beamformer's elements (groups and the x
    slope of the least-squares plane) explain the detected azimuth bias to 0.01 deg; the
    residual (curvature) falls faster than 1/R."""
    nf = sphere_nf
    cur = np.abs(nf.curvature_deg)
    assert np.max(cur) < 0.01
    assert np.max(cur[-1]) < np.max(cur[0]) / 8 * 1.5


def test_2d_cell_synthesis_exact_vs_closed_form(sphere_nf):
    """Over the cell's set directions: ``exact`` hits them in both angles (1e-6 deg) at every
    radius; the 2-D closed form misses by the near-field bias, falling like 1/R."""
    nf = sphere_nf
    af = []
    for row in nf.synthesis:
        (cell,) = row
        assert cell["cell"] == [0, 1, 2, 3] and cell["points"] >= 4
        assert cell["exact_max_abs_error_deg"] < 1e-6
        af.append(cell["array_factor_max_abs_error_deg"])
    af = np.array(af)
    assert np.all(np.diff(af) < 0)
    assert np.allclose(af * nf.radius_m, af[-1] * nf.radius_m[-1], rtol=0.1)


def test_plane_residual_over_2d_positions():
    """The phase residual after the best-fit plane over (x, z) is zero for lengths linear in
    both coordinates and sums to zero otherwise."""
    scene = load_scene(SPHERE)
    st = Steering.auto(build_setup(scene).rut, scene.radar)
    assert st.dims == 2
    x, z = st.positions_m[:, 0], st.positions_m[:, 1]
    lengths = np.stack([1.0 + 0.2 * x - 0.4 * z, 2.0 - 0.1 * x + 0.3 * z])
    assert np.max(np.abs(_residual_deg(st, lengths))) < 1e-8
    bent = lengths + 1e-3 * (x * z) / np.ptp(x) / max(np.ptp(z), 1e-9)
    r = _residual_deg(st, bent)
    assert np.max(np.abs(r)) > 1e-3 and np.allclose(r.sum(axis=1), 0, atol=1e-8)


def test_nearfield_cli_on_a_2d_cell(tmp_path):
    from rtsgeom.cli import main
    rc = main(["nearfield", str(SPHERE), "--radius-m", "1:2:2", "--points", "4",
               "--out", str(tmp_path / "nf"), "--quiet"])
    assert rc == 0
    d = json.loads((tmp_path / "nf" / "nearfield.json").read_text())
    fe = d["radii"][0]["front_ends"][0]
    assert {"elevation_bias_deg", "geometric_elevation_deg"} <= set(fe)
    assert d["radii"][0]["synthesis"][0]["cell"] == [0, 1, 2, 3]
    assert (tmp_path / "nf" / "nearfield.png").stat().st_size > 0
