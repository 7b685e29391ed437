"""CA/OS-CFAR window and its cost for any ring the schema accepts.

The cell-averaging estimate at a cell under test is the mean of the training ring: the
(2(g_r+t_r)+1) x (2(g_d+t_d)+1) window minus the (2g_r+1) x (2g_d+1) guard window, both axes
cyclic. Checked on grids of guard/training sizes and map shapes against a direct sum.
"""

from __future__ import annotations

import time
import tracemalloc

import numpy as np
import pytest

from rtsgeom.radar.cfar import OS_MAX_CELLS, cfar_mask
from rtsgeom.scene import CfarConfig

WINDOWS = [((0, 0), (1, 1)), ((2, 2), (8, 4)), ((1, 3), (2, 5)), ((4, 0), (3, 2))]
SHAPES = [(64, 32), (128, 24), (40, 40)]


def ring_count(g, t) -> int:
    return (2 * (g[0] + t[0]) + 1) * (2 * (g[1] + t[1]) + 1) - (2 * g[0] + 1) * (2 * g[1] + 1)


def brute_ca(power, g, t):
    """The ring mean by explicit cyclic indexing (the definition)."""
    n_r, n_d = power.shape
    out = np.zeros_like(power)
    offs = [(a, b) for a in range(-(g[0] + t[0]), g[0] + t[0] + 1)
            for b in range(-(g[1] + t[1]), g[1] + t[1] + 1)
            if not (abs(a) <= g[0] and abs(b) <= g[1])]
    for a, b in offs:
        out += np.roll(np.roll(power, -a, 0), -b, 1)
    return out / len(offs)


@pytest.mark.parametrize("shape", SHAPES)
@pytest.mark.parametrize("g,t", WINDOWS)
def test_ca_ring_has_the_guard_and_training_cell_counts(shape, g, t):
    # a unit impulse: the noise estimate is 1/count exactly on the cells whose ring holds it
    p = np.zeros(shape)
    p[shape[0] // 2, shape[1] // 2] = 1.0
    noise = cfar_mask(p, CfarConfig("ca", g, t))[1]
    count = ring_count(g, t)
    hit = noise > 0.5 / count
    assert hit.sum() == count
    np.testing.assert_allclose(noise[hit], 1.0 / count, rtol=1e-9)
    # the guard window around the impulse (the cells that would guard it) does not see it
    r0, d0 = shape[0] // 2, shape[1] // 2
    assert not hit[r0 - g[0]:r0 + g[0] + 1, d0 - g[1]:d0 + g[1] + 1].any()


@pytest.mark.parametrize("g,t", WINDOWS)
@pytest.mark.parametrize("floor", [1.0, 3e-4])
def test_ca_guard_cell_energy_leaves_the_estimate_training_cell_energy_shifts_it(g, t, floor):
    shape = (64, 32)
    cut = (20, 10)
    flat = np.full(shape, floor)
    cfg = CfarConfig("ca", g, t)
    base = cfar_mask(flat, cfg)[1][cut]
    np.testing.assert_allclose(base, floor, rtol=1e-9)
    energy = 1e3 * floor
    if g != (0, 0):  # a guard cell next to the cell under test: no change
        p = flat.copy()
        p[cut[0] + g[0], cut[1] + g[1]] += energy
        assert cfar_mask(p, cfg)[1][cut] == pytest.approx(base, rel=1e-9)
    # the first training cell beyond the guard on the range axis: + energy / count
    p = flat.copy()
    p[cut[0] + g[0] + 1, cut[1]] += energy
    assert cfar_mask(p, cfg)[1][cut] == pytest.approx(base + energy / ring_count(g, t), rel=1e-9)
    # the outermost training cell counts, the next one out does not
    p = flat.copy()
    p[cut[0] + g[0] + t[0], cut[1] + g[1] + t[1]] += energy
    assert cfar_mask(p, cfg)[1][cut] == pytest.approx(base + energy / ring_count(g, t), rel=1e-9)
    p = flat.copy()
    p[cut[0] + g[0] + t[0] + 1, cut[1]] += energy
    assert cfar_mask(p, cfg)[1][cut] == pytest.approx(base, rel=1e-9)


@pytest.mark.parametrize("shape", SHAPES + [(16, 8)])
@pytest.mark.parametrize("g,t", WINDOWS + [((3, 2), (20, 9))])
def test_ca_equals_the_direct_ring_mean_with_wrap(shape, g, t):
    p = np.random.default_rng(shape[0] * 7 + t[0]).exponential(size=shape)
    np.testing.assert_allclose(cfar_mask(p, CfarConfig("ca", g, t))[1], brute_ca(p, g, t),
                               rtol=1e-10)


def test_ca_cost_does_not_grow_with_the_ring():
    # the schema accepts training cells up to 256 and guards up to 64 on each axis
    p = np.random.default_rng(0).exponential(size=(512, 128))
    tracemalloc.start()
    t0 = time.perf_counter()
    cfar_mask(p, CfarConfig("ca", (64, 64), (256, 256)))
    dt = time.perf_counter() - t0
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 12 * p.nbytes, peak  # O(map), not O(map x ring)
    assert dt < 2.0


def test_os_cost_is_bounded_and_small_rings_are_exact():
    rng = np.random.default_rng(3)
    p = rng.exponential(size=(48, 16))
    cfg = CfarConfig("os", (1, 1), (3, 2), os_rank=0.5)
    noise = cfar_mask(p, cfg)[1]
    # the median of the 9x7 - 3x3 = 54 ring cells at one cell, by hand
    r0, d0 = 10, 7
    vals = [p[(r0 + a) % 48, (d0 + b) % 16] for a in range(-4, 5) for b in range(-3, 4)
            if not (abs(a) <= 1 and abs(b) <= 1)]
    assert len(vals) == 54
    # scipy's percentile_filter rounds the rank to a cell: the value is one of the ring cells
    assert noise[r0, d0] in vals
    assert np.sum(np.array(vals) < noise[r0, d0]) in (26, 27)
    p = rng.exponential(size=(256, 64))
    t0 = time.perf_counter()
    cfar_mask(p, CfarConfig("os", (64, 64), (256, 256)))
    assert time.perf_counter() - t0 < 10 * (OS_MAX_CELLS / 512)


@pytest.mark.parametrize("g,t", WINDOWS)
def test_ca_estimate_far_from_a_strong_peak_is_exact(g, t):
    # a noise-free echo 120 dB above a quiet floor: the estimate away from the peak must be the
    # floor itself, not the rounding residue of running sums over the peak
    p = np.full((128, 32), 1e-3)
    p[40, 10] = 1e9
    noise = cfar_mask(p, CfarConfig("ca", g, t))[1]
    ref = brute_ca(p, g, t)
    far = ref < 1.0
    np.testing.assert_allclose(noise[far], ref[far], rtol=1e-9)
    np.testing.assert_allclose(noise, ref, rtol=1e-9)
