"""The code's shape in two figures, read from the source as text (nothing imported): the length
of every function and the parameter count of every public one.

``python -m benchmarks.code_shape`` prints the functions over the limits; tests/test_structure.py
holds the package to them (:data:`MAX_FUNCTION_LINES`, :data:`MAX_PARAMETERS`,
:data:`MAX_WIDE_PUBLIC`).

- A function's length is its lines from ``def`` to its last line, decorators aside, docstring
  included (a nested function counts in its parent's lines and on its own).
- Its parameters are every name it takes, of any kind (``self`` and ``cls`` aside):
  positional, keyword-only, ``*args`` and ``**kwargs`` (``Function.all_parameters``); a
  wide signature is many things to know at a call, in whatever order they are named.
  ``Function.parameters`` counts the positional ones alone.
- Public: the function's name and every enclosing class's name start without ``_``, and it is
  not nested in another function. A module's or package's leading ``_`` (``_lib``) does not
  make its functions private: the package's own layers call them as an API.
- The compiled kernels (decorated ``njit``/``jit``: numba) are left out of both figures; their
  arguments are the flat arrays numba compiles for.
"""

from __future__ import annotations

import ast
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PKG = ROOT / "rtsgeom"

#: the longest a function may be (lines)
MAX_FUNCTION_LINES = 80
#: a public function with more parameters than this is "wide"
MAX_PARAMETERS = 8
#: how many wide public functions the package may have
MAX_WIDE_PUBLIC = 5

KERNEL_DECORATORS = ("njit", "jit")


@dataclass(frozen=True)
class Function:
    """One function (or method) of the package, as the source reads."""

    module: str  #: dotted module name, ``rtsgeom.paths.raytrace``
    qualname: str  #: ``Class.method`` or ``outer.<locals>.inner``
    lineno: int
    lines: int
    parameters: int  #: positional (self/cls aside)
    all_parameters: int  #: every name, keyword-only and ``*args``/``**kwargs`` included
    public: bool
    kernel: bool

    @property
    def where(self) -> str:
        return f"{self.module}.{self.qualname}"


def _decorator_name(node: ast.expr) -> str:
    if isinstance(node, ast.Call):
        node = node.func
    if isinstance(node, ast.Attribute):
        return node.attr
    return node.id if isinstance(node, ast.Name) else ""


def _parameters(node: ast.FunctionDef | ast.AsyncFunctionDef) -> tuple[int, int]:
    """(positional, all) parameter counts, ``self``/``cls`` aside."""
    a = node.args
    positional = [x.arg for x in (*a.posonlyargs, *a.args)]
    names = positional + [x.arg for x in a.kwonlyargs]
    names += [x.arg for x in (a.vararg, a.kwarg) if x is not None]
    return (sum(n not in ("self", "cls") for n in positional),
            sum(n not in ("self", "cls") for n in names))


def _walk(tree: ast.AST, module: str):
    def visit(node, prefix: str, public: bool, in_function: bool):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.ClassDef):
                yield from visit(child, f"{prefix}{child.name}.",
                                 public and not child.name.startswith("_"), in_function)
            elif isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                kernel = any(_decorator_name(d) in KERNEL_DECORATORS
                             for d in child.decorator_list)
                yield Function(module, prefix + child.name, child.lineno,
                               child.end_lineno - child.lineno + 1, *_parameters(child),
                               public and not in_function and not child.name.startswith("_"),
                               kernel)
                yield from visit(child, f"{prefix}{child.name}.<locals>.", False, True)
            else:
                yield from visit(child, prefix, public, in_function)

    yield from visit(tree, "", True, False)


def functions(pkg: Path = PKG) -> list[Function]:
    """Every function and method under ``pkg``, in file order."""
    out = []
    for p in sorted(pkg.rglob("*.py")):
        parts = p.relative_to(pkg.parent).with_suffix("").parts
        module = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        out += _walk(ast.parse(p.read_text()), module)
    return out


def long_functions(fns=None, limit: int = MAX_FUNCTION_LINES) -> list[Function]:
    """The functions (kernels aside) longer than ``limit`` lines, longest first."""
    fns = functions() if fns is None else fns
    return sorted((f for f in fns if f.lines > limit and not f.kernel), key=lambda f: -f.lines)


def wide_public(fns=None, limit: int = MAX_PARAMETERS) -> list[Function]:
    """The public functions (kernels aside) with more than ``limit`` parameters of any kind,
    widest first."""
    fns = functions() if fns is None else fns
    return sorted((f for f in fns if f.public and not f.kernel and f.all_parameters > limit),
                  key=lambda f: -f.all_parameters)


def main() -> None:
    fns = functions()
    long, wide = long_functions(fns), wide_public(fns)
    print(f"{len(fns)} functions; longest {max(f.lines for f in fns if not f.kernel)} lines")
    print(f"over {MAX_FUNCTION_LINES} lines: {len(long)}")
    for f in long:
        print(f"  {f.lines:4d}  {f.where}  (line {f.lineno})")
    print(f"public with over {MAX_PARAMETERS} parameters of any kind: {len(wide)} "
          f"(allowed {MAX_WIDE_PUBLIC})")
    for f in wide:
        print(f"  {f.all_parameters:4d}  {f.where}  ({f.parameters} positional, "
              f"line {f.lineno})")




# --------------------------------------------------------------------------------------------
# numpydoc sections on the package's face
# --------------------------------------------------------------------------------------------

#: the share of ``rtsgeom.__all__`` (callables) whose docstrings carry their numpydoc sections
MIN_NUMPYDOC_SHARE = 0.9


def numpydoc_sections(doc: str | None) -> set[str]:
    """The numpydoc section titles in ``doc``: a title line followed by a line of dashes as
    long."""
    import inspect
    lines = inspect.cleandoc(doc or "").splitlines()
    return {a.strip() for a, b in zip(lines, lines[1:])
            if a.strip() and set(b.strip()) == {"-"} and len(b.strip()) == len(a.strip())}


def numpydoc_missing(obj) -> list[str]:
    """The sections ``obj``'s docstring lacks: a function ``Parameters`` (when it takes any)
    and ``Returns``; a class ``Parameters`` or ``Attributes`` (an exception or warning class:
    only a docstring)."""
    import inspect
    doc = inspect.getdoc(obj)
    if not doc:
        return ["docstring"]
    have = numpydoc_sections(doc)
    if inspect.isclass(obj):
        if issubclass(obj, BaseException):
            return []
        return [] if have & {"Parameters", "Attributes"} else ["Parameters/Attributes"]
    try:
        takes = any(n not in ("self", "cls") for n in inspect.signature(obj).parameters)
    except (TypeError, ValueError):
        takes = True
    missing = ["Parameters"] if takes and "Parameters" not in have else []
    return missing + ([] if have & {"Returns", "Yields"} else ["Returns"])


def numpydoc_report() -> tuple[list[str], dict[str, list[str]]]:
    """(the callables of ``rtsgeom.__all__``, those lacking sections -> what they lack)."""
    import rtsgeom
    names = [n for n in rtsgeom.__all__ if callable(getattr(rtsgeom, n))]
    missing = {n: m for n in names if (m := numpydoc_missing(getattr(rtsgeom, n)))}
    return names, missing


def _print_numpydoc() -> None:
    names, missing = numpydoc_report()
    print(f"numpydoc sections on {len(names) - len(missing)} of {len(names)} callables of "
          f"rtsgeom.__all__ ({1 - len(missing) / len(names):.0%}; at least "
          f"{MIN_NUMPYDOC_SHARE:.0%})")
    for n, m in missing.items():
        print(f"  {n}: no {', '.join(m)}")


if __name__ == "__main__":
    main()
    _print_numpydoc()
