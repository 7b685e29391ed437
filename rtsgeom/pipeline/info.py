"""``rtsgeom info``: what a setup is, in numbers an RF engineer checks first."""

from __future__ import annotations

import warnings

import numpy as np

from .. import __version__
from ..geometry import Setup
from ..geometry.farfield import (angular_resolution_rad, aperture_m, apparent_azimuth_rad,
                                 coarray_period_m, curvature_phase_error_rad, fraunhofer_distance_m,
                                 grating_lobe_directions_rad, smallest_spacing_m,
                                 unambiguous_half_width_rad)
from ..calibration.probes import probe_front_ends
from ..errors import SceneError
from ..paths import exact_paths
from ..radar.budget import format_budget
from ..radar.channels import channel_coupling, channel_gain, plane_wave_errors
from ..radar.steering import Steering
from .plan import modelled_pair, target_cells, uses_cells

__all__ = ["scene_info", "format_info", "reachable_spans"]

CLOSED_FORM_MODES = ("paper", "array-factor")


def reachable_spans(setup: Setup, mode: str | None = None, paths=None) -> dict:
    """The angles ``rtsgeom run`` can synthesize, per adjacent front-end pair.

    The span is *measured* as ``run`` measures it (:func:`rtsgeom.calibration.pair.
    probe_front_ends`: each front end alone, detected by the simulated RuT with the scene's
    seed and noise; the Rx/Tx separation and the near field move it off the geometric
    angles), pairs adjacent in measured angle, each target's the pair ``run`` plans it on
    (:func:`rtsgeom.pipeline.plan.modelled_pair`). The
    closed-form amplitude modes (``paper``, ``array-factor``) address only the front ends'
    geometric angles, so for them the span is the intersection. ``nearest`` puts each target
    on its nearest front end: every angle is accepted.

    Parameters
    ----------
    setup : Setup
    mode : str, optional
        Amplitude mode (default: the scene's ``rts.aoa_mode``).
    paths : Paths, optional
        Default: exact paths (``run``'s default; ``run --paths raytrace`` measures on its own).

    Returns
    -------
    dict
        ``mode``, ``measured_angle_deg`` per front end, ``pairs`` (each ``pair``, ``lo_deg``,
        ``hi_deg``) and ``targets`` (each ``index``, ``angle_deg``, ``pair`` or None,
        ``reachable``).
    """
    scene = setup.scene
    mode = mode or scene.rts.aoa_mode
    if uses_cells(scene):
        return _reachable_cells(setup, mode)
    with warnings.catch_warnings():  # a front end not detected: said below, as the reason
        warnings.simplefilter("ignore", RuntimeWarning)
        probe = probe_front_ends(setup, exact_paths(setup) if paths is None else paths,
                                 scene.seed)
    meas = probe.angle_rad
    missed = [int(q) for q in np.flatnonzero(~np.isfinite(meas))]
    if missed:  # no span to state (it would be NaN): why instead
        raise SceneError(f"front end(s) {missed} not detected alone by the RuT at their probe "
                         "ranges (below the CFAR threshold with this link and noise, or "
                         f"clipped){probe.clipping_note()}: the angles between them cannot be measured")
    geo = setup.fe_azimuth_rad()
    order = np.argsort(meas)
    pairs = []
    for i, j in zip(order[:-1], order[1:]):
        lo, hi = float(meas[i]), float(meas[j])
        if mode in CLOSED_FORM_MODES:
            g_lo, g_hi = sorted((float(geo[i]), float(geo[j])))
            lo, hi = max(lo, g_lo), min(hi, g_hi)
        pairs.append({"pair": [int(i), int(j)], "lo_deg": float(np.degrees(lo)),
                      "hi_deg": float(np.degrees(hi))})
    targets = []
    for k, t in enumerate(scene.targets):
        pair = None if not np.all(np.isfinite(meas)) else modelled_pair(t.angle_rad, probe)
        ok = pair is not None
        if ok and mode in CLOSED_FORM_MODES:
            span = next(p for p in pairs if sorted(p["pair"]) == sorted(pair))
            ok = span["lo_deg"] <= np.degrees(t.angle_rad) <= span["hi_deg"]
        targets.append({"index": k, "angle_deg": float(np.degrees(t.angle_rad)),
                        "pair": None if pair is None else [int(pair[0]), int(pair[1])],
                        "reachable": bool(ok or mode == "nearest")})
    return {"mode": mode, "measured_angle_deg": [float(x) for x in np.degrees(meas)],
            "pairs": pairs, "targets": targets}


def _reachable_cells(setup: Setup, mode: str) -> dict:
    """:func:`reachable_spans` of a scene of 2-D cells: each target's enclosing cell of front
    ends (``pipeline.plan.target_cells``, what ``run`` plans with); ``pairs`` is empty (the
    cells are not pairs along an arc) and ``cells`` True."""
    _, _, found = target_cells(setup)
    targets = [{"index": k, "angle_deg": float(np.degrees(t.angle_rad)),
                "elevation_deg": float(np.degrees(t.elevation_rad)),
                "pair": None, "cell": None if cell is None else [int(q) for q in cell],
                "reachable": cell is not None, "why": why}
               for k, (t, (cell, why)) in enumerate(zip(setup.scene.targets, found))]
    return {"mode": mode, "cells": True, "pairs": [], "targets": targets}


def scene_info(setup: Setup, reachable: bool = False) -> dict:
    """What a setup is, in numbers (``rtsgeom info --json``); with ``reachable`` also
    :func:`reachable_spans` (one simulated frame).

    Parameters
    ----------
    setup : Setup
    reachable : bool
        Also the set directions each target can reach.

    Returns
    -------
    dict
        What ``rtsgeom info --json`` prints.
    """
    s, r, rut, fe = setup.scene, setup.scene.radar, setup.rut, setup.fe
    one_position = rut.azimuth_positions_m.size < 2
    spacing = np.degrees(np.diff(fe.angle_rad))
    res = np.degrees(angular_resolution_rad(rut))
    out = {
        "rtsgeom_version": __version__,
        "scene": s.name,
        "source": s.source,
        "scene_sha256": s.sha256,
        "radar": _radar_info(setup),
        "far_field": {
            "aperture_m": aperture_m(rut),
            "angular_resolution_deg": res,
            "fraunhofer_distance_m": fraunhofer_distance_m(rut),
            "arc_radius_m": s.rts.arc_radius_m,
        },
        "virtual_array": _virtual_array(rut),
        "rts": {
            "f_rts_hz": s.rts.f_rts_hz, "f_s_hz": s.rts.f_s_hz,
            "delay_resolution_s": s.rts.delay_resolution_s,
            "calibration_period_s": 1.0 / (s.rts.f_rts_hz + r.bandwidth_hz / 2.0),
        },
        "front_ends": _front_ends_info(setup, one_position),
        "front_end_spacing_deg": [float(x) for x in spacing],
        "spacing_within_resolution": [bool(x <= res) for x in spacing],
        "targets": [
            {"range_m": t.range_m, "velocity_mps": t.velocity_mps, "rcs_dbsm": t.rcs_dbsm,
             "angle_deg": float(np.degrees(t.angle_rad)),
             "elevation_deg": float(np.degrees(t.elevation_rad))}
            for t in s.targets
        ],
    }
    bias = _channel_bias_deg(setup)
    if bias is not None:
        for q, b in enumerate(bias):
            out["front_ends"][q]["radar_channel_bias_deg"] = _finite(b)
    if one_position:
        out["apparent_azimuth_unavailable"] = NO_AZIMUTH_APERTURE
    if reachable and one_position:  # every angle would read -90 deg: no span to state
        out["reachable_unavailable"] = NO_AZIMUTH_APERTURE
    elif reachable:
        try:
            out["reachable"] = reachable_spans(setup)
        except SceneError as exc:  # a setup the synthesis does not model (its message says)
            out["reachable_unavailable"] = str(exc)
    return out


def _radar_info(setup: Setup) -> dict:
    """``scene_info``'s ``radar``: the chirp, the array and the resolutions."""
    r, rut = setup.scene.radar, setup.rut
    return {
        "antenna_preset": r.antenna_preset if r.array is None else "custom",
        "array": rut.name,
        "f_c_hz": r.f_c_hz, "bandwidth_hz": r.bandwidth_hz,
        "f_center_hz": r.f_center_hz, "wavelength_m": rut.wavelength_m,
        "slope_hz_per_s": r.slope_hz_per_s,
        "num_tx": int(len(rut.tx_local)),
        "tx_order": list(rut.tx_order), "num_rx": rut.num_rx,
        "num_virtual": rut.num_virtual,
        "num_virtual_azimuth": int(np.count_nonzero(rut.azimuth_mask)),
        "element_spacing_m": rut.spacing_m,
        "range_resolution_m": r.range_resolution_m, "max_range_m": r.max_range_m,
        "velocity_resolution_mps": r.velocity_resolution_mps,
        "max_velocity_mps": r.max_velocity_mps,
    }


def _front_ends_info(setup: Setup, one_position: bool) -> list[dict]:
    """``scene_info``'s ``front_ends``: where each is and how the RuT sees it alone."""
    rut, fe = setup.rut, setup.fe
    geo = np.degrees(setup.fe_azimuth_rad())
    if one_position:  # no azimuth aperture: a single front end's azimuth is not measured
        app = np.full(fe.count, np.nan)
    else:
        app = np.degrees(apparent_azimuth_rad(rut, fe.rx, fe.tx))
    curv = np.degrees(curvature_phase_error_rad(setup))
    # elevation of each module centre seen from the RuT: u_el = sin(el) (radar frame)
    fe_el = np.zeros(fe.count) if fe.elevation_rad is None else fe.elevation_rad  # None: an arc
    el_rut = np.degrees(np.arcsin(np.clip(setup.fe_direction_cosines()[:, 1], -1.0, 1.0)))
    return [
        {
            "index": i,
            "arc_angle_deg": float(np.degrees(fe.angle_rad[i])),
            "azimuth_from_rut_deg": float(geo[i]),
            "apparent_azimuth_deg": _finite(app[i]),
            "distance_m": float(np.linalg.norm(fe.module[i] - rut.position)),
            "rx_tx_separation_m": float(fe.separation_m[i]),
            "mounting_offsets_mm": [float(x) for x in fe.offsets_m[i] * 1e3],
            "curvature_phase_error_deg": float(curv[i]),
            "elevation_deg": float(np.degrees(fe_el[i])),
            "elevation_from_rut_deg": float(el_rut[i]),
        }
        for i in range(fe.count)
    ]


def _channel_bias_deg(setup: Setup) -> list[float] | None:
    """The radar's own angle error (deg) from its ``[radar.channels]`` on a far-field target at
    each front end's azimuth (``radar.channels.plane_wave_errors``), None for an ideal radar
    or a 2-D beamformer."""
    radar, rut = setup.scene.radar, setup.rut
    g = channel_gain(radar, rut)
    st = Steering.auto(rut, radar)
    if g is None or st.dims != 1:
        return None
    err = plane_wave_errors(st, g[None], setup.fe_azimuth_rad(), channel_coupling(radar, rut))
    return [float(x) for x in np.degrees(err[0])]


NO_AZIMUTH_APERTURE = ("the azimuth virtual array has fewer than two distinct positions "
                       "(a single element, or elements stacked in elevation): no azimuth is "
                       "measured, so the apparent azimuth and the smallest gap are null")


def _finite(x) -> float | None:
    """A value for the JSON: None where it is undefined (the reason is stated beside it)."""
    x = float(x)
    return x if np.isfinite(x) else None


def _virtual_array(rut) -> dict:
    """The azimuth virtual array as the beamformer sees it: distinct positions (duplicates
    combined), smallest gap, co-array period, grating lobes at boresight, unambiguous field."""
    x = rut.azimuth_positions_m
    period = coarray_period_m(rut)
    gl = np.degrees(grating_lobe_directions_rad(rut))
    return {
        "tx_local_mm": [[float(v) for v in p] for p in rut.tx_local[:, [0, 2]] * 1e3],
        "rx_local_mm": [[float(v) for v in p] for p in rut.rx_local[:, [0, 2]] * 1e3],
        "num_azimuth_elements": int(np.count_nonzero(rut.azimuth_mask)),
        "num_azimuth_unique": int(x.size),
        "azimuth_positions_mm": [float(v) for v in x * 1e3],
        "azimuth_positions_wavelengths": [float(v) for v in x / rut.wavelength_m],
        "smallest_spacing_m": _finite(smallest_spacing_m(rut)),
        "coarray_period_m": period,
        "uniform": bool(x.size > 1 and np.allclose(np.diff(x), np.diff(x)[0], atol=1e-9)),
        "grating_lobes_deg": [float(v) for v in gl if abs(v) > 1e-9],
        "unambiguous_half_width_deg": float(np.degrees(unambiguous_half_width_rad(rut))),
    }


def _tx_line(r: dict) -> str:
    """The board's Tx and which transmit: "4 Tx (Tx order [0, 1, 2]; Tx 3 off: ...)", so the
    virtual element count (the Tx in the order times the Rx) reads against the board's."""
    off = [t for t in range(r["num_tx"]) if t not in r["tx_order"]]
    note = (f"; Tx {', '.join(map(str, off))} off: not in the TDM order, a preset's elevated "
            "Tx transmits with radar.use_elevation_tx = true" if off else "")
    return f"{r['num_tx']} Tx (Tx order {r['tx_order']}{note})"


def format_info(info: dict) -> str:
    r, ff, rts = info["radar"], info["far_field"], info["rts"]
    lines = [
        f"scene {info['scene']}  ({info['source']})",
        f"RuT  {r['antenna_preset']}: {_tx_line(r)}, {r['num_rx']} Rx: "
        f"{r['num_virtual']} virtual elements ({len(r['tx_order'])} Tx x {r['num_rx']} Rx; "
        f"{r['num_virtual_azimuth']} in azimuth) at {r['element_spacing_m'] * 1e3:.3f} mm",
        f"     f_c {r['f_c_hz'] / 1e9:.3f} GHz, B {r['bandwidth_hz'] / 1e9:.3f} GHz, "
        f"lambda {r['wavelength_m'] * 1e3:.3f} mm at {r['f_center_hz'] / 1e9:.3f} GHz",
        f"     range resolution {r['range_resolution_m']:.4f} m, max range "
        f"{r['max_range_m']:.2f} m; velocity resolution {r['velocity_resolution_mps']:.4f} m/s, "
        f"max +-{r['max_velocity_mps']:.3f} m/s",
        f"far field  aperture d_A {ff['aperture_m'] * 1e3:.2f} mm, angular resolution "
        f"1.22 lambda/d_A = {ff['angular_resolution_deg']:.2f} deg, Fraunhofer distance "
        f"{ff['fraunhofer_distance_m']:.3f} m (arc radius {ff['arc_radius_m']:.3f} m)",
        _format_virtual(info["virtual_array"], r["wavelength_m"]),
        f"RTS  f_rts {rts['f_rts_hz'] / 1e6:.1f} MHz, f_s {rts['f_s_hz'] / 1e9:.3f} GS/s, delay "
        f"resolution {rts['delay_resolution_s'] * 1e12:.3g} ps, calibration period "
        f"1/(f_rts + B/2) = {rts['calibration_period_s'] * 1e9:.4f} ns",
        "front ends:",
        "   #  arc deg  azimuth from RuT  apparent (Rx/Tx split)  distance m  array phase error deg p-p",
    ]
    el = _has_elevation(info)
    if el:
        lines[-1] += "  elevation deg (sphere, from RuT)"
    for fe in info["front_ends"]:
        lines.append(f"  {fe['index']:2d} {fe['arc_angle_deg']:8.3f} {fe['azimuth_from_rut_deg']:17.4f}"
                     f" {_num(fe['apparent_azimuth_deg'], 23, 4)} {fe['distance_m']:11.5f}"
                     f" {fe['curvature_phase_error_deg']:18.2f}"
                     + (f"  {fe['elevation_deg']:8.3f} {fe['elevation_from_rut_deg']:9.4f}"
                        if el else ""))
    if info["front_ends"] and "radar_channel_bias_deg" in info["front_ends"][0]:
        lines.append("  the radar's own channel errors ([radar.channels]) move a real target at "
                     "each front end's azimuth by "
                     + ", ".join(f"{fe['radar_channel_bias_deg']:+.4f}"
                                 for fe in info["front_ends"])
                     + " deg (no RTS calibration removes it)")
    # consecutive indices' arc angles: a spacing along an arc, not between a 2-D cell's corners
    for i, (sp, ok) in enumerate(zip(info["front_end_spacing_deg"] if not el else (),
                                     info["spacing_within_resolution"])):
        lines.append(f"  spacing {i}-{i + 1}: {sp:.3f} deg "
                     f"({'within' if ok else 'EXCEEDS'} the angular resolution)")
    reach = info.get("reachable")
    if info.get("reachable_unavailable"):
        lines.append(f"reachable angles: not computed: {info['reachable_unavailable']}")
    if reach and reach.get("cells"):
        lines.append("reachable directions: each target in the cell of front ends that encloses "
                     "its direction cosines (as `run` plans it; 2-D cells, not arc pairs)")
    elif reach:
        how = (" (intersected with the geometric angles: closed-form amplitudes)"
               if reach["mode"] in CLOSED_FORM_MODES else "")
        lines.append(f"reachable angles ({reach['mode']} amplitudes; each front end alone as "
                     f"the simulated RuT detects it, as `run` measures it){how}:")
        for p in reach["pairs"]:
            lines.append(f"  pair {p['pair'][0]}-{p['pair'][1]}: [{p['lo_deg']:.4f}, "
                         f"{p['hi_deg']:.4f}] deg")
    if info["targets"]:
        lines.append("targets:")
        for i, t in enumerate(info["targets"]):
            line = (f"  {i}: {t['range_m']:.3f} m, {t['velocity_mps']:+.3f} m/s, "
                    f"{t['angle_deg']:.3f} deg"
                    + (f" el {t['elevation_deg']:.3f} deg" if el else "")
                    + f", {t['rcs_dbsm']:.1f} dBsm")
            if reach:
                rt = reach["targets"][i]
                if not rt["reachable"]:
                    line += "  OUTSIDE the reachable angles: `run` refuses it"
                elif rt.get("cell") is not None:
                    line += f"  (cell {'-'.join(str(q) for q in rt['cell'])})"
                elif rt["pair"] is not None and reach["mode"] != "nearest":
                    line += f"  (pair {rt['pair'][0]}-{rt['pair'][1]})"
            lines.append(line)
    if info.get("link_budget"):
        lines += format_budget(info["link_budget"])
    return "\n".join(lines)


def _num(x, width: int, digits: int) -> str:
    return f"{'n/a':>{width}}" if x is None else f"{x:{width}.{digits}f}"


def _has_elevation(info: dict) -> bool:
    """Whether a front end or a target of ``info`` is off elevation 0 (a 2-D cell scene)."""
    return any(x.get("elevation_deg", 0.0) for x in info["front_ends"] + info["targets"])


def unreachable_warnings(info: dict, skip_outside_geometric: bool = False) -> list[str]:
    """One line per target outside the reachable angles (empty without ``reachable``).

    ``skip_outside_geometric``: leave out targets outside the front ends' geometric span,
    which the scene check (``geometry.warnings.scene_warnings``) has already warned about."""
    reach = info.get("reachable")
    if not reach:
        return []
    if reach.get("cells"):
        return [f"{t['why']}; `run` refuses it" for t in reach["targets"] if not t["reachable"]]
    geo = [fe["azimuth_from_rut_deg"] for fe in info["front_ends"]]
    spans = ", ".join(f"pair {p['pair'][0]}-{p['pair'][1]} [{p['lo_deg']:.4f}, "
                      f"{p['hi_deg']:.4f}] deg" for p in reach["pairs"])
    return [f"targets[{t['index']}].angle_deg = {t['angle_deg']:g}: outside the reachable "
            f"angles ({reach['mode']} amplitudes: {spans}); `run` refuses it"
            for t in reach["targets"] if not t["reachable"]
            and not (skip_outside_geometric
                     and not min(geo) - 1e-9 <= t["angle_deg"] <= max(geo) + 1e-9)]


def _format_virtual(va: dict, lam: float) -> str:
    gl = va["grating_lobes_deg"]
    pos = ", ".join(f"{v:g}" for v in np.round(va["azimuth_positions_wavelengths"], 3))
    if len(va["azimuth_positions_wavelengths"]) > 24:
        first = va["azimuth_positions_wavelengths"]
        pos = (", ".join(f"{v:g}" for v in np.round(first[:10], 3)) + ", ..., "
               + ", ".join(f"{v:g}" for v in np.round(first[-4:], 3)))
    return (f"virtual array  {va['num_azimuth_elements']} azimuth elements on "
            f"{va['num_azimuth_unique']} distinct positions "
            f"({'uniform' if va['uniform'] else 'NON-UNIFORM'}), at x/lambda = [{pos}]; "
            + (f"smallest gap {va['smallest_spacing_m'] * 1e3:.3f} mm; "
               if va["smallest_spacing_m"] is not None else "no gap (one position); ")
            + "grating lobes at boresight: "
            + (", ".join(f"{v:+.2f}" for v in gl) + " deg" if gl else "none")
            + f"; unambiguous +-{va['unambiguous_half_width_deg']:.1f} deg")
