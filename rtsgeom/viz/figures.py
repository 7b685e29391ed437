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
from pathlib import Path
from typing import Mapping

import matplotlib as mpl
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle

from ..io import atomic_path

__all__ = ["STYLE", "save_figure", "range_doppler_figure", "range_angle_figure",
           "calibration_sweep_figure", "linearity_figure", "tolerance_histogram_figure",
           "design_heatmap_figure"]

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


def _styled(func):
    """Build the figure under :data:`STYLE` (rc parameters are read when artists are made)."""
    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        with mpl.rc_context(STYLE):
            return func(*args, **kwargs)
    return wrapper


def _new_figure(figsize=(6.4, 4.4), nrows=1, ncols=1, **subplot_kw) -> tuple[Figure, object]:
    fig = Figure(figsize=figsize, dpi=DPI, layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(nrows, ncols, squeeze=True, **subplot_kw)
    return fig, axes


def save_figure(fig: Figure, path: str | Path) -> Path:
    """Write ``fig`` as PNG (dpi 120) atomically; return the path."""
    path = Path(path)
    with mpl.rc_context(STYLE), atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=DPI)
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
    """Colour map of power in dB over ``DYNAMIC_RANGE_DB`` below its maximum."""
    finite = power_db[np.isfinite(power_db)]
    vmax = float(finite.max()) if finite.size else 0.0
    mesh = ax.pcolormesh(x, y, power_db, shading="nearest", vmin=vmax - DYNAMIC_RANGE_DB,
                         vmax=vmax, rasterized=True)
    fig.colorbar(mesh, ax=ax, label="power (dB)")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(False)
    if title:
        ax.set_title(title)


@_styled
def range_doppler_figure(power_db, range_m, velocity_mps, detections=None,
                         title: str = "") -> Figure:
    """Range-Doppler map: x velocity (m/s), y range (m), colour power (dB, 60 dB below the
    maximum); ``detections`` (N, 2) of [range_m, velocity_mps] circled."""
    r = _vector("range_m", range_m)
    v = _vector("velocity_mps", velocity_mps)
    p = _grid("power_db", power_db, (r.size, v.size), "n_range, n_doppler")
    det = _points("detections", detections)
    fig, ax = _new_figure()
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
    fig, ax = _new_figure()
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
                             period_s: float | None = None, title: str = "") -> Figure:
    """Phase-coherency calibration: angle error (deg) over the swept RTS delay offset (ns).

    The chosen offset is marked; with ``period_s`` (the phase period 1/(f_rts + B/2)) the
    offsets one period apart, where the same minimum repeats, are marked as well.
    """
    tau = _vector("delta_tau_s", delta_tau_s)
    err = _vector("angle_error_deg", angle_error_deg)
    if err.size != tau.size:
        raise ValueError(f"angle_error_deg has {err.size} values, delta_tau_s {tau.size}")
    order = np.argsort(tau)
    t_ns, err = tau[order] * 1e9, err[order]
    chosen_ns = float(chosen_delta_tau_s) * 1e9
    fig, ax = _new_figure(figsize=(6.4, 3.8))
    ax.plot(t_ns, err, marker=".", label="angle error")
    ax.axhline(0.0, color="0.4", linewidth=0.8)
    if period_s is not None and period_s > 0:
        p_ns = float(period_s) * 1e9
        k = np.arange(np.ceil((t_ns[0] - chosen_ns) / p_ns),
                      np.floor((t_ns[-1] - chosen_ns) / p_ns) + 1)
        for x in chosen_ns + p_ns * k[k != 0]:
            ax.axvline(x, color="C2", linestyle=":", linewidth=1.2)
        ax.plot([], [], color="C2", linestyle=":", label=f"chosen + k periods ({p_ns:.4f} ns)")
    y_chosen = float(np.interp(chosen_ns, t_ns, err))
    ax.axvline(chosen_ns, color="C3", linestyle="--", linewidth=1.2)
    ax.plot([chosen_ns], [y_chosen], marker="o", markersize=7, color="C3", linestyle="none",
            label=f"chosen: {chosen_ns * 1e3:.1f} ps ({y_chosen:.3f} deg)")
    ax.set_xlabel("RTS delay offset $\\Delta\\tau_{rts}$ (ns)")
    ax.set_ylabel("angle error (deg)")
    ax.set_title(title or "Phase coherency calibration")
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
                     title: str = "") -> Figure:
    """Amplitude attenuation and angle linearity and error (paper figure), stacked over the set
    angle: the two channels' attenuation in dB (only with ``amplitude_db_by_mode``, each (2, n)),
    the detected angle against the ideal line, and the error detected - set. One colour per
    synthesis mode; NaN marks a set angle without a detection."""
    s = _vector("set_deg", set_deg)
    det = _mode_arrays("detected_deg_by_mode", detected_deg_by_mode, s.size)
    amp = (None if amplitude_db_by_mode is None
           else _mode_arrays("amplitude_db_by_mode", amplitude_db_by_mode, s.size, rows=2))
    n_panels = 2 if amp is None else 3
    fig, axes = _new_figure(figsize=(6.4, 2.4 * n_panels + 0.4), nrows=n_panels, sharex=True)
    ax_amp, ax_lin, ax_err = (None, *axes) if amp is None else axes
    colour = {m: f"C{i % 10}" for i, m in enumerate(dict.fromkeys([*det, *(amp or {})]))}
    if ax_amp is not None:
        for mode, a in amp.items():
            ax_amp.plot(s, a[0], color=colour[mode], label=f"{mode}: channel 1")
            ax_amp.plot(s, a[1], color=colour[mode], linestyle="--", label=f"{mode}: channel 2")
        ax_amp.set_ylabel("attenuation (dB)")
        ax_amp.legend(loc="best", ncols=2 if len(amp) > 1 else 1)
        ax_amp.set_title(title or "Amplitude attenuation and angle linearity and error")
    else:
        ax_lin.set_title(title or "Angle linearity and error")
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
def tolerance_histogram_figure(errors_deg_by_case: Mapping[str, object],
                               spec_deg: float | None = None, title: str = "") -> Figure:
    """Histograms of angle errors (deg) per case (e.g. mounting-tolerance Monte Carlo draws) on
    common bins; the legend gives each case's count and 95th percentile of |error|; ``spec_deg``
    draws the ±spec limits."""
    cases = {}
    for name, values in errors_deg_by_case.items():
        a = np.asarray(values, dtype=float).ravel()
        cases[str(name)] = a[np.isfinite(a)]
    if not cases:
        raise ValueError("errors_deg_by_case is empty")
    every = np.concatenate(list(cases.values()))
    lo, hi = (float(every.min()), float(every.max())) if every.size else (-1.0, 1.0)
    if spec_deg is not None:
        lo, hi = min(lo, -abs(spec_deg)), max(hi, abs(spec_deg))
    if hi - lo < 1e-12:
        lo, hi = lo - 0.5, hi + 0.5
    bins = np.linspace(lo, hi, int(np.clip(np.sqrt(max(every.size, 1)), 10, 60)) + 1)
    fig, ax = _new_figure(figsize=(6.4, 3.8))
    for name, a in cases.items():
        p95 = float(np.percentile(np.abs(a), 95)) if a.size else np.nan
        ax.hist(a, bins=bins, histtype="step", linewidth=1.5,
                label=f"{name} (n={a.size}, |err| 95 %: {p95:.3f} deg)")
    if spec_deg is not None:
        for sign in (-1, 1):
            ax.axvline(sign * abs(spec_deg), color="red", linestyle="--", linewidth=1.2,
                       label=f"spec ±{abs(spec_deg):g} deg" if sign > 0 else None)
    ax.set_xlabel("angle error (deg)")
    ax.set_ylabel("count")
    ax.set_title(title or "Angle error distribution")
    ax.legend(loc="best")
    return fig


@_styled
def design_heatmap_figure(x, y, z, xlabel: str, ylabel: str, zlabel: str, title: str,
                          mask=None) -> Figure:
    """Heat map of a figure of merit ``z`` (shape (len(y), len(x))) over two design parameters,
    e.g. arc radius vs front-end spacing with colour = worst angle error. ``mask`` (same shape,
    True = excluded, e.g. infeasible) greys out and hatches cells. Labels should carry units."""
    xv = _vector("x", x)
    yv = _vector("y", y)
    zv = _grid("z", z, (yv.size, xv.size), "len(y), len(x)")
    m = np.zeros(zv.shape, bool) if mask is None else np.asarray(mask, bool)
    if m.shape != zv.shape:
        raise ValueError(f"mask must have shape {zv.shape}, got {m.shape}")
    shown = np.ma.masked_array(zv, mask=m | ~np.isfinite(zv))
    fig, ax = _new_figure()
    ax.set_facecolor("0.85")
    mesh = ax.pcolormesh(xv, yv, shown, shading="nearest", rasterized=True)
    fig.colorbar(mesh, ax=ax, label=zlabel)
    if m.any():
        xe, ye = _cell_edges(xv), _cell_edges(yv)
        for j, i in zip(*np.nonzero(m)):
            ax.add_patch(Rectangle((xe[i], ye[j]), xe[i + 1] - xe[i], ye[j + 1] - ye[j],
                                   fill=False, hatch="//", edgecolor="0.55", linewidth=0.0))
        ax.add_patch(Rectangle((0, 0), 0, 0, facecolor="0.85", hatch="//", edgecolor="0.55",
                               label="excluded", visible=True))
        ax.legend(loc="upper right")
    if min(xv.size, yv.size) >= 3 and shown.count() >= 4:
        cs = ax.contour(xv, yv, shown, levels=5, colors="white", linewidths=0.7)
        ax.clabel(cs, fontsize=7, fmt="%.3g")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(False)
    return fig
