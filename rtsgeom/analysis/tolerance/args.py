"""The Monte-Carlo studies' arguments, declared once: the draw distributions, the largest
mounting sigma, and each argument's kind and range (:data:`STUDY_ARGS`). The studies check their
arguments against these declarations (:func:`check_study_args`, :meth:`Arg.check`: the configs,
``rtsgeom.tolerance``, the draws); the commands generate their options from them
(``cli._common.declared_option``)."""

from __future__ import annotations

from dataclasses import dataclass

from ...errors import ParameterError
from ...scene.schema import check_arg

__all__ = ["DISTRIBUTIONS", "MAX_SIGMA_MM", "Arg", "STUDY_ARGS", "check_study_args",
           "check_sigma_mm"]

#: the draws' distributions: the scales are standard deviations, or uniform bounds
DISTRIBUTIONS = ("normal", "uniform")
#: the largest mounting sigma (mm) a study takes, in the CLI and in Python: the phasor model
#: is first order in the errors (checked to 0.3 mm)
MAX_SIGMA_MM = 10.0


@dataclass(frozen=True)
class Arg:
    """One study argument declared once: its kind (``int``, ``float``, ``str``), range or
    choices and unit, and the text of its help. The studies check it with :meth:`check`
    (the configs, ``rtsgeom.tolerance`` ...); the commands generate their option from it
    (``cli._common.declared_option``)."""

    kind: str
    help: str
    lo: float | None = None
    hi: float | None = None
    choices: tuple | None = None
    unit: str | None = None

    def check(self, value, name: str, source: str, lo: float | None = None,
              hi: float | None = None):
        """``value`` checked (``lo``, ``hi``: bounds of the caller's own within the declared
        kind, e.g. the engine's 0 draws, the datasheet's 100 to a million);
        :class:`~rtsgeom.errors.ParameterError` naming ``name`` and the range."""
        decl = {k: v for k, v in (("lo", self.lo if lo is None else lo),
                                  ("hi", self.hi if hi is None else hi),
                                  ("choices", self.choices), ("unit", self.unit))
                if v is not None}
        return check_arg(value, name, self.kind, source, ParameterError, **decl)


#: The Monte-Carlo studies' arguments (tolerance, design, the API's functions and the CLI's
#: options alike).
STUDY_ARGS: dict[str, Arg] = {
    "draws": Arg("int", "Monte-Carlo draws", 1, 10_000_000),
    "seed": Arg("int", "random seed", 0, 2 ** 63 - 1),
    "distribution": Arg("str", "error distribution", choices=DISTRIBUTIONS),
    "spec_deg": Arg("float", "angle-error spec in deg", 1e-6, 90.0, unit="deg"),
    "points": Arg("int", "set-points across the span, ends excluded", 3, 201),
    "chunk": Arg("int", "draws per chunk (memory)", 100, 1_000_000),
}


def check_study_args(source: str, **values) -> tuple:
    """Each of ``values`` (names of :data:`STUDY_ARGS`; None: not given) against its
    declaration; returns them checked and normalised, in order (None stays None)."""
    return tuple(None if v is None else STUDY_ARGS[n].check(v, n, source)
                 for n, v in values.items())


def check_sigma_mm(source: str, sigma_mm) -> tuple[float, float, float]:
    """A study's mounting sigma (radial, tangential, height) in mm, in [0, MAX_SIGMA_MM]:
    returned in metres; :class:`~rtsgeom.errors.ParameterError` naming ``sigma_mm``."""
    mm = check_arg(sigma_mm, "sigma_mm", "vec", source, ParameterError, n=3, lo=0.0,
                   hi=MAX_SIGMA_MM, unit="mm")
    return tuple(float(x) * 1e-3 for x in mm)
