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
import sys
import time
from contextlib import contextmanager
from pathlib import Path

from .._lib.io import check_output_file, staged_dir, write_json
from ..errors import ParameterError, UsageError

__all__ = ["UsageError", "number", "scene_arg", "print_json", "load_scene_checked", "steps",
           "output_path", "output_file_path", "output_folder", "output_file",
           "warn_scene_errors", "show_warning",
           "pair_word", "pair_of", "pairs_of", "pair_options", "prepare_pair", "prepare_arc",
           "emit_result", "write_outputs", "print_outputs", "progress", "study_options",
           "read_calibration", "calibration_kw"]


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
        return v
    return parse


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
    with staged_dir(out, [i for i in inputs if i is not None]) as stage:
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


def warn_scene_errors(scene, command: str, what: str | None = None) -> None:
    """The library's :func:`~rtsgeom.geometry.setup.warn_setup_errors` for a command that
    calls no study that warns itself (``main`` prints the warning on stderr)."""
    from ..geometry.setup import DRAWS_REPLACE, warn_setup_errors
    warn_setup_errors(scene, command, DRAWS_REPLACE if what is None else what)


def show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """``warnings.showwarning`` of the commands: rtsgeom's own warnings as
    ``rtsgeom: warning: <message>`` on stderr, any other (numpy's, a library's) as the same
    one line with its category: a user of the CLI never sees a source line."""
    from ..errors import RtsgeomWarning
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


def pairs_of(setup, pair, cells: bool = False) -> list[tuple[int, int]]:
    """``--pair I J`` as one pair, or ``--pair all``: every adjacent pair of the arc (with
    ``cells``, every measured pair of a 2-D scene's cells: ``pipeline.plan.measured_pairs``)."""
    if list(pair) == ["all"]:
        n = setup.fe.count
        if n < 2:
            raise UsageError("--pair all: the arc needs at least two front ends")
        from ..pipeline.plan import measured_pairs, uses_cells
        if uses_cells(setup.scene):
            if not cells:
                pair_of(setup, (0, 1))  # the error that says what a 2-D scene takes instead
            return measured_pairs(setup)
        return [(i, i + 1) for i in range(n - 1)]
    return [pair_of(setup, pair, cells)]


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


def prepare_pair(args, cells: bool = False):
    """``--pair I J``: scene (with ``--fir`` applied), setup, the pair, exact paths and each
    front end alone as the RuT detects it (``cells``: :func:`pair_of`)."""
    from ..calibration.probes import probe_front_ends
    from ..geometry import build_setup
    from ..paths import exact_paths
    scene = _with_fir(load_scene_checked(args.scene), args)
    setup = build_setup(scene)
    pair = pair_of(setup, args.pair, cells)
    paths = exact_paths(setup)
    return scene, setup, pair, paths, probe_front_ends(setup, paths, scene.seed)


def _with_fir(scene, args):
    """The scene with ``--fir`` (the fractional-delay filter model) where it is given."""
    if getattr(args, "fir", None):
        scene = scene.evolve(rts=scene.rts.evolve(fractional_delay_filter=args.fir))
    return scene


def prepare_arc(args, cells: bool = False):
    """``--pair all``: scene, setup, every adjacent pair (``cells``: :func:`pairs_of`), exact
    paths, each front end alone."""
    from ..calibration.probes import probe_front_ends
    from ..geometry import build_setup
    from ..paths import exact_paths
    scene = _with_fir(load_scene_checked(args.scene), args)
    setup = build_setup(scene)
    pairs = pairs_of(setup, args.pair, cells)
    paths = exact_paths(setup)
    return scene, setup, pairs, paths, probe_front_ends(setup, paths, scene.seed)


# -- writing and printing a result ------------------------------------------------------------

def emit_result(args, stage, png: str, name: str, out: dict, figure, summary_line: str) -> None:
    """``--out DIR``: <png> (from ``figure()``) and <name>.json into the staging folder
    ``stage`` (swapped in as DIR when the command ends); then JSON or one summary line on
    stdout."""
    if stage is not None:
        from ..viz.figures import save_figure
        save_figure(figure(), stage / png)
        write_json(stage / f"{name}.json", out)
    if args.json:
        print_json(out)
    else:
        print(summary_line)


def write_outputs(stage, name: str, out: dict, figure) -> None:
    """Write ``NAME.json`` and ``NAME.png`` (``figure()``) into the staging folder of
    ``--out`` (None: nothing)."""
    if stage is not None:
        from ..viz.figures import save_figure
        write_json(stage / f"{name}.json", out)
        save_figure(figure(), stage / f"{name}.png")


def print_outputs(args, name: str, out: dict, text) -> int:
    """Print the JSON (``--json``) or ``text(out)`` once the output folder is in place, and
    the files :func:`write_outputs` wrote."""
    if args.json:
        print_json(out)
    else:
        print(text(out))
        if args.out:
            print(f"wrote {args.out}/{name}.json, {name}.png")
    return 0


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
            if task is None:  # no bar before the first count (was an unlabelled "0/?")
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

def study_options(p, draws_default: int, allow_all: bool = False) -> None:
    """The scene and the options ``tolerance`` and ``design`` share (``allow_all``:
    ``--pair I J | all``, else exactly two indices)."""
    scene_arg(p)
    if allow_all:
        p.add_argument("--pair", nargs="+", type=pair_word, metavar="I J | all",
                       default=[0, 1], help="adjacent front ends (default 0 1), or all: every "
                                            "adjacent pair on shared per-front-end draws")
    else:
        p.add_argument("--pair", nargs=2, type=number(0, 10_000, integer=True),
                       metavar=("I", "J"), default=[0, 1], help="adjacent front ends (default 0 1)")
    p.add_argument("--spec-deg", type=number(1e-6, 90.0), default=0.1,
                   help="angle-error spec in deg, in [1e-6, 90] (default 0.1)")
    p.add_argument("--draws", type=number(1, 10_000_000, integer=True), default=draws_default,
                   help=f"Monte-Carlo draws, in [1, 10000000] (default {draws_default})")
    p.add_argument("--seed", type=number(0, 2 ** 63 - 1, integer=True), default=None,
                   help="random seed (default: the scene's seed)")
    p.add_argument("--points", type=number(3, 201, integer=True), default=21,
                   help="set-points across the span, ends excluded, in [3, 201] (default 21)")
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
