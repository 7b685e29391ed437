"""What the radar sees of an extended object, against the truth: detection clouds and their
summary per object and frame.

A cloud is the detections the RuT makes of one object in one frame: the truth twin's
(``source`` ``truth``: the same radar on the real scatterers) and the RTS's (``rts``). Which
detection is whose is the project's one association
(:func:`rtsgeom.pipeline.matching.associate_targets`, as for every target of ``run`` and ``play``):
in the radar's resolution cells (range bin, velocity bin, two-target resolution per
direction-cosine axis, elevation included for a 2-D RuT), the RTS's targets where the radar sees
them (R_c further without ``rts.compensate_air_path``), the truth twin's at their set range. A
detection belongs to the object of the target it was assigned to, else of the target it lies
nearest within the gate and one angular cell; detections near no target (noise, cable
ghosts, the sheet) belong to none and are left out. Per object and frame the summary compares
the clouds: their sizes, the difference of their centroids (mean azimuth and range, RTS minus
truth, the RTS's ranges referred to the real scene) and of their extents (azimuth span and
range depth), and the share of the truth's detections the RTS reproduces within one
resolution cell: the same association of the truth's detections (as targets) with the RTS's,
one range and Doppler bin for the gate, each pair within one cell on every axis; and over
each RTS detection paired with the truth twin's detection of its cell (the same
association, the other way round) the largest azimuth and range differences: the fidelity of
what the RTS synthesizes, merged targets included (a scatterer the budget dropped lowers the
share, not the pairs).
"""

from __future__ import annotations

import csv
import io

import numpy as np

__all__ = ["CLOUD_COLUMNS", "SUMMARY_KEYS", "cloud_rows", "clouds_csv", "object_summary",
           "summary_table", "run_objects", "play_objects", "objects_figure", "objects_lines",
           "pairs", "air_offset_m"]

CLOUD_COLUMNS = ("frame", "source", "object", "range_m", "velocity_mps", "azimuth_deg",
                 "elevation_deg", "power_db")
SUMMARY_KEYS = ("object", "frame", "truth_detections", "rts_detections",
                "centroid_azimuth_diff_deg", "centroid_range_diff_m", "azimuth_span_diff_deg",
                "range_depth_diff_m", "reproduced_share", "paired_detections",
                "paired_azimuth_diff_max_deg", "paired_range_diff_max_bins")


def cloud_rows(frame: int, source: str, scene, det, rd, targets, steering=None,
               gate: float = 2.0) -> list[tuple]:
    """The detections ``det`` of frame ``frame`` that belong to an object, as rows of
    :data:`CLOUD_COLUMNS` (module docstring): the association of ``targets`` (with
    ``object_index``; the RTS's where the radar sees them, ``source`` ``truth``: at their set
    range) with ``det`` on the map ``rd`` and the beamformer ``steering``, ``gate`` range and
    Doppler bins."""
    from ..pipeline.matching import associate_targets
    t = tuple(targets)
    if not len(det) or not t:
        return []
    assoc, _, _ = associate_targets(scene, det, rd, gate, steering, t,
                                    real=source == "truth")
    obj = np.array([x.object_index for x in t])
    whose = np.where(assoc.owner >= 0, assoc.owner, assoc.nearest)
    el = det.elevation_deg if det.elevation_rad is not None else np.full(len(det), np.nan)
    rows = []
    for j in np.flatnonzero((whose >= 0)):
        o = int(obj[whose[j]])
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
    """(N, 4): range, velocity, azimuth (deg), elevation (deg, 0 where not measured)."""
    c = np.array([[r[3], r[4], r[5], r[6]] for r in rows], float).reshape(-1, 4)
    c[:, 3] = np.nan_to_num(c[:, 3])
    return c


def _points(c: np.ndarray, dims: int) -> np.ndarray:
    from ..pipeline.matching import direction_columns
    return np.c_[c[:, :2], direction_columns(np.radians(c[:, 2]), np.radians(c[:, 3]), dims)]


def pairs(truth: np.ndarray, rts: np.ndarray, scale) -> tuple[np.ndarray, np.ndarray]:
    """Each detection of one cloud (``truth``; rows of :func:`_cloud`) with the other's
    (``rts``) of the same cell: the one association
    (:func:`rtsgeom.radar.association.associate`) of the first cloud, as targets, with the
    second, one range and Doppler bin for the gate. Returns the index (T,) of the paired
    detection (-1: none) and whether the pair lies within one cell of ``scale`` on every
    axis (T,) (with the truth first: the truth detection is reproduced)."""
    from ..radar.association import associate
    sc = np.asarray(scale, float)
    dims = sc.size - 2
    tp, rp = _points(truth, dims), _points(rts, dims)
    a = associate(tp, rp, sc, gate=1.0)
    ok = a.detection >= 0
    close = np.zeros(len(tp), bool)
    close[ok] = np.all(np.abs(rp[a.detection[ok]] - tp[ok]) <= sc * (1 + 1e-9), axis=1)
    return np.asarray(a.detection), close


def clouds_by_frame(rows, offset_m: float = 0.0):
    """``(frame, object, truth cloud, RTS cloud)`` (clouds: rows of :func:`_cloud`, the RTS's
    ranges referred to the real scene by ``offset_m``) for every frame and object in
    ``rows``."""
    for f, o in sorted({(r[0], r[2]) for r in rows}):
        tr = _cloud([r for r in rows if r[1] == "truth" and r[2] == o and r[0] == f])
        rt = _cloud([r for r in rows if r[1] == "rts" and r[2] == o and r[0] == f])
        rt[:, 0] -= offset_m
        yield f, o, tr, rt


def object_summary(rows, scale, obj: int, frame: int, offset_m: float = 0.0) -> dict:
    """One object's clouds in one frame compared (module docstring): a dict of
    :data:`SUMMARY_KEYS` (differences None where a cloud is empty). ``scale``: the
    association's resolution cell; ``offset_m``: how much further the radar sees the RTS's
    targets than their set range (R_c without ``rts.compensate_air_path``, else 0)."""
    tr = _cloud([r for r in rows if r[1] == "truth" and r[2] == obj and r[0] == frame])
    rt = _cloud([r for r in rows if r[1] == "rts" and r[2] == obj and r[0] == frame])
    rt[:, 0] -= offset_m  # referred to the real scene
    out = {"object": obj, "frame": frame, "truth_detections": len(tr),
           "rts_detections": len(rt)}
    both = len(tr) and len(rt)

    def d(f):
        return float(f(rt) - f(tr)) if both else None
    out["centroid_azimuth_diff_deg"] = d(lambda c: c[:, 2].mean())
    out["centroid_range_diff_m"] = d(lambda c: c[:, 0].mean())
    out["azimuth_span_diff_deg"] = d(lambda c: np.ptp(c[:, 2]))
    out["range_depth_diff_m"] = d(lambda c: np.ptp(c[:, 0]))
    _, close = pairs(tr, rt, scale)
    out["reproduced_share"] = float(close.mean()) if len(tr) else None
    j, _ = pairs(rt, tr, scale)  # each RTS detection's truth twin detection of its cell
    ok = j >= 0
    out["paired_detections"] = int(ok.sum())
    out["paired_azimuth_diff_max_deg"] = (float(np.abs(rt[ok, 2] - tr[j[ok], 2]).max())
                                          if ok.any() else None)
    out["paired_range_diff_max_bins"] = (float(np.abs(rt[ok, 0] - tr[j[ok], 0]).max()
                                               / float(scale[0])) if ok.any() else None)
    return out


def summary_table(rows, scale, num_objects: int, frames, budget=None, offset_m: float = 0.0
                  ) -> list[dict]:
    """Per object and frame :func:`object_summary`, with the frame's budget counts
    (``kept``, ``merged``, ``dropped``: :attr:`rtsgeom.pipeline.merge.Budgeted.counts`) where
    ``budget`` (per frame a counts dict, or None) is given."""
    out = []
    for f in frames:
        for o in range(num_objects):
            s = object_summary(rows, scale, o, int(f), offset_m)
            if budget is not None and budget[int(f)] is not None:
                s.update({k: budget[int(f)][k] for k in ("kept", "merged", "dropped")})
            out.append(s)
    return out


def run_objects(result) -> tuple[list, dict]:
    """A run's clouds (frame 0) and its ``summary.json`` ``objects`` section (per object the
    comparison, with the planner's budget counts where ``[rts] max_targets_per_channel`` is
    set)."""
    from ..pipeline.matching import association_scale
    scene, rd, st = result.scene, result.rd, result.cube.steering
    scale = association_scale(scene, rd, st)
    rows = []
    if result.truth_detections is not None:  # the same radar and map bins as the RTS frame
        rows += cloud_rows(0, "truth", scene, result.truth_detections, rd, scene.targets, st)
    rows += cloud_rows(0, "rts", scene, result.detections, rd, scene.targets, st)
    budget = result.calibration.get("budget")
    counts = None if budget is None else [{k: budget[k] for k in ("kept", "merged",
                                                                    "dropped")}]
    n_obj = sum(1 for m in scene.objects if not m.moving)
    return rows, {"objects": [m.where for m in scene.objects if not m.moving],
                  "resolution_cell": _cell(scale), "budget": budget,
                  "frames": summary_table(rows, scale, n_obj, [0], counts,
                                          air_offset_m(scene))}


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
                                                frames, counts, air_offset_m(result.scene))}


def air_offset_m(scene) -> float:
    """How much further the radar sees the RTS's targets than their set range
    (:func:`rtsgeom.rts.channels.apparent_range`: R_c without ``rts.compensate_air_path``)."""
    from ..rts.channels import apparent_range
    return float(apparent_range(scene, 0.0))


def objects_lines(section: dict) -> list[str]:
    """One printed line per object of an ``objects`` section (:func:`run_objects`,
    :func:`play_objects`): detections of truth and RTS, the share of the truth's the RTS
    reproduces within a cell, and the largest differences of paired detections (each RTS
    detection and the truth twin's of its cell)."""
    def span(v):
        v = [x for x in v if x is not None]
        if not v:
            return "n/a"
        lo, hi = min(v), max(v)
        return f"{lo:g}" if lo == hi else f"{lo:g}-{hi:g}"
    out = []
    for o, where in enumerate(section["objects"]):
        t = [r for r in section["frames"] if r["object"] == o]
        share = [r["reproduced_share"] for r in t if r["reproduced_share"] is not None]
        az = [r["paired_azimuth_diff_max_deg"] for r in t
              if r["paired_azimuth_diff_max_deg"] is not None]
        rb = [r["paired_range_diff_max_bins"] for r in t
              if r["paired_range_diff_max_bins"] is not None]
        n_t, n_r = span([r["truth_detections"] for r in t]), span([r["rts_detections"] for r in t])
        line = (f"object {where}: {len(t)} frame(s), truth {n_t} / RTS {n_r} detections a frame, "
                f"{100 * min(share):.0f} % (worst frame) of the truth's reproduced within a cell"
                if share else f"object {where}: no truth twin detection")
        if az:
            line += (f"; each RTS detection against the truth twin's of its cell: max |azimuth| "
                     f"{max(az):.3f} deg, max |range| {max(rb):.2f} bins")
        if "kept" in t[0] if t else False:
            line += (f"; budget: kept {span([r['kept'] for r in t])}, merged "
                     f"{span([r['merged'] for r in t])}, dropped {span([r['dropped'] for r in t])}")
        out.append(line)
    return out


def _cell(scale) -> dict:
    out = {"range_m": float(scale[0]), "velocity_mps": float(scale[1]),
           "direction_cosine": float(scale[2])}
    if len(scale) > 3:
        out["direction_cosine_elevation"] = float(scale[3])
    return out


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
    ranges = None
    if models and models[0].moving and len({t["frame"] for t in table}) > 1:
        from ..scene.scenario import trajectory
        i = int(models[0].where.split("[")[1].rstrip("]"))
        ranges = trajectory(scene.scenario.targets[i].waypoints,
                            scene.scenario.frame_times()).range_m
    title = scene.name
    row = next((t for t in table if t["frame"] == frame and "kept" in t), None)
    if row is not None:  # the budget's counts at the frame shown
        title += (f" (budget {scene.rts.max_targets_per_channel} a channel: kept "
                  f"{row['kept']}, merged {row['merged']}, dropped {row['dropped']})")
    return object_figure(outlines, np.array(scat, float).reshape(-1, 2), rows, frame, table,
                         title=title, ranges_m=ranges)
