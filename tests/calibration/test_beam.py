"""Tests of ``rtsgeom.calibration.beam``: which probe columns a beam pair's fit uses."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from rtsgeom.calibration.beam import BeamProbes

#: a fine sweep's errors per column: one that crosses zero (negative to positive), one that
#: does not
CROSS, FLAT = np.linspace(-1.0, 1.0, 9), np.linspace(0.5, 2.0, 9)


@pytest.mark.parametrize("dims, axis_pair, columns, want", [
    # a pair across a cell's diagonal: the across-line columns that cross zero, odd
    (2, False, (FLAT, CROSS, FLAT, FLAT), ([1], [True])),
    (2, False, (FLAT, CROSS, FLAT, CROSS), ([1, 3], [True, True])),
    (2, False, (CROSS, FLAT, CROSS, -FLAT), ([0, 2], [False, False])),  # none across: along
    (2, False, (FLAT, FLAT, FLAT, FLAT), ([0, 2], [False, False])),
    # side by side / stacked (an axis pair) or on an arc: the along-line columns, even
    (2, True, (FLAT, CROSS, FLAT, CROSS), ([0, 2], [False, False])),
    (1, False, (CROSS, FLAT), ([0, 1], [False, False])),
    (1, False, (FLAT, FLAT), ([0, 1], [False, False])),
])
def test_fit_columns_are_the_crossing_ones_across_a_diagonal_pair_else_along(dims, axis_pair,
                                                                           columns, want):
    """Columns range-major (along, across per probe range): for a two-dimensional pair that
    is not on an axis the across-line columns crossing zero over the sweep, flagged odd; any
    other pair (or none crossing) the along-line columns, flagged even."""
    probes = SimpleNamespace(dims=dims, axis_pair=axis_pair, ranges=(20.0, 23.0))
    cols, odd = BeamProbes.fit_columns(probes, np.stack(columns, axis=1))
    assert cols.tolist() == want[0] and odd.tolist() == want[1]
    assert odd.dtype == bool
