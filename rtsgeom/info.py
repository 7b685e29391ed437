"""``rtsgeom info``: what a setup is, in numbers an RF engineer checks first."""

from __future__ import annotations

import numpy as np

from . import __version__
from .geometry import Setup
from .geometry.farfield import (angular_resolution_rad, aperture_m, apparent_azimuth_rad,
                                coarray_period_m, curvature_phase_error_rad,
                                fraunhofer_distance_m, grating_lobe_directions_rad,
                                smallest_spacing_m, unambiguous_half_width_rad)

__all__ = ["scene_info", "format_info"]


def scene_info(setup: Setup) -> dict:
    s, r, rut, fe = setup.scene, setup.scene.radar, setup.rut, setup.fe
    geo = np.degrees(setup.fe_azimuth_rad())
    app = np.degrees(apparent_azimuth_rad(rut, fe.rx, fe.tx))
    curv = np.degrees(curvature_phase_error_rad(setup))
    spacing = np.degrees(np.diff(fe.angle_rad))
    res = np.degrees(angular_resolution_rad(rut))
    return {
        "rtsgeom_version": __version__,
        "scene": s.name,
        "source": s.source,
        "scene_sha256": s.sha256,
        "radar": {
            "antenna_preset": r.antenna_preset if r.array is None else "custom",
            "array": rut.name,
            "f_c_hz": r.f_c_hz, "bandwidth_hz": r.bandwidth_hz,
            "f_center_hz": r.f_center_hz, "wavelength_m": rut.wavelength_m,
            "slope_hz_per_s": r.slope_hz_per_s,
            "tx_order": list(rut.tx_order), "num_rx": rut.num_rx,
            "num_virtual": rut.num_virtual,
            "num_virtual_azimuth": int(np.count_nonzero(rut.azimuth_mask)),
            "element_spacing_m": rut.spacing_m,
            "range_resolution_m": r.range_resolution_m, "max_range_m": r.max_range_m,
            "velocity_resolution_mps": r.velocity_resolution_mps,
            "max_velocity_mps": r.max_velocity_mps,
        },
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
        "front_ends": [
            {
                "index": i,
                "arc_angle_deg": float(np.degrees(fe.angle_rad[i])),
                "azimuth_from_rut_deg": float(geo[i]),
                "apparent_azimuth_deg": float(app[i]),
                "distance_m": float(np.linalg.norm(fe.module[i] - rut.position)),
                "rx_tx_separation_m": float(fe.separation_m[i]),
                "mounting_offsets_mm": [float(x) for x in fe.offsets_m[i] * 1e3],
                "curvature_phase_error_deg": float(curv[i]),
            }
            for i in range(fe.count)
        ],
        "front_end_spacing_deg": [float(x) for x in spacing],
        "spacing_within_resolution": [bool(x <= res) for x in spacing],
        "targets": [
            {"range_m": t.range_m, "velocity_mps": t.velocity_mps, "rcs_dbsm": t.rcs_dbsm,
             "angle_deg": float(np.degrees(t.angle_rad))}
            for t in s.targets
        ],
    }


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
        "smallest_spacing_m": smallest_spacing_m(rut),
        "coarray_period_m": period,
        "uniform": bool(x.size > 1 and np.allclose(np.diff(x), np.diff(x)[0], atol=1e-9)),
        "grating_lobes_deg": [float(v) for v in gl if abs(v) > 1e-9],
        "unambiguous_half_width_deg": float(np.degrees(unambiguous_half_width_rad(rut))),
    }


def format_info(info: dict) -> str:
    r, ff, rts = info["radar"], info["far_field"], info["rts"]
    lines = [
        f"scene {info['scene']}  ({info['source']})",
        f"RuT  {r['antenna_preset']}: Tx order {r['tx_order']}, {r['num_rx']} Rx, "
        f"{r['num_virtual']} virtual elements ({r['num_virtual_azimuth']} in azimuth) at "
        f"{r['element_spacing_m'] * 1e3:.3f} mm",
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
    for fe in info["front_ends"]:
        lines.append(f"  {fe['index']:2d} {fe['arc_angle_deg']:8.3f} {fe['azimuth_from_rut_deg']:17.4f}"
                     f" {fe['apparent_azimuth_deg']:23.4f} {fe['distance_m']:11.5f}"
                     f" {fe['curvature_phase_error_deg']:18.2f}")
    for i, (sp, ok) in enumerate(zip(info["front_end_spacing_deg"],
                                     info["spacing_within_resolution"])):
        lines.append(f"  spacing {i}-{i + 1}: {sp:.3f} deg "
                     f"({'within' if ok else 'EXCEEDS'} the angular resolution)")
    if info["targets"]:
        lines.append("targets:")
        for i, t in enumerate(info["targets"]):
            lines.append(f"  {i}: {t['range_m']:.3f} m, {t['velocity_mps']:+.3f} m/s, "
                         f"{t['angle_deg']:.3f} deg, {t['rcs_dbsm']:.1f} dBsm")
    return "\n".join(lines)


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
            f"smallest gap {va['smallest_spacing_m'] * 1e3:.3f} mm; grating lobes at boresight: "
            + (", ".join(f"{v:+.2f}" for v in gl) + " deg" if gl else "none")
            + f"; unambiguous +-{va['unambiguous_half_width_deg']:.1f} deg")
