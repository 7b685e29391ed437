"""Tests of ``rtsgeom.synthesis.cells``: closed forms and invariants on grids of inputs."""

from __future__ import annotations

import numpy as np
import pytest


@pytest.mark.parametrize("count", [2, 3, 5])
def test_enclosing_interval_is_the_adjacent_pair_in_one_dimension(count):
    """1-D cells: a direction between two neighbouring front ends (in any index order) is
    enclosed by exactly that pair, also with only two front ends; outside the span none."""
    from rtsgeom.errors import CellUnreachable
    from rtsgeom.synthesis.cells import enclosing_cell
    rng = np.random.default_rng(count)
    x = np.sort(rng.uniform(-0.5, 0.5, count))
    perm = rng.permutation(count)
    pts = x[perm][:, None]
    for k in range(count - 1):
        for f in (0.0, 0.3, 0.99):
            u = x[k] + f * (x[k + 1] - x[k])
            got = enclosing_cell([u], pts)
            assert sorted(perm[list(got)]) == [k, k + 1]  # channel q sits at rank perm[q]
    for u in (x[0] - 0.01, x[-1] + 0.01):
        with pytest.raises(CellUnreachable):
            enclosing_cell([u], pts)


def test_every_refusal_of_enclosing_cell_is_said_whole():
    """1-D outside the span (either side; its ends enclosed), one front end alone, fewer than
    three front ends in 2-D, and a 2-D direction outside the hull (its corners enclosed): each
    ``CellUnreachable`` whole, with the span or hull in direction cosines."""
    from conftest import assert_refused
    from rtsgeom.errors import CellUnreachable
    from rtsgeom.synthesis.cells import enclosing_cell
    x = np.array([0.1, -0.2, 0.3])[:, None]
    assert enclosing_cell([-0.2], x) == (1, 0) and enclosing_cell([0.3], x) == (0, 2)
    for u in (-0.2000001, 0.3000001):
        assert_refused(lambda: enclosing_cell([u], x),
                       f"direction cosine {u:.6f} is outside the front ends' span "
                       "[-0.200000, 0.300000]", CellUnreachable)
    assert_refused(lambda: enclosing_cell([0.1], x[:1]),
                   "direction cosine 0.100000 is outside the front ends' span "
                   "[0.100000, 0.100000]", CellUnreachable)
    for n in (1, 2):
        assert_refused(lambda: enclosing_cell([0.0, 0.0], np.zeros((n, 2))),
                       f"{n} front ends cannot enclose a 2-D direction (a cell needs at least 3 "
                       "not on one line)", CellUnreachable)
    sq = np.array([[-0.1, -0.05], [0.2, -0.05], [-0.1, 0.15], [0.2, 0.15]])
    assert enclosing_cell([0.2, 0.15], sq) == (0, 1, 2, 3)
    assert len(enclosing_cell([0.05, 0.05], sq, quads=False)) == 3
    for u in ([0.21, 0.0], [0.0, -0.06], [-0.3, 0.4]):
        assert_refused(lambda: enclosing_cell(u, sq),
                       f"direction (u_az, u_el) = ({u[0]:.6f}, {u[1]:.6f}) is outside every "
                       "cell of the front ends (their hull spans u_az [-0.100000, 0.200000], "
                       "u_el [-0.050000, 0.150000])", CellUnreachable)
