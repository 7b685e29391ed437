"""Ray-traced paths with Sionna RT (``--paths raytrace``): the setup's reflections per element pair.

This module, :mod:`~rtsgeom.paths.raytrace_monostatic` (a mesh object's returns to a
monostatic radar) and :mod:`~rtsgeom.paths.raytrace_backend` (the pre-flight check of Dr.Jit's
backend, re-exported here) are the one adapter of rtsgeom that imports ``sionna``, ``mitsuba``
or ``drjit``, lazily, on the first :func:`raytrace_paths` call, after the pre-flight.

Scene
    The sheet mesh (``setup.sheet``, ITU material from ``sheet.material``), the RuT's circuit
    board as a thin box (:func:`rtsgeom.geometry.export.rut_board_mesh`, ITU metal: the copper
    ground plane under the patches; it carries the sheet <-> RuT multi-bounce paths) and the
    ``[[structure]]`` meshes of the scene. One Sionna transmitter per RuT Tx element and per
    front end's Tx antenna, one receiver per RuT Rx element and per front end's Rx antenna, each
    an isotropic single-element array (``synthetic_array=False``), at the radar's centre
    frequency ``c / setup.rut.wavelength_m``.

Precision
    Sionna computes in float32. Everything is translated by ``-setup.rut.position`` before it is
    handed over (delays are translation invariant), so the radar sits at the origin where float32
    is finest: line-of-sight delays agree with the exact model to about 0.0003 ps.

Rows returned (a :class:`~rtsgeom.paths.table.Paths` table, ``method="raytrace"``)
    ``tx_to_fe`` (RuT Tx m -> FE q Rx), ``fe_to_rx`` (FE q Tx -> RuT Rx k) and ``rut_to_rut``
    (RuT Tx m -> setup -> RuT Rx k, at least one interaction off the RuT's own board: the direct
    Tx -> Rx coupling, line of sight or its grazing bounce on the board, is not a setup echo).
    Front end <-> front end paths are ignored. ``gain`` is Sionna's ``a`` (no propagation
    phase) times ``10^(-L/20)`` per bounce off a surface with an absorber of L dB
    (``sheet.reflection_loss_db``, ``[[structure]] reflection_loss_db``), ``delay_s`` Sionna's
    ``tau`` in float64. Duplicate paths (same interaction types and
    objects, hit points within 1 mm, delays within a few float32 ulps) are dropped, as are paths
    weaker than ``raytrace.min_gain_db``.

Backend: the ``cuda_ad_mono_polarized`` Mitsuba variant where Dr.Jit finds CUDA, else
``llvm_ad_mono_polarized``; ``RTSGEOM_RAYTRACE_BACKEND=llvm`` (or ``cuda``) forces one. Dr.Jit's
kernel cache goes to the user's cache folder, ``$XDG_CACHE_HOME/rtsgeom/drjit`` (default
``~/.cache/rtsgeom/drjit``), or ``$RTSGEOM_CACHE_DIR/drjit``; ``DRJIT_CACHE_DIR`` overrides both.

Known limits (see RAYTRACE.md): Sionna drops every path segment shorter than 1 cm; its image
method accepts a hit on another triangle whose image lies within 1 cm; geometric optics on a
faceted cylinder seen from (near) its axis returns one glint per facet, so the coherent sheet echo
depends on the tessellation.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from scipy.constants import c

from ..geometry import Setup
from ..scene import RaytraceConfig
from ..errors import SceneError
from .raytrace_backend import (INSTALL_HINT, _default_cache_dir, SIONNA_LOCK, backend_info,
                               ensure_available, preflight)
from ..errors import RaytraceUnavailable
from .table import FE_TO_RX, RUT_TO_RUT, TX_TO_FE, Paths

__all__ = ["RaytraceUnavailable", "RaytraceResult", "preflight", "ensure_available",
           "backend_info", "itu_type", "trace", "raytrace_paths", "INSTALL_HINT"]

# Slab thickness of the board's material (the box itself comes from geometry.export)
BOARD_THICKNESS_M = 1.6e-3
DUPLICATE_VERTEX_TOL_M = 1e-3  # two rows whose hit points all agree within this are one path
DUPLICATE_DELAY_ULPS = 4  # ... and whose float32 delays agree within this many ulps

_INTERACTION_NAMES = {1: "specular", 2: "diffuse", 4: "refraction", 8: "diffraction"}

@dataclass(frozen=True)
class RaytraceResult:
    """A ray-tracing run: the :class:`Paths` table plus per-row details for cross-checks.

    ``vertices`` (P, D, 3) are the interaction points in the world frame (NaN past the last
    interaction), ``primitives`` (P, D) the triangle index within ``objects`` (P, D) (object
    names, ``""`` past the last interaction). Row ``i`` describes ``paths`` row ``i``.
    """

    paths: Paths
    vertices: np.ndarray
    primitives: np.ndarray
    objects: np.ndarray
    variant: str
    timings_s: dict = field(default_factory=dict)
    stats: dict = field(default_factory=dict)

    def hit_points(self, i: int) -> np.ndarray:
        """The interaction points (world frame, in order from transmitter to receiver) of
        ``paths`` row ``i``: (bounces, 3); empty for line of sight."""
        v = self.vertices[i]
        return v[np.all(np.isfinite(v), axis=-1)]


# ------------------------------------------------------------------------------------------
# Scene
# ------------------------------------------------------------------------------------------


def itu_type(material: str, fieldname: str = "sheet.material") -> str:
    """``itu_metal`` -> ``metal``: the ITU-R P.2040 material type of an rtsgeom material name.

    Unknown names raise :class:`SceneError` naming ``fieldname``. Frequency validity is checked
    when the material is evaluated at the radar frequency (:func:`trace`).
    """
    from sionna.rt.radio_materials.itu import ITU_MATERIALS_PROPERTIES  # after ensure_available
    known = sorted(k for k in ITU_MATERIALS_PROPERTIES if k != "vacuum")
    kind = material[4:] if material.startswith("itu_") else None
    if kind not in known:
        raise SceneError(f"{fieldname} = {material!r}: must be an ITU radio material, one of "
                         + ", ".join("itu_" + k for k in known))
    return kind


def _mi_mesh(mi, mesh, name: str, offset: np.ndarray):
    """trimesh -> mitsuba Mesh (float32, translated by ``offset``), faces in trimesh order so
    Sionna's primitive index is the trimesh face index."""
    v = np.asarray(mesh.vertices, float) + offset
    f = np.asarray(mesh.faces, np.int64)
    m = mi.Mesh(name, vertex_count=len(v), face_count=len(f), has_vertex_normals=False,
                has_vertex_texcoords=False)
    params = mi.traverse(m)
    params["vertex_positions"] = mi.Float(np.ascontiguousarray(v, np.float32).ravel())
    params["faces"] = mi.UInt32(np.ascontiguousarray(f, np.uint32).ravel())
    params.update()
    return m


def _load_structure(path: str, index: int):
    import trimesh
    where = f"structure[{index}].mesh"
    try:
        mesh = trimesh.load(path, force="mesh", process=True)
    except Exception as exc:  # trimesh raises many kinds for unreadable files
        raise SceneError(f"{where} = {path!r}: cannot read the mesh ({exc})") from None
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise SceneError(f"{where} = {path!r}: must be a mesh with at least one triangle")
    if not np.all(np.isfinite(mesh.vertices)):
        raise SceneError(f"{where} = {path!r}: the mesh has non-finite vertices")
    return mesh


@dataclass
class _Built:
    scene: object
    tx_names: list
    rx_names: list
    object_names: dict  # object_id -> name
    meshes: dict  # name -> trimesh (world frame)
    absorber: dict = field(default_factory=dict)  # object_id -> amplitude factor per bounce


def _build_scene(setup: Setup, mi, rt) -> _Built:
    from sionna.rt.radio_materials.itu import ITU_MATERIALS_PROPERTIES
    from ..geometry.export import rut_board_mesh
    sc = setup.scene
    origin = np.asarray(setup.rut.position, float)
    off = -origin
    freq = c / setup.rut.wavelength_m
    scene = rt.load_scene()  # empty
    scene.frequency = freq

    materials: dict = {}

    def material(name: str, fieldname: str, thickness: float):
        kind = itu_type(name, fieldname)
        key = (kind, round(float(thickness), 9))
        if key not in materials:
            label = f"{kind}_{len(materials)}"
            try:
                if kind == "metal":  # ITU's metal is frequency independent (eps_r 1, 1e7 S/m):
                    eps, _, sigma, _ = next(iter(ITU_MATERIALS_PROPERTIES["metal"].values()))
                    mat = rt.RadioMaterial(name=label, thickness=float(thickness),  # any band
                                           relative_permittivity=eps, conductivity=sigma)
                else:
                    mat = rt.ITURadioMaterial(name=label, itu_type=kind, thickness=float(thickness))
                scene.add(mat)  # evaluates the ITU model at the scene frequency
            except ValueError as exc:
                raise SceneError(f"{fieldname} = {name!r}: {exc} (the radar's centre frequency is "
                                 f"{freq / 1e9:.3f} GHz)") from None
            materials[key] = mat
        return materials[key]

    meshes = {}
    objects = []
    if setup.sheet is not None:
        meshes["sheet"] = setup.sheet
        objects.append(("sheet", material(sc.sheet.material, "sheet.material",
                                          sc.sheet.thickness_m)))
    meshes["rut_board"] = rut_board_mesh(setup)
    objects.append(("rut_board", material("itu_metal", "rut board", BOARD_THICKNESS_M)))
    loss_db = {"sheet": sc.sheet.reflection_loss_db}
    for i, (path, mat, loss) in enumerate(sc.extra_meshes):
        name = f"structure_{i}"
        meshes[name] = _load_structure(path, i)
        objects.append((name, material(mat, f"structure[{i}].material", 0.1)))
        loss_db[name] = loss
    scene.add([rt.SceneObject(mi_mesh=_mi_mesh(mi, meshes[n], n, off), name=n, radio_material=m)
               for n, m in objects])

    scene.tx_array = rt.PlanarArray(num_rows=1, num_cols=1, pattern="iso", polarization="V")
    scene.rx_array = rt.PlanarArray(num_rows=1, num_cols=1, pattern="iso", polarization="V")
    rut, fe = setup.rut, setup.fe
    devices, tx_names, rx_names = [], [], []

    def device(cls, name, p, names):
        q = np.asarray(p, float) + off
        devices.append(cls(name=name, position=mi.Point3f(*map(float, q))))
        names.append(name)

    for m, p in enumerate(rut.tx_world):
        device(rt.Transmitter, f"rut_tx{m}", p, tx_names)
    for q, p in enumerate(fe.tx):
        device(rt.Transmitter, f"fe{q}_tx", p, tx_names)
    for k, p in enumerate(rut.rx_world):
        device(rt.Receiver, f"rut_rx{k}", p, rx_names)
    for q, p in enumerate(fe.rx):
        device(rt.Receiver, f"fe{q}_rx", p, rx_names)
    scene.add(devices)
    if list(scene.transmitters) != tx_names or list(scene.receivers) != rx_names:
        raise RuntimeError("Sionna RT reordered the radio devices")  # index order = insertion
    ids = {int(scene.objects[n].object_id): n for n, _ in objects}
    absorber = {i: 10.0 ** (-loss_db[n] / 20.0) for i, n in ids.items() if loss_db.get(n, 0.0)}
    return _Built(scene, tx_names, rx_names, ids, meshes, absorber)


# ------------------------------------------------------------------------------------------
# Solve and extract
# ------------------------------------------------------------------------------------------


def _dedupe(tau: np.ndarray, inter: np.ndarray, objs: np.ndarray, verts: np.ndarray) -> np.ndarray:
    """Keep-mask over the paths of one element pair: drop rows that repeat an earlier one
    (same interaction types and objects, every hit point within 1 mm, delay within a few ulps).
    Arrays: tau (P,), inter/objs (P, D), verts (P, D, 3)."""
    n = tau.size
    keep = np.ones(n, bool)
    if n < 2:
        return keep
    tol = DUPLICATE_DELAY_ULPS * np.spacing(np.abs(tau).astype(np.float32)).astype(float)
    groups: dict = {}
    for i in range(n):
        groups.setdefault((inter[i].tobytes(), objs[i].tobytes()), []).append(i)
    for idx in groups.values():
        if len(idx) < 2:
            continue
        idx = np.asarray(idx)
        idx = idx[np.argsort(tau[idx], kind="stable")]
        kept: list[int] = []
        for i in idx:
            for j in reversed(kept):
                if tau[i] - tau[j] > tol[i]:
                    break
                if np.all(np.linalg.norm(np.nan_to_num(verts[i] - verts[j]), axis=-1)
                          <= DUPLICATE_VERTEX_TOL_M):
                    keep[i] = False
                    break
            if keep[i]:
                kept.append(i)
    return keep


@dataclass(frozen=True)
class _Solved:
    """Sionna's paths for every (receiver, transmitter) pair, one antenna each, as float64
    numpy: ``valid``/``tau``/``a`` (rx, tx, P), ``inter``/``objs``/``prims`` (D, rx, tx, P),
    ``verts`` (D, rx, tx, P, 3); at ``max_depth = 0`` one row of no interaction."""

    valid: np.ndarray
    tau: np.ndarray
    a: np.ndarray
    inter: np.ndarray
    objs: np.ndarray
    prims: np.ndarray
    verts: np.ndarray


def _solve(built: _Built, rt, cfg: RaytraceConfig, seed: int) -> _Solved:
    """Run Sionna's path solver on ``built`` (deterministic, no diffraction, every antenna its
    own source: ``synthetic_array=False``) and take its tensors to numpy."""
    solver = rt.PathSolver(deterministic=True)
    res = solver(built.scene, max_depth=int(cfg.max_depth),
                 max_num_paths_per_src=int(cfg.samples_per_src) * max(1, int(cfg.max_depth)),
                 samples_per_src=int(cfg.samples_per_src), synthetic_array=False,
                 los=bool(cfg.los), specular_reflection=bool(cfg.specular_reflection),
                 diffuse_reflection=bool(cfg.diffuse_reflection),
                 refraction=bool(cfg.refraction), diffraction=False,
                 seed=int(seed % (2**31 - 1)))
    valid = np.asarray(res.valid.numpy(), bool)[:, 0, :, 0, :]  # (rx, tx, P)
    tau = res.tau.numpy().astype(np.float64)[:, 0, :, 0, :]
    a_re, a_im = res.a
    a = (a_re.numpy().astype(np.float64) + 1j * a_im.numpy().astype(np.float64))[:, 0, :, 0, :]
    if int(cfg.max_depth) > 0:
        inter = res.interactions.numpy()[:, :, 0, :, 0, :]  # (D, rx, tx, P)
        objs = res.objects.numpy()[:, :, 0, :, 0, :]
        prims = res.primitives.numpy()[:, :, 0, :, 0, :]
        verts = res.vertices.numpy().astype(np.float64)[:, :, 0, :, 0, :, :]
    else:
        shape = (1,) + tau.shape
        inter = np.zeros(shape, np.uint32)
        objs = prims = np.full(shape, 0xFFFFFFFF, np.uint32)
        verts = np.zeros(shape + (3,))
    return _Solved(valid, tau, a, inter, objs, prims, verts)


class _Rows:
    """The paths kept so far, column by column, and the counts of those dropped (raw,
    duplicates, weaker than ``min_gain_db``)."""

    COLUMNS = ("front_end", "direction", "rut_tx", "rut_rx", "delay_s", "gain", "bounces",
               "interactions", "surfaces")

    def __init__(self, solved: _Solved, built: _Built, min_gain_db: float, origin: np.ndarray):
        self.s, self.built, self.min_gain_db, self.origin = solved, built, min_gain_db, origin
        self.board_id = next(i for i, name in built.object_names.items() if name == "rut_board")
        self.cols = {k: [] for k in self.COLUMNS}
        self.det_v, self.det_p, self.det_o = [], [], []
        self.raw = self.dupes = self.weak = 0

    def take(self, ti: int, ri: int, direction: str, fe_i: int, m: int, k: int,
             need_bounce: bool) -> None:
        """Keep the valid, distinct, strong enough paths from transmitter ``ti`` to receiver
        ``ri`` as rows (``need_bounce``: rut_to_rut, a setup echo must leave the radar's
        board)."""
        s = self.s
        sel = np.flatnonzero(s.valid[ri, ti])
        if sel.size == 0:
            return
        it = s.inter[:, ri, ti, sel].T  # (p, D)
        if need_bounce:
            off_board = np.any((it != 0) & (s.objs[:, ri, ti, sel].T != self.board_id), axis=1)
            sel, it = sel[off_board], it[off_board]
            if sel.size == 0:
                return
        self.raw += sel.size
        ob = s.objs[:, ri, ti, sel].T
        vt = s.verts[:, ri, ti, sel].transpose(1, 0, 2)
        vt = np.where((it != 0)[..., None], vt, np.nan)
        keep = _dedupe(s.tau[ri, ti, sel], it, np.where(it != 0, ob, 0), vt)
        self.dupes += int((~keep).sum())
        g = s.a[ri, ti, sel]
        for oid, f in self.built.absorber.items():  # an absorber's loss once per bounce off it
            g = g * f ** np.sum((it != 0) & (ob == oid), axis=1)
        with np.errstate(divide="ignore"):
            strong = 20 * np.log10(np.abs(g)) >= self.min_gain_db
        self.weak += int((keep & ~strong).sum())
        keep &= strong
        pr = s.prims[:, ri, ti, sel].T
        for j in np.flatnonzero(keep):
            self._row(j, (direction, fe_i, m, k), s.tau[ri, ti, sel[j]], g[j], it[j], ob[j],
                      pr[j], vt[j])

    def _row(self, j, where, delay, gain, it, ob, pr, vt) -> None:
        direction, fe_i, m, k = where
        for key, v in zip(("direction", "front_end", "rut_tx", "rut_rx", "delay_s", "gain",
                           "bounces"), (direction, fe_i, m, k, delay, gain, int((it != 0).sum()))):
            self.cols[key].append(v)
        names = [_INTERACTION_NAMES.get(int(x), f"type{int(x)}") for x in it if x != 0]
        self.cols["interactions"].append("+".join(names) if names else "los")
        self.det_v.append(vt + self.origin)
        self.det_p.append(np.where(it != 0, pr.astype(np.int64), -1))
        self.det_o.append([self.built.object_names.get(int(o), "?") if x != 0 else ""
                           for o, x in zip(ob, it)])
        self.cols["surfaces"].append("+".join(o for o in self.det_o[-1] if o))

    def table(self):
        """The rows sorted by (direction, front end, RuT Tx, RuT Rx, delay): the paths table and
        the hit points, primitives and object names per interaction."""
        cols, n, d = self.cols, len(self.cols["delay_s"]), self.s.verts.shape[0]
        order = np.lexsort((cols["delay_s"], cols["rut_rx"], cols["rut_tx"], cols["front_end"],
                            cols["direction"])) if n else np.zeros(0, int)
        paths = Paths.build(**{k: np.asarray(v)[order] if n else np.zeros(0)
                               for k, v in cols.items()}, method="raytrace")
        vertices = np.asarray(self.det_v, float).reshape(n, d, 3)[order]
        primitives = np.asarray(self.det_p, np.int64).reshape(n, d)[order]
        objects = np.asarray(self.det_o, dtype=object).reshape(n, d)[order].astype(str)
        return paths, vertices, primitives, objects


def trace(setup: Setup, config: RaytraceConfig | None = None) -> RaytraceResult:
    """Ray-trace ``setup`` with Sionna RT; the :class:`RaytraceResult` with the paths table.

    Parameters
    ----------
    setup : Setup
        The RTS setup (sheet, front ends, RuT, structures).
    config : RaytraceConfig, optional
        Solver settings; the scene's ``[raytrace]`` section by default.

    Returns
    -------
    RaytraceResult
        The paths table with hit points, the Mitsuba variant, timings and counts.

    Raises
    ------
    RaytraceUnavailable
        Sionna RT or its Dr.Jit backend cannot run here.
    """
    cfg = config or setup.scene.raytrace
    timings = {}
    t0 = time.perf_counter()
    mi, rt = ensure_available()
    timings["import_s"] = time.perf_counter() - t0
    with SIONNA_LOCK:
        t0 = time.perf_counter()
        built = _build_scene(setup, mi, rt)
        timings["build_s"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        solved = _solve(built, rt, cfg, setup.scene.seed)
        timings["solve_s"] = time.perf_counter() - t0
        variant = mi.variant()
    t0 = time.perf_counter()
    rows = _Rows(solved, built, cfg.min_gain_db, np.asarray(setup.rut.position, float))
    n_tx, n_rxel = setup.rut.tx_world.shape[0], setup.rut.rx_world.shape[0]
    for q in range(setup.fe.count):
        for m in range(n_tx):  # RuT Tx m -> FE q Rx
            rows.take(m, n_rxel + q, TX_TO_FE, q, m, -1, False)
        for k in range(n_rxel):  # FE q Tx -> RuT Rx k
            rows.take(n_tx + q, k, FE_TO_RX, q, -1, k, False)
    for m in range(n_tx):
        for k in range(n_rxel):  # RuT Tx m -> setup -> RuT Rx k
            rows.take(m, k, RUT_TO_RUT, -1, m, k, True)
    paths, vertices, primitives, objects = rows.table()
    timings["extract_s"] = time.perf_counter() - t0
    stats = {"raw_paths": rows.raw, "duplicates_dropped": rows.dupes, "weak_dropped": rows.weak,
             "rows": vertices.shape[0],
             "samples_per_src": int(cfg.samples_per_src), "max_depth": int(cfg.max_depth),
             "frequency_hz": c / setup.rut.wavelength_m,
             "faces": {k: int(len(v.faces)) for k, v in built.meshes.items()}}
    return RaytraceResult(paths, vertices, primitives, objects, variant, timings, stats)


def raytrace_paths(setup: Setup, config: RaytraceConfig | None = None) -> Paths:
    """Ray-traced :class:`Paths` of ``setup`` (``method="raytrace"``); ``config`` defaults to the
    scene's ``[raytrace]`` section. Raises :class:`RaytraceUnavailable` when Sionna RT cannot run
    here and :class:`SceneError` for an unknown or out-of-band material, or for antenna
    patterns (``[radar.pattern]``/``[rts.pattern]`` other than isotropic: not yet handed to
    Sionna RT, so they are refused rather than silently dropped).

    Parameters
    ----------
    setup : Setup
    config : RaytraceConfig, optional
        Default: the scene's ``[raytrace]``.

    Returns
    -------
    Paths
        Line of sight and reflections.

    Raises
    ------
    RaytraceUnavailable
        Sionna RT cannot run here.
    """
    for cfg, where in ((setup.scene.radar.pattern, "radar.pattern.kind"),
                       (setup.scene.rts.pattern, "rts.pattern.kind")):
        if cfg.kind != "isotropic":
            raise SceneError(f"{setup.scene.source or '<scene>'}: {where} = \"{cfg.kind}\": "
                             "must be isotropic with --paths raytrace (antenna patterns enter "
                             "the exact paths only so far)")
    return trace(setup, config).paths

