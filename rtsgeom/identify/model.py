"""The probe's forward model: the RuT's spectrum at the probe's range-Doppler bin per virtual
element as a function of one front end's mounting and channel parameters (:data:`PARAMS`), and
:func:`measure`, the same quantity read off a capture (see :mod:`rtsgeom.identify`)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from scipy.constants import c

from .._lib.arcmath import ModuleLayout, antenna_positions, layout_offsets
from ..errors import CaptureError
from ..geometry import Setup
from ..paths.exact import leg_delays
from .capture import Capture, check_capture_radar
from ..radar.frame import noise_power
from ..radar.phasors import bin_response
from ..radar.processing import range_doppler
from ..radar.windows import window
from ..rts.channels import EchoKind, Echoes, requested_delay
from ..rts.fir import fir_if_gain, realised_delay
from ..radar.fmcw import AdcCube

__all__ = ["PARAMS", "ProbeModel", "measure", "probe_offset_bins", "SUBBIN_LIMIT"]

#: the fitted parameters per front end / channel, SI inside (m, rad, s; gain as ln|G|)
PARAMS = ("radial_offset", "tangential_offset", "height_offset", "yaw_offset", "delay_offset",
          "log_gain", "phase")
# central-difference steps (SI), per parameter
_STEP = np.array([1e-6, 1e-6, 1e-6, 1e-5, 1e-14, 1e-6, 1e-6])



@dataclass(frozen=True)
class ProbeModel:
    """The probe's spectrum at its bin per virtual element, for a batch of parameter vectors
    (:data:`PARAMS`, SI) of front end ``active`` on the nominal ``setup``."""

    setup: Setup
    active: int
    range_m: float
    velocity_mps: float
    amplitude: float
    range_bin: int
    doppler_bin: int
    rts_delay_s: float | None = None  # the RTS channel's programmed delay (None: the scene's)

    @classmethod
    def of(cls, setup: Setup, cap: Capture, range_bin: int | None = None) -> "ProbeModel":
        radar = setup.scene.radar
        f_d = 2 * radar.f_c_hz * cap.velocity_mps / c
        rb = (int(np.round(cap.range_m * 2 * radar.slope_hz_per_s / c * radar.samples_per_chirp
                           / radar.adc_rate_hz)) if range_bin is None else int(range_bin))
        n_l = radar.chirps_per_tx
        db = (int(np.round(f_d * radar.tdm_cycle_s * n_l)) + n_l // 2) % n_l
        return cls(setup, cap.active, cap.range_m, cap.velocity_mps, cap.amplitude, rb, db,
                   cap.rts_delay_s)

    def programmed_delay(self) -> float:
        """The probe channel's requested delay: the capture's recorded ``rts_delay_s``, else
        what the scene programs for the probe's range (``requested_delay``)."""
        if self.rts_delay_s is not None:
            return float(self.rts_delay_s)
        return float(requested_delay(self.setup.scene, self.range_m))

    def nominal(self) -> np.ndarray:
        """The scene's own values of the parameters (its offsets, gain and phase errors)."""
        f = self.setup.scene.rts.front_ends[self.active]
        yaw = f.yaw_offset_rad
        return np.array([f.radial_offset_m, f.tangential_offset_m, f.height_offset_m, yaw, 0.0,
                         f.gain_offset_db * np.log(10) / 20, f.phase_offset_rad])

    def echoes(self, theta) -> Echoes:
        """One direct echo per parameter vector ``theta`` (B, 7)."""
        th = np.atleast_2d(np.asarray(theta, float))
        scene, rut, fe = self.setup.scene, self.setup.rut, self.setup.fe
        q = slice(self.active, self.active + 1)
        ro = fe.rx_offset_m[q] if fe.rx_offset_m is not None else layout_offsets(fe.separation_m[q])[0]
        to = fe.tx_offset_m[q] if fe.tx_offset_m is not None else layout_offsets(fe.separation_m[q])[1]
        pitch = None if fe.pitch_rad is None else fe.pitch_rad[q]
        rx, tx, _ = antenna_positions(fe.arc_centre, fe.arc_radius_m, fe.angle_rad[q],
                                      fe.separation_m[q], th[:, None, 0:3],
                                      layout=ModuleLayout(ro, to, th[:, 3:4], pitch))
        t_a, t_b = leg_delays(rut.tx_world, rut.rx_world, rx, tx)  # (B, 1, Ntx), (B, 1, Nrx)
        t_a, t_b = t_a[:, 0, rut.virtual_tx], t_b[:, 0, rut.virtual_rx]  # (B, V)
        lam = rut.wavelength_m
        g = (lam / (4 * np.pi * c * t_a)) * (lam / (4 * np.pi * c * t_b))
        gain = np.exp(th[:, 5] + 1j * th[:, 6]) * self.amplitude
        rts = scene.rts
        tau0 = realised_delay(self.programmed_delay(), rts.f_s_hz,
                              rts.fractional_delay, rts.fractional_delay_step_s)
        tau_if = tau0 + th[:, 4]
        tau_air = t_a + t_b
        fir = fir_if_gain(scene, tau_if, tau_if + tau_air.mean(axis=1))
        f_d = 2 * scene.radar.f_c_hz * self.velocity_mps / c
        return Echoes.build(tau_air_s=tau_air, amplitude=np.conj(g * gain[:, None]),
                            tau_if_s=tau_if, f_if_hz=rts.f_rts_hz, doppler_hz=f_d, target=0,
                            front_end=self.active, kind=EchoKind.DIRECT, fast_gain=fir)

    def response(self, theta) -> np.ndarray:
        """Spectrum at the probe's bin per virtual element, (B, V) complex128."""
        ech = self.echoes(theta)
        return bin_response(ech, self.setup.scene.radar, self.setup.rut, [self.range_bin],
                            [self.doppler_bin])[0]

    def jacobian(self, theta, free) -> tuple[np.ndarray, np.ndarray]:
        """Response (V,) at ``theta`` and its derivatives (V, P) along the ``free`` parameters
        (central differences, all columns in one batched call)."""
        th = np.asarray(theta, float)
        free = list(free)
        h = _STEP[free]
        batch = np.repeat(th[None], 2 * len(free) + 1, axis=0)
        k = np.arange(len(free))
        batch[1 + k, free] += h
        batch[1 + len(free) + k, free] -= h
        y = self.response(batch)
        return y[0], ((y[1:1 + len(free)] - y[1 + len(free):]) / (2 * h[:, None])).T

    def noise_variance(self, theta, snr_db: float) -> float:
        """Noise variance of one complex spectrum value at the bin for the scene's per-sample
        SNR ``snr_db`` of this echo (``radar.frame.noise_power``) after both windowed DFTs."""
        radar = self.setup.scene.radar
        p = noise_power(self.echoes(theta), snr_db)
        return float(p * np.sum(window(radar.range_window, radar.samples_per_chirp) ** 2)
                     * np.sum(window(radar.doppler_window, radar.chirps_per_tx) ** 2))


def measure(setup: Setup, cap: Capture, check_direction: bool = True
            ) -> tuple[np.ndarray, float, ProbeModel]:
    """The RuT's processing of a capture: the range-Doppler spectrum (``radar.processing``) at
    the probe's bin per virtual element (V,), the noise variance of one spectrum value (median
    of |X|^2 over the whole map / ln 2: the median of an exponential, untouched by the few
    target cells), and the probe's model at that bin (the strongest of the three range bins
    around the set range).

    The capture is checked against the scene first: its shape and recorded radar
    (:func:`~rtsgeom.identify.capture.check_capture_radar`), the probe inside the radar's
    range and velocity, and the strongest echo of its range-Doppler map at the probe's bin
    (within one bin): a sidecar that does not describe its capture is refused, not fitted.
    ``check_direction``: also that the probe's direction across the array is the named front
    end's (off where the radar's own channel errors are fitted too: an uncalibrated radar's
    antenna phases bend the direction onto the neighbour's; the joint fit's residual checks
    the capture instead)."""
    radar = setup.scene.radar
    want = (radar.chirps_per_tx, setup.rut.num_virtual, radar.samples_per_chirp)
    if cap.data.shape != want:
        raise CaptureError(f"capture of front end {cap.active}: shape {list(cap.data.shape)} "
                           f"does not match the scene's radar {list(want)} [loop, virtual, sample]")
    if not 0 <= cap.active < setup.fe.count:
        raise CaptureError(f"{cap.source}: active_front_end = {cap.active}: must be a front "
                           f"end of the scene (0..{setup.fe.count - 1})")
    order = tuple(int(t) for t in setup.rut.tx_order)
    if cap.tx_order is not None and tuple(cap.tx_order) != order:
        raise CaptureError(f"{cap.source}: tx_order = {list(cap.tx_order)}: must be the "
                           f"scene's radar's {list(order)} (another TDM order puts other "
                           "antennas in each virtual channel)")
    check_capture_radar(cap, radar)
    if not cap.range_m < radar.max_range_m:
        raise CaptureError(f"{cap.source}: probe_range_m = {cap.range_m:g}: must be below the "
                           f"scene's radar range {radar.max_range_m:g} m")
    if not abs(cap.velocity_mps) < radar.max_velocity_mps:
        raise CaptureError(f"{cap.source}: probe_velocity_mps = {cap.velocity_mps:g}: must be "
                           f"within the scene's unambiguous +-{radar.max_velocity_mps:g} m/s")
    # processed at unit peak (complex64 keeps a capture of any scale finite), read back in the
    # capture's units in float64
    scale = float(np.max(np.abs(cap.data)))
    rd = range_doppler(AdcCube((cap.data / scale).astype(np.complex64), radar, setup.rut))
    model = ProbeModel.of(setup, cap)
    power, gain = _positive_half(rd.power, model, radar, cap)
    _check_peak(power, model, radar, cap)
    _check_subbin(power, model, radar, cap)
    rbs = (model.range_bin + np.arange(-1, 2)) % radar.samples_per_chirp
    best = int(rbs[np.argmax(power[rbs, model.doppler_bin])])
    model = ProbeModel.of(setup, cap, best)
    x = rd.spectrum
    sigma2 = float(np.median(x.real.astype(float) ** 2 + x.imag.astype(float) ** 2) / np.log(2))
    if not sigma2 > 0:
        raise CaptureError(f"{cap.source}: no receiver noise in the capture (the median "
                           "range-Doppler power is 0): must be a recorded or simulated "
                           "capture with noise")
    y = rd.spectrum[best, model.doppler_bin].astype(complex) * gain
    if check_direction:
        _check_front_end(setup, model, y, cap)
    return y * scale, sigma2 * (gain * scale) ** 2, model


def _positive_half(power: np.ndarray, model: ProbeModel, radar, cap: Capture
                   ) -> tuple[np.ndarray, float]:
    """The power map the probe is searched in and the factor from a spectrum value to the
    complex-baseband model's. A complex capture: the whole map, 1. A real-only capture
    (``cap.adc == "real"``, the AWR2944's receiver): ``x = Re(z)`` has the conjugate-symmetric
    spectrum ``X[k, d] = (Z[k, d] + conj(Z[-k, -d])) / 2``, so the echo appears twice; the
    estimator reads the positive-frequency half (range bins 1 .. N/2 - 1, the mirror zeroed)
    at twice its value (``2 X[k] = Z[k]`` up to the mirror's leakage through the range
    window), and its noise variance is four times the map's. Its unambiguous range is half
    the complex ADC's: ``c f_adc / (4 S)``."""
    if cap.adc != "real":
        return power, 1.0
    n_s = radar.samples_per_chirp
    if not 2 <= model.range_bin <= n_s // 2 - 2:
        r_max = radar.max_range_m / 2
        raise CaptureError(f"{cap.source}: probe_range_m = {cap.range_m:g}: must be within a "
                           f"real-only capture's unambiguous range, below {r_max:.4g} m "
                           "(beat frequencies up to half the ADC rate; above it the echo "
                           "folds onto its mirror)")
    half = power.copy()
    half[0] = 0.0
    half[n_s // 2:] = 0.0
    return half, 2.0


def _check_front_end(setup: Setup, model: ProbeModel, y: np.ndarray, cap: Capture) -> None:
    """The probe's spectrum across the virtual array (its direction) matches the named front
    end's nominal response better than, or as well as (within 0.02 of |cos|), every other
    front end's: a sidecar naming another front end fits with a low residual, since the
    tangential offset moves the response to the other front end."""
    cos = np.empty(setup.fe.count)
    for q in range(setup.fe.count):
        m = dataclasses.replace(model, active=q)
        h = m.response(m.nominal()[None])[0]
        cos[q] = abs(np.vdot(h, y)) / (np.linalg.norm(h) * np.linalg.norm(y))
    best = int(np.argmax(cos))
    if best != cap.active and cos[best] - cos[cap.active] > 0.02:
        raise CaptureError(f"{cap.source}: active_front_end = {cap.active}: must be the front "
                           f"end the capture shows: its probe's direction matches front end "
                           f"{best} (|cos| {cos[best]:.3f}), not {cap.active} "
                           f"(|cos| {cos[cap.active]:.3f})")


#: the largest distance (bins) between the probe's echo as measured in the capture's own
#: range-Doppler map and where the sidecar's probe_range_m / probe_velocity_mps put it on the
#: nominal setup (3-bin interpolation of both; a clean capture reads within 0.001 bin).
#: Range: a radial mounting offset of 5 mm moves the echo 0.03 bin, a channel delay offset of
#: 100 ps 0.1 bin (diewald2022); a sidecar range wrong by 0.11 m (0.5 bin) fitted a channel
#: phase 90 deg off at residual 1.02. Doppler: nothing of the setup moves a probe's Doppler; a
#: sidecar velocity wrong by 0.2 m/s (0.9 bin) read a tangential offset of +2.3 mm for +0.3
SUBBIN_LIMIT = {"range": 0.25, "doppler": 0.05}


def _interpolated(p_lo: np.ndarray, p_0: np.ndarray, p_hi: np.ndarray) -> np.ndarray:
    """The peak's fractional offset from the centre bin of three powers (Gaussian
    interpolation: exact for a Gaussian main lobe, the same estimator for measurement and
    model, so their difference is the echo's shift)."""
    a, b, c_ = (np.log(np.maximum(x, 1e-300)) for x in (p_lo, p_0, p_hi))
    den = a - 2 * b + c_
    return np.where(den < 0, 0.5 * (a - c_) / np.where(den < 0, den, -1.0), 0.0)


def probe_offset_bins(power: np.ndarray, model: ProbeModel, span: int = 3
                      ) -> tuple[float, float]:
    """(range, Doppler) offset in bins of the probe's echo in the capture's power map
    ``power`` (R, D) from where the nominal setup puts the sidecar's probe (``model``): each
    interpolated over the three bins around its own strongest cell, the measurement's within
    one bin of the sidecar's probe, the model's within ``span`` range bins and 2 Doppler bins
    of it (the model's echo sits away from the sidecar's range when the recorded RTS delay
    and the scene's air path disagree)."""
    n_r, n_d = power.shape
    rb, db = model.range_bin, model.doppler_bin
    radar, rut = model.setup.scene.radar, model.setup.rut
    near_r, near_d = (rb + np.arange(-1, 2)) % n_r, (db + np.arange(-1, 2)) % n_d
    block = power[np.ix_(near_r, near_d)]
    i, j = np.unravel_index(int(np.argmax(block)), block.shape)
    mr, md = int(near_r[i]), int(near_d[j])
    # the model on a (2 span + 1) x 5 grid of (range, Doppler) bins around the sidecar's
    ro, do = np.arange(-span, span + 1), np.arange(-2, 3)
    gr, gd = np.meshgrid((rb + ro) % n_r, (db + do) % n_d, indexing="ij")
    resp = bin_response(model.echoes(model.nominal()[None]), radar, rut, gr.ravel(),
                        gd.ravel()).sum(axis=1)
    p_model = np.sum(np.abs(resp) ** 2, axis=-1).reshape(gr.shape)
    a, b = np.unravel_index(int(np.argmax(p_model)), p_model.shape)
    a, b = int(np.clip(a, 1, len(ro) - 2)), int(np.clip(b, 1, len(do) - 2))

    def three(centre, n):
        return (centre + np.arange(-1, 2)) % n
    p_meas = np.r_[power[three(mr, n_r), md], power[mr, three(md, n_d)]]
    p_mod = np.r_[p_model[a - 1:a + 2, b], p_model[a, b - 1:b + 2]]
    got = _interpolated(p_meas[[0, 3]], p_meas[[1, 4]], p_meas[[2, 5]])
    want = _interpolated(p_mod[[0, 3]], p_mod[[1, 4]], p_mod[[2, 5]])
    dd = (md - db + n_d // 2) % n_d - n_d // 2  # circular
    return (float(mr - rb + got[0] - (ro[a] + want[0])),
            float(dd + got[1] - (do[b] + want[1])))


def _check_subbin(power: np.ndarray, model: ProbeModel, radar, cap: Capture) -> None:
    """The sidecar's probe range and velocity against the echo in the capture within
    :data:`SUBBIN_LIMIT` of a bin (:func:`probe_offset_bins`): a probe range wrong by less than a
    bin passes the strongest-cell check but fits a wrong channel phase and gain (the range
    shift of the model's bin response), a wrong velocity a wrong Doppler phase ramp across
    the TDM slots (a tangential offset).

    First, where the sidecar records the RTS delay it programmed (``rts_delay_s``), the echo
    against that delay plus the scene's two-way air path of the front end: the echo's range
    measures the path, so captures of another arc are refused here, whose curvature and
    spreading loss the radar's antenna phases and the channel gains absorb in the joint fit
    (a 1.2 m arc on the 1 m scene read 1.33 bins away and was accepted at residual 0.86
    without this check). Its limit, 0.25 bin, is a radius error of 3.8 cm at the bundled
    scene's 0.151 m bins."""
    r_bin = c * radar.adc_rate_hz / (2 * radar.slope_hz_per_s * radar.samples_per_chirp)
    v_bin = c / (2 * radar.f_c_hz * radar.tdm_cycle_s * radar.chirps_per_tx)
    if model.rts_delay_s is not None:  # the echo against the recorded delay + the scene's air
        dr, _ = probe_offset_bins(power, model)
        if not abs(dr) <= SUBBIN_LIMIT["range"]:
            raise CaptureError(_air_path_message(model, cap, dr, r_bin))
    # the sidecar's probe range (and velocity) against the echo, the scene's delay for it
    dr, dd = probe_offset_bins(power, dataclasses.replace(model, rts_delay_s=None))
    for name, have, off, step, unit, axis, also in (
            ("probe_range_m", cap.range_m, dr, r_bin, "m", "range",
             "or a radial or channel delay offset larger than that moves the echo"),
            ("probe_velocity_mps", cap.velocity_mps, dd, v_bin, "m/s", "doppler", "")):
        limit = SUBBIN_LIMIT[axis]
        if not abs(off) <= limit:
            raise CaptureError(
                f"{cap.source}: {name} = {have:g}: must be where the capture's echo is, "
                f"{have + off * step:.5g} {unit} ({off:+.2f} bins of {step:.4g} {unit} away, "
                f"at most {limit:g} bin on the nominal setup): the sidecar does not describe "
                f"this capture{', ' + also if also else ''}")


def _air_path_message(model: ProbeModel, cap: Capture, dr: float, r_bin: float) -> str:
    """The range check's line when the sidecar records the RTS's programmed delay: the echo's
    range then measures the two-way air path, which is the scene's arc that disagrees."""
    scene = model.setup.scene
    rts = scene.rts
    air = float(model.echoes(model.nominal()[None]).tau_air_s.mean()) * c  # two-way, m
    tau0 = realised_delay(model.programmed_delay(), rts.f_s_hz, rts.fractional_delay,
                          rts.fractional_delay_step_s)
    want = c / 2 * (float(tau0) + air / c)
    own = float(requested_delay(scene, model.range_m)) * 1e9
    return (f"{cap.source}: the capture's echo is at {want + dr * r_bin:.4g} m, where the scene "
            f"puts it {want:.4g} m ({dr:+.2f} bins of {r_bin:.3g} m, at most "
            f"{SUBBIN_LIMIT['range']:g}): front end {cap.active}'s two-way air path on the "
            f"scene's arc (rts.arc_radius_m = {rts.arc_radius_m:g} m, {air:.4g} m) misses the "
            f"capture's by about {2 * dr * r_bin:+.2g} m, with the RTS delay its sidecar "
            f"records (rts_delay_s = {model.programmed_delay() * 1e9:.4f} ns; the scene "
            f"programs {own:.4f} ns for probe_range_m = {model.range_m:g}): the capture was "
            "made on another arc or front-end position; identify it against the bench's "
            "scene")


def _check_peak(power: np.ndarray, model: ProbeModel, radar, cap: Capture) -> None:
    """The strongest cell of the range-Doppler map lies within one bin of the sidecar's probe
    (range and Doppler, the latter circular)."""
    n_s, n_l = power.shape
    ri, di = np.unravel_index(int(np.argmax(power)), power.shape)
    dd = abs(int(di) - model.doppler_bin)
    if abs(int(ri) - model.range_bin) <= 1 and min(dd, n_l - dd) <= 1:
        return
    r_bin = c * radar.adc_rate_hz / (2 * radar.slope_hz_per_s * n_s)
    v_bin = c / (2 * radar.f_c_hz * radar.tdm_cycle_s * n_l)
    raise CaptureError(
        f"{cap.source}: probe_range_m = {cap.range_m:g}, probe_velocity_mps = "
        f"{cap.velocity_mps:g}: must be where the capture's strongest echo is, "
        f"{ri * r_bin:.4g} m and {(int(di) - n_l // 2) * v_bin:+.4g} m/s (range bin {ri}, "
        f"Doppler bin {di}; the sidecar's probe is at bins {model.range_bin}, "
        f"{model.doppler_bin}): the sidecar does not describe this capture")
