"""rtsgeom.scene.scenario's rules read in full: each refusal of check_scenario and of the
drive's size (the field, the value and the whole sentence, each bound taken at its edge and
refused just beyond), the waypoint a set-point's refusal blames, the set-points it returns;
the segment a waypoint's time belongs to and the frames' times."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from rtsgeom.scene.scenario import (MAX_FRAMES, MAX_TARGET_FRAMES, ScenarioConfig,
                                    ScenarioTargetConfig, check_scenario, frame_times,
                                    trajectory)

DEG = math.pi / 180.0
INF = math.inf
#: on the boresight from 10 m to 20 m in 2 s: 10, 15, 20 m at the 1 s frames, 5 m/s receding
AWAY = ((0.0, 10.0, 0.0, 0.0), (2.0, 20.0, 0.0, 0.0))


def drive(*waypoints, duration=2.0, period=1.0, static=0, elevation=False, compensate=True,
          arc=0.8, objects=()):
    """A scene of one scenario target per ``waypoints`` (SI rows; those at ``objects`` an
    extended object) and ``static`` [[targets]]."""
    tg = tuple(ScenarioTargetConfig(waypoints=tuple(map(tuple, w)),
                                    scatterers=((0.0, 0.0, 0.0, 0.0),) if i in objects else None)
               for i, w in enumerate(waypoints))
    return SimpleNamespace(
        scenario=ScenarioConfig(duration_s=duration, frame_period_s=period, targets=tg),
        targets=(None,) * static, radar=SimpleNamespace(elevation_processing=elevation),
        rts=SimpleNamespace(arc_radius_m=arc, compensate_air_path=compensate))


def check(scene, r_lim=30.0, v_lim=9.0, air=0.0, per_frame=None):
    got = []
    sps = check_scenario(scene, lambda f, v, a: got.append((f, v, a)),
                         (r_lim, v_lim, "WHY_R", "WHY_V"), air, per_frame)
    return got, sps


W = "scenario.targets[{}].waypoints"
START = "0: a drive starts at t_s = 0"
BLAME = "{} (at t = {} s, on the way from it, {})"
FAR = "a waypoint of a drive with every range < {} m, WHY_R"
ARC = ("a waypoint of a drive with every range > rts.arc_radius_m ({} m): the RTS cannot emit "
       "before the radar signal reached it")
FAST = "a waypoint of a drive with every radial velocity in (-{0}, {0}) m/s, WHY_V"
W0, W1 = [0.0, 10.0, 0.0, 0.0], [2.0, 20.0, 0.0, 0.0]

CASES = [
    ("within every limit", (AWAY,), {}, {"r_lim": 20.5, "v_lim": 5.5}, []),
    ("short steps", (((0.0, 10.0, 0.0, 0.0), (0.5, 11.0, 0.0, 0.0), (2.0, 12.0, 0.0, 0.0)),), {},
     {}, []),
    ("a late start", (((0.5, 10.0, 0.0, 0.0), (2.0, 20.0, 0.0, 0.0)),), {}, {},
     [(W.format(0) + "[0][0]", 0.5, START)]),
    ("a repeated time", (((0.0, 10.0, 0.0, 0.0), (1.0, 11.0, 0.0, 0.0), (1.0, 12.0, 0.0, 0.0),
                          (2.0, 13.0, 0.0, 0.0)),), {}, {},
     [(W.format(0) + "[2][0]", 1.0, "> 1 s: waypoint times must increase strictly")]),
    ("a time going back", (((0.0, 10.0, 0.0, 0.0), (2.5, 11.0, 0.0, 0.0), (1.5, 12.0, 0.0, 0.0)),),
     {}, {}, [(W.format(0) + "[2][0]", 1.5, "> 2.5 s: waypoint times must increase strictly")]),
    ("an early end", (((0.0, 10.0, 0.0, 0.0), (1.0, 11.0, 0.0, 0.0), (1.5, 12.0, 0.0, 0.0)),),
     {}, {}, [(W.format(0) + "[2][0]", 1.5, ">= scenario.duration_s (2 s): the last waypoint ends the "
                                    "drive, or later")]),
    ("an end at the duration", (AWAY,), {}, {}, []),
    ("one waypoint: at rest", (((0.0, 10.0, 0.0, 0.0),),), {}, {}, []),
    # each target on its own: a refused one does not stop the next
    ("four refused", (((1.0, 10.0, 0.0, 0.0),), ((0.0, 10.0, 0.0, 0.0), (0.0, 11.0, 0.0, 0.0)),
                      ((0.0, 10.0, 0.0, 0.0), (1.0, 11.0, 0.0, 0.0)), AWAY), {},
     {"r_lim": 15.0},
     [(W.format(0) + "[0][0]", 1.0, START),
      (W.format(1) + "[1][0]", 0.0, "> 0 s: waypoint times must increase strictly"),
      (W.format(2) + "[1][0]", 1.0, ">= scenario.duration_s (2 s): the last waypoint ends the "
                                    "drive, or later"),
      (W.format(3) + "[0]", W0, BLAME.format(FAR.format(15), 1, "the range is 15 m"))]),
    # the range at its bound refused, blaming the waypoint that starts the frame's segment
    ("range at its bound", (AWAY,), {}, {"r_lim": 15.0},
     [(W.format(0) + "[0]", W0, BLAME.format(FAR.format(15), 1, "the range is 15 m"))]),
    ("range at the last waypoint", (AWAY,), {}, {"r_lim": np.nextafter(15.0, INF)},
     [(W.format(0) + "[1]", W1, BLAME.format(FAR.format(15), 2, "the range is 20 m"))]),
    ("range less the air path", (AWAY,), {}, {"r_lim": 15.5, "air": 0.5},
     [(W.format(0) + "[0]", W0, BLAME.format(FAR.format(15), 1, "the range is 15 m"))]),
    ("a row in degrees", (((0.0, 25.12345678, 0.1, 0.0), (4.0, 25.12345678, -0.1, 0.0)),),
     {"duration": 4.0}, {"r_lim": 20.0},
     [(W.format(0) + "[0]", [0.0, 25.123457, round(math.degrees(0.1), 6), 0.0],
       BLAME.format(FAR.format(20), 0, "the range is 25.12 m"))]),
    # the arc: the range must exceed its radius where the RTS subtracts the air path
    ("at the arc", (AWAY,), {"arc": 10.0}, {},
     [(W.format(0) + "[0]", W0, BLAME.format(ARC.format(10), 0, "the range is 10 m"))]),
    ("just beyond the arc", (AWAY,), {"arc": np.nextafter(10.0, 0.0)}, {}, []),
    ("the arc not subtracted", (AWAY,), {"arc": 12.0, "compensate": False}, {}, []),
    # radial velocity: |v| >= v_lim refused, either sign
    ("receding at the limit", (AWAY,), {}, {"v_lim": 5.0},
     [(W.format(0) + "[0]", W0, BLAME.format(FAST.format(5), 0, "the radial velocity is 5 m/s"))]),
    ("approaching beyond", (((0.0, 20.0, 0.0, 0.0), (2.0, 10.0, 0.0, 0.0)),), {}, {"v_lim": 5.0},
     [(W.format(0) + "[0]", [0.0, 20.0, 0.0, 0.0],
       BLAME.format(FAST.format(5), 0, "the radial velocity is -5 m/s"))]),
    ("just below the limit", (AWAY,), {}, {"v_lim": np.nextafter(5.0, INF)}, []),
    ("speeding up", (((0.0, 10.0, 0.0, 0.0), (1.0, 15.0, 0.0, 0.0), (2.0, 25.0, 0.0, 0.0)),), {},
     {"v_lim": 5.0}, [(W.format(0) + "[0]", W0, BLAME.format(FAST.format(5), 0,
                                                            "the radial velocity is 5 m/s"))]),
    # elevations need the RuT's 2-D beamforming
    ("an elevation", (((0.0, 10.0, 0.0, 0.0), (2.0, 10.0, 0.0, 2 * DEG)),), {}, {},
     [("radar.elevation_processing", False, f"true: {W.format(0)} has elevations; a target off "
       "the horizontal plane needs the RuT's 2-D beamforming")]),
    ("an elevation seen", (((0.0, 10.0, 0.0, 0.0), (2.0, 10.0, 0.0, 2 * DEG)),),
     {"elevation": True}, {}, []),
    # every rule a drive breaks, in the rules' order
    ("far and fast", (AWAY,), {"elevation": False}, {"r_lim": 12.0, "v_lim": 4.0, "air": 1.0},
     [(W.format(0) + "[0]", W0, BLAME.format(FAR.format(11), 1, "the range is 15 m")),
      (W.format(0) + "[0]", W0, BLAME.format(FAST.format(4), 0, "the radial velocity is 5 m/s"))]),
]


@pytest.mark.parametrize("waypoints, scene, limits, want", [c[1:] for c in CASES],
                         ids=[c[0] for c in CASES])
def test_a_drives_waypoints_are_refused_in_full_at_each_bound(waypoints, scene, limits, want):
    got, _ = check(drive(*waypoints, **scene), **limits)
    assert got == want


def test_a_drive_returns_the_set_points_of_its_objects_whose_waypoints_pass():
    """Only an extended object's (its scatterers are checked by check_moving_objects), only
    where its waypoints pass; a drive over its size: none."""
    good = ((0.0, 12.0, 0.1, 0.0), (2.0, 14.0, -0.1, 0.0))
    late = ((0.5, 12.0, 0.1, 0.0), (2.0, 14.0, -0.1, 0.0))
    scene = drive(good, good, late, good, objects=(1, 2, 3))
    got, sps = check(scene)
    assert got == [(W.format(2) + "[0][0]", 0.5, START)]
    assert sorted(sps) == [1, 3]
    want = trajectory(good, frame_times(1.0, 2.0))
    for k in ("time_s", "range_m", "azimuth_rad", "elevation_rad", "velocity_mps", "position_m",
              "velocity_vec_mps"):
        assert np.array_equal(getattr(sps[1], k), getattr(want, k)), k
    assert check(SimpleNamespace(scenario=None)) == ([], {})
    got, sps = check(drive(good, objects=(0,)), per_frame=1025)
    assert sps == {} and len(got) == 1


@pytest.mark.parametrize("duration, refused", [(99.999, False), (100.0, True)])
def test_a_drive_has_at_most_max_frames(duration, refused):
    sc = drive(((0.0, 10.0, 0.0, 0.0),), duration=duration, period=1e-3, objects=(0,))
    got, sps = check(sc)
    assert sorted(sps) == ([] if refused else [0])
    assert MAX_FRAMES == 100_000
    if not refused:
        assert got == [] and sc.scenario.num_frames == MAX_FRAMES
        return
    assert got == [("scenario.frame_period_s", 1e-3,
                    f">= {100.0 / 99_999:g} s: scenario.duration_s = 100 s would take 100001 "
                    "frames (at most 100000)")]


@pytest.mark.parametrize("static, per_frame, n_t", [(1023, None, 1024), (1024, None, 1025),
                                                    (0, 1024, 1024), (3, 1025, 1025)])
def test_a_drives_frame_holds_at_most_max_targets(static, per_frame, n_t):
    """[[targets]] and the drive's targets (the objects' scatterers counted, ``per_frame``)."""
    got, _ = check(drive(((0.0, 10.0, 0.0, 0.0),), static=static, duration=0.0),
                   per_frame=per_frame)
    assert got == ([] if n_t <= 1024 else [
        ("scenario.targets", "1 entries", "at most 1024 point targets a frame with [[targets]] "
         "and the objects' scatterers (they make 1025)")])


@pytest.mark.parametrize("targets, refused", [(10, False), (11, True)])
def test_a_drive_holds_at_most_max_target_frames(targets, refused):
    """100 000 frames x 10 targets are the million target-frames allowed; 11 are refused with
    the frame period that would fit."""
    got, sps = check(drive(((0.0, 10.0, 0.0, 0.0),), duration=99.999, period=1e-3,
                           objects=(0,)), per_frame=targets)
    assert sorted(sps) == ([] if refused else [0])
    assert MAX_TARGET_FRAMES == 1_000_000
    assert got == ([] if not refused else [
        ("scenario.frame_period_s", 1e-3,
         f">= {99.999 * 11 / (1_000_000 - 11):g} s: 100000 frames x 11 targets would be 1100000 "
         "target-frames (at most 1000000: the played drive's memory; a shorter "
         "scenario.duration_s or fewer targets)")])


def test_at_a_waypoint_the_target_moves_on_the_segment_that_starts_there():
    """The velocity at an inner waypoint's time is the next segment's, at the last one the
    segment that ends there; before the first and after the last: at rest there."""
    wp = np.array([[0.0, 10.0, 0.2, 0.0], [1.0, 12.0, -0.1, 0.1], [3.0, 15.0, 0.3, -0.05]])
    p = np.stack([wp[:, 1] * np.cos(wp[:, 3]) * np.sin(wp[:, 2]),
                  wp[:, 1] * np.cos(wp[:, 3]) * np.cos(wp[:, 2]), wp[:, 1] * np.sin(wp[:, 3])],
                 axis=1)
    sp = trajectory(wp, [-1.0, 0.0, 1.0, 2.0, 3.0, 4.0])
    v01, v12 = p[1] - p[0], (p[2] - p[1]) / 2.0
    want_v = [np.zeros(3), v01, v12, v12, v12, np.zeros(3)]
    want_p = [p[0], p[0], p[1], p[1] + v12, p[2], p[2]]
    assert np.allclose(sp.velocity_vec_mps, want_v, rtol=0, atol=1e-12)
    assert np.allclose(sp.position_m, want_p, rtol=0, atol=1e-12)
    r = np.linalg.norm(want_p, axis=1)
    assert np.allclose(sp.range_m, r, rtol=1e-12)
    assert np.allclose(sp.elevation_rad, np.arcsin(np.array(want_p)[:, 2] / r), atol=1e-12)
    assert np.allclose(sp.azimuth_rad, np.arctan2(np.array(want_p)[:, 0], np.array(want_p)[:, 1]),
                       atol=1e-12)
    assert np.allclose(sp.velocity_mps, np.einsum("fi,fi->f", want_p, want_v) / r, atol=1e-12)
    assert np.array_equal(sp.time_s, [-1.0, 0.0, 1.0, 2.0, 3.0, 4.0])


@pytest.mark.parametrize("period, duration, want", [
    (0.1, 0.3, [0.0, 0.1, 0.2, 0.3]), (0.3, 1.0, [0.0, 0.3, 0.6, 0.9]), (0.5, 0.0, [0.0]),
    (0.7, 2.1, [0.0, 0.7, 1.4, 2.1]), (1.0, 1.999, [0.0, 1.0]),
    (1 / 3, 1.0, [0.0, 0.333333333333, 0.666666666667, 1.0])])
def test_frame_times_are_whole_periods_up_to_the_duration_as_written(period, duration, want):
    """k * period rounded to 1e-12 s (0.3, not 0.30000000000000004), the duration's last
    period taken where the division rounds below it (0.3 / 0.1 = 2.9999999999999996)."""
    assert frame_times(period, duration).tolist() == want
    sc = ScenarioConfig(duration_s=duration, frame_period_s=period)
    assert sc.frame_times().tolist() == want and sc.num_frames == len(want)
