"""The channel phasors' per-draw outputs read whole (``rtsgeom.analysis.tolerance.phasors``):
evaluate() against draw() (the worst set-point per draw, its counters, the calibration steps
and the range offsets from the air legs), the refused cases' messages, the procedure replaced,
the angle errors over leading axes."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.constants import c

from conftest import ROOT, two_front_end_pair
from rtsgeom.analysis.tolerance.phasors import (ALL_CASES, CASES, NOMINAL_AMPLITUDES,
                                                ChannelPhasors)
from rtsgeom.geometry import build_setup
from rtsgeom.scene import load_scene


@pytest.fixture(scope="module")
def models():
    cell = ChannelPhasors.build(build_setup(load_scene(ROOT / "scenes" / "sphere4.toml")),
                                points=4)
    return {"pair": two_front_end_pair(1.0)[1], "cell": cell}


def _offsets(model, n=5, seed=1, scale=2e-4):
    return np.random.default_rng(seed).standard_normal((n, len(model.front_ends), 3)) * scale


@pytest.mark.parametrize("kind", ["pair", "cell"])
def test_evaluate_in_full_against_the_draws(models, kind):
    """Per draw and case the worst set-point's signed error (a pair), the worst signed
    azimuth and elevation and the largest angular distance (a cell), in deg; the counts of
    unconverged peaks and of set-points off the set range's bin; the calibration steps and
    each channel's range offset from channel 0's (c/2 times the element-mean air delay plus
    its calibration delay)."""
    m = models[kind]
    off = _offsets(m)
    u = np.arange(5) % len(m.subbin_steps)
    cases = CASES + ((NOMINAL_AMPLITUDES,) if kind == "pair" else ())
    got = m.evaluate(off, cases, subbin=u)
    d = m.draw(off, u, cases)
    keys = {"steps", "range_offset_m"} | {f"{c_}{s}" for c_ in cases
                                          for s in ("", "_fallbacks", "_off_bin")}
    assert set(got) == keys
    steps = m.calibration_steps(m.channel_phasors(off))
    np.testing.assert_array_equal(got["steps"], steps)
    if kind == "pair":
        assert np.all(steps[:, 0] == 0)
    t_a, t_b = m.air_legs(off)
    tot = (t_a + t_b).mean(-1) + steps * m.delay_resolution_s
    np.testing.assert_allclose(got["range_offset_m"], c / 2 * (tot - tot[:, :1]), rtol=1e-12,
                               atol=1e-18)
    assert np.all(got["range_offset_m"][:, 0] == 0)
    for case in cases:
        e = np.degrees(d[case]["error_rad"])
        want = []
        for i in range(5):
            if kind == "pair":
                want.append([e[i][np.argmax(np.abs(e[i]))]])
            else:
                az, el = e[i, :, 0], e[i, :, 1]
                want.append([az[np.argmax(np.abs(az))], el[np.argmax(np.abs(el))],
                             np.degrees(d[case]["distance_rad"][i].max())])
        np.testing.assert_array_equal(got[case], np.array(want))
        assert got[case + "_fallbacks"] == int(np.sum(~d[case]["converged"]))
        assert got[case + "_off_bin"] == int(np.sum(d[case]["bin"] != 0))
    assert m.columns == (("angle",) if kind == "pair" else
                         ("azimuth", "elevation", "angular_distance"))
    assert m.dims == (1 if kind == "pair" else 2)
    assert m.subbin_steps[m.subbin_zero] == 0


@pytest.mark.parametrize("kind", ["pair", "cell"])
def test_a_procedure_replaced_and_the_blocks_change_no_bit(models, kind):
    """with_procedure: a copy whose procedure has the fields given (the model itself and its
    other fields unchanged); evaluated in blocks of 2 draws, every output bit for bit the
    unblocked one's, the counters summed over the blocks."""
    m = models[kind]
    small = m.with_procedure(block_draws=2)
    assert small.procedure.block_draws == 2
    assert m.procedure.block_draws == {"pair": 1000, "cell": 500}[kind]
    assert type(small.procedure) is type(m.procedure)
    assert small.channels is m.channels and small.table is m.table
    off = _offsets(m, n=5, seed=4, scale=1e-3)
    a, b = m.evaluate(off), small.evaluate(off)
    assert a.keys() == b.keys()
    for k in a:
        np.testing.assert_array_equal(a[k], b[k])
    e = m.evaluate(np.zeros((0, len(m.front_ends), 3)))
    assert all(np.size(e[case]) == 0 for case in CASES) and e["steps"].shape[0] == 0


def test_the_cases_a_draw_refuses(models):
    """A pair takes every case; a cell not the nominal amplitudes (designed once): each
    refusal names the case and what the model takes."""
    from conftest import assert_refused
    assert ALL_CASES == CASES + (NOMINAL_AMPLITUDES,) == ("uncalibrated", "calibrated",
                                                          "calibrated_nominal_amplitudes")
    pair, cell = models["pair"], models["cell"]
    z2, z4 = np.zeros((1, 2, 3)), np.zeros((1, 4, 3))
    assert set(pair.draw(z2, None, ALL_CASES)) == {"steps", *ALL_CASES}
    assert_refused(lambda: pair.draw(z2, None, ("raw",)),
                   "case 'raw': must be one of uncalibrated, calibrated, "
                   "calibrated_nominal_amplitudes",
                   ValueError)
    assert_refused(lambda: cell.draw(z4, None, (NOMINAL_AMPLITUDES,)),
                   "case 'calibrated_nominal_amplitudes': must be one of uncalibrated, "
                   "calibrated",
                   ValueError)
    assert_refused(lambda: cell.draw(z4, None, ("calibrated", "raw")),
                   "case 'raw': must be one of uncalibrated, calibrated", ValueError)


@pytest.mark.parametrize("kind", ["pair", "cell"])
def test_angle_errors_over_leading_axes(models, kind):
    """angle_errors on offsets (2, 3, Q, 3): the draw's errors in deg shaped (2, 3, M[, 2]),
    and with return_converged the peaks' convergence (2, 3, M); the sub-bin position
    broadcast over the leading axes; the calibrated case by default."""
    m = models[kind]
    off = _offsets(m, n=6, seed=7).reshape((2, 3) + (len(m.front_ends), 3))
    flat = off.reshape((6,) + off.shape[2:])
    d = m.draw(flat, np.full(6, 1), ("calibrated",))["calibrated"]
    e, ok = m.angle_errors(off, return_converged=True, subbin=1)
    want = np.degrees(d["error_rad"])
    np.testing.assert_array_equal(e, want.reshape((2, 3) + want.shape[1:]))
    np.testing.assert_array_equal(ok, d["converged"].reshape(2, 3, -1))
    u = m.draw(flat, None, ("uncalibrated",))["uncalibrated"]
    np.testing.assert_array_equal(m.angle_errors(off, "uncalibrated"),
                                  np.degrees(u["error_rad"]).reshape(e.shape))
