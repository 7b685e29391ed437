"""The long waits of ``adc`` and ``nearfield`` say what they do on stderr, as ``run`` does;
``--quiet`` and ``--json`` keep them silent there."""

from __future__ import annotations

import json
import re

import numpy as np

from conftest import DEFAULT_SCENE
from rtsgeom.cli import main

_STEP = re.compile(r"^\s+(.+): \d+\.\d s$", re.M)


def test_adc_reports_progress(tmp_path, capsys):
    out = tmp_path / "cube.npy"
    assert main(["adc", str(DEFAULT_SCENE), "--amplitudes", "nearest", "--out", str(out)]) == 0
    cap = capsys.readouterr()
    steps = _STEP.findall(cap.err)
    assert steps and steps[0].startswith("simulating diewald2022"), cap.err
    assert np.load(out).ndim == 3 and cap.out.startswith("wrote")
    assert main(["adc", str(DEFAULT_SCENE), "--amplitudes", "nearest", "--out", str(out),
                 "--quiet"]) == 0
    assert capsys.readouterr().err == ""


def test_nearfield_reports_progress(tmp_path, capsys):
    args = ["nearfield", str(DEFAULT_SCENE), "--radius-m", "1:2:2", "--points", "3"]
    assert main(args) == 0
    cap = capsys.readouterr()
    assert _STEP.findall(cap.err) == ["near field at 2 arc radii (1 to 2 m)"], cap.err
    assert main(args + ["--json"]) == 0
    cap = capsys.readouterr()
    assert cap.err == "" and json.loads(cap.out)
    assert main(args + ["--quiet"]) == 0
    assert capsys.readouterr().err == ""


def test_failed_step_reports_no_duration(tmp_path, capsys):
    """A step that raises prints the error only, not "step: 0.0 s" as if it had finished."""
    missing = tmp_path / "missing.toml"
    assert main(["calibrate", str(missing), "--pair", "0", "1"]) == 2
    err = capsys.readouterr().err
    assert "cannot read scene file" in err and not _STEP.findall(err), err
