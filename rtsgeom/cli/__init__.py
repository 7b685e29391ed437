"""Command-line interface: thin wrappers over the library, outputs written atomically.

One module per command (``info.py``, ``run.py``, ... as :data:`COMMANDS` lists them): each
registers its arguments, calls the library and writes its output. What several commands share
is in ``_common.py``; the maps and report of ``run`` in ``_maps.py``. Bad input (scene files,
arguments) ends with one clear line on stderr and exit code 2, never a traceback.
"""

from __future__ import annotations

import argparse
import gc
import importlib
import os
import signal as _sig
import sys
import warnings

from .. import __version__
from ..errors import RtsgeomError, RtsgeomWarning, Terminated
from ._signals import honoured_signals, received

__all__ = ["main", "console", "build_parser"]

#: Every subcommand: (the module of this package that registers it, its one-line help). ``main``
#: imports only the module of the command it runs (the modules import numpy, scipy, the signal
#: chain), so ``rtsgeom --help`` and ``rtsgeom info`` start without the heavy libraries; the
#: other commands are listed from this table. ``tests/cli/test_lazy_cli.py`` checks it against what
#: the modules register. A study whose command is made from its config is one line here:
#: ``"name": ("study", "help", "rtsgeom.analysis.module:NameStudy")`` (``cli/study.py``).
COMMANDS: dict[str, tuple[str, ...]] = {
    "info": ("info", "summary of a scene: elements, front ends, far-field figures"),
    "paths": ("paths", "per-element propagation paths as CSV"),
    "export-mesh": ("export_mesh", "export the setup as GLB/PLY/OBJ/STL"),
    "run": ("run", "the main job: simulate the scene, detect, compare with set-points"),
    "play": ("play", "play the scene's [scenario]: programme, tracks per frame"),
    "adc": ("adc", "save the raw ADC cube (.npy) or a DCA1000 capture"),
    "calibrate": ("calibrate", "phase calibration sweep of a front-end pair"),
    "linearity": ("linearity", "synthesized-angle linearity across a pair's span"),
    "tolerance": ("tolerance", "mounting-tolerance Monte Carlo of a front-end pair or a whole arc"),
    "design": ("design", "arc radius x front-end spacing design map"),
    "nearfield": ("nearfield", "near-field violation: single front-end bias, phase error and "
                               "synthesized-angle error vs arc radius"),
    "ghosts": ("ghosts", "cable ghosts: predicted ranges and levels per front end and "
                         "target (and simulated with --simulate)"),
    "show": ("show", "3D view of the setup: PNG, interactive HTML or a window"),
    "identify": ("identify", "estimate each front end's mounting errors and each channel's "
                             "gain/phase/delay from probe captures"),
    "transfer": ("transfer", "calibration transfer: an RTS calibrated with one radar, tested "
                             "with drawn radars of the type"),
    "resolution": ("resolution", "angular resolution test: two targets in one cell, the truth "
                                 "twin beside the RTS over separation x phase"),
    "objects": ("objects", "extended object: the smallest front-end arc and per-channel "
                           "budget that reproduce it over its ranges"),
    "kpi": ("kpi", "the setup's datasheet: KPIs with an uncertainty budget, checked against a "
                   "spec"),
}


def _modules() -> tuple[str, ...]:
    """The modules that register commands, in the table's order."""
    return tuple(dict.fromkeys(entry[0] for entry in COMMANDS.values()))


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (``rtsgeom: error: ...``, exit 2) instead of the usage
    block; ``--help`` stays complete. Subcommand parsers are of this class too."""

    def error(self, message: str):
        sub = self.prog.split(" ", 1)[1] if " " in self.prog else ""
        where = f"{sub}: " if sub else ""
        self.exit(2, f"rtsgeom: error: {where}{message} (see '{self.prog} --help')\n")


def build_parser(command: str | None = None, *, lazy: bool = False) -> argparse.ArgumentParser:
    """The CLI's parser. By default every command's module registers its command (the complete
    parser). ``lazy``: only the module of ``command`` does (none for ``None``; all for a word
    not in :data:`COMMANDS`, so a command a module registers but the table misses still runs);
    the other commands appear with their help line (enough for ``rtsgeom --help`` and for
    argparse's choice check) and nothing of their module is imported."""
    ap = _Parser(
        prog="rtsgeom",
        description="Radar target simulator setups as geometry: per-element paths, FMCW "
                    "signal model, arbitrary angle-of-arrival synthesis and its calibration.")
    ap.add_argument("--version", action="version", version=f"rtsgeom {__version__}")
    sub = ap.add_subparsers(dest="command", metavar="COMMAND", required=True)
    if not lazy or (command is not None and command not in COMMANDS):
        modules = _modules()  # complete, or a word the table does not know: every module tries
    else:
        modules = (COMMANDS[command][0],) if command is not None else ()
    for name in modules:
        try:
            mod = importlib.import_module(f".{name}", __name__)
        except ModuleNotFoundError as exc:  # a module not written yet
            if exc.name != f"{__name__}.{name}":
                raise
            continue
        mod.register(sub)
    for cmd, entry in COMMANDS.items():  # the commands not registered above
        if cmd not in sub.choices:
            sub.add_parser(cmd, help=entry[1], add_help=False)
    # list the commands in the table's order whichever module registered first (argparse keeps
    # the help lines in registration order; no public API reorders them)
    order = list(COMMANDS)
    sub._choices_actions.sort(key=lambda a: order.index(a.dest)  # noqa: SLF001
                              if a.dest in order else len(order))
    return ap


def _command_of(argv: list[str]) -> str | None:
    """The subcommand named on a command line: the first word that is not an option (the
    top-level parser takes no option with a value)."""
    for word in argv:
        if not word.startswith("-"):
            return word
    return None


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    with honoured_signals():  # from the start: the command's module loads the heavy libraries
        try:
            args = build_parser(_command_of(argv), lazy=True).parse_args(argv)
        except KeyboardInterrupt as exc:  # Terminated too
            return _stopped(isinstance(exc, Terminated))
        code = _dispatch(args)
        if code not in (130, 143) and received() is not None:
            # the signal's exception was swallowed (a callback printed "Exception ignored"):
            # the command still does not end as if nothing happened
            code = _stopped(received() == _sig.SIGTERM)
    return code


def console() -> None:
    """The ``rtsgeom`` command (the console script and ``python -m rtsgeom``): :func:`main` on
    ``sys.argv``, then the process exits with its code. Before the exit every object the
    command leaves is frozen out of the cyclic garbage collector (``gc.freeze``): the
    interpreter's teardown would otherwise walk them all (0.2 s of CPU after a main job of
    2.5 s) only to free memory the exit returns anyway. Not in :func:`main`, which tests and
    notebooks call many times in one process."""
    code = main()
    gc.freeze()
    sys.exit(code)


def _stopped(terminated: bool) -> int:
    """The line and exit code of a command ended by SIGTERM (143) or Ctrl-C/SIGINT (130)."""
    print(f"rtsgeom: {'terminated' if terminated else 'interrupted'}", file=sys.stderr)
    return 143 if terminated else 130


def _dispatch(args) -> int:
    from ._common import show_warning
    try:
        with warnings.catch_warnings():  # the library's warnings, each call's, on stderr
            warnings.simplefilter("always", RtsgeomWarning)
            warnings.showwarning = show_warning
            return int(args.func(args) or 0)
    except RtsgeomError as exc:  # every error rtsgeom raises on purpose
        print(f"rtsgeom: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # the reader went away (`rtsgeom ... | head`): stop quietly
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except OSError as exc:  # an output path that cannot be written, a missing input file
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"rtsgeom: error: {where}{exc.strerror or exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:  # Terminated too
        return _stopped(isinstance(exc, Terminated))


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
