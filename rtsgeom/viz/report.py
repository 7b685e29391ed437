"""Self-contained HTML reports: one file, images embedded as data URIs, no scripts, no links out.

A report is a title, the scene summary (the dict of :func:`rtsgeom.pipeline.info.scene_info`, shown as
tables) and a list of sections. A section is a dict with

* ``heading`` (str, required),
* ``text`` (str; blank lines separate paragraphs),
* ``images`` (list of PNG file paths or PNG bytes),
* ``table`` (``{"columns": [...], "rows": [[...], ...]}``, optionally ``"digits": [...]``:
  decimals per column, None for the automatic format),
* ``warnings`` (list of str, shown highlighted).

All text is HTML-escaped; the file is written atomically.
"""

from __future__ import annotations

import base64
import html
import math
from pathlib import Path
from typing import Any, Iterable, Mapping

from matplotlib.ticker import EngFormatter

from .. import __version__
from .._lib.io import write_text

__all__ = ["write_report", "render_report"]

_PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
_SECTION_KEYS = {"heading", "text", "images", "table", "warnings"}

# Field-name suffix -> unit; Hz, s and m get SI prefixes (77 GHz, 3.9 mm, 250 ps).
_UNITS = (("_hz_per_s", "Hz/s"), ("_hz", "Hz"), ("_mps", "m/s"), ("_deg", "deg"), ("_mm", "mm"),
          ("_dbsm", "dBsm"), ("_db", "dB"), ("_m", "m"), ("_s", "s"))
_PREFIXED = {"Hz", "Hz/s", "s", "m"}
# Absolute precision of the quantities without SI prefixes: values are rounded to it, so that
# numerical noise (-3.42094e-06 m/s) reads as 0.
_PRECISION = {"m/s": 1e-4, "deg": 1e-4, "mm": 1e-4, "dB": 1e-3, "dBsm": 1e-3}
# Readable names of the keys of scene_info and the summaries (the rest: underscores to spaces).
_NAMES = {
    "f_c": "start frequency f_c", "f_center": "centre frequency", "f_rts": "RTS IF f_rts",
    "f_s": "RTS sampling rate f_s", "slope": "chirp slope S", "num_rx": "Rx antennas",
    "num_virtual": "virtual channels", "num_virtual_azimuth": "azimuth virtual channels",
    "tx_order": "Tx order", "antenna_preset": "antenna preset", "max_range": "maximum range",
    "max_velocity": "maximum velocity", "aperture": "azimuth aperture d_A",
    "fraunhofer_distance": "Fraunhofer distance 2 d_A^2 / lambda",
    "arc_radius": "arc radius R_c", "delay_resolution": "delay resolution",
    "calibration_period": "calibration period", "rcs": "RCS", "snr": "SNR",
    "arc_angle": "arc angle", "azimuth_from_rut": "azimuth from the RuT",
    "apparent_azimuth": "apparent azimuth", "rx_tx_separation": "Rx-Tx separation",
    "mounting_offsets": "mounting offsets", "curvature_phase_error": "curvature phase error",
    "front_end_spacing": "front-end spacing", "spacing_within_resolution":
    "spacing within the angular resolution", "scene_sha256": "scene SHA-256",
    "rtsgeom_version": "rtsgeom version",
}

_CSS = """
body { font-family: system-ui, -apple-system, "Segoe UI", Roboto, sans-serif; margin: 2em auto;
       max-width: 1100px; padding: 0 1em; color: #1d2329; line-height: 1.45; }
h1 { font-size: 1.6em; border-bottom: 2px solid #1f6fb4; padding-bottom: .2em; }
h2 { font-size: 1.25em; margin-top: 1.8em; color: #1f4f7a; }
h3 { font-size: 1.05em; margin: 1.2em 0 .4em; }
table { border-collapse: collapse; margin: .4em 0 1em; font-size: .9em; }
th, td { border: 1px solid #c9d0d8; padding: .25em .6em; text-align: left; vertical-align: top; }
th { background: #eef2f6; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
.meta { color: #555; font-size: .9em; }
.warning { background: #fff4e0; border-left: 4px solid #e08a00; padding: .4em .8em;
           margin: .4em 0; }
figure { margin: 1em 0; }
figure img { max-width: 100%; height: auto; border: 1px solid #dde2e8; }
figcaption { color: #555; font-size: .85em; }
.kv { display: flex; flex-wrap: wrap; gap: 0 2em; }
footer { margin-top: 3em; color: #777; font-size: .8em; }
"""


def _esc(value: Any) -> str:
    return html.escape(str(value), quote=True)


def _label_unit(key: str) -> tuple[str, str | None]:
    """``f_c_hz`` -> (``start frequency f_c``, ``Hz``): the readable name (:data:`_NAMES`, else
    the key with spaces for underscores) and the unit of the key's suffix."""
    label, unit = key, None
    for suffix, u in _UNITS:
        if key.endswith(suffix) and len(key) > len(suffix):
            label, unit = key[: -len(suffix)], u
            break
    return _NAMES.get(label, label.replace("_", " ")), unit


def _format_number(value: float, unit: str | None, digits: int | None = None) -> str:
    if not math.isfinite(value):
        return str(value)
    if digits is not None:
        text = f"{value:.{digits}f}"
        if float(text) == 0.0:
            text = text.lstrip("-")
        return f"{text} {unit}" if unit else text
    if unit in _PREFIXED and value != 0.0:
        return EngFormatter(unit=unit, places=None, sep=" ", usetex=False,
                            useMathText=False)(float(f"{value:.5g}")).replace("\u2212", "-")
    if unit in _PRECISION:
        q = _PRECISION[unit]
        value = round(value / q) * q + 0.0
    text = f"{value:.6g}" if value != 0 else "0"
    return f"{text} {unit}" if unit else text


def _plain(value: Any) -> Any:
    """numpy scalars and arrays -> Python numbers and lists."""
    return value.tolist() if hasattr(value, "tolist") else value


def _format_value(value: Any, unit: str | None = None, digits: int | None = None) -> str:
    value = _plain(value)
    if value is None:
        return "\u2013"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, (list, tuple)):  # an empty list says "none", not an empty cell
        return ", ".join(_format_value(v, unit, digits) for v in value) if value else "none"
    if _is_number(value):
        if isinstance(value, int) and unit is None:
            return str(value)
        return _format_number(float(value), unit, digits)
    return str(value)


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _cell(value: Any, unit: str | None = None, digits: int | None = None) -> str:
    value = _plain(value)
    cls = ' class="num"' if _is_number(value) else ""
    return f"<td{cls}>{_esc(_format_value(value, unit, digits))}</td>"


def _table(columns: Iterable[Any], rows: Iterable[Iterable[Any]],
           units: list[str | None] | None = None, digits: list | None = None) -> str:
    columns = list(columns)
    head = "".join(f"<th>{_esc(c)}</th>" for c in columns)
    body = []
    for row in rows:
        row = list(row)
        if len(row) != len(columns):
            raise ValueError(f"report table row {row!r} has {len(row)} cells, the table has "
                             f"{len(columns)} columns")
        u = units or [None] * len(row)
        dg = digits or [None] * len(row)
        body.append("<tr>" + "".join(_cell(v, un, d) for v, un, d in zip(row, u, dg)) + "</tr>")
    return f"<table><thead><tr>{head}</tr></thead><tbody>{''.join(body)}</tbody></table>"


def _key_value_table(d: Mapping[str, Any]) -> str:
    rows = []
    for key, value in d.items():
        label, unit = _label_unit(str(key))
        rows.append(f"<tr><th>{_esc(label)}</th>{_cell(value, unit)}</tr>")
    return f"<table><tbody>{''.join(rows)}</tbody></table>"


def _records_table(records: list[Mapping[str, Any]]) -> str:
    """A list of dicts as one table; columns are the union of keys, units in the headers."""
    keys = list(dict.fromkeys(k for r in records for k in r))
    labels, units = zip(*(_label_unit(str(k)) for k in keys)) if keys else ((), ())
    cols = [f"{lab} ({u})" if u else lab for lab, u in zip(labels, units)]
    # values in the body carry no unit: the header has it
    rows = [[_rounded(r.get(k, ""), u) for k, u in zip(keys, units)] for r in records]
    return _table(cols, rows)


def _rounded(value: Any, unit: str | None) -> Any:
    """``value`` rounded to the precision of its unit (:data:`_PRECISION`), lists elementwise."""
    value = _plain(value)
    if isinstance(value, list):
        return [_rounded(v, unit) for v in value]
    if _is_number(value) and isinstance(value, float) and unit in _PRECISION:
        q = _PRECISION[unit]
        return round(value / q) * q + 0.0
    return value


_INFO_PARTS = (("radar", "Radar under test"), ("far_field", "Far field"),
               ("rts", "Radar target simulator"))


def _scene_section(info: Mapping[str, Any]) -> str:
    out = ["<section>", "<h2>Scene</h2>"]
    meta = [(k, info[k]) for k in ("scene", "source", "scene_sha256", "rtsgeom_version")
            if k in info]
    if meta:
        out.append("<p class=\"meta\">" + "<br>".join(
            f"{_esc(_label_unit(k)[0])}: <code>{_esc(v)}</code>" for k, v in meta) + "</p>")
    shown = {k for k, _ in meta}
    tables = []
    for key, heading in _INFO_PARTS:
        if isinstance(info.get(key), Mapping):
            tables.append(f"<div><h3>{_esc(heading)}</h3>{_key_value_table(info[key])}</div>")
            shown.add(key)
    if tables:
        out.append('<div class="kv">' + "".join(tables) + "</div>")
    for key, value in info.items():  # front_ends, targets, and whatever scene_info adds later
        if key in shown:
            continue
        heading = _label_unit(key)[0].capitalize()
        if isinstance(value, list) and value and all(isinstance(v, Mapping) for v in value):
            out.append(f"<h3>{_esc(heading)}</h3>{_records_table(value)}")
        elif isinstance(value, Mapping):
            out.append(f"<h3>{_esc(heading)}</h3>{_key_value_table(value)}")
        elif isinstance(value, list) and not value:
            continue
        else:
            label, unit = _label_unit(key)
            out.append(f"<p><b>{_esc(label)}</b>: "
                       f"{_esc(_format_value(value, unit))}</p>")
    out.append("</section>")
    return "\n".join(out)


def _png_bytes(image: Any) -> tuple[bytes, str]:
    """PNG data and a caption (the file name) of a section image."""
    if isinstance(image, (bytes, bytearray, memoryview)):
        data, name = bytes(image), ""
    else:
        p = Path(image)  # a file: prefer bytes, so a report shows what its run produced
        data, name = p.read_bytes(), p.name
    if not data.startswith(_PNG_MAGIC):
        raise ValueError(f"report image {name or '(bytes)'} is not a PNG file")
    return data, name


def _section(sec: Mapping[str, Any]) -> str:
    unknown = set(sec) - _SECTION_KEYS
    if unknown:
        raise ValueError(f"report section has unknown keys {sorted(unknown)} (allowed: "
                         f"{sorted(_SECTION_KEYS)})")
    if "heading" not in sec:
        raise ValueError("report section needs a 'heading'")
    out = ["<section>", f"<h2>{_esc(sec['heading'])}</h2>"]
    for w in sec.get("warnings") or ():
        out.append(f'<div class="warning"><b>Warning:</b> {_esc(w)}</div>')
    text = sec.get("text")
    if text:
        for para in str(text).split("\n\n"):
            if para.strip():
                out.append(f"<p>{_esc(para.strip())}</p>")
    for image in sec.get("images") or ():
        data, name = _png_bytes(image)
        uri = "data:image/png;base64," + base64.b64encode(data).decode("ascii")
        cap = f"<figcaption>{_esc(name)}</figcaption>" if name else ""
        out.append(f'<figure><img src="{uri}" alt="{_esc(name or sec["heading"])}">{cap}</figure>')
    table = sec.get("table")
    if table:
        out.append(_table(table.get("columns", []), table.get("rows", []),
                          digits=table.get("digits")))
    out.append("</section>")
    return "\n".join(out)


def render_report(title: str, scene_info: Mapping[str, Any], sections: list[Mapping[str, Any]]
                  ) -> str:
    """The report as an HTML string (see :func:`write_report`)."""
    body = [f"<h1>{_esc(title)}</h1>", _scene_section(scene_info)]
    body += [_section(s) for s in sections]
    return ("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
            "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
            f"<title>{_esc(title)}</title>\n<style>{_CSS}</style>\n</head>\n<body>\n"
            + "\n".join(body)
            + f"\n<footer>rtsgeom {_esc(__version__)}</footer>\n</body>\n</html>\n")


def write_report(path: str | Path, title: str, scene_info: Mapping[str, Any],
                 sections: list[Mapping[str, Any]]) -> Path:
    """Write a self-contained HTML report (images inline, no scripts, no external resources).

    ``scene_info`` is the dict of :func:`rtsgeom.pipeline.info.scene_info`; it becomes the first section.
    """
    path = Path(path)
    write_text(path, render_report(title, scene_info, sections))
    return path
