"""The CLI starts without the heavy libraries: which modules a command imports, not
how long it takes (robust on a loaded machine), and the lazy parser is the complete one."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from rtsgeom.cli import COMMANDS, build_parser

ROOT = Path(__file__).resolve().parents[2]
SCENE = ROOT / "scenes" / "diewald2022.toml"

#: Loaded only by the commands that use them (3D view, ray tracing, clusters, figures, tables,
#: compiled kernels).
OPTIONAL = ("sionna", "mitsuba", "drjit", "pyvista", "vtk", "dask", "distributed", "matplotlib",
            "pandas", "xarray", "trimesh", "rich", "numba", "llvmlite")

_PROBE = """
import json, runpy, sys
sys.argv = ["rtsgeom", *json.loads(sys.argv[1])]
try:
    runpy.run_module("rtsgeom", run_name="__main__", alter_sys=True)
except SystemExit as exc:
    code = exc.code
else:
    code = 0
with open(OUT, "w") as f:
    json.dump({"code": code, "modules": sorted(sys.modules)}, f)
"""


def _imported(args: list[str], tmp_path: Path) -> tuple[int, set[str]]:
    out = tmp_path / "modules.json"
    code = f"OUT = {str(out)!r}\n" + _PROBE
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    subprocess.run([sys.executable, "-c", code, json.dumps(args)], cwd=ROOT, env=env,
                   capture_output=True, text=True, timeout=120, check=False)
    res = json.loads(out.read_text())
    return res["code"], set(res["modules"])


def _loaded(modules: set[str], names) -> list[str]:
    return sorted(n for n in names if n in modules or any(m.startswith(n + ".") for m in modules))


def test_help_imports_no_numeric_library(tmp_path):
    code, mods = _imported(["--help"], tmp_path)
    assert code == 0
    heavy = _loaded(mods, ("numpy", "scipy", *OPTIONAL))
    assert heavy == [], f"rtsgeom --help imports {heavy}"
    # the CLI, its signal handling and the exceptions it reports (rtsgeom.errors imports
    # nothing), no pipeline stage
    assert not [m for m in mods if m.startswith("rtsgeom.")
                and m not in ("rtsgeom.cli", "rtsgeom.cli._signals", "rtsgeom.errors")], (
        "rtsgeom --help imports parts of the pipeline")


@pytest.mark.parametrize("args", [["info", str(SCENE)], ["info", str(SCENE), "--json"],
                                  ["run", "--help"], ["tolerance", "--help"]])
def test_commands_import_only_what_they_use(tmp_path, args):
    code, mods = _imported(args, tmp_path)
    assert code == 0
    heavy = _loaded(mods, OPTIONAL + ("scipy.signal", "scipy.optimize", "scipy.interpolate",
                                      "scipy.stats"))
    assert heavy == [], f"rtsgeom {' '.join(args)} imports {heavy}"


@pytest.mark.parametrize("args", [["ghosts", str(SCENE)], ["calibrate", "--help"],
                                  ["calibrate", str(SCENE), "--pair", "0", "1", "--json",
                                   "--quiet"]])
def test_commands_without_kernels_skip_numba(tmp_path, args):
    """The compiled kernels (numba, ~0.2 s to import and ~0.3 s to set up on the first call)
    load inside the functions that call them, and only once a process's work would pay for
    them (``_util.use_kernels``; before that the numpy definitions, the same bits): commands
    that never call one, and ``calibrate`` (a few thousand snapshots), do not pay for numba."""
    code, mods = _imported(args, tmp_path)
    assert code == 0
    assert _loaded(mods, ("numba", "llvmlite")) == [], f"rtsgeom {' '.join(args)} imports numba"


def test_calibrate_imports_only_what_it_uses(tmp_path):
    """``calibrate --pair 0 1`` (target: a new process under a second): matplotlib for its
    figure, none of the other optional libraries (numba: see above) and none of scipy's
    optimize/signal/interpolate/stats."""
    code, mods = _imported(["calibrate", str(SCENE), "--pair", "0", "1", "--quiet",
                            "--out", str(tmp_path / "cal")], tmp_path)
    assert code == 0
    assert (tmp_path / "cal" / "calibration.json").is_file()
    unused = [n for n in OPTIONAL if n not in ("numba", "llvmlite", "matplotlib")]
    heavy = _loaded(mods, (*unused, "scipy.signal", "scipy.optimize", "scipy.interpolate",
                           "scipy.stats"))
    assert heavy == [], f"rtsgeom calibrate imports {heavy}"


def test_unknown_command_is_a_one_line_error(tmp_path):
    code, _mods = _imported(["no-such-command"], tmp_path)
    assert code == 2


def _subparsers(parser):
    return next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")


def test_command_table_matches_the_modules():
    """The lazy table (name, module, help) is what the modules register, in the same order, and
    each command's lazily built parser equals its parser in the complete one."""
    full = _subparsers(build_parser())
    listed = [(a.dest, a.help) for a in full._choices_actions]
    assert listed == [(name, entry[1]) for name, entry in COMMANDS.items()]
    for name, (module, *_h) in COMMANDS.items():
        prog_full = full.choices[name]
        lazy = _subparsers(build_parser(name, lazy=True))
        assert lazy.choices[name].format_help() == prog_full.format_help()
        assert prog_full.get_default("func").__module__ == f"rtsgeom.cli.{module}"
    top_lazy = build_parser(None, lazy=True).format_help()
    assert top_lazy == build_parser().format_help()


@pytest.mark.parametrize("code", [0, 2, 130])
def test_the_console_entry_exits_with_mains_code_its_objects_frozen_first(monkeypatch, code):
    """``rtsgeom`` (console script, ``python -m rtsgeom``) is main's exit code; what the
    command left is frozen out of the garbage collector before the interpreter's teardown."""
    import gc

    import rtsgeom.cli as cli
    monkeypatch.setattr(cli, "main", lambda: code)
    gc.unfreeze()
    try:
        with pytest.raises(SystemExit) as exc:
            cli.console()
        assert exc.value.code == code
        assert gc.get_freeze_count() > 0
    finally:
        gc.unfreeze()
