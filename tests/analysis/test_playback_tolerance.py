"""The drive's mounting tolerance: its arguments refused word for word, each declared range
at its edges, a scene without a drive named."""

from __future__ import annotations

import pytest

from conftest import ROOT, assert_bounds, assert_refused
from rtsgeom.analysis.playback.tolerance import drive_tolerance
from rtsgeom.scene import load_scene

F = "drive_tolerance"
_SIGMA = "must be 3 finite numbers in [0, 10] mm"


@pytest.fixture(scope="module")
def drive():
    return load_scene(ROOT / "scenes" / "crossing.toml")


BOUNDS = [
    ("draws", [(None, f"{F}: draws = None: must be an integer in [1, 1e+07]"),
               (0, f"{F}: draws = 0: must be in [1, 1e+07]"),
               (10_000_001, f"{F}: draws = 10000001: must be in [1, 1e+07]"),
               (2.5, f"{F}: draws = 2.5: must be an integer in [1, 1e+07]")]),
    ("seed", [(-1, f"{F}: seed = -1: must be in [0, 9.22337e+18]")]),
    ("distribution", [("cauchy", f"{F}: distribution = 'cauchy': must be one of normal, "
                                 "uniform")]),
    ("spec_deg", [(0.0, f"{F}: spec_deg = 0: must be in [1e-06, 90] deg"),
                  (90.5, f"{F}: spec_deg = 90.5: must be in [1e-06, 90] deg")]),
    ("sigma_mm", [((0.1, 0.1), f"{F}: sigma_mm = (0.1, 0.1): must be a list of 3 numbers in mm"),
                  ((0.1, 0.1, 10.5), f"{F}: sigma_mm = (0.1, 0.1, 10.5): {_SIGMA}"),
                  ((-0.1, 0.1, 0.1), f"{F}: sigma_mm = (-0.1, 0.1, 0.1): {_SIGMA}")]),
]


@pytest.mark.parametrize("name, bad", BOUNDS, ids=[b[0] for b in BOUNDS])
def test_drive_tolerance_refuses_each_argument_word_for_word(drive, name, bad):
    assert_bounds(lambda v: drive_tolerance(drive, **{name: v}), [], bad)


def test_a_scene_without_a_drive_is_named(default_scene):
    assert_refused(lambda: drive_tolerance(default_scene, draws=10),
                   f"{default_scene.source}: has no [scenario] (docs/scenario.md)")


def test_the_edges_of_the_ranges_are_taken(drive):
    r = drive_tolerance(drive, sigma_mm=(0.0, 10.0, 0.0), draws=1, seed=0, spec_deg=90.0,
                        distribution="uniform")
    assert r.draws == 1 and r.spec_deg == 90.0 and r.distribution == "uniform"
    assert r.seed == 0 and r.yield_("calibrated") == 1.0  # every error within 90 deg
