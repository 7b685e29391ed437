"""Cable ghosts: predicted ghost ranges and levels against the simulated
range-Doppler map."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.constants import c

from rtsgeom.analysis.ghosts import _peak, _zoom_power, ghost_analysis, ghost_orders
from rtsgeom.cli import main
from rtsgeom.rts.channels import KIND_GHOST
from rtsgeom.pipeline.run import run_scene

from conftest import DEFAULT_SCENE, make_scene


def one_target(rl_fe=15.0, rl_be=15.0, loss=1.0, length=1.0, vf=0.7, snr=None):
    """One target at 30 m on FE 0 (noise-free unless ``snr``), both cables set alike."""
    def mutate(doc):
        if snr is None:
            doc["radar"].pop("snr_db", None)
        else:
            doc["radar"]["snr_db"] = snr
        doc["targets"] = [{"range_m": 30.0, "angle_deg": 3.4}]
        for fe in doc["rts"]["front_ends"]:
            fe.update(cable_length_m=length, cable_velocity_factor=vf, cable_loss_db=loss)
            for key, val in (("return_loss_fe_db", rl_fe), ("return_loss_be_db", rl_be)):
                if val is None:
                    fe.pop(key, None)
                else:
                    fe[key] = val
    return make_scene(mutate)


@pytest.fixture(scope="module")
def base():
    return ghost_analysis(one_target(), simulate=True)


def first(report):
    pred = report.targets[0]["ghosts"][0]
    sim = report.simulated[0]["ghosts"][0] if report.simulated else None
    return pred, sim


def test_first_ghost_is_l_over_vf_behind_the_target(base):
    pred, sim = first(base)
    fe = base.front_ends[0]
    assert pred["order"] == 1
    assert pred["range_offset_m"] == pytest.approx(1.0 / 0.7, rel=1e-12)  # 1.43 m
    assert pred["delay_s"] == pytest.approx(2 * 1.0 / (0.7 * c), rel=1e-12)  # 9.53 ns
    assert pred["range_m"] == pytest.approx(30.0 + 1.0 / 0.7)
    assert fe["range_offset_per_order_m"] == pytest.approx(1.4286, abs=1e-4)
    # in the simulated range-Doppler map, within 0.2 range bins
    assert abs(sim["offset_error_bins"]) < 0.2
    assert sim["offset_from_target_m"] == pytest.approx(1.0 / 0.7,
                                                        abs=0.2 * base.scene.radar.range_resolution_m)
    # the level: two cables -> 2 Gamma_fe Gamma_be a^2 = -26 dB; the second ghost 3 rho^2
    rho = 10 ** (-(15 + 15 + 2 * 1.0) / 20)
    assert pred["level_db"] == pytest.approx(20 * np.log10(2 * rho))
    assert base.targets[0]["ghosts"][1]["level_db"] == pytest.approx(20 * np.log10(3 * rho ** 2))
    assert sim["level_db"] == pytest.approx(pred["level_db"], abs=0.2)
    assert sim["within_cfar_window_of_target"]  # 9.5 bins: inside the CA-CFAR training ring


@pytest.mark.parametrize("change, first_db", [
    ({"rl_fe": 21.0}, -6.0),  # 6 dB more return loss at the front end: Gamma / 2
    ({"rl_be": 9.0}, +6.0),  # 6 dB less at the back end: Gamma x 2
    ({"loss": 2.0}, -2.0),  # 1 dB more cable loss, run twice per round trip
])
def test_ghost_level_follows_reflections_and_cable_loss(base, change, first_db):
    p0, s0 = first(base)
    other = ghost_analysis(one_target(**change), simulate=True)
    p1, s1 = first(other)
    assert p1["level_db"] - p0["level_db"] == pytest.approx(first_db, abs=1e-9)
    assert s1["level_db"] - s0["level_db"] == pytest.approx(first_db, abs=0.1)
    assert p1["range_m"] == p0["range_m"]
    # the second ghost has two round trips: twice the change
    assert (other.targets[0]["ghosts"][1]["level_db"]
            - base.targets[0]["ghosts"][1]["level_db"]) == pytest.approx(2 * first_db, abs=1e-9)


def test_no_mismatch_no_ghosts(base):
    scene = one_target(rl_fe=None, rl_be=None)
    rep = ghost_analysis(scene, simulate=True)
    assert all(not fe["mismatched"] and fe["ghosts"] == [] for fe in rep.front_ends)
    assert rep.targets[0]["ghosts"] == [] and rep.simulated[0]["ghosts"] == []
    assert not np.any(rep.result.echoes.kind == KIND_GHOST)
    # nothing where the ghost would be: more than 60 dB below the target (window sidelobes)
    t = _peak(rep.result.rd, rep.result.cube, 30.0, 0.0)
    g = _peak(rep.result.rd, rep.result.cube, 30.0 + 1.0 / 0.7, 0.0)
    assert g.level_db - t.level_db < -60.0
    assert g.level_db - t.level_db < first(base)[1]["level_db"] - 30.0
    # one end matched is enough: no round trip
    assert ghost_orders(one_target(rl_be=None))[0]["ghosts"] == []


def test_floor_limits_the_orders():
    scene = one_target()
    assert [g["order"] for g in ghost_orders(scene, -80.0)[0]["ghosts"]] == [1, 2]
    assert [g["order"] for g in ghost_orders(scene, -30.0)[0]["ghosts"]] == [1]
    assert ghost_orders(scene, -20.0)[0]["ghosts"] == []
    # low return loss: many orders, levels (n + 1) rho^n
    many = ghost_orders(one_target(rl_fe=3.0, rl_be=3.0, loss=0.0), -80.0)[0]["ghosts"]
    rho = 10 ** (-6 / 20)
    assert len(many) > 10
    assert [g["level_db"] for g in many] == pytest.approx(
        [20 * np.log10((n + 1) * rho ** n) for n in range(1, len(many) + 1)])


def test_zoom_equals_the_map_on_the_bin_grid():
    result = run_scene(one_target(), aoa_mode="nearest")
    rd = result.rd
    d = rd.power.shape[1] // 2
    bins = np.arange(190, 220)
    z = _zoom_power(result.cube, d, bins.astype(float))
    assert np.allclose(z, rd.power[bins, d], rtol=1e-4, atol=1e-6 * rd.power[bins, d].max())


def test_ghosts_cli_default_scene(tmp_path):
    out = tmp_path / "g"
    assert main(["ghosts", str(DEFAULT_SCENE), "--simulate", "--out", str(out)]) == 0
    d = json.loads((out / "ghosts.json").read_text())
    assert (out / "ghosts.png").stat().st_size > 0
    assert len(d["targets"]) == 4 and len(d["simulated"]) == 4
    for t, s in zip(d["targets"], d["simulated"]):
        assert [g["order"] for g in t["ghosts"]] == [1, 2]
        g1 = s["ghosts"][0]
        # with the scene's noise the first ghost (-26 dB) stands 20+ dB clear of it
        assert abs(g1["offset_error_bins"]) < 0.2
        assert g1["level_db"] == pytest.approx(t["ghosts"][0]["level_db"], abs=0.6)
        assert g1["above_map_median_db"] > 15
    with pytest.raises(SystemExit) as exc:
        main(["ghosts", str(DEFAULT_SCENE), "--floor-db", "5"])
    assert exc.value.code == 2
