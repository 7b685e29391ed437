"""Fuzzing: the scene loader and the CLI never fail in an unplanned way.

Contract checked on every input: a valid :class:`Scene` with finite numbers (on which
``scene_warnings`` runs) or a :class:`SceneError` naming the source, within a deadline; for the
CLI, exit code 0 or 2 (argparse's ``SystemExit(2)`` counts as 2) and no other exception.

The mutators are shared with the standalone runner ``python -m benchmarks.fuzz_scene`` (which
tries 10^5 inputs); here hypothesis drives them through ``random.Random`` instances it controls,
so failures shrink. The whole file takes about 5 s.
"""

from __future__ import annotations

import argparse
import contextlib
import copy
import datetime as dt
import io
import math
import os
import signal
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rtsgeom.cli import build_parser, main
from rtsgeom.scene import loads_scene, parse_scene

from conftest import DEFAULT_SCENE, ROOT, default_doc

if str(ROOT) not in sys.path:  # benchmarks/ is a package at the repository root
    sys.path.insert(0, str(ROOT))
from benchmarks.fuzz_scene import (DEFAULT_BYTES, SOURCE, check_outcome,  # noqa: E402
                                   mutate_bytes, mutate_doc, random_value)

# RTSGEOM_FUZZ_EXAMPLES=5000 for a deeper run (the default keeps this file at about 5 s)
FUZZ = settings(max_examples=int(os.environ.get("RTSGEOM_FUZZ_EXAMPLES", "600")), deadline=2000,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


@contextlib.contextmanager
def hang_guard(seconds: float = 10.0):
    """Fail an example that runs for longer than ``seconds`` (hypothesis' deadline only
    measures examples that finish)."""
    if not hasattr(signal, "setitimer"):
        yield
        return

    def alarm(signum, frame):
        raise TimeoutError(f"input took longer than {seconds} s")
    old = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


@FUZZ
@given(rng=st.randoms(use_true_random=False))
def test_fuzz_mutated_documents(rng):
    doc = mutate_doc(copy.deepcopy(default_doc()), rng)
    with hang_guard():
        check_outcome(parse_scene, doc, SOURCE, ROOT / "scenes")


@FUZZ
@given(rng=st.randoms(use_true_random=False))
def test_fuzz_mutated_bytes(rng):
    raw = mutate_bytes(DEFAULT_BYTES, rng)
    with hang_guard():
        check_outcome(loads_scene, raw, SOURCE, ROOT / "scenes")


def _leaf_paths(node, prefix=()):
    items = node.items() if isinstance(node, dict) else enumerate(node)
    for k, v in items:
        if isinstance(v, (dict, list)):
            yield from _leaf_paths(v, prefix + (k,))
        else:
            yield prefix + (k,)


LEAVES = sorted(_leaf_paths(default_doc()), key=str)

TOML_VALUES = st.recursive(
    st.one_of(st.booleans(), st.integers(), st.integers(min_value=-10**400, max_value=10**400),
              st.floats(), st.floats(allow_nan=False, allow_infinity=False, width=32),
              st.text(max_size=30), st.dates(), st.times(), st.datetimes()),
    lambda inner: st.one_of(st.lists(inner, max_size=4),
                            st.dictionaries(st.text(max_size=8), inner, max_size=3)),
    max_leaves=8)


@FUZZ
@given(path=st.sampled_from(LEAVES), value=TOML_VALUES)
def test_fuzz_one_field_any_value(path, value):
    """Every field of the default scene, set to any value of any TOML type."""
    doc = copy.deepcopy(default_doc())
    node = doc
    for k in path[:-1]:
        node = node[k]
    node[path[-1]] = value
    with hang_guard():
        outcome, msg = check_outcome(parse_scene, doc, SOURCE, ROOT / "scenes")
    if outcome == "rejected":
        assert msg.startswith(f"{SOURCE}: ")


def test_mutators_are_deterministic_and_varied():
    import random
    a = [mutate_bytes(DEFAULT_BYTES, random.Random(i)) for i in range(50)]
    b = [mutate_bytes(DEFAULT_BYTES, random.Random(i)) for i in range(50)]
    assert a == b and len(set(a)) > 40
    outcomes = {check_outcome(parse_scene, mutate_doc(copy.deepcopy(default_doc()),
                                                      random.Random(i)), SOURCE)[0]
                for i in range(300)}
    assert outcomes == {"valid", "rejected"}  # the fuzzer reaches both ends
    values = [random_value(random.Random(i)) for i in range(300)]
    kinds = {type(v) for v in values}
    assert {bool, int, float, str, list, dict, dt.date}.issubset(kinds)


# --------------------------------------------------------------------------------------------
# The CLI argument parser
# --------------------------------------------------------------------------------------------


def _subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


PARSER = build_parser()
SUBCOMMANDS = _subcommands(PARSER)
OPTIONS = sorted({opt for sub in SUBCOMMANDS.values() for a in sub._actions
                  for opt in a.option_strings} | {"--version", "-h", "--help", "--bogus", "-"})
SAFE = {"info"}  # subcommands that only read: run for real; the others are only parsed


@pytest.fixture(scope="module")
def cli_dir(tmp_path_factory):
    """A folder with a valid scene, a bad one, a binary file and a sub-folder; the fuzzed CLI
    runs with this as its working directory, so relative paths stay inside it."""
    d = tmp_path_factory.mktemp("cli")
    (d / "scene.toml").write_bytes(DEFAULT_SCENE.read_bytes())
    (d / "bad.toml").write_text(DEFAULT_SCENE.read_text().replace("arc_radius_m = 1.0",
                                                                  "arc_radius_m = nan"))
    (d / "binary.toml").write_bytes(bytes(range(256)))
    (d / "folder").mkdir()
    return d


ARG_VALUES = st.one_of(
    st.sampled_from(["scene.toml", "bad.toml", "binary.toml", "missing.toml", "folder", ".",
                     "out.csv", "out.glb", "0", "-1", "1e999", "nan", "inf", "-inf", "9" * 5000,
                     "", " ", "--", "=", "exact", "raytrace"]),
    st.text(alphabet=st.characters(blacklist_categories=("Cs",), blacklist_characters="\x00/"),
            max_size=12),
    st.floats().map(str), st.integers().map(str))

ARGV = st.lists(st.one_of(st.sampled_from(sorted(SUBCOMMANDS)), st.sampled_from(OPTIONS),
                          ARG_VALUES), max_size=6)


def _argv_with_command():
    return st.tuples(st.sampled_from(sorted(SUBCOMMANDS)), ARGV).map(lambda t: [t[0], *t[1]])


def _argv_info():
    """``info SCENE [--json]``, sometimes with one stray token: gets past argparse often."""
    files = st.sampled_from(["scene.toml", "bad.toml", "binary.toml", "missing.toml", "folder"])
    stray = st.one_of(st.just([]), st.just([]), st.just([]),
                      st.lists(st.one_of(st.sampled_from(OPTIONS), ARG_VALUES), max_size=1))
    json = st.sampled_from([[], ["--json"]])
    return st.tuples(st.one_of(files, files, ARG_VALUES), json, stray
                     ).map(lambda t: ["info", t[0], *t[1], *t[2]])


@settings(max_examples=int(os.environ.get("RTSGEOM_FUZZ_EXAMPLES", "250")), deadline=3000,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(argv=st.one_of(ARGV, _argv_with_command(), _argv_info()))
def test_fuzz_cli_arguments(argv, cli_dir):
    before = sorted(p.name for p in cli_dir.iterdir())
    cwd = os.getcwd()
    os.chdir(cli_dir)
    out, err = io.StringIO(), io.StringIO()
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err), hang_guard():
            try:
                args = PARSER.parse_args(argv)
            except SystemExit as exc:
                code = exc.code
            else:
                if args.command in SAFE:
                    try:
                        code = main(argv)
                    except SystemExit as exc:
                        code = exc.code
                else:
                    code = 0  # parsed; running it is out of scope (slow or writes files)
    finally:
        os.chdir(cwd)
    assert code in (0, 2), (argv, code, err.getvalue()[-500:])
    assert "Traceback" not in err.getvalue()
    if code == 2:
        assert err.getvalue().startswith(("usage:", "rtsgeom: error: ")), err.getvalue()[:300]
    assert sorted(p.name for p in cli_dir.iterdir()) == before  # nothing written


def test_cli_parser_knows_the_geometry_commands():
    assert {"info", "paths", "export-mesh"} <= set(SUBCOMMANDS)
    assert math.isfinite(len(OPTIONS)) and "--json" in OPTIONS


def test_hang_guard_interrupts():
    import time
    with pytest.raises(TimeoutError):
        with hang_guard(0.05):
            time.sleep(1.0)
    assert Path(os.getcwd()).exists()
