"""Visualisation: the 3D setup view, the result figures and the HTML report.

Images are checked for content (not blank, the requested size), the report for being one
self-contained file (no scripts, no links out, every image embedded) that a browser can load.
"""

from __future__ import annotations

import dataclasses
import importlib.util
import shutil
import subprocess
import sys
from html.parser import HTMLParser

import numpy as np
import pytest
from matplotlib.image import imread

from rtsgeom.cli import main
from rtsgeom.geometry import build_setup
from rtsgeom.pipeline.info import scene_info
from rtsgeom.paths import Paths, exact_paths
from rtsgeom.paths.table import FE_TO_RX, TX_TO_FE
from rtsgeom.viz import figures as F
from rtsgeom.viz.report import write_report
from rtsgeom.viz.meshes import path_polylines
from rtsgeom.viz.scene3d import _html_requirements, render_setup_png, rut_scale_factor

from conftest import DEFAULT_SCENE, make_scene


def _png_stats(path, background=None):
    """(height, width), number of distinct colours, fraction of non-background pixels."""
    img = imread(path)
    rgb = np.round(img[..., :3] * 255).astype(np.uint8)
    flat = rgb.reshape(-1, 3)
    colours, counts = np.unique(flat, axis=0, return_counts=True)
    bg = colours[np.argmax(counts)] if background is None else np.asarray(background)
    non_bg = np.any(np.abs(flat.astype(int) - bg) > 8, axis=1).mean()
    return img.shape[:2], len(colours), float(non_bg)


# --------------------------------------------------------------------------------------------
# 3D view
# --------------------------------------------------------------------------------------------


def test_show_writes_a_png_that_shows_the_setup(tmp_path, capsys):
    out = tmp_path / "setup.png"
    assert main(["show", str(DEFAULT_SCENE), "--png", str(out), "--paths", "exact"]) == 0
    assert f"wrote {out}" in capsys.readouterr().out
    shape, n_colours, non_bg = _png_stats(out)
    assert shape == (1000, 1600)  # the default window size
    assert n_colours > 500  # shaded sheet, board, markers, lines, text
    assert non_bg > 0.1
    assert not list(tmp_path.glob("*.part*"))  # atomic write left nothing behind


def test_show_needs_an_output_without_a_display(tmp_path, monkeypatch, capsys):
    monkeypatch.delenv("DISPLAY", raising=False)
    assert main(["show", str(DEFAULT_SCENE), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "--png" in err and "DISPLAY" in err


def test_reflections_are_drawn_only_with_vertices():
    setup = build_setup(make_scene())
    fe = setup.fe

    @dataclasses.dataclass(frozen=True)
    class PathsWithVertices(Paths):
        vertices: tuple = ()

    base = dict(front_end=[0, 0, 1, 1], direction=[TX_TO_FE, TX_TO_FE, FE_TO_RX, FE_TO_RX],
                rut_tx=[0, 0, -1, -1], rut_rx=[-1, -1, 2, 2], delay_s=[3.3e-9, 4e-9, 3.3e-9, 5e-9],
                gain=[1e-3, 1e-4, 1e-3, 1e-4], bounces=[0, 1, 0, 2])
    plain = Paths.build(**base)
    los, refl = path_polylines(setup, plain, scale=1.0)
    assert len(los) == 2 and refl == []  # reflections without vertices cannot be drawn ...
    from rtsgeom.viz.scene3d import undrawable_reflections
    assert undrawable_reflections(plain) == 2  # ... but are counted (and noted in the view)

    bounce = fe.module[1] + [0.0, 0.3, 0.0]
    with_v = PathsWithVertices(*dataclasses.astuple(plain),
                               vertices=(None, np.array([[0.1, 0.5, 0.0]]), None,
                                         np.array([bounce, [0.0, 0.5, 0.1]])))
    los, refl = path_polylines(setup, with_v, scale=1.0)
    assert len(los) == 2 and [len(p) for p in refl] == [3, 4]
    assert np.allclose(los[0], [setup.rut.tx_world[0], fe.rx[0]])
    assert np.allclose(refl[1][0], fe.tx[1]) and np.allclose(refl[1][-1], setup.rut.rx_world[2])
    assert undrawable_reflections(with_v) == 0
    # NaN rows past the last interaction (Sionna's layout) are dropped, not drawn to NaN
    nan_v = PathsWithVertices(*dataclasses.astuple(plain),
                              vertices=np.array([[[np.nan] * 3] * 2, [[0.1, 0.5, 0.0], [np.nan] * 3],
                                                 [[np.nan] * 3] * 2, [bounce, [0.0, 0.5, 0.1]]]))
    los, refl = path_polylines(setup, nan_v, scale=1.0)
    assert [len(p) for p in refl] == [3, 4] and all(np.isfinite(p).all() for p in refl)


def test_plain_table_with_reflections_warns_in_the_view():
    """A reflected path that cannot be drawn is never dropped silently."""
    from rtsgeom.viz.scene3d import build_plotter
    setup = build_setup(make_scene())
    p = exact_paths(setup)
    refl = Paths.build(p.front_end[:3], p.direction[:3], p.rut_tx[:3], p.rut_rx[:3],
                       p.delay_s[:3] * 1.1, p.gain[:3], bounces=[1, 1, 1])
    with pytest.warns(UserWarning, match="3 of 3 reflected paths"):
        build_plotter(setup, Paths.concat([p, refl]), window_size=(320, 200)).close()


@pytest.mark.raytrace
def test_show_raytrace_draws_every_reflection(tmp_path):
    """``show --paths raytrace`` draws the reflections too (it used to draw only the
    line-of-sight rays)."""
    from rtsgeom.paths import raytrace
    ok, msg = raytrace.preflight()
    if not ok:
        pytest.skip(f"Sionna RT unavailable: {msg}")
    setup = build_setup(make_scene())
    res = raytrace.trace(setup)
    n_refl = int((res.paths.bounces > 0).sum())
    assert n_refl > 100  # the sheet and the board reflect
    los, refl = path_polylines(setup, res, scale=1.0)
    assert len(refl) == n_refl
    for i, poly in zip(np.flatnonzero(res.paths.bounces > 0)[:50], refl):
        assert len(res.hit_points(i)) == res.paths.bounces[i]
        assert np.isfinite(poly).all() and len(poly) >= 2 + res.paths.bounces[i] - 1
    # the CLI draws them: more reflection-coloured pixels than with exact paths
    from rtsgeom.viz.meshes import REFLECTION
    counts = {}
    for method in ("exact", "raytrace"):
        out = tmp_path / f"{method}.png"
        assert main(["show", str(DEFAULT_SCENE), "--png", str(out), "--paths", method,
                     "--size", "800x500", "--quiet"]) == 0
        rgb = np.round(imread(out)[..., :3] * 255).astype(int)
        target = np.array(_rgb_of(REFLECTION))
        counts[method] = int((np.abs(rgb - target).max(axis=-1) <= 40).sum())
    assert counts["raytrace"] > counts["exact"] + 200


def _rgb_of(colour):
    from matplotlib.colors import to_rgb
    return [round(255 * x) for x in to_rgb(colour)]


def test_render_variants_without_sheet_or_targets(tmp_path):
    def mutate(doc):
        doc["sheet"]["enabled"] = False
        doc["targets"] = []
        doc["radar"]["yaw_deg"] = 5.0
        doc["rts"]["front_ends"] = doc["rts"]["front_ends"][:1]

    setup = build_setup(make_scene(mutate))
    assert rut_scale_factor(setup) in (1, 2, 5, 10, 20, 50)
    out = render_setup_png(setup, tmp_path / "bare.png", paths=exact_paths(setup),
                           window_size=(640, 400))
    shape, n_colours, non_bg = _png_stats(out)
    assert shape == (400, 640) and n_colours > 100 and non_bg > 0.02


_HTML_NEEDS = _html_requirements()
_HTML_DEPS = all(importlib.util.find_spec(m) for m in _HTML_NEEDS)


@pytest.mark.subprocess
@pytest.mark.skipif(not _HTML_DEPS, reason="HTML export needs " + ", ".join(_HTML_NEEDS.values()))
def test_show_writes_interactive_html(tmp_path):
    out = tmp_path / "setup.html"
    # a subprocess: the trame server and nest-asyncio2 patch asyncio for the whole process
    run = subprocess.run([sys.executable, "-m", "rtsgeom", "show", str(DEFAULT_SCENE), "--html",
                          str(out), "--quiet"], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    text = out.read_text()
    assert text.lstrip().lower().startswith("<!doctype html") and len(text) > 100_000


@pytest.mark.skipif(_HTML_DEPS, reason="the HTML export packages are installed")
def test_html_export_names_the_missing_packages(tmp_path, capsys):
    assert main(["show", str(DEFAULT_SCENE), "--html", str(tmp_path / "s.html")]) == 2
    err = capsys.readouterr().err
    assert all(pip in err for pip in _HTML_NEEDS.values())
    assert not (tmp_path / "s.html").exists()


# --------------------------------------------------------------------------------------------
# Figures
# --------------------------------------------------------------------------------------------


def _figures():
    rng = np.random.default_rng(8)
    r, v, a = np.linspace(0, 77, 128), np.linspace(-9.7, 9.7, 64), np.linspace(-60, 60, 61)
    rd = -100 + 3 * rng.standard_normal((r.size, v.size))
    rd[55, 32] = -30
    ra = -90 + 3 * rng.standard_normal((r.size, a.size))
    ra[55, 34] = -35
    tau = np.arange(-0.5e-9, 1.0e-9 + 1e-15, 25e-12)
    s = np.linspace(3.4, 12.2, 12)
    return {
        "range_doppler": F.range_doppler_figure(rd, r, v, detections=[[33.5, 0.0]], title="rd"),
        "range_angle": F.range_angle_figure(ra, r, a, detections=[[33.5, 7.2]],
                                            set_points=[[33.5, 7.0]]),
        "calibration": F.calibration_sweep_figure(tau, np.abs(np.sin(np.pi * (tau - 2e-10) / 1e-9)),
                                                  2e-10, period_s=1e-9,
                                                  residual_error_deg=0.001),
        "linearity": F.linearity_figure(s, {"paper": s + 0.2 * np.sin(s), "exact": s + 0.01},
                                        {"paper": np.stack([-(s - 3.4), -(12.2 - s)]),
                                         "exact": np.stack([-(s - 3.4), -(12.2 - s)]) / 2}),
        "linearity_no_amplitude": F.linearity_figure(s, {"exact": s}),
        "tolerance": F.tolerance_histogram_figure({"1 mm": 0.2 * rng.standard_normal(400),
                                                   "2 mm": 0.4 * rng.standard_normal(400)},
                                                  spec_deg=0.5),
        "design": F.design_heatmap_figure(np.linspace(0.5, 3, 6), np.linspace(2, 20, 5),
                                          rng.random((5, 6)), "arc radius (m)",
                                          "front-end spacing (deg)", "worst error (deg)", "design",
                                          mask=np.eye(5, 6, dtype=bool)),
    }


def test_each_figure_saves_a_nonempty_png_without_pyplot(tmp_path):
    import matplotlib.pyplot as plt
    before = plt.get_fignums()
    for name, fig in _figures().items():
        out = F.save_figure(fig, tmp_path / f"{name}.png")
        shape, n_colours, non_bg = _png_stats(out, background=(255, 255, 255))
        assert shape[0] > 300 and shape[1] > 600, name
        assert n_colours > 50 and non_bg > 0.05, name
    assert plt.get_fignums() == before  # no figure leaked into pyplot's global state
    assert not list(tmp_path.glob("*.part*"))


def test_a_figure_drawn_once_has_savefigs_bytes():
    """print_png draws a constrained-layout figure once, savefig twice: the same PNG bytes."""
    import io

    import matplotlib as mpl
    once, twice = _figures(), _figures()
    for name in once:
        a, b = io.BytesIO(), io.BytesIO()
        F.print_png(once[name], a)
        with mpl.rc_context(F.STYLE):
            twice[name].savefig(b, format="png", dpi=F.DPI)
        assert a.getvalue() == b.getvalue(), name


def test_figure_inputs_are_checked():
    r, v = np.arange(4.0), np.arange(3.0)
    with pytest.raises(ValueError, match=r"power_db must have shape \(4, 3\)"):
        F.range_doppler_figure(np.zeros((3, 4)), r, v)
    with pytest.raises(ValueError, match="detections"):
        F.range_doppler_figure(np.zeros((4, 3)), r, v, detections=[1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match=r"amplitude_db_by_mode\['paper'\]"):
        F.linearity_figure(r, {"paper": r}, {"paper": r})


def _legend_entries_without_artist(fig):
    """Legend labels whose handle draws nothing (no data, no visible line)."""
    bad = []
    for ax in fig.axes:
        leg = ax.get_legend()
        if leg is None:
            continue
        for h, t in zip(leg.legend_handles, leg.get_texts()):
            label = t.get_text()
            owners = [a for a in ax.get_children() if getattr(a, "get_label", lambda: "")()
                      == label and a is not h]
            if not owners:
                bad.append(label)
                continue
            a = owners[0]
            if hasattr(a, "get_xdata") and not np.size(a.get_xdata()):
                bad.append(label)
    return bad


def test_calibration_figure_shows_the_residual_of_the_json_and_no_empty_legend_entry():
    """The plot quotes the JSON's residual, which comes from the refinement (it used to quote
    the sweep interpolated at the chosen delay: 0.008 deg against the JSON's 0.0048 deg), and
    the legend lists 'chosen + k periods' only when such a line falls inside the sweep."""
    tau = np.arange(-0.4e-9, 0.4e-9 + 1e-15, 50e-12)  # less than one period: no repeat line
    err = np.abs(np.sin(np.pi * (tau - 0.21e-9) / 1e-9))
    for residual in (0.0048, 0.0123, 1e-5):
        fig = F.calibration_sweep_figure(tau, err, 0.2137e-9, period_s=1e-9,
                                         residual_error_deg=residual,
                                         refine_delta_tau_s=[0.2e-9, 0.2137e-9],
                                         refine_error_deg=[0.03, residual])
        labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
        chosen = [lab for lab in labels if lab.startswith("chosen:")]
        assert chosen and f"{residual:.4f} deg" in chosen[0], labels
        assert not any("periods" in lab for lab in labels), labels
        assert _legend_entries_without_artist(fig) == []
    # a sweep over two periods draws the repeat lines, and then lists them
    tau = np.arange(-1.2e-9, 1.2e-9 + 1e-15, 50e-12)
    fig = F.calibration_sweep_figure(tau, np.abs(np.sin(np.pi * tau / 1e-9)), 0.0, 1e-9,
                                     residual_error_deg=None)
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert any("periods" in lab for lab in labels)
    assert _legend_entries_without_artist(fig) == []


def test_linearity_figure_numbers_channels_like_the_cli():
    """The plot numbers channels as the CLI's --pair does (it used to say channel 1/2 for
    --pair 0 1)."""
    s = np.linspace(3.4, 12.2, 5)
    for pair in ((0, 1), (2, 3)):
        fig = F.linearity_figure(s, {"exact": s}, {"exact": np.stack([-s, s])}, pair=pair)
        labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
        assert labels == [f"exact: front end {pair[0]}", f"exact: front end {pair[1]}"]


def test_tolerance_figure_resolves_both_cases():
    """A common-bin histogram put the calibrated case (errors ~1e-3 deg)
    into one bin next to the uncalibrated one (~1 deg). The empirical CDF resolves both."""
    rng = np.random.default_rng(0)
    for scale_unc, scale_cal in ((1.0, 1e-3), (0.3, 1e-2), (5.0, 1e-4)):
        cases = {"uncalibrated": scale_unc * rng.standard_normal(2000),
                 "calibrated": scale_cal * rng.standard_normal(2000)}
        fig = F.tolerance_cdf_figure(cases, spec_deg=0.1)
        lines = [ln for ln in fig.axes[0].get_lines() if len(ln.get_xdata()) > 100]
        assert len(lines) == 2
        for ln, a in zip(lines, cases.values()):
            x, y = np.asarray(ln.get_xdata()), np.asarray(ln.get_ydata())
            # the curve climbs over the case's own range: >= 50 distinct steps below its p99
            assert np.unique(y[x <= np.percentile(np.abs(a), 99)]).size > 50
            np.testing.assert_allclose(np.interp(np.median(np.abs(a)), x, y), 0.5, atol=0.02)


def test_design_with_one_radius_draws_lines_and_says_the_sheet_is_off(tmp_path, capsys,
                                                                      monkeypatch):
    """With one radius (``--radius-m 0.5:0.5:1``) the five figures are drawn as lines (they
    used to be empty heat maps), and the output says that the sheet is disabled at small
    spacings (that used to be only in the JSON)."""
    saved = {}

    def record(fig, path):
        saved[path.name] = fig
        return path
    monkeypatch.setattr(F, "save_figure", record)
    assert main(["design", str(DEFAULT_SCENE), "--radius-m", "0.5:0.5:1", "--spacing-deg",
                 "1:8:2", "--draws", "20", "--out", str(tmp_path), "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "sheet disabled" in out and "note: sheet disabled in 1 of 2 designs" in out
    pngs = [n for n in saved if n.startswith("design_")]
    assert len(pngs) == 5
    for name in pngs:
        ax = saved[name].axes[0]
        data = [np.asarray(ln.get_ydata(), float) for ln in ax.get_lines()]
        assert sum(np.isfinite(d).sum() for d in data) >= 2, name  # a visible line
    # JSON mode keeps stdout machine-readable and says it on stderr
    assert main(["design", str(DEFAULT_SCENE), "--radius-m", "0.5:0.5:1", "--spacing-deg",
                 "1:1:1", "--draws", "20", "--json"]) == 0
    cap = capsys.readouterr()
    import json
    assert json.loads(cap.out)["designs"][0]["sheet"] == "disabled"
    assert "sheet disabled" in cap.err


@pytest.mark.parametrize("name", [r"$\undefinedcmd{x}$", "cost $5 and $", r"a_b^c $\frac{1}$"])
def test_user_text_in_titles_never_crashes_a_figure(tmp_path, name):
    """A scene name with TeX in it crashes no figure (it used to crash every one)."""
    r, v = np.arange(4.0), np.arange(3.0)
    fig = F.range_doppler_figure(np.zeros((4, 3)), r, v, title=f"{name}: range-Doppler map")
    F.save_figure(fig, tmp_path / "rd.png")
    assert fig.axes[0].get_title() == f"{name}: range-Doppler map"
    # a title made outside figures.py (analysis modules set their own) is caught on saving
    fig = F.range_doppler_figure(np.zeros((4, 3)), r, v)
    fig.suptitle(name)
    F.save_figure(fig, tmp_path / "rd2.png")
    # the whole run with such a scene name writes its figures
    scene = make_scene(lambda doc: doc.__setitem__("name", name))
    from rtsgeom.pipeline.output import write_maps
    from rtsgeom.pipeline.run import run_scene
    paths = write_maps(run_scene(scene, aoa_mode="nearest"), tmp_path)
    assert all(p.stat().st_size > 1000 for p in paths)


def test_user_text_in_the_3d_title_is_plain(tmp_path, capfd):
    """VTK hands "$...$" to matplotlib's mathtext: a TeX scene name is drawn literally."""
    scene = make_scene(lambda doc: doc.__setitem__("name", r"$\undefinedcmd{x}$"))
    render_setup_png(build_setup(scene), tmp_path / "s.png", window_size=(320, 200))
    assert "MathText" not in capfd.readouterr().err


# --------------------------------------------------------------------------------------------
# Report
# --------------------------------------------------------------------------------------------

_VOID = {"meta", "img", "br", "hr", "link", "input", "col", "area", "base", "wbr", "source"}


class _TagChecker(HTMLParser):
    """Collects tags and checks that every non-void element is closed in order."""

    def __init__(self):
        super().__init__()
        self.stack, self.errors, self.tags = [], [], []

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))
        if tag not in _VOID:
            self.stack.append(tag)

    def handle_endtag(self, tag):
        if not self.stack or self.stack.pop() != tag:
            self.errors.append(f"unexpected </{tag}>")


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("report")
    setup = build_setup(make_scene())
    png = F.save_figure(_figures()["calibration"], tmp / "cal.png")
    sections = [
        {"heading": "Calibration <sweep>", "text": "First & only.\n\n<script>alert(1)</script>",
         "images": [png, png.read_bytes()], "warnings": ["spacing > resolution"]},
        {"heading": "Numbers", "table": {"columns": ["case", "error (deg)"],
                                         "rows": [["a", 0.125], ["b", np.float64(1.5)]]}},
    ]
    path = write_report(tmp / "report.html", "rtsgeom <test>", scene_info(setup), sections)
    return path, path.read_text(encoding="utf-8")


def test_report_is_self_contained_and_escaped(report):
    _, text = report
    checker = _TagChecker()
    checker.feed(text)
    assert checker.errors == [] and checker.stack == []
    imgs = [a for t, a in checker.tags if t == "img"]
    assert len(imgs) == 2 and all(a["src"].startswith("data:image/png;base64,") for a in imgs)
    assert 'src="http' not in text and "href=" not in text and "<script" not in text
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in text and "rtsgeom &lt;test&gt;" in text
    # the scene summary: radar, far field, RTS and the front ends as tables
    for part in ("Radar under test", "Far field", "Radar target simulator", "Front ends"):
        assert part in text
    assert "77 GHz" in text and "arc angle (deg)" in text and "arc_angle" not in text and "spacing &gt; resolution" in text


def test_report_rejects_non_png_images(tmp_path):
    with pytest.raises(ValueError, match="not a PNG"):
        write_report(tmp_path / "r.html", "t", {}, [{"heading": "h", "images": [b"GIF89a"]}])
    assert not (tmp_path / "r.html").exists()


_CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")


@pytest.mark.skipif(_CHROMIUM is None, reason="Chromium (chromium or chromium-browser) is not on "
                                               "PATH: the report is not loaded in a browser")
@pytest.mark.subprocess
def test_report_loads_in_headless_chromium(report, tmp_path):
    path, _ = report
    shot = tmp_path / "shot.png"
    run = subprocess.run([_CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu",
                          "--disable-background-networking", "--disable-component-update",
                          "--disable-sync", "--no-first-run", f"--user-data-dir={tmp_path / 'u'}",
                          f"--screenshot={shot}", "--window-size=1200,2000",
                          path.resolve().as_uri()],
                         capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, run.stderr
    assert shot.is_file() and shot.stat().st_size > 10_000


@pytest.mark.parametrize("n", [0, 1, 7, 8, 9, 16, 32, 100])
def test_the_view_labels_all_targets_up_to_eight_else_every_kth_in_azimuth(n):
    """Up to MAX_TARGET_LABELS targets all labelled in azimuth order; more: that many, spread
    evenly over the azimuth order with the outermost two included, no target twice."""
    from types import SimpleNamespace

    from rtsgeom.viz.scene3d import MAX_TARGET_LABELS, labelled_targets
    rng = np.random.default_rng(n)
    angles = rng.permutation(np.linspace(-0.5, 0.5, n))
    setup = SimpleNamespace(scene=SimpleNamespace(
        targets=[SimpleNamespace(angle_rad=a) for a in angles]))
    got = labelled_targets(setup)
    order = list(np.argsort(angles))
    assert MAX_TARGET_LABELS == 8
    if n <= 8:
        assert got == order
        return
    assert len(got) == 8 == len(set(got))
    ranks = [order.index(j) for j in got]
    assert ranks == sorted(ranks) and ranks[0] == 0 and ranks[-1] == n - 1
    assert np.ptp(np.diff(ranks)) <= 1  # evenly spread: gaps differ by one at most


@pytest.mark.parametrize("title, lines", [("lab: range-Doppler map", 1),
                                          ("x" * 30 + " " + "y" * 40 + " (ADC CLIPPED: 12 samples)", 3)])
def test_a_power_maps_long_title_wraps_and_the_axes_make_room_for_it(title, lines):
    """The maps' margins are fixed: a title over 60 characters is wrapped at spaces and the
    axes' top comes down 0.04 of the figure per extra line, so no line is cut at an edge."""
    r, v = np.linspace(0, 50, 8), np.linspace(-5, 5, 6)
    fig = F.range_doppler_figure(np.zeros((8, 6)), r, v, title=title)
    ax = fig.axes[0]
    shown = ax.get_title()
    assert shown.count("\n") == lines - 1 and shown.replace("\n", " ") == title
    assert max(len(s) for s in shown.split("\n")) <= 60
    assert ax.get_position().y1 == pytest.approx(0.93 - 0.04 * (lines - 1))
    fig.canvas.draw()
    title_box = ax.title.get_window_extent()
    width, height = fig.canvas.get_width_height()
    assert 0 <= title_box.x0 and title_box.x1 <= width and title_box.y1 <= height


def test_a_title_of_any_length_keeps_the_maps_axes_and_no_lines_drawn_is_an_empty_mesh():
    """A scene name of 2000 characters: at most four title lines (the rest elided), the axes
    keep their place instead of subplots_adjust refusing a top under the bottom; merging no
    polylines (a sheet without cutouts has no rims) is an empty mesh, not an error."""
    from rtsgeom.viz.meshes import merge_lines
    fig = F.range_doppler_figure(np.zeros((8, 6)), np.linspace(0, 50, 8),
                                 np.linspace(-5, 5, 6), title="lab " * 500)
    shown = fig.axes[0].get_title()
    assert shown.count("\n") == 3 and shown.endswith(" ...")
    assert fig.axes[0].get_position().y1 == pytest.approx(0.93 - 0.04 * 3)
    assert merge_lines([]).n_points == 0


@pytest.mark.parametrize("pairs", [2, 3, 8])
def test_the_sweeps_legend_and_a_long_title_stay_on_the_figure(pairs):
    """All four legend entries (periods drawn) in one row inside the figure, and a long title
    wrapped onto two lines inside it, for two panels (the narrowest figure) and more."""
    from rtsgeom.viz.sweeps import calibration_sweeps_figure
    t = np.linspace(-1e-9, 1e-9, 21)
    sweeps = [{"label": f"{k}-{k + 1}", "delta_tau_s": t, "angle_error_deg": 20 * np.sin(3e9 * t + k),
               "chosen_delta_tau_s": 0.0, "residual_error_deg": 0.01, "period_s": 0.6e-9}
              for k in range(pairs)]
    fig = calibration_sweeps_figure(sweeps, title="a-rather-long-lab-scene-name: phase "
                                    "coherency calibration of the front-end pairs " * 2)
    fig.canvas.draw()
    width, height = fig.canvas.get_width_height()
    legend = fig.legends[0]
    assert len(legend.get_texts()) == 4
    box = legend.get_window_extent()
    assert 0 <= box.x0 and box.x1 <= width
    title = fig._suptitle  # noqa: SLF001
    assert title.get_text().count("\n") == 1
    tb = title.get_window_extent()
    assert 0 <= tb.x0 and tb.x1 <= width and tb.y1 <= height
