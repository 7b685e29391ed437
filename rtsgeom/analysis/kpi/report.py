"""The datasheet's views: its figures (matplotlib, the house style of ``viz.figures``), a
self-contained HTML page (every figure a base64 PNG inside it, no stylesheet, script or font
fetched from anywhere) and a PDF of at most three pages (matplotlib's PdfPages)."""

from __future__ import annotations

import base64
import html
import io
import math
import textwrap

import matplotlib as mpl
import numpy as np
from matplotlib.figure import Figure

from ...viz.figures import STYLE, new_figure
from .headline import headline

__all__ = ["figures", "accuracy_figure", "to_html", "write_pdf"]

GROUPS = (("mounting", "offset"), ("calibration and delay", " ps"),
          ("RuT channels", "RuT "), ("noise", "noise"))


def _group(row) -> str:
    if "offset" in row.quantity:
        return "mounting"
    if row.unit == "ps":
        return "calibration and delay"
    if row.quantity.startswith("RuT"):
        return "RuT channels"
    return "noise"


def _title(sheet, what: str) -> str:
    return f"{sheet.scene_name}: {what}"


def accuracy_figure(sheet) -> Figure:
    """The error after calibration at each set angle, its +-U (k = 2) band, the Monte Carlo's
    95 % interval and the spec's limit."""
    with mpl.rc_context(STYLE):
        fig, ax = new_figure((8.0, 3.8))
        pts = sheet.accuracy
        if not pts:
            ax.text(0.5, 0.5, sheet.accuracy_note, ha="center", va="center", wrap=True,
                    transform=ax.transAxes)
            ax.set_axis_off()
            return fig
        for k, pair in enumerate(dict.fromkeys(p.pair for p in pts)):
            sel = [p for p in pts if p.pair == pair]
            x = np.array([p.set_deg for p in sel])
            e = np.array([p.error_deg for p in sel])
            u = np.array([p.expanded_deg for p in sel])
            lo = np.array([p.mc_interval_deg[0] for p in sel])
            hi = np.array([p.mc_interval_deg[1] for p in sel])
            lab = k == 0
            ax.fill_between(x, e - u, e + u, color="C0", alpha=0.25,
                            label="error +- U (k = 2), GUM" if lab else None)
            ax.plot(x, e, "C0-", marker="o", label="error after calibration" if lab else None)
            ax.vlines(x, lo, hi, color="C1", lw=2.5, alpha=0.8,
                      label="Monte Carlo 95 % interval" if lab else None)
            bad = [p for p in sel if not p.validated]
            if bad:
                ax.plot([p.set_deg for p in bad], [p.mc_interval_deg[1] for p in bad], "rv",
                        label="GUM and Monte Carlo differ > 10 % of U" if lab else None)
        spec = sheet.spec
        if spec is not None and spec.angle_accuracy_deg is not None:
            for s in (-1, 1):
                ax.axhline(s * spec.angle_accuracy_deg, color="C3", ls="--", lw=1,
                           label="spec angle_accuracy_deg" if s > 0 else None)
        if spec is not None and spec.azimuth_deg is not None:
            ax.axvspan(*spec.azimuth_deg, color="C2", alpha=0.07, label="spec azimuth_deg")
        for g in sheet.fov["gaps_deg"]:
            ax.axvspan(*g, color="C3", alpha=0.15)
        ax.set_xlabel("set angle (deg)")
        ax.set_ylabel("synthesized - set angle (deg)")
        ax.set_title(_title(sheet, "angle accuracy after calibration"), parse_math=False)
        ax.legend(fontsize=7, loc="best")
    return fig


def budget_figure(sheet) -> Figure:
    """Each input group's contribution u_i (deg, root sum of squares within the group) over
    the set angles, and the combined u_c."""
    with mpl.rc_context(STYLE):
        fig, ax = new_figure((8.0, 3.4))
        pts = sheet.accuracy
        if not pts:
            ax.set_axis_off()
            return fig
        x = np.arange(len(pts))
        bottom = np.zeros(len(pts))
        for k, (name, _) in enumerate(GROUPS):
            v = np.array([math.sqrt(sum(r.contribution_deg ** 2 for r in p.budget
                                        if _group(r) == name)) for p in pts])
            ax.bar(x, v ** 2, bottom=bottom, color=f"C{k}", label=name)
            bottom += v ** 2
        ax.plot(x, [p.combined_deg ** 2 for p in pts], "k.", label="u_c^2 (GUM)")
        ax.plot(x, [(p.mc_half_width_deg / 1.96) ** 2 for p in pts], "x", color="C5",
                label="(Monte Carlo half-width / 1.96)^2")
        step = max(1, len(pts) // 12)
        ax.set_xticks(x[::step], [f"{p.set_deg:.1f}" for p in pts][::step])
        ax.set_xlabel("set angle (deg)")
        ax.set_ylabel("variance contribution (deg^2)")
        ax.set_title(_title(sheet, "uncertainty budget: each input group's share of u_c^2"),
                     parse_math=False)
        ax.legend(fontsize=7, ncols=3, loc="upper center")
        ax.set_ylim(0, 1.3 * max(float(np.max(bottom)), 1e-12))
    return fig


def fov_figure(sheet) -> Figure:
    """The field of view: each front end as the RuT detects it, each pair's span (grey:
    not synthesizable), the gaps and the spec's span."""
    fov = sheet.fov
    with mpl.rc_context(STYLE):
        fig, ax = new_figure((8.0, 2.6))
        for fe in fov["front_ends"]:
            a = fe.get("measured_azimuth_deg", fe["geometric_azimuth_deg"])
            ax.plot(a, fe["elevation_deg"], "k^", ms=8)
            ax.annotate(f"FE {fe['index']}", (a, fe["elevation_deg"]), xytext=(0, 8),
                        textcoords="offset points", ha="center", fontsize=7)
        for k, p in enumerate(fov["pairs"]):
            col = "C0" if p["synthesizable"] else "0.6"
            ax.plot([p["lo_deg"], p["hi_deg"]], [0, 0], color=col, lw=6, alpha=0.7,
                    solid_capstyle="butt")
        for g in fov["gaps_deg"]:
            ax.axvspan(*g, color="C3", alpha=0.2)
        spec = sheet.spec
        if spec is not None and spec.azimuth_deg is not None:
            ax.axvspan(*spec.azimuth_deg, ymin=0.05, ymax=0.15, color="C2", alpha=0.5,
                       label=f"spec {spec.azimuth_deg[0]:g} .. {spec.azimuth_deg[1]:g} deg")
            ax.legend(fontsize=7, loc="upper right")
        lo, hi = fov["azimuth_deg"]
        ax.set_title(_title(sheet, f"field of view {lo:.2f} .. {hi:.2f} deg ({fov['mode']}), "
                                   f"{len(fov['gaps_deg'])} gap(s)"), parse_math=False)
        ax.set_xlabel("azimuth seen from the RuT (deg)")
        ax.set_ylabel("elevation (deg)")
        ax.set_ylim(min(-1.0, fov["elevation_deg"][0] - 1), max(1.5, fov["elevation_deg"][1]
                                                                 + 1.5))
    return fig


def nearfield_ghosts_figure(sheet) -> Figure:
    """Left: each front end's distance over the Fraunhofer distance and its bias before
    calibration; right: the cable ghosts' levels over their range offsets."""
    nf, gh = sheet.nearfield, sheet.ghosts
    with mpl.rc_context(STYLE):
        fig, (ax, bx) = new_figure((8.0, 3.2), ncols=2)
        idx = [f["index"] for f in nf["front_ends"]]
        ax.bar(idx, [f["bias_deg"] for f in nf["front_ends"]], color="C0")
        for f in nf["front_ends"]:
            ax.annotate(f"R/R_F {f['distance_over_fraunhofer']:.0f}", (f["index"], f["bias_deg"]),
                        xytext=(0, 3), textcoords="offset points", ha="center", fontsize=7)
        ax.set_xticks(idx)
        top = max([abs(f["bias_deg"]) for f in nf["front_ends"]] + [1e-6])
        ax.set_ylim(min(0.0, min(f["bias_deg"] for f in nf["front_ends"]) * 1.2), 1.2 * top)
        ax.set_xlabel("front end")
        ax.set_ylabel("bias before calibration (deg)")
        ax.set_title(f"near field: R_F = {nf['fraunhofer_distance_m']:.3g} m", parse_math=False)
        any_ghost = False
        for fe in gh["cable_ghosts"]:
            for g in fe["ghosts"]:
                bx.plot([g["range_offset_m"]] * 2, [gh["floor_db"], g["level_db"]], "C1-")
                bx.plot(g["range_offset_m"], g["level_db"], "C1o")
                any_ghost = True
        if not any_ghost:
            bx.text(0.5, 0.5, f"no cable ghost above {gh['floor_db']:g} dB", ha="center",
                    va="center", transform=bx.transAxes)
        bx.axhline(0, color="k", lw=0.8)
        spec = sheet.spec
        if spec is not None and spec.ghost_suppression_db is not None:
            bx.axhline(-spec.ghost_suppression_db, color="C3", ls="--", lw=1,
                       label="spec ghost_suppression_db")
            bx.legend(fontsize=7)
        bx.set_ylim(gh["floor_db"], 5)
        bx.set_xlim(left=0.0)
        bx.set_xlabel("range offset behind the target (m)")
        bx.set_ylabel("level relative to the target (dB)")
        bx.set_title("cable ghosts", parse_math=False)
    return fig


def figures(sheet) -> dict:
    """Every figure, by name, in the report's order."""
    return {"field_of_view": fov_figure(sheet), "angle_accuracy": accuracy_figure(sheet),
            "uncertainty_budget": budget_figure(sheet),
            "near_field_and_ghosts": nearfield_ghosts_figure(sheet)}


def _png_base64(fig: Figure) -> str:
    buf = io.BytesIO()
    with mpl.rc_context(STYLE):
        fig.savefig(buf, format="png", dpi=110)
    return base64.b64encode(buf.getvalue()).decode("ascii")


def _fmt(v, digits: int = 4) -> str:
    if v is None:
        return "-"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, float):
        return f"{v:.{digits}g}"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_fmt(x, digits) for x in v) + "]"
    return str(v)


def _table(head, rows, classes=None) -> str:
    h = "".join(f"<th>{html.escape(x)}</th>" for x in head)
    body = []
    for k, r in enumerate(rows):
        cls = f" class='{classes[k]}'" if classes and classes[k] else ""
        body.append(f"<tr{cls}>" + "".join(f"<td>{html.escape(_fmt(x))}</td>" for x in r)
                    + "</tr>")
    return f"<table><tr>{h}</tr>{''.join(body)}</table>"


def _spec_rows(sheet):
    rows, classes = [], []
    for c in sheet.checks:
        verdict = "no value" if c.passed is None else ("pass" if c.passed else "FAIL")
        rows.append((c.kpi, c.value, c.limit, c.margin, verdict, c.note))
        classes.append("" if c.passed else "fail")
    return rows, classes


_CSS = ("body{font-family:sans-serif;max-width:1000px;margin:1em auto;color:#222}"
        "table{border-collapse:collapse;margin:0.5em 0}td,th{border:1px solid #bbb;"
        "padding:2px 6px;font-size:90%;text-align:left}tr.fail td{background:#fdd}"
        "img{max-width:100%}h2{border-bottom:1px solid #ccc}")


def to_html(sheet, figs: dict | None = None) -> str:
    """The datasheet as one self-contained HTML page: inline CSS, figures as data: URIs."""
    figs = figures(sheet) if figs is None else figs
    d = sheet.to_dict()
    esc = html.escape
    parts = [f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{esc(sheet.scene_name)}"
             f" datasheet</title><style>{_CSS}</style></head><body>",
             f"<h1>{esc(sheet.scene_name)}: RTS setup datasheet</h1>"]
    if sheet.spec is not None:
        verdict = "PASS: every KPI meets the spec" if sheet.passed else "FAIL: see below"
        rows, classes = _spec_rows(sheet)
        parts += [f"<h2>Spec: {esc(verdict)}</h2>",
                  _table(("KPI", "value", "limit", "margin", "verdict", "note"), rows, classes)]
    parts += ["<h2>Key figures</h2>", _table(("KPI", "value"), headline(d))]
    titles = {"field_of_view": "Field of view", "angle_accuracy": "Angle accuracy",
              "uncertainty_budget": "Uncertainty budget (JCGM 100, validated by JCGM 101)",
              "near_field_and_ghosts": "Near field, ghosts and leakage"}
    for name, fig in figs.items():
        parts.append(f"<h2>{esc(titles.get(name, name))}</h2><img alt='{esc(name)}' "
                     f"src='data:image/png;base64,{_png_base64(fig)}'>")
        if name == "angle_accuracy":
            parts.append(f"<p>{esc(d['angle_accuracy_summary']['gum_validation'])}.</p>")
        if name == "uncertainty_budget" and sheet.accuracy:
            worst = max(sheet.accuracy, key=lambda p: p.accuracy_deg)
            parts.append(f"<p>The budget at the worst set angle, {worst.set_deg:.3f} deg (pair "
                         f"{worst.pair}): u_c = {worst.combined_deg:.4g} deg, U = "
                         f"{worst.expanded_deg:.4g} deg; Monte Carlo 95 % interval "
                         f"[{worst.mc_interval_deg[0]:.4g}, {worst.mc_interval_deg[1]:.4g}] "
                         "deg.</p>")
            parts.append(_table(("quantity", "u(x_i)", "unit", "distribution",
                                 "c_i (deg/unit)", "u_i(y) (deg)"),
                                [(r.quantity, r.standard_uncertainty, r.unit, r.distribution,
                                  r.sensitivity, r.contribution_deg) for r in worst.budget]))
    rv = sheet.range_velocity
    parts.append("<h2>Range and velocity limits</h2>" + _table(("limit", "value"), [
        ("air path (m)", rv["limits"]["air_path_m"]),
        ("FIR latency (m)", rv["limits"]["fir_latency_m"]),
        ("processing's largest range (m)", rv["limits"]["processing_max_range_m"]),
        ("buffer", rv["limits"]["buffer_note"])]))
    parts.append(f"<p>Inputs: {esc(_fmt(sheet.inputs))}. Computed in {sheet.elapsed_s:.1f} s "
                 "by rtsgeom kpi.</p></body></html>")
    return "".join(parts)


def write_pdf(sheet, path, figs: dict | None = None) -> int:
    """The datasheet as a PDF of three pages (the key figures and the spec; the field of view
    and the angle accuracy; the budget, near field and ghosts); returns the page count."""
    from matplotlib.backends.backend_pdf import PdfPages
    figs = figures(sheet) if figs is None else figs
    pages = [_text_page(sheet), _stack(figs["field_of_view"], figs["angle_accuracy"]),
             _stack(figs["uncertainty_budget"], figs["near_field_and_ghosts"])]
    with PdfPages(path) as pdf:
        for page in pages:
            pdf.savefig(page)
    return len(pages)


def _stack(*figs) -> Figure:
    """Figures stacked on one A4 page (as images: each keeps its own layout)."""
    page = Figure(figsize=(8.27, 11.69))
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    FigureCanvasAgg(page)
    for k, f in enumerate(figs):
        buf = io.BytesIO()
        f.savefig(buf, format="png", dpi=150)
        buf.seek(0)
        img = mpl.image.imread(buf)
        ax = page.add_axes((0.04, 0.52 - 0.48 * k, 0.92, 0.46))
        ax.imshow(img)
        ax.set_axis_off()
    return page


def _text_page(sheet) -> Figure:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    page = Figure(figsize=(8.27, 11.69))
    FigureCanvasAgg(page)
    y = 0.95
    page.text(0.06, y, f"{sheet.scene_name}: RTS setup datasheet", fontsize=15, weight="bold")
    y -= 0.05
    if sheet.spec is not None:
        page.text(0.06, y, "Spec: " + ("PASS" if sheet.passed else "FAIL"), fontsize=12,
                  color="green" if sheet.passed else "red", weight="bold")
        y -= 0.03
        for c in sheet.checks:
            verdict = "no value" if c.passed is None else ("pass" if c.passed else "FAIL")
            line = (f"{c.kpi}: value {_fmt(c.value)}, limit {_fmt(c.limit)}, margin "
                    f"{_fmt(c.margin)}: {verdict}" + (f" ({c.note})" if c.passed is None
                                                      else ""))
            for part in textwrap.wrap(line, 110):
                page.text(0.08, y, part, fontsize=8.5, color="k" if c.passed else "red")
                y -= 0.018
            y -= 0.004
        y -= 0.02
    page.text(0.06, y, "Key figures", fontsize=12, weight="bold")
    y -= 0.03
    for name, value in headline(sheet.to_dict()):
        page.text(0.08, y, f"{name}:", fontsize=8.5)
        for line in textwrap.wrap(value, 62) or [""]:
            page.text(0.45, y, line, fontsize=8.5)
            y -= 0.018
        y -= 0.004
    y -= 0.02
    page.text(0.06, y, "Uncertainty: GUM (JCGM 100) budget per set angle, k = 2, validated by "
                       "a Monte Carlo (JCGM 101)", fontsize=8.5)
    y -= 0.022
    for line in textwrap.wrap("Inputs: " + _fmt(sheet.inputs), 130):
        page.text(0.06, y, line, fontsize=7)
        y -= 0.016
    return page
