"""Warnings: scenes that load (they break no rule in ``scene.py``) but are physically doubtful.

:func:`scene_warnings` returns one line per finding, in the style of the loader's errors::

    <file>: <field> = <value>: <what is doubtful and why>

The CLI prints them to stderr as ``rtsgeom: warning: ...`` (``cli._common.load_scene_checked``)
and goes on. Errors, i.e. scenes that cannot be simulated at all, stay in ``scene.py``.
"""

from __future__ import annotations

import math

import numpy as np

from . import build_setup
from .farfield import angular_resolution_rad, fraunhofer_distance_m
from ..scene import Scene
from ..scene.schema import fmt as _fmt

__all__ = ["scene_warnings", "height_phase_deg"]

_OFFSETS = ("radial_offset_mm", "tangential_offset_mm", "height_offset_mm")


def height_phase_deg(dz_m: float, range_m: float, wavelength_m: float) -> float:
    """Two-way phase (deg) a height offset ``dz_m`` adds at distance ``range_m``: each leg
    grows by sqrt(R^2 + dz^2) - R ~ dz^2 / 2R (second order), both legs by dz^2 / R."""
    return float(np.degrees(2 * np.pi * (2 * (np.hypot(range_m, dz_m) - range_m)) / wavelength_m))


def scene_warnings(scene: Scene) -> list[str]:
    """Physically doubtful but legal settings of a validated scene (empty list: none)."""
    setup = build_setup(scene)
    radar = scene.radar
    src = scene.source or "<scene>"
    out: list[str] = []

    def warn(fieldname: str, value, text: str) -> None:
        out.append(f"{src}: {fieldname} = {_fmt(value)}: {text}")

    _arc_warnings(setup, warn)
    _mounting_warnings(setup, warn)
    _back_end_warnings(setup, warn)
    if radar.snr_db is None and radar.link is None:
        out.append(f"{src}: radar.snr_db is not set: the simulation is noiseless")
    if radar.snr_db is not None and radar.link is not None:
        out.append(f"{src}: radar.snr_db = {radar.snr_db:g} overrides the thermal noise of "
                   "[radar.link] (a fixed per-sample SNR of the strongest target echo)")
    return out


def _arc_warnings(setup, warn) -> None:
    """The arc seen from the RuT: neighbours within a resolution cell, the far field, the
    targets within the front ends' span."""
    scene, rut, fe = setup.scene, setup.rut, setup.fe
    rts = scene.rts
    az = setup.fe_azimuth_rad()  # radar frame, module centres
    res = angular_resolution_rad(rut)

    # Arbitrary AoA interpolates between neighbouring front ends: both must fall into one
    # resolution cell of the RuT (paper eq. 24).
    for i in range(1, fe.count):
        gap = abs(az[i] - az[i - 1])
        if gap > res:
            warn(f"rts.front_ends[{i}].angle_deg", math.degrees(rts.front_ends[i].angle_rad),
                 f"front ends {i - 1} and {i} are {math.degrees(gap):.4g} deg apart seen from "
                 f"the RuT, more than its angular resolution 1.22 lambda/d_A = "
                 f"{math.degrees(res):.4g} deg (paper eq. 24): angles between them cannot be "
                 "synthesised")

    # Far field: the paper's model (eq. 13) assumes plane waves across the RuT's aperture.
    dist = np.linalg.norm(fe.module - rut.position, axis=1)
    r_ff = fraunhofer_distance_m(rut)
    if dist.min() < r_ff:
        warn("rts.arc_radius_m", rts.arc_radius_m,
             f"the nearest front end is {dist.min():.4g} m from the RuT, closer than its "
             f"Fraunhofer distance 2 d_A^2/lambda = {r_ff:.4g} m: phase-front curvature is not "
             "negligible (see curvature_deg in `rtsgeom info`)")

    # Targets are synthesised between front ends; outside their span means extrapolation.
    lo, hi = float(az.min()), float(az.max())
    from ..scene.objects import target_field, target_labels
    names = target_labels(scene)  # an object's scatterers as the file writes them
    for i, tg in enumerate(scene.targets):
        if not lo - 1e-9 <= tg.angle_rad <= hi + 1e-9:
            warn(target_field(names[i], "angle_deg"), math.degrees(tg.angle_rad),
                 f"outside the span of the front ends seen from the RuT "
                 f"[{math.degrees(lo):.4g}, {math.degrees(hi):.4g}] deg: the RTS can only "
                 "interpolate between front ends")



def _mounting_warnings(setup, warn) -> None:
    """Each front end's mounting: offsets beyond lambda/4, a height offset's phase, the
    antennas within their cutouts."""
    scene, rut, fe = setup.scene, setup.rut, setup.fe
    rts = scene.rts
    lam = rut.wavelength_m
    dist = np.linalg.norm(fe.module - rut.position, axis=1)

    # Mounting errors: lambda/4 radially is already half a wavelength of two-way path.
    for i, f in enumerate(rts.front_ends):
        offs = (f.radial_offset_m, f.tangential_offset_m)
        for name, v in zip(_OFFSETS, offs):
            if abs(v) > lam / 4.0:
                warn(f"rts.front_ends[{i}].{name}", v * 1e3,
                     f"larger than lambda/4 = {lam / 4.0 * 1e3:.3g} mm: a mounting error of "
                     "this size costs up to 180 deg of two-way phase unless calibrated away")
        # A height offset lengthens each leg only in second order, dz^2 / 2R: two-way
        # dz^2 / R, a phase of 2 pi dz^2 / (R lambda); warn where that reaches the radial
        # warning's 180 deg.
        dz = f.height_offset_m
        r_flat = float(np.sqrt(max(dist[i] ** 2 - dz * dz, 0.0)))  # dist includes dz
        phase_deg = height_phase_deg(dz, r_flat, lam)
        if phase_deg >= 180.0:
            warn(f"rts.front_ends[{i}].height_offset_mm", dz * 1e3,
                 f"lengthens both legs by dz^2 / 2R = {dz * dz / (2 * r_flat) * 1e3:.3g} mm at "
                 f"R = {r_flat:.4g} m: {phase_deg:.4g} deg of two-way phase unless calibrated "
                 "away")

    # Each antenna should look at the RuT through its cutout, not through metal.
    if scene.sheet.enabled:
        r_cut = 0.5 * scene.sheet.cutout_diameter_m
        for i, f in enumerate(rts.front_ends):
            t, h = f.tangential_offset_m, f.height_offset_m
            off = {label: math.hypot(t + at, h + ah)
                   for label, (at, ah) in zip(("Rx", "Tx"), f.antenna_offsets_m())}
            outside = [label for label, v in off.items() if v > r_cut]
            if outside:
                name, v = (("height_offset_mm", h) if abs(h) >= abs(t)
                           else ("tangential_offset_mm", t))
                warn(f"rts.front_ends[{i}].{name}", v * 1e3,
                     f"with tangential_offset_mm = {t * 1e3:g}, height_offset_mm = "
                     f"{h * 1e3:g} and the antennas at rx/tx [t, h] = "
                     f"{[round(x * 1e3, 3) for x in f.antenna_offsets_m()[0]]}/"
                     f"{[round(x * 1e3, 3) for x in f.antenna_offsets_m()[1]]} mm the "
                     f"{' and '.join(outside)} antenna{'s are' if len(outside) > 1 else ' is'} "
                     f"up to {max(off[k] for k in outside) * 1e3:.3g} mm from the centre of the "
                     f"cutout (radius {r_cut * 1e3:.3g} mm): looking at the RuT through the sheet")



def _back_end_warnings(setup, warn) -> None:
    """The RuT's element spacing and the RTS back end: the IF band, the calibration and
    fractional-delay steps."""
    radar, rts, rut = setup.scene.radar, setup.scene.rts, setup.rut
    lam = rut.wavelength_m
    # Element spacing above lambda/2: grating lobes fold angles beyond +-asin(lambda/2d).
    d = rut.spacing_m
    if d > 0.5 * lam * (1.0 + 1e-9):
        fov = math.degrees(math.asin(min(1.0, lam / (2.0 * d))))
        custom = radar.array is not None
        warn("radar.array.rx_mm" if custom else "radar.element_spacing_m",
             d if custom else radar.element_spacing_m,
             f"{'the grid unit (smallest virtual gap) ' if custom else ''}more than lambda/2 = "
             f"{0.5 * lam:.4g} m: angles beyond +-{fov:.3g} deg are "
             "ambiguous (grating lobes)")

    # The RTS back end samples the IF band [f_rts - B/2, f_rts + B/2] at f_s.
    top = rts.f_rts_hz + 0.5 * radar.bandwidth_hz
    if top > 0.5 * rts.f_s_hz:
        warn("rts.f_rts_hz", rts.f_rts_hz,
             f"the IF band reaches f_rts + B/2 = {top / 1e9:.4g} GHz, above the back end's "
             f"Nyquist frequency rts.f_s_hz/2 = {rts.f_s_hz / 2e9:.4g} GHz")

    # Calibration steps that are not whole multiples of the delay resolution get rounded.
    ratio = rts.calibration_step_s / rts.delay_resolution_s
    if abs(ratio - round(ratio)) > 1e-6 * ratio:
        warn("rts.calibration_step_ps", rts.calibration_step_s * 1e12,
             f"not a whole multiple of the RTS delay resolution "
             f"{rts.delay_resolution_s * 1e12:g} ps: the steps will be uneven")

    # A fractional-delay step that does not divide the sample period 1/f_s leaves uneven
    # settings in each sample (100 ps at 4 GSPS: 0/100/200 ps, then 250 ps): a pair's realised
    # delay difference then depends on where the target's delay falls in the sample.
    if rts.fractional_delay:
        ts, step = 1.0 / rts.f_s_hz, rts.fractional_delay_step_s
        n = ts / step
        if abs(n - round(n)) > 1e-6 * n:
            finer = ts / math.ceil(n)
            warn("rts.fractional_delay_step_s", step,
                 f"does not divide the back end's sample period 1/rts.f_s_hz = {ts * 1e12:.6g} "
                 f"ps ({n:.4g} steps): the settings within each sample are uneven and the "
                 "delay difference a front-end pair realises varies with the target's range "
                 f"by up to a step ({step * 1e12:.4g} ps); `run` plans pairs on an arc on "
                 "realised delays and designs the amplitudes for what is left (summary.json "
                 "calibration.targets; cells on a sphere are not planned so yet); "
                 f"a step that divides 1/f_s, e.g. {finer * 1e12:.6g} ps, leaves none")
