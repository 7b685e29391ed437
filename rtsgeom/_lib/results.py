"""What every study's result shows of itself: a short ``repr``, an HTML table for notebooks,
``to_dataframe()`` and ``plot()``.

A result class derives from :class:`Result` (as a dataclass with ``repr=False``, so that the
dataclass does not write its own field-by-field repr, which printed every array in full) and
says three things:

* ``_summary()``: a title (what was studied) and (name, value) rows, the headline numbers;
  :meth:`Result.__repr__` prints at most :data:`MAX_LINES` lines of them, arrays summarised by
  :func:`brief` (shape and range, never the values);
* ``_columns()``: equal-length columns (name -> 1-D values) of its per-item numbers, the
  table :meth:`Result.to_dataframe` returns (a :class:`pandas.DataFrame`);
* ``plot()``: its figure (matplotlib, imported by the figure functions only).

Every result writes itself in one place: :meth:`Result.to_json` (its ``to_dict()``),
:meth:`Result.to_csv` (its table) and, where a command has an ``--out`` folder, its own
``write(folder)`` (the files of that folder); a command only chooses which.
"""

from __future__ import annotations

import dataclasses
import html
import math
from pathlib import Path

import numpy as np

from .io import write_json, write_text

__all__ = ["Result", "brief", "MAX_LINES"]

MAX_LINES = 20  # of a repr, the title included
_WIDTH = 100  # characters of one row's value


def brief(value) -> str:
    """A value in one short line: numbers to 4 significant digits, arrays as their shape and
    range, mappings and sequences by their length and first items."""
    if value is None:
        return "None"
    if isinstance(value, (bool, np.bool_)):
        return str(bool(value))
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        v = float(value)
        return "nan" if math.isnan(v) else f"{v:.4g}"
    if isinstance(value, str):
        return value if len(value) <= _WIDTH else value[:_WIDTH - 3] + "..."
    if isinstance(value, np.ndarray):
        if value.size == 0:
            return f"array {value.shape}: empty"
        shape = "x".join(str(n) for n in value.shape)
        if value.dtype == bool:
            return f"array ({shape}) bool: {int(value.sum())} True"
        if not np.issubdtype(value.dtype, np.number):
            return f"array ({shape}) {value.dtype}"
        a = np.asarray(value, float)
        finite = a[np.isfinite(a)]
        if value.size == 1:
            return brief(a.ravel()[0])
        if not finite.size:
            return f"array ({shape}): no finite values"
        rng = f"{brief(finite.min())} .. {brief(finite.max())}"
        missing = a.size - finite.size
        return f"array ({shape}): {rng}" + (f", {missing} not finite" if missing else "")
    if isinstance(value, dict):
        keys = ", ".join(str(k) for k in list(value)[:6])
        return f"{{{keys}{', ...' if len(value) > 6 else ''}}}"
    if isinstance(value, (tuple, list)):
        if all(isinstance(v, (int, float, np.number)) for v in value) and len(value) <= 6:
            return "(" + ", ".join(brief(v) for v in value) + ")"
        return f"{type(value).__name__} of {len(value)}"
    name = getattr(value, "name", None)
    return f"{type(value).__name__} {name!r}" if isinstance(name, str) else type(value).__name__


class Result:
    """Mixin of a study's result (module doc)."""

    def _summary(self) -> tuple[str, list[tuple[str, object]]]:
        """(title, rows): what was studied and its headline numbers (values as they are, or
        already formatted strings)."""
        rows = [(f.name, getattr(self, f.name)) for f in dataclasses.fields(self)]
        return type(self).__name__, rows

    def _columns(self) -> dict:
        """Equal-length columns (name -> 1-D values) for :meth:`to_dataframe`."""
        raise NotImplementedError

    def _rows(self) -> tuple[str, list[tuple[str, str]]]:
        title, rows = self._summary()
        rows = [(str(k), v if isinstance(v, str) else brief(v)) for k, v in rows]
        rows = [(k, v if len(v) <= _WIDTH else v[:_WIDTH - 3] + "...") for k, v in rows]
        if len(rows) > MAX_LINES - 1:
            more = len(rows) - (MAX_LINES - 2)
            rows = rows[:MAX_LINES - 2] + [("...", f"{more} more (to_dict(), to_dataframe())")]
        return title, rows

    def __repr__(self) -> str:
        title, rows = self._rows()
        width = max((len(k) for k, _ in rows), default=0)
        return "\n".join([f"<{type(self).__name__}: {title}>"]
                         + [f"  {k:<{width}}  {v}" for k, v in rows])

    def _repr_html_(self) -> str:
        title, rows = self._rows()
        body = "".join(f"<tr><th style='text-align:left'>{html.escape(k)}</th>"
                       f"<td style='text-align:left'>{html.escape(v)}</td></tr>"
                       for k, v in rows)
        return (f"<table><caption style='text-align:left'><b>{type(self).__name__}</b>: "
                f"{html.escape(title)}</caption>{body}</table>")

    def to_dataframe(self):
        """The per-item numbers as a :class:`pandas.DataFrame` (one row per item; the
        columns' units in their names)."""
        import pandas as pd
        cols = self._columns()
        return pd.DataFrame({k: np.asarray(v) if isinstance(v, np.ndarray) else list(v)
                             for k, v in cols.items()})

    def plot(self):
        """The result's figure (a :class:`matplotlib.figure.Figure`)."""
        raise NotImplementedError(f"{type(self).__name__} has no figure")

    def to_json(self, path: str | Path) -> Path:
        """Write ``to_dict()`` as a JSON file (atomically); returns the path."""
        write_json(Path(path), self.to_dict())
        return Path(path)

    def to_csv(self, path: str | Path) -> Path:
        """Write :meth:`to_dataframe` (one row per item) as a CSV file (atomically); returns
        the path."""
        write_text(Path(path), self.to_dataframe().to_csv(index=False))
        return Path(path)
