"""The figure of an extended object: what the radar sees of it, truth against RTS.

Left: a bird's-eye view (the RuT at the origin, x to the right, y ahead) of each object's
outline at one frame with its scatterers, the truth twin's detections and the RTS's. Right
(over a drive): per frame the detections of truth and RTS, the truth's the RTS reproduces
within a resolution cell, the targets the RTS kept under its budget, and the difference of
the clouds' centroid azimuths; the object's range above the frames.
"""

from __future__ import annotations

import numpy as np

from .figures import _styled, _title, new_figure

__all__ = ["object_figure"]


def _xy(rows) -> np.ndarray:
    a = np.array([[r[3], r[5]] for r in rows], float).reshape(-1, 2)
    az = np.radians(a[:, 1])
    return np.c_[a[:, 0] * np.sin(az), a[:, 0] * np.cos(az)]


def _birds_eye(ax, outlines, scatterers, rows, frame: int) -> None:
    """The left panel: each object's outline at ``frame``, its scatterers and the truth
    twin's and the RTS's detections, seen from above."""
    for k, poly in enumerate(outlines):
        p = np.vstack([poly, poly[:1]])
        ax.plot(p[:, 0], p[:, 1], color="0.35", lw=1.2, label="object outline" if k == 0 else None)
    sc = np.asarray(scatterers, float).reshape(-1, 2)
    ax.scatter(sc[:, 0], sc[:, 1], s=14, color="0.5", label=f"scatterers ({len(sc)})", zorder=2)
    for src, style in (("truth", dict(marker="o", s=70, facecolors="none", edgecolors="C0",
                                      linewidths=1.5)),
                       ("rts", dict(marker="x", s=45, color="C3", linewidths=1.5))):
        xy = _xy([r for r in rows if r[1] == src and r[0] == frame])
        ax.scatter(xy[:, 0], xy[:, 1], label=f"{src} twin detections ({len(xy)})" if src ==
                   "truth" else f"RTS detections ({len(xy)})", zorder=3, **style)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x, lateral (m)")
    ax.set_ylabel("y, ahead of the RuT (m)")
    ax.legend(loc="best", fontsize=8)


def _drive_panel(bx, table, ranges_m) -> None:
    """The right panel over a drive: per frame the detection counts of truth and RTS, those
    the RTS reproduces, the targets kept, and the centroid azimuths' difference."""
    objs = sorted({t["object"] for t in table})
    for o in objs[:3]:
        rows_o = [t for t in table if t["object"] == o]
        f = [t["frame"] for t in rows_o]
        suffix = f" (object {o})" if len(objs) > 1 else ""
        bx.plot(f, [t["truth_detections"] for t in rows_o], "o-", color="C0", ms=3,
                label="truth detections" + suffix)
        bx.plot(f, [t["rts_detections"] for t in rows_o], "x-", color="C3", ms=4,
                label="RTS detections" + suffix)
        bx.plot(f, [round(t["truth_detections"] * (t["reproduced_share"] or 0.0))
                    for t in rows_o], "^:", color="C4", ms=3,
                label="truth detections the RTS reproduces (within a cell)" + suffix)
        if "kept" in rows_o[0]:
            bx.plot(f, [t["kept"] for t in rows_o], "s--", color="C2", ms=3,
                    label="targets the RTS kept (budget)")
    from matplotlib.ticker import MaxNLocator
    bx.xaxis.set_major_locator(MaxNLocator(integer=True))
    bx.yaxis.set_major_locator(MaxNLocator(integer=True))
    bx.set_xlabel("frame")
    bx.set_ylim(bottom=0)  # counts from zero: a drop to 3 of 5 reads as it is
    if ranges_m is not None:  # the object's range on top: dynamic resolution reads by it
        top = bx.secondary_xaxis("top")
        ticks = [k for k in bx.get_xticks() if 0 <= k < len(ranges_m) and k == int(k)]
        top.set_xticks(ticks, [f"{ranges_m[int(k)]:.3g}" for k in ticks])
        top.set_xlabel("range of the object's origin (m)", fontsize=8)
    bx.set_ylabel("count")
    tx = bx.twinx()
    for o in objs[:3]:
        rows_o = [t for t in table if t["object"] == o]
        d = [np.nan if t["centroid_azimuth_diff_deg"] is None
             else t["centroid_azimuth_diff_deg"] for t in rows_o]
        tx.plot([t["frame"] for t in rows_o], d, color="C1", lw=1.0,
                label="centroid azimuth, RTS - truth")
    tx.set_ylabel("centroid azimuth difference (deg)", color="C1")
    h1, l1 = bx.get_legend_handles_labels()
    h2, l2 = tx.get_legend_handles_labels()
    bx.legend(h1 + h2[:1], l1 + l2[:1], loc="upper left", fontsize=8)
    _title(bx, "over the drive")


@_styled
def object_figure(outlines, scatterers, rows, frame: int, table=None, title: str = "",
                  ranges_m=None):
    """The object figure (module docstring).

    Parameters
    ----------
    outlines : list of ndarray (K, 2)
        Each object's footprint at ``frame`` (radar frame x, y; m).
    scatterers : ndarray (N, 2)
        The frame's scatterers (x, y; m).
    rows : list of tuple
        ``clouds.csv`` rows (:data:`rtsgeom.analysis.objects.CLOUD_COLUMNS`).
    frame : int
        The frame the bird's-eye view shows.
    table : list of dict, optional
        The per object and frame summary (:func:`rtsgeom.analysis.objects.summary_table`);
        over more than one frame, the right panel.
    ranges_m : array_like, optional
        Per frame the range of the (first) object's origin (m), shown above the frames.
    """
    frames = sorted({t["frame"] for t in table}) if table else [frame]
    drive = len(frames) > 1
    fig, axes = new_figure(figsize=(11.0, 4.8) if drive else (6.4, 5.2), ncols=2 if drive else 1)
    ax = axes[0] if drive else axes
    _birds_eye(ax, outlines, scatterers, rows, frame)
    _title(ax, (title or "extended object") + (f": frame {frame}" if drive else ""))
    if drive:
        _drive_panel(axes[1], table, ranges_m)
    return fig
