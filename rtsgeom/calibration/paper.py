"""The paper's calibration procedure as written (section "Measurement"), for comparison with
rtsgeom's own (:func:`rtsgeom.calibration.pair.calibrate_pair`; docs/paper-comparison.md)."""

from __future__ import annotations

import numpy as np
from scipy.constants import c

from .._lib.util import frozen
from ..geometry import Setup
from ..paths import Paths, nominal_model
from ..radar.processing import nearest_detection
from ..rts.channels import RtsProgram, requested_delay
from ..scene import TargetConfig
from ..synthesis.closed_form import ratio_paper
from ..synthesis.model import ChannelModel
from .probes import (FrontEndProbe, if_phase_slope_hz, mean_air_delay, probe_front_ends,
                     probe_ranges, probe_total_delay, simulate_detect)
from .steps import realisable
from .sweep import Calibration

__all__ = ["calibrate_pair_paper"]


def calibrate_pair_paper(setup: Setup, paths: Paths, pair: tuple[int, int],
                         probe: FrontEndProbe | None = None, seed: int = 0,
                         set_angle_rad: float | None = None, span_s=None,
                         step_s=None) -> Calibration:
    """The paper's calibration procedure as written (section "Measurement"): one target at
    one set angle (default: the middle of the pair's geometric span), its amplitudes fixed
    from eq. (23) with the nominal geometric front-end angles (times the amplitude
    calibration's gain correction) and never re-designed, channel J's delay swept over the
    scene's span (paper: [-0.5, 1] ns in 25 ps steps, one frame per step, no refinement),
    the delay with the smallest |angle error| kept.

    rtsgeom's own procedure (:func:`calibrate_pair`) instead re-designs the amplitudes with
    the exact model at every step and uses two probes; with fixed amplitudes the optimum
    is where the *fixed* design happens to hit the set angle, which need not be the
    coherence point (docs/paper-comparison.md)."""
    scene = setup.scene
    rts = scene.rts
    i, j = pair
    probe = probe or probe_front_ends(setup, paths, seed)
    nom, nom_paths = nominal_model(setup, paths)
    th = nom.fe_azimuth_rad()[[i, j]]
    alpha = float(np.mean(th)) if set_angle_rad is None else float(set_angle_rad)
    rng = float(probe_ranges(setup, 1)[0])
    target = TargetConfig(rng, 0.0, 10.0, alpha)
    unit = ChannelModel.build(nom, nom_paths, pair, target).unit_gain
    rho = float(ratio_paper(th[0], th[1], alpha))
    amp = (unit * probe.gain_correction[i], unit * rho * probe.gain_correction[j])
    tau = float(requested_delay(scene, rng))
    span = span_s or rts.calibration_span_s
    step = step_s or rts.calibration_step_s
    grid = np.arange(span[0], span[1] + step / 2, step)
    errs = np.full(grid.size, np.inf)
    for k, d in enumerate(grid):
        prog = RtsProgram.build([0, 0], [i, j], [tau, tau + d], [0.0, 0.0], list(amp))
        step_seed = np.random.SeedSequence([int(seed) % 2 ** 32, int(round(d * 1e15)) + 2 ** 40])
        rd, det = simulate_detect(setup, paths, prog, step_seed)
        n = nearest_detection(det, rd, rng)
        if n is not None:
            errs[k] = abs(np.degrees(det.angle_rad[n] - alpha))
    k = int(np.argmin(errs))
    res = rts.delay_resolution_s
    best = float(realisable(grid[k], res))  # the grid's steps are multiples unless the
    # scene's calibration_step_ps is not (validate warns)
    air = mean_air_delay(setup)
    range_offset = 0.5 * c * ((air[j] + best) - air[i])
    period = 1.0 / float(if_phase_slope_hz(scene, probe_total_delay(setup, [rng])))
    deg = float(np.degrees(alpha))
    return Calibration(pair, best, float(errs[k]), float(range_offset), frozen(grid),
                       frozen(errs), frozen(np.zeros(0)), frozen(np.zeros(0)), (deg, deg), period,
                       1, 0.0, quantisation_residual_s=float(grid[k] - best),
                       delay_resolution_s=float(res))
