"""N-channel synthesis in azimuth and elevation: cells, closed form vs exact,
the pair as the N = 2 case, and the bundled sphere4 scene end to end."""

import dataclasses

import numpy as np
import pytest

from rtsgeom.errors import CellUnreachable
from rtsgeom.synthesis.cells import enclosing_cell
from rtsgeom.errors import AngleUnreachable
from rtsgeom.radar.steering import Steering
from rtsgeom.synthesis.model import ChannelModel
from rtsgeom.synthesis.closed_form import closed_form_amplitudes
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.scene import TargetConfig, load_scene

SPHERE = "scenes/sphere4.toml"


@pytest.fixture(scope="module")
def sphere():
    scene = load_scene(SPHERE)
    setup = build_setup(scene)
    return scene, setup, exact_paths(setup)


# -- cells ------------------------------------------------------------------------------------

@pytest.mark.parametrize("du", [(0.05, 0.03), (0.1, 0.2), (0.02, 0.01)])
def test_cells_grid(du):
    """On an az x el grid of front ends every interior point lies in the quad whose corners
    bracket it in both axes; outside the hull is unreachable."""
    ux, uz = np.arange(4) * du[0], np.arange(3) * du[1]
    pts = np.stack(np.meshgrid(ux, uz, indexing="ij"), -1).reshape(-1, 2)
    rng = np.random.default_rng(0)
    for p in rng.uniform([0, 0], [ux[-1], uz[-1]], (50, 2)):
        cell = enclosing_cell(p, pts)
        c = pts[list(cell)]
        assert len(cell) == 4
        assert c[:, 0].min() <= p[0] <= c[:, 0].max() and c[:, 1].min() <= p[1] <= c[:, 1].max()
        assert np.isclose(np.ptp(c[:, 0]), du[0]) and np.isclose(np.ptp(c[:, 1]), du[1])
        tri = enclosing_cell(p, pts, quads=False)
        assert len(tri) == 3 and set(tri) <= set(cell)
    with pytest.raises(CellUnreachable):
        enclosing_cell((ux[-1] + 0.01, 0.0), pts)
    # 1-D: sorted intervals
    x = np.array([0.3, -0.1, 0.1])[:, None]
    assert enclosing_cell([0.0], x) == (1, 2) and enclosing_cell([0.2], x) == (2, 0)
    with pytest.raises(CellUnreachable):
        enclosing_cell([0.31], x)


# -- the ideal far field: closed form against exact --------------------------------------------

def cells(setup, paths, channels, target) -> ChannelModel:
    """The channel model of ``channels`` seen by the beamformer the RuT runs (2-D here)."""
    return ChannelModel.build(setup, paths, channels, target,
                              steering=Steering.auto(setup.rut, setup.scene.radar))


def ideal(cs: ChannelModel, u_fe):
    """The channel model with ideal far-field responses: plane waves from ``u_fe`` (Q, D),
    all in the centre candidate bin, no Doppler (the closed form told those directions)."""
    st = cs.steering
    v = cs.responses.shape[-1]
    x = np.zeros((3, len(u_fe), v), complex)
    x[1][:, st.mask] = np.exp(-1j * (st.wavevector @ np.asarray(u_fe).T)).T
    return dataclasses.replace(cs, responses=x, doppler_hz=0.0, fe_u=np.asarray(u_fe))


@pytest.mark.parametrize("cell", [(0, 1, 2, 3), (0, 1, 2), (0, 2, 3), (1, 2, 3)])
@pytest.mark.parametrize("spread", [(0.08, 0.08), (0.15, 0.12), (0.05, 0.2)])
def test_closed_form_equals_exact_in_ideal_far_field(sphere, cell, spread):
    scene, setup, paths = sphere
    cs = cells(setup, paths, cell, scene.targets[0])
    corners = np.array([[0.0, 0.0], [0.0, 1.0], [1.0, 0.0], [1.0, 1.0]]) * spread + [0.05, -0.04]
    u_fe = corners[list(cell)]
    cs = ideal(cs, u_fe)
    rng = np.random.default_rng(len(cell))
    for _ in range(4):
        b = rng.dirichlet(np.ones(len(cell)) * 3)  # a point inside the cell
        u = b @ u_fe
        ph = cs.coherent_phases(u)  # what a calibration establishes
        w_cf = cs.solve(u, ph, mode="array-factor")
        got = cs.direction_cosines(w_cf, u)
        assert np.abs(got - u).max() < 1e-9  # the closed form is exact here
        w_ex = cs.solve(u, ph, mode="exact")
        assert np.abs(cs.direction_cosines(w_ex, u) - u).max() < 1e-9
        if len(cell) == 3:  # one solution: both modes find it
            assert np.allclose(np.abs(w_ex), np.abs(w_cf), rtol=1e-5, atol=1e-8)


def test_closed_form_pair_is_paper_array_factor():
    """D = 1, Q = 2: the null-space closed form is eq. 23 with the true array factor."""
    from rtsgeom.synthesis.closed_form import ratio_array_factor
    from rtsgeom.radar.steering import Steering
    scene = load_scene("scenes/diewald2022.toml")
    setup = build_setup(scene)
    st = Steering.auto(setup.rut, scene.radar)
    for th_i, th_j in ((0.05, 0.2), (-0.1, 0.05), (0.3, 0.4)):
        for f in (0.2, 0.5, 0.8):
            alpha = th_i + f * (th_j - th_i)
            a = closed_form_amplitudes(st, np.sin([[th_i], [th_j]]), [np.sin(alpha)])
            rho = ratio_array_factor(th_i, th_j, alpha, st.size)
            assert np.isclose(a[1] / a[0], rho, rtol=1e-5)


def test_pair_is_the_n2_case():
    """The 1-D pair's solve at direction cosines u is its closed form at arcsin u, bit for
    bit, and puts the detected angle there."""
    scene = load_scene("scenes/diewald2022.toml")
    setup = build_setup(scene)
    paths = exact_paths(setup)
    t = scene.targets[0]
    m = ChannelModel.build(setup, paths, (0, 1), t)
    u = np.sin(t.angle_rad)
    for mode in ("exact", "array-factor", "paper"):
        w = m.solve([u], mode=mode)
        assert np.array_equal(w, m.pair_weights(m.pair_ratio(float(np.arcsin(u)), None, mode)))
    assert float(m.direction(m.solve([u]))) == pytest.approx(t.angle_rad, abs=1e-8)


# -- the bundled scene ------------------------------------------------------------------------

def test_exact_model_hits_cell_points(sphere):
    """Exact mode on the real (near-field) geometry: the modelled peak at the set point, over
    a grid of points inside the cell; outside the cell unreachable."""
    scene, setup, paths = sphere
    u_fe = setup.fe_direction_cosines()
    t = TargetConfig(25.0)
    cs = cells(setup, paths, (0, 1, 2, 3), t)
    lo, hi = u_fe.min(0), u_fe.max(0)
    for fx in (0.2, 0.5, 0.8):
        for fz in (0.15, 0.5, 0.85):
            u = lo + np.array([fx, fz]) * (hi - lo)
            w = cs.solve(u)
            assert np.abs(cs.direction_cosines(w, u) - u).max() < 1e-9
            assert np.all(np.abs(w) > 0)
    with pytest.raises(AngleUnreachable):
        cs.solve(hi + 0.2 * (hi - lo))


@pytest.mark.slow
@pytest.mark.heavy
def test_sphere4_run_within_0_05_deg():
    """Targets at several (az, el) inside the cell (not the bundled ones), detected within
    0.05 deg in both angles after calibration (exact mode) on a setup with channel phase and
    gain errors the calibration has to find. (The bundled scene's run is the golden record's,
    ``python -m benchmarks.golden``; one run here, two took 130 s of the suite.)"""
    from rtsgeom.pipeline.run import run_scene
    scene = load_scene(SPHERE)
    moved = tuple(t.evolve(angle_rad=np.radians(a), elevation_rad=np.radians(e))
                  for t, a, e in zip(scene.targets, (4.0, 11.5, 8.0, 6.0),
                                     (-3.5, 1.0, 2.0, -1.0)))
    fes = list(scene.rts.front_ends)  # hardware errors the calibration has to find
    fes[1] = fes[1].evolve(phase_offset_rad=np.radians(30.0))
    fes[3] = fes[3].evolve(phase_offset_rad=np.radians(-50.0), gain_offset_db=1.0)
    wrong = scene.evolve(targets=moved, rts=scene.rts.evolve(front_ends=tuple(fes)))
    result = run_scene(wrong)
    ch = result.calibration["channels"]
    assert len(ch["spanning_tree"]) == 3 and len(ch["loop_closure_s"]) == 2
    # loops close within a few of the 25 ps sweep steps (noise on a flat-bottomed minimum)
    assert max(abs(x) for x in ch["loop_closure_s"]) < 50e-12
    assert abs(ch["residual_deg"]["azimuth"]) < 0.05
    assert abs(ch["residual_deg"]["elevation"]) < 0.05
    for m in result.matches:
        e = m["error"]
        assert e is not None, m
        assert abs(e["angle_deg"]) < 0.05 and abs(e["elevation_deg"]) < 0.05, m
