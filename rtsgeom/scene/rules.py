"""The rules between a scene's fields: :func:`problems` lists every one a scene violates.

Each entry reads ``<file>: <field> = <value>: must be <what is allowed>`` and blames the field a
user would change (naming the other fields involved). Loading raises on them
(:func:`rtsgeom.scene.scene.parse_scene`), :meth:`Scene.evolve` checks variants with them, and the arc
design (``analysis/design.py``) filters candidate designs with them.

The limits are what the processing can resolve, not only what a formula allows: the CFAR
window must fit in the range-Doppler map, and a target must stay far enough inside the
unambiguous range and velocity that its window main lobe and CFAR ring do not wrap around.

This module does not import :mod:`rtsgeom.scene.scene` (which imports it) nor ``geometry``; the
positions come from the one shared formula in :mod:`rtsgeom._lib.arcmath`.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .._lib.arcmath import antenna_positions
from .channels import channel_rules
from .presets import ArraySpec
from .registry import RADAR_PRESETS, WINDOWS, AOA_MODES
from ..errors import SceneError
from .scenario import check_scenario
from .objects import (check_moving_objects, check_static_objects, target_field, target_labels,
                      targets_per_frame)
from .schema import fmt, specs
from .sections import FrontEndConfig, RadarConfig, RtsConfig


__all__ = ["problems", "arc_centre_m", "azimuth_from_radar_rad", "front_end_module_m",
           "MAX_ADC_SAMPLES", "MAX_CALIBRATION_STEPS"]

MAX_CALIBRATION_STEPS = 100_000  # calibration_span / calibration_step
# samples_per_chirp * chirps_per_tx * virtual elements. The cube is complex64 (8 B/sample); the
# chain's peak is about 8 such buffers (phases and FFT copies, noise), ~2 GiB at this limit
# (measured: see docs/scene-format.md, "Resource limits").
MAX_ADC_SAMPLES = 1 << 25


def front_end_module_m(centre, radius_m: float, fe: "FrontEndConfig") -> tuple[float, ...]:
    """World position of a front end's module centre (mounting offsets applied)."""
    off = (fe.radial_offset_m, fe.tangential_offset_m, fe.height_offset_m)
    _, _, mod = antenna_positions(np.asarray(centre, float), radius_m, fe.angle_rad,
                                  fe.rx_tx_separation_m, off,
                                  elevation_rad=fe.elevation_rad or None)
    return tuple(float(x) for x in mod)


def azimuth_from_radar_rad(radar: "RadarConfig", point) -> float:
    """Azimuth of a world point seen from the RuT's phase centre, in the radar frame."""
    p = radar.position_m
    return math.remainder(math.atan2(point[0] - p[0], point[1] - p[1]) - radar.yaw_rad,
                          2.0 * math.pi)


def arc_centre_m(scene) -> tuple[float, float, float]:
    """The arc centre: ``rts.arc_center_m``, by default the RuT's phase centre."""
    c0 = scene.rts.arc_center_m
    return c0 if c0 is not None else scene.radar.position_m


def problems(scene) -> list[str]:
    """Every cross-field rule ``scene`` violates, one message each (empty: none)."""
    out: list[str] = []
    src = scene.source or "<scene>"

    def fail(fieldname: str, value: Any, allowed: str) -> None:
        out.append(f"{src}: {fieldname} = {fmt(value)}: must be {allowed}")

    for rule in (_array_rules, _radar_rules, _rts_rules, _sheet_rules, _placement_rules, _calibration_rules,
                 _target_rules, _spacing_rules, _elevation_rules, _estimator_rules,
                 channel_rules, _scenario_rules):
        rule(scene, fail)
    return out


def _elevation_rules(scene, fail) -> None:
    """Front ends or targets off the horizontal plane need the RuT's 2-D beamforming."""
    off_plane = (any(fe.elevation_rad for fe in scene.rts.front_ends)
                 or any(t.elevation_rad for t in scene.targets))
    if off_plane and not scene.radar.elevation_processing:
        fail("radar.elevation_processing", False,
             "true: front ends or targets off the horizontal plane (elevation_deg != 0) need the "
             "RuT's 2-D (azimuth x elevation) beamforming, with an array that has elevation "
             "extent (e.g. use_elevation_tx = true)")


def _estimator_rules(scene, fail) -> None:
    """Spatial smoothing is for the super-resolution estimators and the azimuth row: eq. 14's
    Bartlett beamformer uses the whole array (a smoothed Bartlett would be another estimator),
    and smoothing a 2-D array is not implemented (the array's length is checked where the
    array is built, ``Steering.build``)."""
    radar = scene.radar
    if radar.angle_subarray and radar.angle_estimator == "bartlett":
        fail("radar.angle_subarray", radar.angle_subarray,
             "0 with radar.angle_estimator = \"bartlett\" (eq. 14 beamforms the whole array; "
             "spatial smoothing is for capon and music)")
    if radar.angle_subarray and radar.elevation_processing:
        fail("radar.angle_subarray", radar.angle_subarray,
             "0 with radar.elevation_processing = true: spatial smoothing is implemented for "
             "the 1-D azimuth row only (2-D arrays need 2-D subarrays, not implemented); "
             "without smoothing capon and music peak where bartlett does")
    if radar.angle_subarray == 1:
        fail("radar.angle_subarray", 1, "0 (no smoothing) or >= 2 (a subarray of one "
             "element has no direction)")


def _radar_rules(scene, fail) -> None:
    """chirp_repetition_s >= chirp_duration_s; the ADC window samples_per_chirp / adc_rate_hz
    (from adc_start_s) inside the ramp; each axis of the range-Doppler map (samples_per_chirp,
    chirps_per_tx) holds the CFAR window 2 x (guard + training cells) + 1 and room for a target
    away from the edges (see the target limits); the ADC cube within MAX_ADC_SAMPLES."""
    radar = scene.radar
    t_ramp, n_s, f_adc = radar.chirp_duration_s, radar.samples_per_chirp, radar.adc_rate_hz
    if radar.chirp_repetition_s < t_ramp:
        fail("radar.chirp_repetition_s", radar.chirp_repetition_s,
             f">= radar.chirp_duration_s ({t_ramp:g} s): a chirp cannot repeat before it ends")
    window = n_s / f_adc
    if window > t_ramp:
        fail("radar.samples_per_chirp", n_s,
             f"<= {math.floor(t_ramp * f_adc)}: samples_per_chirp / adc_rate_hz "
             f"= {window:g} s exceeds chirp_duration_s = {t_ramp:g} s")
    elif radar.adc_start_s > t_ramp - window:
        fail("radar.adc_start_s", radar.adc_start_s, f"in [0, {t_ramp - window:g}] s")
    # The CFAR window (cell under test, guard and training cells on both sides) must fit in
    # each axis of the range-Doppler map (both axes are cyclic: a bigger ring meets itself),
    # and leave room for a target inside the limits of resolvable_limits (see there).
    cfar, default_cfar = radar.cfar, type(radar.cfar)()
    for ax, axis, size, key, win in ((0, "range", n_s, "samples_per_chirp", radar.range_window),
                                     (1, "Doppler", radar.chirps_per_tx, "chirps_per_tx",
                                      radar.doppler_window)):
        g, t = cfar.guard_cells[ax], cfar.training_cells[ax]
        ml = WINDOWS[win].mainlobe_half_bins
        edge = ml + g + t + 1 if ax == 0 else 2 * (ml + 1) + 1
        need = max(2 * (g + t) + 1, edge)
        if size < need:
            why = (f"the {axis} axis must hold the CFAR window 2 x (radar.cfar.guard_cells[{ax}] "
                   f"{g} + radar.cfar.training_cells[{ax}] {t}) + 1 cells and leave a target "
                   f"room inside the {win} window's main lobe ({ml} bins) from the edge: "
                   f"{need} cells")
            if cfar == default_cfar or need == edge:
                fail(f"radar.{key}", size, f">= {need}: {why}")
            else:
                fail("radar.cfar.training_cells", list(cfar.training_cells),
                     f"smaller: with radar.{key} = {size}, {why}")
    n_rx = radar.num_rx
    per_loop = n_s * radar.num_tx_active * n_rx
    n_adc = per_loop * radar.chirps_per_tx
    if n_adc > MAX_ADC_SAMPLES:
        fail("radar.chirps_per_tx", radar.chirps_per_tx,
             f"<= {MAX_ADC_SAMPLES // per_loop}: samples_per_chirp x chirps_per_tx x virtual "
             f"elements = {n_adc} ADC samples (at most {MAX_ADC_SAMPLES}, about 2 GiB peak "
             "memory in complex64 processing)")


def _array_rules(scene, fail) -> None:
    """A custom [radar.array]: tx_order indexes tx_mm, each Tx at most once; no two antennas at
    one place; use_elevation_tx and board_gap_mm belong to presets. A preset's board gap only
    where it has separate Tx and Rx groups."""
    radar = scene.radar
    arr = radar.array
    if arr is None:
        p = RADAR_PRESETS[radar.antenna_preset]
        if radar.board_gap_m is not None and p.board_gap_units is None:
            fail("radar.board_gap_mm", radar.board_gap_m * 1e3,
                 f"left out: the {p.name} preset interleaves its Tx and Rx antennas, so no "
                 "board gap applies")
        elif radar.board_gap_m is None and p.board_gap_units is not None:
            # the preset's own gap scales with the element spacing (board_gap_units * d) and
            # must stay in the board gap's range, [0, 0.5] m, as an explicit one does
            d_max = 0.5 / p.board_gap_units
            d = radar.element_spacing_m or radar.wavelength_m / 2.0
            if d > d_max:
                fail("radar.element_spacing_m", radar.element_spacing_m,
                     f"at most {d_max:g} m for the {p.name} preset (its Tx-Rx board gap, "
                     f"{p.board_gap_units:g} element spacings, must stay within 0.5 m; or give "
                     "radar.board_gap_mm)")
        return
    n_tx = len(arr.tx_mm)
    bad = [i for i in arr.tx_order if i >= n_tx]
    if bad:
        fail("radar.array.tx_order", list(arr.tx_order),
             f"indices into radar.array.tx_mm, in [0, {n_tx - 1}] ({bad[0]} is not)")
    if len(set(arr.tx_order)) != len(arr.tx_order):
        fail("radar.array.tx_order", list(arr.tx_order), "distinct: each Tx in one TDM slot")
    for key, pts in (("tx_mm", arr.tx_mm), ("rx_mm", arr.rx_mm)):
        q = {(round(x * 1e6), round(z * 1e6)) for x, z in pts}
        if len(q) != len(pts):
            fail(f"radar.array.{key}", [list(p) for p in pts], "distinct positions (two "
                 "antennas at one place)")
    if radar.use_elevation_tx:
        fail("radar.use_elevation_tx", True, "false with [radar.array] (its tx_order sets the "
             "TDM slots)")
    if radar.board_gap_m is not None:
        fail("radar.board_gap_mm", radar.board_gap_m * 1e3, "left out with [radar.array] (the "
             "custom positions include any gap)")


def _rts_rules(scene, fail) -> None:
    """Front ends ordered by strictly increasing angle_deg; f_s_hz >= the chirp's bandwidth;
    fractional_delay_step_s <= 1/f_s_hz;
    calibration_span_ns [start, stop] with stop > start."""
    rts = scene.rts
    angles = [fe.angle_rad for fe in rts.front_ends]
    elev = [fe.elevation_rad for fe in rts.front_ends]
    if not any(elev):
        if any(b <= a for a, b in zip(angles, angles[1:])):
            fail("rts.front_ends", [round(math.degrees(a), 6) for a in angles],
                 "ordered by strictly increasing angle_deg")
    else:
        keys = list(zip(angles, elev))
        if any(b <= a for a, b in zip(keys, keys[1:])):
            fail("rts.front_ends", [[round(math.degrees(a), 6), round(math.degrees(e), 6)]
                                    for a, e in keys],
                 "ordered by strictly increasing (angle_deg, elevation_deg)")
    if rts.f_s_hz < scene.radar.bandwidth_hz:  # no sampling scheme keeps a band wider than f_s
        fail("rts.f_s_hz", rts.f_s_hz,
             f">= the chirp's bandwidth radar.bandwidth_hz = {scene.radar.bandwidth_hz:g} Hz "
             f"(the back end samples the IF band [f_rts - B/2, f_rts + B/2]; without aliasing: "
             f">= 2 (rts.f_rts_hz + B/2) = {2 * (rts.f_rts_hz + 0.5 * scene.radar.bandwidth_hz):g}"
             " Hz)")
    if rts.fractional_delay_step_s > 1.0 / rts.f_s_hz:
        fail("rts.fractional_delay_step_s", rts.fractional_delay_step_s,
             f"in [1e-15, {1.0 / rts.f_s_hz:g}] s")
    span = rts.calibration_span_s
    if span[1] <= span[0]:
        fail("rts.calibration_span_ns", [round(x * 1e9, 9) for x in span],
             "[start, stop] with stop > start")


def _sheet_rules(scene, fail) -> None:
    """angle_max_deg > angle_min_deg; cutouts smaller than the sheet's height, holding both
    antennas of their front end, inside the sheet's extent and not overlapping."""
    sheet, rts = scene.sheet, scene.rts
    a0, a1 = math.degrees(sheet.angle_min_rad), math.degrees(sheet.angle_max_rad)
    if a1 <= a0:
        fail("sheet.angle_max_deg", a1, f"> sheet.angle_min_deg ({a0:g} deg)")
    if not sheet.enabled:
        return
    if sheet.cutout_diameter_m >= sheet.height_m:
        fail("sheet.cutout_diameter_m", sheet.cutout_diameter_m,
             f"< sheet.height_m ({sheet.height_m:g} m): the cutouts would cut the sheet in two")
    # Cutouts of neighbouring front ends must not overlap (the sheet would fall apart), and each
    # cutout must hold its front end's two antennas.
    r_sheet = rts.arc_radius_m + sheet.radius_offset_m
    if r_sheet <= 0.05:
        fail("sheet.radius_offset_m", sheet.radius_offset_m,
             f"> {0.05 - rts.arc_radius_m:g} m (the sheet's inner radius, rts.arc_radius_m = "
             f"{rts.arc_radius_m:g} m plus this, must exceed 0.05 m)")
        return
    for i, fe in enumerate(rts.front_ends):
        if fe.rx_offset_m is None or fe.tx_offset_m is None:
            if fe.rx_tx_separation_m >= sheet.cutout_diameter_m:
                fail(f"rts.front_ends[{i}].rx_tx_separation_m", fe.rx_tx_separation_m,
                     f"< sheet.cutout_diameter_m ({sheet.cutout_diameter_m:g} m) so both "
                     "antennas look through the cutout")
        else:
            for key, (t, h) in zip(("rx_offset_mm", "tx_offset_mm"), fe.antenna_offsets_m()):
                if math.hypot(t, h) >= 0.5 * sheet.cutout_diameter_m:
                    fail(f"rts.front_ends[{i}].{key}", [t * 1e3, h * 1e3],
                         f"within the cutout: |[t, h]| < sheet.cutout_diameter_m / 2 = "
                         f"{sheet.cutout_diameter_m * 500:g} mm so the antenna looks through it")
        half = math.asin(min(1.0, 0.5 * sheet.cutout_diameter_m / r_sheet))
        if fe.angle_rad - half < sheet.angle_min_rad or fe.angle_rad + half > sheet.angle_max_rad:
            fail(f"rts.front_ends[{i}].angle_deg", math.degrees(fe.angle_rad),
                 f"within the sheet [{math.degrees(sheet.angle_min_rad + half):g}, "
                 f"{math.degrees(sheet.angle_max_rad - half):g}] deg (sheet extent minus "
                 "half a cutout)")
    if any(fe.elevation_rad for fe in rts.front_ends):
        _cap_rules(scene, r_sheet, fail)
        return
    for i in range(1, len(rts.front_ends)):
        a, b = rts.front_ends[i - 1], rts.front_ends[i]
        chord = 2.0 * r_sheet * math.sin(0.5 * (b.angle_rad - a.angle_rad))
        if chord < sheet.cutout_diameter_m:
            min_deg = math.degrees(2.0 * math.asin(min(1.0, 0.5 * sheet.cutout_diameter_m
                                                       / r_sheet)))
            fail(f"rts.front_ends[{i}].angle_deg", math.degrees(b.angle_rad),
                 f">= {math.degrees(a.angle_rad) + min_deg:.4g} deg: front ends "
                 f"{i - 1} and {i} are closer ({chord * 1e3:.1f} mm) than their cutouts "
                 f"({sheet.cutout_diameter_m * 1e3:.1f} mm) allow")


def _cap_rules(scene, r_sheet: float, fail) -> None:
    """Front ends on a sphere: each cutout inside the cap's elevation extent (sheet.height_m
    as a chord, +-asin(height / 2 r)), and no two cutouts overlapping (chord between any two
    front ends' directions on the sheet >= the cutout diameter)."""
    sheet, fes = scene.sheet, scene.rts.front_ends
    half = math.asin(min(1.0, 0.5 * sheet.cutout_diameter_m / r_sheet))
    top = math.asin(min(1.0, 0.5 * sheet.height_m / r_sheet))
    for i, fe in enumerate(fes):
        if abs(fe.elevation_rad) + half > top:
            fail(f"rts.front_ends[{i}].elevation_deg", math.degrees(fe.elevation_rad),
                 f"within +-{math.degrees(top - half):.4g} deg (the spherical cap's extent "
                 "+-asin(sheet.height_m / 2 r_sheet) minus half a cutout)")
    for i in range(len(fes)):
        for j in range(i):
            a, b = fes[j], fes[i]
            cos_g = (math.sin(a.elevation_rad) * math.sin(b.elevation_rad)
                     + math.cos(a.elevation_rad) * math.cos(b.elevation_rad)
                     * math.cos(b.angle_rad - a.angle_rad))
            chord = 2.0 * r_sheet * math.sin(0.5 * math.acos(max(-1.0, min(1.0, cos_g))))
            if chord < sheet.cutout_diameter_m:
                fail(f"rts.front_ends[{i}].angle_deg", math.degrees(b.angle_rad),
                     f"further from front end {j}: front ends {j} and {i} are closer "
                     f"({chord * 1e3:.1f} mm) than their cutouts "
                     f"({sheet.cutout_diameter_m * 1e3:.1f} mm) allow")


def _modules(scene) -> list[tuple[float, ...]]:
    centre = arc_centre_m(scene)
    return [front_end_module_m(centre, scene.rts.arc_radius_m, fe) for fe in scene.rts.front_ends]


def _placement_rules(scene, fail) -> None:
    """The RuT sits inside the arc (and inside the sheet), and every front end is in front."""
    rts, sheet, radar = scene.rts, scene.sheet, scene.radar
    centre = arc_centre_m(scene)
    pos = radar.position_m
    dist = math.dist(pos, centre)
    r_sheet = rts.arc_radius_m + sheet.radius_offset_m
    r_in, what = rts.arc_radius_m, "rts.arc_radius_m"
    if sheet.enabled and r_sheet < r_in:
        r_in, what = r_sheet, "the sheet's inner radius rts.arc_radius_m + sheet.radius_offset_m"
    if dist >= r_in:
        fail("radar.position_m", list(pos),
             f"inside the arc: less than {what} = {r_in:g} m from rts.arc_center_m "
             f"{list(centre)} (it is {dist:.4g} m away)")
    for i, (fe, mod) in enumerate(zip(rts.front_ends, _modules(scene))):
        az = math.degrees(azimuth_from_radar_rad(radar, mod))
        if not -90.0 < az < 90.0:
            fail(f"rts.front_ends[{i}].angle_deg", math.degrees(fe.angle_rad),
                 f"an angle that puts the front end in front of the radar: seen from "
                 f"radar.position_m {list(pos)} with radar.yaw_deg = "
                 f"{math.degrees(radar.yaw_rad):g} it is at azimuth {az:.4g} deg, outside "
                 "(-90, 90) deg")


def _calibration_rules(scene, fail) -> None:
    """The RTS delay must take the calibration's steps; the sweep must cover one period of the
    phase it calibrates (paper: 1 / (f_rts + B/2) = 1 ns). Where the sweep is left at its
    default [-0.5, 1.0] ns, a too-long period is blamed on rts.f_rts_hz (with its lower bound
    1/span - B/2), else on rts.calibration_span_ns."""
    rts, radar = scene.rts, scene.radar
    step = rts.calibration_step_s
    if rts.delay_resolution_s > step * (1.0 + 1e-9):
        how = (f"rts.fractional_delay = true with rts.fractional_delay_step_s = "
               f"{rts.fractional_delay_step_s:g} s: use a finer fractional_delay_step_s"
               if rts.fractional_delay else
               "rts.fractional_delay = false: the delay moves in whole back-end samples "
               "1/rts.f_s_hz; set rts.fractional_delay = true")
        fail("rts.calibration_step_ps", step * 1e12,
             f">= the RTS delay resolution {rts.delay_resolution_s * 1e12:g} ps ({how})")
    span = rts.calibration_span_s[1] - rts.calibration_span_s[0]
    if span <= 0:
        return
    period = 1.0 / (rts.f_rts_hz + 0.5 * radar.bandwidth_hz)
    span_ns = [round(x * 1e9, 9) for x in rts.calibration_span_s]
    if span < period * (1.0 - 1e-9) and _default_span(rts.calibration_span_s):
        # the sweep is the default one: the IF that sets the period is what departs from it
        fail("rts.f_rts_hz", rts.f_rts_hz,
             f">= 1/span - radar.bandwidth_hz/2 = {1.0 / span - 0.5 * radar.bandwidth_hz:g} Hz "
             f"(at most {_rts_spec('f_rts_hz').hi:g} Hz), so that one period 1/(rts.f_rts_hz + radar.bandwidth_hz/2)"
             f" = {period * 1e9:.4g} ns fits the calibration sweep rts.calibration_span_ns = "
             f"{span_ns} (default, {span * 1e9:.4g} ns); or widen rts.calibration_span_ns to "
             f">= {period * 1e9:.4g} ns")
    elif span < period * (1.0 - 1e-9):
        fail("rts.calibration_span_ns", span_ns,
             f"at least one period 1/(rts.f_rts_hz + radar.bandwidth_hz/2) = "
             f"{period * 1e9:.4g} ns wide (it spans {span * 1e9:.4g} ns)")
    if span / step > MAX_CALIBRATION_STEPS:
        fail("rts.calibration_step_ps", step * 1e12,
             f">= {span / MAX_CALIBRATION_STEPS * 1e12:.4g} ps: rts.calibration_span_ns "
             f"{span_ns} would take {span / step:.4g} steps (at most {MAX_CALIBRATION_STEPS})")


def _rts_spec(name: str):
    """The declaration of field ``name`` of ``[rts]`` (its file key, range, default)."""
    return dict(specs(RtsConfig))[name]


def _default_span(span_s) -> bool:
    """Whether the calibration sweep is the scene format's default (not set by the user)."""
    default = [x * _rts_spec("calibration_span_s").scale
               for x in _rts_spec("calibration_span_s").default]
    return all(abs(a - b) <= 1e-21 for a, b in zip(span_s, default))


def resolvable_limits(radar: "RadarConfig") -> tuple[float, float, str, str]:
    """(largest beat range, largest |velocity|) the processing resolves, and why.

    Range: the unambiguous range less the bins of the range window's main lobe and the CFAR
    ring (guard + training cells); beyond, the peak and its ring wrap to the near-range bins
    and the target comes out near 0 m or is lost. Velocity: the unambiguous TDM-MIMO velocity
    less the Doppler window's main lobe and the neighbour bin of the peak interpolation;
    beyond, the peak wraps to the opposite velocity and the TDM phase compensation takes the
    wrong sign (an angle error of degrees). The Doppler CFAR ring may wrap: the far edge of
    the cyclic Doppler axis holds only noise (a target at 94 % of the maximum is found in its
    bin, tests/radar/test_signal.py)."""
    cfar = radar.cfar
    k_r = (WINDOWS[radar.range_window].mainlobe_half_bins + cfar.guard_cells[0]
           + cfar.training_cells[0])
    k_d = WINDOWS[radar.doppler_window].mainlobe_half_bins + 1
    r_bin = radar.max_range_m / radar.samples_per_chirp
    v_bin = 2.0 * radar.max_velocity_mps / radar.chirps_per_tx
    why_r = (f"the radar's unambiguous range {radar.max_range_m:.4g} m (adc_rate_hz * c / "
             f"(2 * slope)) less {k_r} range bins of {r_bin:.3g} m (radar.range_window main "
             "lobe + radar.cfar guard and training cells)")
    why_v = (f"the radar's unambiguous TDM-MIMO velocity +-{radar.max_velocity_mps:.4g} m/s "
             f"less {k_d} Doppler bins of {v_bin:.3g} m/s (radar.doppler_window main lobe + "
             "the peak's neighbour bin; beyond, the peak wraps to the opposite velocity and the "
             "TDM compensation takes the wrong sign)")
    return (radar.max_range_m - k_r * r_bin, radar.max_velocity_mps - k_d * v_bin, why_r, why_v)


def _target_rules(scene, fail) -> None:
    """Targets inside what the processing resolves (the echo's beat includes any air path the
    RTS does not subtract)."""
    rts, radar = scene.rts, scene.radar
    if not scene.targets:
        return
    extra = _air_extra_m(scene)
    r_lim, v_lim, why_r, why_v = resolvable_limits(radar)
    r_max = r_lim - extra
    names = target_labels(scene)  # an object's scatterer as the file writes it
    for i, tg in enumerate(scene.targets):
        if tg.range_m >= r_max:
            air = (f" minus the air path {extra:.4g} m the RTS does not subtract (rts."
                   f"compensate_air_path = {str(rts.compensate_air_path).lower()})" * (extra > 1e-9))
            fail(target_field(names[i], "range_m"), tg.range_m, f"< {r_max:.4g} m, {why_r}{air}")
        if abs(tg.velocity_mps) >= v_lim:
            fail(target_field(names[i], "velocity_mps"), tg.velocity_mps,
                 f"in (-{v_lim:.4g}, {v_lim:.4g}) m/s, {why_v}")
        if rts.compensate_air_path and tg.range_m <= rts.arc_radius_m:
            fail(target_field(names[i], "range_m"), tg.range_m,
                 f"> rts.arc_radius_m ({rts.arc_radius_m:g} m): the RTS cannot emit before the "
                 "radar signal reached it")
    check_static_objects(scene, fail, names)


def _air_extra_m(scene) -> float:
    """The air path to the farthest front end that the RTS does not subtract (m)."""
    d_air = max(math.dist(scene.radar.position_m, m) for m in _modules(scene))
    rts = scene.rts
    return max(0.0, d_air - rts.arc_radius_m) if rts.compensate_air_path else d_air


def _scenario_rules(scene, fail) -> None:
    """``[scenario]``: waypoint times from 0, strictly increasing, the last at or after
    duration_s; at most MAX_FRAMES frames; in every frame each moving target's range, radial
    velocity (and elevation) within what the processing resolves, as for ``[[targets]]``."""
    if scene.scenario is not None:
        lim, extra = resolvable_limits(scene.radar), _air_extra_m(scene)
        check_moving_objects(scene, fail, lim, extra, check_scenario(  # objects' scatterers
            scene, fail, lim, extra, targets_per_frame(scene)))


def angular_resolution_rad(radar: "RadarConfig") -> float:
    """1.22 lambda / d_A of the RuT's azimuth virtual array (paper eq. 24), from the preset or
    the custom array (inf for a single azimuth position)."""
    lam = radar.wavelength_m
    if radar.array is not None:
        arr = radar.array
        try:
            d_a = ArraySpec.from_mm(arr.tx_mm, arr.rx_mm, arr.tx_order).azimuth_aperture_m()
        except SceneError:  # reported by _array_rules
            return math.inf
        return 1.22 * lam / d_a if d_a > 0 else math.inf
    d = radar.element_spacing_m or lam / 2.0
    n_a = RADAR_PRESETS[radar.antenna_preset].azimuth_aperture_units(radar.use_elevation_tx)
    return 1.22 * lam / (n_a * d)


def _spacing_rules(scene, fail) -> None:
    """Synthesis interpolates between neighbouring front ends: both must fall into one
    resolution cell of the RuT (paper eq. 24) where a target is synthesised between them."""
    rts, radar = scene.rts, scene.radar
    if not AOA_MODES[rts.aoa_mode].synthesis or rts.allow_wide_spacing or not scene.targets:
        return
    az = [azimuth_from_radar_rad(radar, m) for m in _modules(scene)]
    res = angular_resolution_rad(radar)
    for i in range(1, len(az)):
        lo, hi = sorted((az[i - 1], az[i]))
        if hi - lo <= res:
            continue
        between = [k for k, tg in enumerate(scene.targets) if lo < tg.angle_rad < hi]
        if between:
            k, name = between[0], target_field(target_labels(scene)[between[0]], "angle_deg")
            fail(f"rts.front_ends[{i}].angle_deg", math.degrees(rts.front_ends[i].angle_rad),
                 f"within the RuT's angular resolution 1.22 lambda/d_A = "
                 f"{math.degrees(res):.4g} deg of front end {i - 1} (paper eq. 24): seen from "
                 f"the RuT they are {math.degrees(hi - lo):.4g} deg apart and "
                 f"{name} = {math.degrees(scene.targets[k].angle_rad):g} is "
                 f"synthesised between them (rts.aoa_mode = \"{rts.aoa_mode}\"); set "
                 "rts.allow_wide_spacing = true to force it, or rts.aoa_mode = \"nearest\"")
