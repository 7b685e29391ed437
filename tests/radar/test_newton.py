"""Tests of ``rtsgeom.radar.newton``: closed forms and invariants on grids of inputs."""

from __future__ import annotations

import numpy as np
import pytest

from rtsgeom.radar.newton import parabolic


@pytest.mark.parametrize("vertex", [-0.49, -0.2, 0.0, 0.13, 0.4])
@pytest.mark.parametrize("curv", [-0.3, -2.0, -40.0])
def test_parabolic_offset_is_the_vertex_of_the_parabola(vertex, curv):
    y = curv * (np.array([-1.0, 0.0, 1.0]) - vertex) ** 2 + 5.0
    assert float(parabolic(*y)) == pytest.approx(vertex, abs=1e-12)


@pytest.mark.parametrize("y", [(1.0, 0.8, 1.1), (1.0, 0.5, 0.9), (0.0, 0.0, 0.0), (2.0, 1.0, 0.0)])
def test_parabolic_is_zero_where_the_middle_sample_is_no_peak(y):
    """Convex or flat samples (y0 - 2 y1 + y2 >= 0) have no vertex to move to: offset 0."""
    assert float(parabolic(*y)) == 0.0


def _snapshots(rng, n_d, u_true, snr=30.0):
    """Snapshots (V_s, n) of a uniform 4 x 3 (D = 2) or 8-element (D = 1) half-wavelength
    array, one source per snapshot at ``u_true`` (n, D), a taper and a little noise: the
    wavevector rows kv (V_s, D) and x split in real and imaginary parts."""
    if n_d == 1:
        kv = np.pi * np.arange(8.0)[:, None]
    else:
        gx, gy = np.meshgrid(np.arange(4.0), np.arange(3.0), indexing="ij")
        kv = np.pi * np.stack([gx.ravel(), gy.ravel()], axis=1)
    taper = 0.6 + 0.4 * rng.random(kv.shape[0])
    x = taper[:, None] * np.exp(-1j * kv @ u_true.T)
    x += (rng.normal(size=x.shape) + 1j * rng.normal(size=x.shape)) / snr
    return kv, x.real.copy(), x.imag.copy()


def _fd_newton_step(kv, x, u, h=1e-4):
    """The Newton step on log P at ``u`` (D,) from central differences: -H^-1 g."""
    def f(v):
        return np.log(np.abs(np.sum(x * np.exp(1j * (kv @ v)))) ** 2)
    n_d = u.size
    e = np.eye(n_d) * h
    g = np.array([(f(u + e[a]) - f(u - e[a])) / (2 * h) for a in range(n_d)])
    hess = np.array([[(f(u + e[a] + e[b]) - f(u + e[a] - e[b]) - f(u - e[a] + e[b])
                       + f(u - e[a] - e[b])) / (4 * h * h) for b in range(n_d)]
                     for a in range(n_d)])
    return -np.linalg.solve(hess, g), f(u)


@pytest.mark.parametrize("n_d", [1, 2])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_one_newton_step_is_the_step_of_the_central_differences_of_log_p(n_d, seed):
    """``newton`` (D = 1, 2) and ``newton_1d`` with one step: the step -H^-1 g of log P from its
    analytic gradient and Hessian equals the one from central differences of log P on a grid
    of snapshots and starting points near their peaks (a wrong factor in a derivative moves
    the step), and the power told is P at the start."""
    from rtsgeom.radar.newton import STEP_CLIP, lattice, newton, newton_1d
    rng = np.random.default_rng(seed)
    n = 6
    u_true = rng.uniform(-0.5, 0.5, (n, n_d))
    kv, xr, xi = _snapshots(rng, n_d, u_true)
    u0 = u_true + rng.uniform(-0.01, 0.01, (n, n_d))
    want = np.array([_fd_newton_step(kv, (xr + 1j * xi)[:, i], u0[i])[0] for i in range(n)])
    p0 = np.exp([_fd_newton_step(kv, (xr + 1j * xi)[:, i], u0[i])[1] for i in range(n)])
    assert np.all(np.abs(want) < STEP_CLIP) and np.max(np.abs(want)) > 1e-4  # not a no-op
    u1, _, p = newton(kv, xr, xi, u0, None, 1)
    np.testing.assert_allclose(u1 - u0, want, rtol=1e-4, atol=1e-8)
    np.testing.assert_allclose(p, p0, rtol=1e-10)
    if n_d == 1:
        k = kv[:, 0]
        u1d, _, p1d = newton_1d(k, lattice(k, np.pi), xr, xi, u0[:, 0], 1)
        np.testing.assert_allclose(u1d - u0[:, 0], want[:, 0], rtol=1e-4, atol=1e-8)
        np.testing.assert_allclose(p1d, p0, rtol=1e-10)
