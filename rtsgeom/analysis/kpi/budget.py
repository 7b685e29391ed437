"""The uncertainty budget in the GUM's form (JCGM 100:2008) and its check by propagation of
distributions (JCGM 101:2008).

An input quantity X_i has a standard uncertainty u(x_i), a distribution (normal, rectangular,
triangular: JCGM 100 4.3.7, 4.3.9) and a sensitivity coefficient c_i = d e / d X_i, the
derivative of the synthesized angle's error e from the model (JCGM 100 5.1.3). Its
contribution is u_i(e) = |c_i| u(x_i); the combined standard uncertainty
u_c = sqrt(sum u_i^2) (eq. 10, the inputs uncorrelated) and the expanded uncertainty
U = k u_c with k = 2 (JCGM 100 6.2).

The coefficients are central differences of the model over +-u(x_i) (Kragten's numerical
differentiation, as JCGM 100 5.1.3 allows): where the error is nonlinear in an input over its
spread (a radial offset the calibration compensates to first order), the coefficient is the
secant the spread sees. The Monte Carlo (JCGM 101) draws every input from its distribution,
evaluates the model and takes the probabilistically symmetric 95 % coverage interval (JCGM
101 5.3.2, 7.7); the GUM interval [e - U, e + U] is validated against it (JCGM 101 8.2) with a
tolerance of 10 % of U: where an end differs by more, the datasheet says so and quotes the
Monte Carlo's interval.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["BudgetRow", "combined", "coverage_interval", "validate", "K_COVERAGE",
           "VALIDATION_TOLERANCE", "RECTANGULAR", "TRIANGULAR"]

K_COVERAGE = 2.0  # JCGM 100 6.2.1: about 95 % for a normal output
VALIDATION_TOLERANCE = 0.10  # of U: an interval end further from the Monte Carlo's fails
RECTANGULAR = 1.0 / math.sqrt(3.0)  # u of a rectangular distribution of half-width a: a/sqrt3
TRIANGULAR = 1.0 / math.sqrt(6.0)  # u of a symmetric triangular one of half-width a


@dataclass(frozen=True)
class BudgetRow:
    """One input quantity of the budget: ``standard_uncertainty`` in ``unit``,
    ``sensitivity`` in deg per ``unit``, ``distribution`` as JCGM 100 names them."""

    quantity: str
    standard_uncertainty: float
    unit: str
    distribution: str
    sensitivity: float
    note: str = ""

    @property
    def contribution_deg(self) -> float:
        """|c_i| u(x_i) (deg): JCGM 100 eq. (10)'s term."""
        return abs(self.sensitivity) * self.standard_uncertainty

    def to_dict(self) -> dict:
        return {"quantity": self.quantity, "standard_uncertainty": self.standard_uncertainty,
                "unit": self.unit, "distribution": self.distribution,
                "sensitivity": self.sensitivity, "sensitivity_unit": f"deg/{self.unit}",
                "contribution_deg": self.contribution_deg, "note": self.note}


def combined(rows) -> float:
    """The combined standard uncertainty u_c (deg) of uncorrelated inputs (JCGM 100 eq. 10)."""
    return float(math.sqrt(sum(r.contribution_deg ** 2 for r in rows)))


def coverage_interval(samples, p: float = 0.95) -> tuple[float, float]:
    """The probabilistically symmetric coverage interval of probability ``p`` of Monte-Carlo
    output values (JCGM 101 7.7): their (1-p)/2 and (1+p)/2 quantiles."""
    a = np.asarray(samples, float)
    a = a[np.isfinite(a)]
    if a.size == 0:
        return float("nan"), float("nan")
    lo, hi = np.quantile(a, [(1 - p) / 2, (1 + p) / 2])
    return float(lo), float(hi)


def validate(estimate: float, expanded: float, interval: tuple[float, float],
             tolerance: float = VALIDATION_TOLERANCE) -> tuple[bool, float]:
    """JCGM 101 8.2 with a relative tolerance: whether both ends of the GUM interval
    ``estimate -+ expanded`` lie within ``tolerance * expanded`` of the Monte Carlo's
    ``interval``; and the larger end difference relative to U."""
    lo, hi = interval
    if not (math.isfinite(lo) and math.isfinite(hi)):
        return False, float("inf")
    d = max(abs(estimate - expanded - lo), abs(estimate + expanded - hi))
    scale = max(expanded, 1e-12)
    return bool(d <= tolerance * scale), float(d / scale)
