"""Tests of ``rtsgeom.calibration.fit``: closed forms and invariants on grids of inputs."""

from __future__ import annotations

import math

import numpy as np
import pytest


@pytest.mark.parametrize("true_ps", [-3.0, 0.0, 7.4])
@pytest.mark.parametrize("bad_rows", [(), (2,), (0, 5, 11)])
@pytest.mark.parametrize("vertex_deg", [0.0, 0.01])
def test_fit_centre_finds_the_centre_of_symmetry_despite_lost_steps_and_biased_vertices(
        true_ps, bad_rows, vertex_deg):
    """Probe errors even about delta_0 with a second harmonic, e_p = c_p (1 - cos) + d_p
    sin^2 + v_p, their vertices v_p off zero in opposite directions (a mounting offset's
    amplitude error): the centre of symmetry is delta_0 within 0.01 ps, also when some
    steps lost a probe (NaN: no detection; only that probe's step is dropped), while the
    probes' RMS minimum is not (it is pulled towards the deeper vertex)."""
    from rtsgeom.calibration.fit import CentreFit, fit_centre
    period, step = 1.0e-9, 25e-12
    near = 0.0
    d = near + np.arange(-10, 11) * step
    th = 2 * np.pi * (d - true_ps * 1e-12) / period
    v = np.radians(vertex_deg)
    e = np.stack([0.8 * (1 - np.cos(th)) + 0.05 * np.sin(th) ** 2 - v,
                  -0.5 * (1 - np.cos(th)) + 2 * v], axis=1) * np.radians(0.1)
    for r in bad_rows:
        e[r, r % 2] = np.nan
    got = fit_centre(d, e, period, near, CentreFit(search_s=period / 8))
    assert got == pytest.approx(true_ps * 1e-12, abs=0.01e-12)


@pytest.mark.parametrize("offset_steps", [-3.2, 2.6, 4.0])
def test_fit_centre_searches_the_half_width_it_is_given(offset_steps):
    """The curves' centre ``offset_steps`` sweep steps from the coarse minimum: the default
    search (1.5 steps either side) stops at its edge, a ``search_s`` of 5 steps finds the
    centre within 0.05 ps."""
    from rtsgeom.calibration.fit import CentreFit, fit_centre
    period, step = 1.0e-9, 25e-12
    d = np.arange(-20, 21) * step
    true = offset_steps * step
    th = 2 * np.pi * (d - true) / period
    e = np.stack([0.8 * (1 - np.cos(th)), -0.5 * (1 - np.cos(th))], axis=1)
    near = fit_centre(d, e, period, 0.0)
    assert near == pytest.approx(math.copysign(1.5 * step, offset_steps), abs=0.051e-12)
    wide = fit_centre(d, e, period, 0.0, CentreFit(search_s=5 * step))
    assert wide == pytest.approx(true, abs=0.051e-12)
