"""A study's pair argument: one adjacent pair or 'all', anything else refused in full words."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import assert_refused
from rtsgeom.analysis.pairs import study_pairs
from rtsgeom.geometry import build_setup


@pytest.mark.parametrize("pair, shown", [("01", "'01'"), ((0, 1, 2), "(0, 1, 2)"),
                                         ((True, 1), "(True, 1)"), ((0.0, 1), "(0.0, 1)"),
                                         ([0], "[0]"), (None, "None")])
def test_a_pair_is_two_front_end_indices_or_all(default_scene, pair, shown):
    setup = build_setup(default_scene)
    assert_refused(lambda: study_pairs(setup, pair), f"pair = {shown}: must be two front-end "
                                                     "indices (i, j), or 'all'")
    assert_refused(lambda: study_pairs(setup, pair, name="--pair"),
                   f"--pair = {shown}: must be two front-end indices (i, j), or 'all'")


def test_all_is_every_adjacent_pair_and_numpy_indices_are_indices(crossing_bench):
    setup = build_setup(crossing_bench)
    assert study_pairs(setup, "all") == [(0, 1), (1, 2), (2, 3), (3, 4)]
    assert study_pairs(setup, (np.int64(2), 3)) == [(2, 3)]
    assert study_pairs(setup, [1, 2]) == [(1, 2)]
