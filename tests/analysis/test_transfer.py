"""transfer's working memory: the percentiles partition one copy in place, and the study's
(1 + 2B, P) errors are one array filled in place (benchmarks/transfer_memory.py measures the
peak at the documented maximum)."""

from __future__ import annotations

import numpy as np
import pytest

from rtsgeom.analysis.transfer import TransferStudy, percentiles
from rtsgeom.errors import ParameterError


def test_percentiles_are_numpys_and_leave_the_input_alone():
    rng = np.random.default_rng(0)
    for shape in [(7,), (40, 13), (3, 1001)]:
        x = rng.normal(size=shape)
        x.flat[::5] = np.nan
        keep = x.copy()
        got = percentiles(x)
        a = np.abs(x[np.isfinite(x)])
        assert got == {"p50": float(np.percentile(a, 50)), "p95": float(np.percentile(a, 95)),
                       "max": float(a.max())}
        assert np.array_equal(x, keep, equal_nan=True)
    assert percentiles(np.full(4, np.nan)) == {"p50": None, "p95": None, "max": None}



@pytest.mark.parametrize("pairs", [((0,),), ((0, 1), (2,)), ((0, 1, 2),)])
def test_a_transfer_pair_is_two_front_ends(pairs):
    with pytest.raises(ParameterError, match=r"pairs\[\d\]"):
        TransferStudy(pairs=pairs)
