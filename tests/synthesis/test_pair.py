"""Tests of ``rtsgeom.synthesis.pair``: closed forms and invariants on grids of inputs."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import make_scene


@pytest.mark.parametrize("angle_window", ["none", "hann", "hamming", "blackman"])
@pytest.mark.parametrize("radius", [0.5, 1.0, 3.0])
def test_closed_form_design_is_scale_free_and_puts_the_peak_on_the_set_angle(angle_window,
                                                                            radius):
    """``design_ratio``: the ratio whose composite x_i + rho e^{j phase} x_j peaks at the set
    angle. Its beamformer peak is there (searched), and the ratio does not depend on the
    echoes' common scale (volts or sqrt(W), 1e-6 or 1e6: P'' < 0 is a sign, not a level)."""
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.scene import TargetConfig
    from rtsgeom.synthesis.model import ChannelModel
    from rtsgeom.synthesis.pair import design_ratio

    def mutate(doc):
        doc["radar"]["angle_window"] = angle_window
        doc["rts"]["arc_radius_m"] = radius
    setup = build_setup(make_scene(mutate))
    cm = ChannelModel.build(setup, exact_paths(setup), (0, 1), TargetConfig(20.0))
    st = cm.steering
    x_i, x_j = cm.phasors
    th = np.sort(st.search(cm.phasors))
    phase = float(cm.pair_phase(th[0] + np.array([0.25, 0.75]) * (th[1] - th[0])))
    alphas = th[0] + np.array([0.15, 0.4, 0.6, 0.85]) * (th[1] - th[0])
    rho = design_ratio(st, x_i, x_j, alphas, phase)
    assert np.all(np.isfinite(rho)) and np.all(rho >= 0)
    comp = x_i[None] + (rho * np.exp(1j * phase))[:, None] * x_j[None]
    np.testing.assert_allclose(st.search(comp), alphas, atol=1e-7)
    for scale in (1e-6, 1e-3, 1e3, 1e6):
        np.testing.assert_allclose(design_ratio(st, scale * x_i, scale * x_j, alphas, phase),
                                   rho, rtol=1e-9)


@pytest.mark.parametrize("v, uneven", [(4, False), (8, True), (12, False)])
def test_beam_derivatives_are_the_central_differences_of_the_beam(v, uneven):
    """``beam_derivatives``: b'(u) and b''(u) equal the central differences of b(u) on a grid
    of directions, snapshots and tapers (even and uneven element positions)."""
    from rtsgeom.radar.steering import Steering
    from rtsgeom.radar.windows import window
    from rtsgeom.synthesis.pair import beam_derivatives
    lam = 3.9e-3
    d = lam / 2
    x = (np.arange(v) - (v - 1) / 2) * d
    if uneven:
        x = x + np.random.default_rng(v).uniform(-0.2, 0.2, v) * d
    st = Steering(np.ones(v, bool), x[:, None], window("hann", v), lam, np.array([v * d]),
                  pitch_m=d)
    rng = np.random.default_rng(v)
    snap = rng.standard_normal((50, v)) + 1j * rng.standard_normal((50, v))
    u = rng.uniform(-0.8, 0.8, 50)
    b, b1, b2 = beam_derivatives(st, snap, u)
    h = 1e-5
    bp, bm = beam_derivatives(st, snap, u + h)[0], beam_derivatives(st, snap, u - h)[0]
    scale = np.abs(st.wavevector[:, 0]).max()
    np.testing.assert_allclose(b1, (bp - bm) / (2 * h), rtol=0,
                               atol=1e-6 * scale * np.abs(b).max())
    np.testing.assert_allclose(b2, (bp - 2 * b + bm) / h ** 2, rtol=0,
                               atol=1e-4 * scale ** 2 * np.abs(b).max())
    assert np.abs(b2).max() > 1e-2 * scale ** 2 * np.abs(b).max()  # not all zero
