"""An extended object's input is checked on load as strictly as a point target's, moving or
not, with one line naming the field as the scene file writes it (``targets[1].scatterers[2]``,
never the expanded ``targets[7]`` the file does not have)."""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path

import pytest

from rtsgeom.analysis.playback.frames import frame_target_names, frame_targets
from rtsgeom.errors import SceneError
from rtsgeom.scene import parse_scene
from rtsgeom.scene.objects import target_labels

CAR = Path(__file__).resolve().parents[2] / "scenes" / "car-crossing.toml"
DOC = tomllib.loads(CAR.read_text())
SQUARE = [[0.5, 0.5, 0.0, 0.0], [-0.5, 0.5, 0.0, 0.0], [0.5, -0.5, 0.0, 0.0]]


def bench(targets) -> dict:
    doc = copy.deepcopy(DOC)
    del doc["scenario"]
    doc["targets"] = targets
    return doc


def drive(**change) -> dict:
    doc = copy.deepcopy(DOC)
    doc["scenario"]["targets"][0].update(change)
    return doc


def refused(doc) -> str:
    with pytest.raises(SceneError) as exc:
        parse_scene(doc, "o.toml")
    msg = str(exc.value)
    assert "\n" not in msg
    return msg


@pytest.mark.parametrize("row, field, what", [
    ([0.0, 40.0, 0.0, 0.0], "scenario.targets[0].scatterers[3]", "range"),
    ([20.0, -20.0, 0.0, 0.0], "scenario.targets[0].scatterers[3]", "azimuth"),
])
@pytest.mark.parametrize("heading", ["velocity", "fixed"])
def test_moving_object_scatterers_checked_on_load(row, field, what, heading):
    """A moving object's scatterer beyond the range axis or behind the RuT: refused on load
    naming it (it was accepted, and the drive played a target the radar cannot see)."""
    msg = refused(drive(scatterers=SQUARE + [row], heading=heading))
    assert msg.startswith(f"o.toml: {field} = [") and what in msg, msg


def test_moving_object_scatterers_count_against_the_caps():
    """Each scatterer is a target in every frame: 5 objects of 256 scatterers are 1280
    targets a frame (over 1024), and 256 scatterers over 10001 frames 2.56 million
    target-frames; each object counted once before."""
    doc = copy.deepcopy(DOC)
    doc["scenario"]["targets"] = [dict(doc["scenario"]["targets"][0],
                                       scatterers=[[0.0, 0.0, 0.0, 0.0]] * 256)] * 5
    assert "at most 1024 point targets a frame" in refused(doc)
    doc = drive(scatterers=[[0.0, 0.0, 0.0, 0.0]] * 256)
    doc["scenario"].update(frame_period_s=0.01, duration_s=100.0)
    doc["scenario"]["targets"][0]["waypoints"][1][0] = 100.0
    assert "target-frames" in refused(doc)


@pytest.mark.parametrize("before", [0, 1, 2])
def test_static_object_scatterer_named_as_written(before):
    """The object after ``before`` point targets; its 2nd scatterer beyond the range axis
    was named targets[before + 1], the expanded index; behind the RuT it was accepted."""
    points = [{"range_m": 10.0 + k} for k in range(before)]
    far = SQUARE[:1] + [[0.0, 40.0, 0.0, 0.0]]
    msg = refused(bench(points + [{"range_m": 15.0, "scatterers": far}]))
    assert msg.startswith(f"o.toml: targets[{before}].scatterers[1] (its range_m) = "), msg
    back = SQUARE[:1] + [[0.0, -4.0, 0.0, 0.0]]
    msg = refused(bench(points + [{"range_m": 2.0, "scatterers": back}]))
    assert msg.startswith(f"o.toml: targets[{before}].scatterers[1] (its azimuth_deg) = 180"), msg


def test_labels_follow_the_file():
    """Point targets after an object keep their file index; a drive's frame names its
    object's scatterers."""
    s = parse_scene(bench([{"range_m": 10.0}, {"range_m": 15.0, "scatterers": SQUARE},
                           {"range_m": 20.0}]), "o.toml")
    assert target_labels(s) == ["targets[0]", "targets[1].scatterers[0]",
                                "targets[1].scatterers[1]", "targets[1].scatterers[2]",
                                "targets[2]"]
    car = parse_scene(copy.deepcopy(DOC), "car.toml")
    _, frames = frame_targets(car)
    name = frame_target_names(car, 4, targets=frames[4])
    assert name(11) == "frame 4: scenario.targets[0].scatterers[11]"
