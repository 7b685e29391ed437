"""Tests of ``rtsgeom.analysis.ghosts``: closed forms and invariants on grids of inputs."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import make_scene


@pytest.mark.parametrize("cable_m", [3.0, 6.0, 9.0])
def test_strong_cable_ghosts_outside_the_cfar_window_are_reported_as_detected(cable_m):
    """A badly matched cable (6 dB return loss at both ends, no loss): ghost n lies n L / VF
    behind the target; ``cfar_detected`` is whether the run's CFAR list has a detection within
    one bin of the ghost, and the first ghost (-6 dB, beyond the CFAR ring once L / VF exceeds
    it) is one."""
    from rtsgeom.analysis.ghosts import ghost_analysis

    def m(doc):
        doc["radar"].update(chirps_per_tx=32, samples_per_chirp=128, adc_rate_hz=12.5e6)
        doc.update(targets=[{"range_m": 12.0, "angle_deg": 3.4}])
        doc["rts"]["front_ends"][0].update(cable_length_m=cable_m, return_loss_fe_db=6.0,
                                           return_loss_be_db=6.0, cable_loss_db=0.0)
    scene = make_scene(m)
    rep = ghost_analysis(scene, simulate=True)
    rd, det = rep.result.rd, rep.result.detections
    bin_m = rd.range_m[1] - rd.range_m[0]
    vf = scene.rts.front_ends[0].cable_velocity_factor
    ghosts = [g for g in rep.simulated[0]["ghosts"] if not g.get("beyond_max_range")]
    for g in ghosts:
        if g["level_db"] > -30:  # well above the range sidelobes: where it was predicted
            assert g["offset_from_target_m"] == pytest.approx(g["order"] * cable_m / vf,
                                                              abs=1.5 * bin_m)
        near = np.any(np.abs(det.range_m - g["range_m"]) <= 1.5 * bin_m)
        assert g["cfar_detected"] is bool(near), g
    first = ghosts[0]
    ring = scene.radar.cfar.guard_cells[0] + scene.radar.cfar.training_cells[0]
    if cable_m / vf > (ring + 1) * bin_m:
        assert first["order"] == 1 and first["cfar_detected"] is True
        assert not first["within_cfar_window_of_target"]


def test_ghost_reports_name_their_fields_and_cfar_misses_the_first_ghost():
    """The ghost analysis of the default scene: the first ghost lies in its
    target's CA-CFAR ring (9.5 bins behind, ring 2 + 8), so CFAR does not report it."""
    from rtsgeom.analysis.ghosts import ghost_analysis, ghost_orders, predict_ghosts
    s = make_scene(lambda d: d.update(targets=[{"range_m": 30.0, "angle_deg": 3.4}]))
    orders = ghost_orders(s)
    assert orders[0]["return_loss_fe_db"] == 15.0 and orders[0]["return_loss_be_db"] == 15.0
    pred = predict_ghosts(s)
    assert pred[0]["front_end"] == 0
    rep = ghost_analysis(s, simulate=True)
    first = rep.simulated[0]["ghosts"][0]
    assert first["within_cfar_window_of_target"] and first["cfar_detected"] is False


def _ghost_report(n_targets, simulated=None):
    from types import SimpleNamespace
    from rtsgeom.analysis.ghosts import GhostReport
    targets = []
    for k in range(n_targets):
        ghosts = [{"order": o, "range_m": 10.0 + k + 1.5 * o, "level_db": -20.0 * o}
                  for o in range(1, (k % 5) + 1)]
        targets.append({"index": k, "range_m": 10.0 + k, "front_end": k % 2, "ghosts": ghosts})
    fes = [{"index": 0, "mismatched": True}, {"index": 1, "mismatched": False},
           {"index": 2, "mismatched": True}]
    return GhostReport(SimpleNamespace(name="bench"), -60.0, fes, targets, simulated)


def test_the_ghost_summary_lists_targets_up_to_twelve():
    title, rows = _ghost_report(14)._summary()
    assert title == "bench: cable ghosts above -60 dB"
    assert rows[0] == ("mismatched front ends", "[0, 2]")
    assert rows[1] == ("target 0 (10 m, FE 0)", "none above the floor")
    assert rows[2] == ("target 1 (11 m, FE 1)", "order 1 at 12.5 m -20.0 dB")
    assert rows[4] == ("target 3 (13 m, FE 1)", "order 1 at 14.5 m -20.0 dB, order 2 at 16 m "
                                                "-40.0 dB, order 3 at 17.5 m -60.0 dB")
    assert rows[5] == ("target 4 (14 m, FE 0)", "order 1 at 15.5 m -20.0 dB, order 2 at 17 m "
                                                "-40.0 dB, order 3 at 18.5 m -60.0 dB and 1 more")
    assert len(rows) == 1 + 12 + 1 and rows[-1] == ("...", "2 more targets")
    assert len(_ghost_report(12)._summary()[1]) == 13
    assert _ghost_report(1, simulated=[])._summary()[0] == (
        "bench: cable ghosts above -60 dB, simulated")


def test_the_ghost_table_has_a_row_per_target_and_order_with_the_simulated_level():
    rep = _ghost_report(3)
    cols = rep._columns()
    assert cols == {"target": [1, 2, 2], "front_end": [1, 0, 0],
                    "target_range_m": [11.0, 12.0, 12.0], "order": [1, 1, 2],
                    "range_m": [12.5, 13.5, 15.0], "level_db": [-20.0, -20.0, -40.0]}
    sim = [{"index": 2, "ghosts": [{"order": 1, "level_db": -21.0}]},
           {"ghosts": [{"order": 1, "level_db": -19.0}]},  # no index: its position, 1
           {"index": 2, "ghosts": [{"order": 2, "level_db": -41.0}]}]
    cols = _ghost_report(3, simulated=sim)._columns()
    # the simulated level of each (target, order): an entry's own index, else its position
    assert cols["simulated_level_db"] == [-19.0, -21.0, -41.0]
    sim[2] = {"ghosts": []}
    assert _ghost_report(3, simulated=sim)._columns()["simulated_level_db"] == [-19.0, -21.0,
                                                                                 None]


@pytest.mark.parametrize("floor_db", [-40.0, -25.0])
def test_the_ghost_orders_and_predictions_in_full(floor_db):
    """Each front end's whole entry from the cable's closed form: Gamma = 10^(-RL/20),
    a = 10^(-loss/20), order n at n L / VF (delay n L / (VF c) ... as 2 x range / c) with
    level (n + 1) (Gamma_fe Gamma_be a^2)^n, those above the floor, in order; a matched
    front end (a return loss at one end only) has none. Each target's ghosts sit on its nearest front
    end's, at its range plus the offset."""
    from scipy.constants import c

    from rtsgeom.analysis.ghosts import ghost_orders, predict_ghosts

    def m(doc):
        doc.update(targets=[{"range_m": 12.0, "angle_deg": 3.4, "velocity_mps": -2.0},
                            {"range_m": 20.0, "angle_deg": 12.2}])
        doc["rts"]["front_ends"][0].update(cable_length_m=2.5, return_loss_fe_db=6.0,
                                           return_loss_be_db=10.0, cable_loss_db=1.0)
        doc["rts"]["front_ends"][1]["return_loss_fe_db"] = 20.0  # one end alone: matched
        doc["rts"]["front_ends"][1].pop("return_loss_be_db", None)
    scene = make_scene(m)
    fes = scene.rts.front_ends
    want = []
    for q, fe in enumerate(fes):
        vf = fe.cable_velocity_factor
        entry = {"index": q, "mismatched": q == 0, "cable_length_m": fe.cable_length_m,
                 "cable_velocity_factor": vf, "cable_loss_db": fe.cable_loss_db,
                 "return_loss_fe_db": 6.0 if q == 0 else 20.0,
                 "return_loss_be_db": 10.0 if q == 0 else None,
                 "gamma_fe": 10 ** (-6 / 20) if q == 0 else 0.1,
                 "gamma_be": 10 ** (-10 / 20) if q == 0 else None,
                 "range_offset_per_order_m": fe.cable_length_m / vf, "ghosts": []}
        if q == 0:
            r = 10 ** (-6 / 20) * 10 ** (-10 / 20) * 10 ** (-2 * 1.0 / 20)
            for n in range(1, 40):
                level = 20 * np.log10((n + 1) * r ** n)
                if level < floor_db:
                    break
                entry["ghosts"].append({"order": n, "delay_s": 2 * n * 2.5 / vf / c,
                                        "range_offset_m": n * 2.5 / vf, "level_db": level})
        want.append(entry)
    got = ghost_orders(scene, floor_db)
    assert [len(g["ghosts"]) for g in got] == [len(w["ghosts"]) for w in want]
    assert len(want[0]["ghosts"]) == {-40.0: 2, -25.0: 1}[floor_db]
    for g, w in zip(got, want):
        gh, wh = g.pop("ghosts"), w.pop("ghosts")
        assert g == w
        for a, b in zip(gh, wh):
            assert a == pytest.approx(b, rel=1e-9, abs=1e-18)
            assert a["order"] == b["order"]
        g["ghosts"] = gh
    pred = predict_ghosts(scene, floor_db)
    assert [{k: v for k, v in p.items() if k != "ghosts"} for p in pred] == [
        {"index": 0, "range_m": 12.0, "velocity_mps": -2.0, "angle_deg": pytest.approx(3.4),
         "front_end": 0},
        {"index": 1, "range_m": 20.0, "velocity_mps": 0.0, "angle_deg": pytest.approx(12.2),
         "front_end": 1}]
    assert pred[0]["ghosts"] == [{**x, "range_m": 12.0 + x["range_offset_m"]}
                                 for x in got[0]["ghosts"]]
    assert pred[1]["ghosts"] == []
