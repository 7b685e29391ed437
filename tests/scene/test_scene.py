"""Scene loading and validation: clear errors that name the field."""

from __future__ import annotations

import copy

import pytest

from rtsgeom.errors import SceneError
from rtsgeom.scene import load_scene, parse_scene

from conftest import DEFAULT_SCENE, default_doc


def test_default_scene_loads(default_scene):
    s = default_scene
    assert s.name == "diewald2022"
    assert s.rts.arc_radius_m == 1.0
    assert [round(f.angle_rad * 180 / 3.141592653589793, 6) for f in s.rts.front_ends] == [3.4, 12.2]
    assert s.rts.f_rts_hz == 500e6 and s.rts.f_s_hz == 4e9
    assert s.radar.f_c_hz == 77e9 and s.radar.bandwidth_hz == 1e9
    assert s.radar.chirp_duration_s == 41.33e-6 and s.radar.chirps_per_tx == 120
    assert [(t.range_m, t.velocity_mps) for t in s.targets] == [(33.5, 0.0), (37.0, 4.0),
                                                                (45.0, -2.0), (52.0, -5.0)]
    assert len(s.sha256) == 64


def _mut(fn):
    doc = copy.deepcopy(default_doc())
    fn(doc)
    return doc


CASES = [
    ("missing field", lambda d: d["rts"].pop("arc_radius_m"), "rts.arc_radius_m"),
    ("negative radius", lambda d: d["rts"].__setitem__("arc_radius_m", -1.0), "rts.arc_radius_m"),
    ("unknown key", lambda d: d["radar"].__setitem__("bandwith_hz", 1e9), "radar.bandwith_hz"),
    ("wrong type", lambda d: d["radar"].__setitem__("samples_per_chirp", "512"),
     "radar.samples_per_chirp"),
    ("front ends closer than cutouts",
     lambda d: d["rts"]["front_ends"][1].__setitem__("angle_deg", 5.0),
     "rts.front_ends[1].angle_deg"),
]


@pytest.mark.parametrize("label,mutate,field", CASES, ids=[c[0] for c in CASES])
def test_malformed_scene_names_the_field(label, mutate, field):
    with pytest.raises(SceneError) as err:
        parse_scene(_mut(mutate), "bad.toml")
    msg = str(err.value)
    assert msg.startswith("bad.toml: ")
    assert field in msg


def test_unreadable_and_invalid_toml(tmp_path):
    with pytest.raises(SceneError, match="cannot read"):
        load_scene(tmp_path / "nope.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[radar\nf_c_hz = 1")
    with pytest.raises(SceneError, match="not valid TOML"):
        load_scene(bad)


def test_cli_info_and_bad_scene(tmp_path, capsys):
    from rtsgeom.cli import main
    assert main(["info", str(DEFAULT_SCENE)]) == 0
    out = capsys.readouterr().out
    assert "17.48 deg" in out and "1.0000 ns" in out
    bad = tmp_path / "bad.toml"
    bad.write_text(DEFAULT_SCENE.read_text().replace("arc_radius_m = 1.0", "arc_radius_m = -1.0"))
    assert main(["info", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "rts.arc_radius_m" in err and "Traceback" not in err


# --------------------------------------------------------------------------------------------
# The schema is written once
# --------------------------------------------------------------------------------------------


def test_scene_format_doc_is_generated_from_the_declarations():
    """docs/scene-format.md is what ``python -m rtsgeom.scene.docs`` writes; every key is in it."""
    import rtsgeom.scene as sc
    from rtsgeom.scene.docs import DOC_PATH, render
    from rtsgeom.scene.schema import specs
    text = render()
    assert DOC_PATH.read_text() == text, "run `python -m rtsgeom.scene.docs` and commit the file"
    for cls in (sc.Scene, sc.RadarConfig, sc.CfarConfig, sc.RtsConfig, sc.FrontEndConfig,
                sc.SheetConfig, sc.TargetConfig, sc.RaytraceConfig, sc.StructureConfig):
        for _, s in specs(cls):
            assert f"| `{s.key}` |" in text, s.key


def test_cli_choices_are_the_registries():
    import argparse
    from rtsgeom.cli import build_parser
    from rtsgeom.scene.registry import AOA_MODES, PATH_METHODS, SYNTHESIS_MODES
    found = {}

    def walk(p, name=""):
        for a in p._actions:
            if isinstance(a, argparse._SubParsersAction):
                for sub, sp in a.choices.items():
                    walk(sp, sub)
            elif a.choices is not None:
                found[(name, a.dest)] = tuple(a.choices)
    walk(build_parser())
    expect = {("run", "paths"): tuple(PATH_METHODS), ("show", "paths"): tuple(PATH_METHODS),
              ("paths", "method"): tuple(PATH_METHODS), ("run", "amplitudes"): tuple(AOA_MODES),
              ("adc", "amplitudes"): tuple(AOA_MODES),
              ("linearity", "amplitudes"): SYNTHESIS_MODES}
    for k, v in expect.items():
        assert found[k] == v, (k, found[k])
    from rtsgeom.synthesis.model import SOLVERS
    assert SOLVERS == SYNTHESIS_MODES


def test_defaults_written_once_match_the_dataclasses(default_scene):
    """A scene that sets only the required keys gets each declared default (converted to SI)."""
    from rtsgeom.scene import CfarConfig, FrontEndConfig, RaytraceConfig, SheetConfig
    doc = {"radar": {k: default_doc()["radar"][k] for k in (
        "f_c_hz", "bandwidth_hz", "chirp_duration_s", "samples_per_chirp", "adc_rate_hz",
        "chirps_per_tx")},
           "rts": {"arc_radius_m": 1.0, "f_rts_hz": 5e8, "f_s_hz": 4e9,
                   "front_ends": [{"angle_deg": 3.4}, {"angle_deg": 12.2}]}}
    s = parse_scene(doc, "min.toml")
    assert s.sheet == SheetConfig() and s.raytrace == RaytraceConfig()
    assert s.radar.cfar == CfarConfig()
    assert s.rts.front_ends[0] == FrontEndConfig(angle_rad=default_scene.rts.front_ends[0].angle_rad)
    assert s.sheet.angle_min_rad == __import__("math").radians(-15.0)
    assert s.radar.chirp_repetition_s == s.radar.chirp_duration_s
    assert s.name == "min" and s.targets == () and s.rts.arc_center_m is None


def test_evolve_validates_again(default_scene):
    s = default_scene
    v = s.evolve(rts=s.rts.evolve(arc_radius_m=1.5))
    assert v.rts.arc_radius_m == 1.5 and v.targets == s.targets
    with pytest.raises(SceneError, match=r"arc_radius_m = -1: must be in \[0.05, 100\] m"):
        s.rts.evolve(arc_radius_m=-1.0)
    with pytest.raises(SceneError, match=r"angle_deg = 95: must be in \[-90, 90\] deg"):
        s.rts.front_ends[0].evolve(angle_rad=__import__("math").radians(95.0))
    with pytest.raises(SceneError, match=r"diewald2022.toml: targets\[0\]\.range_m = 0.5: "
                                         r"must be > rts.arc_radius_m"):
        s.evolve(targets=(s.targets[0].evolve(range_m=0.5),))
    with pytest.raises(SceneError, match=r"radar\.chirps_per_tx = 4: must be >= 13: "):
        s.evolve(radar=s.radar.evolve(chirps_per_tx=4))


def test_derive_is_not_checked_again_and_the_nominal_scene_names_no_derived_value(default_scene):
    """A variant the package derives (``derive``) is not read through the file's schema again:
    the nominal scene of a scene carrying a derived value outside the file's range (a reference
    step's 447.8 deg phase, a noise level) raised '<evolve>: ... = 447.803', a field nobody
    wrote. ``evolve``, for values a user sets in code, still checks."""
    import math
    from rtsgeom.geometry.setup import nominal_scene
    s = default_scene
    fe = s.rts.front_ends[1].derive(phase_offset_rad=math.radians(447.803))
    assert fe.phase_offset_rad == math.radians(447.803)
    with pytest.raises(SceneError, match="phase_offset_deg = 447.803"):
        s.rts.front_ends[1].evolve(phase_offset_rad=math.radians(447.803))
    fes = list(s.rts.front_ends)
    fes[0] = fes[0].derive(radial_offset_m=0.002)
    fes[1] = fes[1].derive(gain_offset_db=200.0)  # out of the file's range, derived
    radar = s.radar.derive(yaw_offset_rad=math.radians(1.0), snr_db=-500.0)
    derived = s.derive(rts=s.rts.derive(front_ends=tuple(fes)), radar=radar)
    nominal = nominal_scene(derived)
    assert nominal.rts.front_ends[0].radial_offset_m == 0.0
    assert nominal.radar.yaw_offset_rad == 0.0 and nominal.radar.snr_db == -500.0


def test_problems_lists_every_violated_rule(default_scene):
    from rtsgeom.scene.rules import problems
    assert problems(default_scene) == []
    s = dataclasses_replace(default_scene, targets=(
        default_scene.targets[0].__class__(range_m=0.5), default_scene.targets[1].__class__(
            range_m=30.0, velocity_mps=9.5)))
    found = problems(s)
    assert len(found) == 2 and "targets[0].range_m" in found[0] and "targets[1].velocity_mps" in found[1]
    doc = copy.deepcopy(default_doc())
    doc["targets"][0]["range_m"] = 0.5
    doc["targets"][1]["velocity_mps"] = 9.5
    with pytest.raises(SceneError) as err:
        parse_scene(doc, "p.toml")
    assert len(err.value.problems) == 2 and str(err.value) == err.value.problems[0]


def dataclasses_replace(obj, **kw):
    import dataclasses
    return dataclasses.replace(obj, **kw)


@pytest.mark.parametrize("radius", [0.3, 1.0, 4.0])
@pytest.mark.parametrize("offsets_mm", [(0, 0, 0), (3, -2, 5), (-40, 30, -10)])
def test_scene_module_positions_are_the_geometry_formula(radius, offsets_mm):
    """One formula: the scene's rules see the modules where geometry builds them."""
    import numpy as np
    from rtsgeom.geometry import build_setup
    from rtsgeom.scene.rules import arc_centre_m, front_end_module_m
    doc = copy.deepcopy(default_doc())
    doc["rts"]["arc_radius_m"] = radius
    doc["sheet"]["enabled"] = False
    doc["targets"] = []
    for fe in doc["rts"]["front_ends"]:
        fe.update(radial_offset_mm=offsets_mm[0], tangential_offset_mm=offsets_mm[1],
                  height_offset_mm=offsets_mm[2])
    s = parse_scene(doc, "g.toml")
    setup = build_setup(s)
    mods = [front_end_module_m(arc_centre_m(s), radius, fe) for fe in s.rts.front_ends]
    np.testing.assert_allclose(mods, setup.fe.module, rtol=0, atol=1e-15)


def test_design_filters_candidates_with_the_scene_rules(default_scene):
    import math
    from rtsgeom.analysis.design import two_front_end_scene
    from rtsgeom.scene.rules import problems
    for radius, spacing in ((1.0, 8.0), (0.3, 8.0), (0.06, 60.0), (2.0, 179.0)):
        variant, _, problem = two_front_end_scene(default_scene, (0, 1), radius,
                                                  math.radians(spacing))
        found = problems(variant)
        assert problem == (found[0] if found else None)
        assert problem is None or " must be " in problem
