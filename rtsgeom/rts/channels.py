"""RTS channel model: delay, Doppler, attenuation and cable ghosts per channel (stage 3).

A channel q (one front end) receives the RuT's chirp, down-converts it to the IF ``f_rts``,
delays it by ``tau_rts`` (eq. 1), shifts it by ``f_D,rts`` (eq. 2), scales it (eq. 3) and
re-transmits it. The beat phase the RuT sees is (eq. 8)::

    phi_b(t) = 2 pi [ f_c tau_c + f_rts tau_rts + S (tau t - tau^2 / 2) ],   tau = tau_c + tau_rts

so the over-the-air delay ``tau_c`` acts at RF and the RTS delay at the IF: that difference is
what the phase calibration exploits (eq. 27) and what costs the range offset ("Disadvantages").

The output is an :class:`Echoes` table: per echo and per virtual channel the over-the-air delay
(from the paths table, per element pair), the IF delay, the IF it acts at, the Doppler shift and
the complex amplitude. The FMCW model turns it into an ADC cube.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace
from enum import IntEnum
from functools import lru_cache

import numpy as np
from scipy.constants import c

from .._lib.util import frozen
from ..geometry import Setup
from ..paths.table import FE_TO_RX, RUT_TO_RUT, TX_TO_FE, Paths
from ..scene import Scene
from .fir import fir_if_gain, realised_delay

__all__ = ["RtsProgram", "EchoKind", "Echoes", "target_amplitude", "requested_delay",
           "channel_echoes", "setup_echoes", "cable_ghosts", "program_nearest",
           "nearest_front_ends", "NEAREST_TIE_RAD", "build_echoes", "nominal_link_gain",
           "apparent_range"]


class EchoKind(IntEnum):
    """What an echo is (``Echoes.kind``; an ``int`` subclass, so ``echoes.kind == EchoKind.GHOST``
    compares the stored integers).

    Attributes
    ----------
    DIRECT, GHOST, SETUP
        A target's echo through its channel, a cable ghost of one, the RuT's own chirp
        reflected by the setup; ``Echoes.kind`` holds one per echo.
    """

    DIRECT = 0  # a target's echo through its RTS channel
    GHOST = 1  # a cable ghost of a direct echo (``cable_ghosts``)
    SETUP = 2  # the RuT's own chirp reflected by the setup (``setup_echoes``)


#: the earlier names of the echo kinds (aliases of the members)
KIND_DIRECT, KIND_GHOST, KIND_SETUP = EchoKind.DIRECT, EchoKind.GHOST, EchoKind.SETUP


@dataclass(frozen=True)
class RtsProgram:
    """What the RTS back end is told to generate: one row per (target, channel).

    ``delay_s`` is the requested RTS delay tau_rts (before the buffer/FIR quantisation),
    ``doppler_hz`` the Doppler shift f_D,rts = 2 f_c v / c0 of eq. (2) *as the RuT's beat
    signal sees it* (positive for a receding target; the hardware mixer lowers the re-emitted
    frequency by it, i.e. multiplies by exp(-j 2 pi f_D t)), with f_c the chirp's start
    frequency ``radar.f_c_hz``: the same frequency the processing converts back with, so the
    reported velocity is the programmed one (a real target's phase follows the carrier at the
    ADC window's middle instead; README "Velocity and the carrier frequency"), ``amplitude`` the complex channel
    gain the RTS applies (attenuation and AoA weight). Hardware offsets of the scene are *not* in here: they
    belong to the channel, not to what the RTS is told.

    Attributes
    ----------
    target, front_end : (K,) int
        Which target each channel entry synthesizes, on which front end.
    delay_s : (K,) float
        The programmed delay.
    doppler_hz : (K,) float
    amplitude : (K,) complex
        The channel's weight (the AoA synthesis).
    """

    target: np.ndarray  # (K,) int
    front_end: np.ndarray  # (K,) int
    delay_s: np.ndarray  # (K,)
    doppler_hz: np.ndarray  # (K,)
    amplitude: np.ndarray  # (K,) complex

    @classmethod
    def build(cls, target, front_end, delay_s, doppler_hz, amplitude) -> "RtsProgram":
        return cls(frozen(np.atleast_1d(np.asarray(target, int))),
                   frozen(np.atleast_1d(np.asarray(front_end, int))),
                   frozen(np.atleast_1d(np.asarray(delay_s, float))),
                   frozen(np.atleast_1d(np.asarray(doppler_hz, float))),
                   frozen(np.atleast_1d(np.asarray(amplitude, complex))))

    def __len__(self) -> int:
        return int(self.target.size)


#: the shape of each ``Echoes`` field in echoes E, virtual channels V and fast-time samples N
_ECHO_SHAPES = {"tau_air_s": "EV", "tau_if_s": "E", "f_if_hz": "E", "doppler_hz": "E",
                "amplitude": "EV", "target": "E", "front_end": "E", "kind": "E", "order": "E",
                "fast_gain": "EN"}
_ECHO_INTS = ("target", "front_end", "kind", "order")


@dataclass(frozen=True)
class Echoes:
    """Everything the RuT receives, as separable echoes (E echoes x V virtual channels).

    Construct it with every field (positional or keyword) or with :meth:`build` (keywords,
    per-echo fields broadcast from scalars). The shapes are checked on construction (a
    ``ValueError`` names the field and the shape it must have) and the arrays stored read-only.

    Attributes
    ----------
    tau_air_s, tau_if_s : (E,) float
        Air and IF delays of each echo.
    f_if_hz, doppler_hz : (E,) float
    amplitude : (E,) complex
    target, front_end : (E,) int
    kind : (E,) EchoKind
        Direct echo, cable ghost or setup echo.
    """

    tau_air_s: np.ndarray  # (E, V) over-the-air delay, acts at RF (f_c tau_c of eq. 8)
    tau_if_s: np.ndarray  # (E,) delay applied inside the RTS, acts at f_if
    f_if_hz: np.ndarray  # (E,) frequency at which tau_if acts on the phase (f_rts, eq. 7)
    doppler_hz: np.ndarray  # (E,) frequency shift (f_D,rts, eq. 2)
    amplitude: np.ndarray  # (E, V) complex amplitude at the RuT's receiver
    target: np.ndarray  # (E,) target index, -1 for setup reflections
    front_end: np.ndarray  # (E,) channel, -1 for setup reflections
    kind: np.ndarray  # (E,) int, an EchoKind
    order: np.ndarray  # (E,) ghost order (0 for the direct echo)
    # (E, N) complex gain per fast-time sample (the fractional-delay FIR's response along the
    # IF sweep, rts.fir_if_gain); None: 1 everywhere (an ideal delay)
    fast_gain: np.ndarray | None = None

    def __post_init__(self):
        tau = np.asarray(self.tau_air_s)
        if tau.ndim != 2:
            raise ValueError(f"Echoes.tau_air_s: shape {tau.shape} must be (E, V) (echoes, "
                             "virtual channels)")
        dims = {"E": tau.shape[0], "V": tau.shape[1]}
        if np.ndim(self.fast_gain) == 2:
            dims["N"] = np.shape(self.fast_gain)[1]
        for f in fields(self):
            v = getattr(self, f.name)
            if v is None and f.name == "fast_gain":
                continue
            a = np.asarray(v)
            want = tuple(dims.get(d, d) for d in _ECHO_SHAPES[f.name])
            kind = np.integer if f.name in _ECHO_INTS else np.number
            if a.shape != want or not np.issubdtype(a.dtype, kind):
                names = ", ".join(_ECHO_SHAPES[f.name]) + ("," if len(want) == 1 else "")
                size = ", ".join(map(str, want)) + ("," if len(want) == 1 else "")
                what = "integers" if f.name in _ECHO_INTS else "numbers"
                raise ValueError(f"Echoes.{f.name}: got shape {a.shape} of {a.dtype}, must be "
                                 f"({names}) = ({size}) {what} (E echoes and V virtual "
                                 "channels as in tau_air_s, N fast-time samples)")
            if a.flags.writeable:
                a = frozen(a)
            object.__setattr__(self, f.name, a)

    @classmethod
    def build(cls, *, tau_air_s, amplitude, tau_if_s=0.0, f_if_hz=0.0, doppler_hz=0.0,
              target=-1, front_end=-1, kind=EchoKind.DIRECT, order=0,
              fast_gain=None) -> "Echoes":
        """Echoes from keyword arguments: ``tau_air_s`` and ``amplitude`` (E, V); the per-echo
        fields (E,) or a scalar for every echo (defaults: no IF delay, no Doppler, a direct
        echo of no target or channel)."""
        e = np.shape(tau_air_s)[0] if np.ndim(tau_air_s) else 0

        def per_echo(v):
            a = np.asarray(v)
            return np.full(e, a) if a.ndim == 0 else a

        return cls(tau_air_s=tau_air_s, tau_if_s=per_echo(tau_if_s), f_if_hz=per_echo(f_if_hz),
                   doppler_hz=per_echo(doppler_hz), amplitude=amplitude,
                   target=per_echo(target), front_end=per_echo(front_end), kind=per_echo(kind),
                   order=per_echo(order), fast_gain=fast_gain)

    @property
    def tau_s(self) -> np.ndarray:
        """Total delay tau = tau_c + tau_rts per echo and virtual channel."""
        return self.tau_air_s + self.tau_if_s[:, None]

    def __len__(self) -> int:
        return int(self.tau_if_s.size)

    @classmethod
    def concat(cls, parts: list["Echoes"]) -> "Echoes":
        names = ("tau_air_s", "tau_if_s", "f_if_hz", "doppler_hz", "amplitude", "target",
                 "front_end", "kind", "order")
        out = {n: frozen(np.concatenate([getattr(p, n) for p in parts])) for n in names}
        gains = [p.fast_gain for p in parts if p.fast_gain is not None and len(p)]
        if gains:
            n_s = gains[0].shape[1]
            out["fast_gain"] = frozen(np.concatenate(
                [p.fast_gain if p.fast_gain is not None else np.ones((len(p), n_s), complex)
                 for p in parts]))
        return cls(**out)

    def select(self, mask) -> "Echoes":
        """The echoes where ``mask`` (E,) is True (this table itself where it is True
        everywhere: its fields are read-only, a copy of every field would buy nothing)."""
        m = np.asarray(mask, bool)
        if m.shape == (len(self),) and m.all():
            return self
        return Echoes(**{n: (None if getattr(self, n) is None else frozen(getattr(self, n)[m]))
                         for n in self.__dataclass_fields__})

    def scaled(self, gain) -> "Echoes":
        """The same echoes with the amplitudes multiplied by ``gain`` (scalar or (E,))."""
        g = np.asarray(gain)
        return replace(self, amplitude=frozen(self.amplitude * (g[:, None] if g.ndim == 1 else g)))


# ------------------------------------------------------------------------------------------
# Back-end quantities
# ------------------------------------------------------------------------------------------


def target_amplitude(range_m, rcs_m2, wavelength_m: float) -> np.ndarray:
    """Echo amplitude of a point target, sqrt of the radar equation with isotropic antennas:
    ``sqrt(sigma) lambda / ((4 pi)^(3/2) R^2)`` (eq. 3 up to the constant)."""
    return np.sqrt(rcs_m2) * wavelength_m / ((4 * np.pi) ** 1.5 * np.asarray(range_m) ** 2)


def requested_delay(scene: Scene, range_m) -> np.ndarray:
    """tau_rts = 2 R_t / c0 (eq. 1), minus the nominal over-the-air delay 2 R_c / c0 when the
    RTS compensates it (so the RuT sees the target at its set range)."""
    tau = 2.0 * np.asarray(range_m, float) / c
    if scene.rts.compensate_air_path:
        tau = tau - 2.0 * scene.rts.arc_radius_m / c
    return tau


#: front ends whose angular distances to a target differ by less than this are equally near
#: (rad, about 6e-8 deg: far above the rounding of a set angle, 1e-16 rad, far below any
#: spacing); of them the lowest index carries the target
NEAREST_TIE_RAD = 1e-9


def nearest_front_ends(fe_azimuth_rad, angle_rad) -> np.ndarray:
    """Index of the front end nearest each set angle ``angle_rad`` (T,) among
    ``fe_azimuth_rad`` (F,), deterministic at a tie: distances within
    :data:`NEAREST_TIE_RAD` of the smallest count as equal and the lowest index wins, so a
    target midway between two front ends stays on one of them whatever its angle's rounding
    (``argmin`` alternated between them frame by frame: 8-deg jumps at no change of the
    target), and a drive hands over only where another front end is nearer by more."""
    d = np.abs(np.asarray(fe_azimuth_rad, float)[None, :]
               - np.atleast_1d(np.asarray(angle_rad, float))[:, None])  # (T, F)
    return np.argmax(d <= d.min(axis=1, keepdims=True) + NEAREST_TIE_RAD, axis=1)


def apparent_range(scene: Scene, range_m) -> np.ndarray:
    """Where the RuT sees a target of set range ``range_m`` (m): the set range when the RTS
    compensates the nominal air path, else the air path's R_c further (``requested_delay``
    then delays by 2 R_t / c0 on top of it)."""
    r = np.asarray(range_m, float)
    return r if scene.rts.compensate_air_path else r + scene.rts.arc_radius_m


def program_nearest(scene: Scene, setup: Setup) -> RtsProgram:
    """Each target on the single front end nearest its set angle (no AoA synthesis; a tie
    to the lower index, :func:`nearest_front_ends`)."""
    if not scene.targets:
        return RtsProgram.build([], [], [], [], [])
    az = setup.fe_azimuth_rad()
    tg = scene.targets
    fe = nearest_front_ends(az, [t.angle_rad for t in tg])
    rng = np.array([t.range_m for t in tg])
    rcs = np.array([t.rcs_m2 for t in tg])
    vel = np.array([t.velocity_mps for t in tg])
    lam = setup.rut.wavelength_m
    amp = target_amplitude(rng, rcs, lam) / nominal_link_gain(scene, lam)
    return RtsProgram.build(np.arange(len(tg)), fe, requested_delay(scene, rng),
                            2.0 * scene.radar.f_c_hz * vel / c, amp)


def nominal_link_gain(scene: Scene, wavelength_m: float) -> float:
    """Free-space gain RuT -> front end -> RuT at the nominal arc radius, which the RTS
    divides out so the echo has the target's radar-equation amplitude."""
    g = wavelength_m / (4 * np.pi * scene.rts.arc_radius_m)
    return g * g


# ------------------------------------------------------------------------------------------
# From paths + program to echoes
# ------------------------------------------------------------------------------------------


#: the last few path tables' legs (:func:`_leg_tables`): (paths, n_fe, n_tx, n_rx, tables)
_LEGS: list = []
_LEGS_KEPT = 4


def _leg_tables(paths: Paths, n_fe: int, n_tx: int, n_rx: int):
    """Both legs' padded tables (:func:`_leg_table`) of ``paths``, made once per table object
    (the last few kept): each channel-model build of a calibration read them again, a pass
    over every front end's paths per call (its cost grew with the arc's front ends)."""
    for p, *key, tables in _LEGS:
        if p is paths and key == [n_fe, n_tx, n_rx]:
            return tables
    tables = (_leg_table(paths, TX_TO_FE, n_fe, n_tx), _leg_table(paths, FE_TO_RX, n_fe, n_rx))
    _LEGS.insert(0, (paths, n_fe, n_tx, n_rx, tables))
    del _LEGS[_LEGS_KEPT:]
    return tables


def _leg_table(paths: Paths, direction: int, n_fe: int, n_el: int):
    """Rows of one direction as padded arrays (F, n_el, P): delay and gain (0 where absent)."""
    sel = paths.direction == direction
    fe = paths.front_end[sel]
    el = (paths.rut_tx if direction == TX_TO_FE else paths.rut_rx)[sel]
    delay, gain = paths.delay_s[sel], paths.gain[sel]
    key = fe * n_el + el
    order = np.argsort(key, kind="stable")
    key, delay, gain = key[order], delay[order], gain[order]
    counts = np.bincount(key, minlength=n_fe * n_el)
    p = max(int(counts.max(initial=0)), 1)
    slot = np.arange(key.size) - np.repeat(np.cumsum(counts) - counts, counts)
    d = np.zeros((n_fe * n_el, p))
    g = np.zeros((n_fe * n_el, p), complex)
    d[key, slot] = delay
    g[key, slot] = gain
    return d.reshape(n_fe, n_el, p), g.reshape(n_fe, n_el, p)


def channel_echoes(setup: Setup, paths: Paths, program: RtsProgram) -> Echoes:
    """Echoes of programmed RTS channels through every path combination of both legs.

    For channel (target, q) and virtual element v = (Tx m, Rx k) each pair of a path
    RuT Tx m -> FE q Rx and a path FE q Tx -> RuT Rx k is one echo with
    ``tau_c = tau_a + tau_b`` and beat amplitude ``conj(g_a g_b G_q)`` (G_q: programmed gain
    times the channel's hardware gain/phase error; conjugated because the beat signal is
    tx * conj(rx)). A leg without any path (blocked) contributes nothing.
    """
    scene, rut = setup.scene, setup.rut
    n_fe = setup.fe.count
    k = len(program)
    v = rut.num_virtual
    if k == 0:
        return _empty(v)
    (d_a, g_a), (d_b, g_b) = _leg_tables(paths, n_fe, rut.tx_world.shape[0],
                                         rut.rx_world.shape[0])
    q = program.front_end
    # (K, V, Pa) and (K, V, Pb) -> (K, Pa, Pb, V)
    da, ga = d_a[q][:, rut.virtual_tx], g_a[q][:, rut.virtual_tx]
    db, gb = d_b[q][:, rut.virtual_rx], g_b[q][:, rut.virtual_rx]
    tau_air = da[:, :, :, None] + db[:, :, None, :]  # (K, V, Pa, Pb)
    gain = ga[:, :, :, None] * gb[:, :, None, :]
    pa, pb = tau_air.shape[2], tau_air.shape[3]
    tau_air = tau_air.transpose(0, 2, 3, 1).reshape(k * pa * pb, v)
    gain = gain.transpose(0, 2, 3, 1).reshape(k * pa * pb, v)

    fes = scene.rts.front_ends
    used = np.unique(q)  # the programmed front ends' hardware gains (not every one's)
    hw = np.zeros(n_fe, complex)
    hw[used] = [10 ** (fes[u].gain_offset_db / 20) * np.exp(1j * fes[u].phase_offset_rad)
                for u in used]
    tau_rts = realised_delay(program.delay_s, scene.rts.f_s_hz, scene.rts.fractional_delay,
                             scene.rts.fractional_delay_step_s)
    rep = pa * pb
    # the beat signal is tx * conj(rx) (eq. 8): it carries the conjugate of the received
    # complex gain (paths, RTS gain, hardware phase)
    amp = np.conj(gain * np.repeat(program.amplitude * hw[q], rep)[:, None])
    tau_if = np.repeat(tau_rts, rep)
    fir = fir_if_gain(scene, tau_if, tau_if + tau_air.mean(axis=1))
    direct = Echoes(
        tau_air_s=frozen(tau_air), tau_if_s=frozen(tau_if),
        f_if_hz=frozen(np.full(k * rep, scene.rts.f_rts_hz)),
        doppler_hz=frozen(np.repeat(program.doppler_hz, rep)), amplitude=frozen(amp),
        target=frozen(np.repeat(program.target, rep)), front_end=frozen(np.repeat(q, rep)),
        kind=frozen(np.full(k * rep, KIND_DIRECT)), order=frozen(np.zeros(k * rep, int)),
        fast_gain=None if fir is None else frozen(fir),
    )
    ghosts = cable_ghosts(scene, direct)
    direct = direct.select(np.any(direct.amplitude != 0, axis=1))
    return Echoes.concat([direct, ghosts]) if len(ghosts) else direct


def cable_ghosts(scene: Scene, direct: Echoes, min_level_db: float = -80.0) -> Echoes:
    """Ghost echoes from the mismatched cables between front end and back end.

    A signal reflected at the far end (Gamma_be) and again at the front end (Gamma_fe) runs the
    cable twice more: extra delay ``2 L / (VF c0)`` (a range offset of ``L / VF``) and amplitude
    ``Gamma_fe Gamma_be a^2`` with ``a`` the cable's one-way amplitude loss. Each front end has an
    Rx and a Tx cable of the same kind, so the n-th ghost collects ``n + 1`` bounce combinations.
    The cables carry the IF, so the extra delay acts at ``f_rts``. Ghost orders are added until
    their level drops below ``min_level_db`` relative to the direct echo.
    """
    parts = []
    for q in np.unique(direct.front_end[direct.front_end >= 0]):  # those with echoes, in order
        fe = scene.rts.front_ends[q]
        if fe.return_loss_fe_db is None or fe.return_loss_be_db is None:
            continue
        sel = (direct.front_end == q) & (direct.kind == KIND_DIRECT)
        if not np.any(sel):
            continue
        base = direct.select(sel)
        rho = (10 ** (-fe.return_loss_fe_db / 20) * 10 ** (-fe.return_loss_be_db / 20)
               * 10 ** (-2 * fe.cable_loss_db / 20))
        dt = 2.0 * fe.cable_length_m / (fe.cable_velocity_factor * c)
        n = 1
        while n < 64 and 20 * np.log10((n + 1) * rho ** n) > min_level_db:
            parts.append(replace(base, tau_if_s=frozen(base.tau_if_s + n * dt),
                                 amplitude=frozen(base.amplitude * ((n + 1) * rho ** n)),
                                 kind=frozen(np.full(len(base), KIND_GHOST)),
                                 order=frozen(np.full(len(base), n))))
            n += 1
    return Echoes.concat(parts) if parts else _empty(direct.amplitude.shape[1])


def setup_echoes(setup: Setup, paths: Paths) -> Echoes:
    """The RuT's own chirp reflected by the setup (``rut_to_rut`` rows): static echoes."""
    rut = setup.rut
    sel = paths.direction == RUT_TO_RUT
    if not np.any(sel):
        return _empty(rut.num_virtual)
    p = paths.select(sel)
    parts = []
    for vi in range(rut.num_virtual):
        m = (p.rut_tx == rut.virtual_tx[vi]) & (p.rut_rx == rut.virtual_rx[vi])
        parts.append((vi, p.delay_s[m], p.gain[m]))
    n = max(len(d) for _, d, _ in parts)
    tau = np.zeros((n, rut.num_virtual))
    amp = np.zeros((n, rut.num_virtual), complex)
    for vi, d, g in parts:
        tau[: len(d), vi] = d
        amp[: len(d), vi] = np.conj(g)  # beat = tx * conj(rx)
    zeros = np.zeros(n)
    return Echoes(frozen(tau), frozen(zeros), frozen(zeros), frozen(zeros), frozen(amp),
                  frozen(np.full(n, -1)), frozen(np.full(n, -1)), frozen(np.full(n, KIND_SETUP)),
                  frozen(np.zeros(n, int)))


def build_echoes(setup: Setup, paths: Paths, program: RtsProgram) -> Echoes:
    """All echoes of a run: programmed channels with their ghosts, plus setup reflections."""
    return Echoes.concat([channel_echoes(setup, paths, program), setup_echoes(setup, paths)])


@lru_cache(maxsize=8)  # immutable: one per width (a drive met it twice a frame, 0.4 ms each)
def _empty(v: int) -> Echoes:
    z = np.zeros(0)
    zi = np.zeros(0, int)
    return Echoes(frozen(np.zeros((0, v))), frozen(z), frozen(z), frozen(z),
                  frozen(np.zeros((0, v), complex)), frozen(zi), frozen(zi), frozen(zi), frozen(zi))
