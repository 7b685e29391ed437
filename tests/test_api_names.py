"""Python takes the scene file's unit-suffixed keys beside the SI names (``replace``), and the
studies' warnings are Python warnings, which the commands print."""

from __future__ import annotations

import math
import re
import warnings

import pytest

import rtsgeom
from conftest import DEFAULT_SCENE
from rtsgeom.cli import main
from rtsgeom.errors import NominalSetupWarning, ParameterError, SceneError


@pytest.fixture(scope="module")
def scene():
    return rtsgeom.load_scene(DEFAULT_SCENE)


def test_file_keys_convert_by_their_unit(scene):
    fe = scene.rts.front_ends[0]
    assert rtsgeom.replace(fe, radial_offset_mm=0.5).radial_offset_m == pytest.approx(5e-4)
    assert rtsgeom.replace(fe, radial_offset_m=5e-4) == rtsgeom.replace(fe, radial_offset_mm=0.5)
    assert rtsgeom.replace(fe, angle_deg=3.0).angle_rad == pytest.approx(math.radians(3.0))
    radar = rtsgeom.replace(scene.radar, yaw_offset_deg=0.5)
    assert radar.yaw_offset_rad == pytest.approx(math.radians(0.5))
    assert rtsgeom.replace(scene, seed=3).seed == 3


def test_errors_name_the_key_as_written(scene):
    fe = scene.rts.front_ends[0]
    with pytest.raises(SceneError, match=r"^replace: radial_offset_m = 0\.3 \(the scene file's "
                                         r"radial_offset_mm = 300\): must be in \[-50, 50\] mm"):
        rtsgeom.replace(fe, radial_offset_m=0.3)
    with pytest.raises(SceneError, match=r"^replace: radial_offset_mm = 300: must be in"):
        rtsgeom.replace(fe, radial_offset_mm=300)
    with pytest.raises(ParameterError, match="no field 'radial_offset_cm'; did you mean "
                                             "radial_offset_m, radial_offset_mm"):
        rtsgeom.replace(fe, radial_offset_cm=1)
    with pytest.raises(ParameterError, match="set the same field"):
        rtsgeom.replace(fe, radial_offset_mm=0.1, radial_offset_m=1e-4)


def _with_offset(scene):
    fes = list(scene.rts.front_ends)
    fes[1] = rtsgeom.replace(fes[1], radial_offset_mm=0.3)
    return rtsgeom.replace(scene, rts=rtsgeom.replace(scene.rts, front_ends=tuple(fes)))


def test_a_study_of_a_scene_with_its_own_errors_warns(scene):
    moved = _with_offset(scene)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rtsgeom.tolerance(moved, draws=20, points=5)
        rtsgeom.tolerance(scene, draws=20, points=5)  # nominal: nothing to say
    ours = [w for w in caught if issubclass(w.category, NominalSetupWarning)]
    assert len(ours) == 1, [str(w.message) for w in caught]
    text = str(ours[0].message)
    assert "rts.front_ends[1].radial_offset_mm" in text and "linearity" in text
    assert ours[0].filename == __file__  # points at the caller's line


def test_the_command_prints_the_library_warning_once(tmp_path, capsys):
    doc = DEFAULT_SCENE.read_text().replace("[[rts.front_ends]]",
                                            "[[rts.front_ends]]\nradial_offset_mm = 0.3", 1)
    path = tmp_path / "moved.toml"
    path.write_text(doc)
    assert main(["tolerance", str(path), "--draws", "20", "--points", "5", "--quiet"]) == 0
    cap = capsys.readouterr()
    assert cap.err.count("rtsgeom: warning: tolerance draws mounting errors") == 1, cap.err
    assert "rts.front_ends[0].radial_offset_mm" in cap.err
    # and says what the offset does: the pair as built, uncalibrated and calibrated
    m = re.search(r"the scene's own offsets \(rts.front_ends\[0\].radial_offset_mm\), one "
                  r"setup at the bin centre: worst \|error\| uncalibrated ([\d.]+), calibrated "
                  r"([\d.]+) deg", cap.out)
    assert m, cap.out
    uncal, cal = float(m.group(1)), float(m.group(2))
    assert uncal > 0.1 and cal < 0.01  # 0.3 mm radial: ~0.5 deg until calibrated


#: each command and the top-level function that does its job (a new command needs a line)
COMMAND_FUNCTIONS = {
    "info": "scene_info", "paths": "exact_paths", "export-mesh": "export_setup",
    "run": "run_scene", "play": "play", "adc": "run_scene", "calibrate": "calibrate",
    "linearity": "linearity", "tolerance": "tolerance", "design": "design",
    "nearfield": "nearfield", "ghosts": "ghosts", "show": "show", "identify": "identify",
    "transfer": "transfer", "resolution": "resolution", "objects": "object_design", "kpi": "kpi",
}


@pytest.mark.subprocess
def test_every_command_has_its_function_at_the_top_level():
    """What each command does is importable from ``rtsgeom`` in a fresh interpreter, and
    callable (``rtsgeom.identify`` raised AttributeError until the subpackage happened to be
    imported; it is the package, callable as ``identify(scene, captures)``)."""
    import subprocess
    import sys

    from rtsgeom.cli import COMMANDS
    assert set(COMMAND_FUNCTIONS) == set(COMMANDS)
    names = sorted(set(COMMAND_FUNCTIONS.values()))
    assert set(names) <= set(rtsgeom.__all__)
    code = ("import rtsgeom\n"
            f"for n in {names!r}:\n"
            "    assert callable(getattr(rtsgeom, n)), n\n"
            "from rtsgeom.identify import identify, read_capture\n"
            "assert rtsgeom.identify.read_capture is read_capture\n"
            "import inspect\n"
            "assert list(inspect.signature(identify).parameters)[:2] == ['scene', 'captures']\n")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr[-2000:]


def test_the_package_called_is_its_entry_point(monkeypatch):
    import rtsgeom.identify as package
    monkeypatch.setattr(package, "identify", lambda *a, **k: ("called", a, k))
    assert rtsgeom.identify("scene", ["cap"], accept_misfit=True) == (
        "called", ("scene", ["cap"]), {"accept_misfit": True})


@pytest.mark.parametrize("study, call", [
    ("tolerance", lambda s: rtsgeom.tolerance(s, draws=20, points=5)),
    ("design", lambda s: rtsgeom.design(s, [1.0], [8.0], draws=20, points=5)),
    ("nearfield", lambda s: rtsgeom.nearfield(s, [1.0], points=3)),
])
def test_each_api_warning_points_at_the_callers_line(scene, study, call):
    """Every warning the API raises names the caller's line, whatever the depth of the call
    inside the package (``rtsgeom.design()``'s pointed at rtsgeom/api.py:285)."""
    with pytest.warns(NominalSetupWarning, match=f"^{study} ") as caught:
        call(_with_offset(scene))
    ours = [w for w in caught if issubclass(w.category, NominalSetupWarning)]
    assert len(ours) == 1 and ours[0].filename == __file__, [(w.filename, w.lineno)
                                                             for w in ours]
