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
