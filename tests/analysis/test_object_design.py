"""ObjectDesign's config: each declared range enforced exactly at its edges, the error naming
the field, the value and the allowed range in full; the run count capped."""

from __future__ import annotations

import pytest

from conftest import assert_bounds
from rtsgeom.analysis.object_design import MAX_RUNS, ObjectDesign
from rtsgeom.errors import ParameterError

_BUDGETS = "must be a non-empty tuple of integers >= 1 or None (no limit)"
BOUNDS = [
    ("ranges_m", [(0.5, 1e4), [3.0]],
     [((0.4,), "ObjectDesign: ranges_m[0] = 0.4: must be a finite number in [0.5, 10000]"),
      ((5.0, 10000.5), "ObjectDesign: ranges_m[1] = 10000.5: must be a finite number in "
                       "[0.5, 10000]"),
      ((), "ObjectDesign: ranges_m = []: must be a list (at least 1 and at most 64 entries) of "
           "numbers in [0.5, 10000]"),
      ((1.0,) * 65, "ObjectDesign: ranges_m = [" + "1.0, " * 12 + "...]: must be a list (at least "
                    "1 and at most 64 entries) of numbers in [0.5, 10000]")]),
    ("spacings_deg", [(0.5, 60.0)],
     [((0.4,), "ObjectDesign: spacings_deg[0] = 0.4: must be a finite number in [0.5, 60]"),
      ((60.5,), "ObjectDesign: spacings_deg[0] = 60.5: must be a finite number in [0.5, 60]"),
      ((), "ObjectDesign: spacings_deg = []: must be a list (at least 1 and at most 64 entries) "
           "of numbers in [0.5, 60]")]),
    ("budgets", [(None,), (1, 2), (None, 1000)],
     [((), f"ObjectDesign: budgets = (): {_BUDGETS}"),
      ((0,), f"ObjectDesign: budgets = (0,): {_BUDGETS}"),
      ((None, -1), f"ObjectDesign: budgets = (None, -1): {_BUDGETS}"),
      ((1.5,), f"ObjectDesign: budgets = (1.5,): {_BUDGETS}"),
      ((True,), f"ObjectDesign: budgets = (True,): {_BUDGETS}")]),
    ("min_share", [0.0, 1.0], [(-0.5, "ObjectDesign: min_share = -0.5: must be in [0, 1]"),
                               (1.5, "ObjectDesign: min_share = 1.5: must be in [0, 1]")]),
    ("max_centroid_deg", [0.0, 90.0],
     [(-0.5, "ObjectDesign: max_centroid_deg = -0.5: must be in [0, 90]"),
      (90.5, "ObjectDesign: max_centroid_deg = 90.5: must be in [0, 90]")]),
]


@pytest.mark.parametrize("name, ok, bad", BOUNDS, ids=[b[0] for b in BOUNDS])
def test_object_design_enforces_each_range_at_its_edges(name, ok, bad):
    assert_bounds(lambda v: ObjectDesign(**{name: v}), ok, bad)


@pytest.mark.parametrize("ranges, spacings, budgets", [(50, 2, 2), (25, 4, 2), (40, 5, 1)])
def test_object_design_runs_are_capped(ranges, spacings, budgets):
    """ranges x spacings x budgets <= MAX_RUNS (200) is taken, one more range is refused with
    the count."""
    assert MAX_RUNS == 200 and ranges * spacings * budgets == MAX_RUNS
    kw = dict(spacings_deg=tuple(range(1, spacings + 1)), budgets=tuple(range(1, budgets + 1)))
    ObjectDesign(ranges_m=tuple(range(1, ranges + 1)), **kw)
    with pytest.raises(ParameterError) as exc:
        ObjectDesign(ranges_m=tuple(range(1, ranges + 2)), **kw)
    n = (ranges + 1) * spacings * budgets
    assert str(exc.value) == (f"ObjectDesign: ranges_m x spacings_deg x budgets = {n} runs: "
                              "must be at most 200 (each is a full run)")


def test_object_design_repr_is_short_and_says_the_grid():
    s = ObjectDesign(ranges_m=(7.0, 3.0, 12.5), spacings_deg=(8.0,), budgets=(None, 2))
    assert repr(s) == "ObjectDesign(3 ranges 3..12.5 m, spacings [8.0] deg, budgets [None, 2])"


def test_a_scene_without_an_extended_object_is_refused(default_scene):
    from conftest import assert_refused
    assert_refused(lambda: ObjectDesign()(default_scene),
                   f"{default_scene.source}: has no extended object (a [[targets]] or "
                   "[[scenario.targets]] entry with scatterers or mesh)")
