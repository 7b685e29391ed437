"""The fit of one front end's parameters to its probe captures: which parameters the captures
separate (:func:`free_parameters`, from the Fisher information), the whitened nonlinear least
squares (:func:`fit_front_end`, on :func:`solve_whitened`, which the joint fit of
:mod:`.joint` shares), the Cramer-Rao bound (:func:`cramer_rao`) and the checks of an
estimate (:func:`check_fit`)."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import least_squares

from ..errors import CaptureError
from ..geometry.farfield import angular_resolution_rad
from ..scene.schema import Spec, check_arg
from .model import PARAMS, ProbeModel

__all__ = ["STD_LIMIT", "MIN_EIGENVALUE", "SEPARATE_BY", "RESIDUAL_LIMIT", "ESTIMATE_LIMITS",
           "check_fit", "fisher", "free_parameters", "solve_whitened",
           "FrontEndFit", "fit_front_end", "cramer_rao"]

# optimiser scales (SI), per parameter
_SCALE = np.array([1e-3, 1e-3, 1e-3, 1e-2, 1e-11, 0.1, 0.1])
#: when parameters are inseparable, drop them in this order (the nuisance gain/phase last)
_DROP_ORDER = (4, 3, 0, 2, 1, 6, 5)
#: a parameter whose Cramer-Rao std exceeds this is reported as not identifiable
STD_LIMIT = np.array([5e-3, 5e-3, 5e-3, np.radians(5.0), 100e-12, np.inf, np.inf])
#: smallest eigenvalue of the normalised Fisher matrix kept (a variance inflation of 1e4)
MIN_EIGENVALUE = 1e-4

SEPARATE_BY = {
    0: ("a capture of this front end at another RF start frequency (radar.f_c_hz moved by about "
        "1 GHz; the air path's phase turns with f_c, the channel's delay with f_rts and its "
        "phase not at all; identify does not take such captures yet: every capture is read "
        "with the scene's radar)"),
    4: ("a capture of this front end through another RTS channel, or at another RF start "
        "frequency (the channel delay acts at f_rts, a radial offset at f_c; neither is an "
        "input of identify yet)"),
    3: ("directive front-end antenna patterns in the model (not in identify's model yet; "
        "without them the yaw only moves the Rx and Tx antennas by +-s/2 sin(yaw) in opposite "
        "radial directions, which cancels in the two-way path)"),
    2: "a RuT with elevation elements (radar.use_elevation_tx = true)",
    1: "a higher SNR (more frames averaged)",
}


def fisher(jac_white: np.ndarray) -> np.ndarray:
    """Fisher information 2 Re(J^H J) of whitened complex residuals (unit noise variance)."""
    return 2 * np.real(jac_white.conj().T @ jac_white)


def free_parameters(fim: np.ndarray, candidates=None, kinds=None, names=None
                    ) -> tuple[list[int], dict[int, str]]:
    """Which parameters the Fisher matrix ``fim`` (P, P) separates. Returns the free indices and
    a reason for each one left out.

    ``kinds`` (P,): the :data:`PARAMS` index of each parameter (default: one front end's
    seven in order; the joint fit stacks several front ends and the radar's antennas, an
    antenna's ln-gain and phase counting as a channel's), ``names`` their labels in the
    reasons (default :data:`PARAMS`), ``candidates`` the indices that may be free (default
    all). Normalised to unit diagonal, the Fisher matrix is the matrix of cosines between the
    response's derivatives; an eigenvalue below :data:`MIN_EIGENVALUE` is a direction in which
    the response hardly changes. The parameters are taken in the reverse of
    :data:`_DROP_ORDER` (the channels' gains and phases first, the delay last), each kept
    only if the kept set stays above that eigenvalue, else fixed as inseparable from the
    kept parameters its direction involves; then a kept parameter whose Cramer-Rao std
    exceeds :data:`STD_LIMIT` is fixed too, the first in :data:`_DROP_ORDER` first.
    (Forward, not by elimination: with many front ends, each with its near-null pairs, the
    nearly equal small eigenvalues mix their eigenvectors, and an elimination picked an
    identifiable front end's phase or tangential offset from the mixture.)"""
    n = fim.shape[0]
    kinds = np.arange(n) if kinds is None else np.asarray(kinds)
    names = PARAMS if names is None else names

    def rank(i):
        return _DROP_ORDER.index(int(kinds[i])), i

    def cosines(idx):
        f = fim[np.ix_(idx, idx)]
        d = 1 / np.sqrt(np.diag(f))
        return f * d[:, None] * d[None, :]

    why: dict[int, str] = {}
    free: list[int] = []
    for i in sorted((int(i) for i in (range(n) if candidates is None else candidates)),
                    key=rank, reverse=True):
        if not fim[i, i] > 0:
            why[i] = "does not change the response at this bin"
            continue
        cos = cosines(free + [i])
        w, v = np.linalg.eigh(cos)
        if w[0] >= MIN_EIGENVALUE:
            free.append(i)
            continue
        sim = ({j: abs(cos[-1, k]) for k, j in enumerate(free) if abs(v[k, 0]) > 0.2}
               or {free[k]: abs(cos[-1, k]) for k in np.argsort(-np.abs(v[:-1, 0]))[:3]})
        others = [j for j in sim if sim[j] > 1e-3] or list(sim)
        why[i] = ("inseparable in these captures from "
                  + ", ".join(f"{names[j]} (|cos| {sim[j]:.6f})" for j in others)
                  + " (the response changes alike)")
    while free:
        std = np.sqrt(np.diag(np.linalg.inv(fim[np.ix_(free, free)])))
        over = [k for k in range(len(free)) if std[k] > STD_LIMIT[kinds[free[k]]]]
        if not over:
            break
        k = min(over, key=lambda k: rank(free[k]))
        i = free.pop(k)
        why[i] = (f"too weak in these captures: its Cramer-Rao std would be "
                  f"{_fmt(kinds[i], std[k])} (limit {_fmt(kinds[i], STD_LIMIT[kinds[i]])})")
    for i in why:
        if int(kinds[i]) in SEPARATE_BY:
            why[i] += "; separate it with " + SEPARATE_BY[int(kinds[i])]
    return sorted(free), why


def _fmt(i: int, x: float) -> str:
    if i in (0, 1, 2):
        return f"{x * 1e3:.3g} mm"
    if i in (3, 6):
        return f"{np.degrees(x):.3g} deg"
    if i == 4:
        return f"{x * 1e12:.3g} ps"
    return f"{x:.3g}"


@dataclass(frozen=True)
class FrontEndFit:
    """The fit of one front end (and the channel that drives it) to its captures."""

    index: int
    estimate: np.ndarray  # (7,) PARAMS, SI; the ones not free at the scene's nominal values
    std: np.ndarray  # (7,) standard deviations, NaN where not identifiable
    reasons: tuple  # (7,) None or why the parameter is not identifiable
    correlation: np.ndarray  # (7, 7) of the free estimates (NaN elsewhere)
    residual_rms: float  # rms |residual| / measured noise std (about 1 when the model fits)
    noise_std: float  # measured noise std of one spectrum value (capture units)
    captures: int
    misfit: str | None = None  # why the estimates are not the setup's (accepted misfit)

    @property
    def free(self) -> tuple[int, ...]:
        return tuple(i for i in range(len(PARAMS)) if self.reasons[i] is None)


def _weighted_gain(h: np.ndarray, y: np.ndarray, w: np.ndarray) -> complex:
    """Least-squares complex factor G for y ~ G h (weights w per row)."""
    return complex(np.sum(w[:, None] * np.conj(h) * y) / np.sum(w[:, None] * np.abs(h) ** 2))


def solve_whitened(y, sw, respond, jac_all, theta, scale, choose_free):
    """The whitened nonlinear least squares of :func:`fit_front_end` and the joint fit:
    measurements ``y`` (C, V) with whitening ``sw`` (C, 1), model ``respond(theta)`` (C, V) and
    ``jac_all(theta, free) -> (response (C, V), whitened Jacobian (C V, P))``; the free set
    from ``choose_free(fisher)`` at the start, checked again at the estimate (refit once if it
    changed). Returns (estimate, free, reasons, covariance of the free ones (inverse Fisher),
    the response at the estimate)."""
    n = theta.size

    def solve(th, free):
        def fun(x):
            t = th.copy()
            t[free] = x
            r = (y - respond(t)) * sw
            return np.concatenate([r.real.ravel(), r.imag.ravel()])

        def jac(x):
            t = th.copy()
            t[free] = x
            j = -jac_all(t, free)[1]
            return np.concatenate([j.real, j.imag], 0)

        sol = least_squares(fun, th[free], jac=jac, x_scale=scale[free], method="trf",
                            xtol=1e-12, ftol=1e-12, gtol=1e-12, max_nfev=200)
        out = th.copy()
        out[free] = sol.x
        return out

    free, why = choose_free(fisher(jac_all(theta, range(n))[1]))
    for _ in range(2):  # fit, then check the free set at the estimate (refit if it changed)
        theta = solve(theta, free)
        free2, why2 = choose_free(fisher(jac_all(theta, range(n))[1]))
        if free2 == free:
            break
        free, why = free2, why2
    resp, jac = jac_all(theta, free)
    return theta, free, why, np.linalg.inv(fisher(jac)), resp


def fit_front_end(meas: list[tuple[np.ndarray, float, ProbeModel]], grid_m: float = 50e-3
                  ) -> FrontEndFit:
    """Fit one front end's parameters to its measurements ``(y (V,), sigma2, model)``.

    Start: the scene's values, the complex gain in closed form and the tangential offset from
    a grid over +-``grid_m`` (the only parameter whose phase slope can wrap); then
    ``least_squares`` over the parameters :func:`free_parameters` keeps, whitened residuals,
    the Jacobian by :meth:`ProbeModel.jacobian`."""
    models = [m for _, _, m in meas]
    y = np.stack([v for v, _, _ in meas])  # (C, V)
    w = np.array([1 / s for _, s, _ in meas])  # (C,)
    sw = np.sqrt(w)[:, None]
    theta = models[0].nominal()

    def with_gain(th):
        th = th.copy()
        th[..., 5:7] = 0.0
        return th

    # tangential grid with the gain solved in closed form (variable projection), 16 points
    # per resolution cell of the array at this range (the fit refines from the best one)
    # (at least 9 over the grid; was a fixed 0.5 mm, 201 points: 10 of a fit's 19 s at 1.6 m)
    setup = models[0].setup
    step = min(grid_m / 4, angular_resolution_rad(setup.rut) * setup.scene.rts.arc_radius_m / 16)
    grid = theta[1] + np.arange(-grid_m, grid_m + step / 2, step)
    batch = np.repeat(with_gain(theta)[None], grid.size, axis=0)
    batch[:, 1] = grid
    h = np.stack([m.response(batch) for m in models], 1)  # (G, C, V)
    num = np.abs(np.sum(w[None, :, None] * np.conj(h) * y[None], axis=(1, 2))) ** 2
    den = np.sum(w[None, :, None] * np.abs(h) ** 2, axis=(1, 2))
    theta[1] = grid[np.argmax(num / den)]
    g = _weighted_gain(np.stack([m.response(with_gain(theta)[None])[0] for m in models]), y, w)
    theta[5], theta[6] = np.log(abs(g)), np.angle(g)

    def respond(th):
        return np.stack([m.response(th[None])[0] for m in models])

    def jac_all(th, free):
        parts = [m.jacobian(th, free) for m in models]
        r = np.stack([p[0] for p in parts])
        jac = np.concatenate([p[1] * s for p, s in zip(parts, sw[:, 0])], 0)
        return r, jac

    theta, free, why, cov, resp = solve_whitened(y, sw, respond, jac_all, theta, _SCALE,
                                                 free_parameters)
    std = np.full(7, np.nan)
    std[free] = np.sqrt(np.diag(cov))
    corr = np.full((7, 7), np.nan)
    corr[np.ix_(free, free)] = cov / np.outer(std[free], std[free])
    res = (y - resp) * sw
    theta[6] = float(np.angle(np.exp(1j * theta[6])))
    return FrontEndFit(models[0].active, theta, std, tuple(why.get(i) for i in range(7)), corr,
                       float(np.sqrt(np.mean(np.abs(res) ** 2))),
                       float(np.sqrt(np.mean(1 / w))), len(meas))


def cramer_rao(models, theta, sigma2, free) -> np.ndarray:
    """Cramer-Rao bound (std, (7,), NaN where not free) of the ``free`` parameters at the true
    ``theta`` for captures with probe models ``models`` and noise variances ``sigma2`` per
    spectrum value: ``sqrt(diag(F^-1))``, ``F = sum_c 2 Re(J_c^H J_c) / sigma2_c``."""
    free = list(free)
    f = sum(fisher(m.jacobian(theta, free)[1]) / s
            for m, s in zip(models, np.broadcast_to(sigma2, (len(models),))))
    std = np.full(7, np.nan)
    act = np.diag(f) > 1e-30 * np.max(np.diag(f))  # a parameter that does not act: inf
    d = np.full(len(free), np.inf)
    try:
        d[act] = np.diag(np.linalg.inv(f[np.ix_(act, act)]))
    except np.linalg.LinAlgError:  # exactly degenerate: no finite bound for any of them
        pass
    std[free] = np.where(d > 0, np.sqrt(np.abs(d)), np.inf)
    return std


#: a fit whose whitened residual exceeds this many noise std does not explain its captures
#: (a clean fit reads 0.5-1.6; a capture of an arc of 1.2 m fitted on 1 m read 9.4)
RESIDUAL_LIMIT = 3.0
#: estimates beyond these are not a mounting or channel tolerance but a capture that is not
#: this setup's (a sidecar scale of -1 read +203 dB, a probe range of 30 m for 15.5 m -58 dB):
#: (parameter, name in the output, SI -> output factor, declaration of the output value)
ESTIMATE_LIMITS = tuple(
    (i, name, k, Spec(name, "float", "", unit=u, lo=-hi, hi=hi))
    for i, name, k, u, hi in ((0, "radial_offset_mm", 1e3, "mm", 50.0),
                              (1, "tangential_offset_mm", 1e3, "mm", 50.0),
                              (2, "height_offset_mm", 1e3, "mm", 50.0),
                              (3, "yaw_offset_deg", 180 / np.pi, "deg", 30.0),
                              (4, "delay_offset_s", 1.0, "s", 10e-9),
                              (5, "gain_db", 20 / np.log(10), "dB", 40.0)))
_WHAT_TO_CHECK = ("check that the sidecar's active_front_end, probe_range_m, probe_amplitude "
                  "and scale are the capture's and that the scene's arc and radar are the "
                  "setup's; a radar with its own per-antenna phase errors needs "
                  "--radar-channels")


def check_fit(f: FrontEndFit, accept_misfit: bool = False) -> FrontEndFit:
    """Refuse estimates outside :data:`ESTIMATE_LIMITS` (``CaptureError``); a residual above
    :data:`RESIDUAL_LIMIT` too, or with ``accept_misfit`` the fit flagged with the reason."""
    for i, name, k, s in ESTIMATE_LIMITS:
        if f.reasons[i] is None:
            try:
                check_arg(float(f.estimate[i] * k), name, "float",
                          f"front end {f.index}: estimated", CaptureError, lo=s.lo, hi=s.hi,
                          unit=s.unit)
            except CaptureError as exc:
                raise CaptureError(f"{exc} (not a tolerance of this setup: {_WHAT_TO_CHECK})") \
                    from None
    if not np.isfinite(f.residual_rms):
        raise CaptureError(f"front end {f.index}: the fit did not converge to a finite "
                           f"residual: {_WHAT_TO_CHECK}")
    if f.residual_rms <= RESIDUAL_LIMIT:
        return f
    why = (f"front end {f.index}: residual_rms = {f.residual_rms:.3g} x noise: must be at most "
           f"{RESIDUAL_LIMIT:g} for the estimates to be the setup's (the model does not "
           f"explain the captures; {_WHAT_TO_CHECK})")
    if not accept_misfit:
        raise CaptureError(why)
    return replace(f, misfit=why)
