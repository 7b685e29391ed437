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
