"""Export the whole setup (RuT board and elements, front ends, sheet) as PLY / OBJ / GLB."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import trimesh

from ..errors import OutputError
from .._lib.io import atomic_path
from .setup import Setup

__all__ = ["COLOURS", "rut_board_mesh", "setup_scene", "export_setup"]

#: RGBA colours of the setup's parts (the mesh export and the 3D view, ``viz.scene3d``)
COLOURS = {"sheet": [170, 170, 180, 255], "rut_tx": [220, 60, 40, 255],
           "rut_rx": [40, 90, 220, 255], "fe_rx": [40, 160, 60, 255],
           "fe_tx": [230, 150, 20, 255], "board": [30, 110, 60, 255]}


def _markers(points: np.ndarray, radius: float, colour) -> trimesh.Trimesh:
    parts = []
    for p in np.atleast_2d(points):
        s = trimesh.creation.icosphere(subdivisions=1, radius=radius)
        s.apply_translation(p)
        parts.append(s)
    m = trimesh.util.concatenate(parts)
    m.visual.face_colors = colour
    return m


def rut_board_mesh(setup: Setup) -> trimesh.Trimesh:
    """The RuT's circuit board as a thin box (world frame): the elements' bounding box plus
    3 lambda on each side in x and z, 1.6 mm thick, its front face 0.2 mm behind the elements.

    Built in the radar frame and turned with the radar's yaw, so a yawed radar's elements stay
    in front of its board (the ray tracer uses this box as a reflector).
    """
    rut = setup.rut
    lam = rut.wavelength_m
    pts = np.vstack([rut.tx_local, rut.rx_local])
    lo, hi = pts.min(0), pts.max(0)
    size = np.maximum(hi - lo, 0) + np.array([6 * lam, 0.0, 6 * lam])
    board = trimesh.creation.box(extents=[size[0], 1.6e-3, size[2]])
    board.apply_translation([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2 - 1e-3, (lo[2] + hi[2]) / 2])
    pose = np.eye(4)
    pose[:3, :3] = rut.rotation
    pose[:3, 3] = rut.position
    board.apply_transform(pose)
    return board


def setup_scene(setup: Setup) -> trimesh.Scene:
    """A trimesh scene with named geometry: sheet, RuT board, element and antenna markers."""
    sc = trimesh.Scene()
    lam = setup.rut.wavelength_m
    if setup.sheet is not None:
        sheet = setup.sheet.copy()
        sheet.visual.face_colors = COLOURS["sheet"]
        sc.add_geometry(sheet, geom_name="sheet")
    board = rut_board_mesh(setup)
    board.visual.face_colors = COLOURS["board"]
    sc.add_geometry(board, geom_name="rut_board")
    r = lam / 4
    sc.add_geometry(_markers(setup.rut.tx_world, r, COLOURS["rut_tx"]), geom_name="rut_tx")
    sc.add_geometry(_markers(setup.rut.rx_world, r, COLOURS["rut_rx"]), geom_name="rut_rx")
    sc.add_geometry(_markers(setup.fe.rx, 2 * r, COLOURS["fe_rx"]), geom_name="fe_rx")
    sc.add_geometry(_markers(setup.fe.tx, 2 * r, COLOURS["fe_tx"]), geom_name="fe_tx")
    return sc


def export_setup(setup: Setup, path: str | Path) -> Path:
    """Write the setup to ``path``; the format follows the suffix (.glb, .ply, .obj, .stl).

    Parameters
    ----------
    setup : Setup
        The setup as built (sheet, front ends, RuT).
    path : str or Path
        The file to write; its suffix picks the mesh format (``.gltf`` too).

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    OutputError
        A suffix that is no supported mesh format.
    """
    path = Path(path)
    fmt = path.suffix.lower().lstrip(".")
    if fmt not in ("glb", "gltf", "ply", "obj", "stl"):
        raise OutputError(f"--out {path}: unsupported mesh format '{fmt}' (use .glb, .ply, .obj "
                         "or .stl)")
    sc = setup_scene(setup)
    data = (sc.export(file_type=fmt) if fmt in ("glb", "gltf", "obj")
            else sc.to_geometry().export(file_type=fmt))
    if isinstance(data, str):
        data = data.encode()
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)
    return path
