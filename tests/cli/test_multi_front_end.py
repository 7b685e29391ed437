"""A scene of five front ends: ``design`` says which pair it studies and how to choose another,
logs its progress as plain lines off a terminal, and ``tolerance --pair all --invert-yield``
finds the arc's tolerance (one factor on every drawn scale)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from rtsgeom.cli import main

TEMPLATE = Path(__file__).resolve().parents[2] / "scenes" / "template.toml"


def test_design_names_its_pair_and_logs_progress(capsys):
    assert main(["design", str(TEMPLATE), "--radius-m", "0.5:1:2", "--spacing-deg", "6:6:1",
                 "--draws", "20", "--points", "5", "--json"]) == 0
    cap = capsys.readouterr()
    assert json.loads(cap.out)["pair"] == [0, 1]
    assert "design studies the pair (0, 1) of the scene's 5 front ends" in cap.err
    assert "--pair I J for another adjacent pair (1 2, 2 3, 3 4)" in cap.err
    lines = re.findall(r"^rtsgeom: designs (\d+)/2 \((\d+) %\)", cap.err, re.M)
    assert lines == [("1", "50"), ("2", "100")], cap.err


def test_tolerance_inverts_the_yield_of_a_whole_arc(capsys):
    assert main(["tolerance", str(TEMPLATE), "--pair", "all", "--draws", "100", "--points", "5",
                 "--invert-yield", "0.9", "--json", "--quiet"]) == 0
    out = json.loads(capsys.readouterr().out)
    inv = out["inversion"]
    assert set(inv) == {"uncalibrated", "calibrated"}
    for case, entry in inv.items():
        # the factor scales every drawn scale, and the yield there meets the target
        assert entry["scales"]["radial_mm"] == pytest.approx(
            entry["factor"] * out["scales"]["radial_mm"])
        assert entry["yield"] >= 0.9 or entry["capped"]
    # calibration buys tolerance: the calibrated arc takes a larger factor
    assert inv["calibrated"]["factor"] > inv["uncalibrated"]["factor"]
