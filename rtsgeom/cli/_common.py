"""Shared argument helpers of the CLI."""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

__all__ = ["UsageError", "number", "scene_arg", "print_json", "load_scene_checked"]


class UsageError(ValueError):
    """A command-line argument is invalid (exit code 2)."""


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


def scene_arg(p: argparse.ArgumentParser) -> None:
    p.add_argument("scene", type=Path, help="scene file (TOML), e.g. scenes/diewald2022.toml")


def print_json(obj) -> None:
    print(json.dumps(obj, indent=2, allow_nan=False))


def load_scene_checked(path):
    """Load and validate a scene (errors raise :class:`~rtsgeom.scene.SceneError`, exit code 2)
    and print its physical warnings (``rtsgeom.validate.scene_warnings``) to stderr as
    ``rtsgeom: warning: ...``. Every subcommand that reads a scene should load it with this."""
    from ..scene import load_scene
    from ..validate import scene_warnings
    scene = load_scene(path)
    for line in scene_warnings(scene):
        print(f"rtsgeom: warning: {line}", file=sys.stderr)
    return scene
