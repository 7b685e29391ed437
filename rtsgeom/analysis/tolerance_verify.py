"""The tolerance study's fast model against the full ADC-cube chain (issue 13: ``rtsgeom
tolerance --verify N``).

The first N draws of a study (the same seed, so the same mounting errors and sub-bin
positions as :func:`~rtsgeom.analysis.tolerance.monte_carlo`'s first N) are built as real
setups (``geometry.build_setup`` with the draw's offsets on the pair's front ends, exact
paths), and the programme the fast model assumes (the target's delay with its sub-bin offset
on both channels, channel J's calibration delay, the designed amplitudes with the gain
correction and the redesign) is synthesized as a noise-free ADC cube, processed (range-Doppler
FFTs, CFAR, beamformer search at the detection: ``radar.process``, as ``rtsgeom run``) and
its detected angle compared with the fast model's. One frame per draw and case, at the
set-point that is the draw's worst in the fast model (the number the study reports).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from scipy.constants import c

from ..geometry import build_setup
from ..paths import exact_paths
from ..radar import process
from ..radar.frame import simulate
from ..radar.processing import nearest_detection
from ..rts import RtsProgram, requested_delay
from .tolerance import CASES, draw_offsets, draw_subbins
from .tolerance_model import PairPhasors

__all__ = ["VerifyResult", "verify_draws"]


@dataclass(frozen=True)
class VerifyResult:
    """Per draw and case: the fast model's and the chain's angle error (deg) at the draw's
    worst set-point (NaN where the chain detected nothing within 2 bins)."""

    set_index: dict  # case -> (N,) set-point verified
    model_deg: dict  # case -> (N,)
    chain_deg: dict  # case -> (N,)
    elapsed_s: float

    def difference_deg(self, case: str) -> np.ndarray:
        return np.abs(self.chain_deg[case] - self.model_deg[case])

    @property
    def max_difference_deg(self) -> float:
        """The largest per-draw |chain - model| over all cases (inf if a draw was missed)."""
        d = np.concatenate([self.difference_deg(c) for c in self.model_deg])
        return float(np.max(np.where(np.isfinite(d), d, np.inf))) if d.size else 0.0

    def to_dict(self) -> dict:
        cases = {}
        for case in self.model_deg:
            d = self.difference_deg(case)
            cases[case] = {"max_abs_difference_deg": float(np.max(d)) if d.size else 0.0,
                           "missed": int(np.count_nonzero(~np.isfinite(d)))}
        return {"draws": int(next(iter(self.model_deg.values())).size),
                "max_abs_difference_deg": self.max_difference_deg,
                "set_point": "the draw's worst in the fast model",
                "cases": cases, "elapsed_s": self.elapsed_s}


def verify_draws(model: PairPhasors, sigma_m, n: int, seed: int, distribution: str = "normal",
                 cases=CASES, subbin: bool = True, progress=None) -> VerifyResult:
    """The first ``n`` draws of ``monte_carlo(model, sigma_m, ..., seed, distribution)``
    through the full chain (see the module). ``progress(label, done, total)`` per draw."""
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
    out = {k: {case: np.full(n, np.nan) for case in cases} for k in ("model", "chain")}
    index = {case: np.zeros(n, int) for case in cases}
    for i in range(n):
        offsets = np.zeros((n_fe, 3))
        offsets[pair] = off[i]
        setup = build_setup(scene, offsets_m=offsets)
        paths = exact_paths(setup)
        d_u = int(model.subbin_steps[sub[i]])
        for case in cases:
            e = np.degrees(err[case][i])
            m = int(np.argmax(np.abs(e)))
            index[case][i] = m
            out["model"][case][i] = e[m]
            k = int(det["j_steps"][case][i, m])  # J's delay (steps), as planned per set-point
            a_i, a_j = det["amplitudes"][case][i, m]
            prog = RtsProgram.build([0, 0], pair, [tau0 + d_u * res, tau0 + (d_u + k) * res],
                                    [0.0, 0.0], [a_i, a_j])
            _, cube = simulate(setup, paths, prog)  # noise-free
            rd, dets = process(cube)
            j = nearest_detection(dets, rd, model.range_m + 0.5 * c * d_u * res)
            if j is not None:
                out["chain"][case][i] = np.degrees(dets.angle_rad[j] - model.set_rad[m])
        if progress:
            progress("verify (ADC-cube chain)", i + 1, n)
    return VerifyResult(index, out["model"], out["chain"], time.perf_counter() - t0)
