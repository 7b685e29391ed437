"""Fuzz the scene loader: mutated documents and mutated bytes of the default scene.

Every input must end in a valid :class:`~rtsgeom.scene.scene.Scene` (all numbers finite, and
``scene_warnings`` runs on it) or in a :class:`~rtsgeom.scene.scene.SceneError` whose message starts
with the source name; anything else (another exception, a NaN, an input slower than
``--max-seconds``) is reported and the exit code is 1.

    python -m benchmarks.fuzz_scene --inputs 100000 --seed 0
    python -m benchmarks.fuzz_scene --replay 1234 --seed 0     # re-run one input, show it
    python -m benchmarks.fuzz_scene --engine atheris --inputs 100000   # coverage-guided

Input ``i`` of seed ``s`` is reproducible on its own (its generator is seeded with ``(s, i)``),
so a failure report names what ``--replay`` needs. ``tests/cli/test_fuzz.py`` drives the same
mutators from hypothesis (through ``random.Random`` instances it controls).
"""

from __future__ import annotations

import argparse
import collections
import copy
import dataclasses
import datetime as dt
import math
import random
import re
import signal
import sys
import time
import tomllib
import traceback
from pathlib import Path

from rtsgeom.errors import SceneError
from rtsgeom.scene import loads_scene, parse_scene
from rtsgeom.geometry.warnings import scene_warnings

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_SCENE = ROOT / "scenes" / "diewald2022.toml"
DEFAULT_BYTES = DEFAULT_SCENE.read_bytes()
DEFAULT_DOC = tomllib.loads(DEFAULT_BYTES.decode())
SOURCE = "fuzz.toml"

__all__ = ["mutate_doc", "mutate_bytes", "check_outcome", "check_finite", "FuzzFailure",
           "run_one", "main"]


class FuzzFailure(AssertionError):
    """The loader broke its contract on an input (not a plain rejection)."""


# --------------------------------------------------------------------------------------------
# Random values of every TOML type, weighted towards the edges
# --------------------------------------------------------------------------------------------

SPECIAL_NUMBERS = [
    math.nan, -math.nan, math.inf, -math.inf, -0.0, 0.0, 1e308, -1e308, 5e-324, 1e-300,
    10**30, -10**30, 2**63, -2**63 - 1, 10**400, -1, 0, 1, 2**31, 0.5, 1e-9, 1e9, 77e9,
]
_CHARS = ("abcxyz_-. /\\\"'#=[]{}\n\t\r\x00\x01\x1b\x7f\u00e9\u4e2d\U0001f600\u202e\ufeff")
_KEYS = ["x", "radar", "rts", "sheet", "targets", "front_ends", "angle_deg", "range_m",
         "f_c_hz", "enabled", "cfar", "name", "structure", "mesh", "", " ", "a.b", "\u00e9"]
_NUMBER_TEXT = re.compile(rb"(?<==)[ ]*([-+0-9.eE_x]+|nan|inf|true|false|\"[^\"\n]*\")")
TOKENS = [
    b"nan", b"-nan", b"inf", b"-inf", b"-0.0", b"+0", b"1e999", b"1e-999", b"9" * 30,
    b"9" * 5000, b"0x7fffffffffffffff", b"0o777", b"0b1", b"1_000", b"1__0", b"01", b"1.",
    b"[", b"]", b"[[", b"]]", b"{", b"}", b"=", b"\"", b"'", b"'''", b"\"\"\"", b"\\", b"\\u0000",
    b"\n", b"\r\n", b"\x00", b"\xff", b"\xc3", b"\xef\xbb\xbf", b"true", b"false", b"#",
    b"1979-05-27T07:32:00Z", b"07:32:00", b"1979-05-27", b"[radar]", b"[rts]", b"[sheet]",
    b"[[rts.front_ends]]", b"[[targets]]", b"[[structure]]", b"[radar.cfar]", b",", b".",
    b"x = 1\n", b"[" * 3000, b"a" * 70000,
    # keys tomllib takes seconds to minutes on (quadratic in the dotted parts): refused first
    b"\n" + b".".join([b"k"] * 5000) + b" = 1\n", b"\n[" + b".".join([b'"q"'] * 5000) + b"]\n",
    b"\n" + b"k" * 2000 + b" = 1\n",
]


def random_value(rng: random.Random, depth: int = 0):
    """A random value of a type TOML can hold (no None, no tuples)."""
    kind = rng.randrange(11 if depth < 3 else 7)
    if kind == 0:
        return rng.choice(SPECIAL_NUMBERS)
    if kind == 1:
        return rng.choice((-1.0, 1.0)) * 10.0 ** rng.uniform(-320.0, 308.0)
    if kind == 2:
        return rng.choice((-1, 1)) * rng.randrange(10 ** rng.randrange(1, 40))
    if kind == 3:
        return rng.random() < 0.5
    if kind == 4:
        return "".join(rng.choice(_CHARS) for _ in range(rng.randrange(12)))
    if kind == 5:
        return rng.choice(("x" * rng.choice((201, 5000, 100_000)), "itu_metal", "hann", "ca"))
    if kind == 6:
        return rng.choice((dt.date(1979, 5, 27), dt.time(7, 32),
                           dt.datetime(1979, 5, 27, 7, 32, tzinfo=dt.timezone.utc)))
    if kind == 7:
        return [random_value(rng, depth + 1) for _ in range(rng.randrange(5))]
    if kind == 8:
        return {rng.choice(_KEYS): random_value(rng, depth + 1) for _ in range(rng.randrange(4))}
    if kind == 9:  # an array of tables
        return [{rng.choice(_KEYS): random_value(rng, depth + 1)} for _ in range(rng.randrange(4))]
    return [rng.uniform(-2.0, 2.0) for _ in range(rng.choice((1, 2, 3, 4)))]


# --------------------------------------------------------------------------------------------
# Document mutations
# --------------------------------------------------------------------------------------------


def _slots(node, out=None) -> list[tuple[object, object]]:
    """Every (container, key-or-index) of a document, depth first."""
    out = [] if out is None else out
    items = node.items() if isinstance(node, dict) else enumerate(node)
    for k, v in list(items):
        out.append((node, k))
        if isinstance(v, (dict, list)):
            _slots(v, out)
    return out


def _scale(v, rng: random.Random):
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        return random_value(rng)
    f = rng.choice((-1, 0, 0.5, 2, 10, 1000, 1e-3, 1 + 1e-9, 1 - 1e-9, 1e100, 1.1, 0.9, 3))
    try:
        return v * f
    except OverflowError:  # an integer beyond the float range times a float
        return v


def _retype(v, rng: random.Random):
    if isinstance(v, bool):
        return int(v)
    if isinstance(v, (int, float)):
        return rng.choice((str(v), [v], {"value": v}, bool(v)))
    if isinstance(v, str):
        try:
            return float(v)
        except ValueError:
            return [v]
    if isinstance(v, list):
        return v[0] if v else {}
    if isinstance(v, dict):
        return list(v.values())
    return str(v)


def mutate_doc(doc: dict, rng: random.Random, n_ops: int | None = None) -> dict:
    """Apply 1-4 random mutations to ``doc`` in place (and return it).

    Mutations: set a value of a random type, scale a number (out of range, or just across a
    consistency limit), delete a key or array element, add an unknown key or an element, swap
    two subtrees, change a value's type.
    """
    for _ in range(n_ops if n_ops is not None else rng.randint(1, 4)):
        slots = _slots(doc)
        if not slots:
            doc[rng.choice(_KEYS)] = random_value(rng)
            continue
        parent, key = rng.choice(slots)
        op = rng.randrange(7)
        if op == 0:
            parent[key] = random_value(rng)
        elif op == 1:
            parent[key] = _scale(parent[key], rng)
        elif op == 2:
            del parent[key]
        elif op == 3:
            if isinstance(parent, dict):
                parent[rng.choice(_KEYS) + rng.choice(("", "_x", "_deg"))] = random_value(rng)
            else:
                parent.insert(rng.randrange(len(parent) + 1),
                              copy.deepcopy(rng.choice(parent)) if parent and rng.random() < 0.7
                              else random_value(rng))
        elif op == 4:
            p2, k2 = rng.choice(slots)
            a, b = copy.deepcopy(parent[key]), copy.deepcopy(p2[k2])
            try:
                parent[key], p2[k2] = b, a
            except (IndexError, KeyError):  # the first write removed the second slot's parent
                pass
        elif op == 5:
            parent[key] = _retype(parent[key], rng)
        else:  # change a number slightly: near the limits of what the loader allows
            v = parent[key]
            try:
                step = rng.choice((-1, 1)) * abs(v or 1) * 10.0 ** rng.uniform(-12, 1)
                parent[key] = v + step
            except (TypeError, OverflowError):  # not a number, or an integer beyond floats
                parent[key] = random_value(rng)
    return doc


# --------------------------------------------------------------------------------------------
# Byte mutations
# --------------------------------------------------------------------------------------------

_VALUE_SPANS = [m.span(1) for m in _NUMBER_TEXT.finditer(DEFAULT_BYTES)]


def mutate_bytes(raw: bytes, rng: random.Random, n_ops: int | None = None) -> bytes:
    """Apply 1-4 random byte-level mutations to TOML text."""
    buf = bytearray(raw)
    for _ in range(n_ops if n_ops is not None else rng.randint(1, 4)):
        op = rng.randrange(9)
        n = len(buf)
        pos = rng.randrange(n + 1)
        if op == 0 and n:  # flip a bit
            i = rng.randrange(n)
            buf[i] ^= 1 << rng.randrange(8)
        elif op == 1 and n:  # random byte
            buf[rng.randrange(n)] = rng.randrange(256)
        elif op == 2:  # insert a token
            buf[pos:pos] = rng.choice(TOKENS)
        elif op == 3 and n:  # delete a span
            buf[pos:pos + rng.randrange(1, 64)] = b""
        elif op == 4 and n:  # duplicate a span
            span = bytes(buf[pos:pos + rng.randrange(1, 200)])
            q = rng.randrange(n + 1)
            buf[q:q] = span
        elif op == 5:  # swap two lines
            lines = bytes(buf).split(b"\n")
            i, j = rng.randrange(len(lines)), rng.randrange(len(lines))
            lines[i], lines[j] = lines[j], lines[i]
            buf = bytearray(b"\n".join(lines))
        elif op == 6:  # replace a value (where the default scene has one)
            a, b = rng.choice(_VALUE_SPANS)
            buf[a:b] = rng.choice(TOKENS[:30])
        elif op == 7:  # truncate
            del buf[pos:]
        else:  # random bytes
            buf[pos:pos] = bytes(rng.randrange(256) for _ in range(rng.randrange(1, 16)))
    return bytes(buf)


# --------------------------------------------------------------------------------------------
# The contract
# --------------------------------------------------------------------------------------------


def check_finite(obj, where: str = "scene") -> None:
    """Every float of a (frozen) dataclass tree, and the derived figures, must be finite."""
    if dataclasses.is_dataclass(obj):
        for f in dataclasses.fields(obj):
            check_finite(getattr(obj, f.name), f"{where}.{f.name}")
        for name in ("slope_hz_per_s", "f_center_hz", "wavelength_m", "sampled_bandwidth_hz",
                     "range_resolution_m", "max_range_m", "max_velocity_mps",
                     "velocity_resolution_mps", "delay_resolution_s", "rcs_m2"):
            if hasattr(type(obj), name):
                check_finite(getattr(obj, name), f"{where}.{name}")
    elif isinstance(obj, (tuple, list)):
        for i, x in enumerate(obj):
            check_finite(x, f"{where}[{i}]")
    elif isinstance(obj, float) and not math.isfinite(obj):
        raise FuzzFailure(f"valid scene with a non-finite number: {where} = {obj}")


def check_outcome(load, *args) -> tuple[str, str]:
    """Run ``load(*args)``; return ("valid", "") or ("rejected", the error message). Raise
    :class:`FuzzFailure` (or let any unexpected exception through) when the contract is broken."""
    try:
        scene = load(*args)
    except SceneError as exc:
        msg = str(exc)
        if not msg.startswith(f"{SOURCE}: "):
            raise FuzzFailure(f"SceneError without the source name: {msg[:300]!r}") from None
        if len(msg) > 2000:
            raise FuzzFailure(f"SceneError message of {len(msg)} characters") from None
        return "rejected", msg
    check_finite(scene)
    warnings = scene_warnings(scene)
    if not all(isinstance(w, str) and w.startswith(f"{SOURCE}: ") for w in warnings):
        raise FuzzFailure(f"malformed warnings: {warnings!r}"[:500])
    return "valid", ""


def make_input(seed: int, i: int, mode: str):
    """Input ``i``: ("doc", dict) or ("bytes", bytes)."""
    rng = random.Random(f"{seed}:{i}")
    kind = mode if mode != "mixed" else ("doc", "bytes")[i % 2]
    if kind == "doc":
        return kind, mutate_doc(copy.deepcopy(DEFAULT_DOC), rng)
    return kind, mutate_bytes(DEFAULT_BYTES, rng)


def run_one(kind: str, data) -> tuple[str, str]:
    if kind == "doc":
        return check_outcome(parse_scene, data, SOURCE, ROOT / "scenes")
    return check_outcome(loads_scene, data, SOURCE, ROOT / "scenes")


_FIELD = re.compile(r"^fuzz\.toml: (.*?)(?: = | is |: |\s\()")


class _Slow(Exception):
    pass


def _alarm(signum, frame):
    raise _Slow()


def run_random(inputs: int, seed: int, mode: str, max_seconds: float, quiet: bool) -> int:
    counts = collections.Counter()
    fields = collections.Counter()
    failures = []
    use_alarm = hasattr(signal, "setitimer")
    if use_alarm:
        signal.signal(signal.SIGALRM, _alarm)
    t_start = time.perf_counter()
    worst = (0.0, -1)
    for i in range(inputs):
        kind, data = make_input(seed, i, mode)
        t0 = time.perf_counter()
        try:
            if use_alarm:
                signal.setitimer(signal.ITIMER_REAL, max_seconds)
            outcome, msg = run_one(kind, data)
            if use_alarm:
                signal.setitimer(signal.ITIMER_REAL, 0)
            counts[outcome] += 1
            counts[f"{kind}:{outcome}"] += 1
            if outcome == "rejected":
                m = _FIELD.match(msg)
                fields[re.sub(r"\[\d+\]", "[i]", m.group(1)) if m else "(file level)"] += 1
        except _Slow:
            failures.append((i, kind, f"slower than {max_seconds} s"))
        except Exception as exc:  # noqa: BLE001 - this is what a fuzzer is for
            if use_alarm:
                signal.setitimer(signal.ITIMER_REAL, 0)
            tb = traceback.format_exception(exc)
            failures.append((i, kind, "".join(tb[-3:]).strip()))
        dt_i = time.perf_counter() - t0
        worst = max(worst, (dt_i, i))
        if not quiet and (i + 1) % 10_000 == 0:
            print(f"  {i + 1} inputs, {time.perf_counter() - t_start:.1f} s", file=sys.stderr)
    elapsed = time.perf_counter() - t_start
    print(f"inputs:     {inputs} (seed {seed}, mode {mode})")
    print(f"valid:      {counts['valid']} (doc {counts['doc:valid']}, "
          f"bytes {counts['bytes:valid']})")
    print(f"rejected:   {counts['rejected']} (SceneError; doc {counts['doc:rejected']}, "
          f"bytes {counts['bytes:rejected']})")
    print(f"unexpected: {len(failures)}")
    print(f"time:       {elapsed:.1f} s ({inputs / elapsed:.0f} inputs/s; slowest input "
          f"#{worst[1]}: {worst[0] * 1e3:.1f} ms)")
    print("most frequent rejecting fields:")
    for name, k in fields.most_common(12):
        print(f"  {k:7d}  {name}")
    for i, kind, text in failures[:20]:
        print(f"\n--- input {i} ({kind}; replay: --replay {i} --seed {seed} --mode {mode})\n{text}")
    return 1 if failures else 0


def replay(seed: int, i: int, mode: str) -> int:
    kind, data = make_input(seed, i, mode)
    print(f"input {i} ({kind}):")
    print(repr(data)[:4000])
    try:
        print("outcome: %s %s" % run_one(kind, data))
    except Exception:  # noqa: BLE001
        traceback.print_exc()
        return 1
    return 0


def run_atheris(inputs: int, seed: int) -> int:  # pragma: no cover - optional engine
    """Coverage-guided fuzzing of ``loads_scene`` with atheris (libFuzzer), if installed."""
    import atheris
    import tempfile

    counts = collections.Counter()

    def one(data: bytes) -> None:
        counts[check_outcome(loads_scene, data, SOURCE, ROOT / "scenes")[0]] += 1
        if sum(counts.values()) == inputs:
            print(f"inputs: {inputs}  valid: {counts['valid']}  rejected: {counts['rejected']}  "
                  "unexpected: 0", flush=True)

    atheris.instrument_all()  # coverage feedback from every loaded Python function
    corpus = tempfile.mkdtemp(prefix="rtsgeom-fuzz-")
    Path(corpus, "default.toml").write_bytes(DEFAULT_BYTES)
    atheris.Setup([sys.argv[0], f"-runs={inputs}", f"-seed={seed + 1}", "-max_len=8192",
                   "-timeout=5", corpus], one)
    atheris.Fuzz()  # exits the process; a crash prints the input and exits non-zero
    return 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.fuzz_scene", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--inputs", type=int, default=100_000, help="inputs to try (default 100000)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--mode", choices=("mixed", "doc", "bytes"), default="mixed",
                    help="mutate parsed documents, raw bytes, or alternate (default)")
    ap.add_argument("--max-seconds", type=float, default=2.0,
                    help="an input slower than this counts as a failure (hang guard)")
    ap.add_argument("--engine", choices=("random", "atheris"), default="random")
    ap.add_argument("--replay", type=int, metavar="I", help="re-run input I and show it")
    ap.add_argument("--quiet", action="store_true", help="no progress lines")
    args = ap.parse_args(argv)
    if args.replay is not None:
        return replay(args.seed, args.replay, args.mode)
    if args.engine == "atheris":
        return run_atheris(args.inputs, args.seed)
    return run_random(args.inputs, args.seed, args.mode, args.max_seconds, args.quiet)


if __name__ == "__main__":
    sys.exit(main())
