"""A cell's procedure in the tolerance model (Q = 3 or 4 front ends on a sphere, a RuT that
beamforms in azimuth and elevation): its calibration along a spanning tree of pairs and one
design, peak-matched once on the nominal setup.

The channel weights of set directions over the cell (an n x n azimuth x elevation grid inside
it, :func:`~rtsgeom.analysis.linearity.cell_grid`) are designed once on the nominal setup
(:meth:`ChannelModel.solve <rtsgeom.synthesis.model.ChannelModel.solve>`, ``exact``: peak
matching on the modelled 2-D beamformer output) for the channel phases the cell's calibration
establishes (:func:`~rtsgeom.calibration.channels.tree_phases`: each measured pair of the
spanning tree coherent at the midpoint of its front ends' directions). A draw at phasor level::

    x_qkv(draw) = table[q, u + k_q, k, v] * (x_qv(draw) / x_qv(nominal))
                  * exp(s_qkv(u + k_q) d_qv)

(``u`` the sub-bin position, ``k_q`` the channel's calibration delay in steps, ``s`` the
table's log-magnitude slope over the delay: the echo slides along the range window by the air
delay change d as by an RTS delay, bounded by :func:`~.tables.slide`). The detected bin is the
strongest candidate of the weighted sum (power over the virtual elements), the snapshot that
bin's. ``uncalibrated``: k = 0 and the nominal amplitudes. ``calibrated``: the tree phases of
the draw's channels (the pairs' probes at the nominal directions) as delays by eq. (27)
(wrapped to the smallest |delay|, quantised, refined on the table's exact phase), the amplitude
calibration (each channel's power over the virtual elements against the model's) and each
channel's known loss from its delay divided out at the bin the operator's nominal model detects
(the amplitudes are designed once, at the bin centre: every channel slides alike with the
target's position, so the design holds across the bin up to what the calibration delays move).

Not modelled (the pair's procedure has them): a redesign per sub-bin position and delay (no
closed form in 2-D: peak matching per draw would cost a Gauss-Newton per set-point), and the
planner's alternative delays one IF period away.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..._lib.util import frozen
from ...calibration.channels import pair_edges, spanning_tree, tree_phases
from ...errors import ParameterError
from ...paths import exact_paths
from ...radar.steering import Steering
from ...synthesis.model import ChannelModel
from ..linearity import cell_grid
from .draws import subbin_positions
from .tables import response_table, slide

__all__ = ["CellProcedure", "build_cell", "ANGLES"]

ANGLES = ("azimuth", "elevation", "angular_distance")
REFINE_STEPS = 8  # the calibration delay refined +-this many steps on the table's phase
#: candidate range bins either side of the set range's: an echo lies at most half a bin (its
#: sub-bin position) plus half an IF period of calibration delay (~0.3 bins on sphere4) from
#: the set range's bin centre, so the combined peak is within one bin; one more is compared
HALF_BINS = 2


def _wrap(phi):
    return np.angle(np.exp(1j * np.asarray(phi)))


def _detected_bin(y) -> np.ndarray:
    """The RuT's range bin of spectra ``y`` (..., K, V): the strongest candidate, the power
    summed over the virtual elements, (...,)."""
    return np.argmax(np.sum(y.real ** 2 + y.imag ** 2, -1), -1)


def _unit_vectors(u) -> np.ndarray:
    """Unit direction vectors (..., 3) of direction cosines (..., 2) (the front hemisphere)."""
    u = np.asarray(u, float)
    w = np.sqrt(np.clip(1.0 - np.sum(u ** 2, axis=-1), 0.0, None))
    return np.concatenate([u, w[..., None]], axis=-1)


@dataclass(frozen=True)
class CellProcedure:
    """What the operator of a cell does at phasor level (module docstring): the calibration's
    spanning tree and the design's channel phases, each channel's delay tables at the bin
    centre."""

    set_u: np.ndarray  # (M, 2) the set directions' direction cosines
    phases: np.ndarray  # (Q,) the nominal calibration's channel phases (the design's)
    tree: tuple  # ((parent, child), ...) front-end indices, the calibration's spanning tree
    delay_factor: np.ndarray  # (Q, 2 S + 1, V) F_q(k), k = -S..S
    delay_log_slope: np.ndarray  # (Q, 2 S + 1, V) Re d ln F / d tau (1/s)
    block_draws: int = 500  # draws per block of a chunk (the (n, M, K, V) temporaries bounded)

    @property
    def max_steps(self) -> int:
        return (self.delay_factor.shape[1] - 1) // 2

    def calibration_steps(self, ph, xq: np.ndarray) -> np.ndarray:
        """The cell's calibration in delay steps (..., Q) (the reference channel 0) for the
        channels' phasors (..., Q, V): the tree phases (:func:`tree_phases`) as delays by
        eq. (27), wrapped to the smallest |delay|, quantised, refined on the table's phase."""
        psi = tree_phases(ph.channels, self.tree, xq)  # (..., Q)
        mask = ph.channels.steering.mask
        table_phase = np.angle(self.delay_factor[..., mask].mean(-1))  # (Q, D)
        s = self.max_steps
        sign = np.sign(np.median(table_phase[:, s + 1]))
        k0 = np.round(_wrap(psi) / (sign * 2 * np.pi * ph.cal_slope_hz
                                    * ph.delay_resolution_s)).astype(int)
        r = s - REFINE_STEPS - 1
        cand = np.clip(k0[..., None], -r, r) + np.arange(-REFINE_STEPS, REFINE_STEPS + 1)
        q = np.arange(psi.shape[-1])[:, None]
        miss = np.abs(_wrap(psi[..., None] - table_phase[q, cand + s]))
        return np.take_along_axis(cand, np.argmin(miss, -1)[..., None], -1)[..., 0]

    def draw(self, ph, off, u, cases, pose) -> dict:
        """:meth:`ChannelPhasors.draw <.phasors.ChannelPhasors.draw>` for a cell: per case the
        detected minus set (azimuth, elevation) (n, M, 2) rad, the angular distance (n, M)
        rad, whether the beamformer's Newton peak converged, the detected bin (offset from the
        set range's) and the programme amplitudes (n, M, Q) (relative: times
        ``channels.unit_gain``); the calibration steps (n, Q)."""
        cm, st = ph.channels, ph.channels.steering
        x, shift = cm.perturbed(off, return_shift=True, **pose)  # (n, Q, V)
        nom = ph.x_nominal
        fac = x / np.where(nom != 0, nom, 1.0)  # the draw's factor per channel and element
        steps = self.calibration_steps(ph, x)
        n, n_q = off.shape[0], len(ph.front_ends)
        q = np.arange(n_q)
        d_u = ph.subbin_steps[u]  # (n,)
        out = {"steps": steps}
        v_set = _unit_vectors(self.set_u)
        mask = st.mask
        for case in cases:
            cal = case == "calibrated"
            rows = ph.table_zero + d_u[:, None] + (steps if cal else 0)  # (n, Q)
            t_nom = ph.table[q, rows]  # (n, Q, K, V) the operator's nominal model
            xk = t_nom * fac[:, :, None] * slide(ph.table_log_slope[q, rows],
                                                 shift[:, :, None])
            amps = np.broadcast_to(ph.amplitudes, (n,) + ph.amplitudes.shape)
            if cal:  # the gains measured, each delay's known loss divided out at the bin
                # the operator's nominal model detects (target at its sub-bin position)
                t_pos = ph.table[q, ph.table_zero + d_u[:, None]]  # delays at 0
                k_plan = _detected_bin(np.einsum("nmq,nqkv->nmkv", amps, t_nom))  # (n, M)
                pick = k_plan[:, :, None, None]
                f_d = np.take_along_axis(t_nom[..., mask].mean(-1)[:, None], pick, -1)[..., 0]
                f_0 = np.take_along_axis(t_pos[..., mask].mean(-1)[:, None], pick, -1)[..., 0]
                loss = np.abs(f_d) / np.maximum(np.abs(f_0), 1e-300)  # (n, M, Q)
                amps = amps * ph.gain_correction(x)[:, None, :] / loss
            y = np.einsum("nmq,nqkv->nmkv", amps, xk)  # (n, M, K, V)
            det = _detected_bin(y)  # (n, M): the RuT's bin
            snaps = np.take_along_axis(y, det[:, :, None, None], 2)[:, :, 0]  # (n, M, V)
            uu, ok = st.peak(snaps, self.set_u)
            ang = st.angles(uu)
            dist = 2 * np.arcsin(np.clip(np.linalg.norm(_unit_vectors(uu) - v_set, axis=-1) / 2,
                                         0.0, 1.0))
            out[case] = {"error_rad": ang - ph.set_rad, "distance_rad": dist,
                         "converged": ok, "bin": det - HALF_BINS, "amplitudes": amps}
        return out

    def to_dict(self, ph) -> dict:
        k = self.calibration_steps(ph, ph.x_nominal)
        fe = ph.channels.steering.angles(ph.channels.fe_directions())
        return {
            "cell": list(ph.front_ends),
            "range_m": ph.range_m,
            "front_end_directions_deg": [[float(a) for a in np.degrees(d)] for d in fe],
            "set_points": int(ph.set_rad.shape[0]),
            "set_directions_deg": [[float(a) for a in np.degrees(d)] for d in ph.set_rad],
            "spanning_tree": [list(e) for e in self.tree],
            "nominal_delta_tau_s": [float(x) * ph.delay_resolution_s for x in k],
            "delay_resolution_s": ph.delay_resolution_s,
        }


def build_cell(nom, cell: tuple[int, ...], grid: int, target) -> dict:
    """The fields of a cell's :class:`~.phasors.ChannelPhasors` on the nominal setup ``nom``:
    ``grid`` x ``grid`` set directions (the points inside the cell), the design for the
    nominal calibration's phases, each channel's tables over every sub-bin position and
    calibration delay."""
    radar, rts = nom.scene.radar, nom.scene.rts
    if Steering.auto(nom.rut, radar).dims != 2:
        raise ParameterError("tolerance --cell needs a RuT that beamforms in azimuth and "
                             "elevation (an array with elevation extent, e.g. "
                             "radar.use_elevation_tx = true)")
    n_fe = nom.fe.count
    if len(cell) not in (3, 4) or len(set(cell)) != len(cell) or not all(
            0 <= q < n_fe for q in cell):
        raise ParameterError(f"cell {list(cell)}: must be 3 or 4 distinct front-end indices "
                             f"in [0, {n_fe - 1}]")
    paths = exact_paths(nom)
    cs = ChannelModel.build(nom, paths, cell, target, steering=Steering.auto(nom.rut, radar))
    st = cs.steering
    u_fe = cs.fe_directions()
    all_u = nom.fe_direction_cosines()
    tree = tuple(spanning_tree(all_u, pair_edges(all_u, cell), cell[0]))
    phases = tree_phases(cs, tree)
    sets = cell_grid(st, u_fe, int(grid))
    if sets.shape[0] == 0:
        raise ParameterError(f"cell {list(cell)}: no set direction of a {grid} x {grid} "
                             "grid lies inside it")
    set_u = st.directions(sets)
    amps = np.stack([np.abs(cs.solve(u, phases, "exact")) for u in set_u])
    res = rts.delay_resolution_s
    slope = rts.f_rts_hz + 0.5 * radar.bandwidth_hz
    max_steps = int(np.ceil(0.5 / (slope * res))) + REFINE_STEPS + 1
    sub = subbin_positions(radar.range_resolution_m, res)
    # rows: every sub-bin position plus every calibration delay, one more for the slope
    z = int(np.max(np.abs(sub))) + max_steps + 1
    steps = np.arange(-z, z + 1)
    table = np.stack([response_table(nom, paths, q, target, res, steps, HALF_BINS)
                      for q in cell])  # (Q, D, K, V)
    with np.errstate(divide="ignore"):
        log_slope = np.gradient(np.log(np.abs(table)), res, axis=1)
    ks = slice(z - max_steps, z + max_steps + 1)
    factor = table[:, ks, HALF_BINS] / table[:, z:z + 1, HALF_BINS]  # (Q, 2 S + 1, V)
    procedure = CellProcedure(frozen(set_u), frozen(phases), tree, frozen(factor),
                              frozen(log_slope[:, ks, HALF_BINS]))
    return dict(channels=cs, set_rad=frozen(sets), amplitudes=frozen(amps), table=frozen(table),
                table_log_slope=frozen(log_slope), table_zero=z, subbin_steps=frozen(sub),
                delay_resolution_s=float(res), cal_slope_hz=float(slope), procedure=procedure)
