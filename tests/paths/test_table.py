"""Tests of ``rtsgeom.paths.table``: closed forms and invariants on grids of inputs."""

from __future__ import annotations

import numpy as np
import pytest

from rtsgeom.paths.table import Paths


@pytest.mark.parametrize("n", [1, 4, 9])
def test_a_selection_of_paths_keeps_every_column(n):
    """``Paths.select(mask)`` is every column indexed by the mask, what each bounce hit
    included (a sheet reflection's ``sheet`` must not turn into the default ``unknown``)."""
    rng = np.random.default_rng(n)
    bounces = rng.integers(0, 3, n)
    surfaces = np.array(["" if b == 0 else "+".join(["sheet"] * b) for b in bounces])
    p = Paths.build(np.arange(n) % 3, np.arange(n) % 2,
                    rng.integers(0, 3, n), rng.integers(0, 4, n), rng.uniform(1e-9, 2e-8, n),
                    rng.normal(size=n) + 1j * rng.normal(size=n), bounces,
                    interactions=np.where(bounces == 0, "los", "reflection"),
                    method="raytrace", surfaces=surfaces)
    for mask in (np.ones(n, bool), np.arange(n) % 2 == 0, rng.random(n) < 0.5):
        s = p.select(mask)
        for col in ("front_end", "direction", "rut_tx", "rut_rx", "delay_s", "gain",
                    "bounces", "interactions", "surfaces"):
            np.testing.assert_array_equal(getattr(s, col), getattr(p, col)[mask], err_msg=col)
        assert s.method == p.method
