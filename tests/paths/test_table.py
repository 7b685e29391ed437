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


def _table():
    """Three rows, one per direction: RuT Tx 1 -> front end 0 (line of sight), front end 2 ->
    RuT Rx 3 (a sheet bounce), RuT Tx 0 -> RuT Rx 2 (two bounces, surfaces not said)."""
    return Paths.build([0, 2, -1], [0, 1, 2], [1, -1, 0], [-1, 3, 2],
                       [1e-9, 2.5e-9, 4e-9], [0.5, 1e-3j, -0.01], [0, 1, 2],
                       interactions=["los", "specular", "specular+specular"],
                       surfaces=["", "sheet", "sheet+structure[0]"])


def test_build_defaults_say_line_of_sight_or_an_unknown_reflection():
    p = Paths.build([0, 1, 2], [0, 0, 1], [0, 1, 2], [-1, -1, 0], [1e-9, 2e-9, 3e-9],
                    [1.0, 1.0, 1.0], [0, 1, 2])
    assert list(p.interactions) == ["los", "reflection", "reflection"]
    assert list(p.surfaces) == ["", "unknown", "unknown"]
    assert p.method == "exact"
    q = Paths.build([[0, 1]], [[0, 0]], [[0, 1]], [[-1, -1]], [[1e-9, 2e-9]], [[1.0, 2.0]])
    assert list(q.bounces) == [0, 0] and list(q.interactions) == ["los", "los"]
    assert q.front_end.shape == (2,) and q.gain.dtype == complex and q.direction.dtype == np.int8
    assert not q.delay_s.flags.writeable  # frozen columns


@pytest.mark.parametrize("name", ["front_end", "direction", "rut_tx", "rut_rx", "gain",
                                  "bounces", "interactions", "surfaces"])
def test_every_column_has_the_tables_length(name):
    import dataclasses
    p = _table()
    with pytest.raises(ValueError) as exc:
        dataclasses.replace(p, **{name: getattr(p, name)[:2]})
    assert str(exc.value) == f"Paths.{name} must have shape (3,)"


def test_concat_lengths_and_legs():
    from scipy.constants import c
    p = _table()
    both = Paths.concat([p, _with_method(p, "raytrace")])
    assert len(both) == 6 and both.method == "exact+raytrace"
    assert list(both.surfaces) == list(p.surfaces) * 2
    assert list(both.interactions) == list(p.interactions) * 2
    assert np.array_equal(p.length_m, p.delay_s * c)
    leg = both.leg(2, 1, 3)
    assert len(leg) == 2 and set(leg.delay_s) == {2.5e-9}
    assert len(both.leg(0, 0, 1)) == 2 and len(both.leg(0, 0, 0)) == 0
    assert len(both.leg(2, 1, 2)) == 0  # the Rx element decides a front end -> RuT leg


def _with_method(p, method):
    import dataclasses
    return dataclasses.replace(p, method=method)


def test_the_csv_rows_say_each_column_in_its_unit():
    from scipy.constants import c
    rows = _table().to_csv().splitlines()
    assert rows[0] == ("front_end,direction,rut_element,length_m,delay_s,gain_db,"
                       "gain_phase_deg,bounces,interactions,surfaces")
    assert rows[1] == (f"0,tx_to_fe,tx1,{1e-9 * c:.12f},1.000000000000000e-09,-6.0206,0.0000,0,"
                       "los,")
    assert rows[2] == (f"2,fe_to_rx,rx3,{2.5e-9 * c:.12f},2.500000000000000e-09,-60.0000,"
                       "90.0000,1,specular,sheet")
    assert rows[3] == (f"-1,rut_to_rut,tx0-rx2,{4e-9 * c:.12f},4.000000000000000e-09,-40.0000,"
                       "180.0000,2,specular+specular,sheet+structure[0]")
    assert len(rows) == 4
    zero = Paths.build([0], [0], [0], [-1], [1e-9], [0.0]).to_csv().splitlines()[1]
    assert zero.split(",")[5] == "-6000.0000"  # |g| floored at 1e-300


def test_build_gives_each_column_its_type_whatever_it_was_given():
    """Delays as float64 even from integers, indices as int, the direction int8, gains complex,
    bounces int, interactions and surfaces text."""
    p = Paths.build([0.0, 1.0], [0.0, 1.0], [1.0, -1.0], [-1.0, 2.0], [1, 2], [1, 2],
                    [0.0, 1.0], interactions=[1, 2], surfaces=[3, 4])
    assert p.delay_s.dtype == np.float64 and p.gain.dtype == np.complex128
    assert p.front_end.dtype.kind == p.rut_tx.dtype.kind == p.rut_rx.dtype.kind == "i"
    assert p.direction.dtype == np.int8 and p.bounces.dtype.kind == "i"
    assert p.interactions.dtype.kind == p.surfaces.dtype.kind == "U"
    assert list(p.interactions) == ["1", "2"] and list(p.surfaces) == ["3", "4"]
    assert p.delay_s.tolist() == [1.0, 2.0] and p.rut_rx.tolist() == [-1, 2]
    assert p.length_m.dtype == np.float64
