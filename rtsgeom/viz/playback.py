"""The figure of a played drive (``rtsgeom play``): set and detected azimuth over time with
the hand-overs marked, and the angle error, per AoA mode side by side."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

import numpy as np
from matplotlib.figure import Figure

from .figures import _styled, new_figure

__all__ = ["playback_figure"]

#: targets named one by one in the legend; beyond, the legend names the marks (set, detected,
#: lost) once and each target is a colour (64 targets gave a legend of 192 entries, larger
#: than the figure, and matplotlib's warning about it)
LEGEND_TARGETS = 8


@_styled
def playback_figure(time_s, set_deg, detected_deg: Mapping[str, np.ndarray],
                    handovers_s: Mapping[str, list], title: str = "",
                    objects: Mapping | None = None) -> Figure:
    """One column per AoA mode: top, the set azimuth (lines) and the detected one (dots) of
    every target over time; bottom, the detected minus set azimuth. Dotted vertical lines:
    the frames where a target changed the front ends that carry it (hand-overs).

    Parameters
    ----------
    time_s : (F,) frame times
    set_deg : (F, T) set azimuths
    detected_deg : mode -> (F, T) detected azimuths (NaN where lost)
    handovers_s : mode -> times of the hand-overs
    objects : optional, mode -> the extended objects of the drive in that mode's column:
        ``set_deg`` (F, S) their scatterers' azimuths (thin grey lines), ``truth`` and ``rts``
        (N, 2) their detections (time, azimuth), ``pairs`` (P, 2) each truth detection's
        RTS detection of its cell (time, RTS minus truth azimuth)
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
        named = s.shape[1] <= LEGEND_TARGETS
        for k in range(s.shape[1]):
            if not np.isfinite(s[:, k]).any():  # not a tracked point target (an object's)
                continue
            line, = top.plot(t, s[:, k], lw=1.0,
                             label=f"target {k} set" if named else
                             ("set (one colour per target)" if k == 0 else None))
            top.plot(t, d[:, k], "o", ms=3.5, color=line.get_color(),
                     label=f"target {k} detected" if named else
                     ("detected" if k == 0 else None))
            bottom.plot(t, d[:, k] - s[:, k], "o-", ms=3, lw=0.8, color=line.get_color())
            lost = ~np.isfinite(d[:, k])
            if np.any(lost):
                top.plot(t[lost], s[lost, k], "x", color="red", ms=6,
                         label=f"target {k} lost" if named else "lost")
        if objects is not None and mode in objects:
            _objects(top, bottom, t, objects[mode])
        for i, th in enumerate(handovers_s.get(mode, [])):
            for ax in (top, bottom):
                ax.axvline(th, color="0.4", ls=":", lw=0.9,
                           label="hand-over" if (i == 0 and ax is top) else None)
        top.set_title(f"{title + ': ' if title else ''}{mode}")
        top.set_ylabel("azimuth (deg)")
        bottom.set_ylabel("detected - set azimuth (deg)" if objects is None or mode not in
                          objects else "detected - set (targets) or\nRTS - truth (object) (deg)")
        bottom.set_xlabel("time (s)")
    # one legend for the figure, below the plots (inside, with a few targets, it covered the
    # tracks); constrained layout makes room for it
    handles, labels = [], []
    for ax in axes[0]:  # a hand-over or loss only in another column; each label once
        for h, lab in zip(*ax.get_legend_handles_labels()):
            if lab not in labels:
                handles.append(h)
                labels.append(lab)
    fig.legend(handles, labels, loc="outside lower center", ncol=min(4, len(labels)),
               fontsize=8, frameon=False)
    return fig


def _objects(top, bottom, t, objects) -> None:
    """An extended object's clouds over the drive: its scatterers' set azimuths, the truth
    twin's and the RTS's detections; below, RTS minus truth per truth detection."""
    sd = np.asarray(objects["set_deg"], float).reshape(t.size, -1)
    for k in range(sd.shape[1]):
        top.plot(t, sd[:, k], color="0.75", lw=0.8, zorder=1,
                 label="object scatterers, set" if k == 0 else None)
    tr = np.asarray(objects["truth"], float).reshape(-1, 2)
    rt = np.asarray(objects["rts"], float).reshape(-1, 2)
    top.scatter(tr[:, 0], tr[:, 1], s=40, facecolors="none", edgecolors="C0", lw=1.2,
                zorder=3, label="object: truth twin detections")
    top.scatter(rt[:, 0], rt[:, 1], s=22, marker="x", color="C3", lw=1.2, zorder=4,
                label="object: RTS detections")
    pr = np.asarray(objects["pairs"], float).reshape(-1, 2)
    bottom.plot(pr[:, 0], pr[:, 1], "x", color="C3", ms=5,
                label="object: RTS - truth twin detection of the cell")


@dataclass(frozen=True)
class DriveFrames:
    """What :func:`playback_animation` shows of each of F frames of a drive: the frame times
    ``time_s`` (F,), the programmed ``amplitude`` (F, Q) per channel (0: off), the targets'
    set positions ``target_xy_m`` (F, T, 2) (x right, y along the boresight) and their set
    and detected azimuths ``set_deg``, ``detected_deg`` (F, T) (detected NaN where lost)."""

    time_s: np.ndarray
    amplitude: np.ndarray
    target_xy_m: np.ndarray
    set_deg: np.ndarray
    detected_deg: np.ndarray


def playback_animation(path, frames: DriveFrames, fe_azimuth_deg, arc_radius_m: float, *,
                       title: str = "", fps: int = 5):
    """An animated GIF of a drive (matplotlib's ``PillowWriter``): left, the arc
    seen from above with the RuT at its centre, every front end (filled and sized by its
    programmed amplitude when it carries a target) and each target's set (line) and detected
    (dashed) direction; right, the targets' paths in the plane at true scale, where they are.

    Parameters
    ----------
    path : where the GIF goes (written atomically)
    frames : DriveFrames
        The frames' times, programmed amplitudes, targets' positions and azimuths.
    fe_azimuth_deg : (Q,) front-end azimuths
    arc_radius_m : the arc's radius
    """
    from matplotlib.animation import FuncAnimation, PillowWriter

    from .._lib.io import atomic_path
    from .figures import STYLE
    import matplotlib as mpl

    t = np.asarray(frames.time_s, float)
    az = np.radians(np.asarray(fe_azimuth_deg, float))
    amp = np.asarray(frames.amplitude, float)
    xy = np.asarray(frames.target_xy_m, float)
    s_rad, d_rad = np.radians(frames.set_deg), np.radians(frames.detected_deg)
    with mpl.rc_context(STYLE):
        fig, (ax, ax2) = new_figure(figsize=(9.0, 4.4), ncols=2)
        r = arc_radius_m
        arc = np.linspace(az.min() - 0.1, az.max() + 0.1, 100)
        ax.plot(r * np.sin(arc), r * np.cos(arc), color="0.6", lw=1)
        ax.plot(0, 0, "ks", ms=6)
        fe = ax.scatter(r * np.sin(az), r * np.cos(az), s=20, c="0.7", zorder=3)
        n_t = xy.shape[1]
        colors = [f"C{k}" for k in range(n_t)]
        rays = [ax.plot([], [], color=colors[k], lw=1.2)[0] for k in range(n_t)]
        drays = [ax.plot([], [], color=colors[k], lw=1.2, ls="--")[0] for k in range(n_t)]
        ax.set_aspect("equal")
        lim = 1.25 * r
        ax.set_xlim(-lim * max(np.sin(np.abs(az)).max() + 0.3, 0.5), lim *
                    max(np.sin(np.abs(az)).max() + 0.3, 0.5))
        ax.set_ylim(-0.1 * r, lim)
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        for k in range(n_t):
            ax2.plot(xy[:, k, 0], xy[:, k, 1], color=colors[k], lw=0.8, alpha=0.5)
        dots = [ax2.plot([], [], "o", color=colors[k], ms=6)[0] for k in range(n_t)]
        ax2.plot(0, 0, "ks", ms=6)
        ax2.set_aspect("equal", adjustable="datalim")
        ax2.set_xlabel("x (m)")
        ax2.set_ylabel("y (m)")
        ax2.set_title("set positions")
        ax.plot([], [], color="0.3", lw=1.2, label="set direction")
        ax.plot([], [], color="0.3", lw=1.2, ls="--", label="detected")
        ax.scatter([], [], s=60, c="C3", label="front end carrying a target")
        ax.legend(loc="lower right")
        head = ax.set_title("")
        peak = max(float(amp.max()), 1e-300)

        def draw(f):
            on = amp[f] > 0
            fe.set_sizes(np.where(on, 20 + 180 * amp[f] / peak, 20))
            fe.set_color(np.where(on[:, None], mpl.colors.to_rgba_array(["C3"]),
                                  mpl.colors.to_rgba_array(["0.7"])))
            for k in range(n_t):
                rays[k].set_data([0, lim * np.sin(s_rad[f, k])], [0, lim * np.cos(s_rad[f, k])])
                d = d_rad[f, k]
                drays[k].set_data(([0, lim * np.sin(d)], [0, lim * np.cos(d)])
                                  if np.isfinite(d) else ([], []))
                dots[k].set_data([xy[f, k, 0]], [xy[f, k, 1]])
            head.set_text(f"{title + ': ' if title else ''}t = {t[f]:.2f} s")
            return [fe, head, *rays, *drays, *dots]

        anim = FuncAnimation(fig, draw, frames=len(t), blit=False)
        with atomic_path(path) as tmp:
            anim.save(tmp, writer=PillowWriter(fps=fps))
    return path
