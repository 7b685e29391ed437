"""The fit of one front end's parameters to its probe captures: which parameters the captures
separate (:func:`free_parameters`, from the Fisher information), the whitened nonlinear least
squares (:func:`fit_front_end`), the Cramer-Rao bound (:func:`cramer_rao`) and the result of all
front ends (:class:`Identification`, ``rtsgeom identify --json``)."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import least_squares

from .._lib.results import Result
from ..errors import CaptureError
from ..geometry.setup import build_setup
from ..scene import Scene
from ..scene.schema import Spec, check_arg
from .model import PARAMS, ProbeModel, measure

__all__ = ["STD_LIMIT", "MIN_EIGENVALUE", "SEPARATE_BY", "RESIDUAL_LIMIT", "ESTIMATE_LIMITS",
           "check_fit", "fisher", "free_parameters",
           "FrontEndFit", "fit_front_end", "cramer_rao", "Identification", "identify"]

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


def free_parameters(fim: np.ndarray, candidates=range(7)) -> tuple[list[int], dict[int, str]]:
    """Which parameters the Fisher matrix ``fim`` (7, 7) separates. Returns the free indices and
    a reason for each one left out.

    Normalised to unit diagonal, the Fisher matrix is the matrix of cosines between the
    response's derivatives; an eigenvalue below :data:`MIN_EIGENVALUE` is a direction in which
    the response hardly changes. Of the parameters that carry it (component > 0.2), the first
    in :data:`_DROP_ORDER` is fixed, and so on; then a parameter whose Cramer-Rao std exceeds
    :data:`STD_LIMIT` is fixed too."""
    free = [int(i) for i in candidates]
    why: dict[int, str] = {}
    for i in list(free):
        if not fim[i, i] > 0:
            free.remove(i)
            why[i] = "does not change the response at this bin"
    while free:
        f = fim[np.ix_(free, free)]
        d = 1 / np.sqrt(np.diag(f))
        cos = f * d[:, None] * d[None, :]
        w, v = np.linalg.eigh(cos)
        if w[0] >= MIN_EIGENVALUE:
            std = np.sqrt(np.diag(np.linalg.inv(f)))
            over = [k for k in range(len(free)) if std[k] > STD_LIMIT[free[k]]]
            if not over:
                break
            k = min(over, key=lambda k: _DROP_ORDER.index(free[k]))
            i = free.pop(k)
            why[i] = (f"too weak in these captures: its Cramer-Rao std would be {_fmt(i, std[k])}"
                      f" (limit {_fmt(i, STD_LIMIT[i])})")
            continue
        involved = [free[k] for k in range(len(free)) if abs(v[k, 0]) > 0.2]
        i = min(involved, key=_DROP_ORDER.index)
        others = [j for j in involved if j != i]
        k = free.index(i)
        sim = {j: abs(cos[k, free.index(j)]) for j in others}
        free.remove(i)
        why[i] = ("inseparable in these captures from "
                  + ", ".join(f"{PARAMS[j]} (|cos| {sim[j]:.6f})" for j in others)
                  + " (the response changes alike)")
    for i in why:
        if i in SEPARATE_BY:
            why[i] += "; separate it with " + SEPARATE_BY[i]
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

    # tangential grid with the gain solved in closed form (variable projection)
    step = 0.5e-3
    grid = theta[1] + np.arange(-grid_m, grid_m + step / 2, step)
    batch = np.repeat(with_gain(theta)[None], grid.size, axis=0)
    batch[:, 1] = grid
    h = np.stack([m.response(batch) for m in models], 1)  # (G, C, V)
    num = np.abs(np.sum(w[None, :, None] * np.conj(h) * y[None], axis=(1, 2))) ** 2
    den = np.sum(w[None, :, None] * np.abs(h) ** 2, axis=(1, 2))
    theta[1] = grid[np.argmax(num / den)]
    g = _weighted_gain(np.stack([m.response(with_gain(theta)[None])[0] for m in models]), y, w)
    theta[5], theta[6] = np.log(abs(g)), np.angle(g)

    def jac_all(th, free):
        parts = [m.jacobian(th, free) for m in models]
        r = np.stack([p[0] for p in parts])
        jac = np.concatenate([p[1] * s for p, s in zip(parts, sw[:, 0])], 0)
        return r, jac

    def solve(th, free):
        def fun(x):
            t = th.copy()
            t[free] = x
            r = (y - np.stack([m.response(t[None])[0] for m in models])) * sw
            return np.concatenate([r.real.ravel(), r.imag.ravel()])

        def jac(x):
            t = th.copy()
            t[free] = x
            j = -jac_all(t, free)[1]
            return np.concatenate([j.real, j.imag], 0)

        sol = least_squares(fun, th[free], jac=jac, x_scale=_SCALE[free], method="trf",
                            xtol=1e-12, ftol=1e-12, gtol=1e-12, max_nfev=200)
        out = th.copy()
        out[free] = sol.x
        return out

    free, why = free_parameters(fisher(jac_all(theta, range(7))[1]))
    for _ in range(2):  # fit, then check the free set at the estimate (refit if it changed)
        theta = solve(theta, free)
        free2, why2 = free_parameters(fisher(jac_all(theta, range(7))[1]))
        if free2 == free:
            break
        free, why = free2, why2
    resp, jac = jac_all(theta, free)
    cov = np.linalg.inv(fisher(jac))
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


# the fitted parameters as shown: (PARAMS index, name with its unit, SI -> that unit)
SHOWN = ((0, "radial_offset_mm", 1e3), (1, "tangential_offset_mm", 1e3),
         (2, "height_offset_mm", 1e3), (3, "yaw_offset_deg", 180 / np.pi),
         (4, "delay_offset_ps", 1e12), (5, "gain_db", 20 / np.log(10)),
         (6, "phase_deg", 180 / np.pi))


@dataclass(frozen=True, repr=False)
class Identification(Result):
    """Every front end's fit; :meth:`to_dict` is ``rtsgeom identify --json``. ``print(ident)``
    is a summary; ``to_dataframe()`` one row per front end (each parameter and its std, NaN
    where not identifiable); ``plot()`` the mounting offsets with their 1-sigma bars."""

    scene: Scene
    fits: tuple[FrontEndFit, ...]

    def fit(self, q: int) -> FrontEndFit | None:
        return next((f for f in self.fits if f.index == q), None)

    def _summary(self):
        rows = []
        for f in self.fits:
            parts = [f"{short} {f.estimate[i] * k:.3g}+-{f.std[i] * k:.2g}"
                     for (i, _, k), short in zip(SHOWN[:4], ("r", "t", "h", "yaw"))
                     if f.reasons[i] is None]
            rows.append((f"front end {f.index}", (" ".join(parts) + " (mm, yaw deg)" if parts
                                                  else "nothing identifiable")
                         + f", residual {f.residual_rms:.2f}, {f.captures} captures"))
        return f"{self.scene.name}: {len(self.fits)} front ends identified", rows

    def _columns(self) -> dict:
        cols = {"front_end": [f.index for f in self.fits]}
        for i, name, k in SHOWN:
            ok = [f.reasons[i] is None for f in self.fits]
            cols[name] = [f.estimate[i] * k if o else np.nan for f, o in zip(self.fits, ok)]
            cols[name.rsplit("_", 1)[0] + "_std_" + name.rsplit("_", 1)[1]] = [
                f.std[i] * k if o else np.nan for f, o in zip(self.fits, ok)]
        cols["residual_rms"] = [f.residual_rms for f in self.fits]
        return cols

    def plot(self, title: str = ""):
        """Each front end's fitted radial, tangential and height offset (mm) with 1 sigma."""
        from ..viz.figures import STYLE, new_figure  # matplotlib: only for the figure
        import matplotlib as mpl
        cols = self._columns()
        with mpl.rc_context(STYLE):
            fig, ax = new_figure(figsize=(6.4, 3.6))
            q = np.asarray(cols["front_end"], float)
            for k, (_, name, _) in enumerate(SHOWN[:3]):
                std = name.rsplit("_", 1)[0] + "_std_mm"
                ax.errorbar(q + (k - 1) * 0.12, cols[name], yerr=cols[std], fmt="o",
                            capsize=3, label=name.replace("_offset_mm", ""))
            ax.axhline(0.0, color="0.4", linewidth=0.8)
            ax.set_xticks(q)
            ax.set_xlabel("front end")
            ax.set_ylabel("fitted offset (mm), 1 sigma bars")
            ax.legend(loc="best")
            ax.set_title(title or f"{self.scene.name}: identified mounting offsets",
                         parse_math=False)
        return fig

    def to_dict(self) -> dict:
        out_fe, out_ch, keys = [], [], []

        def entry(f, i, unit, why, name):
            if f.reasons[i] is not None:
                why[name] = f.reasons[i]
                return None
            return {"value": float(f.estimate[i] * unit), "std": float(f.std[i] * unit)}

        for f in self.fits:
            why: dict = {}
            d = {"index": f.index}
            for i, name, unit in ((0, "radial_offset_mm", 1e3), (1, "tangential_offset_mm", 1e3),
                                  (2, "height_offset_mm", 1e3),
                                  (3, "yaw_offset_deg", 180 / np.pi)):
                d[name] = entry(f, i, unit, why, name)
            d["not_identifiable"] = why
            fr = [i for i in f.free if i < 4]
            d["correlations"] = [{"a": PARAMS[a], "b": PARAMS[b], "r": float(f.correlation[a, b])}
                                 for k, a in enumerate(f.free) for b in f.free[k + 1:]
                                 if (a in fr or b in fr) and abs(f.correlation[a, b]) > 0.5]
            d["residual_rms"] = f.residual_rms
            d["misfit"] = f.misfit
            d["captures"] = f.captures
            out_fe.append(d)
            why = {}
            ch = {"index": f.index, "front_end": f.index,
                  "delay_offset_s": entry(f, 4, 1.0, why, "delay_offset_s")}
            g = entry(f, 5, 20 / np.log(10), why, "gain_db")
            ch["gain_db"] = g
            ch["phase_deg"] = entry(f, 6, 180 / np.pi, why, "phase_deg")
            ch["not_identifiable"] = why
            out_ch.append(ch)
            keys.append(f.residual_rms)
        return {"scene": self.scene.name, "front_ends": out_fe, "channels": out_ch,
                "residual_rms": float(np.sqrt(np.mean(np.square(keys)))) if keys else None,
                "residual_rms_unit": "measured noise std of one range-Doppler value",
                "residual_limit": RESIDUAL_LIMIT,
                "model_fits": all(f.misfit is None for f in self.fits)}


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
                  "setup's")


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


def identify(scene: Scene, captures, accept_misfit: bool = False) -> Identification:
    """Fit the nominal ``scene``'s free parameters to probe ``captures`` (:class:`Capture`,
    any number per front end; the captures of one front end are fitted jointly).

    ``captures`` may be a generator (``read_capture`` per file): each is reduced to its
    probe's bin when it arrives, so memory holds one cube at a time. Each capture is checked
    against the scene (:func:`~rtsgeom.identify.model.measure`) and each fit by
    :func:`check_fit`: a misfit raises ``CaptureError`` unless ``accept_misfit``, which keeps
    it flagged (``misfit`` in the JSON)."""
    setup = build_setup(scene)
    groups: dict[int, list] = {}
    for cap in captures:
        groups.setdefault(cap.active, []).append(measure(setup, cap))
        del cap
    return Identification(scene, tuple(check_fit(fit_front_end(groups[q]), accept_misfit)
                                       for q in sorted(groups)))
