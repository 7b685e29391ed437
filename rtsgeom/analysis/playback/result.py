"""A played drive: per frame and target the set-points, the detections and the programme;
the tables ``programme.csv`` and ``tracks.csv``, the summary and the figure of ``rtsgeom play``.
"""

from __future__ import annotations

import io
from dataclasses import dataclass

import numpy as np

from ... import __version__
from ..._lib.results import Result
from ...scene import Scene

__all__ = ["PlaybackResult", "PROGRAMME_COLUMNS", "TRACK_COLUMNS", "BUDGET_ROLES", "budget_line"]

PROGRAMME_COLUMNS = ("frame", "time_s", "target", "channel", "delay_s", "doppler_hz",
                     "amplitude_db", "phase_rad")
TRACK_COLUMNS = ("frame", "time_s", "target", "set_range_m", "set_azimuth_deg",
                 "set_velocity_mps", "range_m", "azimuth_deg", "velocity_mps",
                 "truth_range_m", "truth_azimuth_deg", "truth_velocity_mps", "status",
                 "budget")
#: a target's role under ``[rts] max_targets_per_channel`` (:mod:`rtsgeom.pipeline.merge`):
#: synthesized alone, carrying a merged target (its strongest member), folded into another's
#: merged target, or dropped
BUDGET_ROLES = ("kept", "lead", "merged", "dropped")


@dataclass(frozen=True, repr=False)
class PlaybackResult(Result):
    """A drive played frame by frame (``Playback``).

    The angle, range and velocity errors, losses and hand-overs are over the point targets
    synthesized as themselves (:attr:`tracked`); an object's scatterers are compared as its
    cloud, each RTS detection against the truth twin's detection of its cell
    (:mod:`rtsgeom.analysis.objects`, ``objects.json``).

    Attributes
    ----------
    scene : Scene
        The scene played.
    mode : str
        The amplitude mode.
    time_s : ndarray
        (frames,): each frame's time.
    set, detected : dict
        ``range_m``, ``azimuth_deg``, ``velocity_mps`` arrays (frames, targets); detected NaN
        where the target was lost.
    split : ndarray
        (frames, targets): the other detections near a target's set-point that no target claimed.
    channels : ndarray
        (frames, targets): the front ends that carry each target.
    programme : ndarray, (rows, 7)
        Frame, target, channel, delay_s, doppler_hz, |amplitude|, phase_rad.
    calibration : dict
        The pairs' calibration used.
    warnings : tuple of str
        The run's warnings.
    baseline : PlaybackResult or None
        The switched baseline (``nearest``) on the same drive.
    truth : dict or None
        The truth twin's detections (the same keys, NaN where the real scene gives the target
        no detection of its own; None: not run).
    status : ndarray or None
        (frames, targets): ``detected``, ``merged`` or ``not_detected``.
    clouds : tuple or None
        For a scene with extended objects, the truth twin's and the RTS's detections of each
        object (:mod:`rtsgeom.analysis.objects`) and the resolution cell they are compared in.
    budget : tuple or None
        Per frame the planner's counts under ``[rts] max_targets_per_channel``.
    role : ndarray or None
        (frames, targets): each target's role under that budget (:data:`BUDGET_ROLES`; None
        without one): a ``lead``'s detection and truth are the merged target's and the truth
        twin's detection of its cell, a ``merged`` or ``dropped`` target has neither.
    object_of : ndarray or None
        (targets,): the extended object each target belongs to (-1: a point target).
    chain : str
        The chain asked for (``fast`` or ``full``, :data:`rtsgeom.radar.frame.CHAINS`).
    fallbacks : tuple
        Per frame why the full chain ran where the fast path was asked for (a tuple of
        reasons, one per look: the RTS's, the truth twin's; empty: the fast path held).
    """

    scene: Scene
    mode: str
    time_s: np.ndarray
    set: dict
    detected: dict
    split: np.ndarray
    channels: np.ndarray
    programme: np.ndarray
    calibration: dict
    warnings: tuple[str, ...] = ()
    baseline: "PlaybackResult | None" = None
    truth: dict | None = None
    status: np.ndarray | None = None
    clouds: tuple | None = None  # (clouds.csv rows, resolution cell) of a scene with objects
    budget: tuple | None = None  # per frame the planner's kept/merged/dropped counts
    role: np.ndarray | None = None  # (frames, targets) BUDGET_ROLES under a budget
    object_of: np.ndarray | None = None  # (targets,) each target's object, -1: a point target
    chain: str = "full"
    fallbacks: tuple = ()  # per frame: why the full chain ran on the fast path's request

    def _summary(self):
        s = self.summary()
        err = s["angle_error_deg"]
        n = self.num_targets

        def deg(x):
            return "none detected" if x is None else f"{x:.3g} deg"
        title = (f"{self.scene.name}: {self.mode}, {s['frames']} frames x {n} "
                 f"target{'s' if n != 1 else ''}, {s['lost_frames']} lost, "
                 f"{s['split_frames']} split")
        rows = [("max |angle error|", deg(err["max"])), ("p95 |angle error|", deg(err["p95"])),
                ("hand-overs", s["handovers"]),
                ("largest jump at a hand-over", deg(s["handover_jump_deg"]))]
        if "budget" in s:
            rows.append(("budget", budget_line(s["budget"])))
        if self.baseline is not None:
            b = self.baseline.summary()
            rows.append((f"baseline ({self.baseline.mode}) max |angle error|",
                         deg(b["angle_error_deg"]["max"])))
        rows += [(f"target {t['target']}", f"max {deg(t['angle_error_deg']['max'])}, "
                  f"{t['lost_frames']} lost, {t['handovers']} hand-overs")
                 for t in s["targets"]]
        return title, rows

    @property
    def num_targets(self) -> int:
        return int(self.split.shape[1])

    @property
    def tracked(self) -> np.ndarray:
        """(frames, targets) where a target's track is compared to its set-point: a point
        target (an extended object's scatterers are compared as the object's cloud,
        :mod:`rtsgeom.analysis.objects`) that the RTS synthesizes as itself (under a budget,
        role ``kept``)."""
        out = np.ones(self.split.shape, bool)
        if self.object_of is not None:
            out &= (np.asarray(self.object_of) < 0)[None, :]
        if self.role is not None:
            out &= np.asarray(self.role) == "kept"
        return out

    @property
    def angle_error_deg(self) -> np.ndarray:
        """Detected minus set azimuth (frames, targets), NaN where lost or where the target is
        not synthesized as itself (:attr:`tracked`)."""
        return np.where(self.tracked, self.detected["azimuth_deg"] - self.set["azimuth_deg"],
                        np.nan)

    @property
    def vs_truth_deg(self) -> np.ndarray:
        """Detected minus the truth twin's azimuth (frames, targets), NaN where either has
        none (all NaN without the truth twin)."""
        if self.truth is None:
            return np.full(self.split.shape, np.nan)
        return self.detected["azimuth_deg"] - self.truth["azimuth_deg"]

    def handovers(self) -> list[tuple[int, int]]:
        """(frame, target) where the channels carrying the target differ from the frame before,
        the target synthesized as itself in both (:attr:`tracked`: a budget's merge or drop
        is no hand-over)."""
        a = self.tracked
        return [(f, k) for k in range(self.num_targets) for f in range(1, len(self.time_s))
                if a[f, k] and a[f - 1, k] and self.channels[f, k]
                and self.channels[f - 1, k] and self.channels[f, k] != self.channels[f - 1, k]]

    def handover_jumps_deg(self) -> np.ndarray:
        """At each hand-over, how far the angle error moved from the frame before (deg; NaN
        where either frame lost the target)."""
        e = self.angle_error_deg
        return np.array([abs(e[f, k] - e[f - 1, k]) for f, k in self.handovers()])

    def summary(self) -> dict:
        """The content of ``summary.json``: ``frames``, ``angle_error_deg``, ``range_error_m``
        and ``velocity_error_mps`` {max, p95} of the absolute error over every detected frame
        and target, ``lost_frames`` and
        ``split_frames`` (frames where any target was lost, or seen twice),
        ``handover_jump_deg`` (the largest change of a target's angle error at a hand-over),
        per target the same, ``chain`` (the chain asked for and the frames that ran the full
        chain instead, with their reasons), and the baseline's where it was played."""
        err = np.abs(self.angle_error_deg)
        # the track's range and radial velocity against the set-points
        alone = self.tracked
        r_err = np.where(alone, np.abs(self.detected["range_m"] - self.set["range_m"]), np.nan)
        v_err = np.where(alone, np.abs(self.detected["velocity_mps"] - self.set["velocity_mps"]),
                         np.nan)
        lost = ~np.isfinite(self.detected["azimuth_deg"]) & alone
        jumps = self.handover_jumps_deg()

        def stats(e):
            e = e[np.isfinite(e)]
            return ({"max": float(e.max()), "p95": float(np.percentile(e, 95))} if e.size
                    else {"max": None, "p95": None})

        def jump(j):
            j = j[np.isfinite(j)]
            return float(j.max()) if j.size else None

        hk = np.array([k for _, k in self.handovers()], int)
        out = {
            "mode": self.mode,
            "frames": int(len(self.time_s)),
            "point_targets": int(self.tracked.any(axis=0).sum()),
            "angle_error_deg": stats(err),
            "range_error_m": stats(r_err), "velocity_error_mps": stats(v_err),
            "lost_frames": int(np.any(lost, axis=1).sum()),
            "split_frames": int(np.any(self.split > 0, axis=1).sum()),
            "handover_jump_deg": jump(jumps),
            "handovers": int(len(hk)),
            "vs_truth_deg": stats(np.abs(self.vs_truth_deg)),
            "merged_frames": int(np.any(self._status == "merged", axis=1).sum()),
            "targets": [{"target": k, "angle_error_deg": stats(err[:, k]),
                         "range_error_m": stats(r_err[:, k]),
                         "velocity_error_mps": stats(v_err[:, k]),
                         "lost_frames": int(lost[:, k].sum()),
                         "split_frames": int((self.split[:, k] > 0).sum()),
                         "handovers": int((hk == k).sum()),
                         "handover_jump_deg": jump(jumps[hk == k])}
                        for k in range(self.num_targets)],
        }
        out["chain"] = self._chain_summary()
        if self.role is not None:
            out["budget"] = self._budget_summary()
        if self.baseline is not None:
            out["baseline"] = {k: v for k, v in self.baseline.summary().items()
                               if k != "targets"}
        return out

    def _chain_summary(self) -> dict:
        """The chain asked for, the frames that ran the full chain on the fast path's request
        and how often each reason sent them there."""
        reasons: dict[str, int] = {}
        for f in self.fallbacks:
            for r in set(f):
                reasons[r] = reasons.get(r, 0) + 1
        return {"asked": self.chain, "full_chain_frames": int(sum(1 for f in self.fallbacks
                                                                  if f)),
                "reasons": dict(sorted(reasons.items()))}

    def _budget_summary(self) -> dict:
        """Under ``[rts] max_targets_per_channel``: the per-frame counts (min, max over the
        frames); how the merged targets compare to the truth twin is the objects' summary
        (:mod:`rtsgeom.analysis.objects`: each RTS detection against the truth twin's
        detection of its cell)."""
        out = {"max_targets_per_channel": self.scene.rts.max_targets_per_channel}
        for k in ("kept", "merged", "dropped"):
            v = [c[k] for c in self.budget] if self.budget else [0]
            out[k] = {"min": int(min(v)), "max": int(max(v))}
        return out

    @property
    def _status(self) -> np.ndarray:
        if self.status is not None:
            return np.asarray(self.status)
        return np.where(np.isfinite(self.detected["azimuth_deg"]), "detected", "not_detected")

    def summary_json(self) -> dict:
        """:meth:`summary` with the run's context (scene, drive, calibration, warnings)."""
        sc = self.scene.scenario
        return {"rtsgeom_version": __version__, "scene": self.scene.name,
                "scene_sha256": self.scene.sha256, "seed": self.scene.seed,
                "frame_period_s": sc.frame_period_s, "duration_s": sc.duration_s,
                "static_targets": len(self.scene.targets),
                **self.summary(), "calibration": self.calibration,
                "warnings": list(self.warnings)}

    def to_dataframe(self):
        """The tracks (one row per frame and target, :data:`TRACK_COLUMNS` plus
        ``azimuth_error_deg`` and ``channels``) as a pandas DataFrame."""
        import pandas as pd
        cols = self._track_columns()
        cols["azimuth_error_deg"] = self.angle_error_deg.ravel()
        cols["channels"] = [" ".join(map(str, c)) for c in self.channels.ravel()]
        return pd.DataFrame(cols)

    def programme_dataframe(self):
        """The RTS programme (:data:`PROGRAMME_COLUMNS`) as a pandas DataFrame."""
        import pandas as pd
        return pd.DataFrame(self._programme_columns())

    def _track_columns(self) -> dict:
        n_f, n_t = self.split.shape
        return {"frame": np.repeat(np.arange(n_f), n_t), "time_s": np.repeat(self.time_s, n_t),
                "target": np.tile(np.arange(n_t), n_f),
                **{f"set_{k}": self.set[k].ravel() for k in ("range_m", "azimuth_deg",
                                                             "velocity_mps")},
                **{k: self.detected[k].ravel() for k in ("range_m", "azimuth_deg",
                                                         "velocity_mps")},
                **{f"truth_{k}": (self.truth[k] if self.truth is not None
                                  else np.full((n_f, n_t), np.nan)).ravel()
                   for k in ("range_m", "azimuth_deg", "velocity_mps")},
                "status": self._status.ravel(),
                "budget": (np.asarray(self.role).ravel() if self.role is not None
                           else np.full(n_f * n_t, "", dtype=object))}

    def _programme_columns(self) -> dict:
        p = self.programme
        frame = p[:, 0].astype(int)
        with np.errstate(divide="ignore"):
            amp_db = 20 * np.log10(p[:, 5])
        return {"frame": frame, "time_s": self.time_s[frame], "target": p[:, 1].astype(int),
                "channel": p[:, 2].astype(int), "delay_s": p[:, 3], "doppler_hz": p[:, 4],
                "amplitude_db": amp_db, "phase_rad": p[:, 6]}

    def tracks_csv(self) -> str:
        """``tracks.csv``: :data:`TRACK_COLUMNS`, the detected columns empty where lost."""
        return _csv(self._track_columns(), TRACK_COLUMNS)

    def programme_csv(self) -> str:
        """``programme.csv``: :data:`PROGRAMME_COLUMNS`, one row per frame, target, channel."""
        return _csv(self._programme_columns(), PROGRAMME_COLUMNS)

    def plot(self):
        """Set and detected azimuth over time, the hand-overs marked, and the angle error;
        the switched baseline beside it where it was played."""
        from ...viz.playback import playback_figure  # matplotlib: only for the figure
        runs = [self] + ([self.baseline] if self.baseline is not None else [])
        # under a budget: the targets synthesized as themselves (the merged ones are compared
        # to the truth twin in the summary and objects.png)
        alone = self.tracked
        return playback_figure(
            self.time_s, np.where(alone, self.set["azimuth_deg"], np.nan),
            {r.mode: np.where(r.tracked, r.detected["azimuth_deg"], np.nan) for r in runs},
            {r.mode: [self.time_s[f] for f, _ in r.handovers()] for r in runs},
            title=self.scene.name,
            objects={r.mode: o for r in runs if (o := r._object_tracks()) is not None})

    def _object_tracks(self) -> dict | None:
        """The extended objects' clouds over the drive for :meth:`plot` (None: no object or
        no truth twin)."""
        if self.clouds is None or self.object_of is None:
            return None
        from ..objects import air_offset_m, clouds_by_frame, pairs
        rows, scale = self.clouds
        t = self.time_s
        obj = np.asarray(self.object_of) >= 0
        pr = []
        for f, o, tr, rt in clouds_by_frame(rows, air_offset_m(self.scene)):
            j, _ = pairs(rt, tr, scale)  # each RTS detection's truth of its cell
            ok = j >= 0
            pr += [(t[f], d) for d in rt[ok, 2] - tr[j[ok], 2]]
        return {"set_deg": self.set["azimuth_deg"][:, obj],
                "truth": [(t[r[0]], r[5]) for r in rows if r[1] == "truth"],
                "rts": [(t[r[0]], r[5]) for r in rows if r[1] == "rts"],
                "pairs": pr}

    def animate(self, path, fps: int = 5):
        """Write the drive as an animated GIF (matplotlib's PillowWriter): the arc from above
        with the front ends that carry a target, the set and detected directions, and the
        targets' paths (:func:`rtsgeom.viz.playback.playback_animation`)."""
        from ...geometry import build_setup
        from ...viz.playback import DriveFrames, playback_animation  # matplotlib: the figure
        setup = build_setup(self.scene)
        n_f, n_q = len(self.time_s), setup.fe.count
        amp = np.zeros((n_f, n_q))
        p = self.programme
        np.add.at(amp, (p[:, 0].astype(int), p[:, 2].astype(int)), p[:, 5])
        az = np.radians(self.set["azimuth_deg"])
        xy = self.set["range_m"][..., None] * np.stack([np.sin(az), np.cos(az)], axis=-1)
        frames = DriveFrames(self.time_s, amp, xy, self.set["azimuth_deg"],
                             self.detected["azimuth_deg"])
        return playback_animation(path, frames, np.degrees(setup.fe_azimuth_rad()),
                                  self.scene.rts.arc_radius_m,
                                  title=f"{self.scene.name}: {self.mode}", fps=fps)


def budget_line(b: dict) -> str:
    """One line on a played budget (:meth:`PlaybackResult.summary`'s ``budget``)."""
    def span(k):
        lo, hi = b[k]["min"], b[k]["max"]
        return f"{lo}" if lo == hi else f"{lo}-{hi}"
    line = (f"{b['max_targets_per_channel']} a channel: {span('kept')} targets kept, "
            f"{span('merged')} scatterers merged, {span('dropped')} dropped a frame")
    return line


def _csv(cols: dict, names) -> str:
    """Rows of ``cols`` in the order ``names``: integers as such, floats in full precision
    (``repr``), NaN as an empty field."""
    buf = io.StringIO()
    buf.write(",".join(names) + "\n")
    data = [cols[n] for n in names]
    for row in zip(*data):
        buf.write(",".join(_cell(v) for v in row) + "\n")
    return buf.getvalue()


def _cell(v) -> str:
    if isinstance(v, str):
        return v
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    v = float(v)
    return repr(v) if np.isfinite(v) else ""
