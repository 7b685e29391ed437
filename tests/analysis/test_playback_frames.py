"""rtsgeom.analysis.playback.frames' planner read in full on stand-ins: a frame's programme is
its block's (planned once per block of PLAN_BLOCK frames, with the block's targets, pairs,
calibration and names), cut to its budget's lead programme where the drive has a budget; the
switched baseline's is the nearest front ends'."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from rtsgeom.analysis.playback import frames


def planner(budgets, n=20, mode="exact"):
    fp = object.__new__(frames.FramePlanner)
    fp.mode, fp.budgets, fp._block = mode, budgets, (None, None)
    fp.frames = [f"targets {f}" for f in range(n)]
    fp.pairs = [f"pairs {f}" for f in range(n)]
    fp.setup = SimpleNamespace(scene=SimpleNamespace(targets=(0, 1, 2)))
    fp.paths, fp.probe, fp.cals, fp.offsets = "paths", "probe", "cals", "offsets"
    return fp


@pytest.fixture
def stand_ins(monkeypatch):
    planned = []

    def program_frames(setup, paths, mode, targets, pairs, cal, names):
        planned.append((setup, paths, mode, targets, pairs, cal, names))
        return [(f"programme of {t}", None, [f"note on {t}"]) for t in targets]
    monkeypatch.setattr(frames, "program_frames", program_frames)
    monkeypatch.setattr(frames, "FixedCalibration", lambda *a: ("calibration",) + a)
    monkeypatch.setattr(frames, "frame_target_names", lambda *a: ("names",) + a[1:])
    monkeypatch.setattr(frames, "lead_program", lambda program, budget: ("lead", program, budget))
    monkeypatch.setattr(frames, "program_nearest", lambda scene, setup: ("nearest", scene, setup))
    return planned


def test_a_frames_programme_is_its_blocks_planned_once_per_block(stand_ins):
    assert frames.PLAN_BLOCK == 16
    fp = planner([])
    assert fp.program(1, "scene 1") == ("programme of targets 1", ["note on targets 1"])
    assert fp.program(15, "scene 15") == ("programme of targets 15", ["note on targets 15"])
    assert len(stand_ins) == 1  # frames 0..15: one block
    assert fp.program(16, "scene 16") == ("programme of targets 16", ["note on targets 16"])
    assert fp.program(19, "scene 19")[0] == "programme of targets 19"
    assert fp.program(0, "scene 0")[0] == "programme of targets 0"
    assert len(stand_ins) == 3
    setup, paths, mode, targets, pairs, cal, names = stand_ins[1]
    assert (setup, paths, mode) == (fp.setup, "paths", "exact")
    assert targets == [f"targets {f}" for f in range(16, 20)]  # the last block: 4 frames
    assert pairs == [f"pairs {f}" for f in range(16, 20)]
    assert cal == ("calibration", "probe", "cals", "offsets")
    assert names == [("names", f, 3, f"targets {f}", None) for f in range(16, 20)]
    assert [t for t in stand_ins[0][3]] == [f"targets {f}" for f in range(16)]


def test_a_budgeted_frame_plays_its_lead_programme_with_the_budgets_targets(stand_ins):
    budgets = [SimpleNamespace(targets=f"merged {f}") for f in range(20)]
    fp = planner(budgets)
    assert fp.program(17, "scene 17") == (("lead", "programme of merged 17", budgets[17]),
                                          ["note on merged 17"])
    _, _, _, targets, _, _, names = stand_ins[0]
    assert targets == [f"merged {f}" for f in range(16, 20)]
    assert names == [("names", f, 3, f"targets {f}", budgets[f]) for f in range(16, 20)]


def test_the_switched_baseline_plays_the_nearest_front_ends(stand_ins):
    fp = planner([], mode="nearest")
    assert fp.program(3, "scene 3") == (("nearest", "scene 3", fp.setup), [])
    assert stand_ins == []


@pytest.mark.parametrize("static, k, want", [(None, 0, "frame 4: targets[0]"),
                                             (None, 1, "frame 4: scenario.targets[0]"),
                                             (None, 3, "frame 4: scenario.targets[2]"),
                                             (3, 2, "frame 4: targets[2]"),
                                             (3, 3, "frame 4: scenario.targets[0]")])
def test_a_frames_targets_are_named_as_the_file_writes_them(static, k, want):
    scene = SimpleNamespace(targets=(None,))
    assert frames.frame_target_names(scene, 4, static)(k) == want
