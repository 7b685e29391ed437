"""Calibration transfer: an RTS calibrated with one radar ("golden", the scene's own
``[radar.channels]``), tested with other radars of the same type (``radar.channels``).

The RTS's calibration sweep minimises the angle error *as the golden radar measures it*, so the
golden radar's channel errors go into the RTS's delay offsets. Every other radar has its own
errors. :class:`TransferStudy` calibrates each adjacent pair of the arc with the golden radar
(``calibration.pair.calibrate_pair`` on the setup as built, the engine ``calibrate`` runs), plans
the synthesized targets across each pair's span (``pipeline.pair.pair_design``, what ``run`` and
``linearity`` programme), and measures them with N radars drawn with the stated spreads (each
Tx and Rx antenna's phase ~ N(0, sigma_phase), gain ~ N(0, sigma_gain) dB, independently).

The RuT's output is linear in its virtual channels' gains, so each set-point's noise-free
snapshot on the ideal radar (the phasor model, ``synthesis.model.ChannelModel``, which agrees
with the ADC-cube chain) is formed once and multiplied by every draw's gains ``g_tx[t] g_rx[r]``
(``radar.channels``): the draws are one array, searched by the RuT's beamformer at once.

Per radar and set-point it reports the synthesized angle's error with the golden radar's
calibration, the same with the radar's own boresight compensation, and the radar's own error on
a real far-field target at the set angle (what no RTS calibration changes); for the golden radar
the part its calibration absorbed (its error on an RTS calibrated with an ideal radar, less its
error on its own calibration, and the shift of the calibrated delay offset).
"""

from __future__ import annotations

import dataclasses
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._lib.results import Result
from ..calibration.pair import calibrate_pair
from ..calibration.probes import FrontEndProbe, probe_angles, probe_front_ends, probe_ranges
from ..errors import ParameterError
from ..geometry import Setup, build_setup
from ..paths import Paths
from ..radar.channels import (antenna_gains, channel_coupling, channel_gain, compensation_vector,
                              plane_wave_errors, virtual_gain)
from ..radar.processing import tdm_compensate
from ..radar.steering import Steering
from ..calibration.phasor import PairChannels
from ..pipeline.pair import pair_design
from ..scene import TargetConfig
from ..scene.registry import SYNTHESIS_MODES
from ..scene.schema import check_arg, fmt
from .tolerance.args import STUDY_ARGS
from ..synthesis.model import ChannelModel

__all__ = ["TransferStudy", "Transfer", "draw_channel_gains", "percentiles", "snapshot_angles",
           "own_angle_errors", "set_angles", "ideal_radar", "MAX_RADARS", "MAX_POINTS",
           "MAX_RADAR_POINTS"]

#: radars one study draws (``rtsgeom transfer --radars``, ``rtsgeom.transfer(radars=...)``)
MAX_RADARS = 100_000
#: set-points per pair
MAX_POINTS = 201
#: radars x set-points over every pair: the (B, P) results (three float64 arrays) hold 3 x 8
#: bytes each, 480 MB at this cap (100 000 radars x 201 set-points of one pair)
MAX_RADAR_POINTS = 20_100_000
#: snapshots searched at once (the beamformer's grid of 721 angles per snapshot: ~100 MB)
CHUNK_SNAPSHOTS = 8192


def percentiles(x) -> dict:
    """{p50, p95, max} of |x| (deg), over every value: one working copy of ``x`` (|x|, its
    finite values), partitioned in place for both percentiles."""
    a = np.abs(np.asarray(x, float)).ravel()
    if not np.all(np.isfinite(a)):
        a = a[np.isfinite(a)]
    if a.size == 0:
        return {"p50": None, "p95": None, "max": None}
    top = float(a.max())
    p50, p95 = np.percentile(a, [50, 95], overwrite_input=True)
    return {"p50": float(p50), "p95": float(p95), "max": top}


def draw_channel_gains(rut, radars: int, sigma_phase_rad: float, sigma_gain_db: float,
                       seed) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``radars`` draws of per-antenna errors: virtual gains (B, V) ``g_tx[t] g_rx[r]``, the
    per-antenna phases (B, N_tx + N_rx) rad and gains (B, N_tx + N_rx) dB (Tx first), each
    ~ N(0, sigma) independently."""
    rng = np.random.default_rng(seed)
    n_tx, n_rx = rut.tx_local.shape[0], rut.rx_local.shape[0]
    ph = rng.normal(0.0, sigma_phase_rad, (radars, n_tx + n_rx))
    gd = rng.normal(0.0, sigma_gain_db, (radars, n_tx + n_rx))
    g = virtual_gain(rut, antenna_gains(gd[:, :n_tx], ph[:, :n_tx], n_tx),
                     antenna_gains(gd[:, n_tx:], ph[:, n_tx:], n_rx))
    return g, ph, gd


@dataclass(frozen=True, repr=False)
class Transfer(Result):
    """The study's result: per set-point (P,) over every pair, per radar draw (B, P).
    ``print(res)`` is a summary, ``to_dict()`` the JSON, ``to_dataframe()`` one row per
    (radar, set-point), ``plot()`` the error over the arc.

    Attributes
    ----------
    pairs : tuple of (int, int)
    set_deg : (P,) float
    error_deg, compensated_error_deg, own_error_deg : (B, P) float
    golden_error_deg : (P,) float
    offset_shift_ps : tuple of float
    """

    pairs: tuple[tuple[int, int], ...]
    pair_index: np.ndarray  # (P,) which pair synthesizes each set-point
    set_deg: np.ndarray  # (P,)
    golden_error_deg: np.ndarray  # (P,) the golden radar on its own calibration
    ideal_cal_error_deg: np.ndarray  # (P,) the golden radar on an ideal radar's calibration
    error_deg: np.ndarray  # (B, P) each radar on the golden radar's calibration
    compensated_error_deg: np.ndarray  # (B, P) the same with its own boresight compensation
    own_error_deg: np.ndarray  # (B, P) each radar on a real far-field target at the set angle
    offset_shift_ps: tuple[float, ...]  # per pair: golden calibration's offset - ideal radar's
    programs: np.ndarray  # (P, 4) the RTS programme per set-point: a_i, a_j, off_i_s, off_j_s
    draw_phase_rad: np.ndarray  # (B, N_tx + N_rx) each radar's antenna phase errors, Tx first
    draw_gain_db: np.ndarray  # (B, N_tx + N_rx) and gain errors
    range_m: float
    sigma_phase_deg: float
    sigma_gain_db: float
    spec_deg: float | None = None
    scene_name: str = ""

    def _summary(self):
        e, c, o = (percentiles(x) for x in (self.error_deg, self.compensated_error_deg,
                                            self.own_error_deg))
        title = (f"{self.scene_name + ': ' if self.scene_name else ''}{self.error_deg.shape[0]} "
                 f"radars x {self.set_deg.size} set-points, sigma {self.sigma_phase_deg:g} deg "
                 f"/ {self.sigma_gain_db:g} dB")

        def row(p):
            return f"p50 {p['p50']:.4f}, p95 {p['p95']:.4f}, max {p['max']:.4f}"
        rows = [("|angle error| (deg)", row(e)),
                ("with boresight compensation", row(c)),
                ("on a real target", row(o)),
                ("calibration absorbed (ps)", self.offset_shift_ps)]
        if self.spec_deg is not None:
            rows.append((f"verdict for {self.spec_deg:g} deg", self.verdict()))
        return title, rows

    @property
    def absorbed_deg(self) -> np.ndarray:
        """(P,) what the golden radar's calibration absorbed of its own channel errors: its
        error on an ideal radar's calibration less its error on its own."""
        return self.ideal_cal_error_deg - self.golden_error_deg

    @property
    def excess_deg(self) -> np.ndarray:
        """(B, P) what the RTS calibration adds to each radar's own error: its synthesized
        error less its error on a real target at the set angle."""
        return self.error_deg - self.own_error_deg

    def verdict(self, spec_deg: float | None = None) -> str | None:
        """What a lab needs for the angle spec ``spec_deg`` (met by 95 % of radars x
        set-points): ``transfers`` (the golden radar's calibration serves every radar),
        ``boresight`` (each radar's own boresight compensation first), ``recalibrate`` (the
        radars alone meet it on real targets, the transferred calibration breaks it: an RTS
        calibration per radar), ``radar`` (the radars' own errors exceed it on a real target
        too: no RTS calibration can help; their channels must be compensated)."""
        spec = self.spec_deg if spec_deg is None else spec_deg
        if spec is None:
            return None
        for name, err in (("transfers", self.error_deg), ("boresight",
                          self.compensated_error_deg), ("recalibrate", self.own_error_deg)):
            if percentiles(err)["p95"] <= spec:
                return name
        return "radar"

    def write(self, folder) -> list[str]:
        """``rtsgeom transfer --out``: transfer.json and transfer.png into ``folder``; returns the
        names."""
        from ..viz.figures import save_figure  # matplotlib: only where a figure is written
        self.to_json(Path(folder) / "transfer.json")
        save_figure(self.plot(), Path(folder) / "transfer.png")
        return ["transfer.json", "transfer.png"]

    def to_dict(self) -> dict:
        return {
            "radars": int(self.error_deg.shape[0]), "set_points": int(self.set_deg.size),
            "pairs": [list(p) for p in self.pairs],
            "sigma_phase_deg": self.sigma_phase_deg, "sigma_gain_db": self.sigma_gain_db,
            "angle_error_deg": percentiles(self.error_deg),
            "compensated_angle_error_deg": percentiles(self.compensated_error_deg),
            "own_angle_error_deg": percentiles(self.own_error_deg),
            "excess_angle_error_deg": percentiles(self.excess_deg),
            "golden_angle_error_deg": percentiles(self.golden_error_deg),
            "absorbed_deg": percentiles(self.absorbed_deg),
            "absorbed_offset_ps": list(self.offset_shift_ps),
            "spec_deg": self.spec_deg, "verdict": self.verdict(),
        }

    def to_dataframe(self):
        """One row per (radar, set-point): radar (-1: golden), pair, set_deg, error_deg,
        compensated_error_deg, own_error_deg."""
        import pandas as pd
        b, p = self.error_deg.shape
        rows = {"radar": np.repeat(np.arange(b), p), "pair": np.tile(self.pair_index, b),
                "set_deg": np.tile(self.set_deg, b), "error_deg": self.error_deg.ravel(),
                "compensated_error_deg": self.compensated_error_deg.ravel(),
                "own_error_deg": self.own_error_deg.ravel()}
        gold = {"radar": np.full(p, -1), "pair": self.pair_index, "set_deg": self.set_deg,
                "error_deg": self.golden_error_deg, "compensated_error_deg": np.nan,
                "own_error_deg": np.nan}
        return pd.concat([pd.DataFrame(gold), pd.DataFrame(rows)], ignore_index=True)

    def plot(self):
        """Error over the arc: each radar's (thin), their 5-95 % band, the golden radar's and
        the compensated radars' band; right: the distribution of |error|."""
        import matplotlib as mpl
        from ..viz.figures import STYLE, new_figure  # matplotlib: only for the figure
        with mpl.rc_context(STYLE):
            fig, (ax, bx) = new_figure((11, 4.2), ncols=2, gridspec_kw={"width_ratios": [2, 1]})
            self._draw(ax, bx)
        return fig

    def _draw(self, ax, bx) -> None:
        x = self.set_deg
        for e in self.error_deg[:40]:
            ax.plot(x, e, color="0.75", lw=0.6)
        lo, hi = np.nanpercentile(self.error_deg, [5, 95], axis=0)
        ax.fill_between(x, lo, hi, color="C0", alpha=0.25, label="radars B, 5-95 %")
        ax.plot(x, self.golden_error_deg, "k", lw=2, label="golden radar A (calibrated with)")
        clo, chi = np.nanpercentile(self.compensated_error_deg, [5, 95], axis=0)
        ax.fill_between(x, clo, chi, color="C2", alpha=0.6, zorder=3)
        ax.plot(x, np.nanmedian(self.compensated_error_deg, axis=0), color="C2", lw=1.5,
                ls="--", zorder=4, label="radars B with boresight compensation, 5-95 %")
        if self.spec_deg:
            for s in (-self.spec_deg, self.spec_deg):
                ax.axhline(s, color="C3", ls="--", lw=1)
        ax.set_xlabel("set angle (deg)")
        ax.set_ylabel("synthesized-angle error (deg)")
        ax.set_title(f"{self.scene_name + ': ' if self.scene_name else ''}calibrated with radar "
                     f"A, testing radar B (sigma {self.sigma_phase_deg:g} deg, "
                     f"{self.sigma_gain_db:g} dB)", parse_math=False)
        ax.legend(fontsize=8)
        top = max(float(np.nanmax(np.abs(self.error_deg))), 1e-6)
        bins = np.linspace(0, top, 30)
        bx.hist(np.abs(self.error_deg).ravel(), bins, color="C0", alpha=0.6, label="B")
        bx.hist(np.abs(self.compensated_error_deg).ravel(), bins, color="C2", alpha=0.6,
                label="B compensated")
        if self.spec_deg:
            bx.axvline(self.spec_deg, color="C3", ls="--", lw=1, label="spec")
        bx.set_xlabel("|error| (deg)")
        bx.set_ylabel("radar x set-point count")
        bx.legend(fontsize=8)


@dataclass(frozen=True)
class TransferStudy:
    """Calibrate with the scene's radar, test with ``radars`` drawn radars (module doc).

    ``sigma_phase_deg`` / ``sigma_gain_db``: the spread of each antenna's phase / gain error
    over radars of the type; ``points``: set-points across each pair's span (ends excluded);
    ``pairs``: the pairs (default every adjacent pair of the arc); ``spec_deg``: the angle
    spec the verdict is for; ``seed``: the draws' (and the calibration's noise).

    Parameters
    ----------
    radars : int
        Radars drawn.
    sigma_phase_deg, sigma_gain_db : float
        Spread of each antenna's phase and gain error.
    points : int
        Set-points across each pair's span.
    spec_deg : float, optional
        The angle spec of the verdict.
    seed : int
    """

    radars: int = 100
    sigma_phase_deg: float = 5.0
    sigma_gain_db: float = 0.0
    points: int = 11
    pairs: tuple[tuple[int, int], ...] | None = None
    spec_deg: float | None = None
    mode: str = "exact"
    seed: int = 0

    def __post_init__(self):
        src = "transfer"
        radars = check_arg(self.radars, "radars", "int", src, ParameterError, lo=1,
                           hi=MAX_RADARS)
        values = {"radars": radars,
                  "sigma_phase_deg": check_arg(self.sigma_phase_deg, "sigma_phase_deg", "float",
                                               src, ParameterError, lo=0.0, hi=90.0,
                                               unit="deg"),
                  "sigma_gain_db": check_arg(self.sigma_gain_db, "sigma_gain_db", "float", src,
                                             ParameterError, lo=0.0, hi=6.0, unit="dB"),
                  "points": check_arg(self.points, "points", "int", src, ParameterError, lo=1,
                                      hi=MAX_POINTS),
                  "mode": check_arg(self.mode, "mode", "str", src, ParameterError,
                                    choices=SYNTHESIS_MODES),
                  "seed": STUDY_ARGS["seed"].check(self.seed, "seed", src)}
        if self.spec_deg is not None:
            values["spec_deg"] = STUDY_ARGS["spec_deg"].check(self.spec_deg, "spec_deg", src)
        if self.pairs is not None:
            pairs = self.pairs
            if (not isinstance(pairs, (tuple, list)) or not pairs
                    or not all(isinstance(p, (tuple, list)) for p in pairs)):
                raise ParameterError(f"{src}: pairs = {fmt(pairs)}: must be a non-empty tuple "
                                     "of front-end pairs (i, i + 1)")
            values["pairs"] = tuple(check_arg(list(p), f"pairs[{k}]", "ints", src,
                                              ParameterError, lo=0, hi=10_000, min_items=2,
                                              max_items=2) for k, p in enumerate(pairs))
        for name, v in values.items():  # normalised: -0.0 as 0, numpy scalars as int/float
            object.__setattr__(self, name, v)

    def set_points(self, pairs: int) -> int:
        """Set-points over ``pairs`` pairs; with :attr:`radars` the size of each (B, P) output,
        capped at :data:`MAX_RADAR_POINTS` radar set-points (the memory it holds)."""
        total = self.points * pairs
        if self.radars * total > MAX_RADAR_POINTS:
            raise ParameterError(
                f"transfer: radars = {self.radars} x {total} set-points ({self.points} points x "
                f"{pairs} pairs): must be at most {MAX_RADAR_POINTS:.3g} radar set-points (the "
                f"study's results hold 3 x 8 bytes each; fewer radars or points)")
        return total

    def __call__(self, setup: Setup, paths: Paths, progress=None) -> Transfer:
        if Steering.auto(setup.rut, setup.scene.radar).dims != 1:
            raise ParameterError("transfer: the RuT beamforms in azimuth and elevation; the "
                                 "study covers a RuT that beamforms in azimuth (an arc of pairs)")
        n = setup.fe.count
        if n < 2:
            raise ParameterError("transfer: the arc needs at least two front ends")
        pairs = self.pairs or tuple((i, i + 1) for i in range(n - 1))
        self.set_points(len(pairs))
        ideal = ideal_radar(setup)
        probe = _probe(setup, paths, self.seed)
        probe0 = _probe(ideal, paths, self.seed) if ideal is not setup else probe
        rng_m = float(probe_ranges(setup, 1)[0])
        st = Steering.build(setup.rut, setup.scene.radar)
        coupling = channel_coupling(setup.scene.radar, setup.rut)  # the type's: every radar's
        g_gold = channel_gain(setup.scene.radar, setup.rut)
        g_gold = np.ones(setup.rut.num_virtual, complex) if g_gold is None else g_gold
        g_b, ph_b, gd_b = draw_channel_gains(setup.rut, self.radars,
                                             np.radians(self.sigma_phase_deg),
                                             self.sigma_gain_db, self.seed)
        comp = setup.scene.radar.channels
        c_range = None if comp is None else comp.compensation_range_m
        g_comp = g_b * compensation_vector(g_b, setup.rut, c_range, coupling)
        if comp is not None and comp.compensation == "boresight":
            g_b = g_comp  # every radar of the type runs the scene's compensation
        gains = np.concatenate([g_gold[None], g_b, g_comp])  # golden, B, B compensated
        del g_comp
        # (1 + 2B, P) filled column by column, in degrees in place: the one copy of the
        # study's largest array (2 x 161 MB at 100 000 radars x 201 set-points)
        e = np.empty((gains.shape[0], self.points * len(pairs)))
        idx, sets, errs0, progs, shifts = [], [], [], [], []
        for k, pair in enumerate(pairs):
            if progress:
                progress(f"calibrating pair {pair} with the golden radar")
            cal = calibrate_pair(setup, paths, pair, probe, seed=self.seed)
            cal0 = cal if ideal is setup else calibrate_pair(ideal, paths, pair, probe0,
                                                              seed=self.seed)
            shifts.append((cal.delta_tau_s - cal0.delta_tau_s) * 1e12)
            alphas = set_angles(setup, probe, pair, self.points)
            for a in alphas:
                t = TargetConfig(rng_m, 0.0, 10.0, float(a))
                err, prog = _measure(ideal, paths, pair, t, probe, cal, gains, st, self.mode,
                                     coupling)
                e0, _ = _measure(ideal, paths, pair, t, probe0, cal0, g_gold[None], st,
                                 self.mode, coupling)
                np.degrees(err, out=e[:, len(sets)])
                idx.append(k)
                sets.append(a)
                errs0.append(e0[0])
                progs.append(prog)
        del gains
        b = self.radars
        sets = np.asarray(sets)
        own = own_angle_errors(st, g_b, sets, coupling)
        np.degrees(own, out=own)
        return Transfer(tuple(tuple(p) for p in pairs), np.asarray(idx), np.degrees(sets),
                        e[0], np.degrees(np.asarray(errs0)), e[1:1 + b], e[1 + b:],
                        own, tuple(shifts), np.asarray(progs), ph_b, gd_b, rng_m,
                        float(self.sigma_phase_deg), float(self.sigma_gain_db), self.spec_deg,
                        setup.scene.name)


def _probe(setup: Setup, paths: Paths, seed) -> FrontEndProbe:
    """Each front end alone as the radar detects it; every one must be detected (a front end
    the radar does not see has no measured angle to calibrate the pair by)."""
    with warnings.catch_warnings():  # said below, naming what to change
        warnings.simplefilter("ignore", RuntimeWarning)
        probe = probe_front_ends(setup, paths, seed)
    missed = [int(q) for q in np.flatnonzero(~np.isfinite(probe.angle_rad))]
    if missed:
        ch = setup.scene.radar.channels
        gains = () if ch is None else (*ch.tx_gain_db, *ch.rx_gain_db)
        why = ""
        if gains and min(gains) < 0:
            why = (f"; radar.channels.tx_gain_db / rx_gain_db lower the channels by up to "
                   f"{-min(ch.tx_gain_db or (0,)) - min(ch.rx_gain_db or (0,)):g} dB")
        raise ParameterError(
            f"front end(s) {missed} not detected alone by the scene's "
            f"radar at their probe ranges (below the CFAR threshold, or clipped)"
            f"{probe.clipping_note()}{why}: transfer calibrates each pair on its front ends' "
            "measured angles")
    return probe


def ideal_radar(setup: Setup) -> Setup:
    """The setup as built with an ideal radar (the same paths: channels move none)."""
    if setup.scene.radar.channels is None:
        return setup
    scene = setup.scene
    return build_setup(dataclasses.replace(scene, radar=dataclasses.replace(scene.radar,
                                                                            channels=None)))


def set_angles(setup: Setup, probe: FrontEndProbe, pair, points: int) -> np.ndarray:
    """Set angles (rad) across the pair's span, ends excluded: the intersection of the measured
    and the geometric span, as ``analysis.linearity``."""
    i, j = pair
    meas = np.sort(probe.angle_rad[[i, j]])
    geo = np.sort(setup.fe_azimuth_rad()[[i, j]])
    lo, hi = max(meas[0], geo[0]), min(meas[1], geo[1])
    return lo + np.arange(1, points + 1) / (points + 1) * (hi - lo)


def _measure(ideal: Setup, paths: Paths, pair, target: TargetConfig, probe, cal, gains, st,
             mode: str, coupling=None) -> tuple[np.ndarray, np.ndarray]:
    """The synthesized target's angle error (rad) per radar (gains (B, V)) for the RTS
    programme the calibration ``cal`` plans, and that programme (a_i, a_j, off_i, off_j)."""
    i, j = pair
    off = (0.0, cal.delta_tau_s)
    corr = probe.gain_correction[[i, j]]
    a_i, a_j, _, off_j = pair_design(ideal, paths, PairChannels(pair, off, corr), target, mode,
                                     probe_angles(*probe.angle_rad[[i, j]]),
                                     cal.quantisation_residual_s)
    model = ChannelModel.build(ideal, paths, pair, target, (0.0, off_j), steering=st)
    return (snapshot_angles(model, np.array([a_i, a_j]), gains, coupling) - target.angle_rad,
            np.array([a_i, a_j, 0.0, off_j]))


def snapshot_angles(model: ChannelModel, w, gains, coupling=None) -> np.ndarray:
    """Detected azimuths (B,) rad of programme weights ``w`` (Q,) on ``model`` (an ideal
    radar's) seen by radars of virtual gains ``gains`` (B, V) after the coupling ``coupling``
    (V, V) (``radar.channels``; None: none): each radar's snapshot at its strongest candidate
    bin, TDM-compensated, searched by the beamformer."""
    x = np.tensordot(w, model.responses, axes=([0], [1]))  # (K, V)
    if coupling is not None:
        x = x @ coupling.T
    gains = np.asarray(gains)
    out = np.empty(gains.shape[0])
    for rows in _chunks(gains.shape[0], max(1, CHUNK_SNAPSHOTS // x.shape[0])):
        xb = x[None] * gains[rows, None, :]  # (b, K, V)
        k = np.argmax(np.sum(np.abs(xb) ** 2, axis=-1), axis=-1)
        sel = np.take_along_axis(xb, k[:, None, None], axis=1)[:, 0]
        sel = tdm_compensate(sel, model.doppler_hz, model.setup.rut, model.setup.scene.radar)
        out[rows] = model.steering.search(sel)
    return out


def _chunks(n: int, size: int):
    """Slices of ``range(n)`` of at most ``size`` (memory: one chunk's snapshots at a time)."""
    return (slice(a, min(a + size, n)) for a in range(0, n, size))


def own_angle_errors(st: Steering, gains, angles_rad, coupling=None) -> np.ndarray:
    """Each radar's error (B, P) rad on a real far-field point target at each set angle
    (``radar.channels.plane_wave_errors``), a chunk of radars at a time."""
    gains = np.asarray(gains)
    p = np.size(angles_rad)
    out = np.empty((gains.shape[0], p))
    for rows in _chunks(gains.shape[0], max(1, CHUNK_SNAPSHOTS // max(p, 1))):
        out[rows] = plane_wave_errors(st, gains[rows], angles_rad, coupling)
    return out
