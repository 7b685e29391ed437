"""The line-of-sight paths (``rtsgeom.paths.exact``) against their closed forms, row by row:
each leg's delay |p_a - p_b| / c0, its free-space amplitude lambda / (4 pi d), the rows'
order and columns, and the antennas' field gains each taken towards the other antenna in its
own frame (a made-up pattern that reads the direction's components)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.constants import c

from rtsgeom.geometry import build_setup
from rtsgeom.geometry.patterns import ISOTROPIC, AntennaPatterns, Pattern
from rtsgeom.paths.exact import distances, exact_paths, leg_delays, leg_pattern_gains
from rtsgeom.paths.table import FE_TO_RX, TX_TO_FE


class Reads(Pattern):
    """A field gain that reads the unit direction (x, y, z) in the antenna's frame:
    1 + a y + j b x + c z (non-isotropic)."""

    def __init__(self, a, b, cz=0.0):
        self.a, self.b, self.cz = a, b, cz

    def field(self, direction):
        v = np.asarray(direction, float)
        u = v / np.linalg.norm(v, axis=-1, keepdims=True)
        return 1 + self.a * u[..., 1] + 1j * self.b * u[..., 0] + self.cz * u[..., 2]


@pytest.fixture(scope="module")
def setup():
    import copy

    from conftest import default_doc
    from rtsgeom.scene import parse_scene
    doc = copy.deepcopy(default_doc())
    doc["radar"]["use_elevation_tx"] = True  # 3 Tx, one elevated
    doc["radar"]["yaw_deg"] = 3.0  # the radar frame turned from the world's
    doc["rts"]["front_ends"][1]["yaw_offset_deg"] = 2.0
    doc["rts"]["front_ends"][0]["height_offset_mm"] = 3.0
    return build_setup(parse_scene(doc, "e.toml"))


def test_distances_and_leg_delays_broadcast_over_draws():
    rng = np.random.default_rng(0)
    a, b = rng.standard_normal((4, 3, 3)), rng.standard_normal((4, 5, 3))
    d = distances(a, b)
    assert d.shape == (4, 3, 5)
    for k in range(4):
        for i in range(3):
            for j in range(5):
                assert d[k, i, j] == pytest.approx(np.sqrt(np.sum((a[k, i] - b[k, j]) ** 2)),
                                                   rel=1e-14)
    tx, rx = rng.standard_normal((2, 3)), rng.standard_normal((4, 3))
    fe_rx, fe_tx = rng.standard_normal((6, 2, 3)), rng.standard_normal((6, 2, 3))
    t_tx, t_rx = leg_delays(tx, rx, fe_rx, fe_tx)
    assert t_tx.shape == (6, 2, 2) and t_rx.shape == (6, 2, 4)
    np.testing.assert_allclose(t_tx, distances(fe_rx, tx) / c, rtol=0, atol=0)
    np.testing.assert_allclose(t_rx[3, 1, 2], np.linalg.norm(fe_tx[3, 1] - rx[2]) / c,
                               rtol=1e-14)


def test_the_exact_paths_row_by_row(setup):
    """RuT Tx -> FE Rx rows first (front end major, then Tx), then FE Tx -> RuT Rx; each
    row's delay the distance over c0 and its gain lambda / (4 pi d), line of sight."""
    p = exact_paths(setup)
    rut, fe = setup.rut, setup.fe
    n_f, n_t, n_r = fe.count, rut.tx_world.shape[0], rut.rx_world.shape[0]
    assert (n_t, n_r) == (3, 4)
    assert len(p) == n_f * (n_t + n_r) and p.method == "exact"
    lam = rut.wavelength_m
    rows = []
    for f in range(n_f):
        for t in range(n_t):
            rows.append((f, TX_TO_FE, t, -1, np.linalg.norm(fe.rx[f] - rut.tx_world[t])))
    for f in range(n_f):
        for r in range(n_r):
            rows.append((f, FE_TO_RX, -1, r, np.linalg.norm(fe.tx[f] - rut.rx_world[r])))
    want = np.array(rows)
    np.testing.assert_array_equal(p.front_end, want[:, 0].astype(int))
    np.testing.assert_array_equal(p.direction, want[:, 1].astype(int))
    np.testing.assert_array_equal(p.rut_tx, want[:, 2].astype(int))
    np.testing.assert_array_equal(p.rut_rx, want[:, 3].astype(int))
    np.testing.assert_allclose(p.delay_s, want[:, 4] / c, rtol=1e-14)
    np.testing.assert_allclose(p.gain, lam / (4 * np.pi * want[:, 4]), rtol=1e-12)
    assert np.all(p.gain.imag == 0)
    assert np.all(p.bounces == 0) and set(p.interactions) == {"los"}
    assert set(p.surfaces) == {""}
    same = exact_paths(setup, AntennaPatterns())
    np.testing.assert_array_equal(same.gain, p.gain)


def test_each_antenna_takes_its_gain_towards_the_other_in_its_own_frame(setup):
    """The RuT's elements read the direction to the front end in the radar frame, a front
    end's antennas the direction to the RuT element in their module frame (x = boresight x
    up, y boresight, z up); the row's gain the free-space amplitude times both."""
    rut, fe = setup.rut, setup.fe
    pats = AntennaPatterns(rut_tx=Reads(0.3, 0.2), rut_rx=Reads(-0.2, 0.1, 0.4),
                           fe_rx=Reads(0.1, -0.3, 0.2),
                           fe_tx=(Reads(0.2, 0.1), Reads(-0.1, 0.25, -0.3)))
    frame = fe.antenna_frame()
    g_tx, g_rx = leg_pattern_gains(setup, pats)
    assert g_tx.shape == (2, 3) and g_rx.shape == (2, 4)
    for f in range(2):
        for t in range(3):
            d = fe.rx[f] - rut.tx_world[t]
            want = (pats.rut_tx.field(d @ rut.rotation) * pats.fe_rx.field(-d @ frame[f]))
            assert g_tx[f, t] == pytest.approx(want, rel=1e-12)
        for r in range(4):
            d = fe.tx[f] - rut.rx_world[r]
            want = pats.rut_rx.field(d @ rut.rotation) * pats.fe_tx[f].field(-d @ frame[f])
            assert g_rx[f, r] == pytest.approx(want, rel=1e-12)
    p = exact_paths(setup, pats)
    iso = exact_paths(setup)
    np.testing.assert_allclose(p.gain, iso.gain * np.concatenate([g_tx.ravel(), g_rx.ravel()]),
                               rtol=1e-12)
    np.testing.assert_array_equal(p.delay_s, iso.delay_s)
    # a front end looks at the RuT along its boresight: a pattern reading only y is ~1 + a
    fwd = leg_pattern_gains(setup, AntennaPatterns(fe_rx=Reads(0.5, 0.0)))[0]
    np.testing.assert_allclose(fwd, 1.5, rtol=1e-3)


def test_one_pattern_per_front_end_or_the_count_is_refused(setup):
    from conftest import assert_refused
    pats = AntennaPatterns(fe_rx=(ISOTROPIC, Reads(0.1, 0.1), ISOTROPIC))
    assert_refused(lambda: leg_pattern_gains(setup, pats),
                   "patterns: 3 front-end patterns for 2 front ends", ValueError)
    assert_refused(lambda: leg_pattern_gains(setup, AntennaPatterns(fe_tx=(ISOTROPIC,))),
                   "patterns: 1 front-end patterns for 2 front ends", ValueError)
