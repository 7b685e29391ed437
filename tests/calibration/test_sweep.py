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
