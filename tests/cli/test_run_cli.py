"""The main job end to end: outputs, accuracy against the set-points, reproducibility."""

from __future__ import annotations

import csv
import json
import re

import numpy as np
import pytest

from rtsgeom.cli import main

from conftest import DEFAULT_SCENE


@pytest.fixture(scope="module")
def two_runs(tmp_path_factory):
    outs = []
    for k in range(2):
        out = tmp_path_factory.mktemp(f"run{k}")
        assert main(["run", str(DEFAULT_SCENE), "--out", str(out), "--quiet",
                     "--maps", "npz,mat,nc", *(["--no-report"] if k else [])]) == 0
        outs.append(out)
    return outs


@pytest.mark.slow
def test_run_writes_the_contract(two_runs):
    out = two_runs[0]
    for name in ("detections.csv", "summary.json", "range_doppler.png", "range_angle.png",
                 "maps.npz", "maps.mat", "maps.nc", "report.html"):
        assert (out / name).stat().st_size > 0, name
    rows = list(csv.DictReader((out / "detections.csv").open()))
    assert list(rows[0])[:4] == ["range_m", "velocity_mps", "angle_deg", "power_db"]
    s = json.loads((out / "summary.json").read_text())
    for key in ("f_c_hz", "bandwidth_hz", "slope_hz_per_s", "adc_rate_hz", "samples_per_chirp",
                "chirps_per_tx", "tx_order", "num_rx"):
        assert key in s["radar"], key
    assert s["radar"]["tx_order"] == [0, 2] and s["radar"]["num_rx"] == 4
    assert s["seed"] == 2022 and len(s["scene_sha256"]) == 64 and s["rtsgeom_version"]
    # the paper's Table I, synthesized at its set angles between the front ends (exact mode)
    rbin, vbin = s["radar"]["range_resolution_m"], s["radar"]["velocity_resolution_mps"]
    for t in s["targets"]:
        e = t["error"]
        assert abs(e["range_m"]) < rbin and abs(e["velocity_mps"]) < vbin
        assert abs(e["angle_deg"]) < 0.1
    html = (out / "report.html").read_text()
    # no address outside the page (embedded images' base64 may spell "http" by chance)
    body = re.sub(r"data:[^\"')\s]+", "", html.split("<footer>")[0])
    assert "http" not in body.replace("http-equiv", "")
    assert html.count("<img") >= 4  # 3D view, two maps, calibration sweep


@pytest.mark.slow
def test_same_seed_same_bytes(two_runs):
    """Two runs of one scene, seconds apart, are byte-identical in every file both wrote (the
    maps' arrays and PNGs included; the second skipped report.html)."""
    a, b = two_runs
    names = sorted(p.name for p in b.iterdir())
    assert {"detections.csv", "summary.json", "maps.npz", "maps.mat", "maps.nc",
            "range_angle.png"} <= set(names)
    for name in names:
        assert (a / name).read_bytes() == (b / name).read_bytes(), name


def test_adc_and_dca1000(tmp_path):
    out = tmp_path / "cube.npy"
    assert main(["adc", str(DEFAULT_SCENE), "--out", str(out), "--amplitudes", "nearest"]) == 0
    cube = np.load(out)
    assert cube.shape == (120, 8, 512) and cube.dtype == np.complex64
    raw = tmp_path / "adc.bin"
    assert main(["adc", str(DEFAULT_SCENE), "--out", str(raw), "--format", "dca1000",
                 "--amplitudes", "nearest"]) == 0
    assert raw.stat().st_size == 120 * 2 * 4 * 512 * 4
    meta = json.loads((tmp_path / "adc.bin.json").read_text())
    assert meta["chirps"] == 240 and meta["scale"] > 0
