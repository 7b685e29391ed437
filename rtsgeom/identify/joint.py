"""The radar's own channels identified together with the front ends: each Tx and Rx antenna's
gain and phase error and every front end's mounting errors and channel gain, from the same
probe captures (``rtsgeom identify --radar-channels``).

A capture of front end q is, per virtual element ``v = (Tx t, Rx r)``, the probe's response on
an ideal radar (:class:`~rtsgeom.identify.model.ProbeModel`, the Rx coupling of the scene
kept) times the radar's chains (``radar.channels``)::

    y_v = g_tx[t] g_rx[r] h_q,v(theta_q),    g = exp(ln|g| + j arg g)

The unknowns are every captured front end's :data:`~rtsgeom.identify.model.PARAMS` and each
antenna's ``ln|g|`` and ``arg g``. Three combinations change no capture, whatever is captured
(:data:`GAUGES`); each is fixed by a convention and reported as such:

* a factor moved from every Rx to every Tx (only the products ``g_tx g_rx`` act): the
  reference Tx keeps the scene's gain and phase;
* a factor common to every virtual channel, which moves every front end's channel gain alike:
  the reference Rx keeps the scene's;
* a phase ramp across the array turns every direction like all front ends moved together (a
  yaw of the radar against the arc); the reference front end keeps the scene's tangential
  offset (and, with elevation elements, its height): the others are read turned with it.

What is left is separable where the captures see it (:func:`~rtsgeom.identify.fit.free_parameters`
on the joint Fisher information, as for one front end): the per-antenna pattern that no front
end's smooth mounting errors (a ramp and a curvature) can mimic. The fit is the whitened
least squares of :func:`~rtsgeom.identify.fit.solve_whitened` from an alternating least
squares on the complex factors (:func:`_start`); its covariance is the inverse Fisher
information, at the truth the Cramer-Rao bound (:func:`joint_cramer_rao`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from .._lib.util import frozen
from ..errors import CaptureError, ParameterError, SceneError
from ..geometry import Setup
from ..geometry.setup import build_setup
from ..radar.channels import antenna_gains
from ..scene import Scene
from ..scene.channels import MAX_GAIN_ERROR_DB
from ..scene.schema import check_arg
from .fit import _SCALE, FrontEndFit, check_fit, fisher, free_parameters, solve_whitened
from .model import PARAMS

__all__ = ["GAUGES", "RadarChannelsFit", "JointModel", "identify_joint", "joint_cramer_rao",
           "check_radar_fit"]

_N = len(PARAMS)
_LOG_GAIN, _PHASE = PARAMS.index("log_gain"), PARAMS.index("phase")
_TANG, _HEIGHT = PARAMS.index("tangential_offset"), PARAMS.index("height_offset")

#: the combinations no probe capture changes: (name, what moves, what would pin it down)
GAUGES = (
    ("tx_rx_factor", "a gain and phase moved from every Rx antenna to every Tx antenna "
     "(only the products g_tx g_rx act on a virtual element)",
     "nothing: a convention; the reference Tx keeps the scene's value"),
    ("common_factor", "a gain and phase common to every virtual channel, which moves every "
     "front end's channel gain and phase alike",
     "nothing: a convention; the reference Rx keeps the scene's value (angles and the "
     "calibration see only differences between front ends)"),
    ("array_ramp", "a phase ramp across the array (in azimuth, and in elevation with "
     "elevation elements), which turns every direction like all front ends moved tangentially "
     "(and in height) together: a yaw of the radar against the arc",
     "a reflector at a surveyed angle (the radar's own boresight measurement) or a surveyed "
     "position of the reference front end; without one the reference front end keeps the "
     "scene's tangential offset (and height) and the others are read turned with it (by "
     "R_c du / cos(theta_q))"),
)


@dataclass(frozen=True)
class RadarChannelsFit:
    """The radar's per-antenna estimates (SI: ln|g| and rad inside; the shown values in dB
    and deg), their standard deviations (NaN where fixed or not identifiable) and why."""

    log_gain: np.ndarray  # (N_tx + N_rx,) the Tx antennas first
    phase: np.ndarray  # (N_tx + N_rx,)
    log_gain_std: np.ndarray
    phase_std: np.ndarray
    reasons: tuple  # ((why ln-gain, why phase) per antenna), None where estimated
    n_tx: int
    reference_tx: int
    reference_rx: int
    reference_front_end: int

    def side(self, which: str):
        """(ln-gain, phase, their stds, reasons) of the ``"tx"`` or ``"rx"`` antennas."""
        s = slice(0, self.n_tx) if which == "tx" else slice(self.n_tx, None)
        return (self.log_gain[s], self.phase[s], self.log_gain_std[s], self.phase_std[s],
                self.reasons[s])

    def to_dict(self) -> dict:
        k_db, k_deg = 20 / np.log(10), 180 / np.pi
        out: dict = {}
        why: dict = {}
        for side in ("tx", "rx"):
            lg, ph, lg_s, ph_s, rs = self.side(side)
            for key, val, std, k, w in ((f"{side}_gain_db", lg, lg_s, k_db, 0),
                                        (f"{side}_phase_deg", ph, ph_s, k_deg, 1)):
                out[key] = [None if r[w] is not None else
                            {"value": float(v * k), "std": float(s * k)}
                            for v, s, r in zip(val, std, rs)]
                for a, r in enumerate(rs):
                    if r[w] is not None:
                        why[f"{key}[{a}]"] = r[w]
        out["not_identifiable"] = why
        out["references"] = {"tx": self.reference_tx, "rx": self.reference_rx,
                             "front_end": self.reference_front_end}
        out["fixed_by_convention"] = [{"name": n, "what": w, "separate_by": s}
                                      for n, w, s in GAUGES]
        return out


@dataclass(frozen=True)
class JointModel:
    """The captures of several front ends with the radar's antenna gains as parameters: the
    parameter vector is every front end's :data:`PARAMS` (in ``fronts`` order) then the
    antennas' ln|g| (Tx, then Rx) and their phases."""

    models: tuple  # ProbeModel per capture, on the ideal-gain setup
    block: np.ndarray  # (C,) index into ``fronts`` of each capture's front end
    fronts: tuple  # the front ends in the parameter vector
    n_tx: int
    n_rx: int
    virtual_tx: np.ndarray  # (V,)
    virtual_rx: np.ndarray  # (V,)

    @property
    def n_ant(self) -> int:
        return self.n_tx + self.n_rx

    @property
    def size(self) -> int:
        return _N * len(self.fronts) + 2 * self.n_ant

    def antenna_index(self, side: str, a: int, what: int) -> int:
        """Index of antenna ``a`` of ``side`` (``"tx"``/``"rx"``), ``what`` = PARAMS index of
        ln-gain or phase, in the parameter vector."""
        k = a + (self.n_tx if side == "rx" else 0)
        return _N * len(self.fronts) + (0 if what == _LOG_GAIN else self.n_ant) + k

    @property
    def reference_tx(self) -> int:
        """The reference Tx: the first that transmits (the reference Rx is Rx 0)."""
        return int(np.min(self.virtual_tx))

    def unseen(self) -> np.ndarray:
        """The antennas no virtual element uses (indices in the Tx-then-Rx order)."""
        return np.r_[np.setdiff1d(np.arange(self.n_tx), self.virtual_tx),
                     self.n_tx + np.setdiff1d(np.arange(self.n_rx), self.virtual_rx)]

    def nominal(self, scene: Scene) -> np.ndarray:
        """The scene's values of every parameter: each front end's (``ProbeModel.nominal``),
        the antennas' ln|g| and phases (``[radar.channels]``, 0 where unset)."""
        ch = scene.radar.channels
        fe = [next(m for m in self.models if m.active == q).nominal() for q in self.fronts]
        g = np.log(np.r_[
            antenna_gains(() if ch is None else ch.tx_gain_db,
                          () if ch is None else ch.tx_phase_rad, self.n_tx),
            antenna_gains(() if ch is None else ch.rx_gain_db,
                          () if ch is None else ch.rx_phase_rad, self.n_rx)])
        return np.r_[np.concatenate(fe), g.real, g.imag]

    def kinds(self) -> np.ndarray:
        """PARAMS index of each parameter (an antenna's ln-gain and phase as a channel's)."""
        return np.r_[np.tile(np.arange(_N), len(self.fronts)),
                     np.full(self.n_ant, _LOG_GAIN), np.full(self.n_ant, _PHASE)]

    def names(self) -> list[str]:
        ant = [f"tx{a}" for a in range(self.n_tx)] + [f"rx{a}" for a in range(self.n_rx)]
        return ([f"front end {q} {p}" for q in self.fronts for p in PARAMS]
                + [f"{a} ln-gain" for a in ant] + [f"{a} phase" for a in ant])

    def virtual_gain(self, theta) -> np.ndarray:
        """The radar's gain per virtual element (V,) for the parameter vector ``theta``."""
        lg = theta[_N * len(self.fronts):][:self.n_ant]
        ph = theta[_N * len(self.fronts) + self.n_ant:]
        e = lg + 1j * ph
        return np.exp(e[self.virtual_tx] + e[self.n_tx + self.virtual_rx])

    def respond(self, theta) -> np.ndarray:
        """The captures' responses (C, V)."""
        g = self.virtual_gain(theta)
        return np.stack([g * m.response(theta[_N * b:_N * b + _N][None])[0]
                         for m, b in zip(self.models, self.block)])

    def jacobian(self, theta, free) -> tuple[np.ndarray, np.ndarray]:
        """Responses (C, V) and their derivatives (C V, len(free)) along ``free``: the front
        ends' columns by :meth:`ProbeModel.jacobian` times the radar's gain, the antennas'
        in closed form (dy/d ln|g| = y, dy/d arg g = j y on the antenna's elements)."""
        free = np.asarray(list(free), int)
        g = self.virtual_gain(theta)
        n_fe = _N * len(self.fronts)
        v = self.virtual_tx.size
        ant = np.zeros((v, self.n_ant))
        ant[np.arange(v), self.virtual_tx] = 1.0
        ant[np.arange(v), self.n_tx + self.virtual_rx] = 1.0
        resp, jac = [], []
        for m, b in zip(self.models, self.block):
            cols = free[(free >= _N * b) & (free < _N * b + _N)] - _N * b
            h, dh = m.jacobian(theta[_N * b:_N * b + _N], cols)
            y = g * h
            full = np.zeros((v, self.size), complex)
            full[:, _N * b + cols] = g[:, None] * dh
            full[:, n_fe:n_fe + self.n_ant] = y[:, None] * ant
            full[:, n_fe + self.n_ant:] = 1j * y[:, None] * ant
            resp.append(y)
            jac.append(full[:, free])
        return np.stack(resp), np.concatenate(jac, 0)


def _ideal_gain_setup(setup: Setup) -> Setup:
    """The setup with the radar's antenna gains at 1 (its Rx coupling kept): the part of the
    response the joint model multiplies by its own antenna gains."""
    ch = setup.scene.radar.channels
    if ch is None:
        return setup
    scene = setup.scene.evolve(radar=setup.scene.radar.evolve(channels=ch.evolve(
        tx_gain_db=(), tx_phase_rad=(), rx_gain_db=(), rx_phase_rad=())))
    return dataclasses.replace(setup, scene=scene)


def _has_elevation(setup: Setup) -> bool:
    """Whether the transmitting virtual array spans heights (then a height ramp acts)."""
    rut = setup.rut
    z = rut.tx_local[rut.virtual_tx, 2] + rut.rx_local[rut.virtual_rx, 2]
    return bool(np.ptp(z) > 0)


def joint_model(setup: Setup, measurements) -> JointModel:
    """The joint model of ``measurements`` ((y, sigma2, ProbeModel) per capture, as
    :func:`~rtsgeom.identify.model.measure` returns them) on ``setup``."""
    ideal = _ideal_gain_setup(setup)
    fronts = tuple(sorted({m.active for _, _, m in measurements}))
    rut = setup.rut
    return JointModel(tuple(dataclasses.replace(m, setup=ideal) for _, _, m in measurements),
                      frozen(np.array([fronts.index(m.active) for _, _, m in measurements])),
                      fronts, rut.tx_local.shape[0], rut.rx_local.shape[0],
                      frozen(np.asarray(rut.virtual_tx)), frozen(np.asarray(rut.virtual_rx)))


def _gauges(model: JointModel, setup: Setup, reference: int) -> dict[int, str]:
    """The parameters fixed by :data:`GAUGES` (and the Tx antennas that never transmit), with
    the reason each output gives."""
    out = {}
    for what, name in ((_LOG_GAIN, "gain"), (_PHASE, "phase")):
        out[model.antenna_index("tx", model.reference_tx, what)] = (
            f"the reference Tx: keeps the scene's {name} ({GAUGES[0][1]})")
        out[model.antenna_index("rx", 0, what)] = (
            f"the reference Rx: keeps the scene's {name} ({GAUGES[1][1]})")
        for a in model.unseen():  # (Tx-then-Rx order: the Tx side's index is the plain one)
            out[model.antenna_index("tx", int(a), what)] = (
                "in no virtual element of this radar's configuration (e.g. the elevated Tx "
                "without radar.use_elevation_tx): no capture sees it; keeps the scene's value")
    b = model.fronts.index(reference)
    ramp = f"the reference front end: keeps the scene's value ({GAUGES[2][1]}; {GAUGES[2][2]})"
    out[_N * b + _TANG] = ramp
    if _has_elevation(setup):
        out[_N * b + _HEIGHT] = ramp
    return out


def _start(model: JointModel, y: np.ndarray, nominal: np.ndarray,
           iterations: int = 200) -> np.ndarray:
    """The fit's start: the front ends' mounting at the scene's values, and the antennas' and
    the captures' complex gains by alternating least squares on ``y_cv = G_c A[t_v] B[r_v]
    h_cv`` (``h``: the nominal response on an ideal radar): each factor in closed form given
    the others, from all ones. Phases of any size (an uncalibrated radar's +-180 deg) need no
    unwrapping, as a logarithm's would; the result is moved to the references' scene values.
    A start from each front end fitted alone would take the radar's phase errors for
    mounting errors (a tangential grid search lands on another lobe under +-20 deg of antenna
    phase)."""
    theta = nominal.copy()
    for k in range(len(model.fronts)):
        theta[_N * k + _LOG_GAIN] = theta[_N * k + _PHASE] = 0.0
    n_fe = _N * len(model.fronts)
    theta[n_fe:] = 0.0
    h = model.respond(theta)  # (C, V) the ideal radar, unit channel gains
    tx, rx = model.virtual_tx, model.virtual_rx
    n_c = y.shape[0]
    g = np.ones(n_c, complex)
    a = np.ones(model.n_tx, complex)
    b = np.ones(model.n_rx, complex)

    def solve(basis, index, n):
        """Per index value, the factor x minimising sum |y - x basis|^2 over its elements."""
        num = np.zeros(n, complex)
        den = np.zeros(n)
        np.add.at(num, index.ravel(), (np.conj(basis) * y).ravel())
        np.add.at(den, index.ravel(), (np.abs(basis) ** 2).ravel())
        out = np.ones(n, complex)
        out[den > 0] = num[den > 0] / den[den > 0]
        return out

    cap = np.repeat(np.arange(n_c)[:, None], tx.size, axis=1)
    for _ in range(iterations):
        g = solve(a[tx] * b[rx] * h, cap, n_c)
        a = solve(g[:, None] * b[rx] * h, np.broadcast_to(tx, y.shape), model.n_tx)
        b = solve(g[:, None] * a[tx] * h, np.broadcast_to(rx, y.shape), model.n_rx)
    # the references keep the scene's values (the captures' gains take the difference); an
    # antenna no capture sees keeps the scene's too
    scene_ant = nominal[n_fe:n_fe + model.n_ant] + 1j * nominal[n_fe + model.n_ant:]
    d_a = np.exp(scene_ant[model.reference_tx]) / a[model.reference_tx]
    d_b = np.exp(scene_ant[model.n_tx]) / b[0]
    a, b, g = a * d_a, b * d_b, g / (d_a * d_b)
    ant = np.log(np.r_[a, b])
    held = np.r_[model.reference_tx, model.n_tx, model.unseen()]
    ant[held] = scene_ant[held]
    theta[n_fe:n_fe + model.n_ant], theta[n_fe + model.n_ant:] = ant.real, ant.imag
    for k in range(len(model.fronts)):
        # y carries conj(G) of the front end's channel: ln|G| = ln|g|, arg G = -arg g
        gk = np.mean(g[model.block == k])
        theta[_N * k + _LOG_GAIN], theta[_N * k + _PHASE] = np.log(abs(gk)), -np.angle(gk)
    return theta


def identify_joint(scene: Scene, measurements, reference: int | None = None,
                   accept_misfit: bool = False):
    """Fit the radar's antenna gains and phases together with every captured front end's
    parameters (see the module). ``measurements``: (y, sigma2, ProbeModel) per capture;
    ``reference``: the front end whose tangential offset (and height) fixes the array ramp
    (default the first captured one). Returns (front-end fits, :class:`RadarChannelsFit`)."""
    setup = build_setup(scene)
    ch = scene.radar.channels
    if ch is not None and ch.compensation != "none":
        raise SceneError(f"radar.channels.compensation = {ch.compensation!r}: must be "
                         "\"none\" to identify the radar's channels (the radar's compensation "
                         "divides its own channel errors out of every capture)")
    model = joint_model(setup, measurements)
    reference = model.fronts[0] if reference is None else int(reference)
    if reference not in model.fronts:
        raise ParameterError(f"reference front end {reference}: must be one of the captured "
                             f"front ends {list(model.fronts)}")
    y = np.stack([m[0] for m in measurements])
    theta = _start(model, y, model.nominal(scene))
    sw = np.sqrt(1 / np.array([m[1] for m in measurements]))[:, None]
    fixed = _gauges(model, setup, reference)
    kinds, names = model.kinds(), model.names()
    cand = [i for i in range(model.size) if i not in fixed]

    def choose(fim):
        free, why = free_parameters(fim, cand, kinds, names)
        return free, {**why, **fixed}

    w = np.repeat(sw[:, 0], model.virtual_tx.size)[:, None]

    def jac_white(th, free):
        resp, jac = model.jacobian(th, free)
        return resp, jac * w

    theta, free, why, cov, resp = solve_whitened(y, sw, model.respond, jac_white, theta,
                                                 _SCALE[kinds], choose)
    std = np.full(model.size, np.nan)
    std[free] = np.sqrt(np.diag(cov))
    corr = np.full((model.size, model.size), np.nan)
    corr[np.ix_(free, free)] = cov / np.outer(std[free], std[free])
    res = np.abs((y - resp) * sw) ** 2
    fits = []
    for k, q in enumerate(model.fronts):
        s = slice(_N * k, _N * k + _N)
        mine = model.block == k
        est = theta[s].copy()
        est[_PHASE] = float(np.angle(np.exp(1j * est[_PHASE])))
        fits.append(check_fit(FrontEndFit(
            q, est, std[s], tuple(why.get(_N * k + i) for i in range(_N)), corr[s, s],
            float(np.sqrt(np.mean(res[mine]))), float(np.sqrt(np.mean(1 / sw[mine, 0] ** 2))),
            int(np.sum(mine))), accept_misfit))
    n_fe = _N * len(model.fronts)
    a = slice(n_fe, n_fe + model.n_ant)
    p = slice(n_fe + model.n_ant, None)
    radar = check_radar_fit(RadarChannelsFit(
        frozen(theta[a]), frozen(np.angle(np.exp(1j * theta[p]))), frozen(std[a]),
        frozen(std[p]),
        tuple((why.get(n_fe + i), why.get(n_fe + model.n_ant + i)) for i in range(model.n_ant)),
        model.n_tx, model.reference_tx, 0, reference))
    return tuple(fits), radar


def check_radar_fit(r: RadarChannelsFit) -> RadarChannelsFit:
    """Refuse antenna gain estimates beyond the scene's ``[radar.channels]`` limit
    (``MAX_GAIN_ERROR_DB``: a chain that far off is broken, or the captures are not this
    radar's): ``CaptureError`` naming the antenna, so that ``identified.toml`` always loads."""
    for side in ("tx", "rx"):
        lg, _, _, _, reasons = r.side(side)
        for a, (x, why) in enumerate(zip(lg, reasons)):
            if why[0] is None:
                check_arg(float(x * 20 / np.log(10)), f"{side}_gain_db[{a}]", "float",
                          "radar channels: estimated", CaptureError, lo=-MAX_GAIN_ERROR_DB,
                          hi=MAX_GAIN_ERROR_DB, unit="dB")
    return r


def joint_cramer_rao(model: JointModel, theta, sigma2, free) -> np.ndarray:
    """Cramer-Rao bound (std, (size,), NaN where not free) of the ``free`` parameters at the
    true ``theta`` for noise variances ``sigma2`` (C,) per spectrum value:
    ``sqrt(diag(F^-1))``, ``F = sum_c 2 Re(J_c^H J_c) / sigma2_c``."""
    free = list(free)
    _, jac = model.jacobian(np.asarray(theta, float), free)
    v = model.virtual_tx.size
    w = np.repeat(1 / np.sqrt(np.broadcast_to(np.asarray(sigma2, float), (len(model.models),))),
                  v)
    std = np.full(model.size, np.nan)
    std[free] = np.sqrt(np.diag(np.linalg.inv(fisher(jac * w[:, None]))))
    return std
