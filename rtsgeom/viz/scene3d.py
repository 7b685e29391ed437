"""3D view of a :class:`~rtsgeom.geometry.Setup` with pyvista: PNG, HTML or a window.

What is drawn (world frame, metres; x lateral, y boresight, z up):

* the RuT board and its Tx/Rx elements, **scaled up** about the phase centre (the board is a few
  centimetres wide, the arc a metre away); a side panel shows the board at true scale;
* the front-end arc (a thin line at the arc radius), each front end's Rx and Tx antenna
  (enlarged markers, labelled ``FE0 Rx`` / ``FE0 Tx``) and the module behind them;
* the metal sheet with its cutouts (semi-transparent grey, the cutout rims outlined);
* the virtual targets as cones at 1.5 x the arc radius in their azimuth, labelled with their true
  range (they are tens of metres away);
* optionally propagation paths: line of sight and reflections in two colours;
* a plan view (top-down) of the same scene in a second side panel.

Rendering without a display uses VTK's EGL (or OSMesa) off-screen window; an Xvfb server is
started only as a last resort (see :func:`ensure_render_backend`).
"""

from __future__ import annotations

import html
import io
import os
import re
from pathlib import Path

import numpy as np
import pyvista as pv

from ..geometry import Setup
from .._lib.io import write_bytes, write_text
from .meshes import (ARC, BACKGROUND, LOS, MODULE, PANEL_BACKGROUND, REFLECTION_BY_BOUNCES,
                     RIM, SHEET, SHEET_LEGEND, TARGET, TARGET_RADIUS_FACTOR, angle_span, arc_points, board,
                     cutout_rims, merge, merge_lines, modules, path_polylines, polyline, rgb,
                     rut_scale_factor, scaled, spheres, split_paths, target_positions,
                     undrawable_reflections)
from .._lib.util import warn_caller
from ..errors import RtsgeomWarning, VizError
from .render_backend import ensure_render_backend

__all__ = ["VizError", "ensure_render_backend", "build_plotter", "render_setup_png",
           "setup_png_bytes",
           "export_setup_html", "show_setup", "TARGET_RADIUS_FACTOR", "rut_scale_factor",
           "undrawable_reflections", "labelled_targets", "MAX_TARGET_LABELS"]


def _add_setup(pl, setup: Setup, paths, scale: float, labels: str) -> list:
    """Add the whole setup to the active renderer; return legend entries.

    ``labels``: "2d" (screen-space text), "3d" (text meshes, kept by the HTML export) or "none".
    """
    rut, fe = setup.rut, setup.fe
    lam = rut.wavelength_m
    legend = []

    # RuT, enlarged about its phase centre
    pl.add_mesh(board(setup, scale), color=rgb("board"), opacity=0.4)
    el_r = 0.22 * lam * scale
    pl.add_mesh(spheres(scaled(rut.tx_world, rut.position, scale), el_r), color=rgb("rut_tx"))
    pl.add_mesh(spheres(scaled(rut.rx_world, rut.position, scale), el_r), color=rgb("rut_rx"))
    legend += [[f"RuT Tx (drawn x{scale:g})", rgb("rut_tx")], ["RuT Rx", rgb("rut_rx")]]

    # arc through the module centres
    a_min, a_max = angle_span(setup)
    pl.add_mesh(polyline(arc_points(setup, a_min, a_max)), color=ARC, line_width=2)
    legend.append([f"front-end arc, R_c = {fe.arc_radius_m:g} m", ARC])

    # sheet with cutouts
    if setup.sheet is not None:
        pl.add_mesh(pv.wrap(setup.sheet), color=SHEET, opacity=0.5, specular=0.5,
                    specular_power=15, ambient=0.25)
        pl.add_mesh(cutout_rims(setup), color=RIM, line_width=3)
        legend.append(["metal sheet with cutouts", SHEET_LEGEND])

    # front ends: module body and enlarged antenna markers
    pl.add_mesh(modules(setup), color=MODULE, opacity=0.9)
    ant_r = max(min(0.006, 0.3 * float(np.min(np.abs(fe.separation_m)))), 0.5 * lam)
    pl.add_mesh(spheres(fe.rx, ant_r), color=rgb("fe_rx"))
    pl.add_mesh(spheres(fe.tx, ant_r), color=rgb("fe_tx"))
    legend += [["front-end Rx antennas", rgb("fe_rx")], ["front-end Tx antennas", rgb("fe_tx")]]

    # virtual targets
    if setup.scene.targets:
        pos, direction = target_positions(setup)
        cone_h = 0.05 * fe.arc_radius_m
        cones = [pv.Cone(center=p + 0.5 * cone_h * d, direction=d, height=cone_h,
                         radius=0.35 * cone_h, resolution=24) for p, d in zip(pos, direction)]
        pl.add_mesh(merge(cones), color=TARGET)
        rays = [np.array([rut.position, p]) for p in pos]
        pl.add_mesh(merge_lines(rays), color=TARGET, opacity=0.35, line_width=1)
        legend.append([f"targets (drawn at {TARGET_RADIUS_FACTOR:g} R_c)", TARGET])

    # propagation paths
    if paths is not None and len(split_paths(paths)[0]):
        los, refl = path_polylines(setup, paths, scale, bounces=True)
        if los:
            pl.add_mesh(merge_lines(los), color=LOS, line_width=2, opacity=0.8)
            legend.append([f"line of sight ({len(los)})", LOS])
        # by bounce count (the last colour: that many or more), the fainter drawn first
        top = len(REFLECTION_BY_BOUNCES)
        groups: dict[int, list] = {}
        for n, polys in refl.items():
            groups.setdefault(min(n, top), []).extend(polys)
        for n in sorted(groups, reverse=True):
            # hundreds of rays (ray tracing: ~1000 off the sheet) drawn faint enough that the
            # elements behind them stay visible; a few stay bold
            k = len(groups[n])
            pl.add_mesh(merge_lines(groups[n]), color=REFLECTION_BY_BOUNCES[n - 1],
                        line_width=2 if k <= 50 else 1,
                        opacity=float(np.clip(30.0 / k, 0.1, 0.8)))
        for n in sorted(groups):
            word = f"{n}{'+' if n == top else ''} bounce{'s' if n > 1 else ''}"
            legend.append([f"reflections, {word} ({len(groups[n])})",
                           REFLECTION_BY_BOUNCES[n - 1]])

    if labels != "none":
        _add_labels(pl, setup, scale, text3d=labels == "3d")
    return legend


#: the most targets labelled in the 3D view; beyond, every k-th in azimuth (the staggered
#: labels of 32 targets rose out of the picture and covered the title)
MAX_TARGET_LABELS = 8


def labelled_targets(setup: Setup) -> list[int]:
    """The indices of the targets the view labels, in azimuth order: all of up to
    :data:`MAX_TARGET_LABELS`, else every k-th (the first and the last included)."""
    order = np.argsort([t.angle_rad for t in setup.scene.targets], kind="stable")
    n = order.size
    if n <= MAX_TARGET_LABELS:
        return [int(j) for j in order]
    keep = np.unique(np.round(np.linspace(0, n - 1, MAX_TARGET_LABELS)).astype(int))
    return [int(order[k]) for k in keep]


def _add_labels(pl, setup: Setup, scale: float, text3d: bool = False) -> None:
    """Text labels with leader lines: FE antennas above/below the cutout, targets staggered.

    Screen-space labels by default; with ``text3d`` flat text meshes facing the overview camera
    (vtk.js, i.e. the HTML export, drops screen-space labels)."""
    rut, fe = setup.rut, setup.fe
    z_hat = np.array([0.0, 0.0, 1.0])
    half_h = 0.5 * setup.scene.sheet.height_m if setup.sheet is not None else 0.1
    lift = min(0.6 * half_h, 0.09)
    anchors, texts, leaders = [], [], []
    for i in range(fe.count):
        for name, p, sign in (("Rx", fe.rx[i], 1.0), ("Tx", fe.tx[i], -1.0)):
            a = p + sign * lift * z_hat
            anchors.append(a)
            texts.append(f"FE{i} {name}")
            leaders.append(np.array([p, a]))
    board_top = board(setup, scale).bounds
    anchors.append(np.array([rut.position[0], rut.position[1], board_top[5] + 0.04]))
    texts.append(f"RuT (x{scale:g})")
    pos = target_positions(setup)[0] if setup.scene.targets else None
    for k, j in enumerate(labelled_targets(setup)):
        t = setup.scene.targets[j]
        p = pos[j]
        a = p + (0.06 + 0.045 * k) * z_hat  # staggered upwards, one level per label
        anchors.append(a)
        leaders.append(np.array([p, a]))
        el = t.elevation_rad
        texts.append(f"T{j}: {t.range_m:.4g} m, {np.degrees(t.angle_rad):.1f} deg"
                     + (f" el {np.degrees(el):.1f} deg" if el else "")
                     + f", {t.velocity_mps:+.3g} m/s")
    pl.add_mesh(merge_lines(leaders), color="#444444", line_width=1)
    if text3d:
        normal = -_overview_direction(setup)  # towards the camera
        up = np.cross(normal, np.cross(z_hat, normal))
        up /= np.linalg.norm(up)
        rot = np.stack([np.cross(up, normal), up, normal], axis=1)  # text (x, y, z) -> world
        size = 0.02 * fe.arc_radius_m
        meshes = []
        for a, t in zip(anchors, texts):
            m = pv.Text3D(t, depth=0.0, height=size)  # in the xy plane, centred on the origin
            m.points = m.points @ rot.T + a + 0.7 * size * up + 2 * size * normal
            meshes.append(m)
        pl.add_mesh(merge(meshes), color="black")
        return
    pl.add_point_labels(np.array(anchors), texts, font_size=14, bold=False, text_color="black",
                        shape_color="white", shape_opacity=0.75, show_points=False,
                        always_visible=True, margin=2)


def _drawn_points(setup: Setup, scale: float) -> np.ndarray:
    """Points spanning what is drawn: the enlarged RuT, the antennas, the sheet, the targets."""
    pts = [board(setup, scale).points, setup.fe.rx, setup.fe.tx]
    if setup.sheet is not None:
        pts.append(setup.sheet.bounds)
    if setup.scene.targets:
        pts.append(target_positions(setup)[0])
    return np.vstack(pts)


def _overview_direction(setup: Setup, elevation_deg: float = 32.0) -> np.ndarray:
    """Viewing direction of the overview: along the RuT's boresight, looking down."""
    boresight = setup.rut.rotation @ np.array([0.0, 1.0, 0.0])
    e = np.radians(elevation_deg)
    return np.cos(e) * boresight - np.sin(e) * np.array([0.0, 0.0, 1.0])


def _set_overview_camera(pl, setup: Setup, scale: float, shift_left: float = 0.0) -> None:
    """Above and behind the RuT, looking along its boresight at the arc, all drawn in view;
    ``shift_left`` moves the picture left by that fraction of the view (room for the legend)."""
    pts = _drawn_points(setup, scale)
    lo, hi = pts.min(0), pts.max(0)
    focal = 0.5 * (lo + hi)
    view = _overview_direction(setup)
    pl.camera_position = [tuple(focal - view), tuple(focal), (0.0, 0.0, 1.0)]
    pl.camera.view_angle = 30.0
    pl.reset_camera(bounds=(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]))
    pl.camera.zoom(1.3)
    pl.camera.SetWindowCenter(2.0 * shift_left, 0.0)


def _add_rut_panel(pl, setup: Setup) -> None:
    """The RuT board at true scale, seen from behind (its x to the right), elements labelled."""
    rut = setup.rut
    lam = rut.wavelength_m
    lateral, boresight = rut.rotation[:, 0], rut.rotation[:, 1]
    pl.set_background(PANEL_BACKGROUND)
    pl.add_mesh(board(setup, 1.0), color=rgb("board"), opacity=0.35)
    pl.add_mesh(spheres(rut.tx_world, 0.3 * lam), color=rgb("rut_tx"))
    pl.add_mesh(spheres(rut.rx_world, 0.3 * lam), color=rgb("rut_rx"))
    active = set(rut.tx_order)
    texts = [f"Tx{i}" + ("" if i in active else " (off)") for i in range(len(rut.tx_world))]
    texts += [f"Rx{k}" for k in range(len(rut.rx_world))]
    # Rx labels alternately above and below: the elements are only lambda/2 apart
    up = np.r_[np.ones(len(rut.tx_world)), np.where(np.arange(len(rut.rx_world)) % 2, -1.0, 1.0)]
    pts = np.vstack([rut.tx_world, rut.rx_world]) - 2e-3 * boresight
    pts[:, 2] += up * 0.9 * lam
    pl.add_point_labels(pts, texts, font_size=12, bold=False, text_color="black",
                        shape_opacity=0.0, show_points=False, always_visible=True)
    pl.add_text(f"RuT at true scale (seen from behind), lambda = {lam * 1e3:.2f} mm",
                position="upper_left", font_size=10, color="black")
    lo = rut.to_local(np.vstack([rut.tx_world, rut.rx_world])).min(0)
    start = rut.position + rut.rotation @ [lo[0], -2e-3, lo[2] - 4 * lam]
    pl.add_mesh(polyline(np.array([start, start + 0.01 * lateral])), color="black", line_width=2)
    pl.add_point_labels((start + 0.005 * lateral - [0.0, 0.0, 0.6 * lam])[None], ["1 cm"],
                        font_size=11, bold=False, text_color="black", shape_opacity=0.0,
                        show_points=False, always_visible=True)
    pl.enable_parallel_projection()
    pl.view_vector(tuple(-boresight), viewup=(0.0, 0.0, 1.0))
    pl.reset_camera()
    pl.camera.zoom(1.1)


def _add_plan_panel(pl, setup: Setup, paths, scale: float, aspect: float) -> None:
    """Top-down view of the same scene, the RuT's boresight up; ``aspect`` of the panel (w/h)."""
    rut = setup.rut
    pl.set_background(PANEL_BACKGROUND)
    _add_setup(pl, setup, paths, scale, labels="none")
    pl.add_text("plan view (top down, RuT boresight up)", position="upper_left", font_size=10,
                color="black")
    local = rut.to_local(_drawn_points(setup, scale))
    lo, hi = local.min(0), local.max(0)
    focal = rut.position + rut.rotation @ (0.5 * (lo + hi))
    pl.camera_position = [tuple(focal + [0.0, 0.0, 10.0]), tuple(focal), tuple(rut.rotation[:, 1])]
    pl.enable_parallel_projection()
    pl.camera.parallel_scale = 0.6 * max(hi[1] - lo[1], (hi[0] - lo[0]) / aspect)
    pl.reset_camera_clipping_range()


def build_plotter(setup: Setup, paths=None, window_size=(1600, 1000), off_screen: bool = True,
                  side_panels: bool = True):
    """A pyvista ``Plotter`` with the overview (and, with ``side_panels``, the true-scale RuT
    and a plan view on the right). The caller shows, screenshots or closes it."""
    if off_screen:
        ensure_render_backend()
    scale = rut_scale_factor(setup)
    kw = dict(off_screen=off_screen, window_size=list(window_size))
    if side_panels:
        pl = pv.Plotter(shape=(2, 3), groups=[(np.s_[:], np.s_[:2])], border=False, **kw)
        pl.subplot(0, 0)
    else:
        pl = pv.Plotter(**kw)
    pl.set_background(BACKGROUND)
    legend = _add_setup(pl, setup, paths, scale, labels="2d" if side_panels else "3d")
    s = setup.scene
    # the title from the geometry drawn, not the scene's description (a copied scene's text
    # kept the template's "1.5 m arc" over a 1.2 m one)
    n = setup.fe.count
    title = (f"{s.name}: {n} front end{'s' if n != 1 else ''} on a "
             f"{s.rts.arc_radius_m:g} m arc, "
             f"{'custom array' if s.radar.array is not None else s.radar.antenna_preset} RuT")
    # user text is plain text: VTK hands "$...$" to matplotlib's mathtext; "\$" keeps a
    # literal dollar (vtkTextRenderer strips the escape before FreeType draws it)
    title = title.replace("$", "\\$")
    pl.add_text(title, position="upper_left", font_size=12, color="black")
    n_t, n_lab = len(s.targets), len(labelled_targets(setup))
    note = (f"RuT drawn x{scale:g} about its phase centre; front-end markers enlarged; "
            f"targets drawn at {TARGET_RADIUS_FACTOR:g} x arc radius"
            + (f" ({n_lab} of {n_t} labelled)" if n_lab < n_t else ""))
    if paths is not None:
        table = split_paths(paths)[0]
        n_refl = int((np.asarray(table.bounces) > 0).sum())
        note += f"; paths: {table.method} ({len(table) - n_refl} direct, {n_refl} reflected)"
        missing = undrawable_reflections(paths)
        if missing:
            msg = (f"{missing} of {n_refl} reflected paths carry no hit points and are not "
                   "drawn (pass the ray-tracing result, paths.raytrace.trace(setup))")
            warn_caller(msg, RtsgeomWarning)
            note += f"; {missing} reflected paths not drawn (no hit points)"
    pl.add_text(note, position="lower_left", font_size=9, color="#333333")
    pl.add_legend(legend, bcolor="white", background_opacity=0.8, border=True,
                  size=(0.25, 0.22 + 0.02 * max(len(legend) - 8, 0)), loc="lower right",
                  face="rectangle")
    pl._rtsgeom_legend = legend  # the HTML export writes it into the page (no screen text there)
    _set_overview_camera(pl, setup, scale, shift_left=0.1 if side_panels else 0.0)
    if side_panels:
        pl.subplot(0, 2)
        _add_rut_panel(pl, setup)
        pl.subplot(1, 2)
        w, h = window_size
        _add_plan_panel(pl, setup, paths, scale, aspect=(w / 3) / (h / 2))
        pl.subplot(0, 0)
    return pl


def _render_image(setup: Setup, paths, window_size, png: bool = False):
    """The setup rendered off screen: the (H, W, 3) uint8 image, or with ``png`` its PNG bytes
    (pyvista's screenshot encoder, Pillow: the view's process needs no matplotlib)."""
    pl = build_plotter(setup, paths, window_size=window_size, off_screen=True)
    try:
        if not png:
            return pl.screenshot(None, return_img=True)
        buf = io.BytesIO()
        pl.screenshot(buf, return_img=False)
        return buf.getvalue()
    finally:
        pl.close()


def setup_png_bytes(setup: Setup, paths=None, window_size=(1600, 1000)) -> bytes:
    """The setup rendered off screen as PNG bytes (what :func:`render_setup_png` writes).

    Parameters
    ----------
    setup : Setup
    paths : Paths, optional
    window_size : (int, int)

    Returns
    -------
    bytes

    Raises
    ------
    VizError
        No off-screen rendering here.
    """
    return _render_image(setup, paths, window_size, png=True)


def render_setup_png(setup: Setup, path: str | Path, paths=None,
                     window_size=(1600, 1000)) -> Path:
    """Render the setup off screen to a PNG file (written atomically); return its path.

    Parameters
    ----------
    setup : Setup
    path : str or Path
    paths : Paths, optional
    window_size : (int, int)

    Returns
    -------
    Path

    Raises
    ------
    VizError
        No off-screen rendering here.
    """
    path = Path(path)
    write_bytes(path, setup_png_bytes(setup, paths, window_size))
    return path


def _html_requirements() -> dict[str, str]:
    """Modules (and their pip names) that pyvista's HTML export needs: pyvista >= 0.49 moved it
    to the trame-pyvista plugin; before, it used trame and trame-vtk directly. Both launch a
    trame server without ``await`` through nest-asyncio(2)."""
    if hasattr(pv.Plotter, "_trame_component"):
        return {"trame_pyvista": "trame-pyvista", "nest_asyncio2": "nest-asyncio2"}
    return {"trame": "trame", "trame_vtk": "trame-vtk", "nest_asyncio": "nest-asyncio"}


class _OfflineWasmNoise:
    """logging filter: drop asyncio's 'Task exception was never retrieved' for network errors
    of trame-vtklocal's background WASM download, which the vtk.js export does not use and
    which fails on offline machines."""

    def filter(self, record) -> bool:
        exc = record.exc_info[1] if record.exc_info else None
        return not (exc is not None and type(exc).__module__.split(".")[0] == "aiohttp")


def _quiet_offline_wasm_download() -> None:
    import logging
    log = logging.getLogger("asyncio")
    if not any(isinstance(f, _OfflineWasmNoise) for f in log.filters):
        log.addFilter(_OfflineWasmNoise())


def export_setup_html(setup: Setup, path: str | Path, paths=None) -> Path:
    """Write an interactive, self-contained (vtk.js) HTML view of the setup; return its path.

    Needs optional packages (with pyvista >= 0.49: ``trame-pyvista`` and ``nest-asyncio2``);
    without them :class:`VizError` names what to install. Screen-space text does not survive
    the export, so the labels are drawn as flat text meshes and the legend is an HTML box;
    the page's title is ``rtsgeom — <scene name>``.
    """
    import importlib.util
    need = _html_requirements()
    missing = [pip for mod, pip in need.items() if importlib.util.find_spec(mod) is None]
    if missing:
        raise VizError(f"HTML export needs the Python packages {', '.join(need.values())} "
                       f"(missing: {', '.join(missing)}); install them with "
                       f"`pip install {' '.join(missing)}`")
    path = Path(path)
    _quiet_offline_wasm_download()
    pl = build_plotter(setup, paths, off_screen=True, side_panels=False)
    try:
        component = getattr(pl, "trame", None)
        buf = component.export_html(None) if component is not None else pl.export_html(None)
        legend = getattr(pl, "_rtsgeom_legend", [])
    finally:
        pl.close()
    write_text(path, _html_page(buf.getvalue(), setup.scene.name, legend))
    return path


def _html_page(page: str, scene_name: str, legend) -> str:
    """The exported page titled ``rtsgeom — <scene>`` (not the viewer's default title) with
    the view's legend as an HTML box (screen-space text does not survive the export)."""
    from matplotlib.colors import to_hex  # matplotlib: only for the HTML page
    name = html.escape(scene_name)
    page = re.sub(r"<title>.*?</title>", lambda m: f"<title>rtsgeom — {name}</title>", page,
                  count=1, flags=re.S)
    rows = "".join(f'<div><span style="display:inline-block;width:12px;height:12px;'
                   f'margin-right:6px;background:{to_hex(colour)}"></span>'
                   f"{html.escape(text)}</div>" for text, colour in legend)
    box = (f'<div id="rtsgeom-legend" style="position:fixed;top:8px;right:8px;z-index:10;'
           f'background:rgba(255,255,255,0.85);border:1px solid #888;padding:6px 8px;'
           f'font:12px sans-serif"><b>rtsgeom — {name}</b>{rows}</div>')
    return re.sub(r"<body([^>]*)>", lambda m: m.group(0) + box, page, count=1)


def show_setup(setup: Setup, paths=None, interactive: bool = True, window_size=(1600, 1000)):
    """Open an interactive window (needs a display: ``DISPLAY`` must be set).

    With ``interactive=False`` render off screen and return the image, (H, W, 3) uint8.
    """
    if not interactive:
        return _render_image(setup, paths, window_size)
    if not os.environ.get("DISPLAY"):
        raise VizError("no display (DISPLAY is not set): write a file with --png or --html")
    pl = build_plotter(setup, paths, window_size=window_size, off_screen=False)
    pl.show()
    return None
