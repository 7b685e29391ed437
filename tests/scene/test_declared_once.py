"""Each choice declared once: a radar preset is one entry (its array and its link values), an
estimator name of the scene's registry is one with its kernel, and a study argument's range is
one declaration that the Python API and the command line both check."""

from __future__ import annotations

import dataclasses

import pytest

import rtsgeom
from rtsgeom.analysis.tolerance.config import STUDY_ARGS
from rtsgeom.cli import build_parser, main
from rtsgeom.errors import ParameterError
from rtsgeom.radar.estimators import KERNELS
from rtsgeom.scene.link import RADAR_LINK_PRESETS, RadarLinkConfig
from rtsgeom.scene.presets import PRESETS
from rtsgeom.scene.registry import ANGLE_ESTIMATORS, RADAR_PRESETS
from rtsgeom.scene.schema import Derived, specs

from conftest import DEFAULT_SCENE


def test_a_radar_preset_is_one_entry():
    """The link values are the preset's own (the same object), for every preset, and each
    gives every [radar.link] field that defaults to the preset's value, with a source."""
    assert RADAR_PRESETS is PRESETS
    assert list(RADAR_LINK_PRESETS) == list(PRESETS)
    from_preset = {name for name, s in specs(RadarLinkConfig)
                   if isinstance(s.default, Derived) and "preset" in s.default.doc}
    assert from_preset  # the test would pass on nothing otherwise
    for name, p in PRESETS.items():
        assert RADAR_LINK_PRESETS[name] is p.link, name
        assert from_preset <= set(p.link["values"]) == set(p.link["sources"]), name


def test_each_estimator_name_has_its_kernel():
    assert list(KERNELS) == list(ANGLE_ESTIMATORS)
    assert all(callable(f) for f in KERNELS.values())


def _option(parser, command, flag):
    sub = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    return next(a for a in sub.choices[command]._actions if flag in a.option_strings)


@pytest.mark.parametrize("command", ["tolerance", "design"])
@pytest.mark.parametrize("name", ["draws", "seed", "spec_deg", "points"])
def test_the_cli_options_are_made_from_the_declaration(command, name):
    """The option's type refuses just outside the declared range and takes its ends; its help
    states the range."""
    arg = STUDY_ARGS[name]
    opt = _option(build_parser(), command, "--" + name.replace("_", "-"))
    integer = arg.kind == "int"
    for v in (arg.lo, arg.hi):
        assert opt.type(str(int(v) if integer else v)) == v
    step = 1 if integer else 1e-9 * max(abs(arg.hi), 1.0)
    for v in (arg.lo - step, arg.hi + step):
        with pytest.raises(Exception, match="outside the allowed range"):
            opt.type(str(int(v) if integer else v))
    assert "in [" in opt.help


@pytest.mark.parametrize("name, bad", [("draws", 0), ("draws", 10_000_001), ("points", 2),
                                       ("points", 202), ("spec_deg", 0.0), ("spec_deg", 91.0),
                                       ("seed", -1), ("distribution", "cauchy")])
def test_the_api_and_the_config_refuse_what_the_declaration_refuses(name, bad):
    scene = rtsgeom.load_scene(DEFAULT_SCENE)
    with pytest.raises(ParameterError, match=name):
        rtsgeom.tolerance(scene, **{name: bad})
    if name in ("spec_deg", "points"):
        with pytest.raises(ParameterError, match=name):
            rtsgeom.ToleranceStudy(**{name: bad})
    elif name != "draws":
        with pytest.raises(ParameterError, match=name):
            rtsgeom.MonteCarlo(**{name: bad})


def test_the_command_refuses_with_the_same_range(capsys):
    with pytest.raises(SystemExit) as exc:  # argparse's refusal: exit 2, one line
        main(["tolerance", str(DEFAULT_SCENE), "--points", "202", "--quiet"])
    assert exc.value.code == 2 and "[3, 201]" in capsys.readouterr().err


def test_the_study_configs_are_frozen():
    for cls in (rtsgeom.ToleranceStudy, rtsgeom.DesignStudy, rtsgeom.LinearityStudy,
                rtsgeom.CalibrationStudy, rtsgeom.MonteCarlo):
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(cls(), dataclasses.fields(cls)[0].name, None)
