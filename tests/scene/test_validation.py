"""Validation at every edge: malformed scenes, hostile files, CLI exit codes, warnings.

Every malformed scene is the default scene's TOML document with one mistake; the error must be a
:class:`SceneError` whose message names the file, the field and (where there is one) the value.
The same documents written to disk must make ``rtsgeom info`` exit 2 without a traceback.
"""

from __future__ import annotations

import copy
import datetime as dt
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from rtsgeom.cli import main
from rtsgeom.cli._common import number
from rtsgeom.scene.registry import RADAR_PRESETS
from rtsgeom.errors import SceneError
from rtsgeom.scene import TargetConfig, load_scene, loads_scene, parse_scene
from rtsgeom.geometry.warnings import scene_warnings

from conftest import DEFAULT_SCENE, ROOT, default_doc


# --------------------------------------------------------------------------------------------
# A minimal TOML writer (inline tables), enough to put any mutated document on disk
# --------------------------------------------------------------------------------------------


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v).replace("\x7f", "\\u007f")
    if isinstance(v, (dt.datetime, dt.date, dt.time)):
        return v.isoformat()
    if isinstance(v, list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{json.dumps(k)} = {_toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(type(v))


def dump_toml(doc: dict) -> str:
    """One ``key = value`` line per top-level key; tables and arrays of tables inline."""
    return "".join(f"{json.dumps(k)} = {_toml_value(v)}\n" for k, v in doc.items())


def test_dump_toml_round_trips_the_default_scene():
    import tomllib
    doc = default_doc()
    assert tomllib.loads(dump_toml(doc)) == doc
    odd = {"x": [math.inf, -0.0, 10**30, "a\x7f\n\"b", dt.date(2020, 1, 2)]}
    back = tomllib.loads(dump_toml(odd))["x"]
    assert back[0] == math.inf and math.copysign(1, back[1]) < 0 and back[2:] == odd["x"][2:]


# --------------------------------------------------------------------------------------------
# Malformed scenes: one mistake each, the message names the field
# --------------------------------------------------------------------------------------------


def _set(path: str, value):
    """A mutation setting ``doc[a][b][i]...`` (dotted path; integers index arrays)."""
    keys = [int(k) if k.isdigit() else k for k in path.split(".")]

    def mutate(doc):
        node = doc
        for k in keys[:-1]:
            node = node[k]
        node[keys[-1]] = value
    return mutate


def _pop(path: str):
    keys = [int(k) if k.isdigit() else k for k in path.split(".")]

    def mutate(doc):
        node = doc
        for k in keys[:-1]:
            node = node[k]
        del node[keys[-1]]
    return mutate


def _all(*mutations):
    def mutate(doc):
        for m in mutations:
            m(doc)
    return mutate


def _many_front_ends(doc):
    doc["sheet"]["enabled"] = False
    doc["targets"] = []
    doc["rts"]["front_ends"] = [{"angle_deg": -80 + 0.5 * i} for i in range(300)]


def _big_adc_cube(doc):
    doc["radar"].update(samples_per_chirp=8192, adc_rate_hz=250e6, chirps_per_tx=4096)


# (id, mutation, field named in the message, text of the value in the message or None)
MALFORMED = [
    ("string for a number", _set("radar.f_c_hz", "77e9"), "radar.f_c_hz", "'77e9'"),
    ("nan", _set("radar.bandwidth_hz", math.nan), "radar.bandwidth_hz", "nan"),
    ("inf", _set("radar.adc_rate_hz", math.inf), "radar.adc_rate_hz", "inf"),
    ("huge integer", _set("radar.samples_per_chirp", 10**30), "radar.samples_per_chirp", "1000"),
    ("integer beyond float", _set("radar.chirp_duration_s", 10**400), "radar.chirp_duration_s",
     None),
    ("date for a number", _set("radar.f_c_hz", dt.date(2022, 1, 1)), "radar.f_c_hz", "2022"),
    ("bool for a number", _set("rts.front_ends.0.angle_deg", True),
     "rts.front_ends[0].angle_deg", "True"),
    ("vector of two", _set("radar.position_m", [0.0, 0.0]), "radar.position_m", "[0.0, 0.0]"),
    ("yaw out of range", _set("radar.yaw_deg", 120.0), "radar.yaw_deg", "120"),
    ("unknown CFAR", _set("radar.cfar.kind", "xx"), "radar.cfar.kind", "'xx'"),
    ("fractional guard cells", _set("radar.cfar.guard_cells", [1.5, 2]),
     "radar.cfar.guard_cells", "1.5"),
    ("chirp repeats before it ends", _set("radar.chirp_repetition_s", 40e-6),
     "radar.chirp_repetition_s", "4e-05"),
    ("SNR as text", _set("radar.snr_db", "high"), "radar.snr_db", "'high'"),
    ("negative zero radius", _set("rts.arc_radius_m", -0.0), "rts.arc_radius_m", "-0"),
    ("no front ends", _set("rts.front_ends", []), "rts.front_ends", None),
    ("too many front ends", _many_front_ends, "rts.front_ends", "300 front ends"),
    ("front ends out of order", _set("rts.front_ends.1.angle_deg", 1.0), "rts.front_ends",
     "[3.4, 1.0]"),
    ("front end outside the sheet", _set("rts.front_ends.1.angle_deg", 29.0),
     "rts.front_ends[1].angle_deg", "29"),
    ("antennas wider than the cutout", _set("rts.front_ends.0.rx_tx_separation_m", 0.06),
     "rts.front_ends[0].rx_tx_separation_m", "0.06"),
    ("RuT outside the arc", _set("rts.arc_center_m", [0.0, -1.5, 0.0]), "radar.position_m",
     "[0.0, 0.0, 0.0]"),
    ("RuT looking away (yaw)", _set("radar.yaw_deg", -85.0), "rts.front_ends[1].angle_deg",
     "12.2"),
    ("front end behind the RuT", _all(
        _set("sheet.enabled", False), _set("rts.arc_center_m", [0.0, 0.0, 0.0]),
        _set("radar.position_m", [0.0, 0.5, 0.0]), _set("rts.front_ends.0.angle_deg", 40.0),
        _set("rts.front_ends.1.angle_deg", 85.0)), "rts.front_ends[1].angle_deg", "85"),
    ("sheet inside the RuT's position", _all(
        _set("rts.arc_center_m", [0.0, -0.52, 0.0]), _set("sheet.radius_offset_m", -0.5)),
     "radar.position_m", "inner radius"),
    ("no fractional delay for 25 ps steps", _set("rts.fractional_delay", False),
     "rts.calibration_step_ps", "25"),
    ("fractional delay step coarser than the calibration step",
     _set("rts.fractional_delay_step_s", 50e-12), "rts.calibration_step_ps", "25"),
    ("calibration span shorter than a period", _set("rts.calibration_span_ns", [0.0, 0.5]),
     "rts.calibration_span_ns", "[0.0, 0.5]"),
    ("zero IF with the default calibration sweep", _set("rts.f_rts_hz", 0.0),
     "rts.f_rts_hz", "1.66667e+08"),
    ("back end sampling slower than the chirp's bandwidth", _set("rts.f_s_hz", 1e6),
     "rts.f_s_hz", "1e+06"),
    ("calibration span reversed", _set("rts.calibration_span_ns", [1.0, 0.0]),
     "rts.calibration_span_ns", "[1.0, 0.0]"),
    ("calibration with a million steps", _all(
        _set("rts.calibration_span_ns", [-500.0, 500.0]), _set("rts.calibration_step_ps", 1.0)),
     "rts.calibration_step_ps", "1"),
    ("ADC cube of 268 M samples", _big_adc_cube, "radar.chirps_per_tx", "4096"),
    ("target beyond the unambiguous range", _set("targets.3.range_m", 78.0),
     "targets[3].range_m", "78"),
    ("uncompensated air path pushes a target out", _all(
        _set("rts.compensate_air_path", False), _set("targets.3.range_m", 77.0)),
     "targets[3].range_m", "77"),
    ("target faster than the unambiguous velocity", _set("targets.1.velocity_mps", 40.0),
     "targets[1].velocity_mps", "40"),
    ("target inside the arc", _set("targets.0.range_m", 0.5), "targets[0].range_m", "0.5"),
    ("sheet extent reversed", _set("sheet.angle_max_deg", -20.0), "sheet.angle_max_deg", "-20"),
    ("cutout taller than the sheet", _set("sheet.height_m", 0.04), "sheet.cutout_diameter_m",
     "0.05"),
    ("sheet radius below 5 cm", _all(_set("rts.arc_radius_m", 0.1),
                                     _set("sheet.radius_offset_m", -0.06)),
     "sheet.radius_offset_m", "-0.06"),
    ("material with punctuation", _set("sheet.material", "metal; rm -rf /"), "sheet.material",
     "'metal; rm -rf /'"),
    ("name too long", _set("name", "x" * 5000), "name", "xxxx...xxxx"),
    ("name with a newline", _set("name", "a\nb"), "name", "'a\\nb'"),
    ("empty name", _set("name", "  "), "name", None),
    ("description too long", _set("description", "y" * 20_000), "description", None),
    ("unknown top-level key", _set("radr", {}), "radr", None),
    ("misspelt field", _set("rts.arc_radius", 1.0), "rts.arc_radius", None),
    ("missing required field", _pop("radar.f_c_hz"), "radar.f_c_hz", None),
    ("missing section", _pop("rts"), "rts", None),
    ("section is an array", _set("radar", [1, 2, 3]), "radar", "[1, 2, 3]"),
    ("targets as one table", _set("targets", {"range_m": 10.0}), "targets", None),
    ("nested garbage", _set("raytrace", {"max_depth": [[[[{"a": [1]}]]]]}), "raytrace.max_depth",
     None),
    ("raytrace depth", _set("raytrace.max_depth", 11), "raytrace.max_depth", "11"),
    ("negative seed", _set("seed", -1), "seed", "-1"),
    ("mesh that does not exist", _set("structure", [{"mesh": "nope.stl"}]), "structure[0].mesh",
     "'nope.stl'"),
    ("mesh path too long", _set("structure", [{"mesh": "a/" * 3000 + "m.stl"}]),
     "structure[0].mesh", None),
]


def _mutated(mutate) -> dict:
    doc = copy.deepcopy(default_doc())
    mutate(doc)
    return doc


@pytest.mark.parametrize("label,mutate,field,value", MALFORMED, ids=[m[0] for m in MALFORMED])
def test_malformed_scene_names_file_field_and_value(label, mutate, field, value):
    with pytest.raises(SceneError) as err:
        parse_scene(_mutated(mutate), "bad.toml", base_dir=ROOT)
    msg = str(err.value)
    assert msg.startswith("bad.toml: "), msg
    assert field in msg, msg
    if value is not None:
        assert f"{field} = " in msg and value in msg, msg
    assert len(msg) < 1000  # huge values are abbreviated
    assert any(w in msg for w in ("must be", "is missing", "is not a known field")), msg


def test_at_least_twenty_distinct_mistakes():
    assert len({m[2] for m in MALFORMED}) >= 20


def test_specific_messages_explain_what_is_allowed():
    def msg(mutate):
        with pytest.raises(SceneError) as err:
            parse_scene(_mutated(mutate), "bad.toml")
        return str(err.value)
    m = msg(_set("rts.fractional_delay", False))
    assert "rts.fractional_delay = false" in m and "250 ps" in m
    m = msg(_set("rts.calibration_span_ns", [0.0, 0.5]))
    assert "1 ns" in m and "rts.f_rts_hz" in m
    m = msg(_set("rts.arc_center_m", [0.0, -1.5, 0.0]))
    assert "rts.arc_center_m" in m and "rts.arc_radius_m = 1 m" in m and "1.5 m away" in m
    m = msg(_set("radar.yaw_deg", -85.0))
    assert "radar.yaw_deg = -85" in m and "(-90, 90)" in m
    m = msg(_all(_set("rts.compensate_air_path", False), _set("targets.3.range_m", 77.0)))
    assert "air path 1 m" in m and "rts.compensate_air_path = false" in m


def test_relative_mesh_paths_resolve_against_the_scene_folder(tmp_path, monkeypatch):
    folder = tmp_path / "scenes"
    (folder / "meshes").mkdir(parents=True)
    (folder / "meshes" / "wall.stl").write_text("solid wall\nendsolid wall\n")
    doc = default_doc()
    doc["structure"] = [{"mesh": "meshes/wall.stl", "material": "itu_concrete"}]
    path = folder / "room.toml"
    path.write_text(dump_toml(doc))
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)  # the working directory must not matter
    scene = load_scene(os.path.relpath(path, elsewhere))
    assert scene.extra_meshes == ((str((folder / "meshes" / "wall.stl").resolve()),
                                   "itu_concrete", 0.0),)  # (path, material, reflection loss dB)
    # ...and the same relative path next to a scene in another folder is an error
    other = tmp_path / "other.toml"
    other.write_text(dump_toml(doc))
    with pytest.raises(SceneError, match=r"structure\[0\]\.mesh = 'meshes/wall.stl'"):
        load_scene(other)


# --------------------------------------------------------------------------------------------
# Hostile files
# --------------------------------------------------------------------------------------------


def _hostile_files(tmp_path: Path) -> dict[str, tuple[Path, str]]:
    """name -> (path, text the error must contain)"""
    text = DEFAULT_SCENE.read_text()
    files = {
        "directory": (tmp_path, "directory"),
        "missing": (tmp_path / "nope.toml", "cannot read"),
        "binary": (b"\x89PNG\r\n\x1a\n\x00\x00\xff\xfe", "not UTF-8"),
        "NUL byte": (b"name = \"a\x00b\"\n", "not valid TOML"),
        "empty": (b"", "radar is missing"),
        "only a comment": (b"# nothing\n", "radar is missing"),
        "top-level array": (b"[1, 2, 3]\n", "not valid TOML"),
        "top-level value": (b"= 3\n", "not valid TOML"),
        "4300+ digit integer": (text.replace("seed = 2022", "seed = " + "9" * 5000).encode(),
                                "not valid TOML"),
        "deeply nested array": (b"x = " + b"[" * 10_000 + b"]" * 10_000, "not valid TOML"),
        "1e999": (text.replace("f_c_hz = 77e9", "f_c_hz = 1e999").encode(), "radar.f_c_hz"),
        "nan": (text.replace("bandwidth_hz = 1e9", "bandwidth_hz = nan").encode(),
                "radar.bandwidth_hz"),
        "-inf": (text.replace("f_s_hz = 4e9", "f_s_hz = -inf").encode(), "rts.f_s_hz"),
        "long string": (text.replace('name = "diewald2022"', 'name = "' + "z" * 200_000 + '"')
                        .encode(), "name = 'zzz"),
        "too large": (b"# " + b"x" * (5 << 20), "too large"),
        "duplicate key": (text.replace("seed = 2022", "seed = 2022\nseed = 1").encode(),
                          "not valid TOML"),
        "table as value": (b"radar = 5\n" + text.split("[radar]", 1)[1].split("[rts]")[0]
                           .encode(), "not valid TOML"),
    }
    out = {}
    for name, (content, expect) in files.items():
        if isinstance(content, bytes):
            p = tmp_path / f"{name.replace(' ', '_')}.toml"
            p.write_bytes(content)
            content = p
        out[name] = (content, expect)
    return out


def test_hostile_files_give_a_scene_error(tmp_path):
    for name, (path, expect) in _hostile_files(tmp_path).items():
        with pytest.raises(SceneError) as err:
            load_scene(path)
        assert expect in str(err.value), (name, str(err.value)[:300])
        assert len(str(err.value)) < 1000, name


def test_documents_that_are_not_tables():
    for data in ([1, 2, 3], "radar", 3.0, None):
        with pytest.raises(SceneError, match=r"^x\.toml: <top level> = .*must be a table"):
            parse_scene(data, "x.toml")


def test_negative_zero_is_zero_where_legal(default_scene):
    from rtsgeom.geometry import build_setup
    doc = default_doc()
    doc["radar"].update(yaw_deg=-0.0, position_m=[-0.0, -0.0, -0.0])
    doc["targets"][0]["velocity_mps"] = -0.0
    scene = parse_scene(doc, "z.toml")
    assert scene.radar.yaw_rad == 0.0 and scene.targets[0].velocity_mps == 0.0
    assert build_setup(scene).fe_azimuth_rad().tolist() == \
        build_setup(default_scene).fe_azimuth_rad().tolist()


def test_special_files_and_byte_order_mark(tmp_path):
    with pytest.raises(SceneError, match="not a regular file"):
        load_scene("/dev/null")
    with pytest.raises(SceneError, match="cannot read"):
        load_scene("a\x00b.toml")
    bom = tmp_path / "bom.toml"
    bom.write_bytes(b"\xef\xbb\xbf" + DEFAULT_SCENE.read_bytes())
    assert load_scene(bom).name == "diewald2022"
    with pytest.raises(SceneError, match="not UTF-8"):
        loads_scene("name = '\udc80'")


# --------------------------------------------------------------------------------------------
# The CLI: exit code 2, one line, no traceback
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("label,mutate,field,value", MALFORMED, ids=[m[0] for m in MALFORMED])
def test_cli_rejects_malformed_scene_with_exit_2(label, mutate, field, value, tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text(dump_toml(_mutated(mutate)))
    assert main(["info", str(path)]) == 2
    cap = capsys.readouterr()
    assert cap.out == ""
    assert cap.err.startswith(f"rtsgeom: error: {path}: ") and field in cap.err
    assert "Traceback" not in cap.err


def test_cli_rejects_hostile_files_with_exit_2(tmp_path, capsys):
    for name, (path, _) in _hostile_files(tmp_path).items():
        assert main(["info", str(path)]) == 2, name
        err = capsys.readouterr().err
        assert err.startswith("rtsgeom: error: ") and "Traceback" not in err, name


def _run_cli(*args, cwd=None):
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    return subprocess.run([sys.executable, "-m", "rtsgeom", *args], capture_output=True,
                          text=True, cwd=cwd, env=env, timeout=120)


@pytest.mark.subprocess
def test_cli_subprocess_exit_codes(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(dump_toml(_mutated(_set("rts.fractional_delay", False))))
    binary = tmp_path / "binary.toml"
    binary.write_bytes(bytes(range(256)))
    for args, field in (((str(bad),), "rts.calibration_step_ps"),
                        ((str(binary),), "not UTF-8"),
                        ((str(tmp_path),), "directory")):
        r = _run_cli("info", *args)
        assert r.returncode == 2, r.stderr
        assert "Traceback" not in r.stderr and field in r.stderr
        assert r.stderr.count("\n") == 1  # one line
    # an unwritable output path is bad input too
    r = _run_cli("paths", str(DEFAULT_SCENE), "--out", str(binary / "x.csv"))
    assert r.returncode == 2 and "Traceback" not in r.stderr and "x.csv" not in r.stdout
    # argument errors: one line (not argparse's usage block), exit 2
    r = _run_cli("info")
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert r.stderr.startswith("rtsgeom: error: info: ") and r.stderr.count("\n") == 1


def test_cli_prints_warnings_to_stderr_and_goes_on(tmp_path, capsys):
    doc = default_doc()
    del doc["radar"]["snr_db"]
    doc["targets"][0]["angle_deg"] = 30.0
    path = tmp_path / "doubtful.toml"
    path.write_text(dump_toml(doc))
    assert main(["info", str(path)]) == 0
    cap = capsys.readouterr()
    lines = cap.err.splitlines()
    assert len(lines) == 2 and all(ln.startswith(f"rtsgeom: warning: {path}: ") for ln in lines)
    assert "radar.snr_db" in cap.err and "targets[0].angle_deg = 30" in cap.err
    assert cap.out.startswith("scene diewald2022")
    assert main(["info", str(DEFAULT_SCENE)]) == 0
    assert capsys.readouterr().err == ""  # the default scene is clean


@pytest.mark.parametrize("argv", [
    ["info"], ["info", "a.toml", "--jsn"], ["nope"], [], ["paths", "a.toml"],
    ["paths", "a.toml", "--out", "x.csv", "--method", "magic"], ["--bogus"],
])
def test_cli_argument_errors_exit_2(argv, capsys):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    assert "Traceback" not in capsys.readouterr().err


@pytest.mark.parametrize("text", ["abc", "nan", "inf", "-inf", "1e999", "11", "-1", "",
                                  "9" * 5000, "0x10", "1.5"])
def test_bad_numbers_exit_2(text, capsys):
    import argparse
    ap = argparse.ArgumentParser(prog="t")
    ap.add_argument("--x", type=number(0, 10))
    ap.add_argument("--n", type=number(0, 10, integer=True))
    for opt in ("--x", "--n"):
        if opt == "--x" and text == "1.5":
            continue  # a valid number
        with pytest.raises(SystemExit) as exc:
            ap.parse_args([opt, text])
        assert exc.value.code == 2
        err = capsys.readouterr().err
        assert "usage:" in err and "Traceback" not in err


# --------------------------------------------------------------------------------------------
# Warnings
# --------------------------------------------------------------------------------------------


WARNINGS = [
    # (forced: synthesis between front ends this far apart is refused, see test_scene_rules)
    ("front ends wider apart than the resolution", _all(
        _set("rts.front_ends.1.angle_deg", 25.0), _set("rts.allow_wide_spacing", True)),
     "rts.front_ends[1].angle_deg = 25", "17.48 deg"),
    ("arc inside the Fraunhofer distance", _all(
        _set("rts.arc_radius_m", 0.1), _set("sheet.enabled", False), _set("targets", [])),
     "rts.arc_radius_m = 0.1", "Fraunhofer"),
    ("target outside the front ends' span", _set("targets.2.angle_deg", -5.0),
     "targets[2].angle_deg = -5", "[3.4, 12.2]"),
    ("mounting offset above lambda/4", _set("rts.front_ends.0.radial_offset_mm", 1.5),
     "rts.front_ends[0].radial_offset_mm = 1.5", "lambda/4"),
    ("antenna behind metal", _set("rts.front_ends.0.height_offset_mm", 30.0),
     "rts.front_ends[0].height_offset_mm = 30", "through the sheet"),
    ("noiseless", _pop("radar.snr_db"), "radar.snr_db is not set", "noiseless"),
    ("grating lobes", _set("radar.element_spacing_m", 0.003), "radar.element_spacing_m = 0.003",
     "grating lobes"),
    ("IF above the back end's Nyquist", _set("rts.f_s_hz", 1.5e9), "rts.f_rts_hz = 5e+08",
     "Nyquist"),
    ("uneven calibration steps", _set("rts.calibration_step_ps", 2.5),
     "rts.calibration_step_ps = 2.5", "whole multiple"),
]


@pytest.mark.parametrize("label,mutate,head,text", WARNINGS, ids=[w[0] for w in WARNINGS])
def test_scene_warnings(label, mutate, head, text):
    scene = parse_scene(_mutated(mutate), "w.toml")
    found = [w for w in scene_warnings(scene) if w.startswith(f"w.toml: {head}") and text in w]
    assert len(found) == 1, scene_warnings(scene)


def test_default_scene_has_no_warnings(default_scene):
    assert scene_warnings(default_scene) == []


@pytest.mark.subprocess
def test_cli_output_into_a_closed_pipe_stops_quietly():
    # `rtsgeom ... | head`: the reader closes the pipe before the CLI writes
    import subprocess
    import sys
    p = subprocess.Popen([sys.executable, "-m", "rtsgeom", "info", str(DEFAULT_SCENE), "--json"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=ROOT)
    p.stdout.close()
    err = p.stderr.read().decode()
    assert p.wait(timeout=60) == 0
    assert "Broken pipe" not in err and "Traceback" not in err


# --------------------------------------------------------------------------------------------
# No hang, the right field blamed, limits that the processing resolves
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("shape", ["{k} = 1\n", "[{k}]\nx = 1\n", "x = {{{k} = 1}}\n",
                                   '{q} = 1\n'])
def test_deeply_dotted_keys_are_refused_before_parsing(shape):
    """tomllib is quadratic in a key's dotted parts (5000 parts: seconds; 200 000: minutes)."""
    import time
    parts = ["a"] * 5000
    text = shape.format(k=".".join(parts), q=".".join(['"a"'] * 5000))
    t0 = time.perf_counter()
    with pytest.raises(SceneError, match=r"^k\.toml: line 1: a key of more than 16 dotted parts"):
        loads_scene(text, "k.toml")
    assert time.perf_counter() - t0 < 1.0


def test_dotted_keys_of_a_legal_depth_and_floats_still_load(default_scene):
    text = DEFAULT_SCENE.read_text().replace("[radar.cfar]\n", "[radar . cfar]\n")
    assert loads_scene(text, "d.toml").radar.cfar == default_scene.radar.cfar
    long = "x = [" + ", ".join(["1.5"] * 20000) + "]\n"  # many dots in values are not keys
    with pytest.raises(SceneError, match="x is not a known field"):
        loads_scene(DEFAULT_SCENE.read_text().replace("seed = 2022", "seed = 2022\n" + long))


def test_integer_field_shows_the_float_as_written():
    m = _msg(_set("radar.samples_per_chirp", 512.0))
    assert "radar.samples_per_chirp = 512.0: must be an integer" in m, m


def test_a_typo_names_the_unknown_key_and_the_missing_one():
    def typo(d):
        d["rts"]["arc_radus_m"] = d["rts"].pop("arc_radius_m")
    m = _msg(typo)
    assert "rts.arc_radus_m is not a known field" in m and "did you mean arc_radius_m?" in m, m
    assert "rts.arc_radius_m is missing" in m, m


def _msg(mutate) -> str:
    with pytest.raises(SceneError) as err:
        parse_scene(_mutated(mutate), "m.toml")
    return str(err.value)


@pytest.mark.parametrize("window", ["none", "hann", "blackman"])
@pytest.mark.parametrize("guard,training", [((2, 2), (8, 4)), ((0, 1), (1, 1)), ((4, 3), (16, 9))])
def test_map_axes_must_hold_the_cfar_window(window, guard, training):
    """The smallest accepted samples_per_chirp / chirps_per_tx hold the CFAR window 2 (guard +
    training) + 1 cells and room for a target away from the edges, and a target at 0 m/s in the middle of the map is found there; one
    cell less is refused naming that field (not, later, 'blocked line of sight')."""
    from rtsgeom.pipeline.run import run_scene

    def base(d):
        d["radar"].update(range_window=window, doppler_window=window)
        d["radar"]["cfar"].update(guard_cells=list(guard), training_cells=list(training))
        d["targets"] = []
    for ax, key in ((0, "samples_per_chirp"), (1, "chirps_per_tx")):
        from rtsgeom.scene.registry import WINDOWS
        ml = WINDOWS[window].mainlobe_half_bins
        edge = ml + guard[ax] + training[ax] + 1 if ax == 0 else 2 * (ml + 1) + 1
        need = max(16 if ax == 0 else 2, 2 * (guard[ax] + training[ax]) + 1, edge)
        ok = _mutated(_all(base, _set(f"radar.{key}", need)))
        s = parse_scene(ok, "c.toml")
        assert getattr(s.radar, key) == need
        if ax == 1 and window == "hann" and guard == (2, 2):  # the chain works at the minimum
            s = s.evolve(targets=(TargetConfig(20.0, 0.0, 10.0, s.rts.front_ends[0].angle_rad),),
                         rts=s.rts.evolve(aoa_mode="nearest"))
            det = run_scene(s, "exact", "nearest").detections
            assert np.any(np.abs(det.range_m - 20.0) < 2 * s.radar.range_resolution_m), det
        if need - 1 >= (16 if ax == 0 else 2):
            m = _msg(_all(base, _set(f"radar.{key}", need - 1)))
            assert ("radar.cfar.training_cells" in m or f"radar.{key} = {need - 1}: must be >= "
                    f"{need}" in m), m
            assert "CFAR window" in m


@pytest.mark.parametrize("key,value", [("chirps_per_tx", 2), ("samples_per_chirp", 16)])
def test_too_short_axes_blame_the_axis(key, value):
    m = _msg(_set(f"radar.{key}", value))
    assert m.startswith(f"m.toml: radar.{key} = {value}: must be >="), m


def test_training_cells_bounded_by_the_map():
    m = _msg(_set("radar.cfar.training_cells", [256, 4]))
    assert m.startswith("m.toml: radar.cfar.training_cells = [256, 4]: must be smaller"), m


def test_adc_size_limit_bounds_memory():
    """2^25 complex64 samples pass (about 2 GiB peak), one chirp loop more does not."""
    from rtsgeom.scene.rules import MAX_ADC_SAMPLES
    big = dict(samples_per_chirp=8192, adc_rate_hz=250e6)
    n_l = MAX_ADC_SAMPLES // (8192 * 8)
    s = parse_scene(_mutated(lambda d: d["radar"].update(big, chirps_per_tx=n_l)), "a.toml")
    assert s.radar.samples_per_chirp * s.radar.chirps_per_tx * 8 <= MAX_ADC_SAMPLES
    m = _msg(lambda d: d["radar"].update(big, chirps_per_tx=n_l + 1))
    assert f"radar.chirps_per_tx = {n_l + 1}: must be <= {n_l}" in m and "GiB" in m, m


@pytest.mark.parametrize("window,training", [("hann", (8, 4)), ("none", (2, 1)),
                                             ("blackman", (20, 10)), ("none", (20, 10)),
                                             ("blackman", (2, 1))])
def test_edge_targets_are_refused_or_resolved(window, training):
    """Just inside the accepted range / velocity limits a target is detected where it was set;
    just beyond them the loader refuses, naming the field and the limit (before the fix such
    targets wrapped to ~0 m or to the negative maximum velocity, silently)."""
    from rtsgeom.pipeline.run import run_scene
    from rtsgeom.scene.rules import resolvable_limits

    def base(d):
        d["radar"].update(range_window=window, doppler_window=window, snr_db=30.0)
        d["radar"]["cfar"]["training_cells"] = list(training)
        d["rts"]["aoa_mode"] = "nearest"
        d["targets"] = [dict(range_m=20.0, velocity_mps=0.0, angle_deg=3.4)]
    radar = parse_scene(_mutated(base), "e.toml").radar
    r_lim, v_lim, _, _ = resolvable_limits(radar)
    assert 0.8 * radar.max_range_m < r_lim < radar.max_range_m
    assert 0.5 * radar.max_velocity_mps < v_lim < radar.max_velocity_mps
    m = _msg(_all(base, _set("targets.0.range_m", r_lim + 0.01)))
    assert "targets[0].range_m" in m and "unambiguous range" in m and "range bins" in m, m
    m = _msg(_all(base, _set("targets.0.velocity_mps", -(v_lim + 0.01))))
    assert "targets[0].velocity_mps" in m and "Doppler bins" in m, m
    r_in = r_lim - radar.range_resolution_m  # the air path is compensated to ~0 here
    v_in = 0.98 * v_lim
    for rng, vel in ((r_in, 0.0), (20.0, v_in), (20.0, -v_in)):
        s = parse_scene(_mutated(_all(base, _set("targets.0.range_m", rng),
                                      _set("targets.0.velocity_mps", vel))), "e.toml")
        det = run_scene(s, "exact", "nearest").detections
        hit = (np.abs(det.range_m - rng) < 3 * radar.range_resolution_m) & (
            np.abs(det.velocity_mps - vel) < 3 * radar.velocity_resolution_mps)
        assert hit.any(), (rng, vel, det.range_m, det.velocity_mps)


def test_wide_spacing_is_refused_for_synthesis_unless_forced():
    wide = _set("rts.front_ends.1.angle_deg", 25.0)
    m = _msg(wide)
    assert m.startswith("m.toml: rts.front_ends[1].angle_deg = 25: must be within the RuT's "
                        "angular resolution"), m
    assert "eq. 24" in m and "targets[0].angle_deg = 7" in m and "allow_wide_spacing" in m
    for ok in (_set("rts.allow_wide_spacing", True), _set("rts.aoa_mode", "nearest"),
               _set("targets", [dict(range_m=30.0, angle_deg=-5.0)])):
        parse_scene(_mutated(_all(wide, ok)), "ok.toml")
    for mode in ("array-factor", "paper"):
        with pytest.raises(SceneError, match="eq. 24"):
            parse_scene(_mutated(_all(wide, _set("rts.aoa_mode", mode))), "m.toml")


def test_mesh_paths_stay_in_the_scene_folder(tmp_path):
    folder = tmp_path / "scenes"
    folder.mkdir()
    (tmp_path / "secret.stl").write_text("solid s\nendsolid s\n")
    (folder / "in.stl").write_text("solid s\nendsolid s\n")
    (folder / "link.stl").symlink_to(tmp_path / "secret.stl")
    doc = default_doc()

    def load(mesh, **kw):
        d = copy.deepcopy(doc)
        d["structure"] = [{"mesh": mesh}]
        return parse_scene(d, "s.toml", base_dir=folder, **kw)
    assert load("in.stl").extra_meshes[0][0] == str(folder / "in.stl")
    msgs = {}
    for mesh in (str(tmp_path / "secret.stl"), str(tmp_path / "nothing.stl"), "../secret.stl",
                 "../nothing.stl"):
        with pytest.raises(SceneError) as err:
            load(mesh)
        msgs[mesh] = str(err.value).split(": must be ", 1)[1]  # what follows the value
        assert "inside the scene's folder" in msgs[mesh]
    assert len(set(msgs.values())) == 1, msgs  # existence elsewhere is not revealed
    with pytest.raises(SceneError, match="link leads out"):
        load("link.stl")
    assert load(str(tmp_path / "secret.stl"), allow_external_meshes=True).extra_meshes


def test_amplitudes_override_cannot_bypass_the_spacing_rule():
    """`run --amplitudes exact` on a `nearest` scene with front ends wider apart than the
    resolution is refused like the same mode written in the scene (eq. 24), before computing."""
    from rtsgeom.pipeline.run import run_scene
    s = parse_scene(_mutated(_all(_set("rts.front_ends.1.angle_deg", 25.0),
                                  _set("rts.aoa_mode", "nearest"))), "n.toml")
    with pytest.raises(SceneError, match="eq. 24"):
        run_scene(s, "exact", "exact")


@pytest.mark.parametrize("preset", [p for p in RADAR_PRESETS.values()
                                    if p.board_gap_units is not None], ids=lambda p: p.name)
def test_preset_board_gap_bounds_the_element_spacing(preset):
    """A preset's own Tx-Rx gap is board_gap_units * d: a spacing that pushes it past 0.5 m is
    refused on load, naming the field and its limit (found by the fuzzer: it used to pass
    loading and fail in build_setup)."""
    from conftest import make_scene
    d_max = 0.5 / preset.board_gap_units
    for d, ok in ((0.999 * d_max, True), (1.001 * d_max, False)):
        if d > 0.1:  # beyond the field's own range
            continue
        def edit(doc, d=d):
            doc["radar"]["antenna_preset"] = preset.name
            doc["radar"]["element_spacing_m"] = d
            doc["radar"].pop("use_elevation_tx", None)
            doc["rts"]["allow_wide_spacing"] = True  # a wide d narrows the beam (eq. 24)
        if ok:
            make_scene(edit)
        else:
            with pytest.raises(SceneError, match=r"radar\.element_spacing_m.*at most"):
                make_scene(edit)


def test_a_sheet_at_the_smallest_arc_says_what_its_radius_must_exceed():
    """arc_radius_m at its minimum (0.05 m) with the sheet on the arc: the message names the
    sheet's inner radius limit, not a "positive radius" the offset 0 already has."""
    from conftest import make_scene
    with pytest.raises(SceneError, match=r"sheet.radius_offset_m = 0: must be > 0 m \(the "
                                         r"sheet's inner radius, rts.arc_radius_m = 0.05 m plus "
                                         r"this, must exceed 0.05 m\)"):
        make_scene(lambda d: d["rts"].update(arc_radius_m=0.05))
