"""``rtsgeom kpi``'s options: made from the study's declared arguments (``KpiStudy.ARGS``),
so the command and ``KpiStudy`` accept and refuse the same values, with the same range in the
help and in the error. (The command's run and outputs: tests/analysis/test_kpi.py.)"""

from __future__ import annotations

import dataclasses

import pytest

from rtsgeom.analysis.kpi import KpiStudy
from rtsgeom.analysis.tolerance.args import Arg
from rtsgeom.cli import build_parser
from rtsgeom.errors import ParameterError

#: option -> (a value just inside each bound, one just outside)
BOUNDS = {"sigma_phase_deg": ((0.0, 90.0), (-1e-9, 90.000001)),
          "points": ((1, 201), (0, 202)),
          "draws": ((100, 1_000_000), (99, 1_000_001)),
          "seed": ((0, 2 ** 63 - 1), (-1, 2 ** 63))}


def _parse(*argv):
    return build_parser("kpi", lazy=True).parse_args(["kpi", "scene.toml", *argv])


def _help() -> str:
    return " ".join(build_parser("kpi", lazy=True)._subparsers._group_actions[0]
                    .choices["kpi"].format_help().split())


@pytest.mark.parametrize("name", sorted(BOUNDS))
def test_the_command_and_the_study_take_the_same_range(name, capsys):
    flag = "--" + name.replace("_", "-")
    inside, outside = BOUNDS[name]
    arg = KpiStudy.ARGS[name]
    assert (arg.lo, arg.hi) == inside
    for v in inside:
        assert getattr(_parse(f"{flag}={v}"), name) == v
        KpiStudy(**{name: v})
    for v in outside:
        with pytest.raises(SystemExit) as exc:
            _parse(f"{flag}={v}")
        assert exc.value.code == 2
        err = capsys.readouterr().err
        assert flag in err and f"[{inside[0]}, {inside[1]}]" in err, err
        with pytest.raises(ParameterError, match=name):
            KpiStudy(**{name: v})


def test_sigma_mm_takes_one_or_three_values_in_the_declared_range(capsys):
    assert _parse("--sigma-mm", "0", "10", "0.5").sigma_mm == [0.0, 10.0, 0.5]
    assert KpiStudy.ARGS["sigma_mm"].hi == 10.0
    with pytest.raises(SystemExit):
        _parse("--sigma-mm", "10.5")
    assert "[0.0, 10.0]" in capsys.readouterr().err
    with pytest.raises(ParameterError, match=r"sigma_mm .*\[0, 10\] mm"):
        KpiStudy(sigma_mm=10.5)


def test_the_defaults_are_the_studys():
    args = _parse()
    study = KpiStudy()
    for name in ("sigma_mm", "sigma_phase_deg", "points", "draws", "seed"):
        assert getattr(args, name) == getattr(study, name), name
    text = _help()
    for part in ("in [1, 201] (default 11)", "in [100, 1000000] (default 2000)",
                 "in [0, 10] (default 0.1)", "(default the scene's seed)",
                 "in [0, 90] (default the RMS of [radar.channels]' phases, else 0)"):
        assert part in text, part


def test_an_option_follows_its_declaration(monkeypatch, capsys):
    """The option is made from the declaration, not written beside it: a narrower range
    declared for the study is the command's range too."""
    narrow = dataclasses.replace(KpiStudy.ARGS["draws"], lo=500, hi=5000)
    monkeypatch.setitem(KpiStudy.ARGS, "draws", narrow)
    monkeypatch.setitem(KpiStudy.ARGS, "points", Arg("int", "set angles", 3, 7))
    with pytest.raises(SystemExit):
        _parse("--draws", "400")
    assert "[500, 5000]" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        _parse("--points", "8")
    assert "[3, 7]" in capsys.readouterr().err
    assert "set angles, in [3, 7] (default 11)" in _help()
