"""SweepConfig, the calibration sweep's settings: each refused value in full words (never a
traceback: NaN, infinity, text or a span of the wrong length included), whole frame counts
taken as integers, unknown settings named."""

from __future__ import annotations

import math

import numpy as np
import pytest

from conftest import assert_refused
from rtsgeom.calibration.sweep import SweepConfig

SPAN = "span_s: must be two finite delays, low < high; got "
STEP = "step_s: must be a positive delay (s); got "
FRAMES = "frames: must be a whole number >= 1; got "


@pytest.mark.parametrize("span, shown", [
    ((1e-9, 1e-9), "(1e-09, 1e-09)"), ((2e-9, 1e-9), "(2e-09, 1e-09)"),
    ((0.0, math.inf), "(0.0, inf)"), ((math.nan, 1e-9), "(nan, 1e-09)"), ((1e-9,), "(1e-09,)"),
    ((0.0, 1e-9, 2e-9), "(0.0, 1e-09, 2e-09)"), (("a", 1e-9), "('a', 1e-09)"), (3e-9, "3e-09")])
def test_a_span_is_two_finite_delays_low_first(span, shown):
    assert_refused(lambda: SweepConfig(span_s=span), SPAN + shown)


@pytest.mark.parametrize("step, shown", [(0.0, "0.0"), (-1e-12, "-1e-12"), (math.inf, "inf"),
                                         (math.nan, "nan"), ("25e-12", "25e-12"),
                                         (True, "True")])
def test_a_step_is_a_positive_delay(step, shown):
    assert_refused(lambda: SweepConfig(step_s=step), STEP + shown)


@pytest.mark.parametrize("frames, shown", [(0, "0"), (-3, "-3"), (1.5, "1.5"), ("2", "2"),
                                           (math.nan, "nan"), (math.inf, "inf"),
                                           (True, "True")])
def test_frames_are_a_whole_number_of_one_or_more(frames, shown):
    assert_refused(lambda: SweepConfig(frames=frames), FRAMES + shown)


def test_accepted_settings_are_normalised():
    s = SweepConfig(span_s=[np.float32(0.0), 1], step_s=25e-12, frames=2.0)
    assert s.span_s == (0.0, 1.0) and type(s.span_s[1]) is float
    assert s.frames == 2 and type(s.frames) is int
    assert SweepConfig(frames=np.int64(1)).frames == 1
    assert SweepConfig(span_s=np.array([-1e-9, 2e-9])).span_s == (-1e-9, 2e-9)
    assert SweepConfig(step_s=np.float64(1e-12)).step_s == 1e-12
    d = SweepConfig()
    assert (d.span_s, d.step_s, d.frames, d.full_chain, d.seed) == (None, None, None, False, 0)


def test_evolve_names_unknown_settings():
    assert SweepConfig().evolve(seed=3) == SweepConfig(seed=3)
    assert_refused(lambda: SweepConfig().evolve(seeds=3, span=1),
                   "['seeds', 'span']: not a sweep setting; allowed: ['span_s', 'step_s', "
                   "'frames', 'full_chain', 'seed']")
    assert_refused(lambda: SweepConfig().evolve(frames=0), FRAMES + "0")


def test_a_sweep_that_detects_no_probe_at_any_step_is_refused_naming_the_pair(cal_setup):
    """``run_sweep`` on probes never detected (every error NaN): one ``CalibrationFailed``
    naming the pair, before any fine sweep."""
    from rtsgeom.calibration.sweep import run_sweep
    from rtsgeom.errors import CalibrationFailed
    setup, _ = cal_setup
    asked = []

    class Blind:
        pair, period_s = (2, 3), 1 / setup.scene.radar.f_c_hz

        def __init__(self):
            self.setup = setup

        def measure(self, t, frames, repeat=None):
            asked.append((len(t), frames))
            return np.full((len(t), 4), np.nan)

        def frame_noise_deg(self, grid):
            return None

    for frames in (None, 3):
        assert_refused(lambda: run_sweep(Blind(), SweepConfig(frames=frames)),
                       "pair (2, 3): no probe detected at any step of the sweep",
                       CalibrationFailed)
    rts = setup.scene.rts
    n = len(np.arange(rts.calibration_span_s[0], rts.calibration_span_s[1]
                      + rts.calibration_step_s / 2, rts.calibration_step_s))
    assert [a[0] for a in asked] == [n, n] and asked[1][1] == 3


# -- the calibration result: every field through to_dict / from_dict, its summary whole -----

def _calibration(dims=2):
    """A made-up calibration with a non-default value in every field (a refinement sweep, a
    missed step as NaN, 2-D probe angles)."""
    from rtsgeom.calibration.sweep import Calibration
    from rtsgeom._lib.util import frozen
    angles = ((1.5, -2.25), (3.0, 0.5)) if dims == 2 else (1.5, 3.0)
    return Calibration(
        pair=(2, 3), delta_tau_s=37e-12, residual_error_deg=0.0123, range_offset_m=4.5e-3,
        sweep_delta_tau_s=frozen([-50e-12, 0.0, 50e-12]),
        sweep_error_deg=frozen([1.25, np.nan, 0.75]),
        refine_delta_tau_s=frozen([30e-12, 35e-12, 40e-12, 45e-12]),
        refine_error_deg=frozen([0.5, 0.25, np.nan, 0.625]),
        probe_angles_deg=angles, period_s=83.3e-12, frames_per_step=3, frame_noise_deg=0.042,
        method="chain", probe_ranges_m=(4.9, 5.1), one_frame_scatter_ps=1.75,
        quantisation_residual_s=-1.2e-12, delay_resolution_s=5e-12, coarse_frames_per_step=2,
        coarse_minimum_s=36e-12, fit_columns=(0, 1, 3), odd_columns=(1,), dims=dims)


def _same(a, b):
    import dataclasses
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, np.ndarray):
            np.testing.assert_array_equal(x, y, err_msg=f.name)
            assert y.dtype == float, f.name
        else:
            assert type(x) is type(y) and x == y, (f.name, x, y)


@pytest.mark.parametrize("dims", [1, 2])
def test_a_calibration_goes_through_its_dict_field_by_field(dims):
    from rtsgeom.calibration.sweep import Calibration
    cal = _calibration(dims)
    d = cal.to_dict()
    pts = lambda t, e: [{"delta_tau_s": float(a), "angle_error_deg":  # noqa: E731
                         None if np.isnan(b) else float(b)} for a, b in zip(t, e)]
    assert d == {
        "pair": [2, 3], "delta_tau_s": 37e-12, "residual_error_deg": 0.0123,
        "range_offset_m": 4.5e-3, "period_s": 83.3e-12, "frames_per_step": 3,
        "frame_noise_deg": 0.042, "method": "chain", "probe_ranges_m": [4.9, 5.1],
        "one_frame_scatter_ps": 1.75, "quantisation_residual_s": -1.2e-12,
        "delay_resolution_s": 5e-12, "coarse_frames_per_step": 2, "coarse_minimum_s": 36e-12,
        "fit_s": 37e-12 - 1.2e-12, "fit_columns": [0, 1, 3], "odd_columns": [1], "dims": dims,
        "points": 3 + 4 + 1,
        "probe_angles_deg": [list(a) for a in cal.probe_angles_deg] if dims == 2
        else list(cal.probe_angles_deg),
        "sweep": pts(cal.sweep_delta_tau_s, cal.sweep_error_deg),
        "refinement": pts(cal.refine_delta_tau_s, cal.refine_error_deg)}
    _same(cal, Calibration.from_dict(d))
    import json
    _same(cal, Calibration.from_dict(json.loads(json.dumps(d))))  # as a file holds it


def test_a_calibration_dict_with_only_the_required_keys_takes_the_defaults():
    from rtsgeom.calibration.sweep import Calibration
    got = Calibration.from_dict({"pair": [0, 1], "delta_tau_s": 1e-12,
                                 "residual_error_deg": None, "period_s": None,
                                 "frame_noise_deg": None})
    assert got.pair == (0, 1) and got.delta_tau_s == 1e-12
    assert np.isnan(got.residual_error_deg) and np.isnan(got.period_s)
    assert np.isnan(got.frame_noise_deg)
    assert np.isnan(got.coarse_minimum_s) and np.all(np.isnan(got.probe_angles_deg))
    assert len(got.probe_angles_deg) == 2
    for name in ("sweep_delta_tau_s", "sweep_error_deg", "refine_delta_tau_s",
                 "refine_error_deg"):
        assert getattr(got, name).shape == (0,) and getattr(got, name).dtype == float, name
    assert (got.range_offset_m, got.frames_per_step, got.method, got.probe_ranges_m,
            got.one_frame_scatter_ps, got.quantisation_residual_s, got.delay_resolution_s,
            got.coarse_frames_per_step, got.fit_columns, got.odd_columns, got.dims) == (
        0.0, 1, "phasor", (), 0.0, 0.0, 0.0, 1, (), (), 1)


@pytest.mark.parametrize("dims", [1, 2])
def test_a_calibrations_summary_and_columns_whole(dims):
    cal = _calibration(dims)
    title, rows = cal._summary()
    assert title == f"pair (2, 3) phase calibration (chain, {dims}-D)"
    assert rows == [
        ("delta_tau", f"{37e-12 * 1e12:.2f} ps (fit {(37e-12 - 1.2e-12) * 1e12:.2f} ps, "
                      f"{5e-12 * 1e12:g} ps steps)"),
        ("residual_error", f"{0.0123:.4g} deg"),
        ("range_offset", f"{4.5e-3 * 1e3:.3g} mm"),
        ("period", f"{83.3e-12 * 1e12:.1f} ps (eq. 27)"),
        ("sweep", "3 coarse + 4 fine steps, 3 frame(s) a fine step"),
        ("frame_noise", f"{0.042:.3g} deg (1 sigma, one frame)"),
        ("one_frame_scatter", f"{1.75:.3g} ps"),
        ("probe_angles_deg", cal.probe_angles_deg)]
    cols = cal._columns()
    assert list(cols) == ["stage", "delta_tau_ps", "angle_error_deg"]
    assert cols["stage"] == ["coarse"] * 3 + ["fine"] * 4
    np.testing.assert_array_equal(cols["delta_tau_ps"], 1e12 * np.r_[
        cal.sweep_delta_tau_s, cal.refine_delta_tau_s])
    np.testing.assert_array_equal(cols["angle_error_deg"], np.r_[
        cal.sweep_error_deg, cal.refine_error_deg])
    assert cal.fit_s == 37e-12 + -1.2e-12
