"""The calibration sweeps of many front-end pairs in one figure: small multiples on shared axes,
so a pair whose sweep or chosen offset stands out from the others is seen at a glance (one
figure per pair made a report of a 64-front-end arc 32 figures long, and cost 0.15 s each)."""

from __future__ import annotations

import math
import textwrap
from typing import Mapping, Sequence

import numpy as np
from matplotlib.lines import Line2D
from matplotlib.ticker import MaxNLocator

from .figures import _styled, _title, new_figure

__all__ = ["calibration_sweeps_figure", "WORST_MARKED"]

#: the pairs with the largest residuals whose panel titles are drawn in red
WORST_MARKED = 3


def _columns(n: int) -> int:
    """Panels per row: all of 1-4 pairs in one row, 4 up to 32 pairs, then 6."""
    return n if n <= 4 else (4 if n <= 32 else 6)


@_styled
def calibration_sweeps_figure(sweeps: Sequence[Mapping], title: str = "") -> object:
    """Angle error (deg) over the RTS delay offset (ns) of each pair, one small panel per
    pair on shared axes, in the given order.

    Parameters
    ----------
    sweeps : sequence of mapping
        One per pair: ``label`` (e.g. ``"0-1"``), ``delta_tau_s`` and ``angle_error_deg`` (the
        sweep, NaN where no probe was detected), ``chosen_delta_tau_s``,
        ``residual_error_deg`` (None: not measured), optionally ``refine_delta_tau_s`` and
        ``refine_error_deg`` (the refinement around the sweep's best grid point) and
        ``period_s`` (the phase period, eq. 27: the offsets whole periods from the chosen
        one, where the same minimum repeats, are dotted).
    title : str
        The figure's title (plain text).

    Returns
    -------
    matplotlib.figure.Figure
        Each panel titled with its pair, chosen offset and residual; the
        :data:`WORST_MARKED` largest residuals in red.
    """
    n = len(sweeps)
    if n == 0:
        raise ValueError("calibration_sweeps_figure needs at least one pair")
    cols = _columns(n)
    rows = math.ceil(n / cols)
    # fixed margins (inches) instead of the house style's constrained layout, and limits and
    # ticks computed once for all panels instead of shared axes: both cost O(panels^2) in
    # matplotlib (2.7 s for 32 panels, 0.6 s so)
    note = n > WORST_MARKED  # the red titles are explained below the panels
    bottom = 0.7 if note else 0.55
    width, height = 2.6 * cols + 0.6, 1.7 * rows + 0.85 + bottom
    fig, axes = new_figure(figsize=(width, height), nrows=rows, ncols=cols, layout=None,
                           gridspec_kw=dict(left=0.65 / width, right=1 - 0.15 / width,
                                            top=1 - 0.85 / height, bottom=bottom / height,
                                            wspace=0.12, hspace=0.4))
    axes = np.asarray(axes, object).reshape(rows, cols)
    xlim, ylim = _limits(sweeps)
    xticks, yticks = (MaxNLocator(nbins=5).tick_values(*lim) for lim in (xlim, ylim))
    xticks = xticks[(xticks >= xlim[0]) & (xticks <= xlim[1])]
    yticks = yticks[(yticks >= ylim[0]) & (yticks <= ylim[1])]
    resid = np.array([np.nan if s.get("residual_error_deg") is None
                      else abs(float(s["residual_error_deg"])) for s in sweeps])
    finite = np.flatnonzero(np.isfinite(resid))
    worst = set(finite[np.argsort(-resid[finite], kind="stable")[:WORST_MARKED]].tolist()
                if note else [])
    periods = False
    for i, ax in enumerate(axes.flat):
        if i >= n:
            ax.set_visible(False)
            continue
        periods |= _panel(ax, sweeps[i], i in worst)
        ax.set_xlim(xlim)
        ax.set_ylim(ylim)
        ax.set_xticks(xticks)
        ax.set_yticks(yticks)
        lowest = i + cols >= n  # the lowest panel of its column carries the x labels
        ax.tick_params(labelbottom=lowest, labelleft=i % cols == 0)
        if lowest:
            ax.set_xlabel("$\\Delta\\tau_{rts}$ (ns)")
        if i % cols == 0:
            ax.set_ylabel("angle error (deg)")
    handles = [Line2D([], [], marker=".", label="sweep: angle error"),
               Line2D([], [], marker="+", linestyle="none", color="C1", label="refinement"),
               Line2D([], [], marker="o", linestyle="--", color="C3",
                      label="chosen offset, its residual")]
    if periods:
        handles.append(Line2D([], [], linestyle=":", color="C2", label="chosen + k periods"))
    _header(fig, handles, title or "Phase coherency calibration of each pair", width, height)
    if worst:
        fig.text(0.5, 0.06 / height, f"red titles: the {len(worst)} largest residuals",
                 ha="center", va="bottom", fontsize=8, color="C3")
    return fig


def _limits(sweeps: Sequence[Mapping]) -> tuple[tuple[float, float], tuple[float, float]]:
    """Common x (ns) and y (deg) limits of every panel: all sweeps, refinements, chosen
    offsets and residuals, and the zero line, with 4 % margins."""
    xs, ys = [], [np.zeros(1)]
    for s in sweeps:
        xs += [_array(s, "delta_tau_s") * 1e9, _array(s, "refine_delta_tau_s") * 1e9,
               np.array([float(s["chosen_delta_tau_s"]) * 1e9])]
        ys += [_array(s, "angle_error_deg"), _array(s, "refine_error_deg"),
               np.array([np.nan if s.get("residual_error_deg") is None
                         else float(s["residual_error_deg"])])]
    out = []
    for v in (np.concatenate(xs), np.concatenate(ys)):
        v = v[np.isfinite(v)]
        lo, hi = (float(v.min()), float(v.max())) if v.size else (-1.0, 1.0)
        pad = 0.04 * (hi - lo) if hi > lo else 1.0
        out.append((lo - pad, hi + pad))
    return out[0], out[1]


def _array(s: Mapping, key: str) -> np.ndarray:
    """``s[key]`` as a float array (empty where absent or None)."""
    v = s.get(key)
    return np.asarray([] if v is None else v, float).ravel()


def _header(fig, handles, title: str, width: float, height: float) -> None:
    """The legend in one row at 7 pt (at 8 pt four entries ran off a two-panel figure) and
    the title wrapped to the figure's width (about 14 characters an inch), two lines at most."""
    fig.legend(handles=handles, loc="upper center", ncols=len(handles),
               frameon=False, bbox_to_anchor=(0.5, 1 - 0.32 / height), fontsize=7)
    fig.suptitle("\n".join(textwrap.wrap(title, max(30, int(14 * width)), max_lines=2,
                                          placeholder=" ...")),
                 fontsize=10, y=1 - 0.02 / height, va="top").set_parse_math(False)


def _panel(ax, s: Mapping, worst: bool) -> bool:
    """One pair's sweep (as ``calibration_sweep_figure`` draws it, without its legend);
    whether it dotted offsets whole periods from the chosen one."""
    tau = _array(s, "delta_tau_s") * 1e9
    err = _array(s, "angle_error_deg")
    order = np.argsort(tau)
    ax.plot(tau[order], err[order], marker=".", markersize=2.5, linewidth=1.0)
    ax.axhline(0.0, color="0.4", linewidth=0.6)
    rt = _array(s, "refine_delta_tau_s") * 1e9
    if rt.size:
        ax.plot(rt, _array(s, "refine_error_deg"), marker="+", markersize=3,
                linestyle="none", color="C1")
    chosen = float(s["chosen_delta_tau_s"]) * 1e9
    period = s.get("period_s")
    if period is not None and period > 0 and tau.size:
        p = float(period) * 1e9
        k = np.arange(np.ceil((tau.min() - chosen) / p), np.floor((tau.max() - chosen) / p) + 1)
        k = k[k != 0]
        for x in chosen + p * k:
            ax.axvline(x, color="C2", linestyle=":", linewidth=0.9)
    else:
        k = ()
    ax.axvline(chosen, color="C3", linestyle="--", linewidth=1.0)
    y = s.get("residual_error_deg")
    if y is not None and np.isfinite(y):
        ax.plot([chosen], [float(y)], marker="o", markersize=4, color="C3", linestyle="none")
        text = f"{s['label']}: {round(chosen * 1e3, 1) + 0.0:.1f} ps, {float(y):.4f} deg"
    else:
        text = f"{s['label']}: {round(chosen * 1e3, 1) + 0.0:.1f} ps, residual not measured"
    _title(ax, text)
    ax.title.set_fontsize(8)
    if worst:
        ax.title.set_color("C3")
    return len(k) > 0
