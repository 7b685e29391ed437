"""Dynamic resolution: the RTS's targets under a per-channel budget.

An extended object is many scatterers, each one synthesized target on a pair of channels
(front ends). Hardware synthesizes at most ``[rts] max_targets_per_channel`` targets per
channel. Under that budget the planner first merges the scatterers the RuT cannot resolve
anyway -- within one range resolution cell, one velocity cell and the RuT's two-target
angular resolution (:func:`rtsgeom.radar.peaks.two_target_resolution`) of the strongest of
them -- into one synthesized target, then drops the weakest targets on every channel still
over the budget.

A merged target reproduces what the RuT sees from the scatterers' *coherent* sum, not their
power centroid (a radar does not see a power centroid): its range and direction are the truth
twin's (:func:`rtsgeom.radar.truth.simulate_truth`, noiseless) detection of that cell -- glint
included: two scatterers a quarter wavelength apart in range pull the detected angle outside
their span -- and its RCS the one a single point there needs for the truth twin's detected
power (the power of the cell's detection minus that of a 0 dBsm point at the detected range,
velocity and direction, through the same radar). Where the truth twin has no detection of
the cell (weaker than its CFAR threshold) the strongest member's range and direction stand
in, with the scatterers' coherent sum at the carrier,
``sigma = |sum_i sqrt(sigma_i) (r0 / r_i)^2 exp(-j 4 pi r_i / lambda)|^2`` at ``r0`` its range.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..geometry import Setup
from ..radar import process
from ..radar.association import resolution_cell
from ..radar.steering import Steering
from ..radar.fmcw import synthesize_each
from ..radar.link import apply_radar_link
from ..radar.processing import range_doppler_power
from ..radar.truth import simulate_truth, truth_echoes
from ..scene import TargetConfig

__all__ = ["Budgeted", "budget_targets", "resolution_clusters", "cell_scale",
           "reference_power_db", "REFERENCE_CHUNK"]


@dataclass(frozen=True)
class Budgeted:
    """The targets the RTS synthesizes under a budget.

    ``targets`` the synthesized targets; ``members`` per synthesized target the indices of the
    scene's targets (scatterers) it stands for, strongest first; ``dropped`` the scene's
    targets left out; ``centroid_deg`` per synthesized target the members' power-centroid
    azimuth (what a merge by power would have set; equal to its azimuth for one member);
    ``truth_found`` whether the truth twin detected the cell."""

    targets: tuple[TargetConfig, ...]
    members: tuple[tuple[int, ...], ...]
    dropped: tuple[int, ...]
    centroid_deg: tuple[float, ...]
    truth_found: tuple[bool, ...]
    limit: int

    @property
    def counts(self) -> dict:
        """``kept`` (synthesized targets), ``merged`` (scatterers folded into a kept target
        of two or more), ``dropped`` (scatterers not synthesized) and ``scatterers``."""
        merged = sum(len(m) for m in self.members if len(m) > 1)
        n = sum(len(m) for m in self.members) + len(self.dropped)
        return {"scatterers": n, "kept": len(self.targets), "merged": merged,
                "dropped": len(self.dropped)}

    def lead(self) -> np.ndarray:
        """Per synthesized target the scene index of its strongest member (the programme's
        ``target``)."""
        return np.array([m[0] for m in self.members], int)

    def to_dict(self) -> dict:
        return {"max_targets_per_channel": self.limit, **self.counts,
                "targets": [{"members": list(m), "range_m": t.range_m,
                             "azimuth_deg": float(np.degrees(t.angle_rad)),
                             "rcs_dbsm": t.rcs_dbsm, "power_centroid_azimuth_deg": cd,
                             "from_truth_twin": bool(tf)}
                            for m, t, cd, tf in zip(self.members, self.targets,
                                                    self.centroid_deg, self.truth_found)],
                "dropped_targets": list(self.dropped)}


def cell_scale(setup: Setup) -> np.ndarray:
    """The RuT's resolution cell: range resolution (m), velocity resolution (m/s) and its
    two-target resolution in azimuth direction cosine (the range-Doppler map's bins)."""
    radar = setup.scene.radar
    return resolution_cell(radar, Steering.auto(setup.rut, radar))[:3]  # azimuth only


def _power(targets) -> np.ndarray:
    return np.array([t.rcs_m2 / t.range_m ** 4 for t in targets])


def resolution_clusters(targets, scale) -> list[list[int]]:
    """Groups of targets the RuT cannot resolve: greedily from the strongest, every target
    within one cell of ``scale`` (range, velocity, direction cosine) of the group's strongest
    joins it. Groups in order of their strongest member's index; members strongest first."""
    t = list(targets)
    pts = np.array([[x.range_m, x.velocity_mps, np.sin(x.angle_rad)] for x in t]).reshape(-1, 3)
    order = np.argsort(-_power(t), kind="stable")
    free = np.ones(len(t), bool)
    groups = []
    for i in order:
        if not free[i]:
            continue
        near = free & np.all(np.abs(pts - pts[i]) < np.asarray(scale), axis=1)
        near[i] = True
        members = [i] + [j for j in order if near[j] and j != i]
        free[members] = False
        groups.append([int(j) for j in members])
    return sorted(groups, key=lambda g: g[0])


#: reference points per batch of :func:`reference_power_db` (memory: this many ADC cubes)
REFERENCE_CHUNK = 16


def reference_power_db(setup: Setup, refs) -> np.ndarray:
    """The truth twin's detected power (dB, noiseless) of each point target of ``refs`` alone
    (K,): the peak of its own range-Doppler map (what :func:`rtsgeom.radar.process` reports as
    a lone point's ``power_db``), all K at once -- one cube per point
    (:func:`rtsgeom.radar.fmcw.synthesize_each`, in blocks of :data:`REFERENCE_CHUNK`) through
    :func:`rtsgeom.radar.processing.range_doppler_power`. With ``[radar.link]`` the link's
    gains apply; its ADC quantisation does not (a lone point far above it)."""
    refs = list(refs)
    if not refs:
        return np.zeros(0)
    scene = setup.scene
    echoes = truth_echoes(setup, refs)
    if scene.radar.link is not None:
        echoes = apply_radar_link(echoes, scene)
    out = np.empty(len(refs))
    for s in range(0, len(refs), REFERENCE_CHUNK):  # blocks of points, each block one batch
        part = echoes.select((np.arange(len(refs)) >= s) & (np.arange(len(refs))
                                                            < s + REFERENCE_CHUNK))
        power = range_doppler_power(synthesize_each(part, scene.radar, setup.rut), scene.radar)
        out[s:s + len(part)] = 10 * np.log10(np.maximum(power.max(axis=(-2, -1)), 1e-300))
    return out


def _merged(setup, targets, group, det, scale) -> tuple[TargetConfig, float, bool, float]:
    """One synthesized target for ``group`` (module docstring): (target, power-centroid
    azimuth in deg, whether the truth twin's detection set it, that detection's power in dB
    or NaN). Where it did, the target's RCS is set by :func:`budget_targets` from the
    detection's power and a reference point's (:func:`reference_power_db`)."""
    wavelength_m = setup.scene.radar.wavelength_m
    ts = [targets[j] for j in group]
    p = _power(ts)
    r = np.array([x.range_m for x in ts])
    u = np.sin([x.angle_rad for x in ts])
    v = float(np.sum(p * [x.velocity_mps for x in ts]) / p.sum())
    centroid = float(np.degrees(np.arcsin(np.clip(np.sum(p * u) / p.sum(), -1, 1))))
    lead = ts[0]
    if len(ts) == 1:
        return lead, centroid, False, float("nan")
    r_c = float(np.sum(p * r) / p.sum())
    found, power_db = False, float("nan")
    rng, az = lead.range_m, lead.angle_rad
    if len(det):
        d_u = np.sin(det.angle_rad)
        near = ((np.abs(det.range_m - r_c) <= scale[0]) & (np.abs(det.velocity_mps - v)
                                                            <= scale[1])
                & (np.abs(d_u - np.sum(p * u) / p.sum()) <= scale[2]))
        if near.any():
            j = np.flatnonzero(near)[np.argmax(det.power_db[near])]
            rng, az, found = float(det.range_m[j]), float(det.angle_rad[j]), True
            power_db = float(det.power_db[j])
    amp = np.sqrt([x.rcs_m2 for x in ts]) * (rng / r) ** 2 * np.exp(
        -4j * np.pi * r / wavelength_m)
    rcs_db = float(10 * np.log10(max(abs(amp.sum()) ** 2, 1e-10)))
    objs = {x.object_index for x in ts}
    return (TargetConfig(range_m=rng, velocity_mps=v, rcs_dbsm=float(np.clip(rcs_db, -100, 100)),
                         angle_rad=az, object_index=objs.pop() if len(objs) == 1 else -1),
            centroid, found, power_db)


def _with_detected_power(setup, made: list) -> list:
    """The merged targets the truth twin detected with the RCS a single point there needs
    for the cell's detected power: that power minus a 0 dBsm reference point's at the same
    range, velocity and direction (:func:`reference_power_db`, all at once)."""
    idx = [k for k, m in enumerate(made) if m[2]]
    refs = [dataclasses.replace(made[k][0], rcs_dbsm=0.0) for k in idx]
    out = list(made)
    for k, ref_db in zip(idx, reference_power_db(setup, refs)):
        t, cd, found, power_db = made[k]
        rcs = float(np.clip(power_db - ref_db, -100, 100))
        out[k] = (dataclasses.replace(t, rcs_dbsm=rcs), cd, found, power_db)
    return out


def budget_targets(setup: Setup, targets, probe, pair_of, limit: int | None = None
                   ) -> Budgeted:
    """The targets the RTS synthesizes under ``limit`` targets per channel (default the
    scene's ``rts.max_targets_per_channel``): merged where the RuT cannot resolve them, then
    the weakest dropped on every channel over the limit (module docstring). ``probe``: the
    front ends as the RuT measures them; ``pair_of(angle_rad, probe_angles_rad)`` a target's
    channels (the planner's ``plan.probe_pair``: the pair it plans the target on)."""
    scene = setup.scene
    limit = scene.rts.max_targets_per_channel if limit is None else limit
    targets = tuple(targets)
    scale = cell_scale(setup)
    groups = resolution_clusters(targets, scale)
    det = None
    if any(len(g) > 1 for g in groups):  # the truth twin's view of every cell, noiseless
        _, cube = simulate_truth(setup, targets, scene.seed, 0.0)
        det = process(cube)[1]
    made = _with_detected_power(setup, [_merged(setup, targets, g, det, scale)
                                        for g in groups])
    keep = np.ones(len(groups), bool)
    power = _power([m[0] for m in made])
    pairs = [pair_of(m[0].angle_rad, probe.angle_rad) for m in made]
    n_ch = len(probe.angle_rad)
    while True:
        load = np.zeros(n_ch, int)
        for k in np.flatnonzero(keep):
            if pairs[k] is not None:
                load[list(pairs[k])] += 1
        over = set(np.flatnonzero(load > limit).tolist())
        cand = [k for k in np.flatnonzero(keep) if pairs[k] is not None and over & set(pairs[k])]
        if not cand:
            break
        keep[min(cand, key=lambda k: power[k])] = False
    kept = np.flatnonzero(keep)
    return Budgeted(tuple(made[k][0] for k in kept), tuple(tuple(groups[k]) for k in kept),
                    tuple(sorted(j for k in np.flatnonzero(~keep) for j in groups[k])),
                    tuple(made[k][1] for k in kept), tuple(made[k][2] for k in kept),
                    int(limit))
