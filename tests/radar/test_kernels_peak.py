"""``radar.peak_kernels.peak_1d`` against its definition (``radar.newton.peak_1d``, numpy), bit for bit:
the Newton peak (phasors from the array's lattice) is accepted iff it converged and its power
is at least ``1 - P_SLACK`` of the largest power on the grid (each point's sum in element
order), otherwise Newton restarts from the grid's maximum under the same test. The kernel may
decide the acceptance from a cheaper bound first; these tests check that it returns exactly
the same u and accepts and rejects exactly the same snapshots, on a grid of arrays (V = 4 ..
16, on and off the lattice) and tapers, with clean, two-target, ambiguous (two equal targets
far apart, started at the wrong one) and noise-only snapshots; and that ``Steering.peak``
gives the same bits whichever of the two a batch's size selects."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from rtsgeom.radar import peak_kernels as kernels
from rtsgeom.radar import newton, steering as steering_mod
from synthesis.test_kernels import plane, steering

GRID = [(v, w, un) for v in (4, 5, 8, 11, 16) for w in ("none", "hann", "blackman")
        for un in (False, True)]


def reference(st, x, u0, iterations=4):
    """The check's definition (``radar.newton.peak_1d``, numpy, each grid point's power
    summed over the elements in order), and which snapshots it accepts at once (``direct``)
    and which converged to a peak that a grid point beats (``beaten``: a local maximum)."""
    k, lat, gc, gs, grid = st._grid_1d
    u_out, ok_out = newton.peak_1d(k, lat, x, u0, gc, gs, grid, iterations)
    _, conv, p = newton.newton_1d(k, lat, np.ascontiguousarray(x.real.T),
                                  np.ascontiguousarray(x.imag.T), u0, iterations)
    b = x[:, :, None] * (gc + 1j * gs)[None]
    power = np.abs(b.sum(1)) ** 2
    direct = conv & (p >= power.max(1) * (1 - newton.P_SLACK))
    return u_out, ok_out, direct, conv & ~direct


def snapshots(st, v, seed):
    rng = np.random.default_rng(seed)
    n = 120
    u1 = rng.uniform(-0.8, 0.8, n)
    clean = plane(st, u1)
    u2 = np.clip(u1 + rng.uniform(0.02, 0.4, n) * rng.choice([-1, 1], n), -0.95, 0.95)
    two = clean + rng.uniform(0.2, 1, n)[:, None] * plane(st, u2) * np.exp(
        1j * rng.uniform(0, 2 * np.pi, n))[:, None]
    far = -np.sign(u1) * np.maximum(np.abs(u1), 0.4)  # the mirror direction, >= 0.8 away
    ambiguous = clean + rng.uniform(0.9, 1.1, n)[:, None] * plane(st, far)
    noise = 0.5 * (rng.standard_normal((n, v)) + 1j * rng.standard_normal((n, v)))
    x = np.concatenate([clean, two, ambiguous, clean + noise, noise])
    u0 = np.concatenate([u1 + 0.01, u1 + 0.01, far + 0.01, u1, rng.uniform(-0.9, 0.9, n)])
    return np.ascontiguousarray(st.weighted(x), complex), u0


@pytest.mark.parametrize("v,win,uneven", GRID)
def test_peak_1d_accepts_exactly_what_the_direct_check_accepts(v, win, uneven):
    st = steering(v, win, uneven)
    x, u0 = snapshots(st, v, v + 7 * uneven)
    k, lat, gc, gs, grid = st._grid_1d
    u, ok = np.empty(u0.size), np.zeros(u0.size, bool)
    kernels.peak_1d(k, lat, x, u0, gc, gs, grid, 4, u, ok)
    u_ref, ok_ref, direct, beaten = reference(st, x, u0)
    np.testing.assert_array_equal(ok, ok_ref)
    np.testing.assert_array_equal(u, u_ref)
    # both outcomes occur: peaks the check accepts at once, and converged peaks it must
    # reject (ambiguous starts at the weaker target, noise: a grid point has more power)
    assert 0.2 < direct.mean() < 0.95
    # (not V = 4 with a taper: the windowed ends leave a beam too wide for a second lobe)
    assert beaten.sum() >= 5 or (v == 4 and win != "none")


def test_peak_1d_on_a_grid_without_mirror_symmetry_is_the_direct_check():
    st = steering(8, "hann")
    x, u0 = snapshots(st, 8, 3)
    k, lat, gc, gs, grid = st._grid_1d
    keep = slice(0, gc.shape[1] - 3)  # an asymmetric grid: the kernel's bound does not apply
    gc, gs, grid = (np.ascontiguousarray(a[..., keep]) for a in (gc, gs, grid))
    assert not kernels._mirrored(gc, gs)
    u, ok = np.empty(u0.size), np.zeros(u0.size, bool)
    kernels.peak_1d(k, lat, x, u0, gc, gs, grid, 4, u, ok)
    st.__dict__["_grid_1d"] = (k, lat, gc, gs, grid)
    u_ref, ok_ref, _, _ = reference(st, x, u0)
    np.testing.assert_array_equal(ok, ok_ref)
    np.testing.assert_array_equal(u, u_ref)


def test_the_grid_bound_bounds_the_direct_powers():
    """_grid_bound >= every direct grid power, for tiny to huge and NaN snapshots."""
    for v in (4, 8, 13):
        st = steering(v, "hann")
        k, lat, gc, gs, grid = st._grid_1d
        half = (gc.shape[1] + 1) // 2
        scratch = [np.empty(half) for _ in range(4)]
        rng = np.random.default_rng(v)
        for scale in (1e-150, 1.0, 1e150):
            x = scale * (rng.standard_normal((200, v)) + 1j * rng.standard_normal((200, v)))
            x[:50] = scale * plane(st, rng.uniform(-1, 1, 50))
            for xn in x:
                br = (xn.real[:, None] * gc - xn.imag[:, None] * gs).sum(0)
                bi = (xn.real[:, None] * gs + xn.imag[:, None] * gc).sum(0)
                bound = kernels._grid_bound(xn, gc, gs, *scratch)
                assert bound >= (br * br + bi * bi).max()
                assert bound <= (br * br + bi * bi).max() * (1 + 1e-12) + 1e-300 * scale ** 2
        xn = np.full(v, np.nan + 0j)
        assert np.isnan(kernels._grid_bound(xn, gc, gs, *scratch))


@pytest.mark.parametrize("v,win,uneven", GRID[::3])
def test_steering_peak_is_the_same_whatever_the_batch_size(v, win, uneven, monkeypatch):
    """Steering.peak runs numpy or the kernel (``_util.use_kernels``: numpy while numba's
    set-up would cost more): the same u and the same decisions, so a calibration (a few
    thousand snapshots, numpy) and a Monte-Carlo study (millions, compiled) agree bit for
    bit on equal snapshots."""
    st = steering(v, win, uneven)
    x, u0 = snapshots(st, v, v + 7 * uneven)
    out = []
    for compiled in (True, False):
        monkeypatch.setattr(steering_mod, "use_kernels", lambda n, s: compiled)
        out.append(st.peak(x, u0[:, None]))
    np.testing.assert_array_equal(out[0][0], out[1][0])
    np.testing.assert_array_equal(out[0][1], out[1][1])


def test_use_kernels_rents_numpy_until_numba_would_be_cheaper(monkeypatch):
    """``_util.use_kernels``: numpy while a process's estimated numpy work stays below half
    of numba's set-up, the kernels from the batch that would pass it on, and always once
    the kernels are loaded."""
    from rtsgeom._lib import util as _util
    monkeypatch.setattr(_util, "_numpy_s", 0.0)
    assert _util.use_kernels(1, 1.0)  # loaded here (this module imports them)
    for m in _util.KERNEL_MODULES:
        monkeypatch.delitem(sys.modules, m, raising=False)
    half = _util.KERNEL_SETUP_S / 2
    assert not _util.use_kernels(1000, 0.4 * half / 1000)
    assert not _util.use_kernels(1000, 0.4 * half / 1000)
    assert _util.use_kernels(1000, 0.4 * half / 1000)  # would pass half the set-up
    assert _util.use_kernels(10 ** 9, 1e-6)
    assert not _util.use_kernels(10, 1e-6)  # small batches still fit the budget
