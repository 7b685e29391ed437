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
