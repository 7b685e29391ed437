"""Which front-end pairs a study takes: one pair given by its indices, or every pair of the arc
(``"all"``), as the calibration, linearity and tolerance studies name them alike."""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from ..geometry import Setup
from ..pipeline.plan import check_pair, measured_pairs, uses_cells

__all__ = ["ALL", "study_pairs", "is_all"]

#: the word for every pair of the arc (``pair="all"``, ``--pair all``)
ALL = "all"


def is_all(pair) -> bool:
    """Whether ``pair`` asks for every pair (``"all"``, or ``["all"]`` as argparse gives it)."""
    return (isinstance(pair, str) and pair == ALL) or (
        isinstance(pair, (list, tuple)) and list(pair) == [ALL])


def study_pairs(setup: Setup, pair, cells: bool = False, name: str | None = None
                ) -> list[tuple[int, int]]:
    """The pairs a study takes, each in canonical order (the lower index first: I keeps its
    delay, J is swept).

    Parameters
    ----------
    setup : Setup
    pair : tuple of 2 int, or 'all'
        One pair, or every adjacent pair of the arc (with ``cells``, every measured pair of a
        2-D scene's cells: :func:`~rtsgeom.pipeline.plan.measured_pairs`).
    cells : bool
        A 2-D scene's neighbouring front ends are pairs too (what a calibration measures).
    name : str, optional
        How the errors name the argument (default ``pair I J``).

    Returns
    -------
    list of (int, int)

    Raises
    ------
    ParameterError
        Not two adjacent (neighbouring) indices, or ``all`` on an arc of fewer than two front
        ends or, without ``cells``, on a scene of 2-D cells.
    """
    if is_all(pair):
        n = setup.fe.count
        if n < 2:
            raise ParameterError(f"{name or 'pair all'}: the arc needs at least two front ends")
        if uses_cells(setup.scene):
            if not cells:  # the error that says what a 2-D scene takes instead
                check_pair(setup, 0, 1, name or "pair all")
            return measured_pairs(setup)
        return [(i, i + 1) for i in range(n - 1)]
    if (not isinstance(pair, (tuple, list, np.ndarray)) or len(pair) != 2
            or not all(isinstance(p, (int, np.integer)) and not isinstance(p, bool)
                       for p in pair)):
        raise ParameterError(f"{name or 'pair'} = {pair!r}: must be two front-end indices "
                             "(i, j), or 'all'")
    i, j = (int(p) for p in pair)
    return [check_pair(setup, i, j, name or f"pair {i} {j}", cells)]
