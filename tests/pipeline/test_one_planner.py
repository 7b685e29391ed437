"""One planner and one pair calibration: the pair on an arc is the
N = 2, D = 1 case of the channel calibration, and ``plan_targets`` plans both pairs on an arc
and cells on a sphere."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import make_scene
from rtsgeom.calibration.pair import calibrate_pair
from rtsgeom.calibration.probes import probe_front_ends
from rtsgeom.calibration.channels import calibrate_channels
from rtsgeom.pipeline.plan import plan_targets, uses_cells
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.errors import SceneError
from rtsgeom.scene import load_scene

from conftest import ROOT


@pytest.mark.parametrize("separation_m", [0.0, 0.02])
def test_channel_calibration_of_an_arc_pair_is_the_pair_calibration(separation_m):
    """On an azimuth-only RuT the N-channel calibration's edge is ``calibrate_pair`` (the same
    delay, bit for bit), and the channels' offsets are its delay."""
    def mutate(doc):
        for fe in doc["rts"]["front_ends"]:
            fe["rx_tx_separation_m"] = separation_m
    setup = build_setup(make_scene(mutate))
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, 0)
    ref = calibrate_pair(setup, paths, (0, 1), probe, (0.0, 0.0), seed=0)
    cal = calibrate_channels(setup, paths, (0, 1), probe, seed=0)
    assert cal.offsets_s[1] == ref.delta_tau_s and cal.tree == [(0, 1)]


def test_one_planner_for_arcs_and_spheres():
    """``plan_targets`` takes the cell branch for a sphere scene (N channels per target) and
    refuses a pair calibration file there; the arc keeps pairs."""
    arc = make_scene()
    assert not uses_cells(arc)
    sphere = load_scene(ROOT / "scenes" / "sphere4.toml")
    assert uses_cells(sphere)
    setup = build_setup(sphere)
    paths = exact_paths(setup)
    with pytest.raises(SceneError, match="calibration file holds pair calibrations"):
        plan_targets(setup, paths, "exact", calibrate=False, calibration={})
    prog, record, _ = plan_targets(setup, paths, "array-factor", calibrate=False)
    counts = np.bincount(np.asarray(prog.target))
    assert set(record["cells"]) == {str(k) for k in range(len(sphere.targets))}
    assert all(n == len(record["cells"][str(k)]) for k, n in enumerate(counts))
