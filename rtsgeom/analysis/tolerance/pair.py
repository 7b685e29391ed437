"""The phasor model of one front-end pair under mounting errors (the fast model of the tolerance
study, :mod:`rtsgeom.analysis.tolerance.driver`; paper section "Arbitrary Angle of Arrival", eqs. 14-27).

The operator designs the amplitudes of the set-points on the nominal setup
(:class:`~rtsgeom.synthesis.model.ChannelModel`), for the phase the calibration establishes
(:meth:`PairPhasors.coherence_phase`) and **for the range bin the RuT detects**; the RuT sees
the setup as built. Everything the model needs is precomputed on the nominal setup as tables
over the RTS delay, so that a draw is a few lookups and one angle estimate per set-point:

* ``table[q, D, k, v]``: channel q's spectrum (``radar.phasors.bin_response``, through the
  same ``rts.channel_echoes`` as the ADC-cube chain: realised (quantised) delays, the
  fractional-delay FIR when modelled) at candidate range bin k (the set range's bin and
  ``HALF_BINS`` either side) with its RTS delay offset by D steps of the delay resolution.
* The target's sub-bin position is drawn per draw, uniform over one range bin, as an RTS
  delay offset ``u`` in steps of the delay resolution (the RTS can place a target nowhere
  else): channel I reads ``table[0, u]``, channel J ``table[1, u + k]`` with ``k`` its
  calibration delay. The delay moves J's echo by ``c0 k dtau / 2`` in range (paper
  "Disadvantages"); two bins can then carry nearly equal power.
* The bin logic is the RuT's: the detected bin is the strongest candidate (power summed over
  the virtual elements), and the design is made for the bin the RuT then detects
  (:func:`rtsgeom.calibration.sweep.design_at_detected_bin`, shared with ``ChannelModel.solve`` and
  the calibration sweep).

A draw's mounting errors enter at phasor level (eq. 15/16 with the exact geometry,
:meth:`ChannelModel.perturbed`)::

    x_qkv(draw) = table[q, D_q, k, v] * (a_qv b_qv / a'_qv b'_qv)
                  * exp(j 2 pi (f_c + S t_mid - S tau_t) d_qv) * exp(s_qkv d_qv)

with ``d = tau' - tau`` the air-delay change per element (exact legs), and ``s`` the real part
of d ln(table) / dD: the echo slides along the range window's slope by the air delay as it
does by an RTS delay (first order; the phase of that derivative is the IF slope, which the
exact RF term replaces). Neglected: second order in d (~1e-5 of the phasor at 0.3 mm).
``rtsgeom tolerance --verify N`` and ``tests/test_tolerance*.py`` check it against the full
ADC-cube chain.

Calibration at phasor level, as the paper's two steps: amplitude (each channel's power over
the virtual channels against the model's, ``probe_front_ends``) and delay (channel J's offset
that makes both channels' beamformer outputs coherent at the probe angles, eq. (27), quantised
and refined on the table's exact phase: :meth:`PairPhasors.calibration_steps`). In the case
``calibrated`` the operator then plans each set-point as ``rtsgeom run`` does
(``aoa.plan.pair_design``): the exact design on the nominal model with J at the calibrated
delay, for the bin the RuT detects; where that bin is ambiguous (J's echo straddles a bin
boundary: no consistent design, or a power margin below ``plan.MIN_BIN_MARGIN``) J's delay one
IF period either side (the same phase, the echo about a bin further) is tried
(:meth:`_Design.planned`). ``calibrated_nominal_amplitudes`` keeps the design made without the
delay (J at the target's own delay), which is also the ``uncalibrated`` design.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from scipy.constants import c

from ..._lib.util import frozen, single_threaded_blas
from ...calibration.probes import if_phase_slope_hz, probe_ranges
from ...synthesis.model import ChannelModel
from ...synthesis.pair import beam_derivatives
from ...geometry import Setup
from ...geometry.setup import nominal_setup
from ...paths import exact_paths
from ...radar.phasors import bin_response
from ...radar.processing import refine_angles, tdm_compensate
from ...radar.steering import smoothed_estimator
from ...rts.channels import (KIND_DIRECT, RtsProgram, channel_echoes, fir_modelled, fir_taps,
                             requested_delay)
from ...scene import TargetConfig
from .subbin import centre_index, subbin_positions

__all__ = ["PairPhasors", "HALF_BINS", "PROBE_FRACTIONS", "response_table"]

HALF_BINS = 2  # candidate bins either side of the set range's (default scene; see build)
PROBE_FRACTIONS = (0.25, 0.75)  # calibrate_pair's probe angles across the span
_TABLE_BYTES = 64 * 2 ** 20  # peak of one block of response_table's temporaries


def response_table(setup: Setup, paths, channel: int, target: TargetConfig, resolution_s: float,
                   steps: np.ndarray, half_bins: int = HALF_BINS) -> np.ndarray:
    """Channel ``channel``'s TDM-compensated spectrum (unit programme amplitude) at the
    target's candidate range bins with its RTS delay offset by ``steps`` (D,) times
    ``resolution_s``: (D, 2 half_bins + 1, V). The programme goes through
    ``rts.channel_echoes`` (what the ADC-cube chain synthesizes) and
    ``radar.phasors.bin_response``, in blocks of bounded memory."""
    scene, radar, rut = setup.scene, setup.scene.radar, setup.rut
    steps = np.asarray(steps, int)
    # the cable ghosts land bins away and are dropped: not formed at all (the direct echoes
    # do not depend on the return losses; a fifth of the table's time was their copies); the
    # fractional-delay FIR not formed along the chirp (an ideal delay for channel_echoes) but
    # as its taps' whole-sample copies (rts.fir_taps): bin_response then sums a few dozen
    # tones per geometry instead of every echo's N samples (a design's tables 74 -> 15 ms)
    fes = tuple(dataclasses.replace(f, return_loss_fe_db=None) for f in scene.rts.front_ends)
    setup = dataclasses.replace(setup, scene=dataclasses.replace(
        scene, rts=dataclasses.replace(scene.rts, front_ends=fes,
                                       fractional_delay_filter="ideal")))
    tau = float(requested_delay(scene, target.range_m))
    r0 = int(np.round(target.range_m / radar.range_resolution_m))
    rbins = np.arange(r0 - half_bins, r0 + half_bins + 1) % radar.samples_per_chirp
    dbin = np.full(rbins.size, radar.chirps_per_tx // 2)  # velocity 0
    # memory per delay step: per echo (one per path combination of the two legs) the
    # fast-time tones and their FIR gain, (N,) each per element; or with the taps (T,)
    # weights and the (V K) sums, plus the tones at the whole-sample delays the block spans
    # (res / t_s of them per step, (N,) each, three arrays)
    per_step = len(channel_echoes(setup, paths, RtsProgram.build(
        [0], [channel], [tau], [0.0], [1.0])))
    n_s, n_taps = radar.samples_per_chirp, scene.rts.fractional_delay_taps
    row = (per_step * 16 * rut.num_virtual * n_s * 4 if not fir_modelled(scene) else
           per_step * 16 * (2 * n_taps + 4 * rut.num_virtual * rbins.size)
           + 48 * n_s * resolution_s * scene.rts.f_s_hz)
    block = max(1, int(_TABLE_BYTES // row))
    out = np.empty((steps.size, rbins.size, rut.num_virtual), complex)
    for b in range(0, steps.size, block):
        k = steps[b:b + block]
        prog = RtsProgram.build(np.arange(k.size), np.full(k.size, channel),
                                tau + k * resolution_s, np.zeros(k.size), np.ones(k.size))
        ech = channel_echoes(setup, paths, prog)
        ech = ech.select(ech.kind == KIND_DIRECT)  # (none other: see above)
        # (what channel_echoes forms as fast_gain: rts.fir_if_gain of the same delays)
        fir = fir_taps(scene, ech.tau_if_s, ech.tau_if_s + ech.tau_air_s.mean(axis=1))
        resp = bin_response(ech, radar, rut, rbins, dbin, fir)  # (K, E, V)
        acc = np.zeros((k.size,) + resp.shape[::2], complex)  # each target's echoes summed
        np.add.at(acc, ech.target, np.swapaxes(resp, 0, 1))  # (a one-hot einsum was 15 %)
        out[b:b + block] = acc
    return tdm_compensate(out, 0.0, rut, radar)


def _readonly(a: np.ndarray) -> np.ndarray:
    """``a`` made read-only in place (an array this module made and shares with no one)."""
    a.flags.writeable = False
    return a


def _set_beams(st, rows: np.ndarray, sets: np.ndarray) -> np.ndarray:
    """Beam responses and their first two derivatives in u at the set angles of table rows
    (R, K, V): (R, 3, M, K), contiguous per row (a draw's lookup copies one block)."""
    w = st.weighted(rows)  # (R, K, V_s)
    kv = st.wavevector[:, 0]
    e = np.exp(1j * kv * np.sin(sets)[:, None])  # (M, V_s)
    # the three sums over the elements as one product (R K, V_s) x (V_s, 3 M) (broadcasting
    # the (R, K, M, V_s) products was 10 % of a design; numpy's einsum loops 4x this product,
    # run with single-threaded BLAS by PairPhasors.build)
    ops = np.concatenate([e, 1j * kv * e, -(kv * kv) * e]).T  # (V_s, 3 M)
    r, k = w.shape[:2]
    beams = (w.reshape(r * k, -1) @ ops).reshape(r, k, 3, sets.size)
    return np.ascontiguousarray(np.moveaxis(beams, 1, -1))


@dataclass(frozen=True)
class _Design:
    """The exact closed-form design (``aoa.sweep.ratio_from_beams``) for the bin the RuT
    detects (``aoa.sweep.detected_bin_choice``), from tables of the channels' beam responses
    at the set angles, so that a draw's redesign for its calibration delay is a lookup and a
    quadratic: ``beams_i``, ``beams_j`` (rows, 3, M, K) (b, b', b'' per table row; I's from
    row ``i0`` on, the rows it can sit at), ``power`` (2, D, K) each
    channel's power over the elements, ``p_one`` (U,) channel I alone at its peak per sub-bin
    position (the power normalisation, ``ChannelModel.scale``)."""

    beams_i: np.ndarray  # (D_i, 3, M, K) channel I from table row i0 on
    beams_j: np.ndarray  # (D, 3, M, K) channel J
    i0: int
    power: np.ndarray
    p_one: np.ndarray
    probe_beams: np.ndarray  # (2, D, P) beam responses at the probes, the set range's bin
    unit_gain: float
    reach: int  # design bins either side of the set range's (the table has one more)

    def phase(self, row_i, row_j) -> np.ndarray:
        """J's phase the calibration establishes, (n,), as the operator's nominal model sees it
        with I at ``row_i`` and J at ``row_j`` (``ChannelModel.coherent_phases``: the circular
        mean over the probes; ``aoa.plan.pair_amplitudes`` designs for it)."""
        z = self.probe_beams[0][row_i] * np.conj(self.probe_beams[1][row_j])  # (n, P)
        mag = np.abs(z)
        return np.angle(np.sum(z / np.where(mag > 0, mag, 1.0), axis=-1))

    def _bins(self, reach: int) -> tuple[int, int]:
        """The first and the number of the bins compared with ``reach`` design bins either
        side of the set range's (the detection compared one bin further)."""
        return self.beams_j.shape[-1] // 2 - reach - 1, 2 * reach + 3

    def _args(self, table):
        return (self.beams_i, self.beams_j, self.i0, table, self.power, self.p_one,
                float(self.unit_gain))

    def __call__(self, table, row_i, row_j, sub, reach: int | None = None, sp=None):
        """Programme amplitudes (n, M, 2), the design bin (n, M, index into the table's K),
        whether design and detection agree (n, M) and the detected bin's power over the next
        strongest (n, M) for channel I at table row ``row_i`` (n,), J at ``row_j`` (n,), sub-bin
        position index ``sub`` (n,); designs in the ``reach`` bins either side of the set
        range's (default :attr:`reach`), the detection compared one bin further. ``sp`` (n,):
        one set-point per row instead of all (M = 1). Compiled per draw and set-point
        (``rtsgeom.synthesis.kernels.design_rows``: ``ratio_from_beams`` and ``detected_bin_choice``
        for one set-point, without the batch's temporaries)."""
        from .kernels import design_rows
        row_i, row_j, sub = (np.ascontiguousarray(a, np.int64) for a in (row_i, row_j, sub))
        lo, n_k = self._bins(self.reach if reach is None else reach)
        n = row_i.size
        m = self.beams_j.shape[2] if sp is None else 1
        sp = np.zeros(0, np.int64) if sp is None else np.ascontiguousarray(sp, np.int64)
        amps, k = np.empty((n, m, 2)), np.empty((n, m), np.int64)
        ok, margin = np.empty((n, m), bool), np.empty((n, m))
        design_rows(*self._args(table), row_i, row_j, sub,
                    np.exp(1j * self.phase(row_i, row_j)), sp, lo, n_k, amps, k, ok, margin)
        return amps, k, ok, margin

    def planned(self, table, row_i, row_j, sub, period_steps: int, reach_far: int):
        """``aoa.plan.pair_design``'s choice of J's delay, per set-point: the calibrated one
        (row ``row_j``) or one period of the IF phase either side (m = 0, -1, 1: the same
        phase, J's echo about a bin further), the first whose design the RuT detects at the
        bin it was designed for with a power margin above ``plan.MIN_BIN_MARGIN``, else the
        best (consistent, margin, smallest |m|). Returns amplitudes (n, M, 2) and m (n, M).
        Compiled per draw and set-point (``rtsgeom.synthesis.kernels.plan_rows``)."""
        from ...pipeline.plan import MIN_BIN_MARGIN
        from .kernels import plan_rows
        row_i, row_j, sub = (np.ascontiguousarray(a, np.int64) for a in (row_i, row_j, sub))
        p = int(period_steps)
        e = np.exp(1j * np.stack([self.phase(row_i, row_j + s * p) for s in (0, -1, 1)]))
        n, m = row_i.size, self.beams_j.shape[2]
        amps, shift = np.empty((n, m, 2)), np.empty((n, m), np.int64)
        plan_rows(*self._args(table), row_i, row_j, sub, e, p, *self._bins(self.reach),
                  *self._bins(int(reach_far)), float(MIN_BIN_MARGIN), amps, shift)
        return amps, shift


def reference_target(nominal: Setup, range_m: float | None = None) -> TargetConfig:
    """The tolerance studies' reference target: at the centre of the range bin nearest
    ``range_m`` (default: the calibration's first probe range), velocity 0, boresight."""
    bin_m = nominal.scene.radar.range_resolution_m
    r0 = float(probe_ranges(nominal, 1)[0]) if range_m is None else float(range_m)
    return TargetConfig(max(round(r0 / bin_m), 1) * bin_m)


#: Largest |d ln|x| / d tau * shift| the first-order slide applies (see :func:`slide`).
MAX_SLIDE = 0.5


def slide(log_slope, shift_s):
    """exp(d ln|x|/d tau * shift): the first-order change of a spectrum's magnitude as the
    draw's air delay slides the echo along the range window. The log slope is unbounded at the
    window's spectral nulls (a Hann window has them two bins from an echo at a bin centre), where
    exp() of it blew an empty bin up into the strongest one (a phantom detection two bins off);
    the exponent is limited to +-MAX_SLIDE (and NaN at an exact null to 0), which leaves every
    regular bin bit-identical (exponents ~1e-4) and keeps a null bin near null. (In place on
    one temporary: ``nan_to_num`` then ``clip`` made five passes, 4 % of a draw.)"""
    x = np.asarray(log_slope * shift_s, float)
    np.clip(x, -MAX_SLIDE, MAX_SLIDE, out=x)  # +-inf to the bounds; NaN stays NaN ...
    x[np.isnan(x)] = 0.0  # ... and becomes 0
    return np.exp(x, out=x)


@dataclass(frozen=True)
class PairPhasors:
    """The design (set-points, amplitudes per sub-bin position) and the response tables of one
    front-end pair on its nominal :class:`~rtsgeom.synthesis.model.ChannelModel` (``channels``).

    ``table[q, j]``: channel q (0: I, 1: J) with RTS delay offset ``(j - table_zero)`` steps,
    (K, V) at the candidate bins (middle: the set range's). ``subbin_steps`` (U,): the target's
    possible sub-bin positions (delay steps, one range bin, centred on 0); ``design_amplitudes``
    (U, M, 2) and ``design_bin`` (U, M) the design at each. ``amplitudes``, ``delay_factor``
    and ``delay_log_slope`` are the bin-centre special case (u = 0, the set range's bin)."""

    channels: ChannelModel  # Q = 2, on the nominal setup, target at the bin centre
    fe_angle_rad: np.ndarray  # (2,) each front end alone, detected (nominal, phasor level)
    set_rad: np.ndarray  # (M,) set-points, ends of the span excluded
    probe_rad: np.ndarray  # (2,) calibration probes
    amplitudes: np.ndarray  # (M, 2) designed A_I, A_J at the bin centre
    delay_factor: np.ndarray  # (2 S + 1, V) J's response to a delay offset, bin centre
    delay_log_slope: np.ndarray  # (2 S + 1, V) d ln|delay_factor| / d tau (1/s)
    cal_slope_hz: float  # f_rts + B/2: eq. (27)
    delay_resolution_s: float
    table: np.ndarray  # (2, D, K, V)
    table_log_slope: np.ndarray  # (2, D, K, V) Re d ln table / d tau (1/s)
    table_zero: int  # index of delay offset 0 in the table
    subbin_steps: np.ndarray  # (U,) int
    design_amplitudes: np.ndarray  # (U, M, 2)
    design_bin: np.ndarray  # (U, M) index into K
    design_consistent: np.ndarray  # (U, M) design and detection agree on the bin
    design: "_Design"  # the exact design for any (sub-bin, J delay) row pair
    period_steps: int = 0  # J's IF phase period in delay steps (plan's alternative delays)
    reach_far: int = 1  # bins J's echo can reach with a period's shift

    @classmethod
    def build(cls, setup: Setup, pair: tuple[int, int], points: int = 21,
              range_m: float | None = None, solve_bin_centre: bool = True) -> "PairPhasors":
        """Design on the nominal setup of ``setup`` (its mounting and channel errors dropped).

        The reference target sits at the centre of the range bin nearest ``range_m`` (default:
        the calibration's first probe range), velocity 0; a draw moves it within the bin
        (:attr:`subbin_steps`). The set-points divide the span between the two front ends'
        detected angles into ``points + 1`` parts (ends excluded, as ``aoa.linearity``).

        ``solve_bin_centre`` False: the set-points without a closed-form design at the bin
        centre are left NaN (:meth:`solved` designs them; ``analysis.design`` first checks
        whether the calibrated plan exists at all).

        BLAS single-threaded: the tables' products are many and small (two threads took 2.4x
        the CPU time of one for the same build).

        :class:`~rtsgeom.scene.scene.SceneError` for an estimator that does not peak where the
        beamformer does (Capon or MUSIC with spatial smoothing): the design is the closed
        form for the beamformer's peak (``aoa.sweep.ratio_from_beams``) and the draws'
        angles are its peak; those estimators' are not modelled (the ADC chain, ``calibrate``
        and ``linearity``, runs them)."""
        radar = setup.scene.radar
        if smoothed_estimator(radar.angle_estimator, radar.angle_subarray):
            from ...errors import SceneError
            raise SceneError(
                f"radar.angle_estimator = {radar.angle_estimator} with radar.angle_subarray = "
                f"{radar.angle_subarray}: the tolerance model (tolerance, design) designs the "
                "amplitudes in closed form for the beamformer's peak and estimates the draws' "
                "angles there; a smoothed Capon or MUSIC peaks elsewhere (0.37 deg on the "
                "default scene), which it does not model: set angle_subarray = 0 (both then "
                "peak where the beamformer does) or use the ADC chain (calibrate, linearity)")
        with single_threaded_blas():
            model = cls._build(setup, pair, points, range_m)
        return model.solved() if solve_bin_centre else model

    def solved(self) -> "PairPhasors":
        """The model with the bin-centre set-points that have no closed-form design (spacings
        beyond the beam's resolution) designed by ``ChannelModel.solve``'s root finder on the
        searched peak (:class:`~rtsgeom.synthesis.model.AngleUnreachable` where even that fails);
        elsewhere in the bin they stay NaN, which fails the spec. (A root finder per set-point:
        most of the build of such a design.)"""
        c0 = self.subbin_zero
        missing = np.flatnonzero(~np.isfinite(self.design_amplitudes[c0]).all(-1))
        if missing.size == 0:
            return self
        amps = np.array(self.design_amplitudes)
        model = self.channels
        with single_threaded_blas():
            phases = (0.0, float(model.pair_phase(self.probe_rad)))
            for m in missing:
                a = float(self.set_rad[m])
                amps[c0, m] = model.amplitudes(
                    model.pair_weights(model.pair_ratio(a, phases), phases), np.sin([a]))
        return dataclasses.replace(self, amplitudes=frozen(amps[c0]),
                                   design_amplitudes=frozen(amps))

    @classmethod
    def _build(cls, setup: Setup, pair: tuple[int, int], points: int,
               range_m: float | None) -> "PairPhasors":
        nom = nominal_setup(setup)
        radar, rts = nom.scene.radar, nom.scene.rts
        pair = (int(pair[0]), int(pair[1]))
        target = reference_target(nom, range_m)
        paths = exact_paths(nom)
        model = ChannelModel.build(nom, paths, pair, target)
        st = model.steering
        th = st.search(model.phasors)
        frac = np.arange(1, points + 1) / (points + 1)
        sets = th[0] + frac * (th[1] - th[0])
        probes = th[0] + np.asarray(PROBE_FRACTIONS) * (th[1] - th[0])
        res = rts.delay_resolution_s
        slope = rts.f_rts_hz + 0.5 * radar.bandwidth_hz
        max_steps = int(np.ceil(0.5 / (slope * res))) + 4
        sub = subbin_positions(radar.range_resolution_m, res)  # the target's places in its bin
        n_bin = sub.size  # delay steps per range bin
        # the exact period of J's IF phase at the target (eq. 27 refined), as aoa.plan uses it
        period = 1.0 / float(if_phase_slope_hz(nom.scene, 2 * target.range_m / c))
        p_steps = int(round(period / res))
        half = n_bin // 2 + max_steps + p_steps + 2
        d = np.arange(-half, half + 1)
        # J's echo lies at most (n_bin // 2 + max_steps [+ a period]) / n_bin bins from the set
        # range's (sub-bin position plus the calibration delay [plus plan's period shift]):
        # its nearest bin, `reach`, bounds where the combined peak (between the echoes) is
        # detected; the designs there, the detection compared one bin further
        reach = max(1, int(np.floor((n_bin // 2 + max_steps) / n_bin + 0.5)))
        reach_far = max(1, int(np.floor((n_bin // 2 + max_steps + p_steps) / n_bin + 0.5)))
        nb = reach_far + 1
        t_j = response_table(nom, paths, pair[1], target, res, d, nb)
        # I only ever sits at the sub-bin positions (+-1 row for the slope): the rows beyond
        # are never read (edge copies keep the array rectangular)
        near = np.clip(d, -(n_bin // 2) - 1, n_bin // 2 + 1)
        lo = int(near.min())
        t_i = response_table(nom, paths, pair[0], target, res, np.arange(lo, -lo + 1), nb)
        table = np.stack([t_i[near - lo], t_j])
        with np.errstate(divide="ignore"):
            log_slope = np.gradient(np.log(np.abs(table)), res, axis=1)
        z = half
        # beam responses and derivatives at the set angles: J on every table row, I on the
        # rows it can sit at (from i0 on)
        i0 = z - n_bin // 2 - 1
        beams_i = _set_beams(st, table[0, i0:z + n_bin // 2 + 2], sets)
        beams_j = _set_beams(st, table[1], sets)
        power = np.sum(table.real ** 2 + table.imag ** 2, -1)  # (2, D, K)
        x_i = table[0, z + sub]  # (U, K, V)
        k_one = np.argmax(power[0, z + sub], -1)  # (U,) I alone: its strongest bin
        one = x_i[np.arange(sub.size), k_one]  # (U, V)
        u_one, _ = st.peak(one, st.directions(np.full(sub.size, th[0])))
        b_one, _, _ = beam_derivatives(st, one, u_one[:, 0])
        p_one = np.abs(b_one) ** 2  # (U,)
        probe_beams = st.beam(table[:, :, nb], st.directions(probes))  # (2, D, P)
        # the tables were made here and nothing else holds them: read-only in place (frozen()
        # would copy ~50 MiB per design; the table after its design below, whose kernel was
        # compiled for a writeable one)
        log_slope, beams_i, beams_j = (_readonly(a) for a in (log_slope, beams_i, beams_j))
        design = _Design(beams_i, beams_j, i0, frozen(power), frozen(p_one),
                         frozen(probe_beams), model.unit_gain, reach)
        amps, kbin, ok, _ = design(table, z + sub, z + sub, np.arange(sub.size))
        table = _readonly(table)
        c0 = centre_index(sub)
        # (no closed-form design at the bin centre, spacings beyond the beam's resolution: NaN
        # here, designed by solved())
        ks = slice(z - max_steps, z + max_steps + 1)
        centre = nb
        factor = table[1, ks, centre] / table[1, z, centre]
        return cls(model, frozen(th), frozen(sets), frozen(probes), frozen(amps[c0]),
                   frozen(factor), frozen(log_slope[1, ks, centre]), slope, res,
                   table, log_slope, z, frozen(sub), frozen(amps),
                   frozen(kbin), frozen(ok), design, p_steps, reach_far)

    setup = property(lambda self: self.channels.setup)  # nominal
    pair = property(lambda self: self.channels.channels)
    range_m = property(lambda self: self.channels.range_m)
    x_nominal = property(lambda self: self.channels.phasors)  # (2, V)

    @property
    def max_steps(self) -> int:
        return (self.delay_factor.shape[0] - 1) // 2

    @property
    def subbin_zero(self) -> int:
        """Index of the bin centre in :attr:`subbin_steps`."""
        return centre_index(self.subbin_steps)

    # -- one draw's channels -------------------------------------------------------------

    def air_legs(self, offsets_m, pose: dict | None = None) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`ChannelModel.air_legs`: (..., 2, V) each for offsets (..., 2, 3); ``pose``:
        its rotation and RuT-pose keywords (``yaw_rad``, ``pitch_rad`` (..., 2),
        ``rut_offset_m`` (..., 3), ``rut_yaw_rad`` (...,))."""
        return self.channels.air_legs(offsets_m, **(pose or {}))

    def channel_phasors(self, offsets_m, return_shift: bool = False, pose: dict | None = None):
        """Per-element phasors of both channels at the bin centre for mounting errors
        (..., 2, 3) and ``pose`` (:meth:`ChannelModel.perturbed`). ``return_shift``: also the
        air delay change (..., 2, V) (s)."""
        return self.channels.perturbed(offsets_m, return_shift, **(pose or {}))

    def coherence_phase(self, xq: np.ndarray) -> np.ndarray:
        """The phase to give channel J so that both channels' beamformer outputs add in phase
        at the probe angles (the circular mean over the probes), (...,) for phasors
        (..., 2, V) (:meth:`ChannelModel.coherent_phases`). The amplitudes are designed for
        this one phase, the one the calibration establishes (``tests/test_design.py``)."""
        return self.channels.pair_phase(self.probe_rad, xq)

    def calibration_steps(self, xq: np.ndarray) -> np.ndarray:
        """The calibration of channel J, in delay-resolution steps (int, (...,)): the coherence
        phase (:meth:`coherence_phase`) as a delay by eq. (27), wrapped to the smallest
        |delay|, quantised, and refined by +-3 steps against the table's exact phase (what
        the calibration sweep, which measures the outcome, converges to)."""
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
        """Beamformer snapshots (..., M, V) at the set range's bin for a target at its centre
        (the bin-centre special case, without the bin selection of :meth:`draw_errors`).
        ``steps`` (...,): J's calibration delay in steps, None: uncalibrated (calibrated:
        with the gain correction, and with ``redesign`` J's amplitude divided by the delay's
        loss at the bin); ``shift_s`` (..., 2, V): the draw's air delay change, moving J's
        echo along the window's slope (first order)."""
        x_i, x_j = xq[..., 0, :], xq[..., 1, :]
        a_i, a_j = self.amplitudes[:, 0], self.amplitudes[:, 1]  # (M,)
        if steps is not None:
            g = self.gain_correction(xq)  # (..., 2)
            k = np.asarray(steps) + self.max_steps
            f = self.delay_factor[k]  # (..., V)
            if redesign:  # from the nominal model: the operator does not know the shift
                g[..., 1] /= np.abs(f[..., self.channels.steering.mask].mean(axis=-1))
            if shift_s is not None:
                f = f * slide(self.delay_log_slope[k], shift_s[..., 1, :])
            x_j = x_j * f
            a_i, a_j = a_i * g[..., 0, None], a_j * g[..., 1, None]  # (..., M)
        return a_i[..., None] * x_i[..., None, :] + a_j[..., None] * x_j[..., None, :]

    # -- the draw as the RuT detects it ------------------------------------------------------

    def draw_errors(self, offsets_m, subbin=None, cases=("calibrated",), pose: dict | None = None,
                    return_detail: bool = False):
        """Detected minus set angle (rad) per case, {case: (n, M)}, for mounting errors
        ``offsets_m`` (n, 2, 3) and sub-bin positions ``subbin`` (n,) (indices into
        :attr:`subbin_steps`; None: the bin centre). With ``return_detail`` also
        {"steps": (n,), "converged": {case: (n, M)}, "bin": {case: (n, M)},
        "amplitudes": {case: (n, M, 2)}} (the detected bin as an offset from the set range's,
        the programme amplitudes)."""
        from .kernels import detect_rows
        offsets_m = np.asarray(offsets_m, float)
        n = offsets_m.shape[0]
        u = np.full(n, self.subbin_zero) if subbin is None else np.asarray(subbin, int)
        xq, shift = self.channel_phasors(offsets_m, return_shift=True, pose=pose)
        nom = self.x_nominal
        fac = xq / np.where(nom != 0, nom, 1.0)  # the draw's factor per channel and element
        steps = self.calibration_steps(xq)
        g = self.gain_correction(xq)
        d_u = self.subbin_steps[u]  # (n,)
        z = self.table_zero

        def spectrum(q, j):  # (n, K, V); in place on the gathered rows (the same products)
            x = self.table[q, j]
            x *= fac[:, q, None, :]
            x *= slide(self.table_log_slope[q, j], shift[:, q, None, :])
            return x

        x_i = spectrum(0, z + d_u)
        amps0 = self.design_amplitudes[u]  # (n, M, 2)
        out, detail = {}, {"steps": steps, "converged": {}, "bin": {}, "amplitudes": {},
                           "j_steps": {}}
        for case in cases:
            cal = case != "uncalibrated"
            j = z + d_u + (steps if cal else 0)
            m = np.zeros((n, self.set_rad.size), int)
            if case == "calibrated":  # designed for the known delay, for the RuT's bin
                amps, m = self.design.planned(self.table, z + d_u, j, u, self.period_steps,
                                              self.reach_far)
                a_i, a_j = amps[..., 0], amps[..., 1]
            else:
                a_i, a_j = amps0[..., 0], amps0[..., 1]
            if cal:
                a_i, a_j = a_i * g[:, 0, None], a_j * g[:, 1, None]
            shifts = (0, -1, 1) if np.any(m) else (0,)  # J's alternative delays (plan)
            x_j = np.stack([spectrum(1, j + s_ * self.period_steps) for s_ in shifts])
            sel = np.where(m == -1, 1, np.where(m == 1, 2, 0))  # (n, M) index into shifts
            # the RuT's bin (the strongest) and the snapshot there, (n, M) and (n, M, V)
            snaps = np.empty(sel.shape + x_i.shape[-1:], complex)
            det = np.empty(sel.shape, np.int64)
            detect_rows(x_i, x_j, sel, np.ascontiguousarray(a_i), np.ascontiguousarray(a_j),
                        snaps, det)
            ang, ok = refine_angles(snaps, self.channels.steering, None, self.set_rad,
                                    return_converged=True)
            out[case] = ang - self.set_rad
            detail["converged"][case] = ok
            detail["bin"][case] = det - self.table.shape[2] // 2
            detail["amplitudes"][case] = np.stack([a_i, a_j], -1)
            detail["j_steps"][case] = (j - z - d_u)[:, None] + m * self.period_steps
        return (out, detail) if return_detail else out

    def angle_errors(self, offsets_m, case: str = "calibrated", return_converged: bool = False,
                     subbin=None):
        """Detected minus set angle (deg), (..., M), for mounting errors (..., 2, 3), the target
        at sub-bin position ``subbin`` (indices into :attr:`subbin_steps`, default the bin
        centre) (:meth:`draw_errors`)."""
        off = np.asarray(offsets_m, float)
        lead = off.shape[:-2]
        flat = off.reshape((-1, 2, 3))
        sb = None if subbin is None else np.broadcast_to(subbin, lead).reshape(-1)
        err, det = self.draw_errors(flat, sb, (case,), return_detail=True)
        e = np.degrees(err[case]).reshape(lead + (-1,))
        ok = det["converged"][case].reshape(lead + (-1,))
        return (e, ok) if return_converged else e

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
            "subbin_positions": int(self.subbin_steps.size),
            "design_bins_consistent": float(np.mean(self.design_consistent)),
        }
