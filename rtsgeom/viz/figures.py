"""Result figures with matplotlib: one function per figure, plain numpy arrays in, a Figure out.

No pyplot: every figure is a :class:`matplotlib.figure.Figure` rendered by the Agg backend, so
nothing leaks into pyplot's global figure list and no display is needed. All figures share one
style (:data:`STYLE`, applied while the figure is built and while it is saved). Axes are labelled
with units; angles are in degrees, delays in nanoseconds (converted here from SI inputs).

Figures follow the paper: the range-Doppler map, the phase-coherency calibration sweep and the
"amplitude attenuation and angle linearity and error" plot.
"""

from __future__ import annotations

import functools
import textwrap
from pathlib import Path
from typing import Mapping

import matplotlib as mpl
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle

from .._lib.io import atomic_path

__all__ = ["STYLE", "new_figure", "print_png", "save_figure", "range_doppler_figure",
           "range_angle_figure", "calibration_sweep_figure", "linearity_figure",
           "tolerance_cdf_figure", "tolerance_histogram_figure", "design_heatmap_figure",
           "design_lines_figure"]

STYLE = {
    "font.size": 9,
    "axes.titlesize": 10,
    "axes.labelsize": 9,
    "legend.fontsize": 8,
    "xtick.labelsize": 8,
    "ytick.labelsize": 8,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "grid.linewidth": 0.6,
    "lines.linewidth": 1.4,
    "lines.markersize": 4,
    "image.cmap": "viridis",
    "axes.prop_cycle": mpl.cycler(color=mpl.colormaps["tab10"].colors),
    "figure.facecolor": "white",
    "savefig.facecolor": "white",
}
DPI = 120
DYNAMIC_RANGE_DB = 60.0  # colour scale of power maps: this far below the maximum
_DETECTION = dict(marker="o", s=70, facecolors="none", edgecolors="red", linewidths=1.3)
_SET_POINT = dict(marker="x", s=50, color="white", linewidths=1.5)
# the power maps' fixed margins (fractions of the figure) instead of the constrained layout,
# whose text measuring was a third of the main job's two maps (0.5 -> 0.4 s of CPU)
_MAP_MARGINS = dict(left=0.1, right=0.97, bottom=0.11, top=0.93)


def _styled(func):
    """Build the figure under :data:`STYLE` (rc parameters are read when artists are made)."""
    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        with mpl.rc_context(STYLE):
            return func(*args, **kwargs)
    return wrapper


def new_figure(figsize=(6.4, 4.4), nrows=1, ncols=1, layout="constrained",
               **subplot_kw) -> tuple[Figure, object]:
    """A figure of the house style (``DPI``, constrained layout unless ``layout`` says
    otherwise) on the Agg canvas, without pyplot's global state, and its axes (``nrows`` x
    ``ncols``, squeezed; ``subplot_kw`` to ``Figure.subplots``, e.g. ``gridspec_kw``)."""
    fig = Figure(figsize=figsize, dpi=DPI, layout=layout)
    FigureCanvasAgg(fig)
    axes = fig.subplots(nrows, ncols, squeeze=True, **subplot_kw)
    return fig, axes


def _plain_text_if_not_math(fig: Figure) -> None:
    """Show every text that mathtext cannot parse literally instead of failing the whole
    figure: a title made elsewhere from a user's string (a scene name with ``$\\x$`` in it)
    must never crash a figure."""
    from matplotlib.cbook import is_math_text
    from matplotlib.mathtext import MathTextParser
    from matplotlib.text import Text
    parser = MathTextParser("path")
    for t in fig.findobj(Text):
        s = t.get_text()
        if not (t.get_parse_math() and is_math_text(s)):
            continue
        try:
            parser.parse(s, 72, t.get_fontproperties())
        except ValueError:
            t.set_parse_math(False)


def _title(ax, text: str) -> None:
    """A title that may carry a user's string (a scene name): plain text, never mathtext."""
    ax.set_title(text, parse_math=False)


def print_png(fig: Figure, target) -> None:
    """``fig`` as PNG (dpi 120, :data:`STYLE`) into ``target``, a path or a binary file: the
    Agg canvas drawn once. ``Figure.savefig`` draws a figure with a layout engine twice, the
    first time only to lay it out (35-75 ms more for a figure of 0.15-0.2 s); the bytes are
    the same (``tests/viz/test_viz.py``)."""
    with mpl.rc_context(STYLE):
        if fig.dpi == DPI and isinstance(fig.canvas, FigureCanvasAgg):
            fig.canvas.print_png(target)
        else:  # a figure made elsewhere: savefig sets the resolution
            fig.savefig(target, format="png", dpi=DPI)


def save_figure(fig: Figure, path: str | Path) -> Path:
    """Write ``fig`` as PNG (dpi 120) atomically; return the path."""
    path = Path(path)
    _plain_text_if_not_math(fig)
    with atomic_path(path) as tmp:
        print_png(fig, tmp)
    return path


def _vector(name: str, values) -> np.ndarray:
    a = np.asarray(values, dtype=float)
    if a.ndim != 1 or a.size == 0:
        raise ValueError(f"{name} must be a non-empty 1-D array, got shape {a.shape}")
    return a


def _grid(name: str, values, shape: tuple[int, int], axes_names: str) -> np.ndarray:
    a = np.asarray(values, dtype=float)
    if a.shape != shape:
        raise ValueError(f"{name} must have shape {shape} ({axes_names}), got {a.shape}")
    return a


def _points(name: str, values) -> np.ndarray | None:
    """Optional (N, 2) marker coordinates; None or empty -> None."""
    if values is None:
        return None
    a = np.asarray(values, dtype=float)
    if a.size == 0:
        return None
    a = np.atleast_2d(a)
    if a.ndim != 2 or a.shape[1] != 2:
        raise ValueError(f"{name} must have shape (N, 2), got {a.shape}")
    return a


def _power_map(ax, fig, x, y, power_db, xlabel: str, ylabel: str, title: str) -> None:
    """Colour map of power in dB over ``DYNAMIC_RANGE_DB`` below its maximum; a long title
    (a lab's scene name, a clipping note) wrapped, the top margin lowered for each extra line
    (the margins are fixed: nothing else makes room for it; four lines at most, so the axes
    keep their height)."""
    lines = textwrap.wrap(title, 60, max_lines=4, placeholder=" ...") if title else []
    fig.subplots_adjust(**{**_MAP_MARGINS,
                           "top": _MAP_MARGINS["top"] - 0.04 * max(len(lines) - 1, 0)})
    finite = power_db[np.isfinite(power_db)]
    vmax = float(finite.max()) if finite.size else 0.0
    mesh = ax.pcolormesh(x, y, power_db, shading="nearest", vmin=vmax - DYNAMIC_RANGE_DB,
                         vmax=vmax, rasterized=True)
    fig.colorbar(mesh, ax=ax, label="power (dB)")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(False)
    if title:
        _title(ax, "\n".join(lines))


@_styled
def range_doppler_figure(power_db, range_m, velocity_mps, detections=None,
                         title: str = "") -> Figure:
    """Range-Doppler map: x velocity (m/s), y range (m), colour power (dB, 60 dB below the
    maximum); ``detections`` (N, 2) of [range_m, velocity_mps] circled."""
    r = _vector("range_m", range_m)
    v = _vector("velocity_mps", velocity_mps)
    p = _grid("power_db", power_db, (r.size, v.size), "n_range, n_doppler")
    det = _points("detections", detections)
    fig, ax = new_figure(layout=None)
    _power_map(ax, fig, v, r, p, "radial velocity (m/s)", "range (m)", title or "Range-Doppler map")
    if det is not None:
        ax.scatter(det[:, 1], det[:, 0], label=f"detections ({len(det)})", **_DETECTION)
        ax.legend(loc="upper right")
    return fig


@_styled
def range_angle_figure(power_db, range_m, angle_deg, detections=None, set_points=None,
                       title: str = "") -> Figure:
    """Range-angle map: x azimuth (deg), y range (m), colour power (dB); ``detections`` circled
    and ``set_points`` (the targets' set range and angle) crossed, both (N, 2) [range_m, deg]."""
    r = _vector("range_m", range_m)
    a = _vector("angle_deg", angle_deg)
    p = _grid("power_db", power_db, (r.size, a.size), "n_range, n_angle")
    det = _points("detections", detections)
    sp = _points("set_points", set_points)
    fig, ax = new_figure(layout=None)
    _power_map(ax, fig, a, r, p, "azimuth (deg)", "range (m)", title or "Range-angle map")
    if sp is not None:
        ax.scatter(sp[:, 1], sp[:, 0], label="set points", **_SET_POINT)
    if det is not None:
        ax.scatter(det[:, 1], det[:, 0], label=f"detections ({len(det)})", **_DETECTION)
    if sp is not None or det is not None:
        ax.legend(loc="upper right")
    return fig


@_styled
def calibration_sweep_figure(delta_tau_s, angle_error_deg, chosen_delta_tau_s: float,
                             period_s: float | None = None, title: str = "", *,
                             residual_error_deg: float | None,
                             refine_delta_tau_s=None, refine_error_deg=None) -> Figure:
    """Phase-coherency calibration: angle error (deg) over the swept RTS delay offset (ns).

    The chosen offset is marked at ``residual_error_deg``, the calibration's one residual (as
    in its JSON and on stdout; it comes from the refinement around the sweep's best grid
    point, drawn when ``refine_delta_tau_s`` and ``refine_error_deg`` are given); None (the
    chain detected no probe there) draws the chosen offset's line without a value. With
    ``period_s`` (the phase period
    1/(f_rts + B/2), eq. 27) the offsets whole periods away, where the same minimum repeats,
    are marked where they fall inside the sweep.
    """
    tau = _vector("delta_tau_s", delta_tau_s)
    err = _vector("angle_error_deg", angle_error_deg)
    if err.size != tau.size:
        raise ValueError(f"angle_error_deg has {err.size} values, delta_tau_s {tau.size}")
    order = np.argsort(tau)
    t_ns, err = tau[order] * 1e9, err[order]
    chosen_ns = float(chosen_delta_tau_s) * 1e9
    fig, ax = new_figure(figsize=(6.4, 3.8))
    ax.plot(t_ns, err, marker=".", label="sweep: angle error")
    ax.axhline(0.0, color="0.4", linewidth=0.8)
    if refine_delta_tau_s is not None and refine_error_deg is not None:
        rt = np.asarray(refine_delta_tau_s, float).ravel()
        re = np.asarray(refine_error_deg, float).ravel()
        if rt.size != re.size:
            raise ValueError(f"refine_error_deg has {re.size} values, refine_delta_tau_s "
                             f"{rt.size}")
        if rt.size:
            ax.plot(rt * 1e9, re, marker="+", linestyle="none", color="C1",
                    label="refinement")
    if period_s is not None and period_s > 0:
        p_ns = float(period_s) * 1e9
        k = np.arange(np.ceil((t_ns[0] - chosen_ns) / p_ns),
                      np.floor((t_ns[-1] - chosen_ns) / p_ns) + 1)
        k = k[k != 0]
        for n, x in enumerate(chosen_ns + p_ns * k):  # the legend entry only with a line
            ax.axvline(x, color="C2", linestyle=":", linewidth=1.2,
                       label=f"chosen + k periods ({p_ns:.4f} ns)" if n == 0 else None)
    if residual_error_deg is not None and np.isfinite(residual_error_deg):
        y = float(residual_error_deg)
        ax.axvline(chosen_ns, color="C3", linestyle="--", linewidth=1.2)
        ax.plot([chosen_ns], [y], marker="o", markersize=7, color="C3", linestyle="none",
                label=f"chosen: {chosen_ns * 1e3:.1f} ps (residual {y:.4f} deg)")
    else:
        ax.axvline(chosen_ns, color="C3", linestyle="--", linewidth=1.2,
                   label=f"chosen: {chosen_ns * 1e3:.1f} ps (residual not measured)")
    ax.set_xlabel("RTS delay offset $\\Delta\\tau_{rts}$ (ns)")
    ax.set_ylabel("angle error (deg)")
    _title(ax, title or "Phase coherency calibration")
    ax.legend(loc="best")
    return fig


def _cell_edges(centres: np.ndarray) -> np.ndarray:
    """Edges of cells centred on ``centres`` (as ``shading="nearest"`` draws them)."""
    if centres.size == 1:
        return centres[0] + np.array([-0.5, 0.5])
    mid = 0.5 * (centres[1:] + centres[:-1])
    return np.r_[2 * centres[0] - mid[0], mid, 2 * centres[-1] - mid[-1]]


def _mode_arrays(name: str, by_mode: Mapping[str, object], n: int, rows: int | None = None
                 ) -> dict[str, np.ndarray]:
    out = {}
    for mode, values in by_mode.items():
        a = np.asarray(values, dtype=float)
        want = (n,) if rows is None else (rows, n)
        if a.shape != want:
            raise ValueError(f"{name}[{mode!r}] must have shape {want}, got {a.shape}")
        out[str(mode)] = a
    return out


@_styled
def linearity_figure(set_deg, detected_deg_by_mode: Mapping[str, object],
                     amplitude_db_by_mode: Mapping[str, object] | None = None,
                     title: str = "", pair: tuple[int, int] | None = None) -> Figure:
    """Amplitude attenuation and angle linearity and error (paper figure), stacked over the set
    angle: the two channels' attenuation in dB (only with ``amplitude_db_by_mode``, each (2, n)),
    the detected angle against the ideal line, and the error detected - set. One colour per
    synthesis mode; NaN marks a set angle without a detection. The channels are named by their
    front-end indices ``pair`` (0-based, as the CLI's ``--pair``), else "channel I" and "J"."""
    s = _vector("set_deg", set_deg)
    det = _mode_arrays("detected_deg_by_mode", detected_deg_by_mode, s.size)
    amp = (None if amplitude_db_by_mode is None
           else _mode_arrays("amplitude_db_by_mode", amplitude_db_by_mode, s.size, rows=2))
    n_panels = 2 if amp is None else 3
    fig, axes = new_figure(figsize=(6.4, 2.4 * n_panels + 0.4), nrows=n_panels, sharex=True)
    ax_amp, ax_lin, ax_err = (None, *axes) if amp is None else axes
    colour = {m: f"C{i % 10}" for i, m in enumerate(dict.fromkeys([*det, *(amp or {})]))}
    names = (("channel I", "channel J") if pair is None
             else tuple(f"front end {int(q)}" for q in pair))
    if ax_amp is not None:
        for mode, a in amp.items():
            ax_amp.plot(s, a[0], color=colour[mode], label=f"{mode}: {names[0]}")
            ax_amp.plot(s, a[1], color=colour[mode], linestyle="--", label=f"{mode}: {names[1]}")
        ax_amp.set_ylabel("attenuation (dB)")
        ax_amp.legend(loc="best", ncols=2 if len(amp) > 1 else 1)
        _title(ax_amp, title or "Amplitude attenuation and angle linearity and error")
    else:
        _title(ax_lin, title or "Angle linearity and error")
    ax_lin.plot(s, s, color="0.5", linestyle=":", label="ideal")
    for mode, d in det.items():
        ax_lin.plot(s, d, color=colour[mode], marker=".", label=mode)
        ax_err.plot(s, d - s, color=colour[mode], marker=".", label=mode)
    ax_lin.set_ylabel("detected angle (deg)")
    ax_lin.legend(loc="best")
    ax_err.axhline(0.0, color="0.4", linewidth=0.8)
    ax_err.set_ylabel("error (deg)")
    ax_err.set_xlabel("set angle (deg)")
    return fig


@_styled
def tolerance_cdf_figure(errors_deg_by_case: Mapping[str, object],
                         spec_deg: float | None = None, title: str = "") -> Figure:
    """Empirical CDFs of the absolute angle error (deg) per case (e.g. the worst error per drawn setup of
    the mounting-tolerance Monte Carlo) on a log axis, so that cases whose errors differ by
    orders of magnitude (uncalibrated: degrees; calibrated: thousandths) are both resolved (a
    histogram on common bins put the calibrated case into one bin). The legend gives each
    case's count, 95th percentile and the fraction within ``spec_deg`` (the vertical line)."""
    cases = {}
    for name, values in errors_deg_by_case.items():
        a = np.abs(np.asarray(values, dtype=float).ravel())
        cases[str(name)] = np.sort(a[np.isfinite(a)])
    if not cases:
        raise ValueError("errors_deg_by_case is empty")
    every = np.concatenate(list(cases.values()))
    positive = every[every > 0]
    floor = float(positive.min()) if positive.size else 1e-6
    if spec_deg is not None:
        floor = min(floor, abs(spec_deg))
    fig, ax = new_figure(figsize=(6.4, 4.8))
    for name, a in cases.items():
        if not a.size:
            continue
        p95 = float(np.percentile(a, 95))
        label = f"{name} (n={a.size}, 95 %: {p95:.3g} deg"
        if spec_deg is not None:
            label += f", {100 * np.mean(a <= abs(spec_deg)):.1f} % within spec"
        # the ECDF as a step function; zeros are drawn at the axis' left end
        x = np.maximum(a, 0.5 * floor)
        ax.step(np.r_[x[0], x], np.r_[0.0, np.arange(1, a.size + 1) / a.size], where="post",
                linewidth=1.5, label=label + ")")
    if spec_deg is not None:
        ax.axvline(abs(spec_deg), color="red", linestyle="--", linewidth=1.2,
                   label=f"spec {abs(spec_deg):g} deg")
    ax.set_xscale("log")
    ax.set_ylim(0, 1.02)
    ax.set_xlabel("|angle error| (deg)")
    ax.set_ylabel("fraction of setups")
    _title(ax, title or "Angle error distribution (empirical CDF)")
    # below the axes: on them it covered a curve (every corner holds one of the CDFs)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncols=1, frameon=False)
    return fig


def tolerance_histogram_figure(errors_deg_by_case: Mapping[str, object],
                               spec_deg: float | None = None, title: str = "") -> Figure:
    """Kept for earlier callers: the empirical CDFs of :func:`tolerance_cdf_figure`."""
    return tolerance_cdf_figure(errors_deg_by_case, spec_deg, title)


def _design_arrays(x, y, z, mask):
    """The checked inputs of the design figures: x, y vectors, z (len(y), len(x)) and the
    exclusion mask of the same shape (all False when None)."""
    xv = _vector("x", x)
    yv = _vector("y", y)
    zv = _grid("z", z, (yv.size, xv.size), "len(y), len(x)")
    m = np.zeros(zv.shape, bool) if mask is None else np.asarray(mask, bool)
    if m.shape != zv.shape:
        raise ValueError(f"mask must have shape {zv.shape}, got {m.shape}")
    return xv, yv, zv, m


ANNOTATE_CELLS = 150  # a heat map of at most this many cells writes each value in its cell


@_styled
def design_heatmap_figure(x, y, z, xlabel: str, ylabel: str, zlabel: str, title: str, *,
                          mask=None, contour_floor: float | None = None,
                          integer_y: bool = False, integer_z: bool = False) -> Figure:
    """Heat map of a figure of merit ``z`` (shape (len(y), len(x))) over two design parameters,
    e.g. arc radius vs front-end spacing with colour = worst angle error. ``mask`` (same shape,
    True = excluded, e.g. infeasible) greys out and hatches cells (and the legend says so only
    where a cell is hatched). Labels should carry units.

    Contour lines only at levels >= ``contour_floor`` (a level below it, e.g. 1e-5 deg of a
    0.1 deg spec, is the noise of the evaluation, not a design contour; None: any level) and
    none when fewer than two such levels exist. A small map (<= :data:`ANNOTATE_CELLS` cells)
    writes each value in its cell. A map whose every |value| is below ``contour_floor`` is
    coloured over [0, floor] (its differences are noise). ``integer_y``/``integer_z``:
    whole-number ticks on the y axis / colour bar (a count)."""
    from matplotlib.ticker import MaxNLocator
    xv, yv, zv, m = _design_arrays(x, y, z, mask)
    shown = np.ma.masked_array(zv, mask=m | ~np.isfinite(zv))
    fig, ax = new_figure()
    ax.set_facecolor("0.85")
    kw = {}
    if contour_floor is not None and shown.count() and float(np.abs(shown).max()) < contour_floor:
        # every value below the meaningful level: colours over [0, floor], not over the noise
        kw = dict(vmin=0.0, vmax=float(contour_floor))
    if integer_z and shown.count():
        lo, hi = float(shown.min()), float(shown.max())
        kw = dict(vmin=lo - 0.5, vmax=max(hi, lo + 1) + 0.5)
    mesh = ax.pcolormesh(xv, yv, shown, shading="nearest", rasterized=True, **kw)
    bar = fig.colorbar(mesh, ax=ax, label=zlabel)
    if integer_z:
        bar.locator = MaxNLocator(integer=True)
        bar.update_ticks()
    if m.any():
        xe, ye = _cell_edges(xv), _cell_edges(yv)
        for j, i in zip(*np.nonzero(m)):
            ax.add_patch(Rectangle((xe[i], ye[j]), xe[i + 1] - xe[i], ye[j + 1] - ye[j],
                                   fill=False, hatch="//", edgecolor="0.55", linewidth=0.0))
        ax.add_patch(Rectangle((0, 0), 0, 0, facecolor="0.85", hatch="//", edgecolor="0.55",
                               label="excluded", visible=True))
        ax.legend(loc="upper right")
    if zv.size <= ANNOTATE_CELLS:
        norm = mesh.norm
        for j, i in zip(*np.nonzero(~np.ma.getmaskarray(shown))):
            v = float(zv[j, i])
            dark = norm(v) < 0.55 if np.isfinite(norm(v)) else True
            ax.text(xv[i], yv[j], f"{v:.0f}" if integer_z else f"{v:.3g}", ha="center",
                    va="center", fontsize=7, color="white" if dark else "black")
    elif min(xv.size, yv.size) >= 3 and shown.count() >= 4:
        _contours(ax, xv, yv, shown, contour_floor)
    if integer_y:
        ax.set_yticks(yv)
        ax.set_yticklabels([f"{v:.0f}" for v in yv])
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    _title(ax, title)
    ax.grid(False)
    return fig


def _contours(ax, xv, yv, shown, floor: float | None) -> None:
    """White contour lines at 'nice' levels within the data, those below ``floor`` left out."""
    from matplotlib.ticker import MaxNLocator
    lo, hi = float(shown.min()), float(shown.max())
    if floor is not None:
        lo = max(lo, float(floor))
    if not hi > lo:
        return
    levels = [v for v in MaxNLocator(6).tick_values(lo, hi) if lo <= v <= hi]
    if len(levels) < 2:
        return
    cs = ax.contour(xv, yv, shown, levels=levels, colors="white", linewidths=0.7)
    ax.clabel(cs, fontsize=7, fmt="%.3g")


@_styled
def design_lines_figure(x, y, z, xlabel: str, ylabel: str, zlabel: str, title: str,
                        mask=None) -> Figure:
    """A 1-D design sweep as lines: ``z`` (shape (len(y), len(x))) over whichever of ``x``
    and ``y`` has more than one value, one line per value of the other (a heat map of a
    single row or column shows nothing readable). ``mask`` (True = excluded) is drawn hollow."""
    xv, yv, zv, m = _design_arrays(x, y, z, mask)
    if xv.size >= yv.size:  # lines over x, one per y
        axis, other, other_label, zz, mm = xv, yv, ylabel, zv, m
        axis_label = xlabel
    else:
        axis, other, other_label, zz, mm = yv, xv, xlabel, zv.T, m.T
        axis_label = ylabel
    fig, ax = new_figure()
    for k, val in enumerate(other):
        line, = ax.plot(axis, np.where(mm[k], np.nan, zz[k]), marker="o",
                        label=f"{other_label} = {val:g}", linestyle="-")
        if mm[k].any():
            ax.plot(axis[mm[k]], zz[k][mm[k]], marker="o", linestyle="none",
                    markerfacecolor="none", color=line.get_color(), label="excluded")
    if not np.isfinite(zz).any():
        ax.text(0.5, 0.5, "no finite values", transform=ax.transAxes, ha="center",
                va="center", color="0.4")
    ax.set_xlabel(axis_label)
    ax.set_ylabel(zlabel)
    _title(ax, title)
    ax.legend(loc="best")
    return fig
