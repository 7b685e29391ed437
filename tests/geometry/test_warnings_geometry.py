"""Warnings that depend on the distance of each front end.

Every warning test in ``test_validation.py`` has the front ends at equal distances from the RuT,
so a mutant that took the Fraunhofer check at the *farthest* front end instead of the nearest
survived them. Here the arc centre is moved off the RuT so the front ends sit at different
distances, chosen in closed form around the Fraunhofer distance 2 d_A^2 / lambda of the RuT.

Off-centre arc of radius R and centre c = rho (sin phi, cos phi, 0), RuT at the origin: the
module at azimuth theta (on the arc) is at distance

    D(theta)^2 = R^2 + rho^2 + 2 R rho cos(theta - phi),

so the angle that puts a front end at distance D is theta = phi +- acos((D^2 - R^2 - rho^2) / (2 R rho)).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from conftest import make_scene
from rtsgeom.geometry import build_setup
from rtsgeom.geometry.farfield import fraunhofer_distance_m
from rtsgeom.geometry.warnings import scene_warnings

# (arc radius R, centre offset rho, centre direction phi in deg): every arc reaches the
# distances 0.6 .. 1.4 r_ff (R - rho < 0.07 m, R + rho > 0.18 m for r_ff = 0.124 m)
# and centres behind and to the side of the RuT (|phi| > 90 deg); signs pick the solution.
ARCS = [(0.12, 0.07, 90.0, (1, 1)), (0.2, 0.14, 90.0, (1, 1)), (0.2, 0.14, -90.0, (1, 1)),
        (0.13, 0.08, 135.0, (-1, -1)), (0.25, 0.19, -120.0, (1, 1)),
        (0.15, 0.09, -135.0, (1, 1))]


def _r_ff() -> float:
    return fraunhofer_distance_m(build_setup(make_scene()).rut)


def _angle_at_distance(dist, radius, rho, phi, sign):
    """The arc angle (rad, in (-90, 90) deg) of the module at ``dist`` from the RuT; of the two
    solutions phi +- acos(k) the one ``sign`` picks if it faces the RuT, else the other."""
    k = (dist ** 2 - radius ** 2 - rho ** 2) / (2 * radius * rho)
    assert abs(k) < 1.0, "distance not reachable on this arc"
    for s in (sign, -sign):
        theta = math.remainder(phi + s * math.acos(k), 2 * math.pi)
        if abs(theta) < math.radians(85.0):
            return theta
    raise AssertionError(f"no front-facing angle at {dist} m on this arc")


def _scene(radius, rho, phi_deg, signs, dists):
    """Two front ends at the given distances from the RuT (at the origin) on an off-centre arc."""
    phi = math.radians(phi_deg)
    angles = sorted(math.degrees(_angle_at_distance(d, radius, rho, phi, s))
                    for d, s in zip(dists, signs))
    assert angles[1] - angles[0] > 1.0, angles
    centre = [rho * math.sin(phi), rho * math.cos(phi), 0.0]

    def mutate(doc):
        rts = doc["rts"]
        rts["arc_radius_m"] = radius
        rts["arc_center_m"] = centre
        for fe, a in zip(rts["front_ends"], angles):
            fe["angle_deg"] = a
        doc["sheet"]["enabled"] = False
        doc["targets"] = []
    return make_scene(mutate)


def _fraunhofer(scene):
    return [w for w in scene_warnings(scene) if "Fraunhofer" in w]


@pytest.mark.parametrize("radius,rho,phi,signs", ARCS)
def test_one_front_end_inside_the_fraunhofer_distance_warns_once(radius, rho, phi, signs):
    r_ff = _r_ff()
    dists = [0.8 * r_ff, 1.25 * r_ff]
    scene = _scene(radius, rho, phi, signs, dists)
    setup = build_setup(scene)
    d = np.linalg.norm(setup.fe.module - setup.rut.position, axis=1)
    np.testing.assert_allclose(np.sort(d), dists, rtol=1e-9)  # the closed form placed them
    found = _fraunhofer(scene)
    assert len(found) == 1, found
    # the message names the nearest front end's distance, not the farthest
    assert f"{0.8 * r_ff:.4g} m from the RuT" in found[0], found[0]
    assert found[0].startswith(f"test.toml: rts.arc_radius_m = {radius:g}:")
    # the grid has the near front end first and last (a check of front end 0 only is caught)



def test_the_grid_has_the_near_front_end_at_either_index():
    r_ff = _r_ff()
    near = set()
    for radius, rho, phi, signs in ARCS:
        setup = build_setup(_scene(radius, rho, phi, signs, [0.8 * r_ff, 1.25 * r_ff]))
        near.add(int(np.argmin(np.linalg.norm(setup.fe.module - setup.rut.position, axis=1))))
    assert near == {0, 1}


@pytest.mark.parametrize("radius,rho,phi,signs", ARCS)
@pytest.mark.parametrize("scale,count", [((0.6, 0.9), 1), ((1.1, 1.4), 0)])
def test_fraunhofer_warning_is_one_line_for_all_front_ends(radius, rho, phi, signs, scale,
                                                           count):
    """Both inside: one warning (not one per front end); both outside: none."""
    r_ff = _r_ff()
    dists = [s * r_ff for s in scale]
    scene = _scene(radius, rho, phi, signs, dists)
    found = _fraunhofer(scene)
    assert len(found) == count, found
    if count:
        assert f"{min(dists):.4g} m from the RuT" in found[0]


# -- each warning's whole text, both sides of its bound ------------------------------------

import rtsgeom  # noqa: E402

LAM = build_setup(make_scene()).rut.wavelength_m  # the RuT's, at its centre frequency


def _wscene(edit=None, **fe0):
    """The default scene as "w.toml" with ``edit(doc)`` applied and front end 0's SI fields
    ``fe0``."""
    import copy

    from conftest import default_doc
    from rtsgeom.scene import parse_scene
    doc = copy.deepcopy(default_doc())
    if edit:
        edit(doc)
    scene = parse_scene(doc, "w.toml")
    if fe0:
        fes = list(scene.rts.front_ends)
        fes[0] = rtsgeom.replace(fes[0], **fe0)
        scene = rtsgeom.replace(scene, rts=rtsgeom.replace(scene.rts, front_ends=tuple(fes)))
    return scene


def _offset_line(name, v_m):
    return (f"w.toml: rts.front_ends[0].{name} = {v_m * 1e3:g}: larger than lambda/4 = "
            f"{LAM / 4 * 1e3:.3g} mm: a mounting error of this size costs up to 180 deg of "
            "two-way phase unless calibrated away")


@pytest.mark.parametrize("field, name", [("radial_offset_m", "radial_offset_mm"),
                                         ("tangential_offset_m", "tangential_offset_mm")])
def test_a_mounting_offset_warns_just_beyond_a_quarter_wavelength(field, name):
    assert scene_warnings(_wscene(**{field: LAM / 4})) == []
    assert scene_warnings(_wscene(**{field: -LAM / 4})) == []
    for v in (LAM / 4 * 1.0001, -LAM / 4 * 1.0001):
        assert scene_warnings(_wscene(**{field: v})) == [_offset_line(name, v)]


def test_a_height_offset_warns_from_180_deg_of_two_way_phase():
    """dz^2 / R of two-way path: 180 deg at dz = sqrt((R + lambda/4)^2 - R^2) (the sheet off:
    no cutout to look through); the text with the path, R and the phase."""
    from rtsgeom.geometry.warnings import height_phase_deg

    def no_sheet(doc):
        doc["sheet"]["enabled"] = False
    dz0 = math.sqrt((1 + LAM / 4) ** 2 - 1)
    assert height_phase_deg(dz0, 1.0, LAM) == pytest.approx(180.0, rel=1e-9)
    assert scene_warnings(_wscene(no_sheet, height_offset_m=0.999 * dz0)) == []
    for dz in (1.001 * dz0, -1.1 * dz0):
        scene = _wscene(no_sheet, height_offset_m=dz)
        s = build_setup(scene)
        dist = float(np.linalg.norm(s.fe.module[0] - s.rut.position))
        r = math.sqrt(dist ** 2 - dz * dz)
        phase = math.degrees(2 * math.pi * 2 * (math.hypot(r, dz) - r) / LAM)
        assert scene_warnings(scene) == [
            f"w.toml: rts.front_ends[0].height_offset_mm = {dz * 1e3:g}: lengthens both legs "
            f"by dz^2 / 2R = {dz * dz / (2 * r) * 1e3:.3g} mm at R = {r:.4g} m: {phase:.4g} deg "
            "of two-way phase unless calibrated away"]


@pytest.mark.parametrize("dz, r", [(1e-3, 1.0), (0.01, 0.5), (0.05, 2.0), (0.3, 1.0)])
def test_the_height_phase_in_closed_form(dz, r):
    from rtsgeom.geometry.warnings import height_phase_deg
    want = math.degrees(2 * math.pi * 2 * (math.sqrt(r * r + dz * dz) - r) / LAM)
    assert height_phase_deg(dz, r, LAM) == pytest.approx(want, rel=1e-9)
    assert height_phase_deg(-dz, r, LAM) == height_phase_deg(dz, r, LAM)
    if dz < 0.02:
        assert height_phase_deg(dz, r, LAM) == pytest.approx(
            math.degrees(2 * math.pi * dz * dz / r / LAM), rel=1e-3)


@pytest.mark.parametrize("t, h, outside, worst", [
    (0.0, 0.03, "Rx and Tx antennas are", math.hypot(0.01, 0.03)),
    (0.02, 0.0, "Rx antenna is", 0.03),
    (-0.02, 0.005, "Tx antenna is", math.hypot(0.03, 0.005)),
    (0.02, 0.02, "Rx antenna is", math.hypot(0.03, 0.02)),  # the Tx 22.4 mm: inside
    (0.0, -0.026, "Rx and Tx antennas are", math.hypot(0.01, 0.026)),
])
def test_an_antenna_outside_its_cutout_warns_in_full(t, h, outside, worst):
    """The antennas at (+-10 mm, 0) in a 25 mm cutout: the one(s) beyond it named with the
    offsets, the layout, the farthest distance and the radius; the field the larger offset
    (height on a tie). An offset beyond lambda/4 warns before it."""
    lines = scene_warnings(_wscene(lambda d: d.update(targets=[]), tangential_offset_m=t,
                                   height_offset_m=h))
    name, v = ("height_offset_mm", h) if abs(h) >= abs(t) else ("tangential_offset_mm", t)
    want = [] if abs(t) <= LAM / 4 else [_offset_line("tangential_offset_mm", t)]
    want.append(f"w.toml: rts.front_ends[0].{name} = {v * 1e3:g}: with tangential_offset_mm = "
                f"{t * 1e3:g}, height_offset_mm = {h * 1e3:g} and the antennas at rx/tx [t, h] "
                f"= [10.0, 0.0]/[-10.0, 0.0] mm the {outside} up to {worst * 1e3:.3g} mm from "
                "the centre of the cutout (radius 25 mm): looking at the RuT through the sheet")
    assert lines == want


def test_antennas_within_their_cutout_or_without_a_sheet_warn_of_nothing():
    assert scene_warnings(_wscene(tangential_offset_m=0.0, height_offset_m=0.02)) == []
    # the Rx antenna on the cutout's edge (15 + 10 = 25 mm) looks through it; 1 um beyond not
    edge = scene_warnings(_wscene(lambda d: d.update(targets=[]), tangential_offset_m=0.015))
    assert edge == [_offset_line("tangential_offset_mm", 0.015)]
    beyond = scene_warnings(_wscene(lambda d: d.update(targets=[]),
                                    tangential_offset_m=0.015001))
    assert len(beyond) == 2 and beyond[1].endswith("the Rx antenna is up to 25 mm from the "
                                                   "centre of the cutout (radius 25 mm): "
                                                   "looking at the RuT through the sheet")
    assert scene_warnings(_wscene(lambda d: d["sheet"].update(enabled=False),
                                 height_offset_m=0.03)) == []


def test_a_target_warns_just_outside_the_front_ends_span():
    def target(angle):
        return lambda d: d["targets"][2].update(angle_deg=angle)
    assert scene_warnings(_wscene(target(3.4))) == []
    assert scene_warnings(_wscene(target(12.2))) == []
    for a in (3.4 - 1e-6, 12.2 + 1e-6, -5.0):
        assert scene_warnings(_wscene(target(a))) == [
            f"w.toml: targets[2].angle_deg = {a:g}: outside the span of the front ends seen "
            "from the RuT [3.4, 12.2] deg: the RTS can only interpolate between front ends"]


def test_wide_neighbours_and_the_far_field_in_full():
    from rtsgeom.geometry.farfield import angular_resolution_rad

    def wide(doc):
        doc["rts"]["front_ends"][1]["angle_deg"] = 25.0
        doc["rts"]["allow_wide_spacing"] = True
    scene = _wscene(wide)
    s = build_setup(scene)
    az = s.fe_azimuth_rad()
    res = angular_resolution_rad(s.rut)
    assert scene_warnings(scene) == [
        f"w.toml: rts.front_ends[1].angle_deg = 25: front ends 0 and 1 are "
        f"{math.degrees(abs(az[1] - az[0])):.4g} deg apart seen from the RuT, more than its "
        f"angular resolution 1.22 lambda/d_A = {math.degrees(res):.4g} deg (paper eq. 24): "
        "angles between them cannot be synthesised"]

    def near(doc):
        doc["rts"]["arc_radius_m"] = 0.1
        doc["sheet"]["enabled"] = False
        doc["targets"] = []
    scene = _wscene(near)
    s = build_setup(scene)
    dist = np.linalg.norm(s.fe.module - s.rut.position, axis=1)
    assert scene_warnings(scene) == [
        f"w.toml: rts.arc_radius_m = 0.1: the nearest front end is {dist.min():.4g} m from "
        f"the RuT, closer than its Fraunhofer distance 2 d_A^2/lambda = {_r_ff():.4g} m: "
        "phase-front curvature is not negligible (see curvature_deg in `rtsgeom info`)"]


def _frac_line(fs, step=1e-12):
    ts = 1 / fs
    n = ts / step
    return (f"w.toml: rts.fractional_delay_step_s = {step:g}: does not divide the back end's "
            f"sample period 1/rts.f_s_hz = {ts * 1e12:.6g} ps ({n:.4g} steps): the settings "
            "within each sample are uneven and the delay difference a front-end pair realises "
            f"varies with the target's range by up to a step ({step * 1e12:.4g} ps); `run` "
            "plans pairs on an arc on realised delays and designs the amplitudes for what is "
            "left (summary.json calibration.targets; cells on a sphere are not planned so "
            f"yet); a step that divides 1/f_s, e.g. {ts / math.ceil(n) * 1e12:.6g} ps, leaves "
            "none")


def test_the_back_ends_warnings_at_their_edges():
    """The IF band's top at Nyquist accepted, beyond warned (with the uneven fractional
    delay that sample rate brings); calibration steps a whole multiple of the delay
    resolution or not; no noise."""
    def fs(v):
        return lambda d: d["rts"].update(f_s_hz=v)
    assert scene_warnings(_wscene(fs(2e9))) == []
    assert scene_warnings(_wscene(fs(1.999e9))) == [
        "w.toml: rts.f_rts_hz = 5e+08: the IF band reaches f_rts + B/2 = 1 GHz, above the back "
        "end's Nyquist frequency rts.f_s_hz/2 = 0.9995 GHz", _frac_line(1.999e9)]
    assert scene_warnings(_wscene(fs(3.999e9))) == [_frac_line(3.999e9)]
    assert scene_warnings(_wscene(lambda d: d["rts"].update(calibration_step_ps=2.5))) == [
        "w.toml: rts.calibration_step_ps = 2.5: not a whole multiple of the RTS delay "
        "resolution 1 ps: the steps will be uneven"]
    assert scene_warnings(_wscene(lambda d: d["rts"].update(calibration_step_ps=3.0))) == []
    assert scene_warnings(_wscene(lambda d: d["radar"].pop("snr_db"))) == [
        "w.toml: radar.snr_db is not set: the simulation is noiseless"]


def test_grating_lobes_warn_beyond_half_a_wavelength():
    def spacing(v):
        return lambda d: d["radar"].update(element_spacing_m=v)
    assert scene_warnings(_wscene(spacing(LAM / 2))) == []
    for d in (LAM / 2 * 1.001, 0.003):
        fov = math.degrees(math.asin(LAM / (2 * d)))
        assert scene_warnings(_wscene(spacing(d))) == [
            f"w.toml: radar.element_spacing_m = {d:g}: more than lambda/2 = {LAM / 2:.4g} m: "
            f"angles beyond +-{fov:.3g} deg are ambiguous (grating lobes)"]
