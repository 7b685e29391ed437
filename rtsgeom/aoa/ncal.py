"""Calibration of N channels against a reference (issue 15; ``channel-sets.md``,
"Choosing and calibrating channels").

A phase is always measured between two channels: each measured pair (i, j) is swept like the
paper's pair calibration (channel j's RTS delay offset over at least one period, two probe
targets synthesized by the pair at amplitude ratios 1:3 and 3:1, the probes' detected
directions compared with the model's coherent prediction, RMS over both probes and both
angles; the vertex of a parabola through the points near the minimum, on the sweep and on a
finer grid, rounded to the delay resolution), but in the RuT's own D-dimensional
beamformer, so pairs stacked in elevation calibrate as pairs side by side. The pairs are the
edges between the cell's front ends (Delaunay edges; the pair on an arc); the per-channel
delays add up along a minimum spanning tree (shortest edges) from the reference channel, and
each measured edge off the tree closes a loop whose closure error (wrapped to one period) is
reported as a check. The amplitude calibration is each front end alone
(``calibration.probe_front_ends``' gain correction); the residual is the detected error of
one target at the cell's centre, synthesized by all its channels, in both angles.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.constants import c
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import breadth_first_order, minimum_spanning_tree
from scipy.spatial import Delaunay

from ..radar.processing import nearest_detection
from ..radar.steering import Steering
from ..rts import RtsProgram, requested_delay
from ..scene import TargetConfig
from .nchannel import ChannelSet

__all__ = ["ChannelCalibration", "calibrate_channels", "calibrate_pair_nd", "pair_edges",
           "spanning_tree", "tree_phases"]

PROBE_RATIOS = (1 / 3, 3.0)  # channel j's amplitude over channel i's for the two probes


@dataclass(frozen=True)
class ChannelCalibration:
    offsets_s: np.ndarray  # (F,) delay offset per channel (reference and unused: 0)
    reference: int
    pairs: list = field(default_factory=list)  # per measured pair: dict (to_dict rows)
    tree: list = field(default_factory=list)  # [(i, j)] edges the offsets were added along
    loop_closure_s: list = field(default_factory=list)  # per off-tree edge
    residual_deg: tuple = (np.nan, np.nan)  # (azimuth, elevation) error at the cell centre
    gain_correction: tuple = ()

    def to_dict(self) -> dict:
        return {"reference": self.reference,
                "delay_offsets_s": [float(x) for x in self.offsets_s],
                "spanning_tree": [list(e) for e in self.tree],
                "loop_closure_s": [float(x) for x in self.loop_closure_s],
                "residual_deg": {"azimuth": float(self.residual_deg[0]),
                                 "elevation": float(self.residual_deg[1])},
                "gain_correction": [float(x) for x in self.gain_correction],
                "pairs": self.pairs}


def pair_edges(u_fe, channels) -> list[tuple[int, int]]:
    """The measured pairs among ``channels``: neighbours in 1-D, Delaunay edges in 2-D."""
    ch = sorted(int(q) for q in channels)
    pts = np.asarray(u_fe, float)[ch]
    if pts.shape[1] == 1 or len(ch) < 3:
        order = [ch[k] for k in np.argsort(pts[:, 0])]
        return [tuple(sorted(p)) for p in zip(order, order[1:])]
    edges = set()
    for s in Delaunay(pts).simplices:
        for a in range(3):
            i, j = ch[s[a]], ch[s[(a + 1) % 3]]
            edges.add((min(i, j), max(i, j)))
    return sorted(edges)


def _angles_to_u(st, det, k):
    if st.dims == 1:
        return np.array([np.sin(det.angle_rad[k])])
    return st.directions(np.array([det.angle_rad[k], det.elevation_rad[k]]))


def _detect(setup, paths, program, seed):
    from ..radar import process
    from ..radar.frame import simulate
    _, cube = simulate(setup, paths, program, seed, setup.scene.radar.snr_db)
    return process(cube)


def calibrate_pair_nd(setup, paths, pair, probe, seed=0, span_s=None, step_s=None) -> dict:
    """Delay offset of channel j relative to channel i of ``pair`` (a row of
    :attr:`ChannelCalibration.pairs`).

    In the RuT's own beamformer: when it is the azimuth row (D = 1) this is the pair
    calibration of the arc, ``calibration.calibrate_pair`` (phasor-model sweep, periodic
    least-squares fit, full-chain confirmation), as a dict; the pair on an arc is the N = 2,
    D = 1 case of the channel calibration, not a second sweep. With a 2-D beamformer (D = 2:
    pairs side by side or stacked in elevation) the sweep of the module doc, through the
    full ADC-cube chain, comparing the probes' detected direction cosines in both axes (the
    phasor sweep's closed-form design and Newton reading are 1-D so far)."""
    from .calibration import (calibrate_pair, if_phase_slope_hz, nominal_model, probe_ranges,
                              probe_total_delay)
    scene = setup.scene
    rts = scene.rts
    nom, nom_paths = nominal_model(setup, paths)
    if Steering.auto(nom.rut, scene.radar).dims == 1:
        cal = calibrate_pair(setup, paths, tuple(int(q) for q in pair), probe, (0.0, 0.0),
                             seed, span_s, step_s)
        row = cal.to_dict()
        row["residual_error_deg"] = float(cal.residual_error_deg)
        return row
    ranges = probe_ranges(setup, 2)
    corr = probe.gain_correction[list(pair)]
    designs, predicted = [], []
    for r, rho in zip(ranges, PROBE_RATIOS):
        cs = ChannelSet.build(nom, nom_paths, pair, TargetConfig(float(r)))
        u_mid = cs.fe_directions().mean(axis=0)
        ph = cs.coherent_phases(u_mid[None])
        w = cs.weights([1.0, rho], ph)
        u_pred = cs.direction_cosines(w, u_mid)
        designs.append(cs.amplitudes(w, u_pred) * corr)
        predicted.append(u_pred)
    st = cs.steering
    base = [float(requested_delay(scene, r)) for r in ranges]

    def error(delta: float) -> float:
        tg, fe, dl, amp = [], [], [], []
        for k, (a, b) in enumerate(zip(base, designs)):
            tg += [k, k]
            fe += list(pair)
            dl += [a, a + delta]
            amp += list(b)
        prog = RtsProgram.build(tg, fe, dl, np.zeros(len(tg)), amp)
        step_seed = np.random.SeedSequence([int(seed) % 2 ** 32, int(round(delta * 1e15))
                                            + 2 ** 40, pair[0], pair[1]])
        rd, det = _detect(setup, paths, prog, step_seed)
        errs = []
        for r, u_pred in zip(ranges, predicted):
            k = nearest_detection(det, rd, r)
            if k is None:
                return np.inf
            errs.append(np.degrees(_angles_to_u(st, det, k) - u_pred))
        return float(np.sqrt(np.mean(np.square(errs))))

    span = span_s or rts.calibration_span_s
    step = step_s or rts.calibration_step_s
    grid = np.arange(span[0], span[1] + step / 2, step)
    errs = np.array([error(d) for d in grid])
    is_min = (np.r_[True, errs[1:] <= errs[:-1]] & np.r_[errs[:-1] <= errs[1:], True])
    good = np.flatnonzero(is_min & (errs <= 2 * np.min(errs) + 0.01))
    k = int(good[np.argmin(np.abs(grid[good]))])  # the least range offset among the deepest
    best, best_err = float(grid[k]), float(errs[k])
    period = 1.0 / float(if_phase_slope_hz(scene, probe_total_delay(setup, ranges)))
    # Near coherence each probe's error is quadratic in the phase error (flat-bottomed under
    # noise): a parabola through the points within +-period/8 of the minimum finds its vertex
    # from all of them, on the sweep and then on a finer grid around it.
    pts_d, pts_e = list(grid), list(errs)
    res = rts.delay_resolution_s
    for _ in range(2):
        # the delays as the RTS realises them: a coarse RTS rounds what it is given, and a
        # point recorded at the requested delay would sit up to half a step off its value
        fine = np.unique(np.round((best + np.linspace(-period / 8, period / 8, 11)) / res)
                         * res)
        pts_d += list(fine)
        pts_e += [error(d) for d in fine]
        d_a, e_a = np.array(pts_d), np.array(pts_e)
        near = np.isfinite(e_a) & (np.abs(d_a - best) <= period / 8 + 1e-15)
        a2, a1, _ = np.polyfit(d_a[near] - best, e_a[near], 2)
        if a2 > 0 and abs(a1 / (2 * a2)) < period / 8:
            best = best - a1 / (2 * a2)
    best = float(np.round(best / res) * res)  # what the RTS can set
    best_err = error(best)
    return {"pair": [int(pair[0]), int(pair[1])], "delta_tau_s": best,
            "residual_error_deg": best_err, "points": int(len(pts_d)) + 1, "range_offset_m": 0.5 * c * best,
            "period_s": period, "sweep_points": int(grid.size)}


def calibrate_channels(setup, paths, channels, probe, seed=None, progress=None,
                       span_s=None, step_s=None) -> ChannelCalibration:
    """Delay offsets of ``channels`` relative to the lowest of them (module doc)."""
    from .calibration import nominal_model
    scene = setup.scene
    seed = scene.seed if seed is None else seed
    nom, nom_paths = nominal_model(setup, paths)
    st = Steering.auto(nom.rut, scene.radar)
    u_fe = nom.fe_direction_cosines()
    u_fe = np.sin(nom.fe_azimuth_rad())[:, None] if st.dims == 1 else u_fe
    ch = sorted(int(q) for q in channels)
    ref = ch[0]
    offsets = np.zeros(setup.fe.count)
    if len(ch) < 2:
        return ChannelCalibration(offsets, ref, gain_correction=tuple(probe.gain_correction))
    edges = pair_edges(u_fe, ch)
    meas = {}
    for e in edges:
        meas[e] = calibrate_pair_nd(setup, paths, e, probe, seed, span_s, step_s)
        if progress:
            progress(f"calibrated pair {e}: delta_tau {meas[e]['delta_tau_s'] * 1e12:.1f} ps")
    tree_edges = spanning_tree(u_fe, edges, ref)
    for p, q in tree_edges:
        i, j = min(p, q), max(p, q)
        d = meas[(i, j)]["delta_tau_s"]  # j relative to i
        offsets[q] = offsets[p] + (d if q == j else -d)
    on_tree = {tuple(sorted(e)) for e in tree_edges}
    closure = []
    for (i, j), m in meas.items():
        if (i, j) in on_tree:
            continue
        per = m["period_s"]
        c = offsets[i] + m["delta_tau_s"] - offsets[j]
        closure.append(float(c - per * np.round(c / per)))
    residual = _residual(setup, paths, nom, nom_paths, ch, offsets, probe, st, seed, tree_edges)
    return ChannelCalibration(offsets, ref, list(meas.values()), tree_edges, closure, residual,
                              tuple(probe.gain_correction))


def spanning_tree(u_fe, edges, ref: int) -> list[tuple[int, int]]:
    """The edges [(parent, child)] (front-end indices, breadth-first from ``ref``) along which
    :func:`calibrate_channels` adds the measured pairs' delays: the minimum spanning tree of
    the measured ``edges`` weighted by their length in direction cosines (the shortest, most
    reliable sweeps first; +1 keeps a 0-length edge)."""
    u_fe = np.asarray(u_fe, float)
    n = u_fe.shape[0]
    w = np.zeros((n, n))
    for i, j in edges:
        w[i, j] = 1.0 + np.linalg.norm(u_fe[i] - u_fe[j])
    tree = minimum_spanning_tree(csr_matrix(w)).toarray()
    sym = csr_matrix((tree + tree.T) > 0)
    order, pred = breadth_first_order(sym, ref, directed=False)
    return [(int(pred[q]), int(q)) for q in order[1:]]


def tree_phases(cs: ChannelSet, tree, phasors=None) -> np.ndarray:
    """The channel phases (Q,) a calibration along ``tree`` [(i, j)] (front-end indices,
    parent first) establishes on the channel set ``cs``: each pair coherent at the midpoint
    of its front ends' directions, where its probes sat (``coherent_phases`` of the pair),
    added up from the reference; channels not on the tree keep phase 0. ``phasors``
    (..., Q, V): the channels as built (e.g. a tolerance draw's, ``ChannelModel.perturbed``;
    the probes stay at the nominal directions), default ``cs.model.phasors``: (..., Q)."""
    ch = list(cs.model.channels)
    pos = {q: k for k, q in enumerate(ch)}
    u = cs.fe_directions()
    x = cs.model.phasors if phasors is None else np.asarray(phasors)
    ph = np.zeros(x.shape[:-1])
    for i, j in tree:
        if i not in pos or j not in pos:
            continue
        a, b = pos[i], pos[j]
        mid = 0.5 * (u[a] + u[b])
        beams = cs.steering.beam(x[..., [a, b], :], mid[None])[..., 0]
        ph[..., b] = ph[..., a] + np.angle(beams[..., 0] * np.conj(beams[..., 1]))
    return ph


def _residual(setup, paths, nom, nom_paths, ch, offsets, probe, st, seed, tree):
    """(azimuth, elevation) error (deg) of one target at the channels' centre, synthesized by
    all of them with the calibrated offsets (exact mode)."""
    from .calibration import probe_ranges
    from .model import AngleUnreachable
    r = float(probe_ranges(setup, 1)[0])
    cs = ChannelSet.build(nom, nom_paths, tuple(ch), TargetConfig(r), offsets[ch])
    u = cs.fe_directions().mean(axis=0)
    try:
        w = cs.solve(u, tree_phases(cs, tree))
    except AngleUnreachable:  # the centre is outside what the channels reach: no error to show
        return (np.nan, np.nan)
    amps = cs.amplitudes(w, u) * probe.gain_correction[ch]
    tau = float(requested_delay(setup.scene, r))
    prog = RtsProgram.build([0] * len(ch), ch, list(tau + offsets[ch]), [0.0] * len(ch),
                            list(amps))
    rd, det = _detect(setup, paths, prog, np.random.SeedSequence([int(seed) % 2 ** 32, 7]))
    k = nearest_detection(det, rd, r)
    if k is None:
        return (np.nan, np.nan)
    set_ang = _set_angles(st, u)
    got = (det.angle_rad[k], 0.0 if det.elevation_rad is None else det.elevation_rad[k])
    return (float(np.degrees(got[0] - set_ang[0])), float(np.degrees(got[1] - set_ang[1])))


def _set_angles(st, u):
    if st.dims == 1:
        return (float(np.arcsin(u[0])), 0.0)
    a = st.angles(u)
    return (float(a[0]), float(a[1]))
