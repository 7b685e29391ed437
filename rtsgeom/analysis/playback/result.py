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

__all__ = ["PlaybackResult", "PROGRAMME_COLUMNS", "TRACK_COLUMNS"]

PROGRAMME_COLUMNS = ("frame", "time_s", "target", "channel", "delay_s", "doppler_hz",
                     "amplitude_db", "phase_rad")
TRACK_COLUMNS = ("frame", "time_s", "target", "set_range_m", "set_azimuth_deg",
                 "set_velocity_mps", "range_m", "azimuth_deg", "velocity_mps",
                 "truth_range_m", "truth_azimuth_deg", "truth_velocity_mps", "status")


@dataclass(frozen=True, repr=False)
class PlaybackResult(Result):
    """A drive played frame by frame (``Playback``).

    Attributes
    ----------
    scene : Scene
        The scene played.
    mode : str
        The amplitude mode.
    time_s : ndarray, (frames,)
        Each frame's time.
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
    def angle_error_deg(self) -> np.ndarray:
        """Detected minus set azimuth (frames, targets), NaN where lost."""
        return self.detected["azimuth_deg"] - self.set["azimuth_deg"]

    @property
    def vs_truth_deg(self) -> np.ndarray:
        """Detected minus the truth twin's azimuth (frames, targets), NaN where either has
        none (all NaN without the truth twin)."""
        if self.truth is None:
            return np.full(self.split.shape, np.nan)
        return self.detected["azimuth_deg"] - self.truth["azimuth_deg"]

    def handovers(self) -> list[tuple[int, int]]:
        """(frame, target) where the channels carrying the target differ from the frame before."""
        return [(f, k) for k in range(self.num_targets) for f in range(1, len(self.time_s))
                if self.channels[f, k] != self.channels[f - 1, k]]

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
        per target the same, and the baseline's where it was played."""
        err = np.abs(self.angle_error_deg)
        # the track's range and radial velocity against the set-points
        r_err = np.abs(self.detected["range_m"] - self.set["range_m"])
        v_err = np.abs(self.detected["velocity_mps"] - self.set["velocity_mps"])
        lost = ~np.isfinite(self.detected["azimuth_deg"])
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
        if self.baseline is not None:
            out["baseline"] = {k: v for k, v in self.baseline.summary().items()
                               if k != "targets"}
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
                "status": self._status.ravel()}

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
        return playback_figure(
            self.time_s, self.set["azimuth_deg"],
            {r.mode: r.detected["azimuth_deg"] for r in runs},
            {r.mode: [self.time_s[f] for f, _ in r.handovers()] for r in runs},
            title=self.scene.name)

    def animate(self, path, fps: int = 5):
        """Write the drive as an animated GIF (matplotlib's PillowWriter): the arc from above
        with the front ends that carry a target, the set and detected directions, and the
        targets' paths (:func:`rtsgeom.viz.playback.playback_animation`)."""
        from ...geometry import build_setup
        from ...viz.playback import playback_animation  # matplotlib: only for the figure
        setup = build_setup(self.scene)
        n_f, n_q = len(self.time_s), setup.fe.count
        amp = np.zeros((n_f, n_q))
        p = self.programme
        np.add.at(amp, (p[:, 0].astype(int), p[:, 2].astype(int)), p[:, 5])
        az = np.radians(self.set["azimuth_deg"])
        xy = self.set["range_m"][..., None] * np.stack([np.sin(az), np.cos(az)], axis=-1)
        return playback_animation(path, self.time_s, np.degrees(setup.fe_azimuth_rad()), amp,
                                  xy, self.set["azimuth_deg"], self.detected["azimuth_deg"],
                                  self.scene.rts.arc_radius_m,
                                  title=f"{self.scene.name}: {self.mode}", fps=fps)


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
