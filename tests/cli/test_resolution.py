"""``rtsgeom resolution``'s output, as the other study commands': the summary (or ``--json``)
and the files written on stdout, progress on stderr, ``--quiet`` silencing the progress
only."""

from __future__ import annotations

import json

import pytest

from rtsgeom.cli import main

ARGS = ["resolution", "scenes/diewald2022.toml", "--separations-deg", "2,4", "--phases-deg",
        "0"]


def test_quiet_silences_the_progress_not_the_result(tmp_path, capsys):
    out = tmp_path / "o"
    assert main(ARGS + ["--out", str(out)]) == 0
    loud = capsys.readouterr()
    assert main(ARGS + ["--out", str(out), "--quiet"]) == 0
    quiet = capsys.readouterr()
    assert loud.err and not quiet.err  # the progress
    assert quiet.out == loud.out  # the summary and the files written
    assert quiet.out.startswith("<Resolution: diewald2022")
    assert quiet.out.rstrip().endswith(
        f"wrote {out}/resolution.csv, summary.json, resolution.png")
    assert main(ARGS + ["--json", "--quiet"]) == 0
    assert json.loads(capsys.readouterr().out) == json.loads(
        (out / "summary.json").read_text())


def test_an_empty_out_is_refused_as_by_the_other_commands(capsys):
    with pytest.raises(SystemExit) as exc:
        main(ARGS + ["--out", ""])
    assert exc.value.code == 2
    assert "--out: '' names no file or folder" in capsys.readouterr().err
