"""``python -m benchmarks.mutation``: mutation testing of the physics core with mutmut.

Not part of the test suite (minutes to hours). mutmut 3 rewrites every function of the mutated
modules into a trampoline that dispatches to the original or to one of its mutants (an operator,
a constant, a keyword argument changed), runs the test selection once to learn which tests reach
which function, and then runs, per mutant, only the tests that reach its function. A mutant
*survives* when those tests still pass: a change of the code that no test notices.

What this driver adds to ``mutmut run``:

* **every physics subpackage** (``SOURCES``): geometry/ (with the arc formula in
  _lib/arcmath.py), paths/ (exact, table), rts/, radar/ (the truth twin and the association
  included), synthesis/, calibration/, pipeline/ (plan, pair, run), identify/, the scenario code
  (scene/scenario.py, analysis/playback/), the calibration transfer, the extended objects
  (scene/objects.py's scatterers, the budget's merge, the shared-cell check, the object study),
  analysis/; ``--modules``
  picks some of them (names as in ``SOURCES``); a file in two modules' globs belongs to the
  more specific one. Left out: the ray tracer and its cross-check (paths/raytrace*,
  paths/crosscheck.py: Sionna, their tests are marked ``raytrace``), the scene's schema and
  rules (input validation: the hostile-input tests, not physics), pipeline/info.py and
  pipeline/output.py (the ``info`` text and the run's writers), cli/, viz/, api.py;
* **targeted fast tests**: each module's tests are the test files that import it and the
  core's (``tests_for``, ``CORE_TESTS``, found at every run: ``MODULES``); the selection is
  their union for the chosen modules, without the ``slow``
  marker, the ray tracer, and the tests that run a child process (marker ``subprocess``) or a
  dask cluster (a mutant is switched by an environment variable inside the forked test
  process, so a subprocess or a dask worker would run the unmutated code anyway, and they are
  slow); the commands' in-process tests (``main([...])``) are in;
* **a reproducible sample**: ``--sample N --seed K`` runs N mutants drawn with
  ``numpy.random.default_rng(K)``, stratified per module (each module's share of the sample is
  its share of all mutants, at least one); without ``--sample`` every mutant runs;
* **a report**: ``benchmarks/mutation-report.md`` and ``.json`` with the killed, survived (each
  survivor's diff) and timed-out mutants and the kill rate (killed + timed out) / (run).

mutmut copies the project into ``mutants/`` in the folder it runs in; this driver runs it in a
scratch copy (``--workdir``, default ``/tmp/rtsgeom-mutation``) whose ``pyproject.toml`` holds the
``[tool.mutmut]`` section of this project's pyproject with the module and test selection filled
in, so the worktree stays clean. ``mutmut run`` in the repository itself uses the same section
(all core modules, the union of their tests).

Equivalent mutants (no observable change, e.g. a changed default that every caller overrides)
are listed in ``EQUIVALENT`` with the reason; they are reported apart and left out of the rate.

    python -m benchmarks.mutation --sample 150 --seed 1
    python -m benchmarks.mutation --modules rts radar --sample 40 --seed 2
    python -m benchmarks.mutation --report-only          # rewrite the report from the last run
    python -m benchmarks.mutation --keep-mutants ...     # reuse the workdir's mutants
    python -m benchmarks.mutation --rerun-survivors      # after new tests: the survivors again
    python -m benchmarks.mutation --rerun-survivors --names NAME ...   # only these survivors

A module's tests are found from their imports, so a new module or test needs no entry; a new
physics subpackage needs one line in ``SOURCES`` (and ``[tool.mutmut]`` ``only_mutate`` in
pyproject.toml, which ``tests/test_mutation_driver.py`` keeps equal to it). New tests for a sample's survivors go to the test file of the module they check
(``tests/<subpackage>/test_<module>.py``); ``KILLED_BY`` names the test per
mutant, ``RENAMED`` a mutant's name in today's code where its function moved or was
renumbered (``benchmarks/mutation_tables.py``); judge the suite on a sample it was not
written for (a new ``--seed``).

    python -m benchmarks.mutation --rerun-survivors --workdir /tmp/mut-fresh4 --report mutation-report-seed4
"""

from __future__ import annotations

import argparse
import fnmatch
import json
import os
import shutil
import signal
import subprocess
import sys
import time
import tomllib
from collections import defaultdict
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
REPORT_MD = ROOT / "benchmarks" / "mutation-report.md"
REPORT_JSON = ROOT / "benchmarks" / "mutation-report.json"

#: the tests every physics module's sample runs besides its own importers: the closed forms
#: and invariants of the core and the tests written for earlier samples' survivors
CORE_TESTS = ("tests/geometry/test_properties.py", "tests/synthesis/test_signal_properties.py")

#: module -> its source globs (relative to the repository; ``*`` spans subfolders): every
#: physics subpackage as it stands. Each module's tests are the fast test files that import it
#: (:func:`tests_for`) and :data:`CORE_TESTS`, found anew at every run, so a new module or test
#: needs no entry here.
SOURCES: dict[str, tuple[str, ...]] = {
    "geometry": ("rtsgeom/geometry/*", "rtsgeom/_lib/arcmath.py"),
    "paths": ("rtsgeom/paths/exact.py", "rtsgeom/paths/table.py"),
    "rts": ("rtsgeom/rts/*",),
    "radar": ("rtsgeom/radar/*",),
    "synthesis": ("rtsgeom/synthesis/*",),
    "calibration": ("rtsgeom/calibration/*",),
    "pipeline": ("rtsgeom/pipeline/plan.py", "rtsgeom/pipeline/pair.py",
                 "rtsgeom/pipeline/run.py"),
    "identify": ("rtsgeom/identify/*",),
    "scenario": ("rtsgeom/scene/scenario.py", "rtsgeom/analysis/playback/*"),
    "transfer": ("rtsgeom/analysis/transfer.py", "rtsgeom/radar/channels.py"),
    "objects": ("rtsgeom/scene/objects.py", "rtsgeom/pipeline/merge.py",
                "rtsgeom/pipeline/cells.py", "rtsgeom/analysis/objects.py",
                "rtsgeom/analysis/object_design.py"),
    "analysis": ("rtsgeom/analysis/*",),
}


def tests_for(module: str) -> tuple[str, ...]:
    """The test files that import ``module``'s sources (``rtsgeom.<package>`` or one of its
    modules), and :data:`CORE_TESTS`."""
    names = set()
    for glob in SOURCES[module]:
        stem = glob.removesuffix("/*").removesuffix(".py").replace("/", ".")
        names.add(stem)
    found = set(CORE_TESTS)
    for t in sorted((ROOT / "tests").rglob("test_*.py")):
        text = t.read_text()
        if any(n in text for n in names):
            found.add(str(t.relative_to(ROOT)))
    return tuple(sorted(found))


# module -> (source globs, the fast test files that exercise it)
MODULES: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {
    m: (globs, tests_for(m)) for m, globs in SOURCES.items()}

# Functions outside the physics core although they sit in its modules: plotting, mesh export
# and JSON serialisation (their contracts are the CLI tests', which run subprocesses and are
# left out here). fnmatch patterns on the mutant name.
EXCLUDE = ("*figure*", "rtsgeom.geometry.export.*", "*to_dict*")

# the per-mutant tables (equivalent with reasons, killed by which test, renamed, not killed)
from benchmarks.mutation_tables import EQUIVALENT, KILLED_BY, NOT_KILLED, RENAMED


def _toml_list(xs) -> str:
    return "[" + ", ".join(json.dumps(str(x)) for x in xs) + "]"


def selection(modules: list[str]) -> tuple[list[str], list[str]]:
    """(source globs, existing test files) of the chosen modules."""
    globs = list(dict.fromkeys(g for m in modules for g in MODULES[m][0]))
    tests = sorted({t for m in modules for t in MODULES[m][1] if (ROOT / t).exists()})
    return globs, tests


def prepare(workdir: Path, modules: list[str], keep: bool = False) -> None:
    """A scratch copy of the project whose [tool.mutmut] names the chosen modules and tests.

    ``keep``: a workdir's ``mutants/`` from an earlier run stays (the copies are refreshed in
    place, keeping the sources' times): mutmut then mutates again only the files that changed
    and runs the stats again only for new tests (generating all mutants takes about 20 minutes
    of a loaded 2-core machine)."""
    if workdir.exists() and not (keep and (workdir / "mutants").is_dir()):
        shutil.rmtree(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc", ".hypothesis", ".pytest_cache")
    for d in ("rtsgeom", "tests", "scenes", "docs"):
        shutil.copytree(ROOT / d, workdir / d, ignore=ignore, dirs_exist_ok=True)
    # the result tables and helpers some tests read or import (test_calibration's sample of
    # the linearity grid, test_cell_calibration's benchmarks.cell_calibration)
    shutil.copytree(ROOT / "benchmarks", workdir / "benchmarks", dirs_exist_ok=True,
                    ignore=shutil.ignore_patterns("__pycache__", "*.md"))
    base = tomllib.loads((ROOT / "pyproject.toml").read_text()).get("tool", {})
    cfg = dict(base.get("mutmut", {}))
    globs, tests = selection(modules)
    cfg["only_mutate"] = globs
    cfg["also_copy"] = sorted(set(cfg.get("also_copy", [])) | {"benchmarks/"})
    cfg["pytest_add_cli_args_test_selection"] = tests
    ini = base.get("pytest", {}).get("ini_options", {})
    # the suite's own settings: its markers, and its warnings-as-errors (a mutant that makes
    # the package warn fails the tests there as it does in the suite)
    lines = ["[tool.pytest.ini_options]", 'testpaths = ["tests"]',
             "markers = " + _toml_list(ini.get("markers", [])),
             "filterwarnings = " + _toml_list(ini.get("filterwarnings", [])), "",
             "[tool.mutmut]"]
    for k, v in cfg.items():
        if isinstance(v, list):
            lines.append(f"{k} = {_toml_list(v)}")
        elif isinstance(v, bool):
            lines.append(f"{k} = {'true' if v else 'false'}")
        elif isinstance(v, (int, float)):
            lines.append(f"{k} = {v}")
        else:
            lines.append(f"{k} = {json.dumps(v)}")
    (workdir / "pyproject.toml").write_text("\n".join(lines) + "\n")


def _env() -> dict:
    env = dict(os.environ)
    env.pop("PYTHONPATH", None)  # the tests must import the mutated copy, never the worktree
    for k in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        env[k] = "1"
    env["RTSGEOM_FUZZ_EXAMPLES"] = env.get("RTSGEOM_FUZZ_EXAMPLES", "50")
    env["RTSGEOM_PROPERTY_EXAMPLES"] = env.get("RTSGEOM_PROPERTY_EXAMPLES", "15")
    return env


_GENERATE = """
from mutmut.__main__ import (copy_src_dir, copy_also_copy_files, setup_source_paths,
                             store_lines_covered_by_tests, create_mutants)
from mutmut.mutation.trampoline import set_mutant_under_test
import os
os.makedirs("mutants", exist_ok=True)
set_mutant_under_test("mutant_generation")
copy_src_dir(); copy_also_copy_files(); setup_source_paths(); store_lines_covered_by_tests()
create_mutants(2)
"""

_MUTMUT = [sys.executable, "-c", "import sys; from mutmut.__main__ import cli; "
           "sys.argv[0] = 'mutmut'; cli()"]

# ``--skip-clean``: mutmut's clean run (the sampled mutants' tests once on the unmutated code)
# repeats what its stats run has just done (every selected test on the unmutated code, which
# must pass); on a loaded machine it costs as much as the stats run
# mutmut runs its stats and clean tests in its own process, then waits for its mutant workers
# with os.wait(), which also returns a child a test forked there and left to end later (a
# forked figure or pool): mutmut then stopped with a KeyError in wait_for_result (seeds 41
# and 107, a geometry-only run). Such strays are reaped here and the wait goes on.
_REAP_STRAYS = (
    "import os as _os, datetime as _dt\n"
    "try:\n"
    "    import mutmut.workers.isolation as _iso\n"
    "except Exception:  # no mutmut project here: mutmut itself says why\n"
    "    _iso = None\n"
    "def _wait(self, timeout=None):\n"
    "    if self._no_tests_results:\n"
    "        return self._no_tests_results.pop(0)\n"
    "    while True:\n"
    "        pid, status = _os.wait()\n"
    "        if pid in self._running:\n"
    "            break\n"
    "    w = self._running.pop(pid)\n"
    "    return _iso.MutantResult(mutant_name=w.mutant_name,\n"
    "        exit_code=_os.waitstatus_to_exitcode(status),\n"
    "        duration=(_dt.datetime.now() - w.start_time).total_seconds())\n"
    "if _iso is not None:\n"
    "    _iso.ForkRunner.wait_for_result = _wait\n")

_SKIP_CLEAN = ("import mutmut.workers.isolation as iso\n"
               "for c in (iso.ForkServerRunner, iso.ForkRunner):\n"
               "    c.run_clean_tests = lambda self, tests: 0\n")


def all_mutants(workdir: Path) -> dict[str, list[str]]:
    """Generate the mutants (no tests run) and list their names per module of ``MODULES``."""
    subprocess.run([sys.executable, "-c", _GENERATE], cwd=workdir, env=_env(), check=True,
                   stdout=subprocess.DEVNULL)
    out: dict[str, list[str]] = defaultdict(list)
    for meta in sorted((workdir / "mutants").rglob("*.py.meta")):
        data = json.loads(meta.read_text())
        rel = str(meta.relative_to(workdir / "mutants"))[:-len(".meta")]
        mod = module_of(rel)
        if mod:
            out[mod].extend(k for k in sorted(data.get("exit_code_by_key", {}))
                            if not any(fnmatch.fnmatch(k, pat) for pat in EXCLUDE))
    return dict(out)


def module_of(path: str) -> str | None:
    """The module of ``MODULES`` a source file belongs to: of the globs it matches, the most
    specific (the longest: ``rtsgeom/radar/channels.py`` is ``transfer``'s, not ``radar``'s)."""
    hits = [(len(g), m) for m, (globs, _) in MODULES.items() for g in globs
            if fnmatch.fnmatch(path, g)]
    return max(hits)[1] if hits else None


def sample(names: dict[str, list[str]], n: int | None, seed: int) -> list[str]:
    """``n`` names, stratified per module (proportional, at least one each), reproducible."""
    total = sum(len(v) for v in names.values())
    if n is None or n >= total:
        return sorted(x for v in names.values() for x in v)
    rng = np.random.default_rng(seed)
    mods = sorted(names)
    share = np.array([len(names[m]) for m in mods], float) / total * n
    k = np.maximum(1, np.floor(share)).astype(int)
    # hand out what the floors left, largest remainders first (deterministic)
    for i in np.argsort(-(share - np.floor(share)), kind="stable")[:max(0, n - k.sum())]:
        k[i] += 1
    picked = []
    for m, km in zip(mods, k):
        pool = sorted(names[m])
        picked += [pool[i] for i in rng.choice(len(pool), size=min(km, len(pool)), replace=False)]
    return sorted(picked)


def run(workdir: Path, names: list[str], children: int, timeout_s: float,
        skip_clean: bool = False) -> float:
    """``mutmut run`` of ``names`` in ``workdir``, its output in ``mutmut-run.log``.

    mutmut runs in a process group of its own, ended when it exits: a mutant's test that forks
    a pool can leave workers behind (orphaned, blocked on mutmut's result pipe), and a run
    that waited for them, or for the end of an output pipe they hold, never returned."""
    t0 = time.perf_counter()
    cmd = list(_MUTMUT)
    cmd[2] = _REAP_STRAYS + (_SKIP_CLEAN if skip_clean else "") + cmd[2]
    log = workdir / "mutmut-run.log"
    with open(log, "w") as out:
        # pass the names through a file-free argv: mutmut matches each name exactly
        proc = subprocess.Popen(cmd + ["run", "--max-children", str(children), *names],
                                cwd=workdir, env=_env(), stdout=out, stderr=subprocess.STDOUT,
                                start_new_session=True)
        try:
            code = proc.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            code = None
        finally:
            _end_group(proc.pid)
    if code is None:
        raise SystemExit(f"mutmut run took more than --timeout-s {timeout_s:g} s; log: {log} "
                         "(run again with --keep-mutants to reuse the mutants and stats)")
    if code != 0:
        print(log.read_text()[-3000:], file=sys.stderr)
        raise SystemExit(f"mutmut run failed (exit {code}); log: {log}")
    return time.perf_counter() - t0


def _end_group(pgid: int) -> None:
    """SIGKILL to what is left of the process group ``pgid`` (the mutmut run's)."""
    try:
        os.killpg(pgid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass


_COLLECT = """
import json, sys
from mutmut.__main__ import SourceFileMutationData, walk_mutatable_files, get_diff_for_mutant
from mutmut.stats import status_by_exit_code
names = set(json.load(open(sys.argv[1])))
out = {}
for path in walk_mutatable_files():
    m = SourceFileMutationData(path=path)
    m.load()
    for k, code in m.exit_code_by_key.items():
        if k not in names:
            continue
        status = status_by_exit_code[code]
        diff = get_diff_for_mutant(k, path=path) if status not in ("killed",) else ""
        out[k] = {"status": status, "exit_code": code, "file": str(path),
                  "duration_s": m.durations_by_key.get(k), "diff": diff}
json.dump(out, open(sys.argv[2], "w"), indent=1)
"""


def collect(workdir: Path, names: list[str]) -> dict:
    (workdir / "sample.json").write_text(json.dumps(names))
    subprocess.run([sys.executable, "-c", _COLLECT, "sample.json", "results.json"], cwd=workdir,
                   env=_env(), check=True)
    return json.loads((workdir / "results.json").read_text())


def summarise(results: dict, meta: dict) -> dict:
    by: dict[str, list[str]] = defaultdict(list)
    for k, r in sorted(results.items()):
        status = ("equivalent" if k in EQUIVALENT and r["status"] in ("survived", "no tests")
                  else r["status"])
        by[status].append(k)
    killed = len(by["killed"]) + len(by["timeout"])
    counted = sum(len(v) for s, v in by.items() if s not in ("equivalent", "not checked"))
    per_module: dict[str, dict[str, int]] = defaultdict(lambda: defaultdict(int))
    for k, r in results.items():
        status = ("equivalent" if k in EQUIVALENT and r["status"] in ("survived", "no tests")
                  else r["status"])
        per_module[module_of(r["file"]) or "?"][status] += 1
    first = defaultdict(int)
    for r in results.values():
        first[r.get("first_status", r["status"])] += 1
    return {**meta, "counts": {s: len(v) for s, v in sorted(by.items())},
            "first_pass": dict(first),
            "kill_rate": killed / counted if counted else None,
            "per_module": {m: dict(v) for m, v in sorted(per_module.items())},
            "survivors": {k: results[k]["diff"] for k in by["survived"] + by["no tests"]
                          + by["suspicious"]},
            "equivalent": {k: {"reason": EQUIVALENT[k], "diff": results[k]["diff"]}
                           for k in by["equivalent"]},
            "killed_later": {k: {"first_status": r["first_status"], "diff": r.get("first_diff", ""),
                                 **({"renamed_to": r["renamed_to"]} if "renamed_to" in r else {})}
                             for k, r in sorted(results.items())
                             if r.get("first_status", r["status"]) != r["status"]
                             and r["status"] == "killed"},
            "timed_out": by["timeout"], "killed": by["killed"]}


def write_report(s: dict) -> None:
    REPORT_JSON.write_text(json.dumps(s, indent=1) + "\n")
    c = s["counts"]
    rate = "n/a" if s["kill_rate"] is None else f"{100 * s['kill_rate']:.1f} %"
    lines = [
        "# Mutation testing of the physics core (mutmut)", "",
        "Written by `python -m benchmarks.mutation` (see its docstring); not part of CI.", "",
        f"* command: `{s['command']}`",
        f"* mutmut {s['mutmut']}, modules: {', '.join(s['modules'])}",
        f"* mutants in these modules: {s['population']}; sampled: {s['sampled']} "
        f"(seed {s['seed']}, stratified per module)",
        f"* wall time: {s['wall_s']:.0f} s on {os.cpu_count()} cores ({s['children']} workers)",
        f"* excluded from the population (not physics): {', '.join(EXCLUDE)}",
        *([f"* first pass: {s['first_pass']}; then the survivors (and no-test mutants) were run "
           f"again after new tests: " + ", ".join(f"{r['mutants']} mutants in {r['wall_s']:.0f} s"
                                                  for r in s["reruns"])]
          if s.get("reruns") else []),
        *[f"* {n}" for n in s.get("notes", [])],
        "", f"**Kill rate: {rate}** = (killed + timed out) / (sampled - equivalent)", "",
        "| status | mutants |", "| --- | --- |",
        *[f"| {k} | {v} |" for k, v in c.items()], "",
        "Per module:", "", "| module | " + " | ".join(sorted(c)) + " |",
        "| --- |" + " --- |" * len(c),
        *[f"| {m} | " + " | ".join(str(v.get(k, 0)) for k in sorted(c)) + " |"
          for m, v in s["per_module"].items()], ""]
    if s["survivors"]:
        lines += ["## Survivors", ""]
        for k, d in s["survivors"].items():
            why = [NOT_KILLED[k], ""] if k in NOT_KILLED else []
            lines += [f"### `{k}`", "", *why, "```diff", d.strip(), "```", ""]
    if s["killed_later"]:
        lines += ["## First-pass survivors killed by later tests", "",
                  "Each was killed by a test added after the first pass (named below; in the "
                  "test file of the module it checks, `tests/<subpackage>/test_<module>.py`).",
                  ""]
        for k, d in s["killed_later"].items():
            by = [f"Killed by `{KILLED_BY[k]}`.", ""] if k in KILLED_BY else []
            if d.get("renamed_to"):
                by += [f"Run as `{d['renamed_to']}`: the same change in today's code (the "
                       "function moved or its mutants were renumbered since the sample).", ""]
            lines += [f"### `{k}` (first pass: {d['first_status']})", "", *by, "```diff",
                      d["diff"].strip(), "```", ""]
    if s["equivalent"]:
        lines += ["## Equivalent mutants (no observable change)", ""]
        for k, e in s["equivalent"].items():
            lines += [f"### `{k}`", "", e["reason"], "", "```diff", e["diff"].strip(), "```", ""]
    if s["timed_out"]:
        lines += ["## Timed out (counted as killed)", "", *[f"* `{k}`" for k in s["timed_out"]],
                  ""]
    REPORT_MD.write_text("\n".join(lines))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.mutation", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--modules", nargs="+", choices=sorted(MODULES), default=sorted(MODULES))
    ap.add_argument("--sample", type=int, default=None, help="mutants to run (default: all)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--children", type=int, default=2, help="parallel mutmut workers")
    ap.add_argument("--workdir", type=Path, default=Path("/tmp/rtsgeom-mutation"))
    ap.add_argument("--timeout-s", type=float, default=6 * 3600.0)
    ap.add_argument("--report-only", action="store_true",
                    help="rewrite the report from the run left in --workdir")
    ap.add_argument("--names", nargs="*", default=None,
                    help="run exactly these mutants (e.g. the survivors of a report)")
    ap.add_argument("--rerun-survivors", action="store_true",
                    help="run the last run's survivors again (after new tests) and merge")
    ap.add_argument("--report", default="mutation-report",
                    help="report name in benchmarks/ (NAME.md and NAME.json)")
    ap.add_argument("--keep-mutants", action="store_true",
                    help="reuse the mutants (and mutmut's stats) left in --workdir by an earlier "
                         "run; --rerun-survivors always does")
    ap.add_argument("--skip-clean", action="store_true",
                    help="skip mutmut's clean run of the sampled mutants' tests (its stats run "
                         "has run them all on the unmutated code already)")
    ap.add_argument("--note", action="append", default=[],
                    help="a line for the report's header (kept with the run's state)")
    a = ap.parse_args(argv)
    global REPORT_MD, REPORT_JSON
    REPORT_MD = ROOT / "benchmarks" / f"{a.report}.md"
    REPORT_JSON = ROOT / "benchmarks" / f"{a.report}.json"
    from importlib.metadata import version
    meta = {"command": "python -m benchmarks.mutation " + " ".join(argv if argv is not None
                                                                   else sys.argv[1:]),
            "mutmut": version("mutmut"), "modules": a.modules, "seed": a.seed,
            "children": a.children}
    state = a.workdir / "driver.json"
    previous: dict = {}
    if a.rerun_survivors:
        meta = json.loads(state.read_text())
        previous = json.loads((a.workdir / "results.json").read_text())
        rerun = sorted(k for k, r in previous.items()
                       if r["status"] in ("survived", "no tests", "suspicious")
                       and (not a.names or k in a.names))  # --names: only those of them
        prepare(a.workdir, meta["modules"], keep=True)
        present = {k for v in all_mutants(a.workdir).values() for k in v}
        # a mutant of code that moved since the sample runs under its new name (RENAMED);
        # one of code removed since is no longer generated: it keeps its first status
        run_as = {k: RENAMED.get(k, k) for k in rerun}
        gone = [k for k in rerun if run_as[k] not in present]
        rerun = [k for k in rerun if run_as[k] in present]
        if gone:
            print(f"no longer generated (code removed since): {', '.join(gone)}", flush=True)
        print(f"re-running {len(rerun)} survivors", flush=True)
        wall = run(a.workdir, [run_as[k] for k in rerun], a.children, a.timeout_s,
                   a.skip_clean)
        meta.setdefault("reruns", []).append({"mutants": len(rerun), "wall_s": round(wall, 1)})
        names = meta["names"]
        state.write_text(json.dumps(meta))
        got = collect(a.workdir, [run_as[k] for k in rerun])
        new = {}
        for k in rerun:
            r = new[k] = got[run_as[k]]
            if run_as[k] != k:
                r["renamed_to"] = run_as[k]
            r["first_status"] = previous[k].get("first_status", previous[k]["status"])
            r["first_diff"] = previous[k].get("first_diff") or previous[k]["diff"]
        previous.update(new)
        (a.workdir / "results.json").write_text(json.dumps(previous, indent=1))
    elif a.report_only:  # from the merged results the last run left
        meta = json.loads(state.read_text())
        names = meta["names"]
        previous = json.loads((a.workdir / "results.json").read_text())
    else:
        prepare(a.workdir, a.modules, keep=a.keep_mutants)
        population = all_mutants(a.workdir)
        names = a.names or sample(population, a.sample, a.seed)
        meta.update(population=sum(len(v) for v in population.values()), sampled=len(names),
                    population_per_module={m: len(v) for m, v in population.items()})
        print(f"{meta['population']} mutants in {', '.join(a.modules)}; running {len(names)}",
              flush=True)
        meta["wall_s"] = run(a.workdir, names, a.children, a.timeout_s, a.skip_clean)
        meta["names"] = names
        state.write_text(json.dumps(meta))
    if a.note:
        meta["notes"] = meta.get("notes", []) + a.note
        state.write_text(json.dumps({**meta, "names": names}))
    results = previous or collect(a.workdir, names)
    s = summarise(results, {k: v for k, v in meta.items() if k != "names"})
    write_report(s)
    rate = s["kill_rate"]
    print(f"kill rate {'n/a' if rate is None else f'{100 * rate:.1f} %'}; {s['counts']}; "
          f"report: {os.path.relpath(REPORT_MD, ROOT)}")  # a --report outside the tree too
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
