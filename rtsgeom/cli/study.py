"""The command of a study made from its config: ``rtsgeom NAME SCENE [--field VALUE ...]``.

A study whose :data:`~rtsgeom.cli.COMMANDS` entry names this module and its config class
(``"name": ("study", "help", "rtsgeom.analysis.module:NameStudy")``) gets its command here,
with nothing written for it: one option per field of the frozen config (a declared argument,
:class:`~rtsgeom.analysis.tolerance.config.Arg`, in the class's ``ARGS``, with its range; a
flag for a bool; a number or a word for an int, float or str default; ``--draws``, ``--seed``,
``--distribution`` for a :class:`~rtsgeom.analysis.tolerance.config.MonteCarlo` field), its
help from the class's numpydoc ``Parameters``; and the run: the scene loaded, the config called
on it, ``--out DIR`` the result's ``write(DIR)``, ``--json`` its ``to_dict()``, else its
summary. ``docs/contributing.md`` walks through adding one.
"""

from __future__ import annotations

import dataclasses
import importlib
import re

from ..analysis.tolerance.config import STUDY_ARGS, MonteCarlo
from . import COMMANDS
from ._common import (declared_option, flagged, load_scene_checked, output_folder, output_path,
                      print_json, scene_arg)

__all__ = ["register", "study_class", "cmd_study"]

#: the field types a command line cannot give (callbacks); they keep their defaults
_SKIPPED = ("steps", "progress", "mapper")


def study_class(path: str):
    """The config class ``module:Name`` of a study's COMMANDS entry."""
    module, _, name = path.partition(":")
    return getattr(importlib.import_module(module), name)


def _helps(cls) -> dict[str, str]:
    """Each field's first line of description in the class's numpydoc ``Parameters``."""
    doc = cls.__doc__ or ""
    out, name = {}, None
    for line in doc.splitlines():
        m = re.match(r"^    (\w+) : ", line)
        if m:
            name = m.group(1)
        elif name and line.startswith("        ") and name not in out:
            out[name] = line.strip().rstrip(".")
    return out


def _add_field(p, f, cls, helps: dict) -> None:
    declared = getattr(cls, "ARGS", {})
    default = f.default
    text = helps.get(f.name, f.name.replace("_", " "))
    flag = "--" + f.name.replace("_", "-")
    if f.name in declared:
        declared_option(p, f.name, declared[f.name], default)
    elif isinstance(default, bool):
        if default:
            p.add_argument("--no-" + f.name.replace("_", "-"), dest=f.name,
                           action="store_false", help=f"not: {text}")
        else:
            p.add_argument(flag, action="store_true", help=text)
    elif isinstance(default, (int, float, str)):
        p.add_argument(flag, type=type(default), default=default,
                       help=f"{text} (default {default})")


def _study_parser(sub, name: str, helptext: str, path: str) -> None:
    cls = study_class(path)
    p = sub.add_parser(name, help=helptext, description=(cls.__doc__ or "").split("\n\n")[0])
    scene_arg(p)
    helps = _helps(cls)
    mc = False
    for f in dataclasses.fields(cls):
        if f.name in _SKIPPED:
            continue
        if f.name == "mc" or isinstance(f.default, MonteCarlo):
            mc = True
            declared_option(p, "draws", STUDY_ARGS["draws"], MonteCarlo.draws)
            declared_option(p, "seed", STUDY_ARGS["seed"], None, "the scene's seed")
            declared_option(p, "distribution", STUDY_ARGS["distribution"], "normal")
            continue
        _add_field(p, f, cls, helps)
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.add_argument("--out", type=output_path, default=None,
                   help="folder for the result's files (its write(folder))")
    p.set_defaults(func=cmd_study, study=path, uses_mc=mc)


def register(sub) -> None:
    """Every study command of :data:`~rtsgeom.cli.COMMANDS` made from its config."""
    for name, entry in COMMANDS.items():
        if entry[0] == "study":
            _study_parser(sub, name, entry[1], entry[2])


def cmd_study(args) -> int:
    cls = study_class(args.study)
    names = {f.name for f in dataclasses.fields(cls)}
    kw = {k: v for k, v in vars(args).items() if k in names and k not in ("mc",)}
    scene = load_scene_checked(args.scene)
    with output_folder(args.out, [args.scene]) as stage:
        with flagged(args):
            if args.uses_mc:
                kw["mc"] = MonteCarlo(args.draws, args.seed, args.distribution)
            result = cls(**kw)(scene)
        if stage is not None:
            result.write(stage)
    if args.json:
        print_json(result.to_dict())
    else:
        print(result)
    return 0
