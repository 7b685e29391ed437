"""The association of detections to targets on hand-made points in resolution cells: the gate's
edge, the nearest-target rule, one detection serving targets of one cell ('merged'), each
detection's nearest target, and the cell the association measures in."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from rtsgeom.radar.association import assign, associate, resolution_cell

SCALE = np.array([0.5, 0.25, 0.0625])  # range bin, velocity bin, two-target resolution in u


def _pts(cells):
    """Points given in resolution cells."""
    return np.asarray(cells, float) * SCALE


@pytest.mark.parametrize("gate", [1.0, 2.0, 3.0])
def test_the_gate_is_inclusive_in_range_and_doppler_bins(gate):
    t = _pts([[20, 5, 0]])
    for off, inside in ((gate, True), (gate + 0.01, False)):
        for axis in (0, 1):
            d = t.copy()
            d[0, axis] += off * SCALE[axis]
            a = associate(t, d, SCALE, gate)
            assert (list(a.detection), a.status) == (([0], ("detected",)) if inside else
                                                     ([-1], ("not_detected",))), (off, axis)
            assert list(a.owner) == ([0] if inside else [-1])


def test_each_target_takes_its_own_detection_and_a_nearer_targets_is_not_its():
    t = _pts([[20, 0, 0], [20, 0, 4], [40, 0, 0]])
    d = _pts([[40.2, 0, 0.1], [20, 0.3, 3.8], [20.1, 0, 0.2]])
    a = associate(t, d, SCALE)
    assert list(a.detection) == [2, 1, 0] and list(a.owner) == [2, 1, 0]
    assert a.status == ("detected",) * 3 and a.merged_with == ((), (), ())
    assert list(a.nearest) == [2, 1, 0]
    # one detection between two targets, nearer the second: only the second may take it
    b = associate(_pts([[20, 0, 0], [20, 0, 2.5]]), _pts([[20, 0, 1.5]]), SCALE)
    assert list(b.detection) == [-1, 0] and b.status == ("not_detected", "detected")


def test_one_detection_serves_the_targets_of_its_cell_as_merged():
    t = _pts([[20, 0, 0], [20, 0, 0.6], [20, 0, 3.0]])
    d = _pts([[20, 0, 0.4]])
    a = associate(t, d, SCALE)
    assert list(a.detection) == [0, 0, -1] and list(a.owner) == [1]
    assert a.status == ("merged", "merged", "not_detected")
    assert a.merged_with == ((1,), (0,), ())
    assert list(a.nearest) == [1]
    # within one angular cell of the detection (inclusive) a target is served by it, beyond not
    for u0, served in ((1.0, True), (1.125, False)):
        c = associate(_pts([[20, 0, 0], [20, 0, u0 + 0.125]]), _pts([[20, 0, u0]]), SCALE)
        assert list(c.detection) == ([0, 0] if served else [-1, 0])
        assert c.status == (("merged", "merged") if served else ("not_detected", "detected"))


def test_a_detection_outside_every_cell_is_nobodys_nearest():
    a = associate(_pts([[20, 0, 0]]), _pts([[20, 0, 1.5], [25, 0, 0]]), SCALE)
    assert list(a.nearest) == [-1, -1] and list(a.owner) == [0, -1]
    empty = associate(np.zeros((0, 3)), _pts([[1, 1, 1]]), SCALE)
    assert list(empty.owner) == [-1] and list(empty.nearest) == [-1] and empty.status == ()
    none = associate(_pts([[1, 1, 0], [2, 1, 0]]), np.zeros((0, 3)), SCALE)
    assert none.status == ("not_detected",) * 2 and none.merged_with == ((), ())
    assert list(none.detection) == [-1, -1] and none.owner.size == 0


def test_the_resolution_cell_is_the_bins_then_the_two_target_resolution(default_scene):
    from rtsgeom.geometry import build_setup
    from rtsgeom.radar.peaks import two_target_resolution
    from rtsgeom.radar.steering import Steering
    radar = default_scene.radar
    st = Steering.auto(build_setup(default_scene).rut, radar)
    res = two_target_resolution(st)
    assert np.array_equal(resolution_cell(radar, st), np.r_[radar.range_resolution_m,
                                                            radar.velocity_resolution_mps, res])
    rd = SimpleNamespace(range_m=np.array([0.0, 0.3, 0.6]), velocity_mps=np.array([-1.0, -0.75]))
    assert resolution_cell(radar, st, rd) == pytest.approx(np.r_[0.3, 0.25, res], rel=1e-15)


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("shape", [(1, 1), (3, 3), (4, 7), (7, 4), (8, 8)])
@pytest.mark.parametrize("density", [0.15, 0.5, 1.0])
def test_assign_is_an_optimal_assignment_with_or_without_the_solver(seed, shape, density):
    """The allowed pairs taken as they are (no row or column shared) or the solver's: the
    same number of allowed pairs and the same total distance as scipy's assignment, each
    target and detection at most once; a conflict-free pattern is returned unchanged."""
    from scipy.optimize import linear_sum_assignment
    rng = np.random.default_rng(seed)
    dist = rng.uniform(0.0, 5.0, shape)
    allowed = rng.random(shape) < density
    rows, cols = assign(allowed, dist)
    ok = allowed[rows, cols]
    r_ref, c_ref = linear_sum_assignment(np.where(allowed, dist, 1e12))
    ok_ref = allowed[r_ref, c_ref]
    assert ok.sum() == ok_ref.sum()
    assert dist[rows[ok], cols[ok]].sum() == pytest.approx(dist[r_ref[ok_ref], c_ref[ok_ref]].sum())
    assert len(set(rows[ok])) == ok.sum() and len(set(cols[ok])) == ok.sum()
    # a pattern without conflicts: one allowed pair per row and column at most
    free = np.zeros(shape, bool)
    k = min(shape)
    free[rng.permutation(shape[0])[:k], rng.permutation(shape[1])[:k]] = rng.random(k) < 0.7
    rows, cols = assign(free, dist)
    assert sorted(zip(rows.tolist(), cols.tolist())) == sorted(zip(*map(list, np.nonzero(free))))
