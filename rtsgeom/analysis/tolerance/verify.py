"""The tolerance study's fast model against the full ADC-cube chain (issue 13: ``rtsgeom
tolerance --verify N``).

The first N draws of a study (the same seed, so the same mounting errors and sub-bin
positions as :func:`~rtsgeom.analysis.tolerance.driver.monte_carlo`'s first N) are built as real
setups (``geometry.build_setup`` with the draw's offsets on the pair's front ends, exact
paths), and the programme the fast model assumes (the target's delay with its sub-bin offset
on both channels, channel J's calibration delay, the designed amplitudes with the gain
correction and the redesign) is synthesized as a noise-free ADC cube, processed (range-Doppler
FFTs, CFAR, beamformer search at the detection: ``radar.process``, as ``rtsgeom run``) and
its detected angle compared with the fast model's. One frame per draw and case, at the
set-point that is the draw's worst in the fast model (the number the study reports), or at
every set-point (``all_points``, ``--verify-all-points``: also the difference of the per-draw
worst errors, the chain's worst taken over all its set-points).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from scipy.constants import c

from ...geometry import build_setup
from ...paths import exact_paths
from ...radar import process
from ...radar.frame import simulate
from ...radar.processing import nearest_detection
from ...rts.channels import RtsProgram, requested_delay
from .driver import CASES, draw_offsets, draw_subbins
from .pair import PairPhasors

__all__ = ["VerifyResult", "verify_draws"]


@dataclass(frozen=True)
class VerifyResult:
    """Per draw and case: the fast model's and the chain's angle error (deg) at the verified
    set-points (NaN where the chain detected nothing within 2 bins): (N,) at each draw's worst
    set-point in the fast model, or (N, M) with ``all_points``."""

    set_index: dict  # case -> (N,) set-point verified (-1: all)
    model_deg: dict  # case -> (N,) or (N, M)
    chain_deg: dict  # case -> (N,) or (N, M)
    elapsed_s: float

    def difference_deg(self, case: str) -> np.ndarray:
        """|chain - model| per draw (the largest over its verified set-points), (N,)."""
        d = np.abs(self.chain_deg[case] - self.model_deg[case])
        d = np.where(np.isfinite(d), d, np.inf)
        return d if d.ndim == 1 else np.max(d, axis=-1)

    def worst_difference_deg(self, case: str) -> np.ndarray:
        """|chain's worst - model's worst| per draw (the study's statistic), (N,)."""
        def worst(e):
            e = np.abs(np.where(np.isfinite(e), e, np.inf))
            return e if e.ndim == 1 else np.max(e, axis=-1)
        return np.abs(worst(self.chain_deg[case]) - worst(self.model_deg[case]))

    @property
    def max_difference_deg(self) -> float:
        """The largest per-draw |chain - model| over all cases (inf if a draw was missed)."""
        d = np.concatenate([self.difference_deg(c) for c in self.model_deg])
        return float(np.max(d)) if d.size else 0.0

    def to_dict(self) -> dict:
        cases = {}
        first = next(iter(self.model_deg.values()))
        for case in self.model_deg:
            d = self.difference_deg(case)
            cases[case] = {"max_abs_difference_deg": float(np.max(d)) if d.size else 0.0,
                           "max_worst_error_difference_deg": (
                               float(np.max(self.worst_difference_deg(case))) if d.size
                               else 0.0),
                           "missed": int(np.count_nonzero(~np.isfinite(d)))}
        return {"draws": int(first.shape[0]),
                "max_abs_difference_deg": self.max_difference_deg,
                "set_point": ("every set-point" if first.ndim == 2
                              else "the draw's worst in the fast model"),
                "cases": cases, "elapsed_s": self.elapsed_s}


def verify_draws(model: PairPhasors, sigma_m, n: int, seed: int, distribution: str = "normal",
                 cases=CASES, subbin: bool = True, progress=None,
                 all_points: bool = False) -> VerifyResult:
    """The first ``n`` draws of ``monte_carlo(model, sigma_m, ..., seed, distribution)``
    through the full chain (see the module): one frame per draw and case at the draw's worst
    set-point, or with ``all_points`` one per set-point (M times the frames).
    ``progress(label, done, total)`` per draw."""
    t0 = time.perf_counter()
    off = draw_offsets(seed, n, sigma_m, distribution)
    sub = (draw_subbins(seed, n, model.subbin_steps.size) if subbin
           else np.full(n, model.subbin_zero))
    err, det = model.draw_errors(off, sub, tuple(cases), return_detail=True)
    scene = model.setup.scene
    n_fe = len(scene.rts.front_ends)
    tau0 = float(requested_delay(scene, model.range_m))
    res = model.delay_resolution_s
    pair = list(model.pair)
    n_m = model.set_rad.size
    shape = (n, n_m) if all_points else (n,)
    out = {k: {case: np.full(shape, np.nan) for case in cases} for k in ("model", "chain")}
    index = {case: np.full(n, -1) for case in cases}
    for i in range(n):
        offsets = np.zeros((n_fe, 3))
        offsets[pair] = off[i]
        setup = build_setup(scene, offsets_m=offsets)
        paths = exact_paths(setup)
        d_u = int(model.subbin_steps[sub[i]])
        for case in cases:
            e = np.degrees(err[case][i])
            if all_points:
                points = range(n_m)
            else:
                index[case][i] = int(np.argmax(np.abs(e)))
                points = [index[case][i]]
            for m in points:
                k = int(det["j_steps"][case][i, m])  # J's delay (steps), as planned
                a_i, a_j = det["amplitudes"][case][i, m]
                prog = RtsProgram.build([0, 0], pair, [tau0 + d_u * res, tau0 + (d_u + k) * res],
                                        [0.0, 0.0], [a_i, a_j])
                _, cube = simulate(setup, paths, prog)  # noise-free
                rd, dets = process(cube)
                j = nearest_detection(dets, rd, model.range_m + 0.5 * c * d_u * res)
                at = (i, m) if all_points else i
                out["model"][case][at] = e[m]
                if j is not None:
                    out["chain"][case][at] = np.degrees(dets.angle_rad[j] - model.set_rad[m])
        if progress:
            progress("verify (ADC-cube chain)", i + 1, n)
    return VerifyResult(index, out["model"], out["chain"], time.perf_counter() - t0)
