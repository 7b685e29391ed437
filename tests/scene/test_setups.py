"""Any lab's setup from a scene: the new keys, their wiring through the pipeline, whole arcs,
and the bundled scene that combines them, ``scenes/custom-array.toml``."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

from rtsgeom.analysis.tolerance.draws import Bounds
from rtsgeom.analysis.tolerance.montecarlo import ToleranceModel
from rtsgeom.analysis.tolerance.phasors import ChannelPhasors
from rtsgeom.analysis.tolerance.montecarlo import monte_carlo
from rtsgeom.cli import main
from rtsgeom.geometry import build_setup
from rtsgeom.geometry.patterns import CosinePattern
from rtsgeom.pipeline.info import scene_info
from rtsgeom.paths import exact_paths
from rtsgeom.paths.table import TX_TO_FE
from rtsgeom.scene.presets import PRESETS
from rtsgeom.errors import SceneError
from rtsgeom.scene import load_scene, loads_scene
from conftest import make_scene

ROOT = Path(__file__).resolve().parents[2]
DEFAULT = ROOT / "scenes" / "diewald2022.toml"
CUSTOM = ROOT / "scenes" / "custom-array.toml"


def _text(path=DEFAULT) -> str:
    return path.read_text()


def _with_front_ends(angles, extra: str = "", text: str | None = None) -> str:
    """The default scene with front ends at ``angles`` (deg), each with ``extra`` lines."""
    s = _text() if text is None else text
    fes = s[s.index("[[rts.front_ends]]"):s.index("[sheet]")]
    one = fes[:fes.index("[[rts.front_ends]]", 5)]
    body = "".join(re.sub(r"angle_deg = [-\d.]+", f"angle_deg = {a}", one) + extra + "\n"
                   for a in angles)
    return s.replace(fes, body)


# ------------------------------------------------------------------------------------------
# Scene keys
# ------------------------------------------------------------------------------------------


def test_custom_array_scene_loads_with_its_slots_and_virtual_array():
    scene = load_scene(CUSTOM)
    arr = scene.radar.array
    assert scene.radar.num_tx_active == len(arr.tx_order) == 3
    assert scene.radar.num_rx == 4
    setup = build_setup(scene)
    rut = setup.rut
    # virtual x / d = tx + rx (d = 1.9 mm): 12 elements, 10 distinct positions
    d = 1.9e-3
    expect = sorted({t + r for t in (0, 4, 8) for r in (0, 1, 3, 4)})
    got = np.round((rut.azimuth_positions_m - rut.azimuth_positions_m[0]) / d, 6)
    assert got.tolist() == expect
    assert rut.num_virtual == 12 and rut.num_azimuth_unique == 10
    info = scene_info(setup)
    va = info["virtual_array"]
    assert va["num_azimuth_unique"] == 10 and not va["uniform"]
    assert info["far_field"]["aperture_m"] == pytest.approx(13 * d)
    assert info["far_field"]["angular_resolution_deg"] == pytest.approx(
        math.degrees(1.22 * rut.wavelength_m / (13 * d)))
    assert va["grating_lobes_deg"] == []  # co-array period d < lambda / 2


@pytest.mark.parametrize("edit, field", [
    ("tx_order = [0, 1, 2]", "radar.array.tx_order"),
])
def test_custom_array_tx_order_out_of_range_names_the_field(edit, field):
    text = _text(CUSTOM).replace("tx_order = [0, 1, 2]", "tx_order = [0, 1, 3]")
    with pytest.raises(SceneError, match=re.escape(field) + r".*\[0, 2\]"):
        loads_scene(text, "x.toml")
    text = _text(CUSTOM).replace("tx_order = [0, 1, 2]", "tx_order = [0, 1, 1]")
    with pytest.raises(SceneError, match=r"radar\.array\.tx_order.*distinct"):
        loads_scene(text, "x.toml")
    text = _text(CUSTOM).replace("[[0.0, 0.0], [7.6", "[[0.0], [7.6")
    with pytest.raises(SceneError, match=r"radar\.array\.tx_mm.*\[x, z\] pairs"):
        loads_scene(text, "x.toml")
    text = _text(CUSTOM).replace("[[0.0, 0.0], [7.6", "[[2000.0, 0.0], [7.6")
    with pytest.raises(SceneError, match=r"radar\.array\.tx_mm\[0\].*\[-1000, 1000\] mm"):
        loads_scene(text, "x.toml")


def test_layout_shorthand_and_offsets_are_exclusive():
    both = _text(CUSTOM).replace("rx_offset_mm = [-15.0, 0.0]\ntx_offset_mm = [15.0, 0.0]\n\n"
                                 "[[rts.front_ends]]\nangle_deg = 8.0",
                                 "rx_offset_mm = [-15.0, 0.0]\ntx_offset_mm = [15.0, 0.0]\n"
                                 "rx_tx_separation_m = 0.02\n\n[[rts.front_ends]]\nangle_deg = 8.0")
    with pytest.raises(SceneError, match=r"rts\.front_ends\[0\]\.rx_tx_separation_m.*left out"):
        loads_scene(both, "x.toml")
    one = _text(CUSTOM).replace("tx_offset_mm = [15.0, 0.0]\n\n[[rts.front_ends]]\nangle_deg = 8.0",
                                "\n[[rts.front_ends]]\nangle_deg = 8.0", 1)
    with pytest.raises(SceneError, match=r"rts\.front_ends\[0\]\.tx_offset_mm is missing"):
        loads_scene(one, "x.toml")


def test_cutout_rule_uses_the_real_antenna_offsets():
    far = _text(CUSTOM).replace("rx_offset_mm = [-15.0, 0.0]", "rx_offset_mm = [-26.0, 0.0]", 1)
    with pytest.raises(SceneError, match=r"rts\.front_ends\[0\]\.rx_offset_mm.*within the cutout"):
        loads_scene(far, "x.toml")
    up = _text(CUSTOM).replace("rx_offset_mm = [-15.0, 0.0]", "rx_offset_mm = [-15.0, 21.0]", 1)
    with pytest.raises(SceneError, match=r"rts\.front_ends\[0\]\.rx_offset_mm"):
        loads_scene(up, "x.toml")  # hypot(15, 21) = 25.8 mm > 25 mm


def test_board_gap_is_a_preset_field():
    s = _text().replace('use_elevation_tx = false', 'use_elevation_tx = false\nboard_gap_mm = 0.0')
    scene = loads_scene(s, "x.toml")
    setup = build_setup(scene)
    gap = setup.rut.rx_local[:, 0].min() - setup.rut.tx_local[:, 0].max()
    assert gap == pytest.approx(0.0, abs=1e-12)
    default = build_setup(load_scene(DEFAULT)).rut
    d = default.spacing_m
    assert default.rx_local[:, 0].min() - default.tx_local[:, 0].max() == pytest.approx(6 * d)
    casc = s.replace('antenna_preset = "awr1843boost"', 'antenna_preset = "awr2243-cascade"')
    with pytest.raises(SceneError, match=r"radar\.board_gap_mm.*interleaves"):
        loads_scene(casc, "x.toml")


def test_pattern_keys_are_checked():
    s = _text() + '\n'
    cos = s.replace("[radar.cfar]", '[radar.pattern]\nkind = "cos"\n\n[radar.cfar]')
    with pytest.raises(SceneError, match=r"radar\.pattern\.hpbw_deg is missing"):
        loads_scene(cos, "x.toml")
    tab = s.replace("[radar.cfar]", '[radar.pattern]\nkind = "table"\ntable = "../x.csv"\n\n'
                                    "[radar.cfar]")
    with pytest.raises(SceneError, match=r"radar\.pattern\.table.*inside the scene's folder"):
        loads_scene(tab, "x.toml")


def test_default_scene_fields_change_nothing():
    """The new keys at their defaults: the setup is bit-identical to an explicit zero draw."""
    scene = load_scene(DEFAULT)
    a = build_setup(scene)
    b = build_setup(scene, offsets_m=np.zeros((2, 3)))
    for x, y in ((a.fe.rx, b.fe.rx), (a.fe.tx, b.fe.tx), (a.rut.tx_world, b.rut.tx_world)):
        assert np.array_equal(x, y)
    assert a.fe.yaw_rad is None and a.fe.rx_offset_m is None


# ------------------------------------------------------------------------------------------
# Wiring: layouts, rotations and pose errors through setup and the channel model
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("yaw_deg", [-3.0, 0.0, 2.0])
@pytest.mark.parametrize("rx_t_mm", [-15.0, 12.0])
def test_channel_model_legs_match_exact_paths_for_signed_layouts_and_rotations(yaw_deg, rx_t_mm):
    """ChannelModel.air_legs (the tolerance model) on a zero draw = the exact paths of the
    setup, for mirrored and normal layouts, yawed or not; and a draw's legs = the exact paths
    of build_setup with that draw (layouts and rotations kept)."""
    from rtsgeom.synthesis.model import ChannelModel
    from rtsgeom.scene import TargetConfig
    text = _text(CUSTOM).replace("yaw_offset_deg = 2.0", f"yaw_offset_deg = {yaw_deg}")
    text = text.replace("rx_offset_mm = [-15.0, 0.0]", f"rx_offset_mm = [{rx_t_mm}, 3.0]")
    scene = loads_scene(text, "x.toml")
    setup = build_setup(scene)
    paths = exact_paths(setup)
    model = ChannelModel.build(setup, paths, (1, 2), TargetConfig(12.0))
    t_a, t_b = model.air_legs(np.zeros((2, 3)))
    rut = setup.rut
    tx_leg = paths.delay_s[(paths.direction == TX_TO_FE)].reshape(3, -1)
    assert np.allclose(t_a, tx_leg[[1, 2]][:, rut.virtual_tx], rtol=0, atol=1e-18)
    off = np.array([[0.3e-3, -0.2e-3, 0.1e-3], [-0.1e-3, 0.4e-3, 0.0]])
    dyaw = np.radians([0.5, -1.0])
    t_a, t_b = model.air_legs(off, yaw_rad=dyaw)
    full = np.zeros((3, 3))
    full[[1, 2]] = off
    yaw = np.radians([0.0, yaw_deg, 0.0])
    yaw[[1, 2]] += dyaw
    moved = build_setup(scene, offsets_m=full, yaw_rad=yaw)
    p2 = exact_paths(moved)
    tx2 = p2.delay_s[p2.direction == TX_TO_FE].reshape(3, -1)
    assert np.allclose(t_a, tx2[[1, 2]][:, rut.virtual_tx], rtol=0, atol=1e-18)
    assert np.allclose(moved.fe.rx_offset_m, setup.fe.rx_offset_m)


def test_rut_pose_error_moves_the_rut_not_the_arc():
    scene = load_scene(DEFAULT)
    moved = build_setup(scene, rut_offset_m=(0.01, 0.0, 0.0), rut_yaw_rad=math.radians(1.0))
    base = build_setup(scene)
    assert np.array_equal(moved.fe.module, base.fe.module)
    assert np.allclose(moved.rut.position, base.rut.position + [0.01, 0, 0])
    # seen from the turned RuT, every front end is 1 deg further towards negative azimuth
    # (plus the parallax of the 1 cm shift, below 0.6 deg at 1 m)
    diff = np.degrees(moved.fe_azimuth_rad() - base.fe_azimuth_rad())
    assert np.all(diff < -1.0 + 0.6) and np.all(diff > -1.0 - 0.6)


@pytest.mark.parametrize("hpbw_deg", [20.0, 60.0])
def test_front_end_pattern_enters_the_exact_paths(hpbw_deg):
    """A cos pattern on the front-end antennas scales each leg by the pattern's field towards
    the RuT element (the closed form cos^(q/2) of the angle off the module's boresight)."""
    s = _text().replace("[sheet]", f'[rts.pattern]\nkind = "cos"\nhpbw_deg = {hpbw_deg}\n\n'
                                   "[sheet]")
    scene = loads_scene(s, "x.toml")
    setup = build_setup(scene)
    iso = exact_paths(setup, patterns=__import__("rtsgeom.geometry.patterns", fromlist=["x"])
                      .AntennaPatterns())
    pat = exact_paths(setup)
    ratio = pat.gain / iso.gain
    q = CosinePattern(math.radians(hpbw_deg)).q
    fe = setup.fe
    sel = pat.direction == TX_TO_FE
    f = pat.front_end[sel]
    t = pat.rut_tx[sel]
    d = setup.rut.tx_world[t] - fe.rx[f]  # FE Rx -> RuT Tx
    _, _, bore = fe.axes()
    cos_off = np.sum(d * bore[f], -1) / np.linalg.norm(d, axis=-1)
    assert np.allclose(ratio[sel], cos_off ** (q / 2), rtol=1e-12)
    assert np.all(ratio[sel] < 1.0)


# ------------------------------------------------------------------------------------------
# Whole arcs
# ------------------------------------------------------------------------------------------


def test_arc_of_two_front_ends_equals_the_pair_study():
    """An arc of two front ends is the pair study bit for bit: with the target's sub-bin
    position drawn per draw (the default of both) and with it at the bin centre."""
    scene = load_scene(DEFAULT)
    setup = build_setup(scene)
    model = ChannelPhasors.build(setup, (0, 1), 5)
    sigma = np.array([0.1, 0.15, 0.05]) * 1e-3
    for dist in ("normal", "uniform"):
        for subbin in (True, False):
            pair = monte_carlo(model, sigma, 300, 11, dist, 0.05, chunk=120, subbin=subbin)
            arc = monte_carlo(ToleranceModel.arc([model], 2), Bounds(tuple(sigma)), 300, 11,
                              dist, 0.05, chunk=70, subbin=subbin)
            for case in ("uncalibrated", "calibrated"):
                assert np.array_equal(arc.worst_error_deg[case][:, 0],
                                      pair.worst_error_deg[case])
                assert arc.yield_(case) == pair.yield_(case)
            assert np.array_equal(arc.delay_s[:, 0], pair.delay_s)
            if subbin:
                assert np.array_equal(arc.subbin_steps, pair.subbin_steps)
            else:
                assert arc.subbin_steps is None and pair.subbin_steps is None


def test_arc_yield_shares_front_ends(tmp_path):
    """Five front ends, four pairs on shared draws: one yield, a draw passes only if every pair
    does; the arc yield is at most the worst pair's; the NPZ holds the per-draw errors."""
    scene = loads_scene(_with_front_ends([-8.0, 0.0, 8.0, 16.0, 24.0]), "x.toml")
    setup = build_setup(scene)
    models = [ChannelPhasors.build(setup, (i, i + 1), 5) for i in range(5 - 1)]
    b = Bounds((0.15e-3, 0.15e-3, 0.1e-3), math.radians(0.5), math.radians(0.5),
               (0.2e-3,) * 3, math.radians(0.01))
    res = monte_carlo(ToleranceModel.arc(models, 5), b, 200, 3, "normal", 0.05,
                      keep_errors=True, chunk=64)
    for case in ("uncalibrated", "calibrated"):
        e = np.abs(res.worst_error_deg[case])
        assert res.yield_(case) == np.mean(np.all(e <= 0.05, axis=1))
        assert res.yield_(case) <= min(res.set_yield(case, p) for p in range(4))
    # the shared front end: the same draw of front end 1 enters pairs (0, 1) and (1, 2)
    assert res.errors["offsets_m"].shape == (200, 5, 3)
    assert res.errors["yaw_rad"].shape == (200, 5)
    out = res.to_dict()
    assert len(out["pairs"]) == 4 and "yield" in out["arc"]["calibrated"]
    res.save_npz(tmp_path / "d.npz")
    with np.load(tmp_path / "d.npz") as z:
        assert z["calibrated_deg"].shape == (200, 4)
        assert np.array_equal(z["offsets_m"], res.errors["offsets_m"])
    # rotations drawn from their own stream: the position draws do not change with them
    res0 = monte_carlo(ToleranceModel.arc(models[:1], 5), Bounds((0.15e-3, 0.15e-3, 0.1e-3)),
                       200, 3, keep_errors=True, chunk=200)
    assert np.array_equal(res0.errors["offsets_m"], res.errors["offsets_m"])
    # nor the sub-bin positions: one target, one position per draw whatever is drawn beside
    assert np.array_equal(res0.subbin_steps, res.subbin_steps)
    with np.load(tmp_path / "d.npz") as z:
        assert np.array_equal(z["subbin_steps"], res.subbin_steps)
    assert out["subbin"]["positions"] == models[0].subbin_steps.size


def test_tolerance_pair_all_cli(tmp_path, capsys):
    p = tmp_path / "arc.toml"
    p.write_text(_with_front_ends([-8.0, 0.0, 8.0, 16.0, 24.0]))
    rc = main(["tolerance", str(p), "--pair", "all", "--draws", "60", "--points", "5",
               "--radial-mm", "0.3", "--sigma-level", "3", "--yaw-deg", "0.5", "--json",
               "--quiet"])
    assert rc == 0
    out = json.loads(capsys.readouterr().out)
    assert [e["pair"] for e in out["pairs"]] == [[0, 1], [1, 2], [2, 3], [3, 4]]
    assert out["scales"]["radial_mm"] == pytest.approx(0.1)  # +-0.3 mm at 3 sigma
    assert out["scales"]["tangential_mm"] == pytest.approx(0.1)  # the old default sigma
    assert 0.0 <= out["arc"]["calibrated"]["yield"] <= 1.0
    rc = main(["tolerance", str(p), "--pair", "all", "--radial-mm", "0.3",
               "--sigma-radial-mm", "0.1", "--quiet"])
    assert rc == 2


# ------------------------------------------------------------------------------------------
# Presets end to end, and the custom-array scene
# ------------------------------------------------------------------------------------------


def _small(text: str) -> str:
    text = re.sub(r"samples_per_chirp = \d+", "samples_per_chirp = 128", text)
    text = re.sub(r"chirps_per_tx = \d+", "chirps_per_tx = 16", text)
    text = text[:text.index("# Table I")] + ("[[targets]]\nrange_m = 20.0\nvelocity_mps = 0.0\n"
                                             "angle_deg = 4.0\n")
    return text.replace('aoa_mode = "exact"', 'aoa_mode = "nearest"')


@pytest.mark.parametrize("name", list(PRESETS))
def test_every_preset_runs_end_to_end(name, tmp_path, capsys):
    from rtsgeom.pipeline.run import run_scene
    p = tmp_path / f"{name}.toml"
    p.write_text(_small(_text()).replace('"awr1843boost"', f'"{name}"'))
    assert main(["info", str(p)]) == 0
    assert "virtual array" in capsys.readouterr().out
    scene = load_scene(p)
    setup = build_setup(scene)
    assert setup.rut.num_azimuth_unique == PRESETS[name].num_azimuth_unique
    from rtsgeom.analysis.nearfield_terms import single_front_end_angles_rad
    t = run_scene(scene).matches[0]
    assert t["detection"] is not None
    assert abs(t["detection"]["range_m"] - 20.0) < scene.radar.range_resolution_m
    # nearest mode: the target sits on front end 0; the chain (ADC cube, FFTs, CFAR,
    # beamformer) detects it where the phasor model of the same paths puts it, near-field bias
    # included (1.4 deg for the cascade, whose Fraunhofer distance is 14 m, at R_c = 1 m)
    expect = math.degrees(single_front_end_angles_rad(setup, exact_paths(setup), 20.0)[0])
    assert abs(t["detection"]["angle_deg"] - expect) < 0.05
    assert abs(expect - 3.4) < 2.0


@pytest.mark.slow
def test_custom_array_scene_runs_and_finds_its_targets(tmp_path):
    """``scenes/custom-array.toml``: custom non-uniform 3 x 4 array, mirrored front ends,
    2 deg yaw error."""
    from rtsgeom.pipeline.run import run_scene
    scene = load_scene(CUSTOM)
    for t in run_scene(scene).matches:
        assert t["detection"] is not None
        assert abs(t["error"]["angle_deg"]) < 0.05


def test_nearfield_bias_sign_follows_the_front_end_layout():
    """Rx at the smaller azimuth (the custom scene) against the mirrored layout: the Rx/Tx
    split's part of the bias flips sign with the layout, as the far-field closed form says
    (the RuT sees its Tx at the FE's Rx and its Rx at the FE's Tx: the apparent direction lies
    between them, on the Rx side for the Tx->Rx leg), and the detected bias moves by twice it."""
    from rtsgeom.analysis.nearfield import nearfield
    text = _text(CUSTOM).replace("yaw_offset_deg = 2.0", "")
    mirrored = (text.replace("rx_offset_mm = [-15.0, 0.0]", "rx_offset_mm = [@, 0.0]")
                .replace("tx_offset_mm = [15.0, 0.0]", "tx_offset_mm = [-15.0, 0.0]")
                .replace("rx_offset_mm = [@, 0.0]", "rx_offset_mm = [15.0, 0.0]"))
    a = nearfield(loads_scene(text, "a.toml"), radii=[1.0], points=3)
    b = nearfield(loads_scene(mirrored, "b.toml"), radii=[1.0], points=3)
    assert np.all(a.separation_deg < 0) and np.all(b.separation_deg > 0)
    assert np.allclose(a.separation_deg, -b.separation_deg, rtol=0.01)  # 2nd order: cos(theta)
    # the rest of the bias (RuT parallax, beat frequency) does not depend on the FE layout's sign
    shift = b.bias_deg - a.bias_deg
    assert np.allclose(shift, 2 * b.separation_deg, rtol=0.15)


# ------------------------------------------------------------------------------------------
# Arc design for N front ends
# ------------------------------------------------------------------------------------------


COVERAGE_SETUPS = {"centred": None,
                   "arc centre +0.1 m x": lambda d: d["rts"].update(arc_center_m=[0.1, 0.0, 0.0]),
                   "arc centre -0.2 m y": lambda d: d["rts"].update(arc_center_m=[0.0, -0.2, 0.0]),
                   "RuT turned 10 deg": lambda d: d["radar"].update(yaw_deg=10.0)}


@pytest.mark.parametrize("radius_m, setup_name", [(0.2, "centred"), (0.2, "RuT turned 10 deg")]
                         + [(1.0, name) for name in COVERAGE_SETUPS])
def test_coverage_plan_respects_resolution_bias_and_cutouts(radius_m, setup_name):
    """The planned arc: the outer front ends' detected angles reach the coverage (in the RuT's
    frame: near-field bias compensated; off-centre arcs and a turned RuT had been placed in
    the arc's frame, e.g. -4.3..15.5 deg detected for -10..10), neighbours at most the
    resolution (eq. 24) apart as the RuT sees them, and the sheet removed exactly when the
    cutouts cannot fit the spacing."""
    from rtsgeom.analysis.coverage import _detected_rad, plan_arc
    mutate = COVERAGE_SETUPS[setup_name]
    scene = load_scene(DEFAULT) if mutate is None else make_scene(
        lambda d: (d.update(targets=[]), mutate(d)))
    cov = (math.radians(-10.0), math.radians(10.0))
    for extra in (0, 1):
        plan = plan_arc(scene, cov, radius_m, extra)
        detected, geometric = (np.degrees(x) for x in _detected_rad(plan.scene))
        assert detected[0] == pytest.approx(-10.0, abs=0.002)
        assert detected[-1] == pytest.approx(10.0, abs=0.002)
        gaps = np.abs(np.diff(geometric))
        assert gaps.max() <= plan.resolution_deg * (1 + 1e-9)
        if mutate is None:  # centred: the arc's spacing is the RuT's, the fewest (+ extra)
            assert plan.spacing_deg <= plan.resolution_deg * (1 + 1e-9)
            assert plan.front_ends == math.ceil(
                (plan.angles_deg[-1] - plan.angles_deg[0]) / plan.resolution_deg
                - 1e-9) + 1 + extra
        fits = plan.spacing_deg >= plan.min_cutout_spacing_deg
        assert (plan.sheet == "disabled") == (not fits)
        assert ("cutout fit" in plan.binding) == (not fits)


def test_design_coverage_cli_prints_the_sheet_change(tmp_path, capsys):
    rc = main(["design", str(DEFAULT), "--coverage-deg", "-10:10", "--radius-m", "0.2:0.2:1",
               "--draws", "20", "--points", "3", "--quiet", "--out", str(tmp_path)])
    assert rc == 0
    text = capsys.readouterr().out
    assert "sheet REMOVED" in text and "cutout fit" in text and "best per radius" in text
    out = json.loads((tmp_path / "coverage.json").read_text())
    assert out["best"][0]["front_ends"] >= 3
    assert (tmp_path / "coverage_worst_calibrated_deg.png").is_file()


@pytest.mark.slow
def test_calibrate_and_linearity_pair_all(tmp_path, capsys):
    """``--pair all``: one entry per adjacent pair plus the arc's summary, each entry the same
    as the single-pair command gives (same seed)."""
    text = _small(_with_front_ends([0.0, 8.0, 16.0]))
    text = text[:text.index("[[targets]]")]
    p = tmp_path / "arc3.toml"
    p.write_text(text)
    assert main(["calibrate", str(p), "--pair", "all", "--json", "--quiet"]) == 0
    arc = json.loads(capsys.readouterr().out)
    assert [e["pair"] for e in arc["pairs"]] == [[0, 1], [1, 2]]
    assert main(["calibrate", str(p), "--pair", "1", "2", "--json", "--quiet"]) == 0
    one = json.loads(capsys.readouterr().out)
    assert arc["pairs"][1]["delta_tau_s"] == one["delta_tau_s"]
    assert arc["arc"]["worst_residual_error_deg"] == max(
        abs(e["residual_error_deg"]) for e in arc["pairs"])
    assert main(["linearity", str(p), "--pair", "all", "--points", "3", "--uncalibrated",
                 "--json", "--quiet"]) == 0
    lin = json.loads(capsys.readouterr().out)
    assert len(lin["pairs"]) == 2 and lin["arc"]["calibrated"] is False
    assert main(["calibrate", str(p), "--pair", "0", "2", "--quiet"]) == 2


@pytest.mark.parametrize("window", ["none", "hamming"])
@pytest.mark.parametrize("name", sorted(PRESETS))
def test_array_factor_closed_form_is_the_rut_beamformer(name, window):
    """The array-factor mode's closed form (``synthesis.array_factor_args``) is the RuT's own
    beamformer for one plane wave: its taper and every virtual element (the cascade's 144 on 86
    positions count with their multiplicity). Symmetric arrays: |AF| = |beam| / sum w to
    1e-12; the cascade's row is asymmetric, so the real part about the weighted centroid is
    an approximation there -- still closer than the distinct-position kernel it replaced."""
    from rtsgeom.synthesis.closed_form import array_factor, array_factor_args
    from rtsgeom.radar.steering import Steering
    scene = load_scene(DEFAULT)
    scene = scene.evolve(radar=scene.radar.evolve(antenna_preset=name, angle_window=window),
                         targets=())
    setup = build_setup(scene)
    st = Steering.build(setup.rut, scene.radar)
    u0, u = 0.05, np.linspace(-0.3, 0.3, 41)
    x = np.zeros(st.mask.size, complex)
    x[st.mask] = np.conj(st.steer(np.array([u0])))
    beam = np.sqrt(st.power(x, u[:, None])) / np.sum(st.taper)
    af = array_factor(u - u0, **array_factor_args(st))
    if name != "awr2243-cascade":
        np.testing.assert_allclose(np.abs(af), beam, atol=1e-12)
    else:
        old = array_factor(u - u0, setup.rut.azimuth_positions_m.size)
        assert np.max(np.abs(np.abs(af) - beam)) < 0.6 * np.max(np.abs(np.abs(old) - beam))
    if window == "none" and name != "awr2243-cascade":  # a filled untapered row: the n form
        assert array_factor_args(st) == {"n": PRESETS[name].num_azimuth_unique}
    custom = build_setup(load_scene(CUSTOM))  # a sparse row: its positions, with repeats
    c_st = Steering.build(custom.rut, custom.scene.radar)
    args = array_factor_args(c_st)
    assert args["positions_wl"].size == int(np.count_nonzero(c_st.mask))


def test_rut_pattern_enters_the_synthesis_design():
    """A cos pattern on the RuT's elements weights front end q by its two-way field gain
    g(theta_q)^2 (Tx element towards its Rx antenna, Rx element towards its Tx antenna): the
    exact design's amplitude ratio A_J / A_I changes by (g_I / g_J)^2 and the synthesized
    angles stay on target."""
    from rtsgeom.geometry.patterns import CosinePattern
    iso_scene = load_scene(DEFAULT)
    s = _text().replace("[radar.cfar]", '[radar.pattern]\nkind = "cos"\nhpbw_deg = 30.0\n\n'
                                        "[radar.cfar]")
    pat_scene = loads_scene(s, "x.toml")
    iso = ChannelPhasors.build(build_setup(iso_scene), (0, 1), 3)
    pat = ChannelPhasors.build(build_setup(pat_scene), (0, 1), 3)
    g = CosinePattern(math.radians(30.0)).field(
        np.stack([np.sin(iso.setup.fe_azimuth_rad()), np.cos(iso.setup.fe_azimuth_rad()),
                  np.zeros(2)], -1)).real
    r_iso = iso.amplitudes[:, 1] / iso.amplitudes[:, 0]
    r_pat = pat.amplitudes[:, 1] / pat.amplitudes[:, 0]
    assert np.allclose(r_pat / r_iso, (g[0] / g[1]) ** 2, rtol=0.02)
    assert np.max(np.abs(pat.angle_errors(np.zeros((2, 3)), "calibrated"))) < 0.01


def test_front_end_pattern_table_from_the_scene_folder(tmp_path):
    az = np.arange(-90, 91, 10.0)
    el = np.array([-45.0, 0.0, 45.0])
    rows = ["azimuth_deg,elevation_deg,gain_db,phase_deg"]
    rows += [f"{a},{e},{-0.01 * a * a},{0.5 * a}" for a in az for e in el]
    (tmp_path / "fe.csv").write_text("\n".join(rows) + "\n")
    text = _text().replace("[sheet]", '[rts.pattern]\nkind = "table"\ntable = "fe.csv"\n\n[sheet]')
    (tmp_path / "s.toml").write_text(text)
    scene = load_scene(tmp_path / "s.toml")
    assert Path(scene.rts.pattern.table) == (tmp_path / "fe.csv").resolve()
    from rtsgeom.geometry.patterns import AntennaPatterns, TablePattern
    setup = build_setup(scene)
    table = TablePattern.from_csv(tmp_path / "fe.csv")
    a = exact_paths(setup)
    b = exact_paths(setup, AntennaPatterns(fe_rx=table, fe_tx=table))
    assert np.array_equal(a.gain, b.gain)
    assert not np.allclose(a.gain, exact_paths(setup, AntennaPatterns()).gain)


def test_raytrace_refuses_patterns_it_cannot_take():
    from rtsgeom.paths.raytrace import raytrace_paths
    s = _text().replace("[sheet]", '[rts.pattern]\nkind = "cos"\nhpbw_deg = 60.0\n\n[sheet]')
    with pytest.raises(SceneError, match=r"rts\.pattern\.kind.*isotropic with --paths raytrace"):
        raytrace_paths(build_setup(loads_scene(s, "x.toml")))


def test_rut_yaw_error_shifts_every_synthesized_angle():
    """A RuT yaw error turns the frame it measures in: every detected angle moves by -yaw,
    which no calibration of the RTS removes (closed form, per draw)."""
    setup = build_setup(load_scene(DEFAULT))
    model = ChannelPhasors.build(setup, (0, 1), 3)
    yaw = math.radians(0.05)
    res = monte_carlo(ToleranceModel.arc([model], 2), Bounds(rut_yaw_rad=yaw), 40, 5, "uniform", 0.1,
                          keep_errors=True)
    drawn = np.degrees(res.errors["rut_yaw_rad"])
    for case in ("uncalibrated", "calibrated"):
        assert np.allclose(res.worst_error_deg[case][:, 0], -drawn, atol=2e-3)


def test_coverage_plan_that_cannot_reach_the_coverage_has_no_design():
    """An arc far off the RuT for its radius (R_c 0.2 m, centre 8 cm behind the RuT), where a
    front end's detected angle jumps with its place: the placement does not converge, and
    the design says so (NaN and the problem) instead of an arc short of the coverage
    ("2 front ends at 4.44, 13.67 deg" detected at -10 .. 3.7 had passed as a design)."""
    from rtsgeom.analysis.coverage import evaluate_arc, plan_arc
    scene = make_scene(lambda d: (d.update(targets=[]),
                                  d["rts"].update(arc_center_m=[0.0, -0.08, 0.0])))
    plan = plan_arc(scene, (math.radians(-10.0), math.radians(10.0)), 0.2)
    assert plan.problem is not None and "coverage's ends" in plan.problem
    design = evaluate_arc(plan, draws=10, points=3)
    assert design.problem == plan.problem
