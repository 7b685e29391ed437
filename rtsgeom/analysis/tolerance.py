"""Mounting-tolerance Monte Carlo of the arbitrary-angle synthesis (paper section "Arbitrary
Angle of Arrival", "Constraints": a radial error of lambda/4 already cancels the composite).

Each draw moves both front ends of a pair radially, tangentially and in height (normal with
given sigmas, or uniform within given bounds). The operator does not know the errors: the
amplitudes of the set-points across the pair's span (21 by default, ends excluded as in
``aoa.linearity``) are designed once on the nominal setup (:class:`~rtsgeom.aoa.model.ChannelModel`,
its ``solve`` and ``amplitudes`` for the phase the calibration establishes, see
:meth:`PairPhasors.coherence_phase`).
For every draw the synthesized angle is evaluated uncalibrated (no delay offset) and after
the calibration.

Phasor level (the paper's eq. 15/16 with the exact geometry). The spectrum of channel q at the
target's range/Doppler bin per virtual element v is the nominal one (``radar.phasors`` via
:class:`~rtsgeom.aoa.model.ChannelModel`) times the changed two-way air delay's phase and
free-space amplitude (``ChannelModel.perturbed``)::

    x_qv(draw) = x_qv(nominal) * (a_qv b_qv / a'_qv b'_qv)
                 * exp(j 2 pi (f_c + S t_mid - S tau_t) (tau'_qv - tau_qv))

with ``t_mid`` the centre of the ADC window (the air delay acts at RF, eq. 8, and through the
range kernel at ``S t_mid``; ``- S tau_t``, the target's total delay, is the -S tau^2/2 term
of eq. 8, 3e-5 of the rest), ``a``, ``b`` the two legs' delays and ``tau = a + b`` (exact
per-element legs, ``geometry.arc`` + ``paths.exact.leg_delays``, broadcast over draws; primed:
the draw). Neglected: -S dtau^2/2 and the beat-frequency shift S dtau against the range bin
(3e-3 bins per mm of path; the window is flat at the bin centre where the target sits, so the
magnitude changes only quadratically: 1e-5 of the phasor at 0.3 mm errors);
``tests/test_tolerance.py`` checks the model against
:func:`~rtsgeom.radar.phasors.bin_response` on drawn setups and the whole chain against the
ADC cube.

Calibration at phasor level, as the paper's two steps:

* amplitude: each channel's power summed over the virtual channels against the model's
  (``probe_front_ends``), a gain correction per channel;
* delay: the offset of channel J that makes both channels' beamformer outputs coherent at the
  calibration's probe angles (1/4 and 3/4 of the span, as ``calibrate_pair``; circular mean of
  the two phase differences), the smallest such (least range offset, as ``calibrate_pair``),
  from eq. (27), d phi / d tau_rts = 2 pi (f_rts + B/2), quantised to the RTS's delay
  resolution and refined on the table below.

The delay is applied exactly, not as a bare phase rotation: it also moves J's echo by
c0 dtau / 2 in range (paper "Disadvantages"), up to half a range bin (7.6 cm) once the errors
reach lambda/8, and the range window's scalloping then weakens J by up to 1.4 dB, which biases
the synthesized angle by up to ~0.5 deg (default scene). So channel J is multiplied by its
exact response to the quantised delay at the bin (a table over +-half a period, from
``bin_response``), plus the first-order change of that response with the draw's own air delay
(the echo slides along the window's slope). Like the ``exact`` mode (``aoa.plan``), the
operator designs J's amplitude for the known delay (case ``calibrated``);
``calibrated_nominal_amplitudes`` keeps the nominal design and shows what skipping that costs.
``range_offset_m`` reports the offset per draw.

Angles come from :func:`~rtsgeom.radar.processing.refine_angles` (Newton on the beamformer
peak from the set angle, global check, fallback to ``estimate_angles``), vectorised over
draws x set-points; the draws are processed in chunks (memory bounded) from one generator
``numpy.random.default_rng(seed)``, so the same seed gives bit-identical results whatever the
chunk size. Every chunk is a pure function of its offsets (:func:`evaluate_chunk`), so a
process pool or cluster can map it (``monte_carlo(..., mapper=...)``).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Callable, Iterable, Iterator

import numpy as np
from scipy.constants import c

from .._util import frozen
from ..aoa.calibration import probe_ranges
from ..aoa.model import ChannelModel
from ..geometry import Setup
from ..geometry.setup import nominal_setup
from ..paths import exact_paths
from ..radar.phasors import bin_response
from ..radar.processing import refine_angles
from ..rts import KIND_DIRECT, RtsProgram, channel_echoes, requested_delay
from ..scene import TargetConfig

__all__ = ["AXES", "DISTRIBUTIONS", "CASES", "ALL_CASES", "NOMINAL_AMPLITUDES", "PairPhasors",
           "ToleranceResult", "draw_offsets", "standard_draws", "evaluate_chunk", "monte_carlo",
           "max_sigma_for_yield", "percentiles"]

AXES = ("radial", "tangential", "height")
DISTRIBUTIONS = ("normal", "uniform")
CASES = ("uncalibrated", "calibrated")
# calibrated, but the nominal design's amplitudes kept (the calibration delay's range offset
# not designed for): what skipping that costs
NOMINAL_AMPLITUDES = "calibrated_nominal_amplitudes"
ALL_CASES = CASES + (NOMINAL_AMPLITUDES,)
PROBE_FRACTIONS = (0.25, 0.75)  # calibrate_pair's probe angles across the span
DEFAULT_CHUNK = 10_000

Progress = Callable[[str, int, int], None]  # (label, draws done, draws total)
Mapper = Callable[[Callable, list], Iterable]  # ordered map of a pure function over chunks


@dataclass(frozen=True)
class PairPhasors:
    """The design (set-points, amplitudes) and the calibration of one front-end pair at a
    target's bin, on its :class:`~rtsgeom.aoa.model.ChannelModel` (``channels``), which holds
    the nominal per-element phasors, the beamformer and the mounting-error perturbation.

    ``delay_factor[K + k, v]``: channel J's spectrum with its RTS delay offset by ``k`` steps of
    the delay resolution, relative to offset 0, for |k| <= K (a bit more than half a
    calibration period): the calibration delay's exact effect at the bin -- the phase of
    eq. (27) and, because the delay also moves J's echo in range, the range window's scalloping
    and residual phase terms (``radar.phasors.bin_response``).
    """

    channels: ChannelModel  # Q = 2, on the nominal setup
    fe_angle_rad: np.ndarray  # (2,) each front end alone, detected (nominal, phasor level)
    set_rad: np.ndarray  # (M,) set-points, ends of the span excluded
    probe_rad: np.ndarray  # (2,) calibration probes
    amplitudes: np.ndarray  # (M, 2) designed A_I, A_J
    delay_factor: np.ndarray  # (2K + 1, V) channel J's response to a delay offset
    delay_log_slope: np.ndarray  # (2K + 1, V) d ln|delay_factor| / d tau (1/s)
    cal_slope_hz: float  # f_rts + B/2: eq. (27)
    delay_resolution_s: float

    @classmethod
    def build(cls, setup: Setup, pair: tuple[int, int], points: int = 21,
              range_m: float | None = None) -> "PairPhasors":
        """Design on the nominal setup of ``setup`` (its mounting and channel errors dropped).

        The target sits at the centre of the range bin nearest ``range_m`` (default: the
        calibration's first probe range), velocity 0; the set-points divide the span between
        the two front ends' detected angles into ``points + 1`` parts (ends excluded, as
        ``aoa.linearity``)."""
        nom = nominal_setup(setup)
        scene, radar = nom.scene, nom.scene.radar
        pair = (int(pair[0]), int(pair[1]))
        bin_m = radar.range_resolution_m
        r0 = float(probe_ranges(nom, 1)[0]) if range_m is None else float(range_m)
        target = TargetConfig(max(round(r0 / bin_m), 1) * bin_m)
        paths = exact_paths(nom)
        model = ChannelModel.build(nom, paths, pair, target)
        x = model.phasors  # (2, V)
        th = model.steering.search(x)
        frac = np.arange(1, points + 1) / (points + 1)
        sets = th[0] + frac * (th[1] - th[0])
        probes = th[0] + np.asarray(PROBE_FRACTIONS) * (th[1] - th[0])
        phases = model.coherent_phases(probes)
        amps = np.array([model.amplitudes(model.solve(float(a), phases), float(a))
                         for a in sets])  # root finding per set-point
        rts = scene.rts
        slope = rts.f_rts_hz + 0.5 * radar.bandwidth_hz
        steps = int(np.ceil(0.5 / (slope * rts.delay_resolution_s))) + 4
        table = _delay_table(nom, paths, pair[1], target, rts.delay_resolution_s, steps)
        log_slope = np.gradient(np.log(np.abs(table)), rts.delay_resolution_s, axis=0)
        return cls(model, frozen(th), frozen(sets), frozen(probes), frozen(amps),
                   frozen(table), frozen(log_slope), slope, rts.delay_resolution_s)

    setup = property(lambda self: self.channels.setup)  # nominal
    pair = property(lambda self: self.channels.channels)
    range_m = property(lambda self: self.channels.range_m)
    x_nominal = property(lambda self: self.channels.phasors)  # (2, V)

    @property
    def max_steps(self) -> int:
        return (self.delay_factor.shape[0] - 1) // 2

    # -- one draw's channels -------------------------------------------------------------

    def air_legs(self, offsets_m, pose: dict | None = None) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`ChannelModel.air_legs`: (..., 2, V) each for offsets (..., 2, 3); ``pose``:
        its rotation and RuT-pose keywords (``yaw_rad``, ``pitch_rad`` (..., 2),
        ``rut_offset_m`` (..., 3), ``rut_yaw_rad`` (...,))."""
        return self.channels.air_legs(offsets_m, **(pose or {}))

    def channel_phasors(self, offsets_m, return_shift: bool = False, pose: dict | None = None):
        """Per-element phasors of both channels at the bin for mounting errors (..., 2, 3)
        and ``pose`` (:meth:`air_legs`) (:meth:`ChannelModel.perturbed`). ``return_shift``:
        also the air delay change (..., 2, V) (s)."""
        return self.channels.perturbed(offsets_m, return_shift, **(pose or {}))

    def coherence_phase(self, xq: np.ndarray) -> np.ndarray:
        """The phase to give channel J so that both channels' beamformer outputs add in phase
        at the probe angles (the circular mean over the probes), (...,) for phasors
        (..., 2, V) (:meth:`ChannelModel.coherent_phases`).

        The amplitudes are designed for this one phase, the one the calibration establishes,
        not for the phase that is coherent at each set angle: the two agree to ~1e-6 relative
        in the ratio while the spacing is below the first null lambda/d_A of the beam, but
        beyond it the other front end's beam is in its first sidelobe at set angles near
        either end, the per-angle coherent phase flips by pi and the design fails there
        (``tests/test_design.py``)."""
        return self.channels.coherent_phases(self.probe_rad, xq)[..., 1]

    def calibration_steps(self, xq: np.ndarray) -> np.ndarray:
        """The calibration of channel J, in delay-resolution steps (int, (...,)).

        The phase that makes both channels' beamformer outputs coherent at the probe angles
        (:meth:`coherence_phase`) becomes a delay by eq. (27), wrapped to the smallest
        |delay|, quantised, and refined by +-3 steps against the delay table's exact phase
        (what the calibration sweep, which measures the outcome, converges to)."""
        phi = self.coherence_phase(xq)
        k0 = np.round(phi / (2 * np.pi * self.cal_slope_hz * self.delay_resolution_s))
        cand = np.clip(k0[..., None].astype(int) + np.arange(-3, 4), -self.max_steps,
                       self.max_steps)
        table_phase = np.angle(self.delay_factor[:, self.channels.steering.mask].mean(axis=1))
        miss = np.abs(np.angle(np.exp(1j * (phi[..., None] - table_phase[cand + self.max_steps]))))
        return np.take_along_axis(cand, np.argmin(miss, axis=-1)[..., None], axis=-1)[..., 0]

    def gain_correction(self, xq: np.ndarray) -> np.ndarray:
        """The amplitude calibration (``probe_front_ends``): per channel the square root of
        modelled over measured power, the power summed over the virtual channels, (..., 2)."""
        p = np.sum(xq.real ** 2 + xq.imag ** 2, axis=-1)
        p0 = np.sum(self.x_nominal.real ** 2 + self.x_nominal.imag ** 2, axis=-1)
        return np.sqrt(p0 / p)

    def snapshots(self, xq: np.ndarray, steps=None, redesign: bool = True,
                  shift_s=None) -> np.ndarray:
        """Beamformer snapshots (..., M, V) of the designed set-points. ``steps`` (...,):
        channel J's calibration delay in resolution steps, None: uncalibrated; calibrated, the
        amplitudes also get the gain correction. ``redesign``: the operator knows the delay and,
        like the ``exact`` mode (``aoa.plan``), designs the amplitudes for it: J's amplitude
        divided by the delay's loss at the bin (the range offset's scalloping; first order of
        the redesign); False keeps the nominal design's amplitudes. ``shift_s``: the air delay
        change (..., 2, V) of the draw, which moves J's echo further along the range window's
        slope once the delay has moved it off the bin centre (first order)."""
        x_i, x_j = xq[..., 0, :], xq[..., 1, :]
        a_i, a_j = self.amplitudes[:, 0], self.amplitudes[:, 1]  # (M,)
        if steps is not None:
            g = self.gain_correction(xq)  # (..., 2)
            k = np.asarray(steps) + self.max_steps
            f = self.delay_factor[k]  # (..., V)
            if redesign:  # from the nominal model: the operator does not know the shift
                g[..., 1] /= np.abs(f[..., self.channels.steering.mask].mean(axis=-1))
            if shift_s is not None:
                f = f * np.exp(self.delay_log_slope[k] * shift_s[..., 1, :])
            x_j = x_j * f
            a_i, a_j = a_i * g[..., 0, None], a_j * g[..., 1, None]  # (..., M)
        return a_i[..., None] * x_i[..., None, :] + a_j[..., None] * x_j[..., None, :]

    def angle_errors(self, offsets_m, case: str = "calibrated", return_converged: bool = False):
        """Detected minus set angle (deg), (..., M), for mounting errors (..., 2, 3)."""
        xq, shift = self.channel_phasors(offsets_m, return_shift=True)
        steps = None if case == "uncalibrated" else self.calibration_steps(xq)
        snaps = self.snapshots(xq, steps, case == "calibrated", shift)
        return self._errors(snaps, return_converged)

    def _errors(self, snaps, return_converged=False):
        ang, ok = refine_angles(snaps, self.channels.steering, None, self.set_rad,
                                return_converged=True)
        err = np.degrees(ang - self.set_rad)
        return (err, ok) if return_converged else err

    def range_offset_m(self, offsets_m, steps, pose: dict | None = None) -> np.ndarray:
        """Range offset between the two channels' echoes after calibration: c0/2 times the
        total delay mismatch (element-mean air delay plus J's delay offset), as
        ``calibrate_pair`` reports it."""
        air = sum(self.air_legs(offsets_m, pose)).mean(axis=-1)
        return 0.5 * c * (air[..., 1] + np.asarray(steps) * self.delay_resolution_s - air[..., 0])

    def to_dict(self) -> dict:
        k = int(self.calibration_steps(self.x_nominal))
        return {
            "pair": list(self.pair),
            "range_m": self.range_m,
            "front_end_angles_deg": [float(a) for a in np.degrees(self.fe_angle_rad)],
            "set_points_deg": [float(a) for a in np.degrees(self.set_rad)],
            "probe_angles_deg": [float(a) for a in np.degrees(self.probe_rad)],
            "nominal_delta_tau_s": k * self.delay_resolution_s,
            "delay_resolution_s": self.delay_resolution_s,
        }


def _delay_table(setup: Setup, paths, channel: int, target: TargetConfig, resolution_s: float,
                 steps: int) -> np.ndarray:
    """Channel ``channel``'s spectrum at the target's bin with its RTS delay offset by
    k * resolution, k = -steps..steps, relative to k = 0: (2 steps + 1, V)."""
    scene, radar = setup.scene, setup.scene.radar
    k = np.arange(-steps, steps + 1)
    tau = float(requested_delay(scene, target.range_m))
    prog = RtsProgram.build(np.arange(k.size), np.full(k.size, channel), tau + k * resolution_s,
                            np.zeros(k.size), np.ones(k.size))
    ech = channel_echoes(setup, paths, prog)
    ech = ech.select(ech.kind == KIND_DIRECT)
    r_bin = int(round(target.range_m / radar.range_resolution_m))
    resp = bin_response(ech, radar, setup.rut, [r_bin], [radar.chirps_per_tx // 2])[0]
    table = resp / resp[steps]
    table[steps] = 1.0
    return table


# ------------------------------------------------------------------------------------------
# Draws
# ------------------------------------------------------------------------------------------


def standard_draws(seed: int, draws: int, distribution: str = "normal",
                   chunk: int = DEFAULT_CHUNK) -> Iterator[np.ndarray]:
    """Unit-scale draws (k, 2, 3) chunk by chunk from ``numpy.random.default_rng(seed)``:
    standard normal, or uniform in [-1, 1]. The stream does not depend on ``chunk``."""
    if distribution not in DISTRIBUTIONS:
        raise ValueError(f"distribution {distribution!r}: must be one of "
                         f"{', '.join(DISTRIBUTIONS)}")
    rng = np.random.default_rng(seed)
    chunk = max(1, int(chunk))
    for start in range(0, draws, chunk):
        k = min(chunk, draws - start)
        if distribution == "normal":
            yield rng.standard_normal((k, 2, 3))
        else:
            yield rng.uniform(-1.0, 1.0, (k, 2, 3))


def draw_offsets(seed: int, draws: int, sigma_m, distribution: str = "normal") -> np.ndarray:
    """All mounting errors (draws, 2, 3) of a study at once (the per-axis scale ``sigma_m``
    (3,) is the standard deviation, or the bound of the uniform distribution)."""
    z = list(standard_draws(seed, draws, distribution, max(draws, 1)))
    z = z[0] if z else np.zeros((0, 2, 3))
    return z * np.asarray(sigma_m, float)


def evaluate_chunk(model: PairPhasors, offsets_m: np.ndarray, cases=CASES,
                   pose: dict | None = None) -> dict:
    """Per draw of ``offsets_m`` (k, 2, 3) (and ``pose``: rotations (k, 2) and RuT pose
    errors, :meth:`PairPhasors.air_legs`): for each case the signed angle error of the worst
    set-point (deg) and the number of snapshots ``refine_angles`` left to ``estimate_angles``;
    the calibration (delay steps of channel J) and the range offset it causes (m). Pure: the
    same offsets give the same bits."""
    xq, shift = model.channel_phasors(offsets_m, return_shift=True, pose=pose)
    steps = model.calibration_steps(xq)
    out = {"steps": steps, "range_offset_m": model.range_offset_m(offsets_m, steps, pose)}
    for case in cases:
        if case not in ALL_CASES:
            raise ValueError(f"case {case!r}: must be one of {', '.join(ALL_CASES)}")
        snaps = model.snapshots(xq, None if case == "uncalibrated" else steps,
                                case == "calibrated", shift)
        err, ok = model._errors(snaps, return_converged=True)
        k = np.argmax(np.abs(err), axis=-1)
        out[case] = np.take_along_axis(err, k[:, None], axis=-1)[:, 0]
        out[case + "_fallbacks"] = int(np.count_nonzero(~ok))
    return out


# ------------------------------------------------------------------------------------------
# Monte Carlo and its statistics
# ------------------------------------------------------------------------------------------


def percentiles(values: np.ndarray, scale: float = 1.0) -> dict:
    """p50, p95, p99 and max of ``values`` (times ``scale``); None where there are none."""
    a = np.asarray(values, float) * scale
    if a.size == 0:
        return {"p50": None, "p95": None, "p99": None, "max": None}
    p = np.percentile(a, [50, 95, 99])
    return {"p50": float(p[0]), "p95": float(p[1]), "p99": float(p[2]), "max": float(a.max())}


@dataclass(frozen=True)
class ToleranceResult:
    """A Monte-Carlo run: per draw the worst signed angle error of each case (deg)."""

    model: PairPhasors
    sigma_m: np.ndarray  # (3,) radial, tangential, height
    distribution: str
    draws: int
    seed: int
    spec_deg: float
    worst_error_deg: dict  # case -> (draws,)
    delay_s: np.ndarray  # (draws,) calibration delay offset of channel J
    range_offset_m: np.ndarray  # (draws,) range offset between the channels after calibration
    fallbacks: dict  # case -> snapshots that needed estimate_angles
    elapsed_s: float = 0.0

    def yield_(self, case: str) -> float:
        e = self.worst_error_deg[case]
        return float(np.mean(np.abs(e) <= self.spec_deg)) if e.size else float("nan")

    def stats(self, case: str) -> dict:
        return {"angle_error_deg": percentiles(np.abs(self.worst_error_deg[case])),
                "yield": self.yield_(case), "fallbacks": self.fallbacks[case]}

    def to_dict(self) -> dict:
        out = {
            "draws": self.draws,
            "seed": self.seed,
            "distribution": self.distribution,
            "scale": "sigma" if self.distribution == "normal" else "bound",
            "sigma_mm": {a: float(s * 1e3) for a, s in zip(AXES, self.sigma_m)},
            "spec_deg": self.spec_deg,
            "pair": self.model.to_dict(),
        }
        for case in self.worst_error_deg:
            out[case] = self.stats(case)
        out["calibration"] = {
            "abs_delta_tau_ps": percentiles(np.abs(self.delay_s), 1e12),
            "abs_range_offset_mm": percentiles(np.abs(self.range_offset_m), 1e3),
        }
        return out


def monte_carlo(model: PairPhasors, sigma_m, draws: int, seed: int,
                distribution: str = "normal", spec_deg: float = 0.1, cases=CASES,
                chunk: int = DEFAULT_CHUNK, progress: Progress | None = None,
                label: str = "tolerance", mapper: Mapper | None = None) -> ToleranceResult:
    """``draws`` setups with mounting errors scaled by ``sigma_m`` (3,) (m; the standard
    deviation, or the uniform bound), evaluated chunk by chunk: in this process, one chunk in
    memory at a time, or by ``mapper(func, chunks)`` (results in chunk order, e.g. a process
    pool's ``map``; the draws are all made here first). The outcome depends on neither."""
    import time
    t0 = time.perf_counter()
    sigma = np.asarray(sigma_m, float).reshape(3)
    if np.any(~np.isfinite(sigma)) or np.any(sigma < 0):
        raise ValueError(f"sigma_m {sigma.tolist()}: must be finite and >= 0")
    parts: list[dict] = []
    done = 0
    chunks = (z * sigma for z in standard_draws(seed, draws, distribution, chunk))
    func = functools.partial(evaluate_chunk, model, cases=tuple(cases))
    for part in (map(func, chunks) if mapper is None else mapper(func, list(chunks))):
        parts.append(part)
        done += len(part["steps"])
        if progress:
            progress(label, done, draws)

    def joined(key):
        return frozen(np.concatenate([p[key] for p in parts]) if parts else np.zeros(0))

    return ToleranceResult(model, frozen(sigma), distribution, int(draws), int(seed),
                           float(spec_deg), {case: joined(case) for case in cases},
                           frozen(joined("steps") * model.delay_resolution_s),
                           joined("range_offset_m"),
                           {case: sum(p[case + "_fallbacks"] for p in parts) for case in cases},
                           time.perf_counter() - t0)


def max_sigma_for_yield(model: PairPhasors, sigma_m, draws: int, seed: int, target_yield: float,
                        spec_deg: float = 0.1, case: str = "calibrated", axis: str = "all",
                        distribution: str = "normal", rel_tol: float = 0.01,
                        cap_m: float = 0.01, chunk: int = DEFAULT_CHUNK,
                        progress: Progress | None = None, mapper: Mapper | None = None) -> dict:
    """The largest mounting tolerance that keeps ``target_yield`` of the setups within
    ``spec_deg`` for ``case``, by bisection on the scale with the same seed (the same unit
    draws scaled: common random numbers, so the yield curve is smooth and, up to the rare
    draw whose error is not monotone in the scale, monotone).

    ``axis="all"`` scales the three sigmas together (their ratios as given; all ones where
    all are zero); an axis name varies that axis alone, the other two held at ``sigma_m``.
    Returns the sigmas found (m), the yield there, the bracket and the evaluations; the search
    stops at ``cap_m`` (a tolerance that large is reported as ``capped``)."""
    base = np.asarray(sigma_m, float).reshape(3)
    if axis == "all":
        direction = base / base.max() if base.max() > 0 else np.ones(3)
        fixed = np.zeros(3)
    elif axis in AXES:
        direction = np.eye(3)[AXES.index(axis)]
        fixed = base * (1 - direction)
    else:
        raise ValueError(f"axis {axis!r}: must be 'all' or one of {', '.join(AXES)}")
    history = []

    def yield_at(t: float) -> float:
        res = monte_carlo(model, fixed + t * direction, draws, seed, distribution, spec_deg,
                          (case,), chunk, progress, f"{case}: sigma {t * 1e3:.4g} mm", mapper)
        y = res.yield_(case)
        history.append({"scale_mm": t * 1e3, "yield": y})
        return y

    def result(t, y, capped=False, note=None):
        sig = fixed + t * direction
        return {"case": case, "axis": axis, "target_yield": target_yield, "spec_deg": spec_deg,
                "sigma_mm": {a: float(s * 1e3) for a, s in zip(AXES, sig)},
                "yield": y, "capped": capped, "note": note,
                "evaluations": history}

    y0 = yield_at(0.0)
    if y0 < target_yield:
        return result(0.0, y0, note="the setup misses the spec even without the varied errors")
    start = min(float(np.max(base * direction)) or 1e-4, cap_m)
    return result(*largest_passing_scale(yield_at, y0, target_yield, start, cap_m, rel_tol))


def largest_passing_scale(yield_at, y0: float, target_yield: float, start: float, cap: float,
                          rel_tol: float, max_bisections: int = 60) -> tuple[float, float, bool]:
    """The largest scale t in [0, cap] with ``yield_at(t) >= target_yield`` (``y0`` the yield
    at 0, which passes): double from ``start`` until the yield drops (or ``cap``: then
    ``capped``), then bisect geometrically to ``rel_tol``. Common random numbers (the same
    seed in every evaluation) keep the yield monotone in t. Returns (t, yield, capped)."""
    lo, y_lo, hi = 0.0, y0, start
    y_hi = yield_at(hi)
    while y_hi >= target_yield:
        if hi >= cap:
            return hi, y_hi, True
        lo, y_lo = hi, y_hi
        hi = min(2 * hi, cap)
        y_hi = yield_at(hi)
    for _ in range(max_bisections):
        if hi - lo <= rel_tol * hi:
            break
        mid = math.sqrt(lo * hi) if lo > 0 else 0.5 * hi
        y = yield_at(mid)
        if y >= target_yield:
            lo, y_lo = mid, y
        else:
            hi = mid
    return lo, y_lo, False
