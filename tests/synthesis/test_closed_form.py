"""Tests of ``rtsgeom.synthesis.closed_form``: closed forms and invariants on grids of inputs."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import SMALL, make_scene

from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths


@pytest.mark.parametrize("n", [2, 4, 7, 8, 16])
def test_array_factor_of_filled_positions_is_the_dirichlet_kernel(n):
    """``array_factor`` with the positions of a filled lambda/2 array equals its closed form
    sin(n pi u/2) / (n sin(pi u/2)) (docstring), for any u, also past the grating lobes."""
    from rtsgeom.synthesis.closed_form import array_factor
    u = np.linspace(-1.9, 1.9, 381)
    closed = array_factor(u, n)
    for offset in (0.0, 3.25):  # the centroid is removed: a shifted array has the same AF
        got = array_factor(u, positions_wl=offset + 0.5 * np.arange(n))
        np.testing.assert_allclose(got, closed, atol=1e-12)
    # a sparse array is not that kernel (here: 2 elements 2 lambda apart, cos(2 pi u))
    np.testing.assert_allclose(array_factor(u, positions_wl=[0.0, 2.0]), np.cos(2 * np.pi * u),
                               atol=1e-12)


@pytest.mark.parametrize("common", [0.0, 0.7, -2.1, 3.0])
def test_closed_form_amplitudes_ignore_a_common_phase(common):
    """Adding one phase to every channel's programmed phase changes nothing physical (the
    beamformer output rotates as a whole): the ``array-factor`` amplitudes on sphere4's four
    front ends are the same for phases + c as for phases, over set points in the cell."""
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.radar.steering import Steering
    from rtsgeom.scene import TargetConfig, load_scene
    from rtsgeom.synthesis.closed_form import closed_form_amplitudes
    from rtsgeom.synthesis.model import ChannelModel
    setup = build_setup(load_scene("scenes/sphere4.toml"))
    cs = ChannelModel.build(setup, exact_paths(setup), (0, 1, 2, 3), TargetConfig(25.0),
                            steering=Steering.auto(setup.rut, setup.scene.radar))
    st = cs.steering
    u_fe = setup.fe_direction_cosines()
    lo, hi = u_fe.min(0), u_fe.max(0)
    phases = np.array([0.3, -1.2, 2.0, 0.4])
    for fx, fz in ((0.3, 0.4), (0.7, 0.8), (0.5, 0.2)):
        u = lo + np.array([fx, fz]) * (hi - lo)
        a = closed_form_amplitudes(st, u_fe, u, phases)
        b = closed_form_amplitudes(st, u_fe, u, phases + common)
        np.testing.assert_allclose(b, a, rtol=1e-9, atol=1e-12)
        assert np.max(a) == pytest.approx(1.0)


@pytest.mark.parametrize("angles", [(3.4, 12.2), (-5.0, 5.0), (-12.0, -2.0)])
def test_closed_forms_put_a_span_end_on_one_channel_alone(angles):
    from rtsgeom.scene import TargetConfig
    from rtsgeom.synthesis.model import ChannelModel

    def mutate(doc):
        doc["radar"].update(SMALL)
        for fe, a in zip(doc["rts"]["front_ends"], angles):
            fe["angle_deg"] = a
        doc["sheet"]["enabled"] = False
        doc["targets"] = []
    setup = build_setup(make_scene(mutate))
    cm = ChannelModel.build(setup, exact_paths(setup), (0, 1), TargetConfig(20.0))
    th = setup.fe_azimuth_rad()
    for mode in ("array-factor", "paper"):
        assert cm.pair_ratio(float(th[0]), mode=mode) == 0.0
        assert cm.pair_ratio(float(th[1]), mode=mode) == 1e12
        assert 0.0 < cm.pair_ratio(float(th.mean()), mode=mode) < 1e12
