"""Where a delay sweep puts the coherence point: the coarse minimum, the fine sweep's centre of
symmetry and its scatter.

The sweep measures signed probe errors ``e`` (S, C) at delays ``d`` (S,) of channel J: each
column a probe's angle error (a pair on an arc) or a probe's direction-cosine error along or
across the pair's line (a 2-D beamformer). Every sweep, 1-D or 2-D, phasor model or full chain, is decided here:

* :func:`coarse_minimum`: the coarse sweep's RMS minimum nearest zero delay;
* :func:`fit_centre`: the coherence point, the common centre of symmetry of the fine sweep's
  error curves;
* :func:`crossing_columns`: which columns cross zero over the sweep;
* :func:`fit_scatter`: the fitted point's scatter from the sweep's own residual.

Why the centre of symmetry and not the minimum: a probe's error is a function of the two
channels' phase mismatch phi = 2 pi f_if (delta - delta_c) (eq. 27) through their cross term,
which goes with cos(phi): **even** about the coherence point delta_c along the pair's line.
Where it is not exactly even -- channel J's echo moves by c0 delta / 2 in range and its gain
in the bin with it, the amplitude design on the nominal setup is off under a mounting
offset -- the probes' RMS minimum moves off the coherence point (up to 13 ps at +-1 mm radial
offset; and a least-squares fit of two harmonics over +-period/4 to the sharper curves of an
array with repeated virtual elements overshot zero and put the fitted minimum 15 ps to
either side of it), while the centre about which the curves are symmetric stays near it.
The fit finds that centre directly: each column a sum of harmonics of (delta - s) with its
own coefficients, and the shared centre s where the residual is least (variable projection).
Near, not on: the phase between the two channels' beam outputs varies across the probes'
directions (an array that is not centro-symmetric, front ends inside its far field), so each
probe's curve is centred a little to either side of the point (custom array -3.2 / +2.5 ps)
and their joint centre sits off it: by up to 1.1 ps for the presets, the custom and a sparse
array at 0.5-3 m, 4 ps for the awr2944 at 0.5 m and 9 ps for the 86-element cascade at 3 m
(front ends inside its 14 m far field). The offset is the geometry's, not the mounting
errors': the sweep measures it on the nominal setup, where the point is known, and subtracts
it (``sweep._fit_offset``; ``benchmarks/calibration_accuracy.py``).

In a 2-D beamformer the error **across** the pair's line crosses zero at the coherence point
but moves with any fixed error across it: a tangential offset of 0.2 mm moved the crossing
for sphere4's elevation pair by 55 ps. A pair side by side or stacked in elevation is
therefore fitted on its errors along the line (even; their centre 14 ps off the point for
the elevation pair, an offset the nominal model gives and the sweep subtracts,
``sweep._fit_offset``), a pair across a cell's diagonal, whose errors
along its line are not symmetric (40 ps), on the across columns that cross zero (any
periodic shape that is zero at s).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

__all__ = ["rms_error_deg", "coarse_minimum", "crossing_columns", "continuous_steps",
           "CentreFit", "fit_centre", "fit_scatter",
           "MC_DRAWS", "SCATTER_DRAW_FRAMES"]

MC_DRAWS = 32  # noise realisations that size the frames per step
SCATTER_DRAW_FRAMES = 16  # fit_scatter draws at this many frames' noise, then scales
SEARCH_GRID_S = 0.5e-12  # the centre's search grid, then the residual's parabola through 3


def rms_error_deg(e) -> np.ndarray:
    """The RMS over the last axis of probe errors ``e`` (rad), in degrees; inf where it is
    undefined (a probe not detected), so that a sweep's minimum never lands there."""
    out = np.degrees(np.sqrt(np.mean(np.square(e), axis=-1)))
    return np.where(np.isfinite(out), out, np.inf)


def coarse_minimum(grid, errs) -> float:
    """The coarse sweep's minimum (s) from its RMS errors ``errs`` (deg) at delays ``grid``:
    minima repeat every period; among the local minima about as deep as the deepest (within
    2 x the deepest + 0.01 deg) the one with the smallest |delta tau|, which costs the least
    range offset (paper, "Disadvantages")."""
    errs, grid = np.asarray(errs, float), np.asarray(grid, float)
    is_min = (np.r_[True, errs[1:] <= errs[:-1]] & np.r_[errs[:-1] <= errs[1:], True])
    good = np.flatnonzero(is_min & (errs <= 2 * np.min(errs) + 0.01))
    return float(grid[int(good[np.argmin(np.abs(grid[good]))])])


def crossing_columns(e_fine, edge: int = 3) -> np.ndarray:
    """Which columns of a fine sweep's signed errors ``e_fine`` (S, C) cross zero over it
    (C,) bool: opposite signs at its two ends, mean of ``edge`` steps each."""
    e = np.asarray(e_fine, float)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a column never detected: NaN
        lo = np.nanmean(e[:edge], axis=0)
        hi = np.nanmean(e[-edge:], axis=0)
    return np.isfinite(lo) & np.isfinite(hi) & (lo * hi < 0)


JUMP_FACTOR = 10.0  # a step's change this many times the sweep's typical bend is a jump


def continuous_steps(e, centre: int, min_steps: int = 7) -> np.ndarray:
    """``e`` (S, C) with every step beyond a jump NaN, per column: the fine sweep's curves
    are smooth in the delay, but where a probe's detection changes its range bin part-way
    through the window (a combined echo straddling two bins of nearly equal power, which the
    2-D probes' placement avoids where it can: ``beam.BeamProbes.placed``) its error jumps
    (sphere4's side-by-side pair at 3 m with 1 mm on a front end, unplaced: 0.013 to 0.021 in
    direction cosine between adjacent 10 ps steps, against 0.0001 of bend), and the curve
    beyond it, a different one, pulled the fitted centre 18 ps. A jump: a step's first
    difference departing from its neighbours' mean (half the third difference) by more than
    :data:`JUMP_FACTOR` x the column's median departure; the steps kept run from the
    ``centre`` step to the nearest jump on either side, the first step that leaves the curve
    not kept. A jump shows in three departures, the largest marks it; a one-step excursion
    (detected in the other bin at one step only) is two jumps in a row whose departures are
    equal but for the noise, so which step is the first off the curve is asked of the curve
    itself: the step the kept steps' quadratic continuation misses by more than the
    threshold. Sweeps of fewer than ``min_steps`` steps are returned as they are."""
    e = np.array(e, float, copy=True)
    if e.ndim != 2 or e.shape[0] < min_steps:
        return e
    n = e.shape[0]
    d = np.diff(e, axis=0)  # (S - 1, C)
    dev = np.full(d.shape, np.nan)
    dev[1:-1] = np.abs(d[1:-1] - 0.5 * (d[:-2] + d[2:]))
    dev[0], dev[-1] = np.abs(d[0] - d[1]), np.abs(d[-1] - d[-2])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a column never detected
        typical = np.nanmedian(dev, axis=0)
    jump = np.isfinite(dev) & (dev > JUMP_FACTOR * typical) & (dev > 0)

    def leaves(c, k, back):
        """Whether step ``k`` misses the quadratic through the three steps before it (towards
        the centre: ``back`` = -1 below it, +1 above) by more than the jump threshold (the
        departure's own scale: twice the third difference's half)."""
        seed = k + back * np.arange(1, 4)
        if seed.min() < 0 or seed.max() >= n:
            return False
        y = e[seed, c]
        miss = abs(e[k, c] - 3 * y[0] + 3 * y[1] - y[2])
        return bool(np.isfinite(miss) and miss > 2 * JUMP_FACTOR * typical[c])

    # a jump between steps k and k + 1 shows in dev at k - 1, k and k + 1: the largest marks it
    for c in range(e.shape[1]):
        ks = np.flatnonzero(jump[:, c])
        if ks.size == 0:
            continue
        peaks = [k for k in ks if dev[k, c] >= np.nanmax(dev[max(k - 1, 0):k + 2, c])]
        lo = [k for k in peaks if k < centre]
        hi = [k for k in peaks if k >= centre]
        if lo:  # the first step off the curve below the centre: k, or k + 1 (an excursion)
            k = max(lo)
            e[:k + 2 if k + 1 < centre and leaves(c, k + 1, +1) else k + 1, c] = np.nan
        if hi:  # above it: k + 1, or k (an excursion)
            k = min(hi)
            e[k if k > centre and leaves(c, k, -1) else k + 1:, c] = np.nan
    return e


def _basis(psi, harmonics: int, odd: bool) -> np.ndarray:
    """(..., S, H + 1) for an even column: a constant and H cosine harmonics of the phase
    ``psi`` (..., S), symmetric about psi = 0; (..., S, 2 H) for a crossing one: H sine and
    H (1 - cosine) harmonics, any periodic shape that is zero at psi = 0."""
    h = np.arange(1, harmonics + 1)
    x = psi[..., None] * h
    if odd:
        return np.concatenate([np.sin(x), 1.0 - np.cos(x)], axis=-1)
    return np.concatenate([np.ones(psi.shape + (1,)), np.cos(x)], axis=-1)


@lru_cache(maxsize=256)
def _basis_gram(d_bytes: bytes, s_bytes: bytes, x_bytes: bytes, period_s: float,
                harmonics: int, odd: bool) -> tuple[np.ndarray, np.ndarray]:
    """A column's basis (K, S_c, 1 + H) at the candidate centres (K,) and its Gram matrices
    (K, 1 + H, 1 + H), from the steps' delays, the candidates and the extra phases as bytes:
    they do not depend on the measured errors, so the Monte-Carlo draws of a sweep (the same
    steps, candidates and phases, other noise) share them (the basis' trigonometry was 40 %
    of a pair's calibration)."""
    d = np.frombuffer(d_bytes)
    s = np.frombuffer(s_bytes)
    x = np.frombuffer(x_bytes)
    psi = 2 * np.pi * (d[None] - s[:, None]) / period_s + x[None]  # (K, S_c)
    b = _basis(psi, harmonics, odd)
    g = np.einsum("ksi,ksj->kij", b, b)
    b.flags.writeable = False
    g.flags.writeable = False
    return b, g


@dataclass(frozen=True)
class CentreFit:
    """How :func:`fit_centre` models the sweep's columns and searches their centre: the
    ``harmonics`` of each column's series, which columns are ``odd`` (C,) bool (None: none),
    the search's half-width ``search_s`` (None: 1.5 steps), and the phase channel J adds
    beyond its delay's, known in advance: ``extra_phase_rad`` (S, C) at the steps and
    ``search_phase`` (delays (F,) -> (F, C)) on the continuous delays."""

    harmonics: int = 2
    search_s: float | None = None
    odd: object = None
    extra_phase_rad: object = None
    search_phase: object = None


def fit_centre(deltas, error_rad, period_s: float, near_s: float, fit: CentreFit = CentreFit(),
               return_fit: bool = False):
    """The coherence point: the common centre of symmetry of the columns of ``error_rad``
    (S, C) measured at ``deltas`` (S,) (module doc), modelled and searched as ``fit`` says.

    Each even column c is modelled as ``a_0 + sum_h a_h cos(h psi_c)`` (symmetric about s,
    its vertex at any value), each crossing one (``odd`` (C,) bool) as ``sum_h b_h sin(h
    psi_c) + a_h (1 - cos(h psi_c))`` (zero at s), psi_c = 2 pi (delta - s) / period + x_c(delta), with its own
    coefficients by least squares over its detected steps (NaN: not detected, that step
    dropped for that column); s is the delay where the summed residual is least, searched
    within ``search_s`` (default 1.5 steps) of ``near_s`` on a 0.5 ps grid, then at the
    vertex of the residual's parabola through its three lowest points. Every step counts, so
    receiver noise enters the point linearly through the fit.

    ``extra_phase_rad`` (S, C): a phase each step adds to channel J beyond the delay's own
    ``2 pi delta / period`` and known in advance, x_c above -- the fractional-delay FIR's
    phase at the step's setting (``calibration.fir.fir_bin_gain``), which cycles with the
    setting every 1/f_s (+-3.7 deg with 5 taps; 33 ps if ignored) and, on a coarse RTS, the
    quantiser's own offset error (``steps.realisation_shift``). The delay returned is then
    the one whose phase mismatch is zero, ``2 pi (delta - s) / period = -mean_c x_c(delta)``
    with x_c on the continuous delays from ``search_phase`` (delays (F,) -> (F, C)), or
    interpolated between the steps.

    ``return_fit``: also the fitted curves at the data's steps (S, C) (NaN where not
    fitted), whose residual is the steps' noise (:func:`fit_scatter`); the point and the
    curves are NaN where too few steps were detected for the fit."""
    harmonics, search_s, odd = fit.harmonics, fit.search_s, fit.odd
    extra_phase_rad, search_phase = fit.extra_phase_rad, fit.search_phase
    d = np.asarray(deltas, float)
    e = np.asarray(error_rad, float).reshape(d.size, -1)
    n_col = e.shape[1]
    odd = np.zeros(n_col, bool) if odd is None else np.asarray(odd, bool)
    x = np.zeros(e.shape) if extra_phase_rad is None else np.asarray(
        extra_phase_rad, float).reshape(e.shape)
    ok = np.isfinite(e)
    fitted = np.full(e.shape, np.nan)
    # a column detected at fewer steps than its coefficients and one more is left out
    n_coef = np.where(odd, 2 * harmonics, harmonics + 1)
    cols = np.flatnonzero(ok.sum(0) >= n_coef + 1)
    if cols.size == 0:
        return (float("nan"), fitted) if return_fit else float("nan")
    step = np.median(np.diff(np.sort(d))) if d.size > 1 else period_s / 40

    def fits(s):
        """Coefficients and residual per candidate centre ``s`` (K,)."""
        s = np.atleast_1d(s)
        total = np.zeros(s.size)
        coefs = []
        for c in cols:
            m = ok[:, c]
            # least squares by the normal equations, batched over the candidates: the basis
            # is a handful of well-separated harmonics over a quarter period or more
            b, g = _basis_gram(d[m].tobytes(), s.tobytes(), x[m, c].tobytes(), float(period_s),
                               int(harmonics), bool(odd[c]))  # (K, S_c, 1 + H), its Gram
            r = np.einsum("ksi,s->ki", b, e[m, c])
            coef = np.linalg.solve(g, r[..., None])[..., 0]  # (K, 1 + H)
            total += np.sum(e[m, c] ** 2) - np.einsum("ki,ki->k", coef, r)
            coefs.append(coef)
        return total, coefs

    half = 1.5 * step if search_s is None else search_s
    grid = near_s + np.arange(-half, half + 1e-15, SEARCH_GRID_S)
    centre = _least(grid, fits(grid)[0])
    _, coefs = fits(centre)
    for c, coef in zip(cols, coefs):
        m = ok[:, c]
        psi = 2 * np.pi * (d[m] - centre) / period_s + x[m, c]
        fitted[m, c] = _basis(psi, harmonics, odd[c]) @ coef[0]
    best = centre if extra_phase_rad is None else _zero_mismatch(centre, d, x[:, cols],
                                                                 period_s, search_phase, cols)
    return (float(best), fitted) if return_fit else float(best)


def _least(grid: np.ndarray, resid: np.ndarray) -> float:
    """The delay of least residual on ``grid``, refined to the vertex of the parabola through
    the lowest point and its two neighbours (the residual is a parabola about its minimum)."""
    k = int(np.argmin(resid))
    centre = float(grid[k])
    if 0 < k < grid.size - 1:
        y0, y1, y2 = resid[k - 1:k + 2]
        curv = y0 - 2 * y1 + y2
        if curv > 0:
            centre += 0.5 * (y0 - y2) / curv * SEARCH_GRID_S
    return centre


def _zero_mismatch(centre: float, d, x_cols, period_s: float, search_phase, cols) -> float:
    """The delay whose phase mismatch is zero, ``2 pi (delta - s) / period = -mean_c
    x_c(delta)``, by four fixed-point steps from the fitted ``centre``: x_c (the fitted columns'
    extra phases ``x_cols`` (S, C_fit)) from ``search_phase`` on the continuous delay, or
    interpolated between the steps ``d``."""
    order = np.argsort(d)
    best = centre
    for _ in range(4):
        if search_phase is not None:
            x_b = np.asarray(search_phase(np.array([best])), float).reshape(-1)[cols]
        else:
            x_b = np.array([np.interp(best, d[order], x_cols[order, i])
                            for i in range(len(cols))])
        best = centre - period_s * float(np.mean(x_b)) / (2 * np.pi)
    return best


def fit_scatter(fit, fitted, e, harmonics: int, seed, pair, repeat=None,
                odd=None) -> tuple[float, float]:
    """The fitted point's 1-sigma scatter (s) with one frame a step, and one frame's noise
    (rad, median over the columns), from a measured fine sweep: its errors ``e`` (S, C) at
    one frame a step, the curves ``fitted`` to them (S, C) and the ``fit`` (errors ->
    (point, curves); :func:`fit_centre`). Each column's noise is its residual about the
    curve (least-squares degrees of freedom); ``MC_DRAWS`` sweeps are drawn as the curves
    plus Gaussian noise of that std / sqrt(``SCATTER_DRAW_FRAMES``) (where the fit is
    linear in the noise) and refitted, their points' std scaled back to one frame. The
    seed: ``seed`` and the ``pair`` (i, j) measured; ``odd`` (C,): the crossing columns, which
    have 2 H coefficients (even ones H + 1).

    Where the fit has no residual degrees of freedom (an RTS with coarse delay steps leaves
    3 or 5 fine steps, through which the curves pass exactly: a zero residual is no evidence
    of no noise) the result is (NaN, NaN): measure the sweep again, independently, and give
    it as ``repeat`` (S, C): each column's noise is then that of the two sweeps' difference,
    var(e - repeat) = 2 sigma^2, with no fit involved."""
    e = np.asarray(e, float)
    used = np.any(np.isfinite(fitted), axis=0)  # the columns the fit used
    if repeat is not None:
        r = (e - np.asarray(repeat, float)) / np.sqrt(2.0)
        ok = np.isfinite(r)
        dof = ok.sum(0)
    else:
        r = e - fitted
        ok = np.isfinite(r)
        # each column's own coefficients (H + 1 even, 2 H crossing), the shared centre once
        n_coef = harmonics + 1 if odd is None else np.where(odd, 2 * harmonics, harmonics + 1)
        dof = ok.sum(0) - n_coef - 1 / max(int(used.sum()), 1)
    if not np.any(used) or np.any(dof[used] < 1):
        return float("nan"), float("nan")
    sigma = np.where(used, np.sqrt(np.sum(np.where(ok, r, 0.0) ** 2, axis=0)
                                   / np.maximum(dof, 1)), 0.0)  # (C,)
    rng = np.random.default_rng(np.random.SeedSequence([int(seed) % 2 ** 32, 1715,
                                                        int(pair[0]), int(pair[1])]))
    base = np.where(np.isfinite(fitted), fitted, e)
    draws = base[None] + (sigma / np.sqrt(SCATTER_DRAW_FRAMES)
                          * rng.standard_normal((MC_DRAWS,) + base.shape))
    est = np.array([fit(x)[0] for x in draws])
    return (float(np.nanstd(est) * np.sqrt(SCATTER_DRAW_FRAMES)),
            float(np.median(sigma[used])))
