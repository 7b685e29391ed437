"""The pair study's beam tables: the beam at each set angle and its first two derivatives in
u = sin(angle), against central differences of the beam itself."""

from __future__ import annotations

import numpy as np
import pytest

from rtsgeom.analysis.tolerance.pair import _set_beams
from rtsgeom.geometry import build_setup
from rtsgeom.radar.steering import Steering


@pytest.mark.parametrize("window", ["none", "hann"])
def test_the_beams_derivatives_are_the_beams_slopes_in_u(default_scene, window):
    scene = default_scene.evolve(radar=default_scene.radar.evolve(angle_window=window))
    setup = build_setup(scene)
    st = Steering.auto(setup.rut, scene.radar)
    rng = np.random.default_rng(7)
    v = setup.rut.num_virtual
    rows = rng.normal(size=(2, 3, v)) + 1j * rng.normal(size=(2, 3, v))
    sets = np.radians([-20.0, 3.0, 11.5])
    b = _set_beams(st, rows, sets)
    assert b.shape == (2, 3, 3, 3) and b.flags.c_contiguous
    h = 1e-5
    u = np.sin(sets)
    up, dn = (_set_beams(st, rows, np.arcsin(u + s))[:, 0] for s in (h, -h))
    scale = np.max(np.abs(b[:, 0]))
    assert np.allclose(b[:, 1], (up - dn) / (2 * h), rtol=0, atol=1e-6 * scale * 50)
    assert np.allclose(b[:, 2], (up - 2 * b[:, 0] + dn) / h ** 2, rtol=1e-3,
                       atol=1e-3 * np.max(np.abs(b[:, 2])))
    # the beam itself: the weighted rows steered to each set angle
    w = st.weighted(rows)
    kv = st.wavevector[:, 0]
    want = np.einsum("rkv,mv->rmk", w, np.exp(1j * kv * u[:, None]))
    assert np.allclose(b[:, 0], want, rtol=1e-12, atol=1e-12 * scale)
