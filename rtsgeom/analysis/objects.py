"""What the radar sees of an extended object, against the truth: detection clouds and their
summary per object and frame.

A cloud is the detections the RuT makes of one object in one frame: the truth twin's
(``source`` ``truth``: the same radar on the real scatterers) and the RTS's (``rts``). A
detection belongs to the object of the nearest of the frame's point targets within the
association's gate (two range and Doppler bins, one angular resolution cell:
:func:`rtsgeom.pipeline.run.association_scale`); detections near no target (noise, cable
ghosts, the sheet) belong to none and are left out. Per object and frame the summary compares
the clouds: their sizes, the difference of their centroids (mean azimuth and range, RTS minus
truth) and of their extents (azimuth span and range depth), and the share of the truth's
detections the RTS reproduces within one resolution cell (range bin, velocity bin and
two-target resolution in direction cosine).
"""

from __future__ import annotations

import csv
import io

import numpy as np

__all__ = ["CLOUD_COLUMNS", "SUMMARY_KEYS", "cloud_rows", "clouds_csv", "object_summary",
           "summary_table", "run_objects", "play_objects", "objects_figure"]

CLOUD_COLUMNS = ("frame", "source", "object", "range_m", "velocity_mps", "azimuth_deg",
                 "elevation_deg", "power_db")
SUMMARY_KEYS = ("object", "frame", "truth_detections", "rts_detections",
                "centroid_azimuth_diff_deg", "centroid_range_diff_m", "azimuth_span_diff_deg",
                "range_depth_diff_m", "reproduced_share")


def cloud_rows(frame: int, source: str, det, targets, scale, gate: float = 2.0) -> list[tuple]:
    """The detections ``det`` of frame ``frame`` that belong to an object, as rows of
    :data:`CLOUD_COLUMNS` (module docstring): each to the object of its nearest target
    (``targets``, with ``object_index``) within ``gate`` range and Doppler cells and one
    angular cell of ``scale`` (range bin, velocity bin, resolution in u)."""
    t = list(targets)
    if not len(det) or not t:
        return []
    obj = np.array([x.object_index for x in t])
    tp = np.c_[[x.range_m for x in t], [x.velocity_mps for x in t], np.sin([x.angle_rad
                                                                          for x in t])]
    dp = np.c_[det.range_m, det.velocity_mps, np.sin(det.angle_rad)]
    sc = np.asarray(scale, float)[:3]
    diff = (dp[:, None, :] - tp[None]) / sc  # (D, T, 3)
    ok = np.all(np.abs(diff[..., :2]) <= gate, axis=-1) & (np.abs(diff[..., 2]) <= 1.0)
    dist = np.where(ok, np.sqrt((diff ** 2).sum(-1)), np.inf)
    near = np.argmin(dist, axis=1)
    el = det.elevation_deg if det.elevation_rad is not None else np.full(len(det), np.nan)
    rows = []
    for j in np.flatnonzero(np.isfinite(dist[np.arange(len(det)), near])):
        o = int(obj[near[j]])
        if o < 0:
            continue
        rows.append((int(frame), source, o, float(det.range_m[j]), float(det.velocity_mps[j]),
                     float(det.angle_deg[j]), float(el[j]), float(det.power_db[j])))
    return rows


def clouds_csv(rows) -> str:
    """``clouds.csv``: one row per detection of an object (:data:`CLOUD_COLUMNS`; elevation
    empty for an RuT that beamforms in azimuth only)."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(CLOUD_COLUMNS)
    for r in rows:
        w.writerow([r[0], r[1], r[2]] + [f"{x:.6g}" if np.isfinite(x) else "" for x in r[3:]])
    return buf.getvalue()


def _cloud(rows) -> np.ndarray:
    return np.array([[r[3], r[4], r[5]] for r in rows], float).reshape(-1, 3)


def object_summary(rows, scale, obj: int, frame: int) -> dict:
    """One object's clouds in one frame compared (module docstring): a dict of
    :data:`SUMMARY_KEYS` (differences None where a cloud is empty)."""
    tr = _cloud([r for r in rows if r[1] == "truth" and r[2] == obj and r[0] == frame])
    rt = _cloud([r for r in rows if r[1] == "rts" and r[2] == obj and r[0] == frame])
    out = {"object": obj, "frame": frame, "truth_detections": len(tr),
           "rts_detections": len(rt)}
    both = len(tr) and len(rt)

    def d(f):
        return float(f(rt) - f(tr)) if both else None
    out["centroid_azimuth_diff_deg"] = d(lambda c: c[:, 2].mean())
    out["centroid_range_diff_m"] = d(lambda c: c[:, 0].mean())
    out["azimuth_span_diff_deg"] = d(lambda c: np.ptp(c[:, 2]))
    out["range_depth_diff_m"] = d(lambda c: np.ptp(c[:, 0]))
    if len(tr):
        sc = np.asarray(scale, float)[:3]
        ut, ur = np.sin(np.radians(tr[:, 2])), np.sin(np.radians(rt[:, 2]))
        close = ((np.abs(tr[:, None, 0] - rt[None, :, 0]) <= sc[0])
                 & (np.abs(tr[:, None, 1] - rt[None, :, 1]) <= sc[1])
                 & (np.abs(ut[:, None] - ur[None]) <= sc[2]))
        out["reproduced_share"] = float(close.any(axis=1).mean())
    else:
        out["reproduced_share"] = None
    return out


def summary_table(rows, scale, num_objects: int, frames, budget=None) -> list[dict]:
    """Per object and frame :func:`object_summary`, with the frame's budget counts
    (``kept``, ``merged``, ``dropped``: :attr:`rtsgeom.pipeline.merge.Budgeted.counts`) where
    ``budget`` (per frame a counts dict, or None) is given."""
    out = []
    for f in frames:
        for o in range(num_objects):
            s = object_summary(rows, scale, o, int(f))
            if budget is not None and budget[int(f)] is not None:
                s.update({k: budget[int(f)][k] for k in ("kept", "merged", "dropped")})
            out.append(s)
    return out


def run_objects(result) -> tuple[list, dict]:
    """A run's clouds (frame 0) and its ``summary.json`` ``objects`` section (per object the
    comparison, with the planner's budget counts where ``[rts] max_targets_per_channel`` is
    set)."""
    from ..pipeline.merge import cell_scale
    scene = result.scene
    scale = cell_scale(result.setup)
    rows = []
    if result.truth_detections is not None:
        rows += cloud_rows(0, "truth", result.truth_detections, scene.targets, scale)
    rows += cloud_rows(0, "rts", result.detections, scene.targets, scale)
    budget = result.calibration.get("budget")
    counts = None if budget is None else [{k: budget[k] for k in ("kept", "merged",
                                                                    "dropped")}]
    n_obj = sum(1 for m in scene.objects if not m.moving)
    return rows, {"objects": [m.where for m in scene.objects if not m.moving],
                  "resolution_cell": _cell(scale), "budget": budget,
                  "frames": summary_table(rows, scale, n_obj, [0], counts)}


def play_objects(result) -> tuple[list, dict]:
    """A played drive's clouds and its ``summary.json`` ``objects`` section (per object and
    frame)."""
    rows, scale = result.clouds
    frames = range(len(result.time_s))
    counts = list(result.budget) if result.budget is not None else None
    return list(rows), {"objects": [m.where for m in result.scene.objects],
                        "resolution_cell": _cell(scale),
                        "budget": None if counts is None else {
                            "max_targets_per_channel":
                                result.scene.rts.max_targets_per_channel,
                            "kept": [c["kept"] for c in counts]},
                        "frames": summary_table(rows, scale, len(result.scene.objects),
                                                frames, counts)}


def _cell(scale) -> dict:
    return {"range_m": float(scale[0]), "velocity_mps": float(scale[1]),
            "direction_cosine": float(scale[2])}


def objects_figure(scene, rows, section: dict, frame: int | None = None):
    """The object figure (:func:`rtsgeom.viz.objects.object_figure`) of a run or a drive:
    the bird's-eye view at ``frame`` (default: the frame with the most truth detections)."""
    from ..viz.objects import object_figure
    table = section["frames"]
    if frame is None:
        frame = max(table, key=lambda t: (t["truth_detections"], -t["frame"]))["frame"] \
            if table else 0
    models = [m for m in scene.objects if m.moving or len(table) and table[-1]["frame"] == 0]
    outlines = [m.outline_at(*m.pose(scene, frame)) for m in models]
    from ..scene.objects import place
    scat = []
    for m in models:
        origin, vel = m.pose(scene, frame)
        pts = place(m, origin, vel, scene.radar, 0)
        scat += [[t.range_m * np.sin(t.angle_rad), t.range_m * np.cos(t.angle_rad)] for t in pts]
    return object_figure(outlines, np.array(scat, float).reshape(-1, 2), rows, frame, table,
                         title=scene.name)
