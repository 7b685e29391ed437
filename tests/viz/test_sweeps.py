"""The calibration sweeps of many pairs in one figure (``rtsgeom.viz.sweeps``) and the report's
calibration images: a panel per pair on common axes holding every pair's data, x labels
under each column, the largest residuals in red; one pair keeps its own figure."""

from __future__ import annotations

import io
import types

import numpy as np
import pytest
from matplotlib.image import imread

from rtsgeom.pipeline import output as O
from rtsgeom.viz.sweeps import WORST_MARKED, _columns, calibration_sweeps_figure


def _record(i: int, rng, residual=True) -> dict:
    """A pair's calibration record as ``to_dict`` writes it (the fields the report reads)."""
    tau = np.linspace(-0.5e-9, 1.0e-9, 61) + rng.uniform(-0.3, 0.3) * 1e-9
    err = np.abs(np.sin(np.pi * (tau - tau[20]) / 1e-9)) * rng.uniform(0.5, 2)
    err[rng.integers(0, 61)] = np.nan  # a step whose probe was not detected
    ref = tau[20] + np.linspace(-20e-12, 20e-12, 9)
    return {"pair": [2 * i, 2 * i + 1], "delta_tau_s": float(tau[20]), "period_s": 1e-9,
            "residual_error_deg": float(rng.uniform(0, 0.01)) if residual else None,
            "sweep": [{"delta_tau_s": float(t), "angle_error_deg":
                       None if np.isnan(e) else float(e)} for t, e in zip(tau, err)],
            "refinement": [{"delta_tau_s": float(t), "angle_error_deg": 0.001} for t in ref]}


def _sweeps(n: int, seed: int = 0, unmeasured=()):
    rng = np.random.default_rng(seed)
    return [O._sweep_arrays(_record(i, rng, i not in unmeasured)) for i in range(n)]


@pytest.mark.parametrize("n", [2, 4, 5, 33])
def test_a_panel_per_pair_on_axes_holding_every_pair(n):
    sweeps = _sweeps(n, seed=n, unmeasured={1})
    fig = calibration_sweeps_figure(sweeps, title="arc: $x$ 50%")
    shown = [ax for ax in fig.axes if ax.get_visible()]
    assert len(shown) == n
    cols = _columns(n)
    assert len(fig.axes) == cols * -(-n // cols) and cols <= 6 and (n > 4 or cols == n)
    xlim, ylim = shown[0].get_xlim(), shown[0].get_ylim()
    for ax, s in zip(shown, sweeps):
        assert ax.get_xlim() == xlim and ax.get_ylim() == ylim  # comparable at a glance
        x = np.r_[s["delta_tau_s"], s["refine_delta_tau_s"], s["chosen_delta_tau_s"]] * 1e9
        y = np.r_[s["angle_error_deg"], s["refine_error_deg"]]
        y = y[np.isfinite(y)]
        assert xlim[0] < x.min() and x.max() < xlim[1]
        assert ylim[0] < min(y.min(), 0) and y.max() < ylim[1]
        assert ax.get_title().startswith(s["label"] + ": ")
    assert "residual not measured" in shown[1].get_title()
    # every column's lowest panel, and only it, carries the x tick labels and the x label
    for i, ax in enumerate(shown):
        lowest = i + cols >= n
        assert bool(ax.get_xlabel()) == lowest
        assert ax.xaxis.get_tick_params()["labelbottom"] == lowest
        assert bool(ax.get_ylabel()) == (i % cols == 0)
    assert fig._suptitle.get_text() == "arc: $x$ 50%"  # a scene name is plain text
    img = imread(io.BytesIO(O.figure_png(fig)))
    assert img.shape[0] > 300 and img.shape[1] > 600


@pytest.mark.parametrize("n", [3, 4, 9])
def test_the_largest_residuals_are_red(n):
    sweeps = _sweeps(n, seed=10 + n, unmeasured={0})
    fig = calibration_sweeps_figure(sweeps)
    red = [i for i, ax in enumerate(a for a in fig.axes if a.get_visible())
           if ax.title.get_color() == "C3"]
    resid = [np.nan if s["residual_error_deg"] is None else s["residual_error_deg"]
             for s in sweeps]
    expect = (sorted(np.argsort(-np.nan_to_num(resid, nan=-1.0))[:WORST_MARKED].tolist())
              if n > WORST_MARKED else [])
    assert red == expect
    notes = [t.get_text() for t in fig.texts if "largest residuals" in t.get_text()]
    assert len(notes) == (n > WORST_MARKED)


def test_the_report_draws_one_figure_of_all_pairs_and_one_pairs_own_figure():
    rng = np.random.default_rng(3)
    records = [_record(i, rng) for i in range(6)]

    def result(pairs):
        return types.SimpleNamespace(calibration={"pairs": pairs},
                                     scene=types.SimpleNamespace(name="bench"))
    one = O._calibration_figures(result(records[:1]))
    assert one == [O._calibration_png("bench", records[0])]  # the pair's own figure
    many = O._calibration_figures(result(records))
    assert len(many) == 1 and many[0] != one[0]
    assert imread(io.BytesIO(many[0])).shape[0] > imread(io.BytesIO(one[0])).shape[0]
    assert O._calibration_figures(result([])) == []


def test_no_pairs_is_an_error():
    with pytest.raises(ValueError, match="at least one pair"):
        calibration_sweeps_figure([])
