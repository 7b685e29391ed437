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


def _result():
    """Two spacings x two budgets x three ranges, hand-made."""
    import numpy as np
    from rtsgeom.analysis.object_design import ObjectDesignResult
    study = ObjectDesign(ranges_m=(5.0, 10.0, 20.0), spacings_deg=(8.0, 16.0), budgets=(None, 2),
                         min_share=0.8, max_centroid_deg=0.5)
    share = np.array([[[0.9, 0.8, 1.0], [0.9, 0.7, 1.0]], [[1.0, 0.95, 0.85], [0.8, 0.9, 0.8]]])
    cent = np.array([[[0.1, -0.5, 0.2], [0.1, 0.1, 0.1]], [[0.6, 0.0, 0.0], [-0.2, 0.3, 0.5]]])
    kept = np.arange(12.0).reshape(2, 2, 3)
    truth = 10.0 + np.arange(12.0).reshape(2, 2, 3)
    return ObjectDesignResult(study, "bench", "targets[0]", np.array([5, 3]), share, cent, kept,
                              truth, truth - 1.0)


def test_the_smallest_design_that_reproduces_the_object():
    res = _result()
    # share >= 0.8 and |centroid| <= 0.5 at every range (both edges included)
    assert res.reproduces.tolist() == [[True, False], [False, True]]
    assert res.best() == {"front_ends": 3, "spacing_deg": 16.0, "max_targets_per_channel": 2}
    title, rows = res._summary()
    assert title == "bench: object design (targets[0])"
    assert rows == [
        ("ranges", "5 .. 20 m"),
        ("tolerance", "share >= 0.8, |centroid| <= 0.5 deg at every range"),
        ("smallest design", "3 front ends 16 deg apart, budget 2"),
        ("5 x 8 deg, budget none", "min share 0.80, max |centroid| 0.50 deg (reproduces)"),
        ("5 x 8 deg, budget 2", "min share 0.70, max |centroid| 0.10 deg"),
        ("3 x 16 deg, budget none", "min share 0.85, max |centroid| 0.60 deg"),
        ("3 x 16 deg, budget 2", "min share 0.80, max |centroid| 0.50 deg (reproduces)")]
    cols = res._columns()
    assert list(cols["spacing_deg"]) == [8.0] * 6 + [16.0] * 6
    assert list(cols["max_targets_per_channel"]) == [0, 0, 0, 2, 2, 2] * 2
    assert list(cols["range_m"]) == [5.0, 10.0, 20.0] * 4
    assert list(cols["front_ends"]) == [5] * 6 + [3] * 6
    assert list(cols["truth_detections"]) == list(res.truth.ravel())


def test_nothing_reproduces_the_object_when_no_design_meets_both():
    import dataclasses
    import numpy as np
    res = _result()
    worse = dataclasses.replace(res, share=res.share - 0.3)
    assert not worse.reproduces.any() and worse.best() is None
    assert worse._summary()[1][2] == ("smallest design", "none reproduces the object")
    assert np.array_equal(dataclasses.replace(res, centroid_deg=res.centroid_deg + 1.0)
                          .reproduces, np.zeros((2, 2), bool))


def test_the_figure_draws_each_designs_share_centroid_and_targets_kept():
    import matplotlib
    matplotlib.use("Agg")
    import numpy as np
    res = _result()
    fig = res.plot()
    ax, cx, bx = fig.axes[:3]
    r = [5.0, 10.0, 20.0]
    designs = [(i, j) for i in range(2) for j in range(2)]
    share = [ln for ln in ax.get_lines() if ln.get_label() != "tolerance"]
    assert [list(ln.get_ydata()) for ln in share] == [list(res.share[i, j]) for i, j in designs]
    assert all(list(ln.get_xdata()) == r for ln in share)
    cen = [ln for ln in cx.get_lines() if ln.get_label() != "tolerance"]
    assert [list(ln.get_ydata()) for ln in cen] == [list(np.abs(res.centroid_deg[i, j]))
                                                    for i, j in designs]
    kept = bx.get_lines()
    assert [list(ln.get_ydata()) for ln in kept[:4]] == [list(res.kept[i, j]) for i, j in designs]
    truth = kept[4]
    assert truth.get_label() == "truth twin's detections"
    assert list(truth.get_xdata()) == r and list(truth.get_ydata()) == list(res.truth[0, 0])
    assert [ln.get_label() for ln in share] == ["5 FE x 8 deg, budget none",
                                                "5 FE x 8 deg, budget 2",
                                                "3 FE x 16 deg, budget none",
                                                "3 FE x 16 deg, budget 2"]
    tol = [ln for ln in ax.get_lines() if ln.get_label() == "tolerance"]
    assert list(tol[0].get_ydata()) == [0.8, 0.8]
    tol = [ln for ln in cx.get_lines() if ln.get_label() == "tolerance"]
    assert list(tol[0].get_ydata()) == [0.5, 0.5]
    assert ax.get_title() == "bench: what the RTS reproduces"
    assert cx.get_ylim() == (0.0, 1.6 * 0.6)
    import matplotlib.pyplot as plt
    plt.close(fig)
