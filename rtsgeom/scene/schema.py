"""The scene schema's machinery: a field is declared once, one generic reader checks it.

Each field of a scene configuration dataclass carries its declaration in the dataclass field's
metadata (:func:`spec`): the key in the file, the kind, the unit, the allowed range, the default
(in the file's units) and a one-line doc. From that one declaration come the reader
(:func:`read`), the re-check of a value set in code (:mod:`.evolve`), and the generated reference
``docs/scene-format.md`` (:mod:`rtsgeom.scene.docs`).

Why dataclass metadata and not pydantic or msgspec: the rest of the package works with the
frozen dataclasses (attribute names in SI units, ``angle_rad``) while the file speaks in the
units people write (``angle_deg``, ``radial_offset_mm``, ``calibration_span_ns``); the
messages must keep the pinned format ``<file>: <field> = <value as written>: must be <allowed>``
and the rules reach across sections. With pydantic this would need aliases, validators and an
error translator per field type -- more code than the reader below -- and a second class
hierarchy beside the dataclasses. One reader over ``dataclasses.fields`` keeps the types as
they are and is about 250 lines.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import reprlib
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
from ..errors import SceneError

__all__ = ["SceneError", "REQUIRED", "Derived", "Spec", "spec", "specs", "read", "check_value",
           "check_record", "check_arg", "fmt", "range_text", "rows_text"]


REQUIRED = object()
MAX_STRING_CHARS = 10_000  # any string unless its field says otherwise


@dataclass(frozen=True)
class Derived:
    """A default computed from the fields read before it (SI values): ``fn(values) -> SI``."""

    doc: str
    fn: Callable[[dict], Any]


@dataclass(frozen=True)
class Spec:
    """One field's declaration (see :func:`spec`)."""

    key: str
    kind: str  # float, int, bool, str, material, vec, floats, points, ints, rows, table, tables
    doc: str
    unit: str = ""
    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    hi_open: bool = False
    default: Any = REQUIRED  # in file units; None = optional; Derived = computed
    scale: float = 1.0  # SI value = file value * scale
    choices: tuple[str, ...] | None = None
    n: int = 0  # vector length
    whole: bool = False  # vector of whole numbers (stored as int)
    max_chars: int = MAX_STRING_CHARS
    printable: bool = False
    cls: type | None = None  # table / tables: the dataclass of the entries
    max_items: int = 0  # tables: at most this many entries
    min_items: int = 0
    item: str = ""  # tables: what one entry is called in messages (``front end``)
    # rows: each row's columns (name, unit, lo, hi, scale); the first ``n`` are required, a
    # missing trailing one is 0
    columns: tuple[tuple[str, str, float, float, float], ...] = ()

    def to_si(self, v: Any) -> Any:
        if self.kind == "rows" and v is not None:
            return tuple(tuple(x * col[4] for x, col in zip(row, self.columns)) for row in v)
        if v is None or self.scale == 1.0:
            return v
        if isinstance(v, tuple):
            return tuple(tuple(y * self.scale for y in x) if isinstance(x, tuple)
                         else x * self.scale for x in v)
        return v * self.scale

    def range_text(self) -> str:
        return range_text(self.lo, self.hi, self.lo_open, self.hi_open, self.unit)


def spec(key: str, kind: str, doc: str, default: Any = REQUIRED, **kw) -> dataclasses.Field:
    """A dataclass field declared once: its file key, kind, range, default (file units), doc.

    The dataclass default is the SI value of the file default, so it is written only here."""
    s = Spec(key, kind, doc, default=default, **kw)
    meta = {"spec": s}
    if default is REQUIRED or isinstance(default, Derived):
        return dataclasses.field(metadata=meta)
    if kind == "table":
        if default is None:  # an optional table: absent = None
            return dataclasses.field(default=None, metadata=meta)
        return dataclasses.field(default_factory=s.cls, metadata=meta)
    if kind == "tables":
        return dataclasses.field(default=(), metadata=meta)
    if kind == "vec" and default is not None:
        conv = (lambda x: int(x)) if s.whole else (lambda x: float(x))
        return dataclasses.field(default=s.to_si(tuple(conv(x) for x in default)), metadata=meta)
    return dataclasses.field(default=s.to_si(default), metadata=meta)


def specs(cls: type) -> list[tuple[str, Spec]]:
    """(attribute name, declaration) of every declared field of a config dataclass, in order."""
    return [(f.name, f.metadata["spec"]) for f in dataclasses.fields(cls) if "spec" in f.metadata]


# --------------------------------------------------------------------------------------------
# Messages
# --------------------------------------------------------------------------------------------

_REPR = reprlib.Repr()
_REPR.maxstring, _REPR.maxother, _REPR.maxlong = 60, 60, 40
_REPR.maxlist, _REPR.maxdict, _REPR.maxlevel = 12, 8, 3


def fmt(v: Any) -> str:
    """The value in an error message: short even for huge or deeply nested input."""
    return _REPR.repr(v) if not isinstance(v, float) else f"{v:g}"


def range_text(lo, hi, lo_open=False, hi_open=False, unit="") -> str:
    u = f" {unit}" if unit else ""
    if lo is not None and hi is not None:
        return f"in {'(' if lo_open else '['}{lo:g}, {hi:g}{')' if hi_open else ']'}{u}"
    if lo is not None:
        return f"{'>' if lo_open else '>='} {lo:g}{u}"
    if hi is not None:
        return f"{'<' if hi_open else '<='} {hi:g}{u}"
    return ""


def _as_float(v: int | float) -> float | None:
    """``float(v)``, or None for an integer too large for a float (TOML integers are unbounded)."""
    try:
        return float(v)
    except OverflowError:
        return None


def _is_num(v: Any) -> bool:
    return not isinstance(v, bool) and isinstance(v, (int, float))


# --------------------------------------------------------------------------------------------
# The one reader
# --------------------------------------------------------------------------------------------


class _Ctx:
    def __init__(self, source: str, where: str, error: type = SceneError):
        self.source, self.where, self.error = source, where, error

    def path(self, key: str) -> str:
        return f"{self.where}.{key}" if self.where else key

    def fail(self, fieldname: str, value: Any, allowed: str) -> None:
        raise self.error(f"{self.source}: {fieldname} = "
                         f"{value if isinstance(value, _Written) else fmt(value)}: must be {allowed}")


class _Written(str):
    """A value already formatted as written (so ``fail`` does not format it again)."""


def _written(v: Any) -> _Written:
    # a float is shown as TOML wrote it (512.0, not 512) where the kind is the problem
    return _Written(repr(v) if isinstance(v, float) else fmt(v))


def _check_unknown(data: dict, cls: type, ctx: _Ctx) -> None:
    known = [s.key for _, s in specs(cls)]
    unknown = sorted(set(data) - set(known))
    if not unknown:
        return
    key = unknown[0]
    shown = _fmt_key(key)
    missing = [k for k, s in ((s.key, s) for _, s in specs(cls))
               if s.default is REQUIRED and k not in data]
    near = difflib.get_close_matches(key, known, n=1, cutoff=0.75) if len(key) <= 200 else []
    hint = ""
    if near:
        hint = f"; did you mean {near[0]}?" + (f" ({ctx.path(near[0])} is missing)"
                                               if near[0] in missing else "")
    raise SceneError(f"{ctx.source}: {ctx.path(shown)} is not a known field{hint} "
                     f"(allowed here: {', '.join(sorted(known))})")


def _fmt_key(key: str) -> str:
    return fmt(key) if len(key) > 60 or not key.isprintable() else key


def read(cls: type, data: Any, source: str, where: str = "", context: dict | None = None) -> Any:
    """Check a parsed TOML table against ``cls``'s declarations and build ``cls``.

    Fields without a declaration (``source``, ``sha256`` ...) come from ``context``."""
    ctx = _Ctx(source, where)
    if not isinstance(data, dict):
        ctx.fail(where or "<top level>", data, "a table")
    _check_unknown(data, cls, ctx)
    values: dict[str, Any] = {}
    for name, s in specs(cls):
        values[name] = _read_field(s, data, ctx, values, context or {})
    for f in dataclasses.fields(cls):
        if "spec" not in f.metadata and context and f.name in context:
            values[f.name] = context[f.name]
    return cls(**values)


def _read_field(s: Spec, data: dict, ctx: _Ctx, values: dict, context: dict) -> Any:
    path = ctx.path(s.key)
    if s.key not in data:
        if s.default is REQUIRED:
            ctx_missing = f"{ctx.source}: {path} is missing (required)"
            raise SceneError(ctx_missing)
        if isinstance(s.default, Derived):
            return s.default.fn({**context, **values})
        if s.kind == "table":
            return None if s.default is None else read(s.cls, {}, ctx.source, path, context)
        if s.kind == "tables":
            v = []
        elif s.kind == "vec" and s.default is not None:
            return s.to_si(tuple(int(x) if s.whole else float(x) for x in s.default))
        else:
            return s.to_si(s.default)
    else:
        v = data[s.key]
    return s.to_si(check_value(s, v, ctx, path, context))


def _check_float(s: Spec, v: Any, ctx: _Ctx, path: str, context) -> float:
    if not _is_num(v):
        ctx.fail(path, v, f"a number{' in ' + s.unit if s.unit else ''}")
    rng = s.range_text()
    f = _as_float(v)
    if f is None or not math.isfinite(f):
        ctx.fail(path, v, f"a finite number {rng}".rstrip())
    if ((s.lo is not None and (f < s.lo or (s.lo_open and f == s.lo)))
            or (s.hi is not None and (f > s.hi or (s.hi_open and f == s.hi)))):
        ctx.fail(path, f, rng)
    return f + 0.0  # -0.0 reads as 0 (numpy refuses a scale of -0.0: "scale < 0")


def _check_int(s: Spec, v: Any, ctx: _Ctx, path: str, context) -> int:
    rng = s.range_text()
    if isinstance(v, bool) or not isinstance(v, int):
        ctx.fail(path, _written(v), f"an integer {rng}".rstrip())
    if (s.lo is not None and v < s.lo) or (s.hi is not None and v > s.hi):
        ctx.fail(path, v, rng)
    return int(v)


def _check_bool(s: Spec, v: Any, ctx: _Ctx, path: str, context) -> bool:
    if not isinstance(v, bool):
        ctx.fail(path, v, "true or false")
    return v


def _check_str(s: Spec, v: Any, ctx: _Ctx, path: str, context) -> str:
    """A string (``str``) or a radio material's name (``material``)."""
    ch = s.choices
    if not isinstance(v, str):
        ctx.fail(path, v, "a string" + (f": one of {', '.join(ch)}" if ch else ""))
    if ch is not None and v not in ch:
        ctx.fail(path, v, f"one of {', '.join(ch)}")
    if len(v) > s.max_chars:
        ctx.fail(path, v, f"a string of at most {s.max_chars} characters (it has {len(v)})")
    if s.printable and not v.isprintable():
        ctx.fail(path, v, "a string of printable characters (no newlines, tabs or control "
                          "characters)")
    if s.printable and not v.strip():
        ctx.fail(path, v, "a non-empty string")
    if s.kind == "material" and not v.replace("_", "").isalnum():
        ctx.fail(path, v, "a radio material name such as itu_metal")
    return v


def _check_vec(s: Spec, v: Any, ctx: _Ctx, path: str, context) -> tuple | None:
    """A fixed-length vector (``s.n`` numbers in [lo, hi], whole numbers with ``s.whole``)."""
    if v is None and s.default is None:
        return None
    unit = s.unit or "m"
    if (not isinstance(v, (list, tuple)) or len(v) != s.n
            or any(not _is_num(x) for x in v)):
        ctx.fail(path, v, f"a list of {s.n} numbers in {unit}")
    out = tuple(_as_float(x) for x in v)
    if not all(x is not None and math.isfinite(x) and s.lo <= x <= s.hi for x in out):
        ctx.fail(path, v, f"{s.n} finite numbers in [{s.lo:g}, {s.hi:g}] {unit}")
    if s.whole:
        if any(x != int(x) for x in out):
            ctx.fail(path, list(out), f"{s.n} whole numbers of {unit}")
        return tuple(int(x) for x in out)
    return out


def _check_table(s: Spec, v: Any, ctx: _Ctx, path: str, context):
    """One sub-table, read into its class (a value already of that class passes as is)."""
    if isinstance(v, s.cls):
        return v
    return read(s.cls, v, ctx.source, path, context)


def _check_tables(s: Spec, v: Any, ctx: _Ctx, path: str, context) -> tuple:
    """An array of tables ``[[...]]`` with ``s.min_items`` to ``s.max_items`` entries, each
    read into ``s.cls`` (a tuple already of that class passes as is)."""
    if isinstance(v, tuple) and all(isinstance(t, s.cls) for t in v):
        items = v
    else:
        if not isinstance(v, list) or not all(isinstance(t, dict) for t in v):
            ctx.fail(path, v, "an array of tables ([[...]])")
        items = None
    n = len(v)
    if s.max_items and n > s.max_items:
        ctx.fail(path, _Written(f"<{n} {s.item}s>"), f"a list of at most {s.max_items} {s.item}s")
    if n < s.min_items:
        ctx.fail(path, [], f"a list of at least {s.min_items} {s.item}")
    if items is None:
        items = tuple(read(s.cls, t, ctx.source, f"{path}[{i}]", context)
                      for i, t in enumerate(v))
    return tuple(items)


def check_value(s: Spec, v: Any, ctx: _Ctx, path: str, context: dict | None = None) -> Any:
    """One value in file units against its declaration; returns it normalised (file units)."""
    k = s.kind
    if k in ("points", "ints", "floats"):
        return _check_list(s, v, ctx, path)
    if k == "rows":
        return _check_rows(s, v, ctx, path)
    check = _CHECKS.get(k)
    if check is None:
        raise AssertionError(f"unknown kind {k}")  # a declaration error, not input
    return check(s, v, ctx, path, context)


#: the checker of each kind of declared value
_CHECKS = {"float": _check_float, "int": _check_int, "bool": _check_bool, "str": _check_str,
           "material": _check_str, "vec": _check_vec, "table": _check_table,
           "tables": _check_tables}


def _check_list(s: Spec, v: Any, ctx: _Ctx, path: str) -> tuple:
    """``points``: a list of [a, b, ...] (``s.n`` numbers each); ``ints``: a list of integers;
    ``floats``: a list of numbers; each with ``s.min_items``..``s.max_items`` entries and every
    number finite and in [lo, hi]."""
    unit = f" {s.unit}" if s.unit else ""
    count = (f"at least {s.min_items}" + (f" and at most {s.max_items}" if s.max_items else ""))
    if s.kind == "floats":
        what = f"a list ({count} entries) of numbers in [{s.lo:g}, {s.hi:g}]{unit}"
        if (not isinstance(v, (list, tuple)) or len(v) < s.min_items
                or (s.max_items and len(v) > s.max_items) or any(not _is_num(x) for x in v)):
            ctx.fail(path, v, what)
        out = tuple(_as_float(x) for x in v)
        for i, x in enumerate(out):
            if x is None or not math.isfinite(x) or not s.lo <= x <= s.hi:
                ctx.fail(f"{path}[{i}]", v[i], f"a finite number in [{s.lo:g}, {s.hi:g}]{unit}")
        return out
    if s.kind == "points":
        what = f"a list ({count} entries) of [{'x, z' if s.n == 2 else ', '.join('xyz'[:s.n])}] pairs of numbers in " \
               f"[{s.lo:g}, {s.hi:g}]{unit}"
        if (not isinstance(v, (list, tuple)) or len(v) < s.min_items
                or (s.max_items and len(v) > s.max_items)
                or any(not isinstance(p, (list, tuple)) or len(p) != s.n
                       or any(not _is_num(x) for x in p) for p in v)):
            ctx.fail(path, v, what)
        out = tuple(tuple(_as_float(x) for x in p) for p in v)
        for i, p in enumerate(out):
            if not all(x is not None and math.isfinite(x) and s.lo <= x <= s.hi for x in p):
                ctx.fail(f"{path}[{i}]", list(v[i]), f"{s.n} finite numbers in "
                                                     f"[{s.lo:g}, {s.hi:g}]{unit}")
        return out
    what = f"a list ({count} entries) of integers in [{s.lo:g}, {s.hi:g}]"
    if (not isinstance(v, (list, tuple)) or len(v) < s.min_items
            or (s.max_items and len(v) > s.max_items)
            or any(isinstance(x, bool) or not isinstance(x, int) for x in v)):
        ctx.fail(path, v, what)
    for i, x in enumerate(v):
        if not s.lo <= x <= s.hi:
            ctx.fail(f"{path}[{i}]", x, f"in [{s.lo:g}, {s.hi:g}]")
    return tuple(int(x) for x in v)


def rows_text(s: Spec, inner: bool = False) -> str:
    """What a ``rows`` field allows: ``[t_s, range_m, azimuth_deg(, elevation_deg)]`` rows
    (``inner``: only the bracket)."""
    names = [c[0] for c in s.columns]
    row = "[" + ", ".join(names[:s.n]) + "".join(f"(, {x}" for x in names[s.n:]) \
        + ")" * (len(names) - s.n) + "]"
    if inner:
        return row
    count = f"at least {s.min_items}" + (f" and at most {s.max_items}" if s.max_items else "")
    return f"a list ({count} entries) of {row} rows"


def _check_rows(s: Spec, v: Any, ctx: _Ctx, path: str) -> tuple:
    """``rows``: a list of rows of ``s.n`` to ``len(s.columns)`` numbers, each column in its own
    range; returned in file units, every row padded to all columns (a missing one is 0)."""
    cols = s.columns
    if (not isinstance(v, (list, tuple)) or len(v) < s.min_items
            or (s.max_items and len(v) > s.max_items)
            or any(not isinstance(r, (list, tuple)) or not s.n <= len(r) <= len(cols)
                   or any(not _is_num(x) for x in r) for r in v)):
        ctx.fail(path, v, rows_text(s))
    out = []
    for i, r in enumerate(v):
        row = [_as_float(x) for x in r] + [0.0] * (len(cols) - len(r))
        for j, (x, (name, unit, lo, hi, _)) in enumerate(zip(row, cols)):
            if x is None or not math.isfinite(x) or not lo <= x <= hi:
                ctx.fail(f"{path}[{i}][{j}]", r[j] if j < len(r) else x,
                         f"a finite {name} in [{lo:g}, {hi:g}]{' ' + unit if unit else ''}")
        out.append(tuple(row))
    return tuple(out)


# --------------------------------------------------------------------------------------------
# The same declarations for the other inputs: files beside the scene, Python arguments
# --------------------------------------------------------------------------------------------


def check_record(declared: dict[str, Spec], data: Any, source: str, error: type = SceneError,
                 where: str = "") -> dict[str, Any]:
    """A plain record (a capture's sidecar, a calibration file's JSON) against declared fields
    ``{key: Spec}``: the values normalised (file units), ``None`` for an absent optional one.
    Keys not declared are ignored (files carry descriptive extras); a missing required key and
    every value out of its declaration raise ``error`` as ``<source>: <key> = <value>: must be
    <allowed>``, like the scene file's; ``where``: the record's place in its file
    (``pairs[0]``), prefixed to each key."""
    ctx = _Ctx(source, where, error)
    if not isinstance(data, dict):
        ctx.fail(where or "<top level>", data, "a JSON object")
    out: dict[str, Any] = {}
    for key, s in declared.items():
        if key not in data or (data[key] is None and s.default is None):
            if s.default is REQUIRED:
                raise error(f"{source}: {ctx.path(key)} is missing (required)")
            out[key] = s.default
            continue
        out[key] = check_value(s, data[key], ctx, ctx.path(key))
    return out


def check_arg(value: Any, name: str, kind: str, source: str, error: type = SceneError,
              **declaration) -> Any:
    """One argument of a function or command against an inline declaration (``kind`` and the
    keywords of :class:`Spec`: ``lo``, ``hi``, ``choices``, ``n``, ``unit`` ...): returns it
    normalised, or raises ``error`` as ``<source>: <name> = <value>: must be <allowed>``."""
    if kind == "vec" and isinstance(value, np.ndarray):
        value = value.tolist()
    if kind in ("vec", "points", "ints", "floats") and isinstance(value, (list, tuple)):
        # numpy scalars as Python numbers (np.bool_ stays a bool, refused as a number)
        value = type(value)(x.item() if isinstance(x, np.generic) else x for x in value)
    if kind == "int" and isinstance(value, np.integer):
        value = int(value)
    if kind == "float" and isinstance(value, np.floating):
        value = float(value)
    return check_value(Spec(name, kind, "", **declaration), value, _Ctx(source, "", error), name)
