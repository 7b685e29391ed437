"""Which detection is which target, for the RTS's frame and for its truth twin.

The RuT's detections are matched to the set-points by the one association
(:func:`rtsgeom.radar.association.associate`) in the radar's resolution cells; the RTS's targets
where the radar sees them (:func:`rtsgeom.rts.channels.apparent_range`), the truth twin's real
targets at their set range. :func:`truth_twin` looks at the real scene with the same radar and
completes each match with what the real scene would have given.
"""

from __future__ import annotations

import numpy as np

from ..geometry import Setup
from ..geometry.arrays import rut_array
from ..radar import Detections, RangeDoppler, process
from ..radar.association import associate, resolution_cell
from ..radar.frame import FrameView, noise_power, observe_fast
from ..radar.steering import Steering
from ..radar.truth import simulate_truth, truth_echoes
from ..radar.windowed import MapAxes, cell_centres
from ..rts.channels import Echoes, apparent_range
from ..scene import Scene

__all__ = ["association_scale", "direction_columns", "target_points", "detection_points",
           "associate_targets", "match_targets", "undetected_reason", "truth_twin",
           "in_gate"]

def association_scale(scene: Scene, rd: RangeDoppler, steering=None) -> np.ndarray:
    """The association's resolution cell: range bin, velocity bin and the RuT's two-target
    resolution per direction-cosine axis (:func:`rtsgeom.radar.peaks.two_target_resolution`)."""
    st = steering if steering is not None else Steering.auto(rut_array(scene.radar),
                                                             scene.radar)
    return resolution_cell(scene.radar, st, rd)


def direction_columns(az_rad, el_rad, dims: int) -> np.ndarray:
    """The association's direction columns (N, dims): sin az (``dims`` 1) or sin az cos el
    and sin el (``dims`` 2)."""
    az, el = np.asarray(az_rad, float).ravel(), np.asarray(el_rad, float).ravel()
    u = np.sin(az)[:, None] if dims == 1 else np.c_[np.sin(az) * np.cos(el), np.sin(el)]
    return u.reshape(len(az), dims)


def target_points(targets, dims: int, range_m=None) -> np.ndarray:
    """Set-points (T, 2 + dims) as the association compares them: range (``range_m`` (T,),
    where the radar sees them, default the set ranges), velocity and the direction cosines
    (:func:`direction_columns`)."""
    t = list(targets)
    az = np.array([x.angle_rad for x in t], float)
    el = np.array([x.elevation_rad for x in t], float)
    r = [x.range_m for x in t] if range_m is None else range_m
    return np.c_[np.reshape(r, (-1, 1)), np.reshape([x.velocity_mps for x in t], (-1, 1)),
                 direction_columns(az, el, dims)].reshape(len(t), 2 + dims)


def detection_points(det: Detections, dims: int) -> np.ndarray:
    """Detections (D, 2 + dims) in the columns of :func:`target_points`."""
    az, el = np.asarray(det.angle_rad, float), np.radians(det.elevation_deg)
    return np.c_[det.range_m, det.velocity_mps, direction_columns(az, el, dims)].reshape(
        len(det), 2 + dims)


def associate_targets(scene: Scene, det: Detections, rd: RangeDoppler, bins: float = 2,
                      steering=None, targets=None, real: bool = False):
    """The one association of ``targets`` (default the scene's) with ``det``
    (:func:`rtsgeom.radar.association.associate`) in the radar's resolution cells
    (:func:`association_scale`): the RTS's targets where the radar sees them
    (:func:`rtsgeom.rts.channels.apparent_range`), ``real`` ones (the truth twin's) at their
    set range. Returns ``(association, scale, seen_at)`` (``seen_at`` (T,) the ranges
    compared)."""
    targets = tuple(scene.targets if targets is None else targets)
    seen_at = [t.range_m if real else float(apparent_range(scene, t.range_m))
               for t in targets]
    scale = association_scale(scene, rd, steering)
    dims = scale.size - 2
    assoc = associate(target_points(targets, dims, seen_at), detection_points(det, dims),
                      scale, bins)
    return assoc, scale, seen_at


def match_targets(scene: Scene, det: Detections, rd: RangeDoppler, bins: int = 2,
                  steering=None, targets=None, real: bool = False) -> list[dict]:
    """Each target's detection by the one association (:func:`rtsgeom.radar.association.associate`):
    an optimal assignment in resolution cells, never a detection that lies nearer another
    target; ``status`` ``detected``, ``merged`` (one detection serves several targets the
    radar cannot resolve: ``merged_with``) or ``not_detected``.

    ``targets`` defaults to the scene's; ``steering`` (the cube's) to the scene radar's
    beamformer; ``bins`` is the range and Doppler gate. The RTS's targets are compared where
    the radar sees them (:func:`rtsgeom.rts.channels.apparent_range`: R_c further without
    ``rts.compensate_air_path``); ``real`` targets (the truth twin's) at their set range.
    """
    targets = tuple(scene.targets if targets is None else targets)
    assoc, scale, seen_at = associate_targets(scene, det, rd, bins, steering, targets, real)
    dr, dv = scale[0], scale[1]
    out = []
    for i, t in enumerate(targets):
        j = int(assoc.detection[i])
        entry = {"index": i, "set": {"range_m": t.range_m, "velocity_mps": t.velocity_mps,
                                     "angle_deg": float(np.degrees(t.angle_rad)),
                                     "rcs_dbsm": t.rcs_dbsm},
                 "status": assoc.status[i], "merged_with": list(assoc.merged_with[i])}
        if det.elevation_rad is not None:
            entry["set"]["elevation_deg"] = float(np.degrees(t.elevation_rad))
        if j >= 0:
            d = {"range_m": float(det.range_m[j]), "velocity_mps": float(det.velocity_mps[j]),
                 "angle_deg": float(det.angle_deg[j]), "power_db": float(det.power_db[j]),
                 "snr_db": float(det.snr_db[j])}
            entry["detection"] = d
            entry["detection_index"] = j
            entry["error"] = {  # from where the RuT sees it (rts.channels.apparent_range)
                "range_m": d["range_m"] - seen_at[i],
                "velocity_mps": d["velocity_mps"] - t.velocity_mps,
                "angle_deg": d["angle_deg"] - entry["set"]["angle_deg"],
                "range_bins": (d["range_m"] - seen_at[i]) / dr,
                "doppler_bins": (d["velocity_mps"] - t.velocity_mps) / dv,
            }
            if det.elevation_rad is not None:  # a RuT with elevation: both angles
                d["elevation_deg"] = float(det.elevation_deg[j])
                entry["error"]["elevation_deg"] = d["elevation_deg"] - entry["set"][
                    "elevation_deg"]
        else:
            entry["detection"] = None
            entry["error"] = None
            # why, from the map (None on the fast path, which forms no map)
            entry["undetected"] = None if isinstance(rd, MapAxes) else undetected_reason(
                scene, det, rd, t, bins, assoc.owner, seen_at[i])
        out.append(entry)
    return out


def in_gate(det: Detections, rd, range_m: float, velocity_mps: float,
            bins: int) -> np.ndarray:
    """Which detections lie within ``bins`` range and Doppler bins of (``range_m``,
    ``velocity_mps``) on the map axes ``rd`` (the association's gate, ends included)."""
    dr = rd.range_m[1] - rd.range_m[0]
    dv = rd.velocity_mps[1] - rd.velocity_mps[0]
    return ((np.abs(det.range_m - range_m) <= bins * dr)
            & (np.abs(det.velocity_mps - velocity_mps) <= bins * dv))


def undetected_reason(scene: Scene, det: Detections, rd: RangeDoppler, target,
                      bins: int = 2, owner=None, seen_at: float | None = None) -> dict:
    """Why a target has no detection: the map's strongest cell within one bin of the target's
    cell over the map's noise (the median of the channel-summed power, a Gamma(V) variable,
    referred to its mean), against the CFAR threshold; or that a detection within ``bins``
    went to another target (two targets in one cell). ``snr_db`` None: a noiseless map."""
    r_t = float(apparent_range(scene, target.range_m)) if seen_at is None else seen_at
    ri = int(np.argmin(np.abs(rd.range_m - r_t)))
    vi = int(np.argmin(np.abs(rd.velocity_mps - target.velocity_mps)))
    cell = rd.power[max(ri - 1, 0):ri + 2, max(vi - 1, 0):vi + 2]
    v = rd.spectrum.shape[-1]
    from scipy.special import gammaincinv  # median of Gamma(V, 1)
    noise = float(np.median(rd.power)) * v / float(gammaincinv(v, 0.5))
    thr = float(scene.radar.cfar.threshold_db)
    snr = None if noise <= 0 else float(10 * np.log10(max(float(cell.max()), 1e-300) / noise))
    near = in_gate(det, rd, r_t, target.velocity_mps, bins)
    if np.any(near):
        mine = np.flatnonzero(near)
        others = sorted({int(owner[j]) for j in mine if owner is not None and owner[j] >= 0})
        why = ("the detection(s) in its cell lie nearer " + (
            "target " + ", ".join(map(str, others)) if others else "another target")
            + ", more than one angular resolution cell from it (two targets in one cell: "
            "see the truth twin)")
    elif snr is not None and snr < thr:
        why = (f"{snr:.1f} dB over the noise at its cell, under the CFAR threshold "
               f"{thr:g} dB (radar.snr_db, when set, is the SNR of the strongest echo)")
    else:
        why = "the CFAR did not report its cell (masked by a stronger neighbour or out of range)"
    return {"snr_db": snr, "threshold_db": thr, "reason": why}


def truth_twin(setup: Setup, targets, echoes: Echoes, matches: list[dict], bins: int = 2,
               seed: int | None = None, compare=None, look: FrameView | None = None
               ) -> tuple[Detections, list[dict], str | None]:
    """The same radar on the real scene (:mod:`rtsgeom.radar.truth`), with the RTS frame's
    noise seed and power, and each target's match completed with ``truth`` (the truth twin's
    own detection of it: range, velocity, angle, elevation where 2-D; None where the real
    scene gives it none of its own either), ``truth_status`` and ``vs_truth`` (the RTS's
    detection minus the truth's, same keys; None unless both exist).

    ``compare``: the targets ``matches`` are of, where they are not ``targets`` (a budget's
    synthesized targets, :mod:`rtsgeom.pipeline.merge`): the truth twin looks at the real
    ``targets`` and each of ``compare`` gets the truth twin's detection of its cell.

    ``look``: the RTS frame's :class:`~rtsgeom.radar.frame.FrameView` (of ``echoes``); where it
    asked for the fast path the truth twin takes it too
    (:func:`rtsgeom.radar.frame.observe_fast`, sharing the RTS frame's noise spectrum), the
    full chain where its frame is outside it.

    Returns the truth twin's detections, the completed matches (new dicts) and why the full
    chain ran where the fast path was asked for (None otherwise)."""
    scene = setup.scene
    seed = scene.seed if seed is None else seed
    snr = scene.radar.snr_db
    noise_w = noise_power(echoes, snr) if snr is not None else None
    near = tuple(targets) if compare is None else tuple(targets) + tuple(compare)
    fast, why = look is not None and look.chain == "fast", None
    if fast:
        view = observe_fast(setup, truth_echoes(setup, targets), cell_centres(
            scene.radar, [t.range_m for t in near], [t.velocity_mps for t in near]), bins,
            seed, noise_w or 0.0, look.noise)
        t_det, t_rd, t_st, why = view.detections, view.rd, view.steering, view.fallback
    if not fast or why is not None:
        _, t_cube = simulate_truth(setup, targets, seed, noise_w)
        t_rd, t_det = process(t_cube)
        t_st = t_cube.steering
    t_matches = match_targets(scene, t_det, t_rd, bins=bins, steering=t_st,
                              targets=targets if compare is None else compare, real=True)
    keys = ("range_m", "velocity_mps", "angle_deg", "elevation_deg")
    out = []
    for m, t in zip(matches, t_matches):
        truth = None
        if t["status"] == "detected":
            truth = {k: t["detection"][k] for k in keys if k in t["detection"]}
        rts = m.get("detection")
        vs = (None if truth is None or rts is None
              else {k: rts[k] - truth[k] for k in truth if k in rts})
        out.append({**m, "truth": truth, "truth_status": t["status"], "vs_truth": vs})
    return t_det, out, why
