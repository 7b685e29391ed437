"""The mutation driver covers every physics subpackage as it stands: its sources name existing
files, every subpackage of the pipeline below the commands is sampled, each module has tests,
and pyproject's ``[tool.mutmut]`` (what ``mutmut run`` in the repository uses) is the driver's
selection."""

from __future__ import annotations

import fnmatch
import tomllib

from benchmarks.mutation import CORE_TESTS, MODULES, SOURCES, module_of, selection
from conftest import ROOT

SOURCE_FILES = [str(p.relative_to(ROOT)) for p in (ROOT / "rtsgeom").rglob("*.py")]


def test_every_glob_names_files_and_every_module_has_tests():
    for m, (globs, tests) in MODULES.items():
        for g in globs:
            assert any(fnmatch.fnmatch(f, g) for f in SOURCE_FILES), (m, g)
        assert set(CORE_TESTS) < set(tests), m
        assert all((ROOT / t).is_file() for t in tests), m


def test_every_physics_subpackage_is_sampled():
    for pkg in ("geometry", "paths", "rts", "radar", "synthesis", "calibration", "pipeline",
                "identify", "analysis"):
        files = [f for f in SOURCE_FILES if f.startswith(f"rtsgeom/{pkg}/")]
        assert any(module_of(f) for f in files), pkg
    assert module_of("rtsgeom/scene/scenario.py") == "scenario"
    assert module_of("rtsgeom/analysis/playback/study.py") == "scenario"
    assert module_of("rtsgeom/analysis/transfer.py") == "transfer"
    assert module_of("rtsgeom/analysis/tolerance/montecarlo.py") == "analysis"
    assert module_of("rtsgeom/paths/raytrace.py") is None  # Sionna: not in the fast tests
    # the drive's pieces: the truth twin and the association (radar), the extended objects'
    # scatterers and the budget's merge, and the arc formula every front end is placed by
    assert module_of("rtsgeom/radar/truth.py") == "radar"
    assert module_of("rtsgeom/radar/association.py") == "radar"
    for f in ("rtsgeom/scene/objects.py", "rtsgeom/pipeline/merge.py",
              "rtsgeom/pipeline/cells.py", "rtsgeom/analysis/objects.py"):
        assert module_of(f) == "objects", f
    assert module_of("rtsgeom/_lib/arcmath.py") == "geometry"
    assert "tests/scene/test_objects.py" in MODULES["objects"][1]


def test_pyproject_holds_the_drivers_selection():
    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["mutmut"]
    globs, tests = selection(sorted(SOURCES))
    assert sorted(cfg["only_mutate"]) == sorted(globs)
    # the tests: the driver's selection, found anew from the imports (a new test file of a
    # physics module joins it; `mutmut run` in the repository must run the same)
    listed = set(cfg["pytest_add_cli_args_test_selection"])
    assert set(CORE_TESTS) <= listed
    assert listed == set(tests), (sorted(set(tests) - listed), sorted(listed - set(tests)))
    assert all((ROOT / t).is_file() for t in listed)


def test_a_run_returns_when_mutmut_exits_and_ends_what_it_left(tmp_path, monkeypatch):
    """A mutant's test that forks a pool can leave workers behind mutmut, holding its output;
    the run returns when mutmut exits (it waited for them until --timeout-s, then failed
    without a report) and ends them."""
    import os
    import sys
    import time

    import benchmarks.mutation as driver
    code = ("import os, sys, time\n"
            "pid = os.fork()\n"
            "if pid == 0:\n"
            "    open('child.pid', 'w').write(str(os.getpid()))\n"
            "    time.sleep(60)\n"
            "    os._exit(0)\n"
            "while not os.path.exists('child.pid'):\n"
            "    time.sleep(0.01)\n"
            "print('mutmut done')\n")
    monkeypatch.setattr(driver, "_MUTMUT", [sys.executable, "-c", code])
    t0 = time.perf_counter()
    driver.run(tmp_path, ["a_mutant"], 1, timeout_s=30.0)
    assert time.perf_counter() - t0 < 15.0
    assert (tmp_path / "mutmut-run.log").read_text() == "mutmut done\n"
    pid = int((tmp_path / "child.pid").read_text())
    for _ in range(100):  # gone, or a zombie its new parent has not reaped yet
        try:
            state = (open(f"/proc/{pid}/status").read().split("State:")[1].split()[0]
                     if os.path.exists(f"/proc/{pid}") else "gone")
        except (FileNotFoundError, IndexError):
            state = "gone"
        if state in ("gone", "Z"):
            break
        time.sleep(0.05)
    assert state in ("gone", "Z")
