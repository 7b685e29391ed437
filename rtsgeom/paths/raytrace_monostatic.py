"""A mesh object's returns to a monostatic radar by Sionna RT: the radar is both ends of every path.

Part of the Sionna RT adapter (:mod:`~rtsgeom.paths.raytrace`, whose scene helpers it shares):
one isotropic transmitter and one isotropic receiver at the same point, the mesh perfectly
conducting (ITU metal), no line of sight; Sionna's ``PathSolver`` finds the specular
reflections (geometrical optics: a flat face returns only where the foot of the perpendicular
from the radar lies on it, as a mirror, ``pi R^2``) and, on request, UTD edge diffraction. The
alternative to the physical optics of :mod:`rtsgeom.scene.mesh`; docs/objects.md compares the
two and says why physical optics is the default.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from scipy.constants import c

from .raytrace import _INTERACTION_NAMES, _mi_mesh
from .raytrace_backend import SIONNA_LOCK, ensure_available

__all__ = ["MonostaticReturns", "monostatic"]


@dataclass(frozen=True, eq=False)  # numpy fields
class MonostaticReturns:
    """Sionna RT's monostatic returns of a mesh: one row per path from the radar back to it.

    ``points`` (N, 3): the apparent scatterer (the path's last interaction for one bounce,
    else the point at range ``c tau / 2`` along the direction the return arrives from) in the
    mesh's frame; ``rcs_dbsm`` (N,) the cross-section a point there needs for the path's power,
    ``sigma = |a|^2 (4 pi)^3 R^4 / lambda^2`` at ``R = c tau / 2``; ``bounces`` (N,);
    ``interactions`` (N,) as in :class:`Paths` (``specular``, ``specular+diffraction`` ...)."""

    points: np.ndarray
    rcs_dbsm: np.ndarray
    bounces: np.ndarray
    interactions: tuple
    variant: str
    timings_s: dict = field(default_factory=dict)

    def __repr__(self) -> str:
        top = f", strongest {self.rcs_dbsm.max():.1f} dBsm" if len(self.rcs_dbsm) else ""
        return f"MonostaticReturns({len(self.rcs_dbsm)} paths{top}, {self.variant})"


def monostatic(vertices: np.ndarray, faces: np.ndarray, radar: np.ndarray, wavelength_m: float,
               max_depth: int = 1, samples_per_src: int = 1_000_000,
               diffraction: bool = False) -> MonostaticReturns:
    """A perfectly conducting mesh's returns to a monostatic radar at ``radar`` (3,), both ends
    of every path (one isotropic transmitter and one receiver at the same point; no line of
    sight), by Sionna RT's ``PathSolver`` (geometrical optics: specular reflections up to
    ``max_depth`` bounces, and UTD edge diffraction with ``diffraction``). Everything is
    translated to put the radar at the origin (float32). The alternative to the physical
    optics of :mod:`rtsgeom.scene.mesh` (docs/objects.md compares them).

    Raises
    ------
    RaytraceUnavailable
        Sionna RT cannot run here.
    """
    import trimesh
    timings = {}
    t0 = time.perf_counter()
    mi, rt = ensure_available()
    timings["import_s"] = time.perf_counter() - t0
    radar = np.asarray(radar, float)
    mesh = trimesh.Trimesh(np.asarray(vertices, float), np.asarray(faces, np.int64), process=False)
    with SIONNA_LOCK:
        t0 = time.perf_counter()
        scene = rt.load_scene()
        scene.frequency = c / wavelength_m
        from sionna.rt.radio_materials.itu import ITU_MATERIALS_PROPERTIES
        eps, _, sigma, _ = next(iter(ITU_MATERIALS_PROPERTIES["metal"].values()))
        mat = rt.RadioMaterial(name="mesh_metal", thickness=0.01, relative_permittivity=eps,
                               conductivity=sigma)
        scene.add(mat)
        scene.add(rt.SceneObject(mi_mesh=_mi_mesh(mi, mesh, "mesh", -radar), name="mesh",
                                 radio_material=mat))
        scene.tx_array = rt.PlanarArray(num_rows=1, num_cols=1, pattern="iso", polarization="V")
        scene.rx_array = rt.PlanarArray(num_rows=1, num_cols=1, pattern="iso", polarization="V")
        scene.add([rt.Transmitter(name="radar_tx", position=mi.Point3f(0.0, 0.0, 0.0)),
                   rt.Receiver(name="radar_rx", position=mi.Point3f(0.0, 0.0, 0.0))])
        timings["build_s"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        res = rt.PathSolver(deterministic=True)(
            scene, max_depth=int(max_depth), max_num_paths_per_src=int(samples_per_src),
            samples_per_src=int(samples_per_src), synthetic_array=False, los=False,
            specular_reflection=True, diffuse_reflection=False, refraction=False,
            diffraction=bool(diffraction), edge_diffraction=bool(diffraction))
        valid = np.asarray(res.valid.numpy(), bool).reshape(-1)
        tau = res.tau.numpy().astype(np.float64).reshape(-1)[valid]
        a_re, a_im = res.a
        a = (a_re.numpy().astype(np.float64)
             + 1j * a_im.numpy().astype(np.float64)).reshape(-1)[valid]
        inter = res.interactions.numpy().reshape(int(max_depth), -1)[:, valid].T  # (N, D)
        verts = res.vertices.numpy().astype(np.float64).reshape(int(max_depth), -1, 3)
        verts = verts[:, valid].transpose(1, 0, 2)  # (N, D, 3), radar at the origin
        variant = mi.variant()
        timings["solve_s"] = time.perf_counter() - t0
    r_eq = c * tau / 2.0
    nb = (inter != 0).sum(axis=1)
    last = verts[np.arange(len(nb)), np.maximum(nb - 1, 0)]
    toward = last / np.maximum(np.linalg.norm(last, axis=1), 1e-12)[:, None]
    pts = np.where((nb == 1)[:, None], last, toward * r_eq[:, None]) + radar
    with np.errstate(divide="ignore"):
        rcs = 10.0 * np.log10(np.abs(a) ** 2 * (4.0 * np.pi) ** 3 * r_eq ** 4 / wavelength_m ** 2)
    names = tuple("+".join(_INTERACTION_NAMES.get(int(x), f"type{int(x)}") for x in row if x)
                  for row in inter)
    return MonostaticReturns(pts, rcs, nb, names, variant, timings)
