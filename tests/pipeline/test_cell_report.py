"""What `info` and report.html show of a 2-D cell scene: elevations of front ends and targets."""

import numpy as np
import pytest

from rtsgeom.geometry import build_setup
from rtsgeom.pipeline.info import format_info, scene_info
from rtsgeom.pipeline.output import targets_table
from rtsgeom.scene import load_scene

from .test_sphere import corners

SCENE = "scenes/diewald2022.toml"


@pytest.mark.parametrize("radius", [0.5, 2.0])
@pytest.mark.parametrize("el_deg", [(-6.0, 4.0), (-15.0, 10.0)])
def test_front_end_elevations_in_info(radius, el_deg):
    scene = corners(load_scene(SCENE), (-3.0, 5.0), el_deg, radius=radius, height=1.5)
    setup = build_setup(scene)
    info = scene_info(setup)
    got = np.array([fe["elevation_from_rut_deg"] for fe in info["front_ends"]])
    # closed form: the module centre's elevation seen from the RuT's phase centre
    p = setup.rut.to_local(setup.fe.module)
    want = np.degrees(np.arctan2(p[:, 2], np.hypot(p[:, 0], p[:, 1])))
    assert np.allclose(got, want, atol=1e-9)
    assert [fe["elevation_deg"] for fe in info["front_ends"]] == pytest.approx(
        [e for _ in range(2) for e in el_deg])
    text = format_info(info)
    assert "elevation deg" in text
    # the two front ends at one azimuth are told apart by their elevation column
    rows = [ln for ln in text.splitlines() if ln.startswith("   0 ") or ln.startswith("   1 ")]
    assert len(rows) == 2 and rows[0] != rows[1]


def test_no_elevation_column_on_an_arc():
    info = scene_info(build_setup(load_scene(SCENE)))
    assert all(fe["elevation_deg"] == 0.0 for fe in info["front_ends"])
    text = format_info(info)
    assert "elevation deg" not in text and " el " not in text  # no column, no target's el


def _match(k, el=None, detected=True):
    s = {"range_m": 20.0 + k, "velocity_mps": 0.0, "angle_deg": 5.0}
    d = {"range_m": 20.01 + k, "velocity_mps": 0.0, "angle_deg": 5.002}
    e = {"range_m": 0.01, "velocity_mps": 0.0, "angle_deg": 0.002}
    if el is not None:
        s["elevation_deg"], d["elevation_deg"], e["elevation_deg"] = el, el - 0.01, -0.01
    return {"index": k, "set": s, "detection": d if detected else None,
            "error": e if detected else None}


@pytest.mark.parametrize("el", [None, 3.0])
def test_targets_table_columns(el):
    tab = targets_table([_match(0, el), _match(1, el, detected=False)])
    n = 4 if el is not None else 3
    assert len(tab["columns"]) == 1 + 3 * n == len(tab["digits"])
    assert all(len(r) == len(tab["columns"]) for r in tab["rows"])
    assert ("set elevation (deg)" in tab["columns"]) == (el is not None)
    if el is not None:
        row = tab["rows"][0]
        assert row[tab["columns"].index("elevation error (deg)")] == -0.01
        assert row[tab["columns"].index("set elevation (deg)")] == el
    assert tab["rows"][1][1 + n] == "not detected"


@pytest.mark.parametrize("radius", [0.6, 1.5])
def test_reachable_cells_in_info(radius):
    """`info` on a cell scene names each target's enclosing cell (the planner's choice, not arc
    pairs) and warns, naming the target, for a direction outside every cell."""
    from rtsgeom.pipeline.info import reachable_spans, unreachable_warnings
    from rtsgeom.pipeline.plan import target_cells
    from rtsgeom.scene import TargetConfig
    scene = corners(load_scene(SCENE), (-3.0, 5.0), (-3.0, 3.0), radius=radius, height=1.5)
    inside = TargetConfig(20.0, angle_rad=np.radians(1.0), elevation_rad=np.radians(0.5))
    outside = TargetConfig(25.0, angle_rad=np.radians(9.0), elevation_rad=np.radians(0.5))
    scene = scene.evolve(radar=scene.radar.evolve(use_elevation_tx=True))  # elevation extent
    setup = build_setup(scene.evolve(targets=(inside, outside)))
    reach = reachable_spans(setup)
    assert reach["cells"] and reach["pairs"] == []
    _, _, found = target_cells(setup)
    assert [t["cell"] for t in reach["targets"]] == [
        None if c is None else list(c) for c, _ in found]
    assert reach["targets"][0]["cell"] == [0, 1, 2, 3] and reach["targets"][0]["reachable"]
    assert not reach["targets"][1]["reachable"]
    info = scene_info(setup)
    info["reachable"] = reach
    warns = unreachable_warnings(info)
    assert len(warns) == 1 and "targets[1]" in warns[0]
    text = format_info(info)
    assert "(cell 0-1-2-3)" in text and "spacing 0-1" not in text
