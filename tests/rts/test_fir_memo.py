"""The fractional-delay FIR's memo of taps and phase rows gives the rows it is asked for, also
when it is full and starts afresh (a long drive meets thousands of distinct delay settings)."""

from __future__ import annotations

import numpy as np

from rtsgeom.rts import fir


def test_a_full_memo_starts_afresh_with_every_setting_asked_for(monkeypatch):
    monkeypatch.setattr(fir, "_FIR_ROWS", {})
    monkeypatch.setattr(fir, "_FIR_ROWS_MAX", 8)
    grid = np.linspace(0.0, 1e8, 16)
    first = np.linspace(0.01, 0.5, 6)
    fir._fir_rows(first, 9, 4e9, grid)  # 6 settings in the memo
    # 3 of them again and 4 new ones: 10 > 8, the memo is refilled
    ask = np.unique(np.concatenate([first[:3], np.linspace(0.6, 0.9, 4)]))
    h, phase, _ = fir._fir_rows(ask, 9, 4e9, grid)
    np.testing.assert_array_equal(h, fir.fractional_delay_fir(ask, 9))
    np.testing.assert_allclose(phase, np.exp(1j * np.outer(ask, 2 * np.pi * grid / 4e9)),
                               rtol=0, atol=1e-15)


def test_more_settings_than_the_memo_holds_are_computed_and_not_kept(monkeypatch):
    """Asked for more distinct settings than the memo holds, the rows are computed (the same
    taps and phase rows as through the memo) and the memo keeps what it held."""
    monkeypatch.setattr(fir, "_FIR_ROWS", {})
    monkeypatch.setattr(fir, "_FIR_ROWS_MAX", 8)
    for f_s, taps, n in [(4e9, 9, 12), (2.5e9, 8, 9), (1e9, 33, 40)]:
        grid = np.linspace(-2e8, 1e8, 16)
        held = np.linspace(-0.4, -0.1, 3)
        fir._fir_rows(held, taps, f_s, grid)
        ask = np.linspace(-0.49, 0.49, n)  # n > 8
        h, phase, kern = fir._fir_rows(ask, taps, f_s, grid)
        w = 2 * np.pi * grid / f_s
        np.testing.assert_array_equal(h, fir.fractional_delay_fir(ask, taps))
        np.testing.assert_allclose(phase, np.exp(1j * np.outer(ask, w)), rtol=0, atol=1e-15)
        k = np.arange(taps) - (taps - 1) / 2
        np.testing.assert_allclose(kern, np.exp(-1j * np.outer(k, w)), rtol=0, atol=1e-15)
        entry = fir._FIR_ROWS[(taps, f_s, grid.tobytes())]
        np.testing.assert_array_equal(entry["mus"], held)  # not kept
        h2, phase2, _ = fir._fir_rows(held, taps, f_s, grid)
        np.testing.assert_array_equal(h2, fir.fractional_delay_fir(held, taps))


def test_more_frequency_grids_than_the_memo_keeps_start_it_afresh(monkeypatch):
    """A third frequency grid (or tap count, or sample rate) with two kept: the memo is
    emptied and keeps the new one alone; every call's rows are the closed forms."""
    monkeypatch.setattr(fir, "_FIR_ROWS", {})
    assert fir._FIR_KEYS_MAX == 2
    mu = np.linspace(-0.45, 0.45, 5)
    keys = [(9, 4e9, np.linspace(0.0, 1e8, 8)), (9, 4e9, np.linspace(0.0, 2e8, 8)),
            (8, 4e9, np.linspace(0.0, 1e8, 8)), (9, 2e9, np.linspace(0.0, 1e8, 8))]
    sizes = []
    for taps, f_s, grid in keys:
        h, phase, _ = fir._fir_rows(mu, taps, f_s, grid)
        np.testing.assert_array_equal(h, fir.fractional_delay_fir(mu, taps))
        np.testing.assert_allclose(phase, np.exp(1j * np.outer(mu, 2 * np.pi * grid / f_s)),
                                   rtol=0, atol=1e-15)
        sizes.append(len(fir._FIR_ROWS))
        assert (taps, f_s, grid.tobytes()) in fir._FIR_ROWS
    assert sizes == [1, 2, 1, 2]


def test_rows_of_shifted_grids_are_the_grid_with_a_shift_and_other_rows_are_refused():
    """``fir_error_response`` with (M, N) frequency rows: rows that are the grid shifted give
    the response at the grid with those shifts; rows of another spacing are refused whole;
    each value is the direct sum ``sum_k h_k exp(-j w (k - D))``."""
    import pytest
    taps, f_s = 9, 4e9
    grid = np.linspace(1e7, 1e8, 12)
    mu = np.array([0.1, 0.45, 0.1])
    shift = np.array([0.0, 3e6, -2e6])
    rows = grid[None, :] + shift[:, None]
    got = fir.fir_error_response(mu, taps, f_s, rows)
    np.testing.assert_allclose(got, fir.fir_error_response(mu, taps, f_s, grid, shift),
                               rtol=0, atol=1e-13)
    h = fir.fractional_delay_fir(mu, taps)
    k = np.arange(taps)
    d = (taps - 1) / 2 + mu
    w = 2 * np.pi * rows / f_s
    direct = np.einsum("mk,mkn->mn", h,
                       np.exp(-1j * w[:, None, :] * (k[None, :, None] - d[:, None, None])))
    np.testing.assert_allclose(got, direct, rtol=0, atol=1e-12)
    bad = rows.copy()
    bad[1] *= 1.01
    with pytest.raises(ValueError) as exc:
        fir.fir_error_response(mu, taps, f_s, bad)
    assert str(exc.value) == "f_hz: each row must be the same frequency grid, shifted"
