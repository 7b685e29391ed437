"""Which detection is which target: one optimal assignment, explained.

Detections and targets are compared in the radar's own resolution cells: range over the range
bin, velocity over the velocity bin, direction (direction cosine u = sin az, and sin el for a
2-D beamformer) over the beamformer's two-target resolution
(:func:`rtsgeom.radar.peaks.two_target_resolution`). In those units:

* a detection is a candidate for a target within ``gate`` range and Doppler bins of it;
* a target is never given a detection that lies nearer (in the normalised distance) to another
  target;
* among the remaining candidates one optimal assignment (``scipy.optimize.linear_sum_assignment``,
  the most pairs, then the least summed distance) gives each target at most one detection of its
  own: status ``detected``;
* a target left without one whose range-Doppler cell holds a detection within one angular
  resolution cell of it is ``merged``: that detection serves it and the target that owns it
  (``merged_with`` lists the others), as when the radar cannot resolve two targets;
* every other target is ``not_detected``.

Each detection also has its ``nearest`` target: the one it lies nearest to, where that is
within the gate and one angular resolution cell (-1: none). A detection the assignment left
without an owner (a second detection of a target, or one of several scatterers the radar
sees as one) still belongs to that target's neighbourhood: the clouds of an extended object
(:mod:`rtsgeom.analysis.objects`) are built from ``owner``, then ``nearest``.

The same function serves ``run``, ``play``, the truth twin, the resolution study and the API.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .peaks import two_target_resolution

__all__ = ["Association", "assign", "associate", "resolution_cell", "STATUSES"]

#: the statuses of a target
STATUSES = ("detected", "merged", "not_detected")

_FORBIDDEN = 1e12  # the cost of a pair the rules exclude (never kept)


def assign(allowed: np.ndarray, dist: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The pairs (rows, columns) of one optimal assignment of targets (rows) to detections
    (columns) over the ``allowed`` pairs: the most pairs, then the least total ``dist``
    (``scipy.optimize.linear_sum_assignment`` with the excluded pairs at a prohibitive cost;
    pairs it returns that are not allowed are to be dropped by the caller). Where no two
    allowed pairs share a row or a column, those pairs are the only optimal assignment and
    are returned as they are: the usual frame, each target alone near its detection, needs
    no solver (importing scipy.optimize is 0.15-0.3 s of a main job's 2.5 s)."""
    if (allowed.sum(axis=0) <= 1).all() and (allowed.sum(axis=1) <= 1).all():
        return np.nonzero(allowed)
    from scipy.optimize import linear_sum_assignment  # here: see above
    return linear_sum_assignment(np.where(allowed, dist, _FORBIDDEN))


def resolution_cell(radar, steering, rd=None) -> np.ndarray:
    """The radar's resolution cell as the association measures in it (K,): the range bin and
    the velocity bin (of the range-Doppler map ``rd``, or the radar's range and velocity
    resolutions, which they equal), then the beamformer's two-target resolution per
    direction-cosine axis (:func:`rtsgeom.radar.peaks.two_target_resolution`)."""
    if rd is None:
        bins = [radar.range_resolution_m, radar.velocity_resolution_mps]
    else:
        bins = [rd.range_m[1] - rd.range_m[0], rd.velocity_mps[1] - rd.velocity_mps[0]]
    return np.r_[bins, two_target_resolution(steering)]


@dataclass(frozen=True)
class Association:
    """Per target the detection that serves it and how.

    ``detection`` (T,) the index of the serving detection, -1 for none; ``status`` (T,) one of
    :data:`STATUSES`; ``merged_with`` the other targets a merged detection serves (empty
    otherwise); ``owner`` (D,) the target each detection was assigned to, -1 for none;
    ``nearest`` (D,) the target each detection lies nearest to within the gate and one angular
    resolution cell, -1 for none.
    """

    detection: np.ndarray
    status: tuple[str, ...]
    merged_with: tuple[tuple[int, ...], ...]
    owner: np.ndarray
    nearest: np.ndarray


def associate(targets: np.ndarray, detections: np.ndarray, scale, gate: float = 2.0
              ) -> Association:
    """Assign detections to targets (see the module's docstring for the rules).

    Parameters
    ----------
    targets : ndarray, shape (T, K)
        Set-points ``(range_m, velocity_mps, u[, u_el])``.
    detections : ndarray, shape (D, K)
        Detections in the same columns.
    scale : array_like, shape (K,)
        One resolution cell per column: range bin (m), velocity bin (m/s), two-target
        resolution in u (and in u_el).
    gate : float
        A detection is a candidate for a target within this many range and Doppler bins.

    Returns
    -------
    Association
    """
    t = np.asarray(targets, float).reshape(-1, np.size(scale))
    d = np.asarray(detections, float).reshape(-1, np.size(scale))
    scale = np.asarray(scale, float)
    n_t, n_d = len(t), len(d)
    det_of = np.full(n_t, -1)
    owner = np.full(n_d, -1)
    near_t = np.full(n_d, -1)
    if n_t and n_d:
        diff = (d[None, :, :] - t[:, None, :]) / scale  # (T, D, K) in resolution cells
        dist = np.sqrt(np.sum(diff ** 2, axis=-1))
        in_gate = np.all(np.abs(diff[..., :2]) <= gate, axis=-1)
        nearest = dist <= dist.min(axis=0, keepdims=True)  # no other target is nearer
        in_cell = in_gate & (np.abs(diff[..., 2:]) <= 1.0).all(axis=-1)
        first = np.argmax(nearest, axis=0)  # (D,) the nearest target (ties: the lower index)
        near_t = np.where(in_cell[first, np.arange(n_d)], first, -1)
        allowed = in_gate & nearest
        rows, cols = assign(allowed, dist)
        ok = allowed[rows, cols]
        det_of[rows[ok]], owner[cols[ok]] = cols[ok], rows[ok]
        status = ["detected" if j >= 0 else "not_detected" for j in det_of]
        shared = in_cell & (owner >= 0)[None]
        merged: dict[int, set[int]] = {}
        for i in np.flatnonzero(det_of < 0):
            cand = np.flatnonzero(shared[i])
            if cand.size:
                j = int(cand[np.argmin(dist[i, cand])])
                det_of[i] = j
                merged.setdefault(j, {int(owner[j])}).add(int(i))
        with_ = [()] * n_t
        for group in merged.values():
            for i in group:
                status[i] = "merged"
                with_[i] = tuple(sorted(group - {i}))
    else:
        status, with_ = ["not_detected"] * n_t, [()] * n_t
    return Association(det_of, tuple(status), tuple(with_), owner, near_t)
