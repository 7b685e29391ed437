"""The whole-arc tolerance study draws the target's sub-bin position (the pair study's model,
shared by every pair of the arc): on arcs of different radii and front-end counts."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from rtsgeom.analysis.tolerance.draws import Bounds
from rtsgeom.analysis.tolerance.montecarlo import ToleranceModel
from rtsgeom.analysis.design import two_front_end_scene
from rtsgeom.analysis.tolerance.phasors import ChannelPhasors
from rtsgeom.analysis.tolerance.montecarlo import monte_carlo
from rtsgeom.analysis.tolerance.draws import DrawStreams, draw_chunks, subbin_draws
from rtsgeom.errors import ParameterError
from rtsgeom.geometry import build_setup
from rtsgeom.scene import load_scene

from conftest import DEFAULT_SCENE as DEFAULT, two_front_end_pair


def _arc_scene(radius_m: float, angles_deg):
    """The default scene as an arc of front ends at ``angles_deg`` on ``radius_m``, no sheet,
    no mounting or channel errors (the design helper's clean front ends, repeated)."""
    scene = load_scene(DEFAULT)
    two, _, problem = two_front_end_scene(scene, (0, 1), radius_m, math.radians(8.0))
    assert problem is None
    proto = two.rts.front_ends[0]
    fes = tuple(dataclasses.replace(proto, angle_rad=math.radians(a)) for a in angles_deg)
    rts = dataclasses.replace(two.rts, front_ends=fes)
    return dataclasses.replace(two, rts=rts,
                               sheet=dataclasses.replace(two.sheet, enabled=False))


@pytest.mark.parametrize("radius_m", [0.5, 2.0])
def test_two_front_end_arc_reproduces_the_pair_study_with_subbin(radius_m):
    """Bit for bit on other radii too (the pair study's streams: positions and sub-bin)."""
    _, model = two_front_end_pair(radius_m)
    sigma = np.array([0.3, 0.2, 0.2]) * 1e-3
    # the same chunk here; the pair study's bits do not depend on it either (test_tolerance)
    pair = monte_carlo(model, sigma, 120, 4, "normal", 0.05, chunk=40)
    arc = monte_carlo(ToleranceModel.arc([model], 2), Bounds(tuple(sigma)), 120, 4, "normal",
                      0.05, chunk=40)
    for case in ("uncalibrated", "calibrated"):
        assert np.array_equal(arc.worst_error_deg[case][:, 0], pair.worst_error_deg[case])
    assert np.array_equal(arc.subbin_steps, pair.subbin_steps)
    # the positions span the bin (uniform over subbin_steps, not the centre only)
    span = model.subbin_steps.max() - model.subbin_steps.min()
    assert np.ptp(arc.subbin_steps) > 0.8 * span
    assert np.count_nonzero(arc.subbin_steps == 0) < 10


@pytest.mark.parametrize("radius_m,angles", [(0.5, (-8.0, 0.0, 8.0)),
                                             (2.0, (-4.0, 4.0, 12.0, 20.0))])
def test_arc_pairs_share_one_target_position(radius_m, angles):
    """One target, one range: every pair of an arc is evaluated at the same sub-bin position
    per draw, each pair exactly what the pair model gives for that draw's front ends at that
    position; the draws' positions are the pair study's stream and do not depend on the
    chunk; the bin-centre run (``subbin=False``) is every pair at the bin centre."""
    setup = build_setup(_arc_scene(radius_m, angles))
    n_fe = len(angles)
    models = [ChannelPhasors.build(setup, (i, i + 1), 3) for i in range(n_fe - 1)]
    steps = ToleranceModel.arc(models, n_fe).subbin_steps
    b = Bounds((0.2e-3, 0.15e-3, 0.1e-3))
    draws, seed = 90, 7
    res = monte_carlo(ToleranceModel.arc(models, n_fe), b, draws, seed, "uniform", 0.05,
                      keep_errors=True, chunk=40)
    idx = next(subbin_draws(seed, draws, steps.size, draws))
    assert np.array_equal(res.subbin_steps, steps[idx])
    again = next(draw_chunks(seed, draws, n_fe, "uniform", draws,
                             DrawStreams(positions=steps.size))).subbin()
    assert np.array_equal(again, idx)
    off = res.errors["offsets_m"]
    centre = monte_carlo(ToleranceModel.arc(models, n_fe), b, draws, seed, "uniform", 0.05,
                         chunk=draws, subbin=False)
    assert centre.subbin_steps is None
    for p, (m, pair) in enumerate(zip(models, [(i, i + 1) for i in range(n_fe - 1)])):
        one = m.evaluate(off[:, pair[0]:pair[1] + 1], subbin=idx)
        mid = m.evaluate(off[:, pair[0]:pair[1] + 1])
        for case in ("uncalibrated", "calibrated"):
            assert np.array_equal(res.worst_error_deg[case][:, p], one[case][:, 0])
            assert np.array_equal(centre.worst_error_deg[case][:, p], mid[case][:, 0])
    # the position matters: somewhere in the bin the worst error is not the bin centre's
    assert not np.array_equal(res.worst_error_deg["calibrated"],
                              centre.worst_error_deg["calibrated"])


def test_arc_refuses_pairs_built_for_different_target_positions():
    setup = build_setup(load_scene(DEFAULT))
    m = ChannelPhasors.build(setup, (0, 1), 3)
    other = dataclasses.replace(m, subbin_steps=m.subbin_steps[1:-1])
    with pytest.raises(ParameterError, match="sub-bin positions"):
        ToleranceModel.arc([m, other], 2)
