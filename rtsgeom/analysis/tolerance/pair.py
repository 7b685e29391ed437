"""The front-end pair's procedure in the tolerance model (Q = 2, D = 1): its calibration and its
design per draw in closed form, as ``rtsgeom run`` plans a pair (paper eqs. 14-27).

The operator designs the amplitudes of the set-points on the nominal setup
(:class:`~rtsgeom.synthesis.model.ChannelModel`), for the phase the calibration establishes
(:meth:`PairProcedure.coherence_phase`) and **for the range bin the RuT detects**; the RuT sees
the setup as built. The target's sub-bin position moves channel I to ``table[0, u]`` and
channel J to ``table[1, u + k]`` with ``k`` its calibration delay; the delay moves J's echo by
``c0 k dtau / 2`` in range (paper "Disadvantages"), so two bins can carry nearly equal power.
The bin logic is the RuT's: the detected bin is the strongest candidate (power summed over the
virtual elements), and the design is made for the bin the RuT then detects
(:func:`rtsgeom.synthesis.pair.design_at_detected_bin`, shared with ``ChannelModel.solve`` and
the calibration sweep), from tables of the channels' beam responses at the set angles, so that
a draw's redesign is a lookup and a quadratic (compiled: :mod:`.kernels`).

Calibration at phasor level, as the paper's two steps: amplitude (each channel's power over
the virtual channels against the model's, ``probe_front_ends``) and delay (channel J's offset
that makes both channels' beamformer outputs coherent at the probe angles, eq. (27), quantised
and refined on the table's exact phase: :meth:`PairProcedure.calibration_steps`). In the case
``calibrated`` the operator then plans each set-point as the planner does
(:func:`rtsgeom.pipeline.pair.plan_pair`): the exact design on the nominal model with J at the
calibrated delay, for the bin the RuT detects; where that bin is ambiguous (no consistent
design, or a power margin below ``MIN_BIN_MARGIN``) J's delay one IF period either side (the
same phase, the echo about a bin further) is tried. ``calibrated_nominal_amplitudes`` keeps the
design made without the delay (J at the target's own delay), which is also the
``uncalibrated`` design.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from scipy.constants import c

from ..._lib.util import frozen, single_threaded_blas
from ...calibration.probes import if_phase_slope_hz
from ...paths import exact_paths
from ...pipeline.pair import MIN_BIN_MARGIN
from ...radar.processing import refine_angles
from ...synthesis.model import ChannelModel
from ...synthesis.pair import beam_derivatives
from .draws import centre_index, subbin_positions
from .tables import readonly, response_table, slide

__all__ = ["PairProcedure", "PROBE_FRACTIONS", "build_pair"]

PROBE_FRACTIONS = (0.25, 0.75)  # calibrate_pair's probe angles across the span


def _set_beams(st, rows: np.ndarray, sets: np.ndarray) -> np.ndarray:
    """Beam responses and their first two derivatives in u at the set angles of table rows
    (R, K, V): (R, 3, M, K), contiguous per row (a draw's lookup copies one block)."""
    w = st.weighted(rows)  # (R, K, V_s)
    kv = st.wavevector[:, 0]
    e = np.exp(1j * kv * np.sin(sets)[:, None])  # (M, V_s)
    # the three sums over the elements as one product (R K, V_s) x (V_s, 3 M) (broadcasting
    # the (R, K, M, V_s) products was 10 % of a design; numpy's einsum loops 4x this product,
    # run with single-threaded BLAS by the build)
    ops = np.concatenate([e, 1j * kv * e, -(kv * kv) * e]).T  # (V_s, 3 M)
    r, k = w.shape[:2]
    beams = (w.reshape(r * k, -1) @ ops).reshape(r, k, 3, sets.size)
    return np.ascontiguousarray(np.moveaxis(beams, 1, -1))


@dataclass(frozen=True)
class _Design:
    """The exact closed-form design (``synthesis.pair.ratio_from_beams``) for the bin the RuT
    detects (``synthesis.pair.detected_bin_choice``), from tables of the channels' beam
    responses at the set angles: ``beams_i``, ``beams_j`` (rows, 3, M, K) (b, b', b'' per table
    row; I's from row ``i0`` on, the rows it can sit at), ``power`` (2, D, K) each channel's
    power over the elements, ``p_one`` (U,) channel I alone at its peak per sub-bin position
    (the power normalisation, ``ChannelModel.amplitudes``)."""

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
        mean over the probes)."""
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
        (:func:`.kernels.design_rows`)."""
        from .kernels import design_rows  # numba: imported with the first design
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
        """The planner's choice of J's delay, per set-point: the calibrated one (row
        ``row_j``) or one period of the IF phase either side (m = 0, -1, 1: the same phase,
        J's echo about a bin further), the first whose design the RuT detects at the bin it
        was designed for with a power margin above ``MIN_BIN_MARGIN``, else the best
        (consistent, margin, smallest |m|). Returns amplitudes (n, M, 2) and m (n, M).
        Compiled per draw and set-point (:func:`.kernels.plan_rows`)."""
        from .kernels import plan_rows  # numba: imported with the first design
        row_i, row_j, sub = (np.ascontiguousarray(a, np.int64) for a in (row_i, row_j, sub))
        p = int(period_steps)
        e = np.exp(1j * np.stack([self.phase(row_i, row_j + s * p) for s in (0, -1, 1)]))
        n, m = row_i.size, self.beams_j.shape[2]
        amps, shift = np.empty((n, m, 2)), np.empty((n, m), np.int64)
        plan_rows(*self._args(table), row_i, row_j, sub, e, p, *self._bins(self.reach),
                  *self._bins(int(reach_far)), float(MIN_BIN_MARGIN), amps, shift)
        return amps, shift


@dataclass(frozen=True)
class PairProcedure:
    """What the operator of a front-end pair does at phasor level (module docstring): the
    probes, J's delay tables, the design per sub-bin position and the design kernels.
    ``delay_factor`` and ``delay_log_slope`` are J's response to a delay offset at the bin
    centre (u = 0, the set range's bin)."""

    fe_angle_rad: np.ndarray  # (2,) each front end alone, detected (nominal, phasor level)
    probe_rad: np.ndarray  # (2,) calibration probes
    delay_factor: np.ndarray  # (2 S + 1, V) J's response to a delay offset, bin centre
    delay_log_slope: np.ndarray  # (2 S + 1, V) d ln|delay_factor| / d tau (1/s)
    design_amplitudes: np.ndarray  # (U, M, 2)
    design_bin: np.ndarray  # (U, M) index into K
    design_consistent: np.ndarray  # (U, M) design and detection agree on the bin
    design: _Design  # the exact design for any (sub-bin, J delay) row pair
    period_steps: int = 0  # J's IF phase period in delay steps (the planner's alternatives)
    reach_far: int = 1  # bins J's echo can reach with a period's shift
    #: draws per block of a chunk: the temporaries (draws x set-points x bins) stay below
    #: glibc's mmap threshold, which saves the page-fault system time of 10 000-draw blocks;
    #: row-wise arithmetic only, so the bits do not depend on it
    block_draws: int = 1000

    @property
    def max_steps(self) -> int:
        return (self.delay_factor.shape[0] - 1) // 2

    def coherence_phase(self, ph, xq: np.ndarray) -> np.ndarray:
        """The phase to give channel J so that both channels' beamformer outputs add in phase
        at the probe angles (the circular mean over the probes), (...,) for phasors
        (..., 2, V) (:meth:`ChannelModel.pair_phase`). The amplitudes are designed for
        this one phase, the one the calibration establishes."""
        return ph.channels.pair_phase(self.probe_rad, xq)

    def calibration_steps(self, ph, xq: np.ndarray) -> np.ndarray:
        """The calibration of channel J, in delay-resolution steps (int, (...,)): the coherence
        phase (:meth:`coherence_phase`) as a delay by eq. (27), wrapped to the smallest
        |delay|, quantised, and refined by +-3 steps against the table's exact phase (what
        the calibration sweep, which measures the outcome, converges to)."""
        phi = self.coherence_phase(ph, xq)
        k0 = np.round(phi / (2 * np.pi * ph.cal_slope_hz * ph.delay_resolution_s))
        cand = np.clip(k0[..., None].astype(int) + np.arange(-3, 4), -self.max_steps,
                       self.max_steps)
        table_phase = np.angle(self.delay_factor[:, ph.channels.steering.mask].mean(axis=1))
        miss = np.abs(np.angle(np.exp(1j * (phi[..., None] - table_phase[cand + self.max_steps]))))
        return np.take_along_axis(cand, np.argmin(miss, axis=-1)[..., None], axis=-1)[..., 0]

    def snapshots(self, ph, xq: np.ndarray, steps=None, redesign: bool = True,
                  shift_s=None) -> np.ndarray:
        """Beamformer snapshots (..., M, V) at the set range's bin for a target at its centre
        (the bin-centre special case, without the bin selection of :meth:`draw`). ``steps``
        (...,): J's calibration delay in steps, None: uncalibrated (calibrated: with the gain
        correction, and with ``redesign`` J's amplitude divided by the delay's loss at the
        bin); ``shift_s`` (..., 2, V): the draw's air delay change, moving J's echo along the
        window's slope (first order)."""
        x_i, x_j = xq[..., 0, :], xq[..., 1, :]
        a_i, a_j = ph.amplitudes[:, 0], ph.amplitudes[:, 1]  # (M,)
        if steps is not None:
            g = ph.gain_correction(xq)  # (..., 2)
            k = np.asarray(steps) + self.max_steps
            f = self.delay_factor[k]  # (..., V)
            if redesign:  # from the nominal model: the operator does not know the shift
                g[..., 1] /= np.abs(f[..., ph.channels.steering.mask].mean(axis=-1))
            if shift_s is not None:
                f = f * slide(self.delay_log_slope[k], shift_s[..., 1, :])
            x_j = x_j * f
            a_i, a_j = a_i * g[..., 0, None], a_j * g[..., 1, None]  # (..., M)
        return a_i[..., None] * x_i[..., None, :] + a_j[..., None] * x_j[..., None, :]

    def draw(self, ph, offsets_m, u, cases, pose) -> dict:
        """:meth:`ChannelPhasors.draw <.phasors.ChannelPhasors.draw>` for the pair: per case
        the detected minus set angle (n, M) rad, whether Newton converged, the detected bin
        (offset from the set range's), the programme amplitudes (n, M, 2) and J's delay as
        planned (n, M) in steps; the calibration steps (n, 2)."""
        from .kernels import detect_rows  # numba: imported with the first design
        n = offsets_m.shape[0]
        xq, shift = ph.channel_phasors(offsets_m, return_shift=True, pose=pose)
        nom = ph.x_nominal
        fac = xq / np.where(nom != 0, nom, 1.0)  # the draw's factor per channel and element
        steps = self.calibration_steps(ph, xq)
        g = ph.gain_correction(xq)
        d_u = ph.subbin_steps[u]  # (n,)
        z = ph.table_zero

        def spectrum(q, j):  # (n, K, V); in place on the gathered rows (the same products)
            x = ph.table[q, j]
            x *= fac[:, q, None, :]
            x *= slide(ph.table_log_slope[q, j], shift[:, q, None, :])
            return x

        x_i = spectrum(0, z + d_u)
        amps0 = self.design_amplitudes[u]  # (n, M, 2)
        out = {"steps": np.stack([np.zeros_like(steps), steps], -1)}
        for case in cases:
            cal = case != "uncalibrated"
            j = z + d_u + (steps if cal else 0)
            m = np.zeros((n, ph.set_rad.size), int)
            if case == "calibrated":  # designed for the known delay, for the RuT's bin
                amps, m = self.design.planned(ph.table, z + d_u, j, u, self.period_steps,
                                              self.reach_far)
                a_i, a_j = amps[..., 0], amps[..., 1]
            else:
                a_i, a_j = amps0[..., 0], amps0[..., 1]
            if cal:
                a_i, a_j = a_i * g[:, 0, None], a_j * g[:, 1, None]
            shifts = (0, -1, 1) if np.any(m) else (0,)  # J's alternative delays (planner)
            x_j = np.stack([spectrum(1, j + s_ * self.period_steps) for s_ in shifts])
            sel = np.where(m == -1, 1, np.where(m == 1, 2, 0))  # (n, M) index into shifts
            # the RuT's bin (the strongest) and the snapshot there, (n, M) and (n, M, V)
            snaps = np.empty(sel.shape + x_i.shape[-1:], complex)
            det = np.empty(sel.shape, np.int64)
            detect_rows(x_i, x_j, sel, np.ascontiguousarray(a_i), np.ascontiguousarray(a_j),
                        snaps, det)
            ang, ok = refine_angles(snaps, ph.channels.steering, None, ph.set_rad,
                                    return_converged=True)
            out[case] = {"error_rad": ang - ph.set_rad, "converged": ok,
                         "bin": det - ph.table.shape[2] // 2,
                         "amplitudes": np.stack([a_i, a_j], -1),
                         "j_steps": (j - z - d_u)[:, None] + m * self.period_steps}
        return out

    def solved(self, ph):
        """``ph`` with the bin-centre set-points that have no closed-form design (spacings
        beyond the beam's resolution) designed by ``ChannelModel.solve``'s root finder on the
        searched peak (:class:`~rtsgeom.errors.AngleUnreachable` where even that fails);
        elsewhere in the bin they stay NaN, which fails the spec. (A root finder per
        set-point: most of the build of such a design.)"""
        c0 = ph.subbin_zero
        missing = np.flatnonzero(~np.isfinite(self.design_amplitudes[c0]).all(-1))
        if missing.size == 0:
            return ph
        amps = np.array(self.design_amplitudes)
        model = ph.channels
        with single_threaded_blas():
            phases = (0.0, float(model.pair_phase(self.probe_rad)))
            for m in missing:
                a = float(ph.set_rad[m])
                amps[c0, m] = model.amplitudes(
                    model.pair_weights(model.pair_ratio(a, phases), phases), np.sin([a]))
        return dataclasses.replace(ph, amplitudes=frozen(amps[c0]), procedure=dataclasses.replace(
            self, design_amplitudes=frozen(amps)))

    def to_dict(self, ph) -> dict:
        k = int(self.calibration_steps(ph, ph.x_nominal))
        return {
            "pair": list(ph.front_ends),
            "range_m": ph.range_m,
            "front_end_angles_deg": [float(a) for a in np.degrees(self.fe_angle_rad)],
            "set_points_deg": [float(a) for a in np.degrees(ph.set_rad)],
            "probe_angles_deg": [float(a) for a in np.degrees(self.probe_rad)],
            "nominal_delta_tau_s": k * ph.delay_resolution_s,
            "delay_resolution_s": ph.delay_resolution_s,
            "subbin_positions": int(ph.subbin_steps.size),
            "design_bins_consistent": float(np.mean(self.design_consistent)),
        }


def build_pair(nom, pair: tuple[int, int], points: int, target, set_rad=None) -> dict:
    """The fields of a pair's :class:`~.phasors.ChannelPhasors` on the nominal setup ``nom``:
    the set-points divide the span between the two front ends' detected angles into
    ``points + 1`` parts (ends excluded, as the linearity study), or are ``set_rad`` (the
    azimuths a drive visits), the tables over J's delay
    (every sub-bin position, calibration delay and planner alternative), the design per
    sub-bin position (NaN where the closed form has none: ``PairProcedure.solved``)."""
    radar, rts = nom.scene.radar, nom.scene.rts
    paths = exact_paths(nom)
    model = ChannelModel.build(nom, paths, pair, target)
    st = model.steering
    th = st.search(model.phasors)
    frac = np.arange(1, points + 1) / (points + 1)
    sets = (th[0] + frac * (th[1] - th[0]) if set_rad is None
            else np.asarray(set_rad, float).reshape(-1))
    probes = th[0] + np.asarray(PROBE_FRACTIONS) * (th[1] - th[0])
    res = rts.delay_resolution_s
    slope = rts.f_rts_hz + 0.5 * radar.bandwidth_hz
    max_steps = int(np.ceil(0.5 / (slope * res))) + 4
    sub = subbin_positions(radar.range_resolution_m, res)  # the target's places in its bin
    n_bin = sub.size  # delay steps per range bin
    # the exact period of J's IF phase at the target (eq. 27 refined), as the planner uses it
    period = 1.0 / float(if_phase_slope_hz(nom.scene, 2 * target.range_m / c))
    p_steps = int(round(period / res))
    half = n_bin // 2 + max_steps + p_steps + 2
    d = np.arange(-half, half + 1)
    # J's echo lies at most (n_bin // 2 + max_steps [+ a period]) / n_bin bins from the set
    # range's (sub-bin position plus the calibration delay [plus the planner's period shift]):
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
    log_slope, beams_i, beams_j = (readonly(a) for a in (log_slope, beams_i, beams_j))
    design = _Design(beams_i, beams_j, i0, frozen(power), frozen(p_one),
                     frozen(probe_beams), model.unit_gain, reach)
    amps, kbin, ok, _ = design(table, z + sub, z + sub, np.arange(sub.size))
    table = readonly(table)
    c0 = centre_index(sub)
    # (no closed-form design at the bin centre, spacings beyond the beam's resolution: NaN
    # here, designed by solved())
    ks = slice(z - max_steps, z + max_steps + 1)
    centre = nb
    factor = table[1, ks, centre] / table[1, z, centre]
    procedure = PairProcedure(frozen(th), frozen(probes), frozen(factor),
                              frozen(log_slope[1, ks, centre]), frozen(amps), frozen(kbin),
                              frozen(ok), design, p_steps, reach_far)
    return dict(channels=model, set_rad=frozen(sets), amplitudes=frozen(amps[c0]), table=table,
                table_log_slope=log_slope, table_zero=z, subbin_steps=frozen(sub),
                delay_resolution_s=res, cal_slope_hz=slope, procedure=procedure)
