"""A played drive's figure draws what was played: per mode, the set azimuth where the target
is tracked, the detected azimuth as dots, their difference below."""

from __future__ import annotations

import numpy as np
import pytest

import rtsgeom
from pipeline.test_scenario import crossing_doc, scene_of
from rtsgeom.analysis.playback.result import PlaybackResult


@pytest.fixture(scope="module")
def played():
    """The bundled crossing at 6 frames (0.4 s apart), the synthesis and the baseline."""
    return rtsgeom.play(scene_of(crossing_doc(frame_period_s=0.4)))


def test_the_figure_draws_the_set_and_detected_azimuths_of_each_mode(played):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig = played.plot()
    modes = [played, played.baseline]
    assert isinstance(played, PlaybackResult) and isinstance(played.baseline, PlaybackResult)
    assert played.baseline is not None and played.mode != played.baseline.mode
    t = np.asarray(played.time_s, float)
    set_deg = np.where(played.tracked, played.set["azimuth_deg"], np.nan)[:, 0]
    for col, run in enumerate(modes):
        top, bottom = fig.axes[col], fig.axes[len(modes) + col]
        det = np.where(run.tracked, run.detected["azimuth_deg"], np.nan)[:, 0]
        lines = top.get_lines()
        assert np.array_equal(lines[0].get_xdata(), t)
        assert np.array_equal(lines[0].get_ydata(), set_deg, equal_nan=True)
        assert np.array_equal(lines[1].get_ydata(), det, equal_nan=True)
        assert np.all(np.isfinite(det))  # the crossing is tracked in every frame
        assert np.allclose(bottom.get_lines()[0].get_ydata(), det - set_deg, rtol=0, atol=1e-12)
    plt.close(fig)
