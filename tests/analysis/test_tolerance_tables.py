"""Tests of ``rtsgeom.analysis.tolerance.tables``: each row of the response table is its
delay step's echoes alone."""

from __future__ import annotations

import dataclasses

import numpy as np
from conftest import small_quiet

from rtsgeom.analysis.tolerance.tables import response_table
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.scene import TargetConfig


def test_each_row_of_the_response_table_is_its_step_alone():
    """A table over several delay steps (one block), each step with several echoes (every
    path a second time, later and weaker: a bounce): each row equals the table of that step
    alone (each step's echoes summed into its own row, none into another's)."""
    setup = build_setup(small_quiet([]))
    los = exact_paths(setup)
    late = dataclasses.replace(los, delay_s=los.delay_s + 0.4e-9, gain=0.3j * los.gain,
                               bounces=los.bounces + 1)
    paths = dataclasses.replace(los, **{
        f.name: np.concatenate([getattr(los, f.name), getattr(late, f.name)])
        for f in dataclasses.fields(los) if f.name != "method"})
    target = TargetConfig(25.0)
    res = setup.scene.rts.delay_resolution_s
    steps = np.array([-7, 0, 3, 40])
    table = response_table(setup, paths, 1, target, res, steps, 1)
    assert table.shape == (4, 3, setup.rut.num_virtual)
    for k, s in enumerate(steps):
        alone = response_table(setup, paths, 1, target, res, [s], 1)
        np.testing.assert_allclose(table[k], alone[0], rtol=1e-12, atol=1e-15)
    assert not np.allclose(table[0], table[-1])
