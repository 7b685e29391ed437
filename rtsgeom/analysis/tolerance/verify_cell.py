"""The full ADC-cube chain check of the 2-D cell tolerance study (``rtsgeom tolerance --cell
--verify N``; :mod:`rtsgeom.analysis.tolerance.cell`): draws of the fast model pushed through
what ``run`` does (ADC cube, range-Doppler FFTs, CFAR, 2-D beamformer), the target at the
draw's sub-bin position."""

from __future__ import annotations

import time

import numpy as np
from scipy.constants import c

from ...paths import exact_paths
from .arc import arc_draws
from .driver import CASES
from .driver import draw_offsets
from .cell import CellPhasors

__all__ = ["verify_cell_draws"]


def verify_cell_draws(model: CellPhasors, sigma_m, n: int, seed: int,
                      distribution: str = "normal", cases=CASES, all_points: bool = False,
                      progress=None, subbin: bool = True, positions=None) -> dict:
    """The first ``n`` draws of ``monte_carlo_cell`` through the full chain
    (``tolerance_verify`` for a cell): each draw built as a real setup (the offsets on the
    cell's front ends, exact paths), the programme the fast model assumes (the target's delay
    at its sub-bin position plus each channel's calibration delay, the model's amplitudes: the
    design with the gain correction and the delays' loss)
    synthesized as a noise-free ADC cube and processed (``radar.process``: range-Doppler,
    CFAR, 2-D beamformer), one frame per draw and case at the set-point with the draw's
    largest angular distance in the fast model (``all_points``: at every set-point). Returns
    per case the model's and the chain's (azimuth, elevation) errors (n, P, 2) deg and the
    largest |chain - model| (inf where the chain detected nothing). ``subbin``: the sub-bin
    positions ``monte_carlo_cell`` draws (False: the bin centre); ``positions`` (n,): indices
    into ``model.subbin_steps`` to use instead (e.g. a grid across the bin)."""
    from ...geometry import build_setup
    from ...radar import process
    from ...radar.frame import simulate
    from ...radar.processing import nearest_detection
    from ...rts.channels import RtsProgram, requested_delay
    t0 = time.perf_counter()
    cell = list(model.cell)
    n_q, n_m = len(cell), model.set_rad.shape[0]
    off = draw_offsets(seed, n, sigma_m, distribution, n_q)
    if positions is not None:
        sub = np.asarray(positions, int).reshape(n)
    elif subbin:
        sub = next(arc_draws(seed, n, n_q, distribution, max(n, 1),
                             model.subbin_steps.size))["subbin"] if n else np.zeros(0, int)
    else:
        sub = np.full(n, model.subbin_zero)
    d = model.draw(off, cases, None, sub)
    scene = model.setup.scene
    tau0 = float(requested_delay(scene, model.range_m))
    res = model.delay_resolution_s
    n_p = n_m if all_points else 1
    out = {case: {"set_index": np.zeros((n, n_p), int),
                  "model_deg": np.full((n, n_p, 2), np.nan),
                  "chain_deg": np.full((n, n_p, 2), np.nan)} for case in cases}
    for i in range(n):
        offsets = np.zeros((len(scene.rts.front_ends), 3))
        offsets[cell] = off[i]
        setup = build_setup(scene, offsets_m=offsets)
        paths = exact_paths(setup)
        for case in cases:
            cal = case == "calibrated"
            k = d["steps"][i] if cal else np.zeros(n_q, int)
            delays = tau0 + (model.subbin_steps[sub[i]] + k) * res
            pts = (range(n_m) if all_points
                   else [int(np.argmax(d[case]["distance_rad"][i]))])
            for j, m in enumerate(pts):
                amps = model.cells.unit_gain * d[case]["amplitudes"][i, m]
                prog = RtsProgram.build([0] * n_q, cell, list(delays), [0.0] * n_q,
                                        list(amps))
                _, cube = simulate(setup, paths, prog)  # noise-free
                rd, dets = process(cube)
                hit = nearest_detection(
                    dets, rd, model.range_m + 0.5 * c * model.subbin_steps[sub[i]] * res)
                out[case]["set_index"][i, j] = m
                out[case]["model_deg"][i, j] = np.degrees(d[case]["error_rad"][i, m])
                if hit is not None:
                    got = np.array([dets.angle_rad[hit], dets.elevation_rad[hit]])
                    out[case]["chain_deg"][i, j] = np.degrees(got - model.set_rad[m])
        if progress:
            progress("verify (ADC-cube chain)", i + 1, n)
    summary = {}
    for case in cases:
        diff = np.abs(out[case]["chain_deg"] - out[case]["model_deg"])
        diff = np.where(np.isfinite(diff), diff, np.inf)
        summary[case] = {"max_abs_difference_deg": float(diff.max()) if diff.size else 0.0,
                         "missed": int(np.count_nonzero(~np.isfinite(diff[..., 0])))}
    return {"draws": n, "subbin_steps": model.subbin_steps[sub].tolist(), "set_point": ("every set-point" if all_points
                                      else "the draw's worst (angular distance) in the fast model"),
            "max_abs_difference_deg": max((v["max_abs_difference_deg"]
                                           for v in summary.values()), default=0.0),
            "cases": summary, "detail": out, "elapsed_s": time.perf_counter() - t0}
