"""Calibration of N channels against a reference.

A phase is always measured between two channels: each measured pair (i, j) is swept like the
paper's pair calibration (channel j's RTS delay offset over at least one period, two probe
targets synthesized by the pair at amplitude ratios 1:3 and 3:1, designed at every step on the
nominal model, the probes' detected directions compared with the design's), but in the RuT's
own D-dimensional beamformer, so pairs stacked in elevation calibrate as pairs side by side:
the coarse minimum of the RMS error, then the 1-D pair calibration's fine sweep and periodic
least-squares fit (``sweep.fit_minimum``) on the signed errors that cross zero
(:func:`crossing_columns`), rounded to the delay resolution; each step the coherent
average of as many frames as keep the fitted minimum's 2-sigma scatter below
``calsteps.TARGET_BIAS_PS`` (measured on the sweep itself, ``calsteps.fit_scatter``). The
pairs are the edges between the cell's front ends (Delaunay edges; the pair on an arc); the
per-channel delays add up along a minimum spanning tree (shortest edges) from the reference
channel, and each measured edge off the tree closes a loop whose closure error (wrapped to
one period) is a check: beyond ``LOOP_CLOSURE_TOL_S`` it is a warning naming the pair, as is a pair whose
sweep detected nothing (:class:`CalibrationFailed` when it leaves a channel without a path to
the reference). The amplitude calibration is each front end alone
(``calibration.probe_front_ends``' gain correction); the residual is the detected error of
one target at the cell's centre, synthesized by all its channels, in both angles.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy.constants import c
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import breadth_first_order, minimum_spanning_tree
from scipy.spatial import Delaunay

from ..radar.processing import nearest_detection
from ..radar.steering import Steering
from ..rts.channels import RtsProgram, requested_delay
from ..scene import TargetConfig
from ..synthesis.model import ChannelModel
from ..errors import CalibrationFailed
from ..errors import AngleUnreachable
from ..paths import nominal_model
from .pair import calibrate_pair
from .probes import if_phase_slope_hz, probe_ranges, probe_total_delay, simulate_detect
from .steps import adds_noise, coarse_frames, coarse_minimum, continuous_delay_setup, fine_frames, fine_window, fit_scatter, realisable, rms_error_deg, sweep_phase
from .sweep import fit_minimum

__all__ = ["ChannelCalibration", "coherence_point_nd", "crossing_columns", "calibrate_channels",
           "calibrate_pair_nd", "pair_edges", "spanning_tree", "tree_phases", "channel_offsets"]

PROBE_RATIOS = (1 / 3, 3.0)
# A loop of pair calibrations closes to within this (wrapped to one period), or the
# calibration is reported as failed, naming the loop's pair: sphere4's loops close to 0 to 5
# ps with the frames per step sized (3 seeds; also with 180 deg on a front end and the front
# ends at +-3 deg), 2 to 25 ps with one frame a step (the elevation pairs' fits scatter ~10
# ps; 37 / 41 ps at +-3 deg); 29 and 37 ps before the 2-D fit was the 1-D one (run's
# elevation errors up to 0.10 deg against <= 0.03 deg).
LOOP_CLOSURE_TOL_S = 25e-12
FINE_STEP_ND_S = 10e-12  # the 2-D fine sweep's step (each step one full-chain simulation)


@dataclass(frozen=True)
class ChannelCalibration:
    offsets_s: np.ndarray  # (F,) delay offset per channel (reference and unused: 0)
    reference: int
    pairs: list = field(default_factory=list)  # per measured pair: dict (to_dict rows)
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


def _pair_probes(setup, paths, pair, probe, delta_s: float = 0.0, p_ref: dict | None = None):
    """The 2-D pair sweep's two probes at a step ``delta_s`` of channel j: their ranges (P,),
    programme amplitudes (P, 2) (the nominal model's design, with channel j at that delay,
    for channels coherent at the front ends' midpoint, amplitude ratios ``PROBE_RATIOS``,
    times the gain correction), the direction cosines (P, D) the design puts them at, and
    the RuT's steering. Designed at every step, as the 1-D sweep (``sweep.phasor_sweep``):
    channel j's echo moves by c0 delta / 2 in range (a quarter bin over +-period/4) and its
    gain in the bin with it; a design fixed at delta = 0 made each probe's error curve
    lopsided about the coherence point (its vertex 50 to 70 ps off in elevation, sphere4).
    ``p_ref``: a dict the sweep keeps across its steps, probe -> channel i's single-channel
    peak power (``ChannelModel.reference_power``; channel i does not move with delta, so one
    2-D grid search a probe instead of one a step)."""
    nom, nom_paths = nominal_model(setup, paths)
    ranges = probe_ranges(setup, 2)
    corr = probe.gain_correction[list(pair)]
    designs, predicted = [], []
    st = Steering.auto(nom.rut, setup.scene.radar)
    for p, (r, rho) in enumerate(zip(ranges, PROBE_RATIOS)):
        cs = ChannelModel.build(nom, nom_paths, pair, TargetConfig(float(r)), (0.0, delta_s),
                                steering=st)
        u_mid = cs.fe_directions().mean(axis=0)
        ph = cs.coherent_phases(u_mid[None])
        w = cs.weights([1.0, rho], ph)
        u_pred = cs.direction_cosines(w, u_mid)
        if p_ref is not None and p not in p_ref:
            p_ref[p] = cs.reference_power()
        designs.append(cs.amplitudes(w, u_pred, None if p_ref is None else p_ref[p]) * corr)
        predicted.append(u_pred)
    return ranges, designs, predicted, cs.steering


def crossing_columns(e_fine, edge: int = 3) -> np.ndarray:
    """The columns (probe x axis) of a fine sweep's signed errors ``e_fine`` (S, P * D) the
    2-D pair fit uses: those that cross zero over the window (opposite signs at its two
    ends, mean of ``edge`` steps each), else all of them.

    Along the pair's own axis a probe's error is even in the phase mismatch (quadratic about
    the coherence point, as on an arc), and its vertex reaches zero only where the chain's
    angle estimate is unbiased: in elevation (one wavelength of aperture) the vertex sits
    0.01 to 0.04 deg off zero, the curve crosses zero ~40 ps either side of it and the
    joint minimum lands on a crossing (sphere4, pair (0, 1): 67 ps against the coherence
    point's 29). Across the axis the error is odd (the elevated virtual rows are offset in
    azimuth) and crosses zero at the coherence point: fitted alone, 4 to 6 ps from it on
    sphere4 with 0 / 0.5 mm radial / 90 deg phase on a front end. A pair on an arc (D = 1)
    has no such column: all of them, the 1-D fit."""
    e = np.asarray(e_fine, float)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a column never detected: NaN
        lo = np.nanmean(e[:edge], axis=0)
        hi = np.nanmean(e[-edge:], axis=0)
    odd = np.isfinite(lo) & np.isfinite(hi) & (lo * hi < 0)
    return np.flatnonzero(odd) if np.any(odd) else np.arange(e.shape[1])


def coherence_point_nd(setup, paths, pair, probe, near_s: float = 0.0,
                       iterations: int = 4) -> float:
    """The continuous coherence point (s) of a pair in the RuT's D-dimensional beamformer:
    the delay offset of channel j, nearest ``near_s``, at which both channels' beam outputs
    at the 2-D sweep's probe directions (:func:`_pair_probes`) are in phase on the setup
    *as built* (circular mean over the probes), on the continuous delay model
    (``calsteps.continuous_delay_setup``). The D-dimensional counterpart of
    ``calibration.coherence_point`` (the point the sweep should find; a check, since a lab
    does not know the setup as built). Newton with slope ``2 pi if_phase_slope_hz``."""
    ranges, _, predicted, _ = _pair_probes(setup, paths, pair, probe)
    f_if = float(if_phase_slope_hz(setup.scene, probe_total_delay(setup, ranges)))
    period = 1.0 / f_if
    cont = continuous_delay_setup(setup)

    st = Steering.auto(cont.rut, setup.scene.radar)

    def phase(d):
        z = 0j
        for r, u in zip(ranges, predicted):
            cs = ChannelModel.build(cont, paths, pair, TargetConfig(float(r)), (0.0, d),
                                    steering=st)
            b = cs.steering.beam(cs.phasors, np.atleast_2d(u))[:, 0]
            z += b[0] * np.conj(b[1]) / max(abs(b[0] * np.conj(b[1])), 1e-300)
        return float(np.angle(z))

    d = float(near_s)
    for _ in range(2):
        for _ in range(iterations):
            d += phase(d) / (2 * np.pi * f_if)
        d += np.round((near_s - d) / period) * period
    return d


def calibrate_pair_nd(setup, paths, pair, probe, seed=0, span_s=None, step_s=None) -> dict:
    """Delay offset of channel j relative to channel i of ``pair`` (a row of
    :attr:`ChannelCalibration.pairs`).

    In the RuT's own beamformer: when it is the azimuth row (D = 1) this is the pair
    calibration of the arc, ``calibration.calibrate_pair`` (phasor-model sweep, periodic
    least-squares fit, full-chain confirmation), as a dict; the pair on an arc is the N = 2,
    D = 1 case of the channel calibration, not a second sweep. With a 2-D beamformer (D = 2:
    pairs side by side or stacked in elevation) the sweep of the module doc, through the
    full ADC-cube chain (one simulation per step and sweep: 61 coarse + 51 fine steps on
    sphere4, a sweep again where its frames per step or its noise estimate need it), comparing the probes'
    detected direction cosines in both axes; the coarse and fine steps, the fit and the
    frames per step are the 1-D pair's (``calsteps.fine_window``, ``calsteps.sweep_phase``,
    ``sweep.fit_minimum``, ``calsteps.fine_frames`` / ``coarse_frames``), the scatter
    they are sized from measured on the sweep itself (``calsteps.fit_scatter``: one frame
    a step, then, only where that scatters beyond ``TARGET_BIAS_PS`` / 2, the fine sweep
    again with the frames it needs); the phasor sweep's closed-form design, bin logic and
    probe placement are 1-D so far. Raises :class:`CalibrationFailed` when no probe is
    detected at any step."""
    scene = setup.scene
    rts = scene.rts
    nom, nom_paths = nominal_model(setup, paths)
    if Steering.auto(nom.rut, scene.radar).dims == 1:
        cal = calibrate_pair(setup, paths, tuple(int(q) for q in pair), probe, (0.0, 0.0),
                             seed, span_s, step_s)
        row = cal.to_dict()
        row["residual_error_deg"] = float(cal.residual_error_deg)
        return row
    p_ref: dict = {}  # channel i's reference power per probe (fixed over the sweep)
    ranges, _, _, st = _pair_probes(setup, paths, pair, probe, 0.0, p_ref)
    base = [float(requested_delay(scene, r)) for r in ranges]
    noisy = adds_noise(scene)

    def signed(delta: float, frames: int = 1, repeat: int = 0) -> np.ndarray:
        """The probes' detected direction-cosine errors (P * D,) (NaN: not detected), the
        coherent average of ``frames`` frames (``repeat`` > 0: an independent measurement
        of the same step, other noise)."""
        _, designs, predicted, _ = _pair_probes(setup, paths, pair, probe, delta, p_ref)
        tg, fe, dl, amp = [], [], [], []
        for k, (a, b) in enumerate(zip(base, designs)):
            tg += [k, k]
            fe += list(pair)
            dl += [a, a + delta]
            amp += list(b)
        prog = RtsProgram.build(tg, fe, dl, np.zeros(len(tg)), amp)
        step_seed = np.random.SeedSequence([int(seed) % 2 ** 32, int(round(delta * 1e15))
                                            + 2 ** 40, pair[0], pair[1]]
                                           + ([int(frames)] if frames > 1 else [])
                                           + ([7919, int(repeat)] if repeat else []))
        rd, det = simulate_detect(setup, paths, prog, step_seed, frames)
        out = np.full((len(ranges), st.dims), np.nan)
        for p, (r, u_pred) in enumerate(zip(ranges, predicted)):
            k = nearest_detection(det, rd, r)
            if k is not None:
                out[p] = _angles_to_u(st, det, k) - u_pred
        return out.ravel()

    span = span_s or rts.calibration_span_s
    step = step_s or rts.calibration_step_s
    grid = np.arange(span[0], span[1] + step / 2, step)
    res = rts.delay_resolution_s
    grid = np.unique(realisable(grid, res))  # the delays as the RTS realises them

    def coarse(frames: int):
        errs = rms_error_deg(np.array([signed(d, frames) for d in grid]))
        if not np.any(np.isfinite(errs)):
            raise CalibrationFailed(f"pair {tuple(int(q) for q in pair)}: no probe detected "
                                    "at any step of the sweep")
        return errs, coarse_minimum(grid, errs)

    period = 1.0 / float(if_phase_slope_hz(scene, probe_total_delay(setup, ranges)))
    # The fine sweep and its fit are the pair calibration's (``calibration.calibrate_pair``):
    # +-period/4 around the coarse minimum, the signed errors of each probe in each axis
    # fitted with their periodic shape (``sweep.fit_minimum``), the FIR's known phase taken
    # out (``calsteps.sweep_phase``). A parabola through the RMS (what this was before) is
    # biased towards the coarse grid point where the RMS is V-shaped and noisy, and a shallow
    # axis (elevation: one wavelength of aperture) carried 16 to 32 ps into the pair
    # (sphere4: 30 ps on the diagonal pair, loop closure -29 ps; 32 ps with a 90 deg phase
    # offset on a front end).
    half = period / 4
    fine_step = res * max(1, round(FINE_STEP_ND_S / res))
    k_half, harmonics, criterion = fine_window(half, fine_step)

    def fine(near: float, frames: int):
        """The fine sweep around ``near`` and its fit: (delays, errors (S, P * D), the fit
        (a function of the errors' fitted columns -> (minimum, fitted curves)), columns)."""
        fine_t = near + np.arange(-k_half, k_half + 1) * fine_step
        e_fine = np.array([signed(d, frames) for d in fine_t])  # (S, P * D)
        extra, search_phase = sweep_phase(setup, ranges, fine_t, (0.0, 0.0), period)
        cols = crossing_columns(e_fine)
        if extra is not None:  # per probe -> per probe and axis
            extra = np.repeat(np.asarray(extra, float).reshape(fine_t.size, -1), st.dims,
                              axis=1)[:, cols]
        if search_phase is not None:
            sp = search_phase
            search_phase = lambda t: np.repeat(np.asarray(sp(t), float),  # noqa: E731
                                               st.dims, axis=1)[:, cols]

        def fit(e):
            return fit_minimum(fine_t, e, period, near, harmonics, max(half / 2, fine_step),
                               extra, criterion, search_phase, return_fit=True)
        return fine_t, e_fine, fit, cols

    k_coarse = 1
    errs, near = coarse(k_coarse)
    fine_t, e_fine, fit, cols = fine(near, 1)
    best_fit, fitted = fit(e_fine[:, cols])
    k_fine, scatter, noise = 1, 0.0, 0.0
    if noisy:  # frames per step from the sweep's own scatter (the 1-D pair's rule)
        scatter, noise = fit_scatter(fit, fitted, e_fine[:, cols], harmonics, seed, pair)
        if not np.isfinite(scatter):  # too few fine steps for a residual (coarse RTS steps):
            # the noise from a second, independent one-frame sweep (no fit involved)
            again_e = np.array([signed(d, 1, repeat=1) for d in fine_t])
            scatter, noise = fit_scatter(fit, fitted, e_fine[:, cols], harmonics, seed, pair,
                                         repeat=again_e[:, cols])
        if not np.isfinite(scatter):
            raise CalibrationFailed(f"pair {tuple(int(q) for q in pair)}: the probes were not "
                                    "detected at enough steps of the fine sweep to measure "
                                    "its noise")
        # the direction-cosine noise taken as the probe-angle noise (du = cos(theta) d theta:
        # exact at broadside, an underestimate by cos(theta) off it)
        k_coarse = coarse_frames(np.degrees(noise))
        k_fine = fine_frames(scatter)
        again = k_fine > 1
        if k_coarse > 1:  # the coarse sweep was too noisy to trust its minimum: again
            errs, near_k = coarse(k_coarse)
            again, near = again or near_k != near, near_k
        if again:
            fine_t, e_fine, fit, cols = fine(near, k_fine)
            best_fit, _ = fit(e_fine[:, cols])
    best = float(realisable(best_fit, res))  # what the RTS can set
    best_err = float(rms_error_deg(signed(best, k_fine)))
    grid_pts = np.concatenate([grid, fine_t, [best]])
    return {"pair": [int(pair[0]), int(pair[1])], "delta_tau_s": best,
            "residual_error_deg": best_err, "points": int(grid_pts.size),
            "range_offset_m": 0.5 * c * best, "period_s": period,
            "sweep_points": int(grid.size), "fit_s": float(best_fit),
            "coarse_minimum_s": near,
            "fit_columns": [int(q) for q in cols],
            # as the arc pair's record (``Calibration.to_dict``): frames averaged per step,
            # the fitted minimum's 1-sigma with one frame a step, one frame's probe noise
            "frames_per_step": int(k_fine), "coarse_frames_per_step": int(k_coarse),
            "one_frame_scatter_ps": scatter * 1e12,
            "frame_noise_deg": float(np.degrees(noise)),
            # the arc pair's record (``Calibration.to_dict``): RMS probe error per step
            "sweep": _points(grid, errs), "refinement": _points(fine_t, rms_error_deg(e_fine))}


def _points(t, e) -> list[dict]:
    return [{"delta_tau_s": float(a), "angle_error_deg": float(b) if np.isfinite(b) else None}
            for a, b in zip(t, e)]


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
    meas, notes = {}, []
    for e in edges:
        try:
            meas[e] = calibrate_pair_nd(setup, paths, e, probe, seed, span_s, step_s)
        except CalibrationFailed as exc:
            notes.append(f"channel calibration: {exc}")
            continue
        if progress:
            progress(f"calibrated pair {e}: delta_tau {meas[e]['delta_tau_s'] * 1e12:.1f} ps")
    edges = [e for e in edges if e in meas]
    tree_edges = spanning_tree(u_fe, edges, ref) if edges else []
    cut = sorted(set(ch) - {ref} - {q for _, q in tree_edges})
    if cut:  # no chain of calibrated pairs from the reference: no offset for these
        raise CalibrationFailed("; ".join(notes + [f"channels {cut} are not connected to the "
                                                   f"reference {ref} by calibrated pairs"]))
    for p, q in tree_edges:
        i, j = min(p, q), max(p, q)
        d = meas[(i, j)]["delta_tau_s"]  # j relative to i
        offsets[q] = offsets[p] + (d if q == j else -d)
    # Each channel's offset to the period nearest zero: the pair delays add up along the
    # tree to beyond half a period (sphere4 with 180 deg on front end 1: channel 3 at -984
    # ps, its echo a whole range bin (15 cm) from the others, and the cell no longer
    # synthesized (5, 3) deg); one period is the same phase at the probes' range (at another
    # range, 0.6 % of a turn per period at 40 m: what any calibration offset costs there).
    per = float(np.median([m["period_s"] for m in meas.values()]))
    offsets = offsets - per * np.round(offsets / per)
    on_tree = {tuple(sorted(e)) for e in tree_edges}
    closure = []
    for (i, j), m in meas.items():
        if (i, j) in on_tree:
            continue
        per = m["period_s"]
        c = offsets[i] + m["delta_tau_s"] - offsets[j]
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
    return ChannelCalibration(offsets, ref, list(meas.values()), tree_edges, closure, residual,
                              tuple(probe.gain_correction), tuple(notes))


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
