"""Calibration of N channels against a reference.

A phase is always measured between two channels: each measured pair (i, j) is calibrated by
the pair's delay sweep (``pair.calibrate_pair``: on an arc the phasor model's, in a 2-D
beamformer the full chain's in both axes, so pairs stacked in elevation calibrate as pairs
side by side). The pairs are the edges between the cell's front ends (Delaunay edges; the
pair on an arc); the per-channel delays add up along a minimum spanning tree (shortest edges)
from the reference channel, and each measured edge off the tree closes a loop whose closure
error (wrapped to one period) is a check: beyond ``LOOP_CLOSURE_TOL_S`` it is a warning
naming the pair, as is a pair whose sweep detected nothing (:class:`CalibrationFailed` when it
leaves a channel without a path to the reference). The amplitude calibration is each front
end alone (``probes.probe_front_ends``' gain correction); the residual is the detected error
of one target at the cell's centre, synthesized by all its channels, in both angles.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._lib.util import tell
from ..radar.processing import nearest_detection
from ..radar.steering import Steering
from ..rts.channels import RtsProgram, requested_delay
from ..scene import TargetConfig
from ..synthesis.model import ChannelModel
from ..errors import AngleUnreachable, CalibrationFailed
from ..paths import nominal_model
from .pair import calibrate_pair
from .probes import probe_ranges, simulate_detect
from .sweep import SweepConfig

__all__ = ["ChannelCalibration", "calibrate_channels", "pair_edges", "spanning_tree",
           "tree_phases", "channel_offsets", "LOOP_CLOSURE_TOL_S"]

# A loop of pair calibrations closes to within this (wrapped to one period), or the
# calibration is reported as failed, naming the loop's pair. It bounds the scatter of the
# pairs' fits: on the bundled 2-D scene the loops close to 0-5 ps with the frames per step
# sized, 2-25 ps with one frame a step (the elevation pairs' fits scatter ~10 ps).
LOOP_CLOSURE_TOL_S = 25e-12


@dataclass(frozen=True)
class ChannelCalibration:
    offsets_s: np.ndarray  # (F,) delay offset per channel (reference and unused: 0)
    reference: int
    pairs: list = field(default_factory=list)  # per measured pair: Calibration.to_dict()
    tree: list = field(default_factory=list)  # [(i, j)] edges the offsets were added along
    loop_closure_s: list = field(default_factory=list)  # per off-tree edge
    residual_deg: tuple = (np.nan, np.nan)  # (azimuth, elevation) error at the cell centre
    gain_correction: tuple = ()
    warnings: tuple = ()  # failed pairs, loop closures beyond LOOP_CLOSURE_TOL_S, no residual

    @property
    def failed(self) -> bool:
        """Whether the calibration is not to be trusted (any of :attr:`warnings`)."""
        return bool(self.warnings)

    def to_dict(self) -> dict:
        return {"reference": self.reference,
                "delay_offsets_s": [float(x) for x in self.offsets_s],
                "spanning_tree": [list(e) for e in self.tree],
                "loop_closure_s": [float(x) for x in self.loop_closure_s],
                "residual_deg": {"azimuth": float(self.residual_deg[0]),
                                 "elevation": float(self.residual_deg[1])},
                "gain_correction": [float(x) for x in self.gain_correction],
                "loop_closure_tolerance_s": LOOP_CLOSURE_TOL_S,
                "warnings": list(self.warnings),
                "pairs": self.pairs}


def pair_edges(u_fe, channels) -> list[tuple[int, int]]:
    """The measured pairs among ``channels``: neighbours in 1-D, Delaunay edges in 2-D."""
    ch = sorted(int(q) for q in channels)
    pts = np.asarray(u_fe, float)[ch]
    if pts.shape[1] == 1 or len(ch) < 3:
        order = [ch[k] for k in np.argsort(pts[:, 0])]
        return [tuple(sorted(p)) for p in zip(order, order[1:])]
    from scipy.spatial import Delaunay  # here: 2-D cells only (a 1-D run skips its import)
    edges = set()
    for s in Delaunay(pts).simplices:
        for a in range(3):
            i, j = ch[s[a]], ch[s[(a + 1) % 3]]
            edges.add((min(i, j), max(i, j)))
    return sorted(edges)














def calibrate_channels(setup, paths, channels, probe, seed=None, progress=None,
                       span_s=None, step_s=None) -> ChannelCalibration:
    """Delay offsets of ``channels`` relative to the lowest of them (module doc)."""
    scene = setup.scene
    seed = scene.seed if seed is None else seed
    nom, nom_paths = nominal_model(setup, paths)
    st = Steering.auto(nom.rut, scene.radar)
    u_fe = nom.fe_direction_cosines(st.dims)
    ch = sorted(int(q) for q in channels)
    ref = ch[0]
    offsets = np.zeros(setup.fe.count)
    if len(ch) < 2:
        return ChannelCalibration(offsets, ref, gain_correction=tuple(probe.gain_correction))
    edges = pair_edges(u_fe, ch)
    config = SweepConfig(span_s, step_s, seed=seed)
    meas, notes = {}, []
    for n_done, e in enumerate(edges, 1):
        try:
            meas[e] = calibrate_pair(setup, paths, e, probe, config=config)
        except CalibrationFailed as exc:
            notes.append(f"channel calibration: {exc}")
            continue
        tell(progress, f"calibrated pair {e}: delta_tau {meas[e].delta_tau_s * 1e12:.1f} ps",
             "calibrating pairs", n_done, len(edges))
    edges = [e for e in edges if e in meas]
    tree_edges = spanning_tree(u_fe, edges, ref) if edges else []
    cut = sorted(set(ch) - {ref} - {q for _, q in tree_edges})
    if cut:  # no chain of calibrated pairs from the reference: no offset for these
        raise CalibrationFailed("; ".join(notes + [f"channels {cut} are not connected to the "
                                                   f"reference {ref} by calibrated pairs"]))
    for p, q in tree_edges:
        i, j = min(p, q), max(p, q)
        d = meas[(i, j)].delta_tau_s  # j relative to i
        offsets[q] = offsets[p] + (d if q == j else -d)
    # Each channel's offset to the period nearest zero: the pair delays can add up along the
    # tree to beyond half a period, which would put a channel's echo a range bin from the
    # others; one period is the same phase at the probes' range (at another range it costs
    # 0.6 % of a turn per period at 40 m, as any calibration offset does).
    per = float(np.median([m.period_s for m in meas.values()]))
    offsets = offsets - per * np.round(offsets / per)
    on_tree = {tuple(sorted(e)) for e in tree_edges}
    closure = []
    for (i, j), m in meas.items():
        if (i, j) in on_tree:
            continue
        per = m.period_s
        c = offsets[i] + m.delta_tau_s - offsets[j]
        closure.append(float(c - per * np.round(c / per)))
        if abs(closure[-1]) > LOOP_CLOSURE_TOL_S:
            notes.append(f"channel calibration: the loop through pair ({i}, {j}) closes to "
                         f"{closure[-1] * 1e12:.1f} ps (tolerance "
                         f"{LOOP_CLOSURE_TOL_S * 1e12:g} ps): that pair or one on the tree "
                         f"{tree_edges} is off its coherence point")
    residual = _residual(setup, paths, nom, nom_paths, ch, offsets, probe, st, seed, tree_edges)
    if not np.all(np.isfinite(residual)):
        notes.append(f"channel calibration: the calibrated channels {ch} do not synthesize "
                     "(or the RuT does not detect) a target at the cell's centre: no residual")
    return ChannelCalibration(offsets, ref, [m.to_dict() for m in meas.values()], tree_edges,
                              closure, residual,
                              tuple(probe.gain_correction), tuple(notes))


def spanning_tree(u_fe, edges, ref: int) -> list[tuple[int, int]]:
    """The edges [(parent, child)] (front-end indices, breadth-first from ``ref``) along which
    :func:`calibrate_channels` adds the measured pairs' delays: the minimum spanning tree of
    the measured ``edges`` weighted by their length in direction cosines (the shortest, most
    reliable sweeps first; +1 keeps a 0-length edge)."""
    from scipy.sparse import csr_matrix  # here: with scipy.spatial, 80 ms of a 1-D run's
    from scipy.sparse.csgraph import breadth_first_order, minimum_spanning_tree  # imports
    u_fe = np.asarray(u_fe, float)
    n = u_fe.shape[0]
    w = np.zeros((n, n))
    for i, j in edges:
        w[i, j] = 1.0 + np.linalg.norm(u_fe[i] - u_fe[j])
    tree = minimum_spanning_tree(csr_matrix(w)).toarray()
    sym = csr_matrix((tree + tree.T) > 0)
    order, pred = breadth_first_order(sym, ref, directed=False)
    return [(int(pred[q]), int(q)) for q in order[1:]]


def tree_phases(cs: ChannelModel, tree, phasors=None) -> np.ndarray:
    """The channel phases (Q,) a calibration along ``tree`` [(i, j)] (front-end indices,
    parent first) establishes on the channel set ``cs``: each pair coherent at the midpoint
    of its front ends' directions, where its probes sat (``coherent_phases`` of the pair),
    added up from the reference; channels not on the tree keep phase 0. ``phasors``
    (..., Q, V): the channels as built (e.g. a tolerance draw's, ``ChannelModel.perturbed``;
    the probes stay at the nominal directions), default ``cs.phasors``: (..., Q)."""
    ch = list(cs.channels)
    pos = {q: k for k, q in enumerate(ch)}
    u = cs.fe_directions()
    x = cs.phasors if phasors is None else np.asarray(phasors)
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
    r = float(probe_ranges(setup, 1)[0])
    cs = ChannelModel.build(nom, nom_paths, tuple(ch), TargetConfig(r), offsets[ch], steering=st)
    u = cs.fe_directions().mean(axis=0)
    try:
        w = cs.solve(u, tree_phases(cs, tree))
    except AngleUnreachable:  # the centre is outside what the channels reach: no error to show
        return (np.nan, np.nan)
    amps = cs.amplitudes(w, u) * probe.gain_correction[ch]
    tau = float(requested_delay(setup.scene, r))
    prog = RtsProgram.build([0] * len(ch), ch, list(tau + offsets[ch]), [0.0] * len(ch),
                            list(amps))
    rd, det = simulate_detect(setup, paths, prog,
                               np.random.SeedSequence([int(seed) % 2 ** 32, 7]))
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


def channel_offsets(n_fe: int, cals: dict) -> np.ndarray:
    """Per-channel delay offsets from pair calibrations chained along the arc."""
    off = np.zeros(n_fe)
    for (i, j), cal in sorted(cals.items()):
        off[j] = off[i] + cal.delta_tau_s
    return off
