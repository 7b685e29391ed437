"""The datasheet's HTML page and the PDF's text page (rtsgeom.analysis.kpi.report) in full, on
a datasheet made here (its JSON the headline test's): every heading, table, paragraph and the
inline style of the page as literal text, the figures' PNGs at the page's resolution, and
every line of the text page in order, inside the page."""

from __future__ import annotations

import base64
import io
import re
from types import SimpleNamespace

import matplotlib
import pytest

matplotlib.use("Agg")
from analysis.test_kpi_headline import ROWS, SHEET  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from rtsgeom.analysis.kpi.report import _text_page, to_html, write_pdf  # noqa: E402

CSS = ("body{font-family:sans-serif;max-width:1000px;margin:1em auto;color:#222}"
       "table{border-collapse:collapse;margin:0.5em 0}td,th{border:1px solid #bbb;"
       "padding:2px 6px;font-size:90%;text-align:left}tr.fail td{background:#fdd}"
       "img{max-width:100%}h2{border-bottom:1px solid #ccc}")


def _row(q, u, unit, dist, s, contrib):
    return SimpleNamespace(quantity=q, standard_uncertainty=u, unit=unit, distribution=dist,
                           sensitivity=s, contribution_deg=contrib)


def _point(set_deg, acc, budget):
    return SimpleNamespace(set_deg=set_deg, pair=(0, 1), accuracy_deg=acc, combined_deg=acc / 3,
                           expanded_deg=acc / 1.5, mc_interval_deg=(-acc, acc / 2),
                           budget=budget)


def _sheet(spec, passed, checks, accuracy):
    return SimpleNamespace(
        scene_name="a<b", spec=spec, passed=passed, checks=checks, accuracy=accuracy,
        to_dict=lambda: SHEET, elapsed_s=12.345, inputs={"points": 3, "sigma_mm": [0.1, 0.2]},
        range_velocity={"limits": {"air_path_m": 1.0, "fir_latency_m": 0.59958,
                                   "processing_max_range_m": 75.625,
                                   "buffer_note": "no buffer & no limit"}})


CHECKS = [SimpleNamespace(kpi="angle_accuracy_deg", value=0.2, limit=0.1, margin=-0.1,
                          passed=False, note="n1"),
          SimpleNamespace(kpi="min_range_m", value=1.6, limit=2.0, margin=0.4, passed=True,
                          note="n2"),
          SimpleNamespace(kpi="resolution_deg", value=None, limit=12.0, margin=None,
                          passed=None, note="no value here")]
POINTS = [_point(5.0, 0.25, [_row("a", 1.0, "mm", "normal", 0.5, 0.5)]),
          _point(7.5, 0.75, [_row("radial offset", 0.1, "mm", "normal", 2.0, 0.2),
                             _row("delay <q>", 3.0, "ps", "rectangular", 0.01, 0.03)])]
HEAD = ("<h2>Key figures</h2><table><tr><th>KPI</th><th>value</th></tr>"
        + "".join(f"<tr><td>{n}</td><td>{v}</td></tr>" for n, v in ROWS)
        .replace("'", "&#x27;") + "</table>")
TAIL = ("<h2>Range and velocity limits</h2><table><tr><th>limit</th><th>value</th></tr>"
        "<tr><td>air path (m)</td><td>1</td></tr><tr><td>FIR latency (m)</td><td>0.5996</td>"
        "</tr><tr><td>processing&#x27;s largest range (m)</td><td>75.62</td></tr>"
        "<tr><td>buffer</td><td>no buffer &amp; no limit</td></tr></table>"
        "<p>Inputs: {&#x27;points&#x27;: 3, &#x27;sigma_mm&#x27;: [0.1, 0.2]}. Computed in "
        "12.3 s by rtsgeom kpi.</p></body></html>")
TOP = ("<!DOCTYPE html><html><head><meta charset='utf-8'><title>a&lt;b datasheet</title><style>"
       + CSS + "</style></head><body><h1>a&lt;b: RTS setup datasheet</h1>")
SPEC = ("<table><tr><th>KPI</th><th>value</th><th>limit</th><th>margin</th><th>verdict</th>"
        "<th>note</th></tr><tr class='fail'><td>angle_accuracy_deg</td><td>0.2</td><td>0.1</td>"
        "<td>-0.1</td><td>FAIL</td><td>n1</td></tr><tr><td>min_range_m</td><td>1.6</td>"
        "<td>2</td><td>0.4</td><td>pass</td><td>n2</td></tr><tr class='fail'>"
        "<td>resolution_deg</td><td>-</td><td>12</td><td>-</td><td>no value</td>"
        "<td>no value here</td></tr></table>")


def _figs():
    tiny = Figure(figsize=(1, 1))
    return {k: tiny for k in ("field_of_view", "angle_accuracy", "uncertainty_budget",
                              "near_field_and_ghosts", "other<")}


def _img(alt):
    return f"<img alt='{alt}' src='data:image/png;base64,PNG'>"


FIGS = ("<h2>Field of view</h2>" + _img("field_of_view")
        + "<h2>Angle accuracy</h2>" + _img("angle_accuracy") + "<p>GUM validated at 3 of 3.</p>"
        + "<h2>Uncertainty budget (JCGM 100, validated by JCGM 101)</h2>"
        + _img("uncertainty_budget"))
WORST = ("<p>The budget at the worst set angle, 7.500 deg (pair (0, 1)): u_c = 0.25 deg, U = "
         "0.5 deg; Monte Carlo 95 % interval [-0.75, 0.375] deg.</p><table><tr><th>quantity"
         "</th><th>u(x_i)</th><th>unit</th><th>distribution</th><th>c_i (deg/unit)</th>"
         "<th>u_i(y) (deg)</th></tr><tr><td>radial offset</td><td>0.1</td><td>mm</td>"
         "<td>normal</td><td>2</td><td>0.2</td></tr><tr><td>delay &lt;q&gt;</td><td>3</td>"
         "<td>ps</td><td>rectangular</td><td>0.01</td><td>0.03</td></tr></table>")
LAST = ("<h2>Near field, ghosts and leakage</h2>" + _img("near_field_and_ghosts")
        + "<h2>other&lt;</h2>" + _img("other&lt;"))


@pytest.mark.parametrize("spec, passed, points, middle", [
    (None, None, POINTS, FIGS + WORST + LAST),
    (object(), False, POINTS, "<h2>Spec: FAIL: see below</h2>" + SPEC + "\0"),
    (object(), True, [], "<h2>Spec: PASS: every KPI meets the spec</h2>" + SPEC + "\0"),
])
def test_the_html_page_in_full(spec, passed, points, middle):
    page = to_html(_sheet(spec, passed, CHECKS, points), figs=_figs())
    page = re.sub(r"base64,[A-Za-z0-9+/=]+'", "base64,PNG'", page)
    if middle.endswith("\0"):  # the spec's table before the key figures, the figures after
        middle = middle[:-1]
        figs = FIGS + (WORST if points else "") + LAST
        assert page == TOP + middle + HEAD + figs + TAIL
    else:
        assert page == TOP + HEAD + middle + TAIL


def test_the_pages_figures_are_pngs_at_110_dpi():
    page = to_html(_sheet(None, None, [], []), figs={"x": Figure(figsize=(2, 1))})
    data = base64.b64decode(re.search(r"base64,([A-Za-z0-9+/=]+)'", page).group(1))
    img = matplotlib.image.imread(io.BytesIO(data))
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and img.shape[:2] == (110, 220)


@pytest.mark.parametrize("spec, passed", [(None, None), (object(), False), (object(), True)])
def test_the_pdfs_text_page_line_by_line(spec, passed):
    page = _text_page(_sheet(spec, passed, CHECKS, POINTS))
    texts = [(t.get_text(), t.get_position()) for t in page.texts]
    lines = [t for t, _ in texts]
    want = ["a<b: RTS setup datasheet"]
    if spec is not None:
        want += ["Spec: " + ("PASS" if passed else "FAIL"),
                 "angle_accuracy_deg: value 0.2, limit 0.1, margin -0.1: FAIL",
                 "min_range_m: value 1.6, limit 2, margin 0.4: pass",
                 "resolution_deg: value -, limit 12, margin -: no value (no value here)"]
    want.append("Key figures")
    for n, v in ROWS:
        want.append(f"{n}:")
        want += __import__("textwrap").wrap(v, 62)
    want += ["Uncertainty: GUM (JCGM 100) budget per set angle, k = 2, validated by a Monte "
             "Carlo (JCGM 101)", "Inputs: {'points': 3, 'sigma_mm': [0.1, 0.2]}"]
    assert lines == want
    # top to bottom, inside the page: each row's name beside its first line, the rest below
    ys = [p[1] for _, p in texts]
    assert all(0.0 < y < 1.0 for y in ys) and ys[0] == 0.95
    assert all(b <= a for a, b in zip(ys, ys[1:]))
    xs = {t: p[0] for t, p in texts}
    assert xs["Key figures"] == 0.06 and xs["field of view:"] == 0.08
    assert xs[ROWS[0][1]] == 0.45
    colors = {t.get_text(): t.get_color() for t in page.texts}
    if spec is not None:
        assert colors["Spec: PASS" if passed else "Spec: FAIL"] == ("green" if passed else "red")
        assert colors["min_range_m: value 1.6, limit 2, margin 0.4: pass"] == "k"
        assert colors["angle_accuracy_deg: value 0.2, limit 0.1, margin -0.1: FAIL"] == "red"


def test_the_pdf_has_three_pages(tmp_path):
    figs = {k: Figure(figsize=(1, 1)) for k in ("field_of_view", "angle_accuracy",
                                                 "uncertainty_budget", "near_field_and_ghosts")}
    path = tmp_path / "k.pdf"
    assert write_pdf(_sheet(None, None, [], []), path, figs) == 3
    assert len(re.findall(rb"/Type\s*/Page\b(?!s)", path.read_bytes())) == 3
