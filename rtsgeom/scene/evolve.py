"""Values set in code, checked against the scene's declarations: :meth:`Evolvable.evolve`
(``dataclasses.replace`` that validates the result again, for values a user writes in Python)
and :meth:`Evolvable.derive` (the package's own variants of a validated scene, not checked
again through the file's schema: their values follow from checked ones, and a failure would name
a field nobody wrote)."""

from __future__ import annotations

import dataclasses
from typing import Any

from .schema import Derived, _Ctx, check_value, specs

__all__ = ["check_fields", "Evolvable"]


def check_fields(obj: Any, source: str, where: str = "") -> None:
    """Check every declared field of a config object (SI values) against its declaration."""
    ctx = _Ctx(source, where)
    for name, s in specs(type(obj)):
        v = getattr(obj, name)
        path = ctx.path(s.key)
        if v is None and (s.default is None or isinstance(s.default, Derived)):
            continue
        if s.kind == "table":
            if v is not None:
                if not isinstance(v, s.cls):
                    ctx.fail(path, v, f"a {s.cls.__name__} (a table set in code is the "
                                      f"section's object, not a {type(v).__name__})")
                check_fields(v, source, path)
            continue
        if s.kind == "tables":
            if not isinstance(v, (tuple, list)) or not all(isinstance(t, s.cls) for t in v):
                ctx.fail(path, v, f"a tuple of {s.cls.__name__} (entries set in code are "
                                  f"the section's objects, e.g. replace(scene.{path}[0], ...), "
                                  "not dicts)")
            check_value(s, tuple(v), ctx, path)
            for i, item in enumerate(v):
                check_fields(item, source, f"{path}[{i}]")
            continue
        if s.kind == "rows":  # back to file units, column by column (as rounded: see below)
            fv = tuple(tuple(x / col[4] for x, col in zip(row, s.columns)) for row in v)
            cols = tuple((n, u, lo - 1e-9 * max(1.0, abs(lo)), hi + 1e-9 * max(1.0, abs(hi)), f)
                         for n, u, lo, hi, f in s.columns)
            check_value(dataclasses.replace(s, columns=cols), fv, ctx, path)
            continue
        if s.scale != 1.0 and v is not None:
            # back to file units; allow the rounding of the unit conversion at the bounds
            fv = tuple(x / s.scale for x in v) if isinstance(v, tuple) else v / s.scale
            lo = None if s.lo is None else s.lo - 1e-9 * max(1.0, abs(s.lo))
            hi = None if s.hi is None else s.hi + 1e-9 * max(1.0, abs(s.hi))
            check_value(dataclasses.replace(s, lo=lo, hi=hi), fv, ctx, path)
        else:
            check_value(s, v, ctx, path)


class Evolvable:
    """Mixin: ``obj.evolve(**changes)`` is ``dataclasses.replace`` that validates again;
    ``obj.derive(**changes)`` is ``dataclasses.replace`` for a variant the package derives."""

    def evolve(self, **changes):
        """A copy with ``changes`` (SI values), its fields checked against their declarations.

        Raises
        ------
        SceneError
            A changed value outside its declaration, named as the file's key.
        """
        new = dataclasses.replace(self, **changes)
        check_fields(new, getattr(self, "source", None) or "<evolve>")
        return new

    def derive(self, **changes):
        """A copy with ``changes``, not checked again: for the package's own variants of a
        validated object (a study's mode, the nominal setup, a calibration's reference step),
        whose values the deriving step computes from checked ones."""
        return dataclasses.replace(self, **changes)
