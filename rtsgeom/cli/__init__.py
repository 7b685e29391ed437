"""Command-line interface: thin wrappers over the library, outputs written atomically.

Each module of this package registers one group of subcommands. Bad input (scene files,
arguments) ends with one clear line on stderr and exit code 2, never a traceback.
"""

from __future__ import annotations

import argparse
import signal as _sig
import sys

from .. import __version__
from ..io import OutputError
from ..parallel import ClusterError
from ..scene import SceneError
from ._common import UsageError

__all__ = ["main", "build_parser"]

_GROUPS = ("geometry", "signal", "aoa", "tolerance", "analysis", "viz", "identify")


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (``rtsgeom: error: ...``, exit 2) instead of the usage
    block; ``--help`` stays complete. Subcommand parsers are of this class too."""

    def error(self, message: str):
        sub = self.prog.split(" ", 1)[1] if " " in self.prog else ""
        where = f"{sub}: " if sub else ""
        self.exit(2, f"rtsgeom: error: {where}{message} (see '{self.prog} --help')\n")


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised like Ctrl-C so that every cleanup (staging folders, temporary files)
    runs the same way."""


def _on_sigterm(signum, frame):
    raise Terminated()


def build_parser() -> argparse.ArgumentParser:
    ap = _Parser(
        prog="rtsgeom",
        description="Radar target simulator setups as geometry: per-element paths, FMCW "
                    "signal model, arbitrary angle-of-arrival synthesis and its calibration.")
    ap.add_argument("--version", action="version", version=f"rtsgeom {__version__}")
    sub = ap.add_subparsers(dest="command", metavar="COMMAND", required=True)
    import importlib
    for name in _GROUPS:
        try:
            mod = importlib.import_module(f".{name}", __name__)
        except ModuleNotFoundError as exc:  # a group not written yet
            if exc.name != f"{__name__}.{name}":
                raise
            continue
        mod.register(sub)
    return ap


def _raytrace_unavailable() -> type[Exception]:
    """The ray tracer's 'no suitable LLVM/Sionna' error, without importing Sionna."""
    from ..paths.raytrace import RaytraceUnavailable
    return RaytraceUnavailable


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    import threading
    old = None
    if threading.current_thread() is threading.main_thread():
        old = _sig.signal(_sig.SIGTERM, _on_sigterm)
    try:
        return _dispatch(args)
    finally:
        if old is not None:
            _sig.signal(_sig.SIGTERM, old)


def _dispatch(args) -> int:
    try:
        return int(args.func(args) or 0)
    except (SceneError, UsageError, OutputError, ClusterError, _raytrace_unavailable()) as exc:
        print(f"rtsgeom: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # the reader went away (`rtsgeom ... | head`): stop quietly
        import os
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except OSError as exc:  # an output path that cannot be written, a missing input file
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"rtsgeom: error: {where}{exc.strerror or exc}", file=sys.stderr)
        return 2
    except Terminated:
        print("rtsgeom: terminated", file=sys.stderr)
        return 143
    except KeyboardInterrupt:
        print("rtsgeom: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
