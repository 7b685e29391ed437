"""A mesh seen by a monostatic radar through Sionna RT (rtsgeom.paths.raytrace_monostatic) against
the mirror's closed form and the physical optics of rtsgeom.scene.mesh.

Sionna RT's PathSolver takes a transmitter and a receiver at the same point: the radar is both
ends of every path. Geometrical optics returns a flat face only where the foot of the
perpendicular from the radar lies on it, as a mirror: ``sigma = pi R^2``, whatever the face's
size; physical optics agrees where the face is much larger than its Fresnel zone and not
where it is small or turned. Skipped where Sionna RT or its LLVM backend cannot run.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh

from rtsgeom.scene.mesh import mesh_scatterers

pytestmark = pytest.mark.raytrace

LAM = 299792458.0 / 77e9


@pytest.fixture(scope="module")
def mono():
    from rtsgeom.paths import raytrace
    ok, msg = raytrace.preflight()
    if not ok:
        pytest.skip(msg)
    from rtsgeom.paths.raytrace_monostatic import monostatic
    return monostatic


def _plate(a: float) -> trimesh.Trimesh:
    v = [[-a / 2, 0, -a / 2], [a / 2, 0, -a / 2], [a / 2, 0, a / 2], [-a / 2, 0, a / 2]]
    return trimesh.Trimesh(v, [[0, 1, 2], [0, 2, 3]], process=False)


@pytest.mark.parametrize("a, r", [(0.2, 15.0), (2.0, 5.0)])
def test_a_plate_is_a_mirror_to_sionna(mono, a, r):
    """Normal incidence: one specular path at the plate's centre, pi R^2 for a small plate and
    a large one alike; physical optics agrees with it for the large plate (14 Fresnel lengths
    across: within the Fresnel ripple of its edges, 0.6 dB) and not for the small one (at 15 m
    a 0.2 m plate is near its far field, 30.3 dBsm against the mirror's 28.5)."""
    m = _plate(a)
    res = mono(m.vertices, m.faces, np.array([0.0, -r, 0.0]), LAM, samples_per_src=100_000)
    assert len(res.rcs_dbsm) == 1 and res.interactions == ("specular",)
    assert res.rcs_dbsm[0] == pytest.approx(10 * math.log10(math.pi * r ** 2), abs=0.05)
    assert np.allclose(res.points[0], 0.0, atol=1e-3)
    _, po = mesh_scatterers(m.vertices, m.faces, np.array([0.0, -r, 0.0]), LAM, 1e3, 10.0)
    gap = abs(po[0] - res.rcs_dbsm[0])
    assert gap <= 1.0 if a > 10 * math.sqrt(LAM * r) else gap >= 1.5


@pytest.mark.parametrize("tilt_deg", [1.0, 5.0])
def test_a_turned_plate_has_no_specular_path(mono, tilt_deg):
    """Turned off normal, the foot of the perpendicular leaves the small plate: geometrical
    optics returns nothing, physical optics the sinc^2 lobe (far above -60 dBsm)."""
    m = _plate(0.2)
    th = math.radians(tilt_deg)
    radar = 15.0 * np.array([math.sin(th), -math.cos(th), 0.0])
    res = mono(m.vertices, m.faces, radar, LAM, samples_per_src=100_000)
    assert len(res.rcs_dbsm) == 0
    _, po = mesh_scatterers(m.vertices, m.faces, radar, LAM, 1e3, 10.0)
    assert po[0] > -60.0
