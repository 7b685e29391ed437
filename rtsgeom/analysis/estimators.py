"""Does the synthesized angle hold for the RuT's direction estimator? (``radar.estimators``)

The ideal far field of a front-end pair: two plane waves from direction cosines u_i, u_j,
channel j at amplitude ratio rho and coherent with channel i at the pair's midpoint u_m (each
channel's beam output real there: what the calibration establishes), so the snapshot is
``x_v = c_i e^{-j k p_v u_i} + rho c_j e^{-j k p_v u_j}`` with |c_q| = 1. Swept over rho from 0 to
infinity, eq. 14's Bartlett peak moves continuously from u_i to u_j: every direction in between
is one synthesized target. A smoothed Capon or MUSIC decorrelates the two channels and may
instead resolve the two front ends: its peak then jumps from near u_i to near u_j at some rho,
and the directions in the jump cannot be synthesized at all. :func:`pair_sweep` measures
that, for a grid of front-end spacings against the array's resolution
(``benchmarks/estimators.py``, ``tests/radar/test_estimators.py``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..radar.steering import Steering

__all__ = ["PairSweep", "pair_snapshots", "pair_sweep", "JUMP"]

#: A step of the detected position t = (u - u_i) / (u_j - u_i) larger than this between
#: neighbouring ratios of the sweep counts as a jump (a continuous peak moves ~0.01-0.03
#: per step of the default sweep).
JUMP = 0.2


def pair_snapshots(st: Steering, n_virtual: int, u_i: float, u_j: float, rho) -> np.ndarray:
    """Far-field snapshots (R, V) of the pair for ratios ``rho`` (R,) (module doc); elements
    that do not take part stay zero."""
    rho = np.atleast_1d(np.asarray(rho, float))
    u_q = np.array([[u_i], [u_j]])
    a = np.conj(st.steer(u_q))  # (2, V_s) the two plane waves
    b = st.beam(a, np.array([[0.5 * (u_i + u_j)]]))[:, 0]  # each channel's beam at u_m
    a = a * (np.conj(b) / np.abs(b))[:, None]  # both real (in phase) at the midpoint
    x = np.zeros((rho.size, n_virtual), complex)
    x[:, st.mask] = a[0][None] + rho[:, None] * a[1][None]
    return x


@dataclass(frozen=True)
class PairSweep:
    """The detected position t(rho) (R,) along the pair (0: front end i, 1: j), its largest
    step between neighbouring ratios and whether it holds (continuous: no step above
    :data:`JUMP`)."""

    rho: np.ndarray
    t: np.ndarray
    max_step: float

    @property
    def holds(self) -> bool:
        return bool(self.max_step <= JUMP)


def pair_sweep(st: Steering, n_virtual: int, spacing_u: float, centre_u: float = 0.0,
               rho=None) -> PairSweep:
    """:class:`PairSweep` of a pair ``spacing_u`` apart in u around ``centre_u`` (D = 1)."""
    rho = np.exp(np.linspace(-5.0, 5.0, 401)) if rho is None else np.asarray(rho, float)
    u_i, u_j = centre_u - spacing_u / 2, centre_u + spacing_u / 2
    u = np.sin(st.search(pair_snapshots(st, n_virtual, u_i, u_j, rho)))
    t = (u - u_i) / spacing_u
    return PairSweep(rho, t, float(np.max(np.abs(np.diff(t)))))
