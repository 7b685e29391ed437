"""benchmarks/_io.py writes the committed benchmark results byte for byte: re-writing each
file from its own parsed content gives the same bytes (JSON floats and CSV cells both round
trip through repr), so folding the benchmarks' writers into it changed no output."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from benchmarks._io import write_json, write_json_csv

B = Path(__file__).resolve().parents[1] / "benchmarks"


@pytest.mark.parametrize("stem, rows_key, newline, sorted_keys", [
    ("calibration_noise", "rows", False, False),
    ("calibration_resolution", "rows", False, False),
    ("calibration_grid", "rows", False, False),
    ("calibration_grid_linearity", "rows", False, False),
    ("tolerance_grid", None, True, True),
])
def test_json_and_csv_pairs_round_trip(tmp_path, stem, rows_key, newline, sorted_keys):
    obj = json.loads((B / f"{stem}.json").read_text())
    rows = obj if rows_key is None else obj[rows_key]
    keys = sorted({k for r in rows for k in r}) if sorted_keys else None
    js, cs = write_json_csv(tmp_path / stem, obj, rows, newline=newline, fieldnames=keys)
    assert js.read_bytes() == (B / f"{stem}.json").read_bytes()
    assert cs.read_bytes() == (B / f"{stem}.csv").read_bytes()


@pytest.mark.parametrize("stem, newline", [("estimators", True), ("realised_plan", False),
                                           ("cell_calibration", False)])
def test_json_only_round_trip(tmp_path, stem, newline):
    obj = json.loads((B / f"{stem}.json").read_text())
    out = write_json(tmp_path / f"{stem}.json", obj, newline=newline, default=float)
    assert out.read_bytes() == (B / f"{stem}.json").read_bytes()
