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
