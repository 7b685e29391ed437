"""What several commands of the CLI share: argument types and options, the front-end pair
words, ``--out`` staging, progress output, the calibration file of ``run``/``adc`` and the way
a result is written and printed.

Every command's module imports this one, ``rtsgeom info`` included: its own imports stay the
standard library, :mod:`rtsgeom.errors` and :mod:`rtsgeom._lib.io`; the helpers that need the
pipeline, figures or rich import them inside the function, so that a command does not load the
parts of the pipeline it does not use.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import sys
import time
from contextlib import contextmanager
from pathlib import Path

from .._lib.io import check_output_file, staged_dir
from ..errors import ParameterError, RtsgeomWarning, UsageError
from ._signals import raise_received

__all__ = ["UsageError", "number", "scene_arg", "print_json", "load_scene_checked", "steps",
           "output_path", "output_file_path", "output_folder", "output_file",
           "show_warning",
           "pair_word", "pair_of", "pair_options", "print_outputs", "progress", "study_options",
           "declared_option",
           "read_calibration", "calibration_kw", "flag_words", "flagged", "numbers"]


def number(lo=None, hi=None, integer=False):
    """argparse type: a finite number (or integer) within [lo, hi], with the range in errors."""
    def parse(text: str):
        try:
            v = int(text) if integer else float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"{text!r} is not {'an integer' if integer else 'a number'}") from None
        if not integer and not math.isfinite(v):
            raise argparse.ArgumentTypeError(f"{text!r} is not a finite number")
        if (lo is not None and v < lo) or (hi is not None and v > hi):
            raise argparse.ArgumentTypeError(f"{text} is outside the allowed range [{lo}, {hi}]")
        return v if integer else v + 0.0  # -0 reads as 0 (numpy refuses a scale of -0.0)
    return parse


def numbers(lo: float, hi: float, most: int, unit: str, example: str):
    """argparse type: ``START:STOP:STEP`` (STOP included, STEP > 0) or a comma-separated list
    of finite numbers, each in [lo, hi] ``unit``, at most ``most`` of them (the grid is refused
    from its count, before any array is made)."""
    def parse(text: str) -> tuple[float, ...]:
        def bad(why: str):
            return argparse.ArgumentTypeError(
                f"{text!r}: {why}; must be START:STOP:STEP (STEP > 0) or a comma-separated "
                f"list such as {example}, each in [{lo:g}, {hi:g}] {unit}, at most {most}")
        try:
            if ":" in text:
                a, b, step = (float(x) for x in text.split(":"))
                if not (step > 0 and b >= a and math.isfinite(a + b + step)):
                    raise bad("not a grid")
                n = math.floor((b - a) / step + 1e-9) + 1
                if n > most:
                    raise bad(f"{n} values")
                vals = tuple(round(a + k * step, 9) for k in range(n))
            else:
                vals = tuple(float(x) + 0.0 for x in text.split(",") if x.strip())
        except ValueError:
            raise bad("not numbers") from None
        if not vals or len(vals) > most:
            raise bad(f"{len(vals)} values")
        if not all(math.isfinite(v) and lo <= v <= hi for v in vals):
            raise bad("a value outside the range")
        return vals
    return parse


def flag_words(message: str, args: dict) -> str:
    """A library error in the words of the command line: the argument names before its first
    ``': '`` that are options of the command (``args``: the parsed namespace's dict) as their
    flags (``verify`` -> ``--verify``, ``invert_yield`` -> ``--invert-yield``)."""
    head, sep, tail = message.partition(": ")
    if not sep:
        return message
    names = {k for k in args if k not in ("scene", "func", "command")}

    def flag(m):
        return "--" + m.group(0).replace("_", "-") if m.group(0) in names else m.group(0)
    return re.sub(r"(?<![-\w./])[a-z][a-z_]*\b(?![-/.])", flag, head) + sep + tail


@contextmanager
def flagged(args):
    """Run a study in the words of the command line: a :class:`ParameterError` raised inside
    becomes the command's :class:`UsageError` (one line, exit 2) with the argument names that
    are the command's options written as its flags (:func:`flag_words`)."""
    try:
        yield
    except ParameterError as exc:
        raise UsageError(flag_words(str(exc), vars(args))) from None


def output_path(text: str) -> Path:
    """argparse type of ``--out`` (and ``--png``/``--html``): a non-empty path. (``Path('')`` is
    ``'.'``, the current folder, which an output folder swap would replace.)"""
    if text == "":
        raise argparse.ArgumentTypeError("'' names no file or folder")
    return Path(text)


def output_file_path(text: str) -> Path:
    """argparse type of an ``--out`` that names one file (``adc``, ``paths``): a trailing
    slash names a folder, which ``Path`` would drop (``newdir/`` became a *file* newdir)."""
    path = output_path(text)
    if text.endswith(("/", os.sep)):  # an existing folder: check_output_file names it
        raise argparse.ArgumentTypeError(f"{text!r} names a folder: give the file to write "
                                         f"(e.g. {text.rstrip('/' + os.sep) or '.'}/out.csv)")
    return path


@contextmanager
def output_folder(out, inputs=()):
    """``--out DIR`` of a command: the staging folder to write into (see
    :func:`rtsgeom._lib.io.staged_dir`), or None without ``--out``. Enter it BEFORE computing: the
    path is checked and the folder locked at once."""
    if out is None:
        yield None
        return
    with staged_dir(out, [i for i in inputs if i is not None],
                    before_swap=raise_received) as stage:
        yield stage


def output_file(out, inputs=()) -> Path:
    """Check an output file path before computing (exit 2 naming it); returns it."""
    check_output_file(out, [i for i in inputs if i is not None])
    return Path(out)


def scene_arg(p: argparse.ArgumentParser) -> None:
    p.add_argument("scene", type=Path, help="scene file (TOML), e.g. scenes/diewald2022.toml")


def print_json(obj) -> None:
    print(json.dumps(obj, indent=2, allow_nan=False))


def load_scene_checked(path):
    """Load and validate a scene (errors raise :class:`~rtsgeom.scene.scene.SceneError`, exit code 2)
    and print its physical warnings (``rtsgeom.geometry.warnings.scene_warnings``) to stderr as
    ``rtsgeom: warning: ...``. Every subcommand that reads a scene should load it with this."""
    from ..scene import load_scene
    from ..geometry.warnings import scene_warnings
    scene = load_scene(path)
    for line in scene_warnings(scene):
        print(f"rtsgeom: warning: {line}", file=sys.stderr)
    return scene


class steps:
    """Progress of a multi-step command on stderr (a spinner per step; silent when quiet).

    ``with steps(quiet) as step: step("calibrating"); ...`` prints each finished step with its
    duration, so a user sees what takes time. ``step.count(label, done, total)`` counts within
    a step (frames, pairs): on a terminal a bar with the time left, elsewhere plain lines
    ``rtsgeom: frame 240/1000 (24 %), 12.1 s, about 38.3 s left`` (:class:`LineProgress`).
    """

    def __init__(self, quiet: bool = False):
        self.quiet = quiet
        self._status = None
        self._bar = None
        self._label = None
        self._t0 = 0.0

    def __enter__(self):
        if not self.quiet:
            from rich.console import Console
            self._console = Console(stderr=True)
            self._lines = None if sys.stderr.isatty() else LineProgress(sys.stderr)
        return self

    def __call__(self, label: str) -> None:
        self._finish()
        if self.quiet:
            return
        self._label, self._t0 = label, time.perf_counter()
        self._status = self._console.status(label + " ...")
        self._status.start()

    def count(self, label: str, done: int, total: int) -> None:
        """``done`` of ``total`` within the current step (a bar or lines, see the class)."""
        if self.quiet:
            return
        if self._lines is not None:
            self._lines(label, done, total)
            return
        if self._bar is None:  # the step's spinner becomes a bar (one live display at once)
            from rich.progress import (BarColumn, MofNCompleteColumn, Progress, TextColumn,
                                       TimeElapsedColumn, TimeRemainingColumn)
            if self._status is not None:
                self._status.stop()
                self._status = None
            self._bar = Progress(TextColumn("{task.description}"), BarColumn(),
                                 MofNCompleteColumn(), TimeElapsedColumn(),
                                 TimeRemainingColumn(), console=self._console, transient=True)
            self._bar.start()
            self._task = self._bar.add_task(label, total=total)
        self._bar.update(self._task, description=label, completed=done, total=total)

    def _finish(self, failed: bool = False) -> None:
        live = self._status is not None or self._bar is not None
        for display in (self._status, self._bar):
            if display is not None:
                display.stop()
        self._status = self._bar = None
        if live and not failed:  # the error message follows; no duration for a failed step
            self._console.print(f"  {self._label}: {time.perf_counter() - self._t0:.1f} s",
                                style="dim", highlight=False, soft_wrap=True)

    def __exit__(self, exc_type, exc, tb):
        self._finish(failed=exc_type is not None)
        return False


def show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """``warnings.showwarning`` of the commands: rtsgeom's own warnings as
    ``rtsgeom: warning: <message>`` on stderr, any other (numpy's, a library's) as the same
    one line with its category: a user of the CLI never sees a source line."""
    if issubclass(category, RtsgeomWarning):
        print(f"rtsgeom: warning: {message}", file=sys.stderr)
    else:
        print(f"rtsgeom: warning: {category.__name__}: {message}", file=sys.stderr)


# -- the front-end pair: --pair I J | all, --cell Q.. | all ----------------------------------

def pair_word(text: str):
    """argparse type of one ``--pair`` (or ``--cell``) word: an index in [0, 10000] or
    ``all``."""
    if text == "all":
        return text
    return number(0, 10_000, integer=True)(text)


def pair_of(setup, pair, cells: bool = False):
    """The pair in its canonical order, the lower index first (I keeps its delay, J is
    swept): ``--pair 1 0`` and ``--pair 0 1`` are the same measurement and give the same
    numbers (the front ends are ordered by angle in the scene). ``cells``: a 2-D scene's
    neighbouring front ends are pairs too (``pipeline.plan.check_pair``)."""
    if len(pair) != 2 or "all" in pair:
        raise UsageError(f"--pair {' '.join(map(str, pair))}: must be two adjacent front-end "
                         "indices I J, or all")
    from ..pipeline.plan import check_pair
    i, j = pair
    try:
        return check_pair(setup, i, j, f"--pair {i} {j}", cells)
    except ParameterError as exc:
        raise UsageError(str(exc)) from None


def pair_options(p: argparse.ArgumentParser) -> None:
    """The scene and the options ``calibrate`` and ``linearity`` share: ``--pair I J | all``,
    ``--json``, ``--out``, ``--quiet``, ``--fir``."""
    scene_arg(p)
    p.add_argument("--pair", nargs="+", type=pair_word, metavar="I J | all",
                   default=[0, 1], help="adjacent front ends (default 0 1), or all: every "
                                        "adjacent pair of the arc in one run")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.add_argument("--out", type=output_path, default=None, help="folder for the plot and JSON")
    p.add_argument("--quiet", action="store_true", help="no progress output")
    p.add_argument("--fir", choices=("windowed-sinc", "ideal"), default=None,
                   help="fractional-delay filter model (default: the scene's "
                        "rts.fractional_delay_filter)")


# -- writing and printing a result ------------------------------------------------------------

def print_outputs(args, name: str, out: dict, text, files=None, code: int = 0) -> int:
    """Print the JSON (``--json``) or ``text(out)`` once the output folder is in place, and
    the files written (``files``, default NAME.json and NAME.png); returns ``code``, the
    command's exit status."""
    if args.json:
        print_json(out)
    else:
        print(text(out))
        if args.out:
            print(f"wrote {args.out}/" + ", ".join(files or (f"{name}.json", f"{name}.png")))
    return code


@contextmanager
def progress(quiet: bool):
    """A ``progress(label, done, total)`` callback on stderr (None when quiet): on a terminal
    one rich bar, relabelled at each stage, that appears with the first count; elsewhere (a
    log file, a pipe) plain lines ``rtsgeom: <label> 12/40 (30 %), 4.1 s, about 9.6 s left``, one
    every 10 % or 5 s and one at each stage's end."""
    if quiet:
        yield None
        return
    if not sys.stderr.isatty():
        yield LineProgress(sys.stderr)
        return
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
    with Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
                  TimeElapsedColumn(), console=Console(stderr=True), transient=True) as bar:
        task = None

        def update(label: str, done: int, total: int) -> None:
            nonlocal task
            if task is None:  # the bar appears with the first count, labelled and sized
                task = bar.add_task(label, total=total)
            bar.update(task, description=label, completed=done, total=total)
        yield update


class LineProgress:
    """``progress(label, done, total)`` as plain lines on ``stream``: one every ``step`` of
    the total or ``every_s`` seconds, whichever comes first, and one when a stage ends; the
    ETA from the stage's mean rate so far."""

    def __init__(self, stream, step: float = 0.1, every_s: float = 5.0, clock=time.monotonic):
        self.stream, self.step, self.every_s, self.clock = stream, step, every_s, clock
        self.label, self.last_frac = None, 0.0
        self.start = self.last_t = self.previous = clock()  # a stage starts where the last ended

    def __call__(self, label: str, done: int, total: int) -> None:
        now = self.clock()
        if label != self.label:
            self.label, self.last_frac = label, 0.0
            self.start = self.last_t = self.previous
        self.previous = now
        frac = done / total if total else 0.0
        end = bool(total) and done >= total
        if not (end or frac - self.last_frac >= self.step - 1e-12
                or now - self.last_t >= self.every_s):
            return
        self.last_t, self.last_frac = now, frac
        elapsed = now - self.start
        line = f"rtsgeom: {label} {done}/{total}" if total else f"rtsgeom: {label} {done}"
        if total:
            line += f" ({100 * frac:.0f} %), {elapsed:.1f} s"
            if 0 < done < total:
                line += f", about {elapsed * (total - done) / done:.1f} s left"
        print(line, file=self.stream, flush=True)
        if end:
            self.label = None  # a stage counted again from zero prints afresh


# -- the Monte-Carlo studies: tolerance and design ---------------------------------------------

def declared_option(p, name: str, arg, default, default_text: str | None = None, **kw) -> None:
    """``--name`` (underscores as dashes) made from a declared argument ``arg`` (kind, range or
    choices, help: ``analysis.tolerance.config.Arg``): its type checks the range and names it,
    its help states the range and the default."""
    def num(v):
        return str(int(v)) if arg.kind == "int" or float(v).is_integer() else f"{v:g}"
    if arg.choices is not None:
        kw.setdefault("choices", arg.choices)
        span = ""
    else:
        kw.setdefault("type", number(arg.lo, arg.hi, integer=arg.kind == "int"))
        span = f", in [{num(arg.lo)}, {num(arg.hi)}]" if arg.lo is not None else ""
    shown = default_text if default_text is not None else default
    p.add_argument(f"--{name.replace('_', '-')}", default=default,
                   help=f"{arg.help}{span} (default {shown})", **kw)


def study_options(p, declared: dict, draws_default: int, allow_all: bool = False) -> None:
    """The scene and the options ``tolerance`` and ``design`` share (``allow_all``:
    ``--pair I J | all``, else exactly two indices); ``declared``: the studies' arguments
    (``analysis.tolerance.config.STUDY_ARGS``), each option made from its declaration."""
    scene_arg(p)
    if allow_all:
        p.add_argument("--pair", nargs="+", type=pair_word, metavar="I J | all",
                       default=[0, 1], help="adjacent front ends (default 0 1), or all: every "
                                            "adjacent pair on shared per-front-end draws")
    else:
        p.add_argument("--pair", nargs=2, type=number(0, 10_000, integer=True),
                       metavar=("I", "J"), default=[0, 1], help="adjacent front ends (default 0 1)")
    declared_option(p, "spec_deg", declared["spec_deg"], 0.1)
    declared_option(p, "draws", declared["draws"], draws_default)
    declared_option(p, "seed", declared["seed"], None, "the scene's seed")
    declared_option(p, "points", declared["points"], 21)
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.add_argument("--out", type=output_path, default=None, help="folder for the plots and JSON")
    p.add_argument("--quiet", action="store_true", help="no progress bar on stderr")


# -- --calibration FILE of run and adc ---------------------------------------------------------

def read_calibration(path) -> dict | None:
    """``--calibration FILE``: the JSON ``rtsgeom calibrate --out DIR`` wrote
    (DIR/calibration.json), or None."""
    if path is None:
        return None
    try:
        doc = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise UsageError(f"--calibration {path}: cannot read it as JSON ({exc})") from None
    if not isinstance(doc, dict):
        raise UsageError(f"--calibration {path}: not a calibration file (a JSON object from "
                         "`rtsgeom calibrate SCENE --out DIR`)")
    return doc


def calibration_kw(args) -> dict:
    """``run_scene``'s calibration argument, only when ``--calibration`` was given (the
    call without it stays as it was)."""
    doc = read_calibration(getattr(args, "calibration", None))
    return {} if doc is None else {"calibration": doc}
