"""Measure a built setup from radar captures: each front end's mounting errors and each RTS
channel's gain, phase and delay, by nonlinear least squares on the RuT's own output.

With one front end active and a probe target programmed, the RuT's spectrum at the probe's
range-Doppler bin, per virtual element ``v``, is (paper eqs. 8, 15/16 with the exact legs)::

    y_v = conj(G_q A g_a,v g_b,v) exp(j 2 pi [f_c tau_air,v + f_rts tau_if - S tau_v^2/2])
          * R_r(S tau_v + f_D) D_d(f_D)                                            (+ noise)

``tau_air,v = |RuT Tx_m - FE Rx| / c0 + |FE Tx - RuT Rx_k| / c0`` moves with the front end's
radial, tangential and height offsets and its yaw (``arcmath.antenna_positions``), ``tau_if``
with the channel's delay offset, ``G_q`` is the channel's complex gain. :class:`ProbeModel`
evaluates this for a batch of parameter vectors at once (``radar.phasors.bin_response``, the
same kernels the simulator is tested against); :func:`identify` fits it with
``scipy.optimize.least_squares``, the Jacobian by batched central differences (one model call
for all columns), the residuals whitened by the noise measured in the capture's own
range-Doppler map. The covariance is the inverse Fisher information ``F = 2 Re(J^H J)`` of the
whitened Jacobian: at the truth and with the true noise it is the Cramer-Rao bound
(:func:`cramer_rao`).

Not every parameter is visible in one capture: a channel delay offset turns the response's phase
(at f_rts) like the channel's phase, and a radial offset does the same (at f_c) except for a
near-field curvature far below the noise. :func:`free_parameters` finds such directions from the
Fisher information's eigenvalues (normalised to unit diagonal, a correlation-like matrix) and
fixes the parameter least worth keeping at its nominal value; the output then says why and which
extra capture separates it. Fixed or not, the fitted response is the measured one, so the
*combination* that coherence between two channels depends on (channel phase + radial offset +
delay offset) is measured: :func:`predicted_calibration` gives the pair's calibration delay
without a sweep.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np
from scipy.constants import c
from scipy.optimize import least_squares

from .arcmath import antenna_positions, layout_offsets
from .geometry import Setup
from .geometry.setup import build_setup
from .paths import exact_paths
from .paths.exact import leg_delays
from .radar.capture import (Capture, capture_probe, read_capture,  # re-exported
                            simulate_capture, write_capture)
from .radar.frame import noise_power
from .radar.phasors import bin_response
from .radar.processing import range_doppler, window
from .rts import KIND_DIRECT, Echoes, fir_if_gain, realised_delay, requested_delay
from .scene import FrontEndConfig, Scene

__all__ = ["PARAMS", "Capture", "ProbeModel", "FrontEndFit", "Identification", "capture_probe",
           "simulate_capture", "write_capture", "read_capture", "measure", "free_parameters",
           "identify", "cramer_rao", "identified_scene_toml", "predicted_calibration",
           "crb_grid", "crb_figure"]

#: the fitted parameters per front end / channel, SI inside (m, rad, s; gain as ln|G|)
PARAMS = ("radial_offset", "tangential_offset", "height_offset", "yaw_offset", "delay_offset",
          "log_gain", "phase")
# optimiser scales and central-difference steps (SI), per parameter
_SCALE = np.array([1e-3, 1e-3, 1e-3, 1e-2, 1e-11, 0.1, 0.1])
_STEP = np.array([1e-6, 1e-6, 1e-6, 1e-5, 1e-14, 1e-6, 1e-6])
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


# ------------------------------------------------------------------------------------------
# The forward model
# ------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ProbeModel:
    """The probe's spectrum at its bin per virtual element, for a batch of parameter vectors
    (:data:`PARAMS`, SI) of front end ``active`` on the nominal ``setup``."""

    setup: Setup
    active: int
    range_m: float
    velocity_mps: float
    amplitude: float
    range_bin: int
    doppler_bin: int

    @classmethod
    def of(cls, setup: Setup, cap: Capture, range_bin: int | None = None) -> "ProbeModel":
        radar = setup.scene.radar
        f_d = 2 * radar.f_c_hz * cap.velocity_mps / c
        rb = (int(np.round(cap.range_m * 2 * radar.slope_hz_per_s / c * radar.samples_per_chirp
                           / radar.adc_rate_hz)) if range_bin is None else int(range_bin))
        n_l = radar.chirps_per_tx
        db = (int(np.round(f_d * radar.tdm_cycle_s * n_l)) + n_l // 2) % n_l
        return cls(setup, cap.active, cap.range_m, cap.velocity_mps, cap.amplitude, rb, db)

    def nominal(self) -> np.ndarray:
        """The scene's own values of the parameters (its offsets, gain and phase errors)."""
        f = self.setup.scene.rts.front_ends[self.active]
        yaw = getattr(f, "yaw_offset_rad", None) or 0.0
        return np.array([f.radial_offset_m, f.tangential_offset_m, f.height_offset_m, yaw, 0.0,
                         f.gain_offset_db * np.log(10) / 20, f.phase_offset_rad])

    def echoes(self, theta) -> Echoes:
        """One direct echo per parameter vector ``theta`` (B, 7)."""
        th = np.atleast_2d(np.asarray(theta, float))
        scene, rut, fe = self.setup.scene, self.setup.rut, self.setup.fe
        q = slice(self.active, self.active + 1)
        ro = fe.rx_offset_m[q] if fe.rx_offset_m is not None else layout_offsets(fe.separation_m[q])[0]
        to = fe.tx_offset_m[q] if fe.tx_offset_m is not None else layout_offsets(fe.separation_m[q])[1]
        pitch = None if fe.pitch_rad is None else fe.pitch_rad[q]
        rx, tx, _ = antenna_positions(fe.arc_centre, fe.arc_radius_m, fe.angle_rad[q],
                                      fe.separation_m[q], th[:, None, 0:3], rx_offset_m=ro,
                                      tx_offset_m=to, yaw_rad=th[:, 3:4], pitch_rad=pitch)
        t_a, t_b = leg_delays(rut.tx_world, rut.rx_world, rx, tx)  # (B, 1, Ntx), (B, 1, Nrx)
        t_a, t_b = t_a[:, 0, rut.virtual_tx], t_b[:, 0, rut.virtual_rx]  # (B, V)
        lam = rut.wavelength_m
        g = (lam / (4 * np.pi * c * t_a)) * (lam / (4 * np.pi * c * t_b))
        gain = np.exp(th[:, 5] + 1j * th[:, 6]) * self.amplitude
        rts = scene.rts
        tau0 = realised_delay(requested_delay(scene, self.range_m), rts.f_s_hz,
                              rts.fractional_delay, rts.fractional_delay_step_s)
        tau_if = tau0 + th[:, 4]
        tau_air = t_a + t_b
        b = th.shape[0]
        fir = fir_if_gain(scene, tau_if, tau_if + tau_air.mean(axis=1))
        f_d = 2 * scene.radar.f_c_hz * self.velocity_mps / c
        return Echoes(tau_air_s=tau_air, tau_if_s=tau_if, f_if_hz=np.full(b, rts.f_rts_hz),
                      doppler_hz=np.full(b, f_d), amplitude=np.conj(g * gain[:, None]),
                      target=np.zeros(b, int), front_end=np.full(b, self.active),
                      kind=np.full(b, KIND_DIRECT), order=np.zeros(b, int), fast_gain=fir)

    def response(self, theta) -> np.ndarray:
        """Spectrum at the probe's bin per virtual element, (B, V) complex128."""
        ech = self.echoes(theta)
        return bin_response(ech, self.setup.scene.radar, self.setup.rut, [self.range_bin],
                            [self.doppler_bin])[0]

    def jacobian(self, theta, free) -> tuple[np.ndarray, np.ndarray]:
        """Response (V,) at ``theta`` and its derivatives (V, P) along the ``free`` parameters
        (central differences, all columns in one batched call)."""
        th = np.asarray(theta, float)
        free = list(free)
        h = _STEP[free]
        batch = np.repeat(th[None], 2 * len(free) + 1, axis=0)
        k = np.arange(len(free))
        batch[1 + k, free] += h
        batch[1 + len(free) + k, free] -= h
        y = self.response(batch)
        return y[0], ((y[1:1 + len(free)] - y[1 + len(free):]) / (2 * h[:, None])).T

    def noise_variance(self, theta, snr_db: float) -> float:
        """Noise variance of one complex spectrum value at the bin for the scene's per-sample
        SNR ``snr_db`` of this echo (``radar.frame.noise_power``) after both windowed DFTs."""
        radar = self.setup.scene.radar
        p = noise_power(self.echoes(theta), snr_db)
        return float(p * np.sum(window(radar.range_window, radar.samples_per_chirp) ** 2)
                     * np.sum(window(radar.doppler_window, radar.chirps_per_tx) ** 2))


def measure(setup: Setup, cap: Capture) -> tuple[np.ndarray, float, ProbeModel]:
    """The RuT's processing of a capture: the range-Doppler spectrum (``radar.processing``) at
    the probe's bin per virtual element (V,), the noise variance of one spectrum value (median
    of |X|^2 over the whole map / ln 2: the median of an exponential, untouched by the few
    target cells), and the probe's model at that bin (the strongest of the three range bins
    around the set range)."""
    from .radar.fmcw import AdcCube
    radar = setup.scene.radar
    want = (radar.chirps_per_tx, setup.rut.num_virtual, radar.samples_per_chirp)
    if cap.data.shape != want:
        raise ValueError(f"capture of front end {cap.active}: shape {list(cap.data.shape)} does "
                         f"not match the scene's radar {list(want)} [loop, virtual, sample]")
    if not 0 <= cap.active < setup.fe.count:
        raise ValueError(f"capture: active front end {cap.active} not in the scene "
                         f"(0..{setup.fe.count - 1})")
    rd = range_doppler(AdcCube(cap.data.astype(np.complex64), radar, setup.rut))
    model = ProbeModel.of(setup, cap)
    rbs = (model.range_bin + np.arange(-1, 2)) % radar.samples_per_chirp
    best = int(rbs[np.argmax(rd.power[rbs, model.doppler_bin])])
    model = ProbeModel.of(setup, cap, best)
    x = rd.spectrum
    sigma2 = float(np.median(x.real.astype(float) ** 2 + x.imag.astype(float) ** 2) / np.log(2))
    return rd.spectrum[best, model.doppler_bin].astype(complex), sigma2, model


# ------------------------------------------------------------------------------------------
# Identifiability and the fit
# ------------------------------------------------------------------------------------------


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


@dataclass(frozen=True)
class Identification:
    """Every front end's fit; :meth:`to_dict` is ``rtsgeom identify --json``."""

    scene: Scene
    fits: tuple[FrontEndFit, ...]

    def fit(self, q: int) -> FrontEndFit | None:
        return next((f for f in self.fits if f.index == q), None)

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
                "residual_rms_unit": "measured noise std of one range-Doppler value"}


def identify(scene: Scene, captures) -> Identification:
    """Fit the nominal ``scene``'s free parameters to probe ``captures`` (:class:`Capture`,
    any number per front end; the captures of one front end are fitted jointly)."""
    setup = build_setup(scene)
    groups: dict[int, list] = {}
    for cap in captures:
        groups.setdefault(cap.active, []).append(measure(setup, cap))
    return Identification(scene, tuple(fit_front_end(groups[q]) for q in sorted(groups)))


# ------------------------------------------------------------------------------------------
# The setup as built: corrected scene, calibration without a sweep
# ------------------------------------------------------------------------------------------


def _has_field(name: str) -> bool:
    return name in {f.name for f in fields(FrontEndConfig)}


def identified_scene(ident: Identification) -> Scene:
    """The scene with its mounting fields (and channel gain/phase errors) set to the
    estimates; parameters not identified keep the scene's values. Yaw only where the schema
    has a per-front-end ``yaw_offset_rad``."""
    scene = ident.scene
    fes = list(scene.rts.front_ends)
    for f in ident.fits:
        e, ok = f.estimate, [r is None for r in f.reasons]
        kw = {}
        for i, name in ((0, "radial_offset_m"), (1, "tangential_offset_m"),
                        (2, "height_offset_m")):
            if ok[i]:
                kw[name] = float(e[i])
        if ok[3] and _has_field("yaw_offset_rad"):
            kw["yaw_offset_rad"] = float(e[3])
        kw["gain_offset_db"] = float(e[5] * 20 / np.log(10))
        kw["phase_offset_rad"] = float(np.angle(np.exp(1j * e[6])))
        fes[f.index] = fes[f.index].evolve(**kw)
    return scene.evolve(rts=scene.rts.evolve(front_ends=tuple(fes)))


def identified_scene_toml(scene_text: str, ident: Identification) -> str:
    """The scene file ``scene_text`` with each identified front end's fields replaced (the
    comments and everything else kept; tomlkit edits TOML in place, a hand-written writer would
    lose the file's comments)."""
    import tomlkit
    doc = tomlkit.parse(scene_text)
    new = identified_scene(ident)
    keys = [("radial_offset_m", "radial_offset_mm", 1e3),
            ("tangential_offset_m", "tangential_offset_mm", 1e3),
            ("height_offset_m", "height_offset_mm", 1e3),
            ("gain_offset_db", "gain_offset_db", 1.0),
            ("phase_offset_rad", "phase_offset_deg", 180 / np.pi)]
    if _has_field("yaw_offset_rad"):
        keys.append(("yaw_offset_rad", "yaw_offset_deg", 180 / np.pi))
    tables = doc["rts"]["front_ends"]
    owner = {"radial_offset_m": 0, "tangential_offset_m": 1, "height_offset_m": 2,
             "yaw_offset_rad": 3, "gain_offset_db": 5, "phase_offset_rad": 6}
    for f in ident.fits:
        cfg = new.rts.front_ends[f.index]
        for attr, key, unit in keys:
            if f.reasons[owner[attr]] is None:  # not identified: the scene's value stays
                tables[f.index][key] = round(float(getattr(cfg, attr)) * unit, 6)
    doc["name"] = f"{new.name}-identified"
    return tomlkit.dumps(doc)


def setup_of(scene: Scene, yaw_rad=None) -> Setup:
    """``build_setup`` with per-front-end yaws ``yaw_rad`` (F,) where the scene has none."""
    setup = build_setup(scene)
    if yaw_rad is None:
        return setup
    from .geometry.arc import front_ends
    return Setup(scene, setup.rut, front_ends(scene, setup.fe.arc_centre, yaw_rad=yaw_rad))


def detected_angles(setup: Setup, paths=None) -> np.ndarray:
    """Each front end alone as the RuT's beamformer sees it (noise-free phasor model at the
    calibration's probe range): what ``calibrate``'s amplitude step measures."""
    from .aoa.model import ChannelModel
    from .scene import TargetConfig
    paths = exact_paths(setup) if paths is None else paths
    r, _ = capture_probe(setup)
    return np.array([float(ChannelModel.build(setup, paths, [q], TargetConfig(r))
                           .direction(np.ones(1))) for q in range(setup.fe.count)])


def predicted_calibration(setup: Setup, pair: tuple[int, int], alphas=None) -> dict:
    """The pair's calibration delay predicted from a setup *as identified* (no sweep): the
    coherence point (``aoa.calibration.coherence_delay``) of the identified geometry and channel
    gains at the probes the sweep would use (``alphas``, default from :func:`detected_angles`)."""
    from .aoa.calibration import coherence_delay, probe_angles
    paths = exact_paths(setup)
    i, j = pair
    if alphas is None:
        ang = detected_angles(setup, paths)
        alphas = probe_angles(ang[i], ang[j])
    d = coherence_delay(setup, paths, (i, j), np.asarray(alphas))
    return {"pair": [int(i), int(j)], "delta_tau_s": float(d),
            "probe_angles_deg": [float(a) for a in np.degrees(alphas)], "method": "identified"}


# ------------------------------------------------------------------------------------------
# What a lab can measure: the Cramer-Rao bound versus SNR and arc radius
# ------------------------------------------------------------------------------------------


def crb_grid(scene: Scene, snr_db, radii_m, active: int = 0) -> np.ndarray:
    """Cramer-Rao std of radial, tangential, height offset (m) and yaw (rad), (R, S, 4), for
    one capture of front end ``active`` at each arc radius ``radii_m`` (R,) and per-sample SNR
    ``snr_db`` (S,). Each parameter is estimated together with what a capture always fits
    (tangential and height offsets, the channel's gain and phase); the channel delay is known
    (it is inseparable otherwise). inf where the parameter does not act."""
    snr = np.atleast_1d(np.asarray(snr_db, float))
    out = np.empty((np.size(radii_m), snr.size, 4))
    for k, r in enumerate(np.atleast_1d(radii_m)):
        sc = scene.evolve(rts=scene.rts.evolve(arc_radius_m=float(r)))
        setup = build_setup(sc)
        rng, amp = capture_probe(setup)
        m = ProbeModel.of(setup, Capture(np.zeros((0, 0, 0), complex), active, rng, 0.0, amp))
        th = m.nominal()
        s2 = m.noise_variance(th, 0.0)  # SNR 0 dB; the bound scales with 10^(-SNR / 20)
        std = np.array([cramer_rao([m], th, s2, sorted({1, 2, 5, 6, p}))[p] for p in range(4)])
        out[k] = std[None, :] * 10 ** (-snr[:, None] / 20)
    return out


def crb_figure(scene: Scene, snr_db, radii_m, active: int = 0):
    """Figure: the Cramer-Rao std of each mounting parameter versus SNR, one line per arc
    radius (:func:`crb_grid`), with the +-0.5 mm / 1 deg of a careful build for scale."""
    import matplotlib.pyplot as plt
    std = crb_grid(scene, snr_db, radii_m, active)
    fig, axes = plt.subplots(1, 4, figsize=(13, 3.6), sharex=True)
    names = ("radial offset (mm)", "tangential offset (mm)", "height offset (mm)", "yaw (deg)")
    units = (1e3, 1e3, 1e3, 180 / np.pi)
    ref = (0.5, 0.5, 0.5, 1.0)
    for p, ax in enumerate(axes):
        for k, r in enumerate(np.atleast_1d(radii_m)):
            y = std[k, :, p] * units[p]
            ax.semilogy(snr_db, np.where(np.isfinite(y), y, np.nan), label=f"R_c = {r:g} m")
        ax.axhline(ref[p], color="0.5", ls="--", lw=0.8)
        ax.set_title(names[p], fontsize=9)
        ax.set_xlabel("per-sample SNR (dB)")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("Cramer-Rao std (one capture)")
    axes[0].legend(fontsize=7)
    el = "with" if scene.radar.use_elevation_tx else "without"
    fig.suptitle(f"{scene.name}: what one probe capture of front end {active} measures "
                 f"({el} elevation Tx; dashed: a careful build's tolerance)", fontsize=10)
    fig.tight_layout()
    return fig


def calibrate_from_identified(scene: Scene, pair: tuple[int, int]) -> dict:
    """``rtsgeom calibrate --from-identified FILE``: the pair's calibration delay of a scene
    written by ``rtsgeom identify --out`` (its mounting fields and channel gain/phase errors
    hold the estimates), predicted without a sweep (:func:`predicted_calibration`)."""
    return predicted_calibration(setup_of(scene), tuple(pair))
