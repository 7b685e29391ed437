"""The tolerance model against the full ADC-cube chain (``rtsgeom tolerance --verify N``).

The first N draws of a study (the same seed, so the same mounting errors and sub-bin
positions as :func:`~.montecarlo.monte_carlo`'s first N) are built as real setups
(``geometry.build_setup`` with the draw's offsets on the set's front ends, exact paths), and
the programme the model assumes (the target's delay at its sub-bin position on every channel
plus each channel's calibration delay, the designed amplitudes with the gain correction and
the redesign) is synthesized as a noise-free ADC cube, processed (range-Doppler FFTs, CFAR,
the beamformer at the detection: ``radar.process``, as ``rtsgeom run``) and its detected
direction compared with the model's. One frame per draw and case, at the set-point that is
the draw's worst in the model (a pair: the largest |error|; a cell: the largest angular
distance), or at every set-point (``all_points``).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from scipy.constants import c

from ..._lib.results import Result
from ...geometry import build_setup
from ...paths import exact_paths
from ...radar import process
from ...radar.frame import simulate
from ...radar.processing import nearest_detection
from ...rts.channels import RtsProgram, requested_delay
from .config import MonteCarlo
from .draws import draw_offsets, draw_subbins
from .phasors import CASES, ChannelPhasors

__all__ = ["VerifyResult", "verify_draws"]


@dataclass(frozen=True, repr=False)
class VerifyResult(Result):
    """Per draw and case: the model's and the chain's direction error (deg) at the verified
    set-points (NaN where the chain detected nothing): a pair's (N,) at each draw's worst
    set-point, (N, M) with ``all_points``; a cell's (N, P, 2) (azimuth, elevation)."""

    set_index: dict  # case -> (N,) set-point verified (-1: all), (N, P) for a cell
    model_deg: dict
    chain_deg: dict
    elapsed_s: float
    subbin_steps: np.ndarray  # (N,) the draws' sub-bin offsets (delay steps)
    dims: int = 1
    all_points: bool = False

    def _summary(self):
        n = int(next(iter(self.model_deg.values())).shape[0]) if self.model_deg else 0
        rows = []
        for case in self.model_deg:
            d = self.difference_deg(case)
            fin = d[np.isfinite(d)]
            rows.append((case, f"|chain - model| max {np.max(fin, initial=0):.3g} deg, "
                               f"{int(np.sum(~np.isfinite(d)))} missed"))
        rows.append(("elapsed_s", self.elapsed_s))
        return f"{n} draws through the full ADC-cube chain against the phasor model", rows

    def _columns(self) -> dict:
        cols = {}
        for case in self.model_deg:
            d = self.difference_deg(case)
            cols.setdefault("draw", np.arange(d.size))
            cols[f"{case}_difference_deg"] = d
            if self.dims == 1 and not self.all_points:
                cols[f"{case}_model_deg"] = self.model_deg[case]
                cols[f"{case}_chain_deg"] = self.chain_deg[case]
        return cols

    def plot(self, title: str = ""):
        """Per case, the chain's error against the model's (deg) and the line of agreement."""
        return _verify_figure(self, title)

    def difference_deg(self, case: str) -> np.ndarray:
        """|chain - model| per draw (the largest over its verified set-points and angles),
        (N,); inf where the chain missed it."""
        d = np.abs(self.chain_deg[case] - self.model_deg[case])
        d = np.where(np.isfinite(d), d, np.inf)
        return d.reshape(d.shape[0], -1).max(axis=-1) if d.ndim > 1 else d

    def worst_difference_deg(self, case: str) -> np.ndarray:
        """|chain's worst - model's worst| per draw (a pair study's statistic), (N,)."""
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
        first = next(iter(self.model_deg.values()))
        cases = {}
        for case in self.model_deg:
            d = self.difference_deg(case)
            cases[case] = {"max_abs_difference_deg": float(np.max(d)) if d.size else 0.0}
            if self.dims == 1:
                cases[case]["max_worst_error_difference_deg"] = (
                    float(np.max(self.worst_difference_deg(case))) if d.size else 0.0)
            cases[case]["missed"] = int(np.count_nonzero(~np.isfinite(d)))
        if self.dims == 1:
            return {"draws": int(first.shape[0]),
                    "max_abs_difference_deg": self.max_difference_deg,
                    "set_point": ("every set-point" if self.all_points
                                  else "the draw's worst in the fast model"),
                    "cases": cases, "elapsed_s": self.elapsed_s}
        return {"draws": int(first.shape[0]), "subbin_steps": self.subbin_steps.tolist(),
                "set_point": ("every set-point" if self.all_points
                              else "the draw's worst (angular distance) in the fast model"),
                "max_abs_difference_deg": self.max_difference_deg, "cases": cases,
                "elapsed_s": self.elapsed_s}


def verify_draws(model: ChannelPhasors, sigma_m, mc: MonteCarlo, *, cases=CASES,
                 all_points: bool = False, positions=None) -> VerifyResult:
    """The first ``mc.draws`` draws of :func:`~.montecarlo.simulate` (``model``, ``sigma_m``,
    ``mc``) through the full chain
    (see the module): ``mc.seed`` (set), ``mc.distribution``; ``mc.subbin``: the sub-bin
    positions the study draws (False: the bin centre); ``positions`` (n,): indices into
    ``model.subbin_steps`` to use instead (e.g. a grid across the bin);
    ``mc.progress(label, done, total)`` per draw."""
    n, seed, distribution = mc.draws, mc.seed, mc.distribution
    subbin, progress = mc.subbin, mc.progress
    t0 = time.perf_counter()
    channels = list(model.front_ends)
    n_q = len(channels)
    off = draw_offsets(seed, n, sigma_m, distribution, n_q)
    if positions is not None:
        sub = np.asarray(positions, int).reshape(n)
    elif subbin:
        sub = draw_subbins(seed, n, model.subbin_steps.size)
    else:
        sub = np.full(n, model.subbin_zero)
    d = model.draw(off, sub, tuple(cases))
    scene = model.setup.scene
    n_fe = len(scene.rts.front_ends)
    tau0 = float(requested_delay(scene, model.range_m))
    res = model.delay_resolution_s
    n_m = model.set_rad.shape[0]
    dims = model.dims
    tail = () if dims == 1 else (2,)
    n_p = n_m if all_points else 1
    out = {k: {case: np.full((n, n_p) + tail, np.nan) for case in cases}
           for k in ("model", "chain")}
    index = {case: np.full((n, n_p), -1) for case in cases}
    for i in range(n):
        offsets = np.zeros((n_fe, 3))
        offsets[channels] = off[i]
        setup = build_setup(scene, offsets_m=offsets)
        paths = exact_paths(setup)
        d_u = int(model.subbin_steps[sub[i]])
        for case in cases:
            e = np.degrees(d[case]["error_rad"][i])  # (M,) or (M, 2)
            if all_points:
                points = range(n_m)
            elif dims == 1:
                points = [int(np.argmax(np.abs(e)))]
            else:
                points = [int(np.argmax(d[case]["distance_rad"][i]))]
            for j, m in enumerate(points):
                if dims == 1:  # J's delay as planned (the planner's alternatives included)
                    k = np.array([0, int(d[case]["j_steps"][i, m])])
                else:
                    k = d["steps"][i] if case == "calibrated" else np.zeros(n_q, int)
                amps = d[case]["amplitudes"][i, m] * (1.0 if dims == 1
                                                     else model.channels.unit_gain)
                prog = RtsProgram.build([0] * n_q, channels, list(tau0 + (d_u + k) * res),
                                        [0.0] * n_q, list(amps))
                _, cube = simulate(setup, paths, prog)  # noise-free
                rd, dets = process(cube)
                hit = nearest_detection(dets, rd, model.range_m + 0.5 * c * d_u * res)
                index[case][i, j] = m
                out["model"][case][i, j] = e[m]
                if hit is not None:
                    got = (dets.angle_rad[hit] if dims == 1
                           else np.array([dets.angle_rad[hit], dets.elevation_rad[hit]]))
                    out["chain"][case][i, j] = np.degrees(got - model.set_rad[m])
        if progress:
            progress("verify (ADC-cube chain)", i + 1, n)
    if dims == 1 and not all_points:  # a pair's worst set-point: (N,)
        out = {k: {case: v[:, 0] for case, v in o.items()} for k, o in out.items()}
        index = {case: v[:, 0] for case, v in index.items()}
    elif dims == 1:
        index = {case: np.full(n, -1) for case in cases}
    return VerifyResult(index, out["model"], out["chain"], time.perf_counter() - t0,
                        model.subbin_steps[sub], dims, all_points)


def _verify_figure(res: VerifyResult, title: str = ""):
    """The chain's worst error against the model's per draw and case (deg)."""
    import matplotlib as mpl
    from ...viz.figures import STYLE, new_figure
    with mpl.rc_context(STYLE):
        fig, ax = new_figure(figsize=(5.2, 4.4))
        lim = 0.0
        for case in res.model_deg:
            m = np.asarray(res.model_deg[case], float).ravel()
            ch = np.asarray(res.chain_deg[case], float).ravel()
            ok = np.isfinite(m) & np.isfinite(ch)
            ax.plot(m[ok], ch[ok], "o", mfc="none", label=f"{case} ({int(ok.sum())} of {m.size})")
            lim = max(lim, float(np.max(np.abs(np.r_[m[ok], ch[ok]]), initial=0)))
        lim = lim * 1.05 or 1.0
        ax.plot([-lim, lim], [-lim, lim], color="0.4", linewidth=0.8, label="agreement")
        ax.set_xlabel("phasor model error (deg)")
        ax.set_ylabel("full-chain error (deg)")
        ax.legend(loc="upper left")
        ax.set_title(title or "Tolerance draws through the full chain", parse_math=False)
    return fig
