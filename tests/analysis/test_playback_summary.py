"""rtsgeom.analysis.playback.result read in full on a hand-made drive: the summary (every key
and value built from the arrays frame by frame), its lines, the budget's line, summary.json's
context, the tracks and programme tables and their CSV text, the hand-overs and their jumps."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from rtsgeom import __version__
from rtsgeom.analysis.playback.result import (PROGRAMME_COLUMNS, TRACK_COLUMNS, PlaybackResult,
                                              budget_line)

NAN = np.nan
F, T = 5, 3
TIME = np.array([0.0, 0.25, 0.5, 0.75, 1.0])
SET_AZ = np.array([[-10.0 + f, -5.0 + f, float(f)] for f in range(F)])
#: target 0 lost at frame 3, target 1 at frame 4; target 2 an object's scatterer
AZ_ERR = np.array([[0.1, 0.0, 1.0], [-0.2, 0.4, 1.0], [0.05, -0.1, 1.0], [NAN, 0.2, 1.0],
                   [0.3, NAN, 1.0]])
SPLIT = np.array([[0, 0, 0], [0, 1, 0], [0, 0, 0], [0, 0, 2], [0, 0, 0]])
#: target 0 handed over at frames 2 and 4; target 1 at frame 1, carried by nothing at frame 3;
#: target 2 (not tracked) every frame
CARRY = [[(0, 1), (0, 1), (5, 6)], [(0, 1), (1, 2), (6, 7)], [(1, 2), (1, 2), (7, 8)],
         [(1, 2), (), (8, 9)], [(2, 3), (1, 2), (9, 10)]]
PROGRAMME = np.array([[0, 0, 0, 1.0e-7, 100.0, 0.5, 0.1], [0, 0, 1, 1.1e-7, 100.0, 0.25, -0.2],
                      [2, 1, 2, 2.0e-7, -50.0, 0.0, 0.3]])


def _channels(rows):
    out = np.empty((len(rows), len(rows[0])), object)
    for f, row in enumerate(rows):
        for k, c in enumerate(row):
            out[f, k] = c
    return out


def played(mode="exact", role=None, budget=None, truth=True, status=None, baseline=None,
           fallbacks=(), chain="fast", max_targets=None, object_of=(-1, -1, 0)):
    rng = np.arange(F * T, dtype=float).reshape(F, T)
    set_ = {"range_m": 10.0 + rng, "azimuth_deg": SET_AZ.copy(), "velocity_mps": 1.0 - 0.5 * rng}
    det = {"range_m": set_["range_m"] + 0.01 * (rng % 4) - 0.015,
           "azimuth_deg": SET_AZ + AZ_ERR,
           "velocity_mps": set_["velocity_mps"] + 0.002 * (rng % 3)}
    det["range_m"][np.isnan(AZ_ERR)] = NAN
    det["velocity_mps"][np.isnan(AZ_ERR)] = NAN
    tru = None
    if truth:
        tru = {k: v + 0.03 for k, v in set_.items()}
        tru["azimuth_deg"][0, 1] = NAN
    scene = SimpleNamespace(name="drive", sha256="f00d", seed=7, targets=(None, None),
                            scenario=SimpleNamespace(frame_period_s=0.25, duration_s=1.0),
                            rts=SimpleNamespace(max_targets_per_channel=max_targets))
    return PlaybackResult(scene, mode, TIME, set_, det, SPLIT, _channels(CARRY), PROGRAMME,
                          {"pairs": []}, ("a warning",), baseline, tru, status, None, budget,
                          role, None if object_of is None else np.array(object_of), chain,
                          fallbacks)


def stats(values):
    v = [float(x) for x in values if np.isfinite(x)]
    return ({"max": max(v), "p95": float(np.percentile(v, 95))} if v
            else {"max": None, "p95": None})


def expected_summary(res, tracked, handovers, jumps, role=None, budget=None, merged=0,
                     chain=None):
    """The summary built frame by frame from the arrays."""
    det, set_ = res.detected, res.set
    cells = [(f, k) for f in range(F) for k in range(T)]

    def err(key, f, k):
        return abs(det[key][f, k] - set_[key][f, k]) if tracked[f][k] else NAN

    def per(key, k=None):
        return stats([err(key, f, j) for f, j in cells if k is None or j == k])
    lost = [[tracked[f][k] and np.isnan(det["azimuth_deg"][f, k]) for k in range(T)]
            for f in range(F)]
    truth = [abs(det["azimuth_deg"][f, k] - res.truth["azimuth_deg"][f, k])
             if res.truth is not None else NAN for f, k in cells]
    fin = [j for _, _, j in jumps if np.isfinite(j)]
    out = {"mode": res.mode, "frames": F,
           "point_targets": sum(any(tracked[f][k] for f in range(F)) for k in range(T)),
           "angle_error_deg": per("azimuth_deg"), "range_error_m": per("range_m"),
           "velocity_error_mps": per("velocity_mps"),
           "lost_frames": sum(any(row) for row in lost),
           "split_frames": sum(any(SPLIT[f] > 0) for f in range(F)),
           "handover_jump_deg": max(fin) if fin else None, "handovers": len(handovers),
           "vs_truth_deg": stats(truth), "merged_frames": merged,
           "targets": []}
    for k in range(T):
        jk = [j for _, kk, j in jumps if kk == k and np.isfinite(j)]
        out["targets"].append({
            "target": k, "angle_error_deg": per("azimuth_deg", k),
            "range_error_m": per("range_m", k), "velocity_error_mps": per("velocity_mps", k),
            "lost_frames": sum(lost[f][k] for f in range(F)),
            "split_frames": int(sum(SPLIT[:, k] > 0)),
            "handovers": sum(1 for _, kk in handovers if kk == k),
            "handover_jump_deg": max(jk) if jk else None})
    out["chain"] = chain or {"asked": "fast", "full_chain_frames": 0, "reasons": {}}
    if role is not None:
        out["budget"] = budget
    return out


def test_a_drives_summary_is_built_from_its_tracked_frames():
    """Target 2 is an object's scatterer (its cloud is compared elsewhere): no error, loss or
    hand-over of its own; splits count over every target; the truth twin over every target."""
    res = played()
    tracked = [[True, True, False]] * F
    handovers = [(2, 0), (4, 0), (1, 1)]
    assert res.handovers() == handovers
    e = res.angle_error_deg
    jumps = [(2, 0, abs(e[2, 0] - e[1, 0])), (4, 0, NAN), (1, 1, abs(e[1, 1] - e[0, 1]))]
    assert np.array_equal(res.handover_jumps_deg(), [j for *_, j in jumps], equal_nan=True)
    assert jumps[0][2] == pytest.approx(0.25, abs=1e-12)
    assert np.array_equal(res.tracked, tracked)
    assert np.allclose(res.angle_error_deg, np.where(tracked, AZ_ERR, NAN), equal_nan=True,
                       rtol=0, atol=1e-12)
    assert res.num_targets == 3
    assert res.summary() == expected_summary(res, tracked, handovers, jumps)
    none = played(truth=False)
    assert np.isnan(none.vs_truth_deg).all() and none.vs_truth_deg.shape == (F, T)
    assert none.summary()["vs_truth_deg"] == {"max": None, "p95": None}


def test_a_budgets_merged_and_dropped_targets_are_no_tracks_and_no_hand_overs():
    """Under a budget only the ``kept`` targets are tracked: target 0 leads a merged target at
    frame 1 (its hand-over at frame 2 is none), target 1 is dropped at frame 4; the budget's
    counts span the frames; 'merged' frames are those whose status says so; the chain's
    reasons are counted once a frame."""
    role = np.full((F, T), "kept", object)
    role[1, 0], role[4, 1], role[:, 2] = "lead", "dropped", "merged"
    status = np.full((F, T), "detected", object)
    status[[1, 3], 2] = "merged"
    counts = [{"kept": 2, "merged": 1, "dropped": 0}, {"kept": 1, "merged": 2, "dropped": 0},
              {"kept": 2, "merged": 1, "dropped": 0}, {"kept": 2, "merged": 1, "dropped": 0},
              {"kept": 1, "merged": 1, "dropped": 1}]
    fallbacks = ((), ("peak", "peak"), (), ("peak", "clip"), ("clip",))
    res = played(role=role, budget=tuple(counts), status=status, fallbacks=fallbacks,
                 max_targets=2, object_of=None)
    tracked = (role == "kept").tolist()
    handovers = [(4, 0), (1, 1)]
    budget = {"max_targets_per_channel": 2, "kept": {"min": 1, "max": 2},
              "merged": {"min": 1, "max": 2}, "dropped": {"min": 0, "max": 1}}
    chain = {"asked": "fast", "full_chain_frames": 3, "reasons": {"clip": 2, "peak": 2}}
    assert res.handovers() == handovers
    e = res.angle_error_deg
    assert res.summary() == expected_summary(res, tracked, handovers,
                                             [(4, 0, NAN), (1, 1, abs(e[1, 1] - e[0, 1]))], role,
                                             budget, merged=2, chain=chain)
    assert list(res.summary()["chain"]["reasons"]) == ["clip", "peak"]
    # no frame counted: the budget's counts are all 0
    empty = played(role=role, budget=None, max_targets=3, object_of=None)
    assert empty.summary()["budget"] == {"max_targets_per_channel": 3,
                                         **{k: {"min": 0, "max": 0}
                                            for k in ("kept", "merged", "dropped")}}


def test_the_baselines_summary_is_nested_without_its_targets_and_the_lines_say_it_all():
    base = played(mode="nearest")
    res = played(baseline=base)
    s = res.summary()
    assert s["baseline"] == {k: v for k, v in base.summary().items() if k != "targets"}
    assert "targets" in base.summary()
    title, rows = res._summary()
    assert title == "drive: exact, 5 frames x 3 targets, 2 lost, 2 split"
    e0 = s["targets"][0]["angle_error_deg"]["max"]
    e1 = s["targets"][1]["angle_error_deg"]["max"]
    assert rows == [
        ("max |angle error|", f"{s['angle_error_deg']['max']:.3g} deg"),
        ("p95 |angle error|", f"{s['angle_error_deg']['p95']:.3g} deg"),
        ("hand-overs", 3),
        ("largest jump at a hand-over", "0.4 deg"),
        ("baseline (nearest) max |angle error|", f"{s['angle_error_deg']['max']:.3g} deg"),
        ("target 0", f"max {e0:.3g} deg, 1 lost, 2 hand-overs"),
        ("target 1", f"max {e1:.3g} deg, 1 lost, 1 hand-overs"),
        ("target 2", "max none detected, 0 lost, 0 hand-overs")]
    assert f"{e0:.3g}" == "0.3" and f"{s['angle_error_deg']['max']:.3g}" == "0.4"


def test_one_target_under_a_budget_says_so_in_its_lines():
    role = np.full((F, 1), "kept", object)
    role[0, 0] = "dropped"
    one = PlaybackResult(
        SimpleNamespace(name="one", rts=SimpleNamespace(max_targets_per_channel=4)), "paper",
        TIME, {k: np.zeros((F, 1)) for k in ("range_m", "azimuth_deg", "velocity_mps")},
        {k: np.full((F, 1), NAN) for k in ("range_m", "azimuth_deg", "velocity_mps")},
        np.zeros((F, 1), int), _channels([[()]] * F), np.zeros((0, 7)), {},
        budget=({"kept": 3, "merged": 0, "dropped": 1},) * F, role=role)
    title, rows = one._summary()
    assert title == "one: paper, 5 frames x 1 target, 4 lost, 0 split"
    assert rows == [("max |angle error|", "none detected"), ("p95 |angle error|", "none detected"),
                    ("hand-overs", 0), ("largest jump at a hand-over", "none detected"),
                    ("budget", "4 a channel: 3 targets kept, 0 scatterers merged, 1 dropped a "
                               "frame"),
                    ("target 0", "max none detected, 4 lost, 0 hand-overs")]


@pytest.mark.parametrize("counts, want", [
    ((1, 1, 0, 0, 2, 2), "3 a channel: 1 targets kept, 0 scatterers merged, 2 dropped a frame"),
    ((1, 4, 0, 7, 0, 1), "3 a channel: 1-4 targets kept, 0-7 scatterers merged, 0-1 dropped a "
                         "frame")])
def test_the_budgets_line_gives_each_count_or_its_span(counts, want):
    b = {"max_targets_per_channel": 3}
    for k, (lo, hi) in zip(("kept", "merged", "dropped"), zip(counts[::2], counts[1::2])):
        b[k] = {"min": lo, "max": hi}
    assert budget_line(b) == want


def test_summary_json_is_the_summary_in_the_runs_context():
    res = played()
    d = res.summary_json()
    head = {"rtsgeom_version": __version__, "scene": "drive", "scene_sha256": "f00d", "seed": 7,
            "frame_period_s": 0.25, "duration_s": 1.0, "static_targets": 2}
    assert d == {**head, **res.summary(), "calibration": {"pairs": []},
                 "warnings": ["a warning"]}
    assert list(d)[:7] == list(head) and list(d)[-2:] == ["calibration", "warnings"]


def _row_cell(v) -> str:
    if isinstance(v, str):
        return v
    if float(v).is_integer() and isinstance(v, (int, np.integer)):
        return str(int(v))
    return repr(float(v)) if np.isfinite(v) else ""


def test_the_tracks_table_and_csv_hold_every_frame_and_target():
    """One row per (frame, target), frame-major: the set, detected and truth columns (empty
    where lost), the status and the budget's role; the table adds the azimuth error and the
    carrying channels."""
    role = np.full((F, T), "kept", object)
    role[2, 1] = "merged"
    status = np.full((F, T), "detected", object)
    status[3, 0] = "not_detected"
    res = played(role=role, status=status, max_targets=2, budget=())
    df = res.to_dataframe()
    assert list(df.columns) == list(TRACK_COLUMNS) + ["azimuth_error_deg", "channels"]
    rows = [(f, k) for f in range(F) for k in range(T)]
    want = {"frame": [f for f, _ in rows], "time_s": [TIME[f] for f, _ in rows],
            "target": [k for _, k in rows]}
    for key in ("range_m", "azimuth_deg", "velocity_mps"):
        want[f"set_{key}"] = [res.set[key][f, k] for f, k in rows]
        want[key] = [res.detected[key][f, k] for f, k in rows]
        want[f"truth_{key}"] = [res.truth[key][f, k] for f, k in rows]
    want["status"] = [status[f, k] for f, k in rows]
    want["budget"] = [role[f, k] for f, k in rows]
    for col, values in want.items():
        if col in ("status", "budget"):
            assert list(df[col]) == values, col
        else:
            assert np.array_equal(df[col].to_numpy(), values, equal_nan=True), col
    assert np.array_equal(df["azimuth_error_deg"], res.angle_error_deg.ravel(), equal_nan=True)
    assert list(df["channels"]) == [" ".join(map(str, CARRY[f][k])) for f, k in rows]
    text = res.tracks_csv()
    lines = text.split("\n")
    assert lines[0] == ",".join(TRACK_COLUMNS) and lines[-1] == "" and len(lines) == 2 + F * T
    for n, (f, k) in enumerate(rows):
        cells = [str(f), repr(float(TIME[f])), str(k)] + [
            _row_cell(want[c][n]) for c in TRACK_COLUMNS[3:12]] + [status[f, k], role[f, k]]
        assert lines[1 + n] == ",".join(cells), n
    assert ",detected," in lines[1] and lines[1 + 3 * T].endswith(",not_detected,kept")
    plain = played(truth=False)  # no truth twin, no budget: empty truth fields and roles
    first = plain.tracks_csv().split("\n")[1].split(",")
    assert first[9:12] == ["", "", ""] and first[12:] == ["detected", ""]
    assert list(plain.to_dataframe()["budget"]) == [""] * (F * T)


def test_the_programme_table_and_csv_hold_every_row_in_db():
    import warnings
    res = played()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # an amplitude of 0 is -inf dB, said by no warning
        df = res.programme_dataframe()
    assert list(df.columns) == list(PROGRAMME_COLUMNS)
    assert df["frame"].tolist() == [0, 0, 2] and df["target"].tolist() == [0, 0, 1]
    assert df["channel"].tolist() == [0, 1, 2] and df["time_s"].tolist() == [0.0, 0.0, 0.5]
    assert df["delay_s"].tolist() == [1.0e-7, 1.1e-7, 2.0e-7]
    assert df["doppler_hz"].tolist() == [100.0, 100.0, -50.0]
    assert df["amplitude_db"].tolist() == [20 * np.log10(0.5), 20 * np.log10(0.25), -np.inf]
    assert df["phase_rad"].tolist() == [0.1, -0.2, 0.3]
    assert df["frame"].dtype.kind == "i" and df["channel"].dtype.kind == "i"
    assert res.programme_csv() == (
        ",".join(PROGRAMME_COLUMNS) + "\n"
        f"0,0.0,0,0,1e-07,100.0,{float(20 * np.log10(0.5))!r},0.1\n"
        f"0,0.0,0,1,1.1e-07,100.0,{float(20 * np.log10(0.25))!r},-0.2\n"
        "2,0.5,1,2,2e-07,-50.0,,0.3\n")
