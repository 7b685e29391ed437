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
