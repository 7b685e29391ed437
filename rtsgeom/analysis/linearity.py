"""Angle linearity of a synthesized target across a pair's span (paper Fig. "Amplitude
attenuation and angle linearity and error"), on the simulated RuT output."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..geometry import Setup
from ..paths import Paths
from ..rts.channels import RtsProgram, requested_delay
from ..scene import TargetConfig
from ..radar.processing import nearest_detection
from ..calibration.pair import Calibration
from ..calibration.probes import FrontEndProbe, simulate_detect, probe_angles, probe_ranges
from ..pipeline.pair import pair_design

__all__ = ["Linearity", "linearity"]


@dataclass(frozen=True)
class Linearity:
    mode: str
    calibrated: bool
    set_deg: np.ndarray
    detected_deg: np.ndarray
    amplitude_db: np.ndarray  # (2, n) programmed attenuation of channels I and J
    end_angles: str = "geometric"  # front-end angles the closed forms used

    @property
    def error_deg(self) -> np.ndarray:
        return self.detected_deg - self.set_deg

    @property
    def max_abs_error_deg(self) -> float:
        return float(np.nanmax(np.abs(self.error_deg)))

    def to_dict(self) -> dict:
        return {
            "mode": self.mode, "calibrated": self.calibrated, "end_angles": self.end_angles,
            "points": [{"set_deg": float(s), "detected_deg": float(d), "error_deg": float(d - s)}
                       for s, d in zip(self.set_deg, self.detected_deg)],
            "max_abs_error_deg": self.max_abs_error_deg,
        }


END_ANGLES = ("geometric", "measured")


def _closed_form_measured(setup, paths, pair, target, mode, probe, offsets, corr):
    """``paper`` / ``array-factor`` amplitudes with the front ends' *measured* angles (each
    alone as the RuT detects it, as the paper's angles were "determined by measurement")
    in the closed form, instead of their geometric azimuths."""
    from ..paths import nominal_model
    from ..synthesis.model import ChannelModel
    from ..synthesis.closed_form import array_factor_args, ratio_array_factor, ratio_paper
    i, j = pair
    th = probe.angle_rad[[i, j]]
    alpha = target.angle_rad
    nom, nom_paths = nominal_model(setup, paths)
    model = ChannelModel.build(nom, nom_paths, pair, target, offsets)
    if mode == "paper":
        rho = float(ratio_paper(th[0], th[1], alpha))
    else:  # the RuT's own beamformer (taper, repeated elements), as the geometric reading
        rho = float(ratio_array_factor(th[0], th[1], alpha,
                                       **array_factor_args(model.steering)))
    rho = float(np.clip(rho, 0.0, 1e12))
    phase = float(model.pair_phase(probe_angles(*th)))
    a_i, a_j = model.amplitudes(model.pair_weights(rho, (0.0, phase)), np.sin([alpha]))
    return a_i * corr[0], a_j * corr[1], rho


def linearity(setup: Setup, paths: Paths, pair: tuple[int, int], mode: str,
              probe: FrontEndProbe, calibration: Calibration | None, points: int = 21,
              seed: int = 0, end_angles: str = "geometric") -> Linearity:
    """Sweep the set angle across ``pair`` and detect each synthesized target on the simulated
    RuT.

    The span is where every mode can work: the intersection of the measured span (each front
    end alone as the RuT detects it; near field and Rx/Tx separation move it) and the
    geometric span (the closed forms only reach between the front ends' geometric angles);
    its ends are excluded, where one channel would be off.

    ``end_angles``: which front-end angles the closed forms (``paper``, ``array-factor``)
    use: ``geometric`` (module azimuths of the nominal setup) or ``measured`` (each front
    end alone as the RuT detects it); ``exact`` ignores it.
    """
    if end_angles not in END_ANGLES:
        raise ParameterError(f"end_angles = {end_angles!r}: must be one of {END_ANGLES}")
    scene = setup.scene
    i, j = pair
    meas = np.sort(probe.angle_rad[[i, j]])
    geo = np.sort(setup.fe_azimuth_rad()[[i, j]])
    th = np.array([max(meas[0], geo[0]), min(meas[1], geo[1])])
    frac = np.arange(1, points + 1) / (points + 1)
    sets = th[0] + frac * (th[1] - th[0])
    off = (0.0, calibration.delta_tau_s if calibration else 0.0)
    corr = probe.gain_correction[[i, j]] if calibration else np.ones(2)
    rng = float(probe_ranges(setup, 1)[0])
    tau = float(requested_delay(scene, rng))
    det_deg = np.full(points, np.nan)
    amp = np.zeros((2, points))
    for k, a in enumerate(sets):
        t = TargetConfig(rng, 0.0, 10.0, float(a))
        if end_angles == "measured" and mode != "exact":
            a_i, a_j, _ = _closed_form_measured(setup, paths, pair, t, mode, probe, off, corr)
        else:
            a_i, a_j, _, off_j = pair_design(setup, paths, pair, t, mode,
                                             probe_angles(*probe.angle_rad[[i, j]]), off, corr,
                                             calibration.quantisation_residual_s
                                             if calibration else 0.0)
        amp[:, k] = a_i, a_j
        off_j = off[1] if end_angles == "measured" and mode != "exact" else off_j
        prog = RtsProgram.build([0, 0], [i, j], [tau + off[0], tau + off_j], [0.0, 0.0],
                                [a_i, a_j])
        rd, det = simulate_detect(setup, paths, prog, seed)
        n = nearest_detection(det, rd, rng)
        if n is not None:
            det_deg[k] = np.degrees(det.angle_rad[n])
    amp_db = 20 * np.log10(np.maximum(amp, 1e-300) / np.max(amp))
    return Linearity(mode, calibration is not None, np.degrees(sets), det_deg, amp_db,
                     end_angles)
