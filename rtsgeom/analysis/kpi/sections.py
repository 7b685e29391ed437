"""The datasheet's sections besides the angle accuracy, each from the analysis that owns it:
the field of view (``pipeline.info.reachable_spans``), range and velocity (the processing's
limits ``scene.rules.resolvable_limits``, the RTS's delay, and the run's detections), targets
(the run's link budget), ghosts and leakage (``analysis.ghosts``, the link budget) and the near
field (``analysis.nearfield``). Each returns a plain dict (the JSON's section, units in the
keys) and the values the spec is checked against.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.constants import c

from ...geometry.farfield import angular_resolution_rad
from ...pipeline.info import reachable_spans
from ...scene.registry import AOA_MODES
from ...scene.rules import resolvable_limits
from ...scene.sections import MAX_TARGETS
from ..ghosts import ghost_analysis
from ..nearfield import nearfield
from ..resolution import ResolutionStudy

__all__ = ["field_of_view", "uncovered_deg", "range_velocity", "targets_section",
           "ghosts_section", "nearfield_section", "resolution_section", "RESOLUTION_STEP_DEG",
           "RESOLUTION_PHASES_DEG"]

RESOLUTION_STEP_DEG = 2.0  # the separations' grid: coarse, for the runtime
RESOLUTION_PHASES_DEG = (0.0, 90.0, 180.0)  # the second target's phase at the RuT


def field_of_view(setup, paths) -> dict:
    """The azimuths the setup emulates with the scene's amplitude mode: each front end alone
    (as the RuT detects it), each adjacent pair's span (synthesizable where the front ends lie
    within the RuT's angular resolution, paper eq. 24, or ``allow_wide_spacing``), the covered
    intervals and the gaps between them; a scene of 2-D cells: its front ends' azimuths and
    elevations."""
    scene = setup.scene
    spans = reachable_spans(setup, None, paths)
    geo = np.degrees(setup.fe_azimuth_rad())
    elev = [float(math.degrees(f.elevation_rad)) for f in scene.rts.front_ends]
    res_deg = math.degrees(angular_resolution_rad(setup.rut))
    if spans.get("cells"):
        return {"mode": spans["mode"], "cells": True, "front_ends": [
            {"index": q, "geometric_azimuth_deg": float(geo[q]), "elevation_deg": elev[q]}
            for q in range(len(geo))],
            "azimuth_deg": [float(geo.min()), float(geo.max())],
            "elevation_deg": [min(elev), max(elev)], "pairs": [], "covered_deg": [],
            "gaps_deg": [], "angular_resolution_deg": res_deg}
    meas = spans["measured_angle_deg"]
    synth = AOA_MODES[spans["mode"]].synthesis
    pairs, covered = [], [[m, m] for m in meas]
    for p in spans["pairs"]:
        i, j = p["pair"]
        spacing = abs(float(geo[j] - geo[i]))
        ok = synth and (spacing <= res_deg or scene.rts.allow_wide_spacing)
        pairs.append({"pair": [i, j], "lo_deg": p["lo_deg"], "hi_deg": p["hi_deg"],
                      "spacing_deg": spacing, "synthesizable": bool(ok)})
        if ok:
            covered.append([p["lo_deg"], p["hi_deg"]])
    merged = _merge(covered)
    gaps = [[a[1], b[0]] for a, b in zip(merged[:-1], merged[1:])]
    return {"mode": spans["mode"], "cells": False,
            "front_ends": [{"index": q, "geometric_azimuth_deg": float(geo[q]),
                            "measured_azimuth_deg": float(meas[q]), "elevation_deg": elev[q]}
                           for q in range(len(meas))],
            "pairs": pairs, "azimuth_deg": [merged[0][0], merged[-1][1]],
            "elevation_deg": [min(elev), max(elev)], "covered_deg": merged, "gaps_deg": gaps,
            "angular_resolution_deg": res_deg}


def _merge(intervals) -> list[list[float]]:
    out: list[list[float]] = []
    for lo, hi in sorted(intervals):
        if out and lo <= out[-1][1] + 1e-9:
            out[-1][1] = max(out[-1][1], hi)
        else:
            out.append([float(lo), float(hi)])
    return out


def uncovered_deg(fov: dict, span) -> float:
    """How much of ``span`` [lo, hi] (deg) the field of view's covered intervals miss."""
    lo, hi = span
    inside = sum(max(0.0, min(hi, b) - max(lo, a)) for a, b in fov["covered_deg"])
    return max(0.0, (hi - lo) - inside)


def range_velocity(setup, run) -> dict:
    """The emulated range span and its limits, the velocity span, the resolution and the
    accuracy the RuT sees on the scene's targets (``run``: its :class:`RunResult`, or None
    without targets)."""
    scene = setup.scene
    radar, rts = scene.radar, scene.rts
    r_lim, v_lim, why_r, why_v = resolvable_limits(radar)
    d_air = float(np.max(np.linalg.norm(setup.fe.module - np.asarray(radar.position_m),
                                        axis=-1)))
    extra = max(0.0, d_air - rts.arc_radius_m) if rts.compensate_air_path else d_air
    bulk_s = ((rts.fractional_delay_taps - 1) / 2 / rts.f_s_hz if rts.fractional_delay
              else 0.0)
    min_air = rts.arc_radius_m if rts.compensate_air_path else d_air
    out = {"min_range_m": min_air + 0.5 * c * bulk_s,
           "max_range_m": r_lim - extra,
           "limits": {
               "air_path_m": min_air,
               "fir_latency_m": 0.5 * c * bulk_s,
               "fir_latency_note": "[assumed] the fractional-delay FIR's bulk (taps - 1)/2 "
                                   "samples are part of the delay buffer (rts.fir), the least "
                                   "delay the back end realises",
               "buffer_note": "the scene declares no buffer depth: no limit from it",
               "processing_max_range_m": r_lim, "processing_note": why_r,
               "unsubtracted_air_path_m": extra},
           "max_velocity_mps": v_lim, "velocity_note": why_v,
           "range_resolution_m": radar.range_resolution_m,
           "velocity_resolution_mps": radar.velocity_resolution_mps,
           "range_step_m": 0.5 * c * rts.delay_resolution_s,
           "range_accuracy_m": None, "velocity_accuracy_mps": None, "targets": []}
    if run is None:
        out["accuracy_note"] = "the scene has no [[targets]] to measure"
        return out
    rows, er, ev = [], [], []
    for m in run.matches:
        e = m.get("error")
        rows.append({"index": m["index"], "set_range_m": m["set"]["range_m"],
                     "set_velocity_mps": m["set"]["velocity_mps"],
                     "range_error_m": None if e is None else e["range_m"],
                     "velocity_error_mps": None if e is None else e["velocity_mps"],
                     "detected": e is not None})
        if e is not None:
            er.append(abs(e["range_m"]))
            ev.append(abs(e["velocity_mps"]))
    out["targets"] = rows
    out["range_accuracy_m"] = max(er) if er else None
    out["velocity_accuracy_mps"] = max(ev) if ev else None
    out["accuracy_note"] = ("largest |detected - set| over the scene's targets through the "
                            "full chain (rtsgeom run), at the scene's SNR")
    return out


def targets_section(setup, run, fov: dict) -> dict:
    """Simultaneous targets: per channel, the back end's ``[rts] max_targets_per_channel``
    where declared, and at most as many echoes of the strongest target's level as the RuT's
    ADC takes before clipping (their amplitudes adding in phase: 10^(margin/20)); in total
    that per channel times the channels over the channels a target uses (2 in the synthesis
    modes); both at most the scene's limit of targets. The resolution KPI is added by the
    study (:func:`resolution_section`)."""
    scene = setup.scene
    margins = []
    if run is not None and run.link_budget is not None:
        margins = [t.get("clip_margin_db") for t in run.link_budget.to_dict()["targets"]]
        margins = [m for m in margins if m is not None]
    n_fe = setup.fe.count
    per_target = 2 if AOA_MODES[fov["mode"]].synthesis and not fov["cells"] else 1
    budget = getattr(scene.rts, "max_targets_per_channel", None)
    notes, per_channel = [], MAX_TARGETS
    margin = min(margins) if margins else None
    if margin is not None:
        per_channel = int(min(per_channel, math.floor(10 ** (margin / 20))))
        notes.append(f"the RuT's ADC clips {margin:.1f} dB above the strongest target's echo: "
                     "that many equal echoes adding in phase")
    if budget is not None:
        per_channel = min(per_channel, int(budget))
        notes.append(f"the back end synthesizes {budget} per channel "
                     "(rts.max_targets_per_channel)")
    if not notes:
        notes.append("no clip margin known (no targets to budget) and no "
                     "rts.max_targets_per_channel: the scene's limit")
    total = int(min(MAX_TARGETS, per_channel * n_fe // per_target))
    return {"per_channel": per_channel, "total": total, "channels": n_fe,
            "channels_per_target": per_target, "clip_margin_db": margin,
            "max_targets_per_channel": budget, "scene_limit": MAX_TARGETS,
            "note": "; ".join(notes)}


def ghosts_section(scene, run) -> dict:
    """Cable ghosts' ranges and levels (``analysis.ghosts``), the setup's own echoes (the
    sheet) in the link budget, the clip margin, and the strongest ghost below its target."""
    rep = ghost_analysis(scene)
    d = rep.to_dict()
    levels = [g["level_db"] for fe in d["front_ends"] for g in fe["ghosts"]]
    setup_echoes = (run.link_budget.to_dict().get("setup_echoes", [])
                    if run is not None and run.link_budget is not None else [])
    strongest = max(levels) if levels else None
    suppression = -strongest if strongest is not None else -d["floor_db"]
    return {"floor_db": d["floor_db"], "cable_ghosts": d["front_ends"], "model": d["model"],
            "strongest_ghost_db": strongest,
            "ghost_suppression_db": suppression,
            "ghost_suppression_note": ("the strongest cable ghost below its target" if levels
                                       else f"no cable ghost above the floor {d['floor_db']:g} "
                                            "dB: at least that"),
            "setup_echoes": setup_echoes,
            "setup_echoes_note": ("the setup's own reflections (the sheet) in the run's link "
                                  "budget; exact paths carry none: rtsgeom info with "
                                  "[radar.link] estimates the sheet by physical optics")}


def nearfield_section(setup):
    """Each front end's distance against the Fraunhofer distance and its bias before
    calibration (``analysis.nearfield`` at the scene's arc radius), and each pair's far-field
    (array-factor) design error the exact model removes: the section and the
    :class:`~rtsgeom.analysis.nearfield.NearField` (its figure)."""
    scene = setup.scene
    nf = nearfield(scene, [scene.rts.arc_radius_m], 5)
    dist = np.linalg.norm(setup.fe.module - np.asarray(scene.radar.position_m), axis=-1)
    d = nf.to_dict()
    at = d["at_scene_radius"]
    fes = [{"index": f["index"], "distance_m": float(dist[f["index"]]),
            "fraunhofer_distance_m": d["fraunhofer_distance_m"],
            "distance_over_fraunhofer": float(dist[f["index"]]) / d["fraunhofer_distance_m"],
            "bias_deg": f["bias_deg"], "phase_error_pp_deg": f["phase_error_pp_deg"]}
           for f in at["front_ends"]]
    return {"fraunhofer_distance_m": d["fraunhofer_distance_m"],
            "fraunhofer_note": d["fraunhofer_note"], "front_ends": fes,
            "pairs": at.get("synthesis", []),
            "bias_1_over_r_coefficient_deg_m": d["bias_1_over_r_coefficient_deg_m"]}, nf


def resolution_section(setup, progress=None) -> dict:
    """The minimum resolvable separation of two equal targets about the arc's middle, the
    truth twin's beside the RTS's, per relative phase (``analysis.resolution``) on a coarse
    grid (every :data:`RESOLUTION_STEP_DEG` up to what the arc reaches); ``rts_deg`` the
    RTS's worst over the phases (None where a phase is not resolved on the grid)."""
    geo = np.degrees(setup.fe_azimuth_rad())
    centre = 0.5 * (geo.min() + geo.max())
    reach = 2 * min(centre - geo.min(), geo.max() - centre) - 1.0
    seps = tuple(float(s) for s in np.arange(RESOLUTION_STEP_DEG, reach + 1e-9,
                                             RESOLUTION_STEP_DEG))
    if not seps:
        return {"min_separation_deg": None, "rts_deg": None, "truth_deg": None,
                "note": f"the arc spans {geo.max() - geo.min():.2f} deg: no two targets "
                        f"{RESOLUTION_STEP_DEG:g} deg apart fit between its front ends"}
    say = None if progress is None else (lambda label, *_: progress(label, 0, 1))
    res = ResolutionStudy(centre_deg=float(centre), separations_deg=seps,
                          phases_deg=RESOLUTION_PHASES_DEG)(setup.scene, say)
    ms = res.min_separation_deg

    def worst(per_phase):
        v = list(per_phase.values())
        return None if not v or any(x is None for x in v) else max(v)
    out = {"min_separation_deg": ms, "rts_deg": worst(ms["rts"]),
           "truth_deg": worst(ms["truth"]), "centre_deg": float(centre),
           "range_m": res.range_m, "separations_deg": list(seps),
           "phases_deg": list(RESOLUTION_PHASES_DEG)}
    out["note"] = ("the RTS's worst over the phases" if out["rts_deg"] is not None else
                   f"the RTS does not resolve two targets at every phase up to {seps[-1]:g} "
                   "deg (the largest separation the arc reaches)")
    return out
