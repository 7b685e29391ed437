"""MonteCarlo, the draws' config every Monte-Carlo study takes: each declared range enforced
exactly at its edges (the engine's own lower bounds: 0 draws, a chunk of 1), the error naming
the field, the value and the range in full; its repr, seeding and split."""

from __future__ import annotations

import pytest

from conftest import assert_bounds
from rtsgeom.analysis.tolerance.config import MC_FIELDS, MonteCarlo

BOUNDS = [
    ("draws", [0, 10_000_000], [(-1, "MonteCarlo: draws = -1: must be in [0, 1e+07]"),
                                (10_000_001, "MonteCarlo: draws = 10000001: must be in [0, 1e+07]")]),
    ("seed", [None, 0, 2 ** 63 - 1],
     [(-1, "MonteCarlo: seed = -1: must be in [0, 9.22337e+18]"),
      (2 ** 63, "MonteCarlo: seed = 9223372036854775808: must be in [0, 9.22337e+18]")]),
    ("distribution", ["normal", "uniform"],
     [("gauss", "MonteCarlo: distribution = 'gauss': must be one of normal, uniform")]),
    ("chunk", [1, 1_000_000], [(0, "MonteCarlo: chunk = 0: must be in [1, 1e+06]"),
                               (1_000_001, "MonteCarlo: chunk = 1000001: must be in [1, 1e+06]")]),
]


@pytest.mark.parametrize("name, ok, bad", BOUNDS, ids=[b[0] for b in BOUNDS])
def test_monte_carlo_enforces_each_range_at_its_edges(name, ok, bad):
    assert_bounds(lambda v: MonteCarlo(**{name: v}), ok, bad)


def test_monte_carlo_repr_seeding_and_split():
    assert repr(MonteCarlo()) == "MonteCarlo(draws=10000, seed=scene's, normal)"
    assert repr(MonteCarlo(5, seed=2, distribution="uniform", subbin=False)) == (
        "MonteCarlo(draws=5, seed=2, uniform, bin centre)")
    mc = MonteCarlo(7)
    assert mc.seeded(11).seed == 11 and mc.seed is None
    fixed = MonteCarlo(7, seed=3)
    assert fixed.seeded(11) is fixed
    assert mc.evolve(draws=9) == MonteCarlo(9)
    with pytest.raises(Exception, match=r"^MonteCarlo: draws = -2: must be in \[0, 1e\+07\]$"):
        mc.evolve(draws=-2)
    assert MC_FIELDS == ("draws", "seed", "distribution", "chunk", "mapper", "progress",
                         "subbin")
    got, rest = MonteCarlo.split({"draws": 4, "seed": 1, "points": 9, "spec_deg": 0.1})
    assert got == MonteCarlo(4, seed=1) and rest == {"points": 9, "spec_deg": 0.1}
    d = MonteCarlo()
    assert (d.draws, d.seed, d.distribution, d.chunk, d.subbin) == (10_000, None, "normal",
                                                                    10_000, True)
