"""The figure of a played drive (``rtsgeom play``): set and detected azimuth over time with
the hand-overs marked, and the angle error, per AoA mode side by side."""

from __future__ import annotations

from typing import Mapping

import numpy as np
from matplotlib.figure import Figure

from .figures import _styled, new_figure

__all__ = ["playback_figure"]


@_styled
def playback_figure(time_s, set_deg, detected_deg: Mapping[str, np.ndarray],
                    handovers_s: Mapping[str, list], title: str = "") -> Figure:
    """One column per AoA mode: top, the set azimuth (lines) and the detected one (dots) of
    every target over time; bottom, the detected minus set azimuth. Dotted vertical lines:
    the frames where a target changed the front ends that carry it (hand-overs).

    Parameters
    ----------
    time_s : (F,) frame times
    set_deg : (F, T) set azimuths
    detected_deg : mode -> (F, T) detected azimuths (NaN where lost)
    handovers_s : mode -> times of the hand-overs
    """
    t = np.asarray(time_s, float)
    s = np.asarray(set_deg, float).reshape(t.size, -1)
    modes = list(detected_deg)
    fig, axes = new_figure(figsize=(4.2 * len(modes) + 0.6, 5.6), nrows=2, ncols=len(modes),
                           sharex=True)
    axes = np.asarray(axes).reshape(2, len(modes))
    for col, mode in enumerate(modes):
        d = np.asarray(detected_deg[mode], float).reshape(t.size, -1)
        top, bottom = axes[0, col], axes[1, col]
        for k in range(s.shape[1]):
            line, = top.plot(t, s[:, k], lw=1.0, label=f"target {k} set")
            top.plot(t, d[:, k], "o", ms=3.5, color=line.get_color(), label=f"target {k} "
                     "detected")
            bottom.plot(t, d[:, k] - s[:, k], "o-", ms=3, lw=0.8, color=line.get_color())
            lost = ~np.isfinite(d[:, k])
            if np.any(lost):
                top.plot(t[lost], s[lost, k], "x", color="red", ms=6,
                         label=f"target {k} lost")
        for i, th in enumerate(handovers_s.get(mode, [])):
            for ax in (top, bottom):
                ax.axvline(th, color="0.4", ls=":", lw=0.9,
                           label="hand-over" if (i == 0 and ax is top) else None)
        top.set_title(f"{title + ': ' if title else ''}{mode}")
        top.set_ylabel("azimuth (deg)")
        bottom.set_ylabel("detected - set azimuth (deg)")
        bottom.set_xlabel("time (s)")
        top.legend(loc="best")
    return fig
