"""A run's summary: one row per target up to twelve, the rest counted, the cube and the first
warning."""

from __future__ import annotations

import numpy as np
import pytest


@pytest.mark.parametrize("n", [1, 11, 12, 13, 20])
def test_a_run_summary_lists_twelve_targets_and_counts_the_rest(n):
    """One row per target up to twelve (each one's errors in mm, m/s and deg, or 'not
    detected'), then '... N more targets'; the first warning and their count."""
    from types import SimpleNamespace
    from rtsgeom.pipeline.run import MAX_SUMMARY_TARGETS, RunResult
    assert MAX_SUMMARY_TARGETS == 12
    matches = [{"index": k, "error": None if k % 3 == 2 else
                {"range_m": 0.0012 * k, "velocity_mps": -0.01, "angle_deg": 0.0002 * k}}
               for k in range(n)]
    fake = SimpleNamespace(scene=SimpleNamespace(name="bench", targets=(None,) * n),
                           aoa_mode="exact", cube=SimpleNamespace(data=np.zeros((4, 8, 16)),
                                                                  clipped=0),
                           detections=SimpleNamespace(range_m=np.zeros(5)), matches=matches,
                           warnings=["first", "second"])
    title, rows = RunResult._summary(fake)
    assert title == f"bench: one frame, {n} targets, exact amplitudes"
    assert rows[:2] == [("cube", "4x8x16 ADC samples"), ("detections", 5)]
    listed = rows[2:2 + min(n, 12)]
    assert listed[0] == ("target 0", "error +0.0 mm, -0.01 m/s, +0.0000 deg")
    if n > 1:
        assert listed[1] == ("target 1", "error +1.2 mm, -0.01 m/s, +0.0002 deg")
    if n > 2:
        assert listed[2] == ("target 2", "not detected")
    more = [("...", f"{n - 12} more targets")] if n > 12 else []
    assert rows[2 + min(n, 12):] == more + [("warnings", "2: first")]
    clipped = SimpleNamespace(**{**vars(fake), "cube": SimpleNamespace(
        data=np.zeros((4, 8, 16)), clipped=7), "warnings": []})
    t2, r2 = RunResult._summary(clipped)
    assert r2[0] == ("cube", "4x8x16 ADC samples, 7 CLIPPED") and r2[-1] == ("warnings", "none")


@pytest.mark.parametrize("snr_db", [None, 20.0])
def test_summary_json_says_the_run_and_the_radar_it_ran(snr_db):
    """``summary`` (summary.json): every radar key is the scene's value under its own name
    (the SNR's absence as null), the counts are the result's, and the whole is JSON."""
    import json

    from conftest import small_quiet
    from rtsgeom.pipeline.run import run_scene, summary
    scene = small_quiet(**({} if snr_db is None else {"snr_db": snr_db}))
    assert scene.radar.snr_db == snr_db
    res = run_scene(scene)
    s = json.loads(json.dumps(summary(res, "exact")))
    r = scene.radar
    same = ("f_c_hz", "bandwidth_hz", "slope_hz_per_s", "adc_rate_hz", "adc_start_s",
            "samples_per_chirp", "chirps_per_tx", "chirp_repetition_s", "range_resolution_m",
            "velocity_resolution_mps", "snr_db")
    assert set(s["radar"]) == set(same) | {"tx_order", "num_rx", "cube_layout"}
    for k in same:
        assert s["radar"][k] == getattr(r, k), k
    assert s["radar"]["tx_order"] == list(res.setup.rut.tx_order)
    assert s["radar"]["num_rx"] == res.setup.rut.num_rx
    assert (s["scene"], s["seed"], s["paths"], s["aoa_mode"]) == (scene.name, scene.seed,
                                                                  "exact", res.aoa_mode)
    assert s["num_detections"] == len(res.detections) >= 2
    assert s["num_echoes"] == len(res.echoes)
    assert s["adc_clipped_samples"] == res.cube.clipped
    assert len(s["targets"]) == len(scene.targets) == 2
    assert all("detection_index" not in t for t in s["targets"])
    assert s["warnings"] == list(res.warnings)
    # the whole dict, built from the result's parts
    import rtsgeom
    from rtsgeom.pipeline.info import scene_info
    info = scene_info(res.setup)
    want = {
        "rtsgeom_version": rtsgeom.__version__, "scene": scene.name,
        "scene_sha256": scene.sha256, "seed": scene.seed, "paths": "exact",
        "aoa_mode": res.aoa_mode,
        "radar": {**{k: getattr(r, k) for k in same},
                  "tx_order": list(res.setup.rut.tx_order), "num_rx": res.setup.rut.num_rx,
                  "cube_layout": "[chirp_loop, virtual_channel (tx_slot * num_rx + rx), "
                                 "sample]"},
        "far_field": info["far_field"], "front_ends": info["front_ends"],
        "calibration": res.calibration,
        "targets": [{k: v for k, v in m.items() if k != "detection_index"}
                    for m in res.matches],
        "link_budget": res.link_budget.to_dict(), "adc_clipped_samples": res.cube.clipped,
        "num_detections": len(res.detections), "num_echoes": len(res.echoes),
        "warnings": list(res.warnings)}
    assert s == json.loads(json.dumps(want))
    assert res.calibration["mode"] == res.aoa_mode and len(res.calibration["targets"]) == 2
    # the cube's layout as the text says: virtual channel v = slot * num_rx + rx
    n_rx = res.setup.rut.num_rx
    assert res.cube.data.shape == (r.chirps_per_tx, len(res.setup.rut.tx_order) * n_rx,
                                   r.samples_per_chirp)


def test_run_scene_refuses_a_calibration_that_is_no_dict():
    from conftest import assert_refused, small_quiet
    from rtsgeom.pipeline.run import run_scene
    scene = small_quiet()
    for bad in ([], "calibration.json", 3):
        assert_refused(lambda: run_scene(scene, calibration=bad),
                       f"run_scene: calibration = {type(bad).__name__}: must be a calibration "
                       "file's content (a dict, json.load of calibration.json)")


@pytest.mark.parametrize("link", [False, True])
@pytest.mark.parametrize("kinds", [(0, 0), (0, 2, 1), ()])
def test_the_budget_estimates_the_sheet_only_for_a_link_without_setup_echoes(monkeypatch, link,
                                                                             kinds):
    """With ``[radar.link]`` the physical-optics sheet estimate (``sheet_paths`` then
    ``setup_echoes``) is formed once where the echoes carry no setup reflection and handed to
    ``link_budget``; never where they carry one, never without ``[radar.link]``."""
    from types import SimpleNamespace
    import rtsgeom.pipeline.run as run
    from rtsgeom.rts.channels import EchoKind
    calls = []
    sp, est, setup = object(), object(), object()
    monkeypatch.setattr(run, "sheet_paths", lambda s: calls.append(("sheet", s)) or sp)
    monkeypatch.setattr(run, "setup_echoes",
                        lambda s, p: calls.append(("echoes", s, p)) or est)
    monkeypatch.setattr(run, "link_budget", lambda *a: a)
    scene = SimpleNamespace(radar=SimpleNamespace(link=object() if link else None,
                                                  snr_db=None))
    echoes = SimpleNamespace(kind=np.array(kinds, int))
    program = object()
    got = run._budget(scene, setup, echoes, program)
    formed = link and EchoKind.SETUP not in kinds
    assert calls == ([("sheet", setup), ("echoes", setup, sp)] if formed else [])
    assert got == (scene, echoes, program, link, None, est if formed else None)
