"""What every calibration measures with: probe targets and each front end alone, as the
simulated RuT detects them (paper section "Calibration", the amplitude step), and the IF and RF
phase slopes that turn a measured phase into a delay (eqs. 8 and 27).

* :func:`probe_front_ends`: each front end alone at its own probe range (one frame): its
  detected angle and power, and the gain correction that equalises measured and modelled
  power (the amplitude calibration).
* :func:`probe_ranges` / :func:`probe_angles`: where a pair's two probe targets sit (apart,
  clear of each other's cable ghosts; at a quarter and three quarters of the span).
* :func:`place_in_bins`: the probes' ranges moved within their range bins so that the bin
  the RuT detects them in stays clear of its neighbours over the fine sweep's window.
* :func:`simulate_detect`: one radar output, the coherent average of K frames of a static
  programme, through the full ADC-cube chain.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.constants import c

from .._lib.util import one_blas_thread, warn_caller
from ..errors import RtsgeomWarning
from ..geometry import Setup
from ..geometry.farfield import two_way_lengths
from ..paths import Paths, nominal_model
from ..radar import process
from ..radar.frame import simulate
from ..radar.processing import nearest_detection
from ..rts.channels import RtsProgram, requested_delay
from ..scene import TargetConfig
from ..synthesis.model import ChannelModel

__all__ = ["FrontEndProbe", "clipping_note", "probe_front_ends", "probe_ranges", "probe_angles",
           "probe_total_delay", "probe_program", "simulate_detect", "if_phase_slope_hz",
           "air_phase_slope_hz", "mean_air_delay", "place_in_bins", "PLACEMENT_OFFSETS_BINS",
           "probes_per_frame", "probe_layout", "ProbeWarning", "front_end_models"]


@dataclass(frozen=True)
class FrontEndProbe:
    """Each front end alone, as the RuT detects it."""

    angle_rad: np.ndarray  # (F,) detected azimuth
    power_db: np.ndarray  # (F,) detected range-Doppler power
    gain_correction: np.ndarray  # (F,) multiply the programmed amplitude by this
    adc_clipped: int = 0  # samples the ADC clipped in the probe frame (with [radar.link])
    #: (F,) each front end alone as the planner's model (the nominal setup, noiseless) reads
    #: it: the span the exact design reaches; None where not modelled
    model_angle_rad: np.ndarray | None = None

    def clipping_note(self) -> str:
        """Why a front end may be missing: the probe frame's ADC clipping, if any."""
        return clipping_note(self.adc_clipped)


PLACEMENT_OFFSETS_BINS = np.linspace(-0.5, 0.4, 10)  # candidate moves of a probe (bins)


def place_in_bins(scene, ranges, margin, offsets_bins=PLACEMENT_OFFSETS_BINS) -> np.ndarray:
    """Probe ranges (P,) moved within a range bin by the candidate ``offsets_bins`` (bins)
    to the one with the largest ``margin`` (ranges (P,) -> (P,)): each probe's worst margin,
    over the fine sweep's window, of the bin the RuT detects it in over the next strongest
    (0 where design and detection disagree). What a lab chooses when it sets its probe
    targets' ranges: a combined echo that straddles two bins of nearly equal power is
    detected in either, and its angle jumps with the bin (the two channels' echoes sit at
    different ranges, so their ratio differs from bin to bin)."""
    ranges = np.asarray(ranges, float)
    bin_m = scene.radar.range_resolution_m  # one range bin
    score = np.array([margin(ranges + o * bin_m) for o in offsets_bins])  # (O, P)
    return ranges + np.asarray(offsets_bins)[np.argmax(score, axis=0)] * bin_m


def clipping_note(clipped: int) -> str:
    """A clause for a 'not detected' message when the ADC clipped ``clipped`` samples."""
    if not clipped:
        return ""
    return (f"; the ADC clipped {clipped} samples of the probe frame (a setup echo above full "
            "scale, e.g. the sheet's reflection: add an absorber, sheet.reflection_loss_db or "
            "[[structure]] reflection_loss_db, or lower the gain in [radar.link])")


def if_phase_slope_hz(scene, tau_s) -> np.ndarray:
    """d(phase)/d(tau_rts) / 2 pi of an echo of total delay ``tau_s`` at the ADC window's
    centre: ``f_rts + S t_mid - S tau`` (eq. 8 at t = t_mid; eq. 27 is its approximation
    f_rts + B/2). Its inverse is the exact period of the calibration sweep."""
    radar = scene.radar
    return (scene.rts.f_rts_hz + (radar.f_center_hz - radar.f_c_hz)
            - radar.slope_hz_per_s * np.asarray(tau_s, float))


def air_phase_slope_hz(scene, tau_s) -> np.ndarray:
    """d(phase)/d(tau_c) / 2 pi of the same echo: ``f_c + S t_mid - S tau`` (the over-the-air
    delay acts at RF). A radial offset dr moves the coherence point by
    ``-air_phase_slope_hz / if_phase_slope_hz * 2 dr / c0``."""
    radar = scene.radar
    return radar.f_center_hz - radar.slope_hz_per_s * np.asarray(tau_s, float)


def probe_total_delay(setup: Setup, ranges) -> float:
    """Mean total delay tau = tau_c + tau_rts of probe targets at ``ranges`` (what sets the
    beat frequency S tau)."""
    return float(np.mean(requested_delay(setup.scene, np.asarray(ranges, float)))
                 + np.mean(mean_air_delay(setup)))


def probe_angles(theta_i: float, theta_j: float) -> tuple[float, float]:
    """Calibration probes at a quarter and three quarters of the span between two front ends."""
    return theta_i + 0.25 * (theta_j - theta_i), theta_i + 0.75 * (theta_j - theta_i)


def probe_ranges(setup: Setup, n: int) -> np.ndarray:
    """Ranges for n simultaneous probe targets: distinct, away from the setup, and clear of
    each other's cable ghosts (at multiples of L / VF behind each probe), which would otherwise
    leak into a neighbour's bin and bias its angle. More than :func:`probes_per_frame` of them
    run past the usable range axis: :func:`probe_layout` measures those in turns."""
    scene = setup.scene
    radar = scene.radar
    r0 = max(0.2 * radar.max_range_m, scene.rts.arc_radius_m + 2.0)
    return r0 + _probe_step(setup, n) * np.arange(n)


def _probe_step(setup: Setup, n: int) -> float:
    """The spacing (m) of n simultaneous probes (:func:`probe_ranges`)."""
    radar = setup.scene.radar
    ghosts = [k * fe.cable_length_m / fe.cable_velocity_factor for fe in setup.scene.rts.front_ends
              if fe.return_loss_fe_db is not None and fe.return_loss_be_db is not None
              for k in range(1, 6)]
    clear = 4 * radar.range_resolution_m
    # Apart by more than the CFAR window in range (guard + training cells): a probe inside a
    # neighbour's training cells raises that one's noise estimate, and on a coarse cube
    # (128 samples: 8 bins = 4.8 m) one probe went undetected.
    cfar_cells = radar.cfar.guard_cells[0] + radar.cfar.training_cells[0] + 2
    step = max(max(8, cfar_cells) * radar.range_resolution_m, 3.0)
    while any(abs(m * step - g) < clear for g in ghosts for m in range(1, n)):
        step += radar.range_resolution_m
    return step


PROBE_RANGE_LIMIT = 0.85  # probes stay below this fraction of the range axis (its IF roll-off)


def probes_per_frame(setup: Setup, n: int) -> int:
    """How many of n front ends' probes one frame holds (at least 1): the probes at
    :func:`probe_ranges` up to ``PROBE_RANGE_LIMIT`` of the RuT's range axis, beyond which
    the IF filter's roll-off and the axis' end lose them (33 front ends 3 m apart ran to 111
    m on a 77 m axis)."""
    limit = PROBE_RANGE_LIMIT * setup.scene.radar.max_range_m
    r0 = float(probe_ranges(setup, 1)[0])
    # no more than the unconstrained spacing allows (a ghost only widens it), then fewer
    # until the spacing they need fits
    k = max(1, min(n, int((limit - r0) // _probe_step(setup, 1)) + 1))
    while k > 1 and r0 + _probe_step(setup, k) * (k - 1) > limit:
        k = max(1, min(k - 1, int((limit - r0) // _probe_step(setup, k)) + 1))
    return k


def probe_layout(setup: Setup, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Each of n front ends' probe range (n,) and the turn (frame) it is measured in (n,):
    :func:`probes_per_frame` front ends a frame at :func:`probe_ranges`, the next ones in the
    next frame at the same ranges (one frame where they all fit: the same ranges as one
    frame). The frames grow linearly with n, and so does the cost."""
    k = probes_per_frame(setup, n)
    ranges = probe_ranges(setup, k)
    q = np.arange(n)
    return ranges[q % k], q // k


def simulate_detect(setup, paths, program, seed, frames: int = 1, clipped: bool = False):
    """One radar output: the coherent average of ``frames`` frames of a static RTS program.

    The K frames carry the same noise-free cube and independent receiver noise, so their
    average is that cube plus noise of power N0 / K: simulated as one frame at an SNR
    10 log10(K) dB higher, which has exactly the distribution of the average and costs one
    frame. With ``[radar.link]`` (no ``snr_db``) the same: the link's noise power / K."""
    snr = setup.scene.radar.snr_db
    if snr is not None and frames > 1:
        snr = snr + 10 * np.log10(frames)
    _, cube = simulate(setup, paths, program, seed, snr, noise_frames=frames)
    rd, det = process(cube)
    return (rd, det, int(cube.clipped)) if clipped else (rd, det)


class ProbeWarning(RtsgeomWarning, RuntimeWarning):
    """A front end the RuT does not detect alone at its probe range (its angle is NaN)."""


@one_blas_thread
def probe_front_ends(setup: Setup, paths: Paths, seed: int = 0) -> FrontEndProbe:
    """Each front end alone at its own probe range: measured angle and power; the gain
    correction equalises measured against modelled power; the angle each reads on the
    nominal model (``model_angle_rad``, noiseless: the span the planner's exact design
    reaches). One simulated frame holds :func:`probes_per_frame` of them; more are measured
    in turns, a frame each, at the same ranges (:func:`probe_layout`; turn t > 0 draws its
    noise from ``SeedSequence([seed, t])``). BLAS on one thread, as :func:`calibrate_pair`.

    Parameters
    ----------
    setup : Setup
        The setup as built (:func:`rtsgeom.build_setup`).
    paths : Paths
        Its propagation paths.
    seed : int
        The first frame's noise seed.

    Returns
    -------
    FrontEndProbe
        Per front end the measured angle (rad; NaN where not detected), the angle on the
        nominal model, power (dB) and gain correction (1 where not detected), and the ADC
        samples the probe frames clipped.

    Warns
    -----
    ProbeWarning
        A front end the RuT does not detect alone at its probe range.
    """
    scene = setup.scene
    n = setup.fe.count
    ranges, turn = probe_layout(setup, n)
    model_p, amps, model_ang = front_end_models(setup, paths, ranges)
    ang = np.full(n, np.nan)
    pw = np.full(n, np.nan)
    n_clip = 0
    for t in range(int(turn.max()) + 1 if n else 0):
        fes = np.flatnonzero(turn == t)
        prog = RtsProgram.build(np.arange(fes.size), fes, requested_delay(scene, ranges[fes]),
                                np.zeros(fes.size), amps[fes])
        frame_seed = seed if t == 0 else np.random.SeedSequence([int(seed) % 2 ** 32, t])
        rd, det, clipped = simulate_detect(setup, paths, prog, frame_seed, clipped=True)
        n_clip += clipped
        for q in fes:
            k = nearest_detection(det, rd, ranges[q])
            if k is not None:
                ang[q], pw[q] = det.angle_rad[k], det.power_db[k]
    missed = [q for q in range(n) if not np.isfinite(ang[q])]
    if missed:  # not silently: its angle is NaN and its gain correction falls back to 1
        warn_caller(f"front end(s) {missed} not detected alone at the probe range(s) "
                      f"{np.round(ranges[missed], 3).tolist()} m (below the CFAR threshold or "
                      "beyond the range axis): their measured angle is NaN and their gain "
                    "correction 1" + clipping_note(n_clip), ProbeWarning)
    meas = 10 ** (pw / 10) / amps ** 2
    corr = np.sqrt(model_p / meas)
    return FrontEndProbe(ang, pw, np.where(np.isfinite(corr), corr, 1.0), n_clip, model_ang)


def front_end_models(setup: Setup, paths: Paths, ranges=None
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each front end alone on the nominal model at its probe range (``ranges`` (F,), default
    :func:`probe_layout`'s): its power summed over the virtual elements at its strongest bin,
    its unit gain and the azimuth the RuT reads it at (rad, noiseless), each (F,)."""
    n = setup.fe.count
    ranges = probe_layout(setup, n)[0] if ranges is None else ranges
    design, design_paths = nominal_model(setup, paths)
    model_p, amps, ang = np.empty(n), np.empty(n), np.empty(n)
    for q in range(n):
        j = (q + 1) % n if n > 1 else q
        m = ChannelModel.build(design, design_paths, (q, j), TargetConfig(float(ranges[q])))
        model_p[q] = np.max(np.sum(np.abs(m.responses[:, 0]) ** 2, axis=-1))
        amps[q] = m.unit_gain
        ang[q] = float(m.direction(np.array([1.0, 0.0])))
    return model_p, amps, ang


def probe_program(design, pair, base, delta):
    """Both probes on both channels; channel J delayed by ``delta`` more."""
    tg, fe, dl, amp = [], [], [], []
    for k, (a_i, a_j) in enumerate(design):
        tg += [k, k]
        fe += list(pair)
        dl += [base[k][0], base[k][1] + delta]
        amp += [a_i, a_j]
    return RtsProgram.build(tg, fe, dl, np.zeros(len(tg)), amp)


def mean_air_delay(setup: Setup) -> np.ndarray:
    """Mean over virtual elements of each front end's two-way line-of-sight delay."""
    return two_way_lengths(setup.rut, setup.fe.rx, setup.fe.tx).mean(axis=1) / c
