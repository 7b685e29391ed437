"""Playback's config: each declared range and choice enforced exactly at its edges, the error
naming the field, the value and the allowed range in full."""

from __future__ import annotations

import pytest

from conftest import assert_bounds
from rtsgeom.analysis.playback.study import Playback

BOUNDS = [
    ("amplitudes", [None, "exact", "array-factor", "paper", "nearest"],
     [("ideal", "Playback: amplitudes = 'ideal': must be one of exact, array-factor, paper, "
                "nearest")]),
    ("paths", ["exact", "raytrace"],
     [("sionna", "Playback: paths = 'sionna': must be one of exact, raytrace")]),
    ("baseline", [True, False], [(1, "Playback: baseline = 1: must be true or false"),
                                 ("yes", "Playback: baseline = 'yes': must be true or false")]),
    ("bins", [0, 64], [(-1, "Playback: bins = -1: must be in [0, 64]"),
                       (65, "Playback: bins = 65: must be in [0, 64]")]),
    ("workers", [1, 256], [(0, "Playback: workers = 0: must be in [1, 256]"),
                           (257, "Playback: workers = 257: must be in [1, 256]")]),
    ("chain", ["fast", "full"], [("quick", "Playback: chain = 'quick': must be one of fast, "
                                           "full")]),
]


@pytest.mark.parametrize("name, ok, bad", BOUNDS, ids=[b[0] for b in BOUNDS])
def test_playback_enforces_each_range_at_its_edges(name, ok, bad):
    assert_bounds(lambda v: Playback(**{name: v}), ok, bad)


def test_playback_defaults_are_the_documented_ones():
    d = Playback()
    assert (d.amplitudes, d.paths, d.baseline, d.bins, d.workers, d.chain) == (
        None, "exact", True, 2, 1, "fast")


def test_a_scene_without_a_drive_is_refused(default_scene):
    from conftest import assert_refused
    assert_refused(lambda: Playback()(default_scene),
                   f"{default_scene.source}: has no [scenario] to play (add [scenario] with "
                   "[[scenario.targets]], docs/scenario.md)")
