"""The scene file's ``[scenario]``: targets that move on straight lines between waypoints.

A scenario target's waypoints are ``[t_s, range_m, azimuth_deg(, elevation_deg)]`` seen from
the RuT (its radar frame: azimuth from its boresight towards +x, elevation up). Between two
waypoints the target moves on the straight line in space joining them, at constant speed (a
crossing car, a cut-in, an overtaking one); its set range, azimuth, elevation and radial
velocity at any time follow from that geometry (:func:`trajectory`). The frames are
``t = k * frame_period_s`` for ``k = 0 .. floor(duration_s / frame_period_s)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .evolve import Evolvable
from .schema import spec
from .sections import HEADING_DOC, MAX_SCATTERERS, MAX_TARGETS, SCATTERER_COLUMNS

__all__ = ["ScenarioTargetConfig", "ScenarioConfig", "SetPoints", "trajectory", "frame_times",
           "check_scenario", "MAX_FRAMES", "MAX_WAYPOINTS", "MAX_TARGET_FRAMES"]

MAX_FRAMES = 100_000
MAX_WAYPOINTS = 10_000
MAX_SCENARIO_TARGETS = 64
#: frames x targets (static and moving) of one drive: a played drive holds ~600 bytes per
#: target and frame (tracks, programme and channels of the mode and its baseline), 600 MB here
MAX_TARGET_FRAMES = 1_000_000
_DEG = math.pi / 180.0

#: a waypoint's columns: (name, unit, lo, hi, scale to SI); elevation may be left out (0)
WAYPOINT_COLUMNS = (("t_s", "s", 0.0, 1e5, 1.0), ("range_m", "m", 0.01, 1e4, 1.0),
                    ("azimuth_deg", "deg", -90.0, 90.0, _DEG),
                    ("elevation_deg", "deg", -60.0, 60.0, _DEG))


@dataclass(frozen=True)
class ScenarioTargetConfig(Evolvable):
    """A moving target: straight lines in space between its waypoints, at constant speed."""

    waypoints: tuple[tuple[float, float, float, float], ...] = spec(
        "waypoints", "rows", "[t_s, range_m, azimuth_deg(, elevation_deg)] seen from the RuT, "
        "times strictly increasing from 0 and the last at or after duration_s (one waypoint: "
        "a target at rest)", n=3, columns=WAYPOINT_COLUMNS, min_items=1,
        max_items=MAX_WAYPOINTS)
    rcs_dbsm: float = spec("rcs_dbsm", "float", "radar cross-section", 10.0, unit="dBsm",
                           lo=-100.0, hi=100.0)
    scatterers: tuple[tuple[float, float, float, float], ...] | None = spec(
        "scatterers", "rows", "an extended object: [x_m, y_m, z_m, rcs_dbsm] per scatterer in "
        "its own frame (x right, y away from the RuT, z up, at heading 0), placed at the "
        "waypoints' position each frame (docs/objects.md)", None, n=4,
        columns=SCATTERER_COLUMNS, min_items=1, max_items=MAX_SCATTERERS)
    mesh: str | None = spec(
        "mesh", "str", "an extended object from a mesh file (relative to the scene's folder), "
        "its scatterers derived from the facets facing the RuT at the first frame, then moving "
        "with it", None,
        max_chars=1000)
    heading: str = spec("heading", "str", "how the object is turned: fixed (heading_deg) or "
                        "velocity (along its motion on the segment)", "fixed",
                        choices=("fixed", "velocity"))
    heading_rad: float = spec("heading_deg", "float", HEADING_DOC + " (heading = fixed)", 0.0,
                              unit="deg", lo=-180.0, hi=180.0, scale=_DEG)

    @property
    def rcs_m2(self) -> float:
        return 10.0 ** (self.rcs_dbsm / 10.0)


@dataclass(frozen=True)
class ScenarioConfig(Evolvable):
    """A drive: moving targets played frame by frame (``rtsgeom play``)."""

    duration_s: float = spec("duration_s", "float", "length of the drive (frames at 0, "
                             "frame_period_s, ... up to it)", unit="s", lo=0.0, hi=1e5)
    frame_period_s: float = spec("frame_period_s", "float", "the RuT's frame period: one "
                                 "set-point, programme and detection per frame", 0.05, unit="s",
                                 lo=1e-4, hi=60.0)
    targets: tuple[ScenarioTargetConfig, ...] = spec(
        "targets", "tables", "[[scenario.targets]] the moving targets", [], cls=ScenarioTargetConfig,
        max_items=MAX_SCENARIO_TARGETS, min_items=1, item="target")

    @property
    def num_frames(self) -> int:
        return int(math.floor(self.duration_s / self.frame_period_s * (1 + 1e-12))) + 1

    def frame_times(self) -> np.ndarray:
        return frame_times(self.frame_period_s, self.duration_s)


def frame_times(frame_period_s: float, duration_s: float) -> np.ndarray:
    """The frames' times ``k * frame_period_s``, ``k = 0 .. floor(duration_s / period)`` (s)."""
    n = int(math.floor(duration_s / frame_period_s * (1 + 1e-12))) + 1
    return np.round(np.arange(n) * frame_period_s, 12)  # 0.3, not 0.30000000000000004


@dataclass(frozen=True)
class SetPoints:
    """One target's set-points per frame (SI): range, azimuth, elevation, radial velocity
    (d range / dt, positive receding) and the position (F, 3) and velocity (F, 3) in the
    RuT's frame (x right, y along the boresight, z up)."""

    time_s: np.ndarray
    range_m: np.ndarray
    azimuth_rad: np.ndarray
    elevation_rad: np.ndarray
    velocity_mps: np.ndarray
    position_m: np.ndarray
    velocity_vec_mps: np.ndarray


def _cartesian(rng, az, el) -> np.ndarray:
    ce = np.cos(el)
    return np.stack([rng * ce * np.sin(az), rng * ce * np.cos(az), rng * np.sin(el)], axis=-1)


def trajectory(waypoints, time_s) -> SetPoints:
    """Set-points of a target moving on straight lines between ``waypoints`` at the times.

    Parameters
    ----------
    waypoints : array_like, (W, 4)
        ``[t_s, range_m, azimuth_rad, elevation_rad]`` rows (SI), times strictly increasing.
    time_s : array_like, (F,)
        Frame times (s). Before the first and after the last waypoint the target rests there.

    Returns
    -------
    SetPoints
        Range ``|p|``, azimuth ``atan2(x, y)``, elevation ``asin(z / |p|)`` and radial velocity
        ``p . v / |p|`` of the position ``p(t)`` on the segment holding ``t`` (at a waypoint, the
        segment that starts there; at the last one, the one that ends there).
    """
    wp = np.atleast_2d(np.asarray(waypoints, float))
    t = np.atleast_1d(np.asarray(time_s, float))
    pts = _cartesian(wp[:, 1], wp[:, 2], wp[:, 3])  # (W, 3)
    if len(wp) == 1:
        pos = np.broadcast_to(pts[0], (t.size, 3)).copy()
        vel = np.zeros_like(pos)
    else:
        seg = np.clip(np.searchsorted(wp[:, 0], t, side="right") - 1, 0, len(wp) - 2)
        t0, t1 = wp[seg, 0], wp[seg + 1, 0]
        vel = (pts[seg + 1] - pts[seg]) / (t1 - t0)[:, None]
        inside = (t >= wp[0, 0]) & (t <= wp[-1, 0])
        vel[~inside] = 0.0  # at rest outside the waypoints' times
        tc = np.clip(t, wp[0, 0], wp[-1, 0])
        pos = pts[seg] + vel * (tc - t0)[:, None]
        pos[~inside] = np.where((t < wp[0, 0])[~inside, None], pts[0], pts[-1])
    rng = np.linalg.norm(pos, axis=1)
    return SetPoints(t, rng, np.arctan2(pos[:, 0], pos[:, 1]), np.arcsin(pos[:, 2] / rng),
                     np.einsum("fi,fi->f", pos, vel) / rng, pos, vel)


def _frames_fit(scene, fail, per_frame: int | None) -> bool:
    """Whether the scenario's frames, targets a frame and target-frames stay within what the
    played drive holds (:data:`MAX_FRAMES`, ``MAX_TARGETS``, :data:`MAX_TARGET_FRAMES`); the
    first one over is reported through ``fail``."""
    sc = scene.scenario
    if sc.num_frames > MAX_FRAMES:
        fail("scenario.frame_period_s", sc.frame_period_s,
             f">= {sc.duration_s / (MAX_FRAMES - 1):g} s: scenario.duration_s = "
             f"{sc.duration_s:g} s would take {sc.num_frames} frames (at most {MAX_FRAMES})")
        return False
    n_t = len(scene.targets) + len(sc.targets) if per_frame is None else per_frame
    if n_t > MAX_TARGETS:
        fail("scenario.targets", f"{len(sc.targets)} entries",
             f"at most {MAX_TARGETS} point targets a frame with [[targets]] and the objects' "
             f"scatterers (they make {n_t})")
        return False
    if sc.num_frames * n_t > MAX_TARGET_FRAMES:
        fail("scenario.frame_period_s", sc.frame_period_s,
             f">= {sc.duration_s * n_t / (MAX_TARGET_FRAMES - n_t):g} s: {sc.num_frames} frames "
             f"x {n_t} targets would be {sc.num_frames * n_t} target-frames (at most "
             f"{MAX_TARGET_FRAMES}: the played drive's memory; a shorter scenario.duration_s "
             "or fewer targets)")
        return False
    return True


def check_scenario(scene, fail, limits, air_extra_m: float, per_frame: int | None = None
                   ) -> dict:
    """The scenario's own rules (called by :func:`rtsgeom.scene.rules.problems`): waypoint
    times, the number of frames, and every frame's set-points within what the processing
    resolves (``limits``: :func:`~rtsgeom.scene.rules.resolvable_limits`; ``air_extra_m``: the
    air path the RTS does not subtract; ``per_frame``: the point targets of a frame, the
    objects' scatterers counted, :func:`rtsgeom.scene.objects.targets_per_frame`). Returns
    each moving object's set-points by its index, where its waypoints pass (its scatterers
    are checked by :func:`rtsgeom.scene.objects.check_moving_objects`)."""
    sc = scene.scenario
    sps: dict = {}
    if sc is None or not _frames_fit(scene, fail, per_frame):
        return sps
    r_lim, v_lim, why_r, why_v = limits
    r_max = r_lim - air_extra_m
    times = sc.frame_times()
    rts = scene.rts
    for i, tg in enumerate(sc.targets):
        where = f"scenario.targets[{i}].waypoints"
        wp = np.asarray(tg.waypoints, float)
        if wp[0, 0] != 0.0:
            fail(f"{where}[0][0]", wp[0, 0], "0: a drive starts at t_s = 0")
            continue
        step = np.diff(wp[:, 0])
        if np.any(step <= 0):
            k = int(np.argmax(step <= 0)) + 1
            fail(f"{where}[{k}][0]", wp[k, 0], f"> {wp[k - 1, 0]:g} s: waypoint times must "
                 "increase strictly")
            continue
        if len(wp) > 1 and wp[-1, 0] < sc.duration_s:
            fail(f"{where}[{len(wp) - 1}][0]", wp[-1, 0], f">= scenario.duration_s "
                 f"({sc.duration_s:g} s): the last waypoint ends the drive, or later")
            continue
        sp = trajectory(wp, times)
        if tg.scatterers is not None or tg.mesh is not None:
            sps[i] = sp

        def blame(k: int, what: str, allowed: str) -> None:
            """The waypoint that starts the segment holding frame k (as written in the file)."""
            w = max(int(np.searchsorted(wp[:, 0], times[k], side="right")) - 1, 0)
            w = min(w, len(wp) - 1)
            row = [wp[w, 0], wp[w, 1], math.degrees(wp[w, 2]), math.degrees(wp[w, 3])]
            fail(f"{where}[{w}]", [round(float(x), 6) for x in row],
                 f"{allowed} (at t = {times[k]:g} s, on the way from it, {what})")

        bad = np.flatnonzero(sp.range_m >= r_max)
        if bad.size:
            blame(bad[0], f"the range is {sp.range_m[bad[0]]:.4g} m",
                  f"a waypoint of a drive with every range < {r_max:.4g} m, {why_r}")
        low = np.flatnonzero(sp.range_m <= rts.arc_radius_m) if rts.compensate_air_path else []
        if len(low):
            blame(low[0], f"the range is {sp.range_m[low[0]]:.4g} m",
                  f"a waypoint of a drive with every range > rts.arc_radius_m "
                  f"({rts.arc_radius_m:g} m): the RTS cannot emit before the radar signal "
                  "reached it")
        fast = np.flatnonzero(np.abs(sp.velocity_mps) >= v_lim)
        if fast.size:
            blame(fast[0], f"the radial velocity is {sp.velocity_mps[fast[0]]:.4g} m/s",
                  f"a waypoint of a drive with every radial velocity in (-{v_lim:.4g}, "
                  f"{v_lim:.4g}) m/s, {why_v}")
        if np.any(wp[:, 3] != 0) and not scene.radar.elevation_processing:
            fail("radar.elevation_processing", False, f"true: {where} has elevations; a "
                 "target off the horizontal plane needs the RuT's 2-D beamforming")
    return sps
