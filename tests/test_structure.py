"""The package's shape: one pipeline, one direction, visible in the folder list.

Read from the source as text (nothing imported): every import, also those inside functions,
points down the pipeline (a subpackage imports only from the stages below it), no module
imports itself back through others (no import circle), the top level holds only the package's
face, no module has grown into two concepts (500 lines), and the code cites no internal issue
tracker (a reader of the code cannot look those up)."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

from benchmarks.code_shape import (MAX_FUNCTION_LINES, MAX_PARAMETERS, MAX_WIDE_PUBLIC,
                                   functions, long_functions, wide_public)
from conftest import ROOT

PKG = ROOT / "rtsgeom"

#: the pipeline's stages from the bottom up: a module may import from its own stage and the
#: ones before it (``rtsgeom`` itself only for ``__version__``)
LAYERS = ("errors", "_lib", "scene", "geometry", "paths", "viz", "rts", "radar", "synthesis",
          "calibration", "pipeline", "identify", "analysis", "api", "cli", "__main__")
MAX_LINES = 500


def _modules() -> dict[str, object]:
    out = {}
    for p in sorted(PKG.rglob("*.py")):
        name = ".".join(p.relative_to(ROOT).with_suffix("").parts)
        out[name[: -len(".__init__")] if name.endswith(".__init__") else name] = p
    return out


def _imports(name: str, path, mods) -> set[str]:
    """The package's modules ``name`` imports (the deepest module each import names)."""
    is_pkg = path.name == "__init__.py"
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = name.split(".") if is_pkg else name.split(".")[:-1]
            if node.level:
                base = base[: len(base) - node.level + 1]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            targets = [mod] + [f"{mod}.{a.name}" for a in node.names]
        else:
            continue
        for t in targets:
            while t and t not in mods:
                t = t.rpartition(".")[0]
            if t and t != name and t.startswith("rtsgeom"):
                found.add(t)
    return found


MODS = _modules()
EDGES = {m: _imports(m, p, MODS) for m, p in MODS.items()}


def _stage(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "rtsgeom"


def test_every_import_points_down_the_pipeline():
    bad = []
    for m, targets in EDGES.items():
        if _stage(m) == "rtsgeom":
            continue  # the package's face (__init__) names everything lazily
        own = LAYERS.index(_stage(m))
        for t in targets:
            stage = _stage(t)
            if stage == "rtsgeom":
                continue  # __version__
            if LAYERS.index(stage) > own:
                bad.append(f"{m} -> {t}")
    assert not bad, bad


def test_no_import_circle():
    """Tarjan's strongly connected components of the module graph: every one a single
    module."""
    index, low, stack, on, circles = {}, {}, [], set(), []
    counter = [0]

    def strong(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in EDGES[v]:
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                circles.append(sorted(comp))

    for v in MODS:
        if v not in index:
            strong(v)
    assert not circles, circles


def test_the_top_level_is_the_packages_face():
    loose = sorted(p.name for p in PKG.glob("*.py"))
    assert loose == ["__init__.py", "__main__.py", "api.py", "errors.py"], loose
    assert {p.name for p in PKG.iterdir() if p.is_dir() and p.name != "__pycache__"} \
        == set(LAYERS) - {"errors", "api", "__main__"}


@pytest.mark.parametrize("module", sorted(MODS))
def test_no_module_is_two_concepts(module):
    lines = MODS[module].read_text().count("\n")
    assert lines <= MAX_LINES, f"{module}: {lines} lines"


def test_no_function_is_over_80_lines():
    """A function past 80 lines is two steps (kernels in numba aside: benchmarks/code_shape.py
    says how lines are counted)."""
    long = [f"{f.where}: {f.lines} lines" for f in long_functions(limit=MAX_FUNCTION_LINES)]
    assert not long, long


def test_few_public_functions_take_over_8_parameters():
    """A public function with more than 8 parameters of any kind (keyword-only, ``*args``
    and ``**kwargs`` counted) takes a small frozen config instead; at most five do (numba
    kernels aside)."""
    wide = [f"{f.where}: {f.all_parameters}" for f in wide_public(limit=MAX_PARAMETERS)]
    assert len(wide) <= MAX_WIDE_PUBLIC, wide


def test_the_packages_face_has_its_numpydoc_sections():
    """At least 90 % of the callables in ``rtsgeom.__all__`` carry their numpydoc sections
    (Parameters/Attributes, Returns: benchmarks/code_shape.py says which each needs)."""
    from benchmarks.code_shape import MIN_NUMPYDOC_SHARE, numpydoc_report
    names, missing = numpydoc_report()
    assert 1 - len(missing) / len(names) >= MIN_NUMPYDOC_SHARE, missing


def test_the_numpydoc_measure_reads_sections():
    from benchmarks.code_shape import numpydoc_missing, numpydoc_sections

    def f(a):
        """One line.

        Parameters
        ----------
        a : int
            A.

        Returns
        -------
        int
        """

    def g(a):
        """One line; ``a``: a number. Returns it.
        ----
        """
    assert numpydoc_sections(f.__doc__) == {"Parameters", "Returns"}
    assert numpydoc_missing(f) == [] and numpydoc_missing(g) == ["Parameters", "Returns"]


def test_the_shape_measure_counts_what_it_says():
    """The measure itself, on a made-up module: lines from ``def`` to the last line, parameters
    without self/cls, nested and underscored functions not public, numba kernels flagged."""
    import textwrap
    src = textwrap.dedent('''
        from numba import njit

        def f(a, b, *c, d, **e):
            x = 1
            return x

        class K:
            def m(self, a):
                def inner(p, q, r):
                    return p
                return inner

            @classmethod
            def c(cls):
                pass

        class _Hidden:
            def m(self, a, b):
                pass

        @njit(cache=True)
        def kern(a, b, c, d, e, f, g, h, i, j):
            return a

        def wide(a, *, b, c, d, e, f, g, h, i):
            pass
    ''')
    from benchmarks.code_shape import _walk
    got = {f.qualname: f for f in _walk(ast.parse(src), "m")}
    assert (got["f"].lines, got["f"].parameters, got["f"].public) == (3, 2, True)
    assert got["f"].all_parameters == 5
    assert (got["K.m"].lines, got["K.m"].parameters, got["K.m"].public) == (4, 1, True)
    assert got["K.m.<locals>.inner"].public is False
    assert got["K.c"].parameters == 0
    assert got["_Hidden.m"].public is False
    assert got["kern"].kernel and not got["f"].kernel
    # keyword-only parameters count: nine of them make a wide function
    assert (got["wide"].parameters, got["wide"].all_parameters) == (1, 9)
    assert [f.qualname for f in wide_public(list(got.values()))] == ["wide"]
    assert not long_functions(list(got.values()), 4)
    assert [f.qualname for f in long_functions(list(got.values()), 2)] == ["K.m", "f"]
    assert len(functions()) > 100


def test_the_code_cites_no_issue_tracker():
    """The package, its tests, benchmarks, examples, scenes and docs say what they do and
    check, not which ticket asked for it."""
    rx = re.compile(r"\b[Ii]ssues? \d+\b|red[- ]team")
    files = [*PKG.rglob("*.py"), *(ROOT / "tests").glob("*.py"),
             *(ROOT / "benchmarks").glob("*.py"), *(ROOT / "examples").glob("*.py"),
             *(ROOT / "scenes").glob("*.toml"), *(ROOT / "docs").glob("*.md"),
             ROOT / "README.md"]
    hits = [f"{p.relative_to(ROOT)}:{k}" for p in files if p != Path(__file__)
            for k, line in enumerate(p.read_text().splitlines(), 1) if rx.search(line)]
    assert not hits, hits


def test_every_exception_is_defined_in_errors():
    """scikit-learn's one ``exceptions`` module: every exception class rtsgeom raises on
    purpose lives in rtsgeom/errors.py."""
    where = [f"{p.relative_to(ROOT)}: {node.name}" for p in PKG.rglob("*.py")
             if p.name != "errors.py"
             for node in ast.walk(ast.parse(p.read_text())) if isinstance(node, ast.ClassDef)
             and any(isinstance(b, ast.Name) and (b.id.endswith(("Error", "Exception"))
                                                 or b.id in ("KeyboardInterrupt",))
                     for b in node.bases)]
    assert not where, where


def test_every_error_is_one_the_cli_reports():
    """The CLI reports one class (``RtsgeomError``, exit 2): every error in errors.py derives
    from it, the control-flow ``Terminated`` and the warnings aside."""
    import rtsgeom.errors as errors
    classes = [getattr(errors, n) for n in errors.__all__]
    errs = [c for c in classes if issubclass(c, Exception) and not issubclass(c, Warning)]
    assert errs and all(issubclass(c, errors.RtsgeomError) for c in errs)
    assert not issubclass(errors.Terminated, errors.RtsgeomError)


def _user_docs() -> list[Path]:
    return [*(ROOT / "docs").glob("*.md"), ROOT / "README.md"]


def test_the_user_docs_say_what_is():
    """docs/*.md and the README describe the current state; the history, with its before and
    after numbers, is CHANGELOG.md's ("The calibration used to fit ..." was history)."""
    rx = re.compile(r"(?<!\bis )(?<!\bare )(?<!\bbe )\bused to\b")
    hits = [f"{p.relative_to(ROOT)}:{k}" for p in _user_docs()
            for k, line in enumerate(p.read_text().splitlines(), 1) if rx.search(line)]
    assert not hits, hits


def test_the_docs_run_the_tests_with_the_checkouts_interpreter():
    """Every pytest command in the docs is the README's (``.venv/bin/python -m pytest``), not a
    bare ``python3``, which is another interpreter without the package's dependencies."""
    rx = re.compile(r"(^|[\s;&|(])python3? -m pytest")
    hits = [f"{p.relative_to(ROOT)}:{k}" for p in _user_docs()
            for k, line in enumerate(p.read_text().splitlines(), 1) if rx.search(line)]
    assert not hits, hits


def test_running_the_examples_from_a_checkout_leaves_git_status_clean():
    """The examples write into ``example_output/`` of the working folder; run from the
    checkout's root or from ``examples/``, git ignores it."""
    import shutil
    import subprocess
    if shutil.which("git") is None or not (ROOT / ".git").exists():
        pytest.skip("not a git checkout")
    for where in ("example_output/calibration_sweep.png",
                  "examples/example_output/calibration_sweep.png"):
        r = subprocess.run(["git", "check-ignore", "-q", where], cwd=ROOT)
        assert r.returncode == 0, f"{where} is not ignored"


#: test files at the top of ``tests/``: the package's face (``api.py``, the public names, the
#: contracts of every command) and the project around it (docs, examples, benchmarks, layout)
PROJECT_TESTS = {"test_api.py", "test_api_names.py", "test_contracts.py", "test_structure.py",
                 "test_docs.py", "test_examples.py", "test_add_a_study.py",
                 "test_benchmark_io.py", "test_mutation_driver.py"}


def test_the_tests_mirror_the_package():
    """``tests/<subpackage>/`` for every subpackage of ``rtsgeom`` and nothing else; the top of
    ``tests/`` holds only the tests of the package's face and of the project around it."""
    subpackages = {p.parent.name for p in PKG.glob("*/__init__.py")}
    folders = {p.name for p in (ROOT / "tests").iterdir()
               if p.is_dir() and not p.name.startswith((".", "__"))}
    assert folders == subpackages, (sorted(folders - subpackages), sorted(subpackages - folders))
    for folder in folders:
        assert (ROOT / "tests" / folder / "__init__.py").exists(), folder
        assert list((ROOT / "tests" / folder).glob("test_*.py")), folder
    top = {p.name for p in (ROOT / "tests").glob("test_*.py")}
    assert top <= PROJECT_TESTS, sorted(top - PROJECT_TESTS)
