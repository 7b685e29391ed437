"""Steering.peak's fast paths against the plain double-precision algorithm (numpy's D-general
Newton, the grid in double precision): the compiled 1-D peak (``rtsgeom.synthesis.kernels.peak_1d``:
Newton with phasors from the array's lattice, the global check in double precision), and
search's skip of NaN snapshots. Across arrays (the default RuT, a sparse and a wide ULA),
snapshot kinds (one source, two sources of nearly equal power, noise), scales 1e-30 and
1e30, and NaN rows. The compiled sums and cosines round differently from numpy's: u agrees
to 1e-12, the decisions (converged, restarted, fallen back) exactly."""

import dataclasses

import numpy as np
import pytest

from rtsgeom.geometry import build_setup
from rtsgeom.radar import steering as S
from rtsgeom.radar.newton import newton
from rtsgeom.radar.steering import Steering
from rtsgeom.scene import load_scene


def _reference_peak(st, snaps, u0, iterations=4):
    """The global check in double precision throughout (the algorithm before the fast path),
    block by block as peak runs it (numpy's SIMD and scalar paths of cos/sin can differ in
    the last bit, so the bits depend on a snapshot's neighbours in the Newton arrays)."""
    u0 = np.broadcast_to(u0, (snaps.shape[0], 1))
    parts = [_reference_block(st, snaps[b:b + S.BLOCK], u0[b:b + S.BLOCK], iterations)
             for b in range(0, snaps.shape[0], S.BLOCK)]
    return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])


def _reference_block(st, snaps, u0, iterations):
    flat = snaps.reshape(-1, snaps.shape[-1])
    kv, grid = st.wavevector, st.grid()
    steer = st.steer(grid).T
    u0 = np.broadcast_to(u0, (flat.shape[0], 1))
    x = st.weighted(flat)
    y = x @ steer
    p_grid = y.real ** 2 + y.imag ** 2
    p_max = p_grid.max(axis=1)
    best = grid[np.argmax(p_grid, axis=1)]
    xr, xi = np.ascontiguousarray(x.real.T), np.ascontiguousarray(x.imag.T)
    u, ok = newton(kv, xr, xi, u0, p_max, iterations)
    bad = np.flatnonzero(~ok)
    if bad.size:
        u2, ok2 = newton(kv, xr[:, bad], xi[:, bad], best[bad], p_max[bad], iterations + 4)
        u[bad[ok2]] = u2[ok2]
        ok[bad[ok2]] = True
    if not ok.all():
        u[~ok, 0] = np.sin(st.search(flat[~ok]))
    return u, ok


def _steerings():
    setup = build_setup(load_scene("scenes/diewald2022.toml"))
    st = Steering.build(setup.rut, setup.scene.radar)
    out = [st]
    # the same elements closer, and spread unevenly (sidelobes near the main lobe's height;
    # a uniform spread would make grating lobes of exactly equal power, where "the global
    # peak" is a tie that rounding decides, before the fast path as after it)
    jitter = np.random.default_rng(5).uniform(-0.3, 0.3, st.positions_m.shape)
    for scale, shake in ((0.5, 0.0), (1.7, 1.0)):
        pos = st.positions_m * scale + shake * jitter * st.pitch_m
        out.append(dataclasses.replace(st, positions_m=pos, aperture_m=st.aperture_m * scale))
    return out


def _snapshots(st, rng, n=3000):
    v = st.mask.size
    pos = np.zeros(v)
    pos[st.mask] = st.wavevector[:, 0]
    a1 = rng.uniform(-0.8, 0.8, n)
    one = np.exp(-1j * pos[None] * a1[:, None])
    # two sources of nearly equal power: which peak is global is decided at the 1e-6 level
    a2 = a1 + rng.uniform(0.15, 0.6, n) * rng.choice([-1, 1], n)
    eps = 10 ** rng.uniform(-9, -3, n) * rng.choice([-1, 1], n)
    two = one + (1 + eps)[:, None] * np.exp(-1j * pos[None] * a2[:, None] + 1j * rng.uniform(
        0, 2 * np.pi, n)[:, None])
    noise = rng.standard_normal((n, v)) + 1j * rng.standard_normal((n, v))
    return np.concatenate([one, two, noise]), np.concatenate([a1, a1, a1])


@pytest.mark.parametrize("scale", [1.0, 1e-30, 1e30])
def test_fast_global_check_decides_as_double_precision(scale):
    rng = np.random.default_rng(7)
    for st in _steerings():
        snaps, start = _snapshots(st, rng)
        snaps = snaps * scale
        u, ok = st.peak(snaps, start[:, None])
        u_ref, ok_ref = _reference_peak(st, snaps, start[:, None])
        # where the grid's maximum is a tie (a lambda/2 array: u = -1 and 1 are the same
        # direction of its pattern), rounding picks the restart point, here as before
        p = np.sort(st.power(snaps, st.grid()), axis=1)
        tie = p[:, -2] >= p[:, -1] * (1 - 1e-12)
        assert tie.mean() < 0.01
        assert np.array_equal(ok[~tie], ok_ref[~tie])
        np.testing.assert_allclose(u[~tie], u_ref[~tie], rtol=0, atol=1e-12)


def test_nan_snapshots_give_what_the_zoom_search_gave():
    rng = np.random.default_rng(3)
    st = _steerings()[0]
    snaps, start = _snapshots(st, rng, 200)
    snaps[::5] = np.nan
    snaps[1::7, st.mask.nonzero()[0][0]] = np.nan
    got = st.search(snaps)
    nan_rows = np.isnan(st.weighted(snaps)).any(axis=1)
    assert np.all(got[nan_rows] == -np.pi / 2)  # argmax over NaN powers: the grid's first
    assert np.array_equal(got[~nan_rows], st.search(snaps[~nan_rows]))
    u, ok = st.peak(snaps, start[:, None])
    assert not ok[nan_rows].any() and np.all(u[nan_rows, 0] == -1.0)
