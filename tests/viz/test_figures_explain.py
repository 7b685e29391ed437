"""The figures explain themselves: design maps draw no contour lines through noise and claim
hatching only where a cell is hatched, count maps have whole-number axes and values in their
cells, the 3D view's reflections are grouped by bounce count, its HTML page is titled and
carries the legend."""

from __future__ import annotations

import numpy as np
from matplotlib.contour import ContourSet

from rtsgeom.viz import figures as F


def _contours(fig):
    return [c for c in fig.axes[0].collections if isinstance(c, ContourSet)]


def test_no_contour_lines_below_the_meaningful_level():
    x, y = np.linspace(0.5, 2, 14), np.linspace(2, 10, 12)  # > ANNOTATE_CELLS: contours
    noise = 1e-5 * np.random.default_rng(0).random((12, 14))
    fig = F.design_heatmap_figure(x, y, noise, "R", "s", "deg", "t", contour_floor=1e-3)
    assert not _contours(fig)
    mesh = fig.axes[0].collections[0]
    assert mesh.norm.vmin == 0.0 and mesh.norm.vmax == 1e-3  # not the noise's range
    real = np.outer(y, 1 / x) * 1e-2
    fig = F.design_heatmap_figure(x, y, real, "R", "s", "deg", "t", contour_floor=1e-3)
    (cs,) = _contours(fig)
    assert min(cs.levels) >= 1e-3 and len(cs.levels) >= 2


def test_small_count_maps_write_whole_numbers_in_their_cells():
    z = np.array([[3.0, 3.0, 4.0], [4.0, 4.0, 5.0]])
    fig = F.design_heatmap_figure([0.5, 1.0, 1.5], [0, 1], z, "R", "extra", "front ends", "t",
                                  integer_y=True, integer_z=True)
    ax = fig.axes[0]
    assert sorted(t.get_text() for t in ax.texts) == sorted(f"{v:.0f}" for v in z.ravel())
    assert [t.get_text() for t in ax.get_yticklabels()] == ["0", "1"]
    bar = fig.axes[1]
    ticks = [float(t) for t in bar.get_yticks() if 3 <= t <= 5]
    assert ticks and all(t == int(t) for t in ticks)


def test_the_hatch_legend_only_where_a_cell_is_hatched():
    x, y, z = [0.5, 1.0], [4.0, 20.0], np.ones((2, 2))
    plain = F.design_heatmap_figure(x, y, z, "R", "s", "deg", "t")
    assert plain.axes[0].get_legend() is None
    mask = np.array([[False, False], [True, True]])
    hatched = F.design_heatmap_figure(x, y, z, "R", "s", "deg", "t", mask=mask)
    assert [t.get_text() for t in hatched.axes[0].get_legend().get_texts()] == ["excluded"]


def test_design_title_names_scene_pair_spec_and_hatching_only_when_true():
    from analysis.test_results import _design
    grid = _design()
    title = grid.plot("worst_error_deg").axes[0].get_title()
    assert title.startswith("unit: ") and "pair (0, 1)" in title and "spec 0.1 deg" in title
    assert "hatched" not in title  # nothing exceeds the resolution in this grid


def test_html_page_is_titled_and_carries_the_legend():
    from rtsgeom.viz.scene3d import _html_page
    page = ("<html><head><title>VTK.js | Example - OfflineLocalView</title></head>"
            "<body class='x'><div id='app'></div></body></html>")
    out = _html_page(page, "my <scene>", [["line of sight (3)", "#00a6c8"],
                                          ["RuT Tx", (1.0, 0.0, 0.0)]])
    assert "<title>rtsgeom — my &lt;scene&gt;</title>" in out and "VTK.js" not in out
    legend = out[out.index("<body class='x'>"):]
    assert legend.index("rtsgeom-legend") < legend.index("id='app'")
    assert "line of sight (3)" in legend and "#ff0000" in legend


def test_reflections_are_grouped_by_bounce_count():
    from types import SimpleNamespace

    from conftest import DEFAULT_SCENE

    from rtsgeom.geometry import build_setup
    from rtsgeom.scene import load_scene
    from rtsgeom.viz.meshes import path_polylines
    setup = build_setup(load_scene(DEFAULT_SCENE))
    bounces = np.array([0, 1, 2, 1, 3])
    class Table(SimpleNamespace):
        def __len__(self):
            return len(self.bounces)

    table = Table(direction=np.full(5, 0), front_end=np.zeros(5, int),
                            rut_tx=np.zeros(5, int), rut_rx=np.zeros(5, int), bounces=bounces)
    from rtsgeom.viz import meshes
    table.direction[:] = meshes.TX_TO_FE
    hits = [np.full((3, 3), np.nan)] + [np.array([[0.1 * k, 0.5, 0.0]] * k + [[np.nan] * 3])
                                        for k in bounces[1:]]
    res = SimpleNamespace(paths=table, vertices=hits)
    los, by = path_polylines(setup, res, 1.0, bounces=True)
    assert len(los) == 1 and {n: len(p) for n, p in by.items()} == {1: 2, 2: 1, 3: 1}
    los2, flat = path_polylines(setup, res, 1.0)
    assert len(flat) == 4
