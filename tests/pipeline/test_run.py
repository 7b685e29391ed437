"""A run's summary: one row per target up to twelve, the rest counted, the cube and the first
warning."""

from __future__ import annotations

import numpy as np
import pytest


@pytest.mark.parametrize("n", [1, 11, 12, 13, 20])
def test_a_run_summary_lists_twelve_targets_and_counts_the_rest(n):
    """One row per target up to twelve (each one's errors in mm, m/s and deg, or 'not
    detected'), then '... N more targets'; the first warning and their count."""
    from types import SimpleNamespace
    from rtsgeom.pipeline.run import MAX_SUMMARY_TARGETS, RunResult
    assert MAX_SUMMARY_TARGETS == 12
    matches = [{"index": k, "error": None if k % 3 == 2 else
                {"range_m": 0.0012 * k, "velocity_mps": -0.01, "angle_deg": 0.0002 * k}}
               for k in range(n)]
    fake = SimpleNamespace(scene=SimpleNamespace(name="bench", targets=(None,) * n),
                           aoa_mode="exact", cube=SimpleNamespace(data=np.zeros((4, 8, 16)),
                                                                  clipped=0),
                           detections=SimpleNamespace(range_m=np.zeros(5)), matches=matches,
                           warnings=["first", "second"])
    title, rows = RunResult._summary(fake)
    assert title == f"bench: one frame, {n} targets, exact amplitudes"
    assert rows[:2] == [("cube", "4x8x16 ADC samples"), ("detections", 5)]
    listed = rows[2:2 + min(n, 12)]
    assert listed[0] == ("target 0", "error +0.0 mm, -0.01 m/s, +0.0000 deg")
    if n > 1:
        assert listed[1] == ("target 1", "error +1.2 mm, -0.01 m/s, +0.0002 deg")
    if n > 2:
        assert listed[2] == ("target 2", "not detected")
    more = [("...", f"{n - 12} more targets")] if n > 12 else []
    assert rows[2 + min(n, 12):] == more + [("warnings", "2: first")]
    clipped = SimpleNamespace(**{**vars(fake), "cube": SimpleNamespace(
        data=np.zeros((4, 8, 16)), clipped=7), "warnings": []})
    t2, r2 = RunResult._summary(clipped)
    assert r2[0] == ("cube", "4x8x16 ADC samples, 7 CLIPPED") and r2[-1] == ("warnings", "none")
