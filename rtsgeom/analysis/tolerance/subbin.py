"""The target's sub-bin positions of the tolerance studies (issue 13): where inside its range
bin an RTS can place a target, as RTS delay offsets in steps of its delay resolution.

A real target sits anywhere in its range bin; an RTS places it at a delay it can realise, so the
positions are the delay steps across one range bin (2 dR / c0 over the delay resolution),
centred on the bin centre (offset 0). The pair study (``PairPhasors.subbin_steps``), the
whole-arc study (one position per draw shared by every pair) and the 2-D cell study
(``CellPhasors.subbin_steps``) draw uniformly among them, index by index, from the stream of
:func:`rtsgeom.analysis.tolerance.driver.subbin_draws`.
"""

from __future__ import annotations

import numpy as np
from scipy.constants import c

__all__ = ["subbin_positions", "centre_index"]


def subbin_positions(range_resolution_m: float, delay_resolution_s: float) -> np.ndarray:
    """The sub-bin positions (delay steps, int (U,)) across one range bin of
    ``range_resolution_m`` for an RTS of ``delay_resolution_s``: U = round(2 dR / (c0 dtau))
    (at least 1) steps, ``arange(U) - U // 2`` (the bin centre is 0). ``PairPhasors.build``
    places them this way (a test holds both to it)."""
    n_bin = max(1, round(2 * float(range_resolution_m) / c / float(delay_resolution_s)))
    return np.arange(n_bin) - n_bin // 2


def centre_index(steps) -> int:
    """Index of the bin centre (offset 0) in sub-bin positions ``steps``."""
    return int(np.flatnonzero(np.asarray(steps) == 0)[0])
