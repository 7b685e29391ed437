"""Scene loading and validation: clear errors that name the field."""

from __future__ import annotations

import copy

import pytest

from rtsgeom.scene import SceneError, load_scene, parse_scene

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
