"""Shared argument helpers of the CLI."""

from __future__ import annotations

import argparse
import json
import math
import sys
from contextlib import contextmanager
from pathlib import Path
from ..errors import UsageError

__all__ = ["UsageError", "number", "scene_arg", "print_json", "load_scene_checked", "steps",
           "output_path", "output_folder", "output_file"]


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


@contextmanager
def output_folder(out, inputs=()):
    """``--out DIR`` of a command: the staging folder to write into (see
    :func:`rtsgeom._lib.io.staged_dir`), or None without ``--out``. Enter it BEFORE computing: the
    path is checked and the folder locked at once."""
    if out is None:
        yield None
        return
    from .._lib.io import staged_dir
    with staged_dir(out, [i for i in inputs if i is not None]) as stage:
        yield stage


def output_file(out, inputs=()) -> Path:
    """Check an output file path before computing (exit 2 naming it); returns it."""
    from .._lib.io import check_output_file
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
    duration, so a user sees what takes time.
    """

    def __init__(self, quiet: bool = False):
        self.quiet = quiet
        self._status = None
        self._label = None
        self._t0 = 0.0

    def __enter__(self):
        if not self.quiet:
            from rich.console import Console
            self._console = Console(stderr=True)
        return self

    def __call__(self, label: str) -> None:
        import time
        self._finish()
        if self.quiet:
            return
        self._label, self._t0 = label, time.perf_counter()
        self._status = self._console.status(label + " ...")
        self._status.start()

    def _finish(self, failed: bool = False) -> None:
        import time
        if self._status is not None:
            self._status.stop()
            if failed:  # the error message follows; no duration for a step that did not finish
                self._status = None
                return
            self._console.print(f"  {self._label}: {time.perf_counter() - self._t0:.1f} s",
                                style="dim", highlight=False, soft_wrap=True)
            self._status = None

    def __exit__(self, exc_type, exc, tb):
        self._finish(failed=exc_type is not None)
        return False


#: what ``tolerance`` and ``design`` do with the scene's own errors (warn_scene_errors)
DRAWS_REPLACE = ("draws mounting errors about the nominal setup; the scene's own errors ({}) "
                 "are not its starting point: each draw replaces them")


def warn_scene_errors(scene, command: str, what: str = DRAWS_REPLACE) -> None:
    """Say on stderr that ``command`` works on the nominal setup
    (``geometry.setup.nominal_scene``) when the scene carries its own mounting, channel or RuT
    pose errors (``geometry.setup.setup_errors``), which it does not start from (a new-user
    trial wrote measured offsets into a scene and got the zero-offset scene's numbers).
    ``what``: the sentence after the command, ``{}`` the fields."""
    from ..geometry.setup import setup_errors
    fields = setup_errors(scene)
    if fields:
        more = f" and {len(fields) - 3} more" if len(fields) > 3 else ""
        print(f"rtsgeom: warning: {command} " + what.format(", ".join(fields[:3]) + more),
              file=sys.stderr)
