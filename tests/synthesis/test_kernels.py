"""The compiled kernels (``rtsgeom.synthesis.kernels``) against their definitions, on a grid of arrays
(uniform rows of V = 4, 8, 12, 16 elements at lambda/2, and an uneven one off the lattice)
and taper windows: the beamformer peak is a stationary maximum of P with no grid point of more
power and finds a plane wave's direction; the closed-form design puts the composite's peak on
the set angle; its compiled form gives the numpy definition's bits; the bin choice equals a
plain loop over the docstring's rule."""

from __future__ import annotations

import numpy as np
import pytest

from rtsgeom.synthesis import kernels
from rtsgeom.synthesis.kernels import SAME_DESIGN_LN
from rtsgeom.synthesis import pair as pair_design
from rtsgeom.synthesis.pair import beam_derivatives, design_ratio, detected_bin_choice
from rtsgeom.radar.steering import Steering
from rtsgeom.radar.windows import window

WAVELENGTH = 3.9e-3


def steering(v: int, win: str, uneven: bool = False) -> Steering:
    d = WAVELENGTH / 2
    x = (np.arange(v) - (v - 1) / 2) * d
    if uneven:  # off the lattice: every element's phasor by its own cosine and sine
        x = x + np.random.default_rng(v).uniform(-0.2, 0.2, v) * d
    return Steering(np.ones(v, bool), x[:, None], window(win, v), WAVELENGTH,
                    np.array([v * d]), pitch_m=d)


GRID = [(v, w, un) for v in (4, 8, 12, 16) for w in ("none", "hann", "blackman")
        for un in (False, True)]


def plane(st, u):
    return np.exp(-1j * st.wavevector[:, 0] * np.asarray(u)[..., None])


@pytest.mark.parametrize("v,win,uneven", GRID)
def test_peak_is_a_global_stationary_maximum(v, win, uneven):
    st = steering(v, win, uneven)
    rng = np.random.default_rng(v)
    n = 400
    u1 = rng.uniform(-0.7, 0.7, n)
    u2 = u1 + rng.uniform(0.1, 0.3, n) * rng.choice([-1, 1], n)
    x = plane(st, u1) + rng.uniform(0.2, 1, n)[:, None] * plane(st, u2) * np.exp(
        1j * rng.uniform(0, 2 * np.pi, n))[:, None]
    x = np.concatenate([x, x[:50] + 0.3 * (rng.standard_normal((50, v))
                                           + 1j * rng.standard_normal((50, v)))])
    u, ok = st.peak(x, np.concatenate([u1, u1[:50]])[:, None])
    assert ok.mean() > 0.9
    u, x = u[ok, 0], x[ok]
    p = np.einsum("nn->n", st.power(x, u[:, None]))
    grid = st.power(x, st.grid())
    assert np.all(p >= grid.max(axis=1) * (1 - 1e-9))  # the global check's property
    h = 1e-6  # stationary: P'(u) = 0 to the central difference's rounding, P'' < 0
    pp, pm = (np.einsum("nn->n", st.power(x, (u + s)[:, None])) for s in (h, -h))
    assert np.all(np.abs(pp - pm) / (2 * h) <= 1e-5 * p)
    assert np.all(pp + pm - 2 * p < 0)


@pytest.mark.parametrize("v,win,uneven", GRID)
def test_peak_finds_a_plane_wave(v, win, uneven):
    st = steering(v, win, uneven)
    u_true = np.linspace(-0.9, 0.9, 37)
    u, ok = st.peak(plane(st, u_true), (u_true + 0.02)[:, None])
    assert ok.all()
    np.testing.assert_allclose(u[:, 0], u_true, rtol=0, atol=1e-12)


@pytest.mark.parametrize("v,win,uneven", GRID)
def test_design_puts_the_composite_peak_on_the_set_angle(v, win, uneven):
    st = steering(v, win, uneven)
    beam = 2 / v  # null-to-null half width in u
    a_i, a_j = -0.3 * beam, 0.35 * beam
    x_i, x_j = plane(st, np.sin(a_i)), plane(st, np.sin(a_j))
    sets = np.linspace(a_i, a_j, 9)[1:-1]
    for phase in (0.0, 0.4, -0.7):
        rho = design_ratio(st, x_i, x_j, sets, phase)
        fine = np.isfinite(rho)
        assert fine.sum() >= 5 and np.all(rho[fine] >= 0)
        comp = x_i + rho[fine, None] * np.exp(1j * phase) * x_j
        u, ok = st.peak(comp, np.sin(sets[fine])[:, None])
        assert ok.all()
        np.testing.assert_allclose(u[:, 0], np.sin(sets[fine]), rtol=0, atol=1e-9)


@pytest.mark.parametrize("v,win,uneven", GRID[::2])
def test_ratio_kernel_gives_the_definitions_bits(v, win, uneven, monkeypatch):
    """``kernels.ratios`` (large batches) against ``pair_design._ratios`` (numpy, the definition,
    small batches), bit for bit: designs across the pair's span and beyond it
    (no root: NaN), J's phases, and degenerate beams (zero, a2 = 0, NaN, inf), through
    ratio_from_beams with either path forced."""
    st = steering(v, win, uneven)
    rng = np.random.default_rng(v + 100 * uneven)
    beam = 2 / v
    n = 3000
    a_i, a_j = rng.uniform(-0.6, -0.1, n) * beam, rng.uniform(0.1, 0.6, n) * beam
    sets = rng.uniform(-0.9, 0.9, n) * beam
    x_i = plane(st, np.sin(a_i)) * np.exp(1j * rng.uniform(-np.pi, np.pi, (n, 1)))
    x_j = plane(st, np.sin(a_j)) * rng.uniform(0.3, 3, (n, 1))
    x_j[:200] += 0.3 * (rng.standard_normal((200, v)) + 1j * rng.standard_normal((200, v)))
    u = np.sin(sets)
    b_i = list(beam_derivatives(st, x_i, u))
    b_j = list(beam_derivatives(st, x_j, u))
    b_j[0][:50] = 0          # no J beam
    b_j[1][50:100] = 0       # a2 = 0: the linear root
    b_i[1][100:150] = 0      # a0 = 0
    b_i[0][150:160] = np.nan
    b_j[2][160:170] = np.inf
    phase = rng.uniform(-np.pi, np.pi, n)
    out = []
    for compiled in (True, False):
        monkeypatch.setattr(pair_design, "use_kernels", lambda n, s: compiled)
        out.append(pair_design.ratio_from_beams(b_i, b_j, phase))
    np.testing.assert_array_equal(out[0], out[1])
    np.testing.assert_array_equal(np.signbit(out[0]), np.signbit(out[1]))
    fine = np.isfinite(out[0])
    assert 0.3 < fine.mean() < 0.97  # designs inside the span, none beyond it
    direct = np.empty(n)  # and the kernel called directly
    kernels.ratios(*(np.ascontiguousarray(a, complex) for a in (*b_i, *b_j)),
                   np.exp(1j * phase), direct)
    np.testing.assert_array_equal(direct, out[1])


def _choice_loop(rho, ph, p_ii, p_jj, c_ij):
    """The bin rule, written as plain loops over one row (the definition)."""
    n_k = rho.size
    fin = [bool(np.isfinite(r) and r > 0) for r in rho]
    power = np.zeros((n_k, n_k))
    det = []
    for kd in range(n_k):
        r = rho[kd] if fin[kd] else 0.0
        for kb in range(n_k):
            power[kd, kb] = p_ii[kb] + r * r * p_jj[kb] + 2 * r * np.real(
                np.exp(1j * ph[kd]) * c_ij[kb])
        det.append(int(np.argmax(power[kd])) if fin[kd] else 0)
    order = sorted(range(n_k), key=lambda k: (abs(k - n_k // 2), k))
    agree = [k for k in order if fin[k] and det[k] == k]
    if agree:
        k = agree[0]
        same = [b == k or (fin[b] and abs(np.log(rho[b] / rho[k])) <= SAME_DESIGN_LN)
                for b in range(n_k)]
        if np.isnan(power[k]).any():
            return rho[k], k, True, np.nan
        others = [power[k, b] for b in range(n_k) if not same[b]]
        return rho[k], k, True, (power[k, k] / max(max(others), 1e-300) if others else np.inf)
    k = det[n_k // 2]
    for _ in range(4):
        k = det[k]
    return rho[k], k, False, 1.0


@pytest.mark.parametrize("n_k", [3, 5, 7])
def test_bin_choice_equals_the_rule(n_k):
    rho, ph, p_ii, p_jj, c_ij = _choice_rows(n_k, non_finite=False)
    n = rho.shape[0]
    got = detected_bin_choice(rho, ph, p_ii, p_jj, c_ij)
    assert 0.05 < got[2].mean() < 0.999  # both branches taken
    assert 0 < np.isinf(got[3]).sum() < got[2].sum()  # every other bin equivalent, or not
    for i in range(n):
        ref = _choice_loop(rho[i], np.full(n_k, ph[i, 0]), p_ii[i], p_jj[i], c_ij[i])
        assert got[1][i] == ref[1] and got[2][i] == ref[2]
        np.testing.assert_allclose([got[0][i], got[3][i]], [ref[0], ref[3]], rtol=1e-12)


def _choice_rows(n_k: int, n: int = 3000, non_finite: bool = True):
    """Rows for the bin choice: ratios with NaN and non-positive bins, a third of the rows
    one design at every bin (within +-1.5 %: most bins equivalent), and (``non_finite``)
    rows whose power is NaN or inf at some bin (inf and NaN channel sums)."""
    rng = np.random.default_rng(n_k)
    rho = rng.uniform(-0.2, 2, (n, n_k))
    same = rng.random(n) < 0.3
    rho[same] = rho[same, n_k // 2, None] * (1 + rng.uniform(-0.015, 0.015, (same.sum(), n_k)))
    rho[rng.random((n, n_k)) < 0.15] = np.nan
    ph = rng.uniform(-np.pi, np.pi, (n, 1))
    p_ii, p_jj = rng.uniform(0, 1, (2, n, n_k)) ** 3
    c_ij = np.sqrt(p_ii * p_jj) * rng.uniform(0, 1, (n, n_k)) * np.exp(
        1j * rng.uniform(-np.pi, np.pi, (n, n_k)))
    if non_finite:
        bad = rng.random((n, n_k)) < 0.01
        p_jj[bad] = np.where(rng.random(bad.sum()) < 0.5, np.nan, np.inf)
    return rho, ph, p_ii, p_jj, c_ij


@pytest.mark.parametrize("n_k", [1, 3, 5, 7])
def test_bin_choice_kernel_gives_the_definitions_bits(n_k, monkeypatch):
    """``kernels.bin_choice_rows`` (large batches) against ``choice.bin_choice_rows_numpy``
    (small batches: a run of a few targets loads no numba), bit for bit, through
    detected_bin_choice with either path forced: both branches, equivalent bins, NaN and inf
    powers."""
    args = _choice_rows(n_k)
    out = []
    for compiled in (True, False):
        monkeypatch.setattr(pair_design, "use_kernels", lambda n, s: compiled)
        out.append(detected_bin_choice(*args))
    for a, b in zip(*out):
        assert a.dtype == b.dtype
        np.testing.assert_array_equal(a, b)
        np.testing.assert_array_equal(np.signbit(a), np.signbit(b))
    ok, margin = out[1][2], out[1][3]
    if n_k > 1:
        assert 0.05 < ok.mean() < 0.999  # both branches taken
        assert 0 < np.isinf(margin).sum() < ok.sum() and np.isnan(margin).any()


def test_numpy_definitions_are_as_silent_as_the_kernels():
    """inf, NaN and 1e300 beams: the numpy definition of the design ratio warns no more than
    the compiled kernel (a RuntimeWarning must not depend on which path a process took)."""
    import warnings

    from rtsgeom.synthesis.pair import _ratios
    z = np.array([1e300 + 1e300j, np.inf + 0j, np.nan + 0j, 1 + 1j])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = _ratios(z, z, z, z, z, z, np.ones(4, complex))
    assert out.shape == (4,) and np.all(np.isnan(out[:3]))
