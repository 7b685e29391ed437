"""The long waits of ``adc`` and ``nearfield`` say what they do on stderr, as ``run`` does;
``--quiet`` and ``--json`` keep them silent there."""

from __future__ import annotations

import json
import re
from pathlib import Path

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


def test_progress_off_a_terminal_prints_plain_lines():
    """Off a terminal (a log file, ``2> file``) the Monte-Carlo studies' progress is plain
    lines with counts, percentages and the time left: one per 10 % or 5 s, and one at the end."""
    import io

    from rtsgeom.cli._common import LineProgress
    t = [0.0]
    stream = io.StringIO()
    report = LineProgress(stream, clock=lambda: t[0])
    for done in range(1, 41):
        t[0] = done * 0.5  # 0.5 s per design: 2 s per 10 %
        report("designs", done, 40)
    lines = stream.getvalue().splitlines()
    assert len(lines) == 10, lines  # every 4 of 40, the last one the end
    assert lines[0] == "rtsgeom: designs 4/40 (10 %), 2.0 s, about 18.0 s left"
    assert lines[-1] == "rtsgeom: designs 40/40 (100 %), 20.0 s"
    stream, t[0] = io.StringIO(), 0.0
    slow = LineProgress(stream, clock=lambda: t[0])
    for done in range(1, 1001):  # 1000 draws at 0.1 s: a line every 5 s before each 10 %
        t[0] = done * 0.1
        slow("draws", done, 1000)
    counts = [int(re.search(r" (\d+)/1000", x).group(1)) for x in stream.getvalue().splitlines()]
    assert counts[:3] == [50, 100, 150] and counts[-1] == 1000


def test_progress_quiet_is_none():
    from rtsgeom.cli._common import progress
    with progress(True) as report:
        assert report is None


def test_steps_count_within_a_step_off_a_terminal(capsys):
    """``steps.count`` off a terminal: plain lines with the count and the time left, then the
    step's duration; ``tell`` sends a count to an object with ``count`` and the message to a
    plain callback (a list's append), no message for a count alone."""
    from rtsgeom._lib.util import tell
    from rtsgeom.cli._common import steps
    with steps() as step:
        step("playing 4 frames")
        for f in range(1, 5):
            tell(step, None, "frame", f, 4)
    err = capsys.readouterr().err
    assert re.search(r"^rtsgeom: frame 1/4 \(25 %\), [0-9.]+ s, about [0-9.]+ s left$", err,
                     re.M), err
    assert re.search(r"^rtsgeom: frame 4/4 \(100 %\), [0-9.]+ s$", err, re.M), err
    assert re.search(r"^  playing 4 frames: [0-9.]+ s$", err, re.M), err
    got: list = []
    tell(got.append, "calibrated pair (0, 1)", "calibrating pairs", 1, 2)
    tell(got.append, None, "frame", 1, 2)
    assert got == ["calibrated pair (0, 1)"]


def test_play_counts_every_frame():
    """``Playback`` tells a counting progress each frame (1..N, in order) for each mode."""
    from rtsgeom.analysis.playback import Playback
    from rtsgeom.scene import load_scene

    class Seen(list):
        def __call__(self, message):
            self.append((message, None, None))

        def count(self, stage, done, total):
            self.append((stage, done, total))
    scene = load_scene(Path(__file__).resolve().parents[2] / "scenes" / "crossing.toml")
    seen = Seen()
    result = Playback(baseline=False)(scene, progress=seen)
    n = len(result.time_s)
    frames = [(d, t) for s, d, t in seen if s.endswith(": frame")]
    assert frames == [(f, n) for f in range(1, n + 1)]
