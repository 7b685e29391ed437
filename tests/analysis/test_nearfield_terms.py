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


# -- the synthesized direction's worst errors: the whole dict against the model's primitives --


def _designs(setup, paths, channels, target, steering=None):
    """The design model (nominal setup) and the detection model (as built), built here."""
    from rtsgeom.paths import nominal_model
    from rtsgeom.synthesis.model import ChannelModel
    nom, nom_paths = nominal_model(setup, paths)
    kw = {} if steering is None else {"steering": steering}
    return (ChannelModel.build(nom, nom_paths, channels, target, **kw),
            ChannelModel.build(setup, paths, channels, target, **kw))


@pytest.mark.parametrize("moved", [False, True])
def test_a_pairs_worst_synthesis_errors_in_full(default_scene, moved):
    """Set-points at k / (points + 1) of the overlap of the measured and geometric spans;
    the ratio designed on the nominal setup (array-factor or exact) at the probes' phase,
    detected on the setup as built at its own phase; the worst |error| per mode, every key."""
    from conftest import moved_front_end

    from rtsgeom.analysis.nearfield_terms import synthesis_errors, synthesis_worst_errors_deg
    from rtsgeom.calibration.probes import probe_angles
    from rtsgeom.paths import exact_paths
    from rtsgeom.radar.steering import Steering
    from rtsgeom.scene import TargetConfig
    scene = moved_front_end(default_scene) if moved else default_scene
    setup = build_setup(scene)
    paths = exact_paths(setup)
    geo = build_setup(default_scene).fe_azimuth_rad()
    single = geo + np.radians([0.3, -0.2])  # measured inside the geometric span
    design, actual = _designs(setup, paths, (0, 1), TargetConfig(15.0))
    lo, hi = single
    sets = lo + np.arange(1, 5) / 5 * (hi - lo)
    probes = probe_angles(*single)
    ph_d, ph_a = float(design.pair_phase(probes)), float(actual.pair_phase(probes))
    worst = {}
    for mode in ("array-factor", "exact"):
        err = [np.degrees(float(actual.direction(actual.pair_weights(
            design.pair_ratio(a, (0.0, ph_d), mode), (0.0, ph_a)))) - a) for a in sets]
        worst[mode] = float(np.max(np.abs(err)))
    got = synthesis_worst_errors_deg(setup, paths, (0, 1), 15.0, single, points=4)
    assert got == {"pair": [0, 1], "span_deg": [float(np.degrees(lo)), float(np.degrees(hi))],
                   "points": 4, "array_factor_max_abs_error_deg": worst["array-factor"],
                   "exact_max_abs_error_deg": worst["exact"]}
    assert (worst["exact"] > 1e-3) is moved  # the design's model is not the built setup's
    st = Steering.auto(setup.rut, scene.radar)
    assert synthesis_errors(setup, paths, st, 15.0, single, 4) == [got]


def _cell_grid(setup, st, n: int):
    """The front ends' extent in (azimuth, elevation) and the n x n set directions at
    (k + 1) / (n + 1) of it, as the cell study places them."""
    ang = st.angles(setup.fe_direction_cosines())
    lo, hi = ang.min(0), ang.max(0)
    f = np.arange(1, n + 1) / (n + 1)
    return lo, hi, [(lo[0] + a * (hi[0] - lo[0]), lo[1] + b * (hi[1] - lo[1]))
                    for a in f for b in f]


@pytest.mark.parametrize("points, n", [(6, 2), (7, 3), (1, 2)])
def test_a_cells_worst_synthesis_errors_in_full(sphere_scene, points, n):
    """An n x n grid, n = round(sqrt(points)) >= 2, at (k + 1) / (n + 1) of the front ends'
    extent in azimuth and elevation (all inside sphere4's rectangle of front ends); each set
    direction designed on the nominal model (array-factor, exact) at the channels' coherent
    phases, detected on the built one; the worst |error| per angle and their larger, every
    key."""
    from rtsgeom.analysis.nearfield_terms import cell_synthesis_errors_deg, synthesis_errors
    from rtsgeom.paths import exact_paths
    from rtsgeom.radar.steering import Steering
    from rtsgeom.scene import TargetConfig
    setup = build_setup(sphere_scene)
    paths = exact_paths(setup)
    st = Steering.auto(setup.rut, sphere_scene.radar)
    cell = (0, 1, 2, 3)
    design, actual = _designs(setup, paths, cell, TargetConfig(15.0), st)
    lo, hi, grid = _cell_grid(setup, st, n)
    want = {"cell": [0, 1, 2, 3],
            "span_deg": {"azimuth": list(np.degrees([lo[0], hi[0]])),
                         "elevation": list(np.degrees([lo[1], hi[1]]))},
            "points": n * n}
    for mode, key in (("array-factor", "array_factor"), ("exact", "exact")):
        errs = []
        for a in grid:
            u = st.directions(np.array(a))
            w = design.solve(u, design.coherent_phases(u[None]), mode=mode)
            got = actual.direction(np.abs(w) * np.exp(1j * actual.coherent_phases(u[None])))
            errs.append(np.abs(np.degrees(got - np.array(a))))
        worst = np.max(errs, axis=0)
        want[f"{key}_max_abs_error_azimuth_deg"] = float(worst[0])
        want[f"{key}_max_abs_error_elevation_deg"] = float(worst[1])
        want[f"{key}_max_abs_error_deg"] = float(max(worst))
    got = cell_synthesis_errors_deg(setup, paths, cell, 15.0, points)
    assert got == want
    assert want["array_factor_max_abs_error_elevation_deg"] != want[
        "array_factor_max_abs_error_azimuth_deg"]
    if points == 6:
        assert synthesis_errors(setup, paths, st, 15.0, None, points) == [got]
        tri = cell_synthesis_errors_deg(setup, paths, (0, 1, 2), 15.0, points)
        assert tri["cell"] == [0, 1, 2] and 0 < tri["points"] < 4  # outside the hull dropped


def test_an_unreachable_set_direction_is_left_out_and_all_unreachable_is_none(
        sphere_scene, monkeypatch):
    """A set direction the design cannot reach (AngleUnreachable) counts as no error of its
    own: the worst is over the others; a mode that reaches none reports None (JSON null) for
    every angle and for their larger."""
    from rtsgeom.analysis.nearfield_terms import cell_synthesis_errors_deg
    from rtsgeom.errors import AngleUnreachable
    from rtsgeom.paths import exact_paths
    from rtsgeom.radar.steering import Steering
    from rtsgeom.scene import TargetConfig
    from rtsgeom.synthesis.model import ChannelModel
    setup = build_setup(sphere_scene)
    paths = exact_paths(setup)
    st = Steering.auto(setup.rut, sphere_scene.radar)
    cell = (0, 1, 2, 3)
    design, actual = _designs(setup, paths, cell, TargetConfig(15.0), st)
    lo, hi, grid = _cell_grid(setup, st, 2)
    errs = []
    for a in grid[1:]:  # the first is unreachable in array-factor mode
        u = st.directions(np.array(a))
        w = design.solve(u, design.coherent_phases(u[None]), mode="array-factor")
        got = actual.direction(np.abs(w) * np.exp(1j * actual.coherent_phases(u[None])))
        errs.append(np.abs(np.degrees(got - np.array(a))))
    worst = np.max(errs, axis=0)
    solve, seen = ChannelModel.solve, []

    def refusing(self, u, phases=None, mode="exact", *args, **kw):
        seen.append(mode)
        if mode == "exact" or seen.count("array-factor") == 1:
            raise AngleUnreachable("made up")
        return solve(self, u, phases, mode, *args, **kw)
    monkeypatch.setattr(ChannelModel, "solve", refusing)
    got = cell_synthesis_errors_deg(setup, paths, cell, 15.0, 4)
    assert got == {"cell": [0, 1, 2, 3],
                   "span_deg": {"azimuth": list(np.degrees([lo[0], hi[0]])),
                                "elevation": list(np.degrees([lo[1], hi[1]]))},
                   "points": 4,
                   "array_factor_max_abs_error_azimuth_deg": float(worst[0]),
                   "array_factor_max_abs_error_elevation_deg": float(worst[1]),
                   "array_factor_max_abs_error_deg": float(max(worst)),
                   "exact_max_abs_error_azimuth_deg": None,
                   "exact_max_abs_error_elevation_deg": None,
                   "exact_max_abs_error_deg": None}
    assert seen == ["array-factor", "exact"] * 4
