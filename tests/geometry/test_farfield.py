"""The azimuth array's period, grating lobes and unambiguous sector
(``rtsgeom.geometry.farfield``) at their edges, on arrays built in the test."""

from __future__ import annotations

import numpy as np
import pytest

from rtsgeom.geometry.arrays import array_from_spec
from rtsgeom.geometry.farfield import (coarray_period_m, grating_lobe_directions_rad,
                                       smallest_spacing_m, unambiguous_half_width_rad)
from rtsgeom.scene.presets import ArraySpec

LAM = 3.9e-3


def _rx_row(xs, spacing=None):
    return array_from_spec(ArraySpec(((0.0, 0.0),), tuple((x, 0.0) for x in xs), (0,),
                                     spacing_m=spacing), LAM)


@pytest.mark.parametrize("units, n", [((0, 1, 2), 1), ((0, 3, 7), 3), ((0, 2, 5), 2),
                                      ((0, 5, 12), 5)])
def test_the_period_is_the_smallest_spacing_over_the_fewest_divisor(units, n):
    """Positions k g0: the period the smallest gap over the first n that puts every position
    on the grid; a max_divisor below n finds none."""
    g0 = 0.7e-3
    rut = _rx_row([u * g0 for u in units])
    dmin = min(np.diff(units)) * g0
    assert coarray_period_m(rut) == pytest.approx(dmin / n, rel=1e-12)
    assert smallest_spacing_m(rut) == pytest.approx(dmin, rel=1e-12)
    if n > 1:
        assert coarray_period_m(rut, max_divisor=n - 1) is None
    assert coarray_period_m(rut, max_divisor=n) == pytest.approx(dmin / n, rel=1e-12)
    assert coarray_period_m(_rx_row([0.0])) is None


def test_the_periods_tolerance_on_both_sides():
    g = 1e-3
    off = _rx_row([0.0, g, 2 * g + 5e-10])  # 0.5 nm off the grid: within 1 nm
    assert coarray_period_m(off) == pytest.approx(g, rel=1e-6)
    assert coarray_period_m(off, tol_m=4e-10, max_divisor=1) is None


@pytest.mark.parametrize("g_lam, steer_deg", [(1.0, 0.0), (2.0, 0.0), (1.5, 10.0), (0.5, 0.0),
                                              (0.75, 30.0)])
def test_grating_lobes_where_the_steering_repeats(g_lam, steer_deg):
    """sin a = sin s + m lambda / g, m != 0, within [-1, 1] (endfire included): ascending;
    the unambiguous half-width asin(min(1, lambda / 2 g))."""
    g = g_lam * LAM
    rut = _rx_row([0.0, g, 2 * g, 3 * g], spacing=g)
    s = np.sin(np.radians(steer_deg))
    want = [np.arcsin(np.clip(s + m / g_lam, -1, 1)) for m in range(-8, 9)
            if m and abs(s + m / g_lam) <= 1 + 1e-9]
    got = grating_lobe_directions_rad(rut, np.radians(steer_deg))
    np.testing.assert_allclose(got, np.sort(want), atol=1e-9)
    assert np.all(np.diff(got) > 0)
    assert unambiguous_half_width_rad(rut) == pytest.approx(np.arcsin(min(1.0, 1 / (2 * g_lam))),
                                                            rel=1e-9)
    if g_lam == 1.0:
        np.testing.assert_allclose(got, [-np.pi / 2, np.pi / 2], atol=1e-6)  # endfire


def test_an_aperiodic_array_has_no_grating_lobe_and_the_whole_sector():
    rut = _rx_row([0.0, 1e-3, 1e-3 * (1 + np.sqrt(2))])
    assert coarray_period_m(rut) is None
    assert grating_lobe_directions_rad(rut).shape == (0,)
    assert unambiguous_half_width_rad(rut) == pytest.approx(np.pi / 2)
