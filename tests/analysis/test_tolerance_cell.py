"""The mounting-tolerance study of a 2-D cell (``rtsgeom tolerance --cell``;
``analysis/tolerance_cell.py``): invariants of the phasor-level model on a grid of cells
(radii, spans in azimuth and elevation, quadrilaterals and a triangle), the driver's
reproducibility and the full ADC-cube chain."""

from __future__ import annotations

import copy
import json
import subprocess
import sys
import tomllib

import numpy as np
import pytest

from conftest import ROOT
from rtsgeom.analysis.tolerance.phasors import CASES
from rtsgeom.analysis.tolerance.draws import draw_offsets, standard_draws
from rtsgeom.analysis.tolerance.phasors import ChannelPhasors
from rtsgeom.analysis.tolerance.config import MonteCarlo
from rtsgeom.analysis.tolerance.search import max_sigma_for_yield
from rtsgeom.analysis.tolerance.montecarlo import monte_carlo
from rtsgeom.analysis.tolerance.verify import verify_draws
from rtsgeom.geometry import build_setup
from rtsgeom.scene import parse_scene

SPHERE = ROOT / "scenes" / "sphere4.toml"

# (radius m, azimuth corners deg, elevation corners deg, front ends: 4 a quadrilateral,
# 3 a triangle)
CELLS = [(1.0, (3.4, 12.2), (-5.0, 5.0), 4),
         (0.7, (-4.0, 4.0), (-3.0, 4.0), 4),
         (1.5, (0.0, 10.0), (-4.0, 4.0), 3)]


def cell_scene(radius, az, el, n):
    doc = copy.deepcopy(tomllib.loads(SPHERE.read_text()))
    doc["rts"]["arc_radius_m"] = radius
    corners = [(az[0], el[0]), (az[0], el[1]), (az[1], el[0]), (az[1], el[1])]
    fes = doc["rts"]["front_ends"]
    for fe, (a, e) in zip(fes, corners):
        fe["angle_deg"], fe["elevation_deg"] = a, e
    doc["rts"]["front_ends"] = fes[:n]
    return parse_scene(doc, "cell.toml")


@pytest.fixture(scope="module", params=range(len(CELLS)), ids=lambda k: f"cell{k}")
def model(request):
    return ChannelPhasors.build(build_setup(cell_scene(*CELLS[request.param])), points=9)


def errors_deg(model, offsets):
    d = model.draw(np.asarray(offsets, float), None, CASES)
    return {case: np.degrees(d[case]["error_rad"]) for case in CASES}


def test_zero_sigma_gives_the_nominal_design(model):
    """No mounting error: the design hits its set directions on the nominal model with the
    calibration's phases (1e-6 deg, both angles); uncalibrated is that model read with the
    channels' own phases (the direction of sum a_q x_q, independently through
    ``ChannelModel.direction``); calibrated misses only by the delay quantisation (< 3e-3 deg)."""
    cs = model.channels
    n_q = len(model.front_ends)
    got = errors_deg(model, np.zeros((1, n_q, 3)))
    for m, a in enumerate(model.amplitudes):
        hit = cs.direction(cs.weights(a, model.procedure.phases))
        assert np.allclose(np.degrees(hit - model.set_rad[m]), 0.0, atol=1e-6)
        raw = cs.direction(cs.weights(a))
        assert np.allclose(got["uncalibrated"][0, m], np.degrees(raw - model.set_rad[m]),
                           atol=1e-5)
    assert np.max(np.abs(got["calibrated"])) < 3e-3


def test_zero_sigma_monte_carlo_repeats_the_nominal_errors(model):
    """Without errors at the bin centre every draw is the nominal setup; with the sub-bin
    drawn, every draw is the nominal setup with its target at the drawn position."""
    res = monte_carlo(model, [0.0, 0.0, 0.0], 5, seed=1, subbin=False)
    nominal = errors_deg(model, np.zeros((1, len(model.front_ends), 3)))
    for case in CASES:
        w = res.worst_error_deg[case]
        assert np.all(w == w[0])  # every draw is the nominal setup
        assert np.isclose(np.max(np.abs(w[0, :2])), np.max(np.abs(nominal[case])))
    res = monte_carlo(model, [0.0, 0.0, 0.0], 6, seed=1)
    idx = np.searchsorted(model.subbin_steps, res.subbin_steps)
    assert np.array_equal(model.subbin_steps[idx], res.subbin_steps)
    for i, u in enumerate(idx):
        d = model.draw(np.zeros((1, len(model.front_ends), 3)), [u], CASES)
        for case in CASES:
            e = np.degrees(d[case]["error_rad"][0])
            assert np.isclose(np.max(np.abs(res.worst_error_deg[case][i, :2])),
                              np.max(np.abs(e)), rtol=0, atol=1e-12)


def test_calibration_absorbs_one_front_end_moved_radially(model):
    """One front end 0.2 mm further out (each in turn): a two-way phase of 37 deg at 77 GHz;
    uncalibrated the direction moves by tenths of a degree, the calibration's delay takes it
    out (the change stays below 0.01 deg and 1/50 of the uncalibrated one)."""
    n_q = len(model.front_ends)
    e0 = errors_deg(model, np.zeros((1, n_q, 3)))
    for q in range(n_q):
        off = np.zeros((1, n_q, 3))
        off[0, q, 0] = 2e-4
        e = errors_deg(model, off)
        unc = np.max(np.abs(e["uncalibrated"] - e0["uncalibrated"]))
        cal = np.max(np.abs(e["calibrated"] - e0["calibrated"]))
        assert unc > 0.2
        assert cal < 0.01 and cal < unc / 50


def test_common_radial_shift_moves_nothing(model):
    """All front ends 0.5 mm further out (the sphere grows): every channel's delay changes
    alike, so neither case's direction moves (1e-3 deg)."""
    n_q = len(model.front_ends)
    e0 = errors_deg(model, np.zeros((1, n_q, 3)))
    off = np.zeros((1, n_q, 3))
    off[0, :, 0] = 5e-4
    e = errors_deg(model, off)
    for case in CASES:
        assert np.max(np.abs(e[case] - e0[case])) < 1e-3


def test_uncalibrated_errors_scale_linearly_with_small_sigma(model):
    """The same unit draws at 5 and 10 um: the error change from nominal doubles (6 %)."""
    z = draw_offsets(3, 20, [1.0, 1.0, 1.0], front_ends=len(model.front_ends))
    e0 = errors_deg(model, np.zeros((1,) + z.shape[1:]))["uncalibrated"]
    a = errors_deg(model, 5e-6 * z)["uncalibrated"] - e0
    b = errors_deg(model, 1e-5 * z)["uncalibrated"] - e0
    assert np.linalg.norm(b - 2 * a) < 0.06 * np.linalg.norm(b)
    assert np.linalg.norm(b) > 0


def test_draws_do_not_depend_on_chunk_and_pair_stream_kept(model):
    a = monte_carlo(model, [1e-4] * 3, 30, seed=5, chunk=7)
    b = monte_carlo(model, [1e-4] * 3, 30, seed=5, chunk=1000)
    for case in CASES:
        assert np.array_equal(a.worst_error_deg[case], b.worst_error_deg[case])
    assert np.array_equal(a.delay_s, b.delay_s)
    # the offsets are the arc study's per-front-end draws (what --out's npz rebuilds)
    from rtsgeom.analysis.tolerance.draws import draw_chunks
    for dist in ("normal", "uniform"):
        unit = next(draw_chunks(5, 30, len(model.front_ends), dist, 30)).offsets()
        assert np.array_equal(unit, draw_offsets(5, 30, [1.0] * 3, dist, len(model.front_ends)))
    # the pair study's stream is the front_ends=2 case, bit for bit
    old = np.random.default_rng(5).standard_normal((30, 2, 3))
    assert np.array_equal(next(standard_draws(5, 30, "normal", 30)), old)


def test_statistics_keys_and_yield(model):
    res = monte_carlo(model, [1e-4] * 3, 200, seed=2)
    out = res.to_dict()
    for case in CASES:
        st = out[case]
        for key in ("azimuth_error_deg", "elevation_error_deg", "angular_distance_deg",
                    "angle_error_deg"):
            p = st[key]
            assert p["p50"] <= p["p95"] <= p["p99"] <= p["max"]
        e = np.abs(res.worst_error_deg[case])
        assert st["yield"] == np.mean(np.max(e[:, :2], axis=1) <= res.spec_deg)
        # the worst angular distance is at most the root sum of squares of the worst
        # azimuth and elevation errors (an azimuth error counts cos el on the sphere)
        assert np.all(e[:, 2] <= np.hypot(e[:, 0], e[:, 1]) + 1e-9)
    assert out["calibrated"]["angular_distance_deg"]["p95"] < \
        out["uncalibrated"]["angular_distance_deg"]["p95"]
    json.dumps(out)


def test_yield_search_brackets_the_target():
    model = ChannelPhasors.build(build_setup(cell_scene(*CELLS[0])), points=4)
    inv = max_sigma_for_yield(model, [1e-4, 0.0, 0.0], MonteCarlo(draws=100, seed=4), 0.9,
                              spec_deg=0.05, case="calibrated", axis="radial", rel_tol=0.05)
    sig = inv["sigma_mm"]["radial"] * 1e-3
    assert not inv["capped"] and inv["yield"] >= 0.9
    above = monte_carlo(model, [sig * 1.12, 0.0, 0.0], 100, 4, spec_deg=0.05,
                             cases=("calibrated",))
    assert above.yield_("calibrated") < 0.9


def test_fast_model_matches_the_full_chain():
    """Two draws (0.1 mm per axis) through the ADC-cube chain (range-Doppler, CFAR, the 2-D
    beamformer) at every set-point, both cases: the phasor model within 1e-4 deg."""
    model = ChannelPhasors.build(build_setup(cell_scene(*CELLS[1])), points=4)
    v = verify_draws(model, [1e-4] * 3, MonteCarlo(draws=2, seed=7), all_points=True)
    assert v.max_difference_deg < 1e-4
    assert all(c["missed"] == 0 for c in v.to_dict()["cases"].values())


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "rtsgeom", "tolerance", *args, "--quiet"],
                          capture_output=True, text=True, cwd=ROOT)


@pytest.mark.subprocess
def test_cli_sphere4_defaults_to_the_cell(tmp_path):
    p = _cli(str(SPHERE), "--draws", "50", "--points", "9", "--json", "--out",
             str(tmp_path / "o"))
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    assert out["cell"]["cell"] == [0, 1, 2, 3] and out["cell"]["set_points"] == 9
    for case in CASES:
        assert {"azimuth_error_deg", "elevation_error_deg", "angular_distance_deg", "yield",
                "fallbacks"} <= set(out[case])
    assert (tmp_path / "o" / "tolerance.json").exists()
    npz = np.load(tmp_path / "o" / "tolerance_draws.npz")
    assert npz["offsets_m"].shape == (50, 4, 3) and npz["calibrated_deg"].shape == (50, 3)


@pytest.mark.subprocess
@pytest.mark.parametrize("args, word", [
    (["--cell", "0", "1"], "3 or 4"),
    (["--cell", "0", "1", "7"], "3 or 4"),
    (["--cell", "all", "--yaw-deg", "0.1", "--verify", "1"], "rotation"),
    (["--cell", "all", "--pair", "all"], "--pair all"),
    (["--cell", "all", "--pair", "0", "1"], "--pair 0 1"),  # was ignored: the cell's study
])
def test_cli_bad_cell_exits_2(args, word):
    p = _cli(str(SPHERE), "--draws", "5", *args)
    assert p.returncode == 2 and word in p.stderr and "Traceback" not in p.stderr


@pytest.mark.subprocess
def test_cli_cell_on_an_azimuth_only_radar_exits_2():
    p = _cli(str(ROOT / "scenes" / "diewald2022.toml"), "--cell", "all", "--draws", "5")
    assert p.returncode == 2 and "elevation" in p.stderr and "Traceback" not in p.stderr


def test_rut_yaw_turns_every_azimuth_alike(model):
    """A RuT yaw error turns the frame it measures in: every set direction's detected azimuth
    moves by the yaw (2 %, both cases; the elevation by < 5 % of it), as on a real bench."""
    n_q = len(model.front_ends)
    e0 = errors_deg(model, np.zeros((1, n_q, 3)))
    yaw = np.radians(0.05)
    d = model.draw(np.zeros((1, n_q, 3)), None, CASES, {"rut_yaw_rad": np.array([yaw])})
    for case in CASES:
        de = np.degrees(d[case]["error_rad"]) - e0[case]
        assert np.allclose(np.abs(de[..., 0]), 0.05, rtol=0.02)
        assert np.all(np.sign(de[..., 0]) == np.sign(de[0, 0, 0]))
        assert np.max(np.abs(de[..., 1])) < 0.05 * 0.05


def test_rotation_draws_keep_the_offset_draws(model):
    """Adding rotation and RuT-pose errors draws them from their own streams: with their
    bounds at zero the study is bit for bit the offsets-only one."""
    from rtsgeom.analysis.tolerance.draws import Bounds
    a = monte_carlo(model, [1e-4] * 3, 20, seed=9)
    b = monte_carlo(model, Bounds((1e-4,) * 3), 20, seed=9)
    c = monte_carlo(model, Bounds((1e-4,) * 3, yaw_rad=np.radians(0.2)), 20, seed=9)
    for case in CASES:
        assert np.array_equal(a.worst_error_deg[case], b.worst_error_deg[case])
        assert not np.array_equal(a.worst_error_deg[case], c.worst_error_deg[case])


def test_gain_calibration_inverts_a_channel_gain(model):
    """The amplitude calibration: channel q's phasors scaled by g_q (any complex factor) give
    the correction 1/|g_q| (each channel's power against the model's)."""
    rng = np.random.default_rng(0)
    g = rng.uniform(0.3, 3.0, len(model.front_ends)) * np.exp(1j * rng.uniform(-3, 3, len(model.front_ends)))
    x = model.x_nominal * g[:, None]
    assert np.allclose(model.gain_correction(x), 1 / np.abs(g), rtol=1e-12)
    assert np.allclose(model.gain_correction(model.x_nominal), 1.0, rtol=1e-12)


def test_a_cell_holding_no_set_direction_is_refused(monkeypatch, sphere_scene):
    """A cell whose grid keeps no set direction inside its hull (a sliver of a cell): named,
    with the grid's size, instead of a study of nothing."""
    import rtsgeom.analysis.tolerance.cell as cell_mod
    from conftest import assert_refused
    from rtsgeom.geometry import build_setup
    from rtsgeom.scene import TargetConfig
    nom = build_setup(sphere_scene)
    monkeypatch.setattr(cell_mod, "cell_grid", lambda st, u, n: np.zeros((0, 2)))
    assert_refused(lambda: cell_mod.build_cell(nom, (0, 1, 2), 5, TargetConfig(15.0)),
                   "cell [0, 1, 2]: no set direction of a 5 x 5 grid lies inside it")


# -- the cell's fields and draws read whole against their definitions ----------------------


@pytest.fixture(scope="module")
def cell0():
    return ChannelPhasors.build(build_setup(cell_scene(*CELLS[0])), points=4)


def test_the_cells_fields_from_their_definitions(cell0):
    """build_cell: the set directions (the 2 x 2 grid of 4 points inside the cell), the
    spanning tree from front end 0 and its phases, the exact design per set direction, the
    delay step and eq. (27)'s slope f_RTS + B/2, the calibration's reach (half an IF period
    plus 8 refining steps and one), the tables' rows (every sub-bin position and calibration
    delay, one more) and bins (2 either side), their log slopes and each channel's delay
    factor at the set range's bin (1 at no delay)."""
    from scipy.constants import c

    from rtsgeom.analysis.linearity import cell_grid
    from rtsgeom.analysis.tolerance.cell import ANGLES, HALF_BINS, REFINE_STEPS
    from rtsgeom.analysis.tolerance.tables import reference_target, response_table
    from rtsgeom.calibration.channels import pair_edges, spanning_tree, tree_phases
    from rtsgeom.paths import exact_paths
    assert (ANGLES, HALF_BINS, REFINE_STEPS) == (("azimuth", "elevation",
                                                  "angular_distance"), 2, 8)
    nom, cs, pr = cell0.setup, cell0.channels, cell0.procedure
    radar, rts = nom.scene.radar, nom.scene.rts
    st = cs.steering
    assert cell0.front_ends == (0, 1, 2, 3) and st.dims == 2
    grid = cell_grid(st, cs.fe_directions(), 2)
    assert grid.shape == (4, 2)
    np.testing.assert_array_equal(cell0.set_rad, grid)
    np.testing.assert_array_equal(pr.set_u, st.directions(grid))
    all_u = nom.fe_direction_cosines()
    tree = tuple(spanning_tree(all_u, pair_edges(all_u, (0, 1, 2, 3)), 0))
    assert pr.tree == tree and len(tree) == 3
    np.testing.assert_array_equal(pr.phases, tree_phases(cs, tree))
    np.testing.assert_array_equal(cell0.amplitudes, np.stack(
        [np.abs(cs.solve(u, pr.phases, "exact")) for u in pr.set_u]))
    res, slope = rts.delay_resolution_s, rts.f_rts_hz + 0.5 * radar.bandwidth_hz
    assert (cell0.delay_resolution_s, cell0.cal_slope_hz) == (res, slope)
    s = math_ceil(0.5 / (slope * res)) + 8 + 1
    assert pr.max_steps == s and pr.block_draws == 500
    n_bin = max(1, round(2 * radar.range_resolution_m / c / res))
    np.testing.assert_array_equal(cell0.subbin_steps, np.arange(n_bin) - n_bin // 2)
    z = n_bin // 2 + s + 1
    v = cell0.x_nominal.shape[-1]
    assert cell0.table_zero == z and cell0.table.shape == (4, 2 * z + 1, 5, v)
    rows = np.array([0, z - 3, z, 2 * z])
    want = np.stack([response_table(nom, exact_paths(nom), q, reference_target(nom, None), res,
                                    rows - z, 2) for q in range(4)])
    np.testing.assert_allclose(cell0.table[:, rows], want, rtol=1e-12, atol=0)
    with np.errstate(divide="ignore"):
        log_slope = np.gradient(np.log(np.abs(cell0.table)), res, axis=1)
    np.testing.assert_array_equal(cell0.table_log_slope, log_slope)
    ks = slice(z - s, z + s + 1)
    np.testing.assert_array_equal(pr.delay_factor, cell0.table[:, ks, 2]
                                  / cell0.table[:, z:z + 1, 2])
    assert pr.delay_factor.shape == (4, 2 * s + 1, v)
    np.testing.assert_allclose(pr.delay_factor[:, s], 1.0, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(pr.delay_log_slope, log_slope[:, ks, 2])


def math_ceil(x):
    import math
    return math.ceil(x)


@pytest.mark.parametrize("offsets_um, positions", [(0.0, None), (30.0, [0, -1]),
                                                   (100.0, [1, 2])])
def test_a_cells_draw_in_full(cell0, offsets_um, positions):
    """CellProcedure.draw: the calibration steps (the procedure's), per case the errors, the
    angular distance between the detected and the set direction (the great-circle angle of
    the unit vectors), the detected bin from the set range's (0 without errors), converged
    peaks and the amplitudes: the design's uncalibrated; calibrated the design times the gain
    correction over each channel's loss at its calibration delay."""
    from rtsgeom.analysis.tolerance.cell import HALF_BINS
    n = 2
    rng = np.random.default_rng(int(offsets_um))
    off = rng.standard_normal((n, 4, 3)) * offsets_um * 1e-6
    u = None if positions is None else np.asarray(positions) + int(
        np.flatnonzero(cell0.subbin_steps == 0)[0])
    d = cell0.draw(off, u, CASES)
    st, pr = cell0.channels.steering, cell0.procedure
    x = cell0.channels.perturbed(off)
    assert set(d) == {"steps", *CASES}
    np.testing.assert_array_equal(d["steps"], pr.calibration_steps(cell0, x))
    m = cell0.set_rad.shape[0]
    for case in CASES:
        got = d[case]
        assert set(got) == {"error_rad", "distance_rad", "converged", "bin", "amplitudes"}
        assert got["error_rad"].shape == (n, m, 2) and got["amplitudes"].shape == (n, m, 4)
        det = st.directions(cell0.set_rad + got["error_rad"])
        w = np.sqrt(1 - np.sum(det ** 2, -1))
        w0 = np.sqrt(1 - np.sum(pr.set_u ** 2, -1))
        cosang = np.sum(det * pr.set_u, -1) + w * w0
        np.testing.assert_allclose(got["distance_rad"], np.arccos(np.clip(cosang, -1, 1)),
                                   rtol=1e-6, atol=1e-9)
        assert got["converged"].dtype == bool and np.all(got["converged"])
        assert np.all(np.abs(got["bin"]) <= HALF_BINS)
        if offsets_um == 0.0:
            assert np.all(got["bin"] == 0)
    np.testing.assert_array_equal(d["uncalibrated"]["amplitudes"],
                                  np.broadcast_to(cell0.amplitudes, (n, m, 4)))
    # calibrated: each channel's loss at its calibration delay, at the bin the nominal model
    # of the operator detects, divided out, the gains corrected
    z, mask, t = cell0.table_zero, st.mask, cell0.table
    d_u = cell0.subbin_steps[u] if u is not None else np.zeros(n, int)
    gain = cell0.gain_correction(x)
    want = np.empty((n, m, 4))
    for i in range(n):
        rows = z + d_u[i] + d["steps"][i]
        for j in range(m):
            y = sum(cell0.amplitudes[j, q] * t[q, rows[q]] for q in range(4))  # (K, V)
            k = int(np.argmax(np.sum(np.abs(y) ** 2, -1)))
            for q in range(4):
                loss = (abs(t[q, rows[q], k][mask].mean())
                        / abs(t[q, z + d_u[i], k][mask].mean()))
                want[i, j, q] = cell0.amplitudes[j, q] * gain[i, q] / loss
    np.testing.assert_allclose(d["calibrated"]["amplitudes"], want, rtol=1e-12)
    assert np.any(d["steps"] != 0)


def test_the_cells_helpers_on_grids():
    """The phase wrapped into (-pi, pi], the strongest bin of the power over the elements,
    unit vectors of direction cosines (the front hemisphere, clipped at the horizon)."""
    from rtsgeom.analysis.tolerance.cell import _detected_bin, _unit_vectors, _wrap
    phi = np.linspace(-20, 20, 401)
    w = _wrap(phi)
    assert np.all((w > -np.pi - 1e-12) & (w <= np.pi + 1e-12))
    np.testing.assert_allclose(np.exp(1j * w), np.exp(1j * phi), atol=1e-12)
    rng = np.random.default_rng(2)
    y = rng.standard_normal((3, 4, 5, 6)) + 1j * rng.standard_normal((3, 4, 5, 6))
    np.testing.assert_array_equal(_detected_bin(y), np.argmax(np.sum(np.abs(y) ** 2, -1), -1))
    y[..., 1, :] = 10 * (1 + 1j)
    y[..., 1, 0] = 0  # the sum over the elements decides, not one element
    y[..., 3, 0] = 30
    assert np.all(_detected_bin(y) == 1)
    u = np.array([[0.0, 0.0], [0.6, 0.0], [0.0, -0.8], [0.3, 0.4], [0.8, 0.8]])
    v = _unit_vectors(u)
    np.testing.assert_allclose(v, [[0, 0, 1], [0.6, 0, 0.8], [0, -0.8, 0.6],
                                   [0.3, 0.4, np.sqrt(0.75)], [0.8, 0.8, 0.0]], atol=1e-15)
    assert _unit_vectors(u[None]).shape == (1, 5, 3)


@pytest.mark.parametrize("cell, accepted", [
    ((0, 1, 2), True), ((1, 2, 3), True), ((0, 1, 2, 3), True),
    ((0, 1), False), ((0, 1, 2, 3, 1), False), ((0, 1, 4), False), ((-1, 1, 2), False),
    ((0, 1, 1), False)])
def test_a_cells_front_ends_at_each_edge(cell, accepted, monkeypatch, sphere_scene):
    """3 or 4 distinct indices in [0, 3]: the ends accepted (the study goes on to its paths),
    one beyond refused with the whole message."""
    import rtsgeom.analysis.tolerance.cell as cell_mod
    from conftest import assert_refused
    from rtsgeom.scene import TargetConfig

    class Reached(Exception):
        pass

    def stop(nom):
        raise Reached

    monkeypatch.setattr(cell_mod, "exact_paths", stop)
    nom = build_setup(sphere_scene)
    call = lambda: cell_mod.build_cell(nom, cell, 3, TargetConfig(15.0))  # noqa: E731
    if accepted:
        with pytest.raises(Reached):
            call()
    else:
        assert_refused(call, f"cell {list(cell)}: must be 3 or 4 distinct front-end indices "
                             "in [0, 3]")
