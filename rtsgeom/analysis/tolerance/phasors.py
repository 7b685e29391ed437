"""The tolerance model: a set of channels (a front-end pair on an arc, a cell of 3 or 4 front
ends on a sphere) under mounting errors, at phasor level (paper section "Arbitrary Angle of
Arrival", eqs. 14-27; "Constraints": a radial error of lambda/4 already cancels the composite).

The operator does not know the errors: the set-points are designed once on the nominal setup
(:class:`~rtsgeom.synthesis.model.ChannelModel`) and calibrated as the lab does; the RuT sees
the setup as built. Everything a draw needs is precomputed on the nominal setup as tables over
each channel's RTS delay (:mod:`.tables`), so that a draw is a few lookups and one angle
estimate per set-point. A draw's mounting errors enter at phasor level (eq. 15/16 with the exact
geometry, :meth:`ChannelModel.perturbed`)::

    x_qkv(draw) = table[q, D_q, k, v] * (a_qv b_qv / a'_qv b'_qv)
                  * exp(j 2 pi (f_c + S t_mid - S tau_t) d_qv) * exp(s_qkv d_qv)

with ``d = tau' - tau`` the air-delay change per element (exact legs) and ``s`` the real part
of d ln(table) / dD: the echo slides along the range window's slope by the air delay as it does
by an RTS delay (first order; the phase of that derivative is the IF slope, which the exact RF
term replaces). Neglected: second order in d (~1e-5 of the phasor at 0.3 mm). The target sits
at a sub-bin position drawn per draw (:mod:`.draws`), and the RuT picks the range bin.

What the operator does (calibrate, design) is the channel set's procedure: the pair's in closed
form per draw, redesigned for the bin the RuT detects and planned as the planner plans
(:class:`~.pair.PairProcedure`), a cell's peak-matched once on the nominal setup and calibrated
along a spanning tree of pairs (:class:`~.cell.CellProcedure`) -- as ``ChannelModel.solve``
has the pair's closed form as its fast path. ``rtsgeom tolerance --verify N`` and the tests
check the model against the full ADC-cube chain.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from scipy.constants import c

from ..._lib.util import single_threaded_blas
from ...errors import SceneError
from ...geometry import Setup
from ...geometry.setup import nominal_setup
from ...radar.steering import smoothed_estimator
from ...synthesis.model import ChannelModel
from .cell import CellProcedure, build_cell
from .draws import centre_index
from .pair import PairProcedure, build_pair
from .tables import reference_target

__all__ = ["ChannelPhasors", "CASES", "ALL_CASES", "NOMINAL_AMPLITUDES"]

CASES = ("uncalibrated", "calibrated")
# calibrated, but the nominal design's amplitudes kept (the calibration delay's range offset
# not designed for): what skipping that costs
NOMINAL_AMPLITUDES = "calibrated_nominal_amplitudes"
ALL_CASES = CASES + (NOMINAL_AMPLITUDES,)


@dataclass(frozen=True)
class ChannelPhasors:
    """The design (set-points, amplitudes) and the response tables of one channel set on its
    nominal :class:`~rtsgeom.synthesis.model.ChannelModel` (``channels``), and its procedure.

    ``table[q, j]``: channel q with RTS delay offset ``(j - table_zero)`` steps, (K, V) at the
    candidate bins (middle: the set range's). ``subbin_steps`` (U,): the target's possible
    sub-bin positions (delay steps, one range bin, centred on 0). ``set_rad``: (M,) azimuths
    (D = 1) or (M, 2) (azimuth, elevation); ``amplitudes`` (M, Q) the design at the bin
    centre.

    Attributes
    ----------
    channels : ChannelModel
        The nominal setup's channel set.
    set_rad : (M,) or (M, 2) float
        The set directions.
    subbin_steps : (S,) int
        The target's sub-bin positions (delay steps).
    delay_resolution_s : float
    """

    channels: ChannelModel  # on the nominal setup, target at the bin centre
    set_rad: np.ndarray
    amplitudes: np.ndarray  # (M, Q)
    table: np.ndarray  # (Q, D, K, V)
    table_log_slope: np.ndarray  # (Q, D, K, V) Re d ln table / d tau (1/s)
    table_zero: int  # index of delay offset 0 in the table
    subbin_steps: np.ndarray  # (U,) int
    delay_resolution_s: float
    cal_slope_hz: float  # f_rts + B/2: eq. (27)
    procedure: PairProcedure | CellProcedure

    @classmethod
    def build(cls, setup: Setup, channels=None, points: int = 21, range_m: float | None = None,
              solve_bin_centre: bool = True, cell: bool = False, set_rad=None
              ) -> "ChannelPhasors":
        """Design on the nominal setup of ``setup`` (its mounting and channel errors dropped)
        for the front ends ``channels`` (default all): a pair in azimuth (``points`` set-points
        across its span, ends excluded) or a cell of 3 or 4 in azimuth and elevation (about
        ``points`` set directions: a round(sqrt points)^2 grid, those inside the cell). The
        reference target sits at the centre of the range bin nearest ``range_m`` (default the
        calibration's first probe range), velocity 0; a draw moves it within the bin.

        ``cell``: a cell's procedure whatever the number of channels (it asks for 3 or 4, and
        a RuT that beamforms in elevation). ``set_rad``: a pair's set-points themselves
        (azimuths, rad) instead of ``points`` across its span. ``solve_bin_centre`` False: a pair's set-points without a closed-form design at the bin
        centre are left NaN (:meth:`PairProcedure.solved` designs them; the arc design first
        checks whether the calibrated plan exists at all). BLAS single-threaded: the tables'
        products are many and small.

        :class:`~rtsgeom.errors.SceneError` for an estimator that does not peak where the
        beamformer does (Capon or MUSIC with spatial smoothing): the design is the closed
        form for the beamformer's peak and the draws' angles are its peak."""
        radar = setup.scene.radar
        if smoothed_estimator(radar.angle_estimator, radar.angle_subarray):
            raise SceneError(
                f"radar.angle_estimator = {radar.angle_estimator} with radar.angle_subarray = "
                f"{radar.angle_subarray}: the tolerance model (tolerance, design) designs the "
                "amplitudes in closed form for the beamformer's peak and estimates the draws' "
                "angles there; a smoothed Capon or MUSIC peaks elsewhere (0.37 deg on the "
                "default scene), which it does not model: set angle_subarray = 0 (both then "
                "peak where the beamformer does) or use the ADC chain (calibrate, linearity)")
        nom = nominal_setup(setup)
        ch = (tuple(range(nom.fe.count)) if channels is None
              else tuple(int(q) for q in channels))
        target = reference_target(nom, range_m)
        with single_threaded_blas():
            if len(ch) == 2 and not cell:  # a pair on the arc: its closed form (fast path)
                model = cls(**build_pair(nom, ch, int(points), target, set_rad))
            else:
                grid = max(2, int(round(np.sqrt(points))))
                model = cls(**build_cell(nom, tuple(sorted(ch)), grid, target))
        if solve_bin_centre and isinstance(model.procedure, PairProcedure):
            return model.procedure.solved(model)
        return model

    setup = property(lambda self: self.channels.setup)  # nominal
    range_m = property(lambda self: self.channels.range_m)
    x_nominal = property(lambda self: self.channels.phasors)  # (Q, V)
    front_ends = property(lambda self: tuple(self.channels.channels))

    @property
    def dims(self) -> int:
        return self.channels.dims

    @property
    def subbin_zero(self) -> int:
        """Index of the bin centre in :attr:`subbin_steps`."""
        return centre_index(self.subbin_steps)

    @property
    def columns(self) -> tuple[str, ...]:
        """The per-draw numbers :meth:`evaluate` reports per case: the worst signed angle
        error (D = 1), or the worst signed azimuth and elevation errors and the largest
        angular distance (D = 2)."""
        return ("angle",) if self.dims == 1 else ("azimuth", "elevation", "angular_distance")

    # -- one draw's channels -----------------------------------------------------------------

    def air_legs(self, offsets_m, pose: dict | None = None) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`ChannelModel.air_legs`: (..., Q, V) each for offsets (..., Q, 3); ``pose``:
        its rotation and RuT-pose keywords (``yaw_rad``, ``pitch_rad`` (..., Q),
        ``rut_offset_m`` (..., 3), ``rut_yaw_rad`` (...,))."""
        return self.channels.air_legs(offsets_m, **(pose or {}))

    def channel_phasors(self, offsets_m, return_shift: bool = False, pose: dict | None = None):
        """Per-element phasors of the channels at the bin centre for mounting errors
        (..., Q, 3) and ``pose`` (:meth:`ChannelModel.perturbed`). ``return_shift``: also the
        air delay change (..., Q, V) (s)."""
        return self.channels.perturbed(offsets_m, return_shift, **(pose or {}))

    def gain_correction(self, xq: np.ndarray) -> np.ndarray:
        """The amplitude calibration (``probe_front_ends``): per channel the square root of
        modelled over measured power, the power summed over the virtual channels, (..., Q)."""
        p = np.sum(xq.real ** 2 + xq.imag ** 2, axis=-1)
        x0 = self.x_nominal
        return np.sqrt(np.sum(x0.real ** 2 + x0.imag ** 2, axis=-1) / p)

    def calibration_steps(self, xq: np.ndarray) -> np.ndarray:
        """Each channel's calibration delay in steps of the delay resolution, (..., Q) (the
        reference channel 0 at 0), as the procedure calibrates (the pair: J coherent with I at
        the probes; a cell: along its spanning tree)."""
        k = self.procedure.calibration_steps(self, xq)
        if isinstance(self.procedure, PairProcedure):
            return np.stack([np.zeros_like(k), k], -1)
        return k

    def range_offsets_m(self, offsets_m, steps, pose: dict | None = None) -> np.ndarray:
        """Each channel's echo's range offset from channel 0's after calibration: c0/2 times
        the element-mean air delay plus the channel's delay offset, (n, Q) (m)."""
        t_a, t_b = self.air_legs(offsets_m, pose)
        tot = (t_a + t_b).mean(-1) + np.asarray(steps) * self.delay_resolution_s  # (n, Q)
        return 0.5 * c * (tot - tot[:, :1])

    # -- the draw as the RuT detects it --------------------------------------------------------

    def draw(self, offsets_m, subbin=None, cases=CASES, pose: dict | None = None) -> dict:
        """For mounting errors ``offsets_m`` (n, Q, 3), ``pose`` (rotations and RuT pose of
        :meth:`air_legs`; None: none) and the target's sub-bin positions ``subbin`` (n,)
        (indices into :attr:`subbin_steps`; None: the bin centre): the calibration ``steps``
        (n, Q) and per case ``error_rad`` (detected minus set: (n, M) rad, or (n, M, 2)
        (azimuth, elevation)), ``converged`` (n, M) (the beamformer's Newton peak),
        ``bin`` (n, M) (the detected bin as an offset from the set range's), ``amplitudes``
        (n, M, Q) (relative: times ``channels.unit_gain``); a cell's also ``distance_rad``,
        a pair's ``j_steps`` (J's delay as planned, steps)."""
        for case in cases:
            if case not in ALL_CASES or (case == NOMINAL_AMPLITUDES
                                         and not isinstance(self.procedure, PairProcedure)):
                allowed = ALL_CASES if isinstance(self.procedure, PairProcedure) else CASES
                raise ValueError(f"case {case!r}: must be one of {', '.join(allowed)}")
        off = np.asarray(offsets_m, float)
        n = off.shape[0]
        u = np.full(n, self.subbin_zero) if subbin is None else np.asarray(subbin, int)
        pose = {k: v for k, v in (pose or {}).items() if v is not None}
        return self.procedure.draw(self, off, u, tuple(cases), pose)

    def angle_errors(self, offsets_m, case: str = "calibrated", return_converged: bool = False,
                     subbin=None):
        """Detected minus set direction (deg), (..., M) (D = 1) or (..., M, 2), for mounting
        errors (..., Q, 3), the target at sub-bin position ``subbin`` (indices into
        :attr:`subbin_steps`, default the bin centre) (:meth:`draw`)."""
        off = np.asarray(offsets_m, float)
        lead = off.shape[:-2]
        flat = off.reshape((-1,) + off.shape[-2:])
        sb = None if subbin is None else np.broadcast_to(subbin, lead).reshape(-1)
        d = self.draw(flat, sb, (case,))[case]
        e = np.degrees(d["error_rad"]).reshape(lead + d["error_rad"].shape[1:])
        ok = d["converged"].reshape(lead + (-1,))
        return (e, ok) if return_converged else e

    def evaluate(self, offsets_m, cases=CASES, pose: dict | None = None, subbin=None) -> dict:
        """Per draw of ``offsets_m`` (k, Q, 3) (``pose``, ``subbin``: :meth:`draw`'s), per
        case: the worst signed error of the set-points (deg), (k, C) (:attr:`columns`), the
        count of peaks Newton left to the grid search and of set-points detected off the set
        range's bin; the calibration steps (k, Q) and the channels' range offsets (k, Q) (m).
        Pure: the same errors give the same bits. Evaluated in blocks of the procedure's
        ``block_draws`` (row by row: the bits do not depend on it)."""
        cases = tuple(cases)
        off = np.asarray(offsets_m, float)
        n = len(off)
        step = self.procedure.block_draws
        parts = []
        for b in range(0, max(n, 1), step):
            sl = slice(b, b + step)
            sub = None if subbin is None else np.asarray(subbin)[sl]
            sub_pose = None if pose is None else {
                k: (None if v is None else np.asarray(v)[sl]) for k, v in pose.items()}
            d = self.draw(off[sl], sub, cases, sub_pose)
            part = {"steps": d["steps"]}
            for case in cases:
                e = np.degrees(d[case]["error_rad"])
                if e.ndim == 2:  # (k, M): the worst set-point's signed error
                    k = np.argmax(np.abs(e), axis=-1)
                    part[case] = np.take_along_axis(e, k[:, None], axis=-1)
                else:  # (k, M, 2): the worst in each angle, and the largest distance
                    k = np.argmax(np.abs(e), axis=1)
                    worst = np.take_along_axis(e, k[:, None, :], axis=1)[:, 0]
                    part[case] = np.column_stack(
                        [worst, np.degrees(d[case]["distance_rad"].max(-1))])
                part[case + "_fallbacks"] = int(np.count_nonzero(~d[case]["converged"]))
                part[case + "_off_bin"] = int(np.count_nonzero(d[case]["bin"]))
            parts.append(part)
        steps = np.concatenate([p["steps"] for p in parts])
        out = {"steps": steps, "range_offset_m": self.range_offsets_m(off, steps, pose)}
        for case in cases:
            out[case] = np.concatenate([p[case] for p in parts])
            for key in (case + "_fallbacks", case + "_off_bin"):
                out[key] = sum(p[key] for p in parts)
        return out

    def to_dict(self) -> dict:
        return self.procedure.to_dict(self)

    def with_procedure(self, **changes) -> "ChannelPhasors":
        """This model with fields of its procedure replaced."""
        return dataclasses.replace(self, procedure=dataclasses.replace(self.procedure, **changes))
