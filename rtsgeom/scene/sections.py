"""The scene file's sections as typed, frozen objects: ``[radar]`` (with ``[radar.cfar]``),
``[rts]`` (with ``[[rts.front_ends]]``), ``[sheet]``, ``[raytrace]``, ``[[targets]]`` and
``[[structure]]``.

Every field is declared once, in its dataclass below (:func:`rtsgeom.scene.schema.spec`: file
key, unit, range, default, doc); the one reader in :mod:`.schema` checks and converts it.
Inside the package everything is SI (metres, seconds, hertz, radians); degrees, millimetres,
nanoseconds, picoseconds and dBsm appear only as field names in the file (``angle_deg``,
``radial_offset_mm``, ``rcs_dbsm``) and are converted on load.

Coordinate frame (world): ``x`` lateral, ``y`` forward (the RuT's boresight at yaw 0), ``z`` up.
Azimuth angles are measured from ``+y`` towards ``+x``: the unit vector of azimuth ``theta`` is
``(sin theta, cos theta, 0)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from scipy.constants import c

from .registry import ANGLE_ESTIMATORS, AOA_MODES, CFAR_KINDS, RADAR_PRESETS, WINDOWS
from .hardware import ArrayConfig, PatternConfig
from .channels import RadarChannelsConfig
from .link import RadarLinkConfig, RtsLinkConfig
from .evolve import Evolvable
from .schema import Derived, spec

__all__ = ["RadarChannelsConfig", "RadarConfig", "CfarConfig", "FrontEndConfig", "RtsConfig", "SheetConfig",
           "TargetConfig", "RaytraceConfig", "PatternConfig", "ArrayConfig", "StructureConfig"]

# Resource limits (the file-level ones live in file.py).
MAX_NAME_CHARS = 200  # ``name`` (printed, may end up in file names)
MAX_FRONT_ENDS = 256
MAX_TARGETS = 1024
MAX_SCATTERERS = 256  # scatterers of one object (an entry's ``scatterers``, a mesh's reduction)
HEADING_DOC = ("the object's heading about the vertical in the sense of azimuth (+y towards "
                "+x), from the RuT's boresight")
#: an object's scatterer row in its own frame (x right, y away from the RuT, z up, heading 0)
SCATTERER_COLUMNS = (("x_m", "m", -50.0, 50.0, 1.0), ("y_m", "m", -50.0, 50.0, 1.0),
                     ("z_m", "m", -50.0, 50.0, 1.0), ("rcs_dbsm", "dBsm", -100.0, 100.0, 1.0))
_DEG = math.pi / 180.0  # x * _DEG == math.radians(x), bit for bit


# --------------------------------------------------------------------------------------------
# Typed, immutable configuration objects: each field declared once
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class CfarConfig(Evolvable):
    """Cell-averaging (``ca``) or ordered-statistic (``os``) CFAR on the range-Doppler map."""

    kind: str = spec("kind", "str", "CFAR kind", "ca", choices=tuple(CFAR_KINDS))
    guard_cells: tuple[int, int] = spec(
        "guard_cells", "vec", "guard cells (range, Doppler) on each side of the cell under test",
        (2, 2), n=2, whole=True, unit="cells", lo=0, hi=64)
    training_cells: tuple[int, int] = spec(
        "training_cells", "vec", "training cells (range, Doppler) on each side beyond the guard "
        "cells; guard + training must fit in the map (see the rules)", (8, 4), n=2, whole=True,
        unit="cells", lo=1, hi=256)
    threshold_db: float = spec("threshold_db", "float", "detection threshold above the noise "
                               "estimate", 15.0, unit="dB", lo=0.0, hi=100.0)
    os_rank: float = spec("os_rank", "float", "OS-CFAR: the quantile of the training cells",
                          0.75, lo=0.0, hi=1.0, lo_open=True)


def _centred_adc_start(v: dict) -> float:
    return 0.5 * (v["chirp_duration_s"] - v["samples_per_chirp"] / v["adc_rate_hz"])


@dataclass(frozen=True)
class RadarConfig(Evolvable):
    """The radar under test (RuT): an FMCW TDM-MIMO radar (paper section "Signal Model").

    ``f_c_hz`` is the lower band edge (paper: f_c), ``bandwidth_hz`` the swept bandwidth B over a
    ramp of ``chirp_duration_s`` (paper: T), so the slope is ``S = B / T``. The ADC takes
    ``samples_per_chirp`` complex samples at ``adc_rate_hz`` starting ``adc_start_s`` after the
    ramp start (default: the sampling window centred in the ramp, so the window's centre
    frequency is ``f_c + B/2`` as the paper's eq. (16) assumes).
    """

    f_c_hz: float = spec("f_c_hz", "float", "lower band edge f_c", unit="Hz", lo=1e9, hi=300e9)
    bandwidth_hz: float = spec("bandwidth_hz", "float", "swept bandwidth B", unit="Hz",
                               lo=1e6, hi=10e9)
    chirp_duration_s: float = spec("chirp_duration_s", "float", "ramp duration T", unit="s",
                                   lo=1e-7, hi=1e-2)
    chirp_repetition_s: float = spec(
        "chirp_repetition_s", "float", "time between chirp starts (>= chirp_duration_s)",
        Derived("chirp_duration_s", lambda v: v["chirp_duration_s"]), unit="s", lo=1e-7, hi=1e-1)
    samples_per_chirp: int = spec(
        "samples_per_chirp", "int", "complex ADC samples per chirp (fit in the ramp; hold the "
        "CFAR window)", unit="", lo=16, hi=8192)
    adc_rate_hz: float = spec("adc_rate_hz", "float", "complex ADC sample rate", unit="Hz",
                              lo=1e5, hi=1e9)
    adc_start_s: float = spec(
        "adc_start_s", "float", "ADC window start after the ramp start (window inside the ramp)",
        Derived("sampling window centred in the ramp", _centred_adc_start), unit="s",
        lo=0.0, hi=1e-2)
    chirps_per_tx: int = spec("chirps_per_tx", "int", "chirp loops N_chirp (one chirp per "
                              "active Tx each; hold the CFAR window)", lo=2, hi=4096)
    antenna_preset: str = spec("antenna_preset", "str", "RuT antenna board",
                               "awr1843boost", choices=tuple(RADAR_PRESETS))
    use_elevation_tx: bool = spec("use_elevation_tx", "bool", "also transmit on the elevated "
                                  "Tx (3 TDM slots instead of 2)", False)
    elevation_processing: bool = spec(
        "elevation_processing", "bool", "the RuT beamforms in azimuth and elevation (2-D, all "
        "virtual elements) when its virtual array has elevation extent; false: the azimuth row "
        "only (eq. 14). Front ends or targets off the horizontal plane need it", False)
    board_gap_m: float | None = spec(
        "board_gap_mm", "float", "lateral gap from the right-most Tx to the first Rx of a preset "
        "with separate Tx and Rx groups; unset = the preset's default, 3 lambda (6 d) for the "
        "single-chip boards (an assumption, it moves the near-field parallax); not for "
        "awr2243-cascade (interleaved) nor a custom array", None, unit="mm", lo=0.0, hi=500.0,
        scale=1e-3)
    array: ArrayConfig | None = spec("array", "table", "[radar.array] a custom array "
                                     "(replaces antenna_preset)", None, cls=ArrayConfig)
    pattern: PatternConfig = spec("pattern", "table", "[radar.pattern] pattern of every RuT "
                                  "element (Tx and Rx)", {}, cls=PatternConfig)
    position_offset_m: tuple[float, float, float] = spec(
        "position_offset_mm", "vec", "pose error of the RuT (world x, y, z): the arc stays "
        "centred on position_m", (0.0, 0.0, 0.0), n=3, unit="mm", lo=-100.0, hi=100.0,
        scale=1e-3)
    yaw_offset_rad: float = spec("yaw_offset_deg", "float", "yaw error of the RuT (it measures "
                                 "in its own, turned frame)", 0.0, unit="deg", lo=-30.0,
                                 hi=30.0, scale=_DEG)
    element_spacing_m: float = spec("element_spacing_m", "float", "element spacing d; 0 = "
                                    "lambda/2 at the centre frequency", 0.0, unit="m",
                                    lo=0.0, hi=0.1)
    position_m: tuple[float, float, float] = spec(
        "position_m", "vec", "phase centre of the RuT's virtual array (world)", (0.0, 0.0, 0.0),
        n=3, unit="m", lo=-1e3, hi=1e3)
    yaw_rad: float = spec("yaw_deg", "float", "yaw of the RuT's boresight from +y towards +x",
                          0.0, unit="deg", lo=-90.0, hi=90.0, scale=_DEG)
    range_window: str = spec("range_window", "str", "taper of the range FFT", "hann",
                             choices=tuple(WINDOWS))
    doppler_window: str = spec("doppler_window", "str", "taper of the Doppler FFT", "hann",
                               choices=tuple(WINDOWS))
    angle_window: str = spec("angle_window", "str", "taper of the angle beamformer", "none",
                             choices=tuple(WINDOWS))
    angle_estimator: str = spec(
        "angle_estimator", "str", "the RuT's direction estimator per detection (bartlett: eq. "
        "14; capon, music: differ from it only with angle_subarray > 0, see "
        "radar/estimators.py)", "bartlett", choices=tuple(ANGLE_ESTIMATORS))
    angle_subarray: int = spec(
        "angle_subarray", "int", "forward-backward spatial smoothing over subarrays of this "
        "many elements of the azimuth row (capon, music; 1-D uniform arrays); 0 = none (one "
        "snapshot, rank-1 covariance); about 2/3 of the row's elements is the usual choice",
        0, unit="", lo=0, hi=4096)
    angle_peaks_max: int = spec(
        "angle_peaks_max", "int", "directions reported per range-Doppler detection at most: "
        "every local peak of the cell's angle spectrum above angle_peak_threshold, strongest "
        "first (TI's multiObjBeamForming reports two); 1 = the global peak only", 2, unit="",
        lo=1, hi=8)
    angle_peak_threshold: float = spec(
        "angle_peak_threshold", "float", "a further angle peak of a detection is reported when "
        "its amplitude is at least this fraction of the strongest peak's (TI's example "
        "profiles: 0.5)", 0.5, unit="", lo=0.0, hi=1.0, lo_open=True)
    cfar: CfarConfig = spec("cfar", "table", "[radar.cfar] detection settings", {},
                            cls=CfarConfig)
    snr_db: float | None = spec("snr_db", "float", "per-sample SNR of the strongest echo; "
                                "unset = noiseless (or thermal noise with [radar.link]); an "
                                "override of the link's noise when both are given", None,
                                unit="dB", lo=-60.0, hi=200.0)
    link: RadarLinkConfig | None = spec(
        "link", "table", "[radar.link] physical link budget (optional: absent = relative "
        "amplitudes, noise from snr_db)", None, cls=RadarLinkConfig)
    channels: RadarChannelsConfig | None = spec(
        "channels", "table", "[radar.channels] the RuT's own per-antenna gain and phase errors "
        "and its compensation (optional: absent = ideal channels)", None,
        cls=RadarChannelsConfig)

    @property
    def slope_hz_per_s(self) -> float:
        return self.bandwidth_hz / self.chirp_duration_s

    @property
    def f_center_hz(self) -> float:
        """Carrier frequency at the centre of the ADC window."""
        t_mid = self.adc_start_s + 0.5 * (self.samples_per_chirp - 1) / self.adc_rate_hz
        return self.f_c_hz + self.slope_hz_per_s * t_mid

    @property
    def wavelength_m(self) -> float:
        """Wavelength at the centre of the ADC window (used for array spacing and beamforming)."""
        return c / self.f_center_hz

    @property
    def sampled_bandwidth_hz(self) -> float:
        return self.slope_hz_per_s * self.samples_per_chirp / self.adc_rate_hz

    @property
    def range_resolution_m(self) -> float:
        return c / (2.0 * self.sampled_bandwidth_hz)

    @property
    def max_range_m(self) -> float:
        """Unambiguous range of the complex ADC: beat frequencies in [0, f_adc)."""
        return self.adc_rate_hz * c / (2.0 * self.slope_hz_per_s)

    @property
    def num_tx_active(self) -> int:
        """TDM slots: the custom array's ``tx_order``, else the preset's."""
        if self.array is not None:
            return len(self.array.tx_order)
        return len(RADAR_PRESETS[self.antenna_preset].active_tx_order(self.use_elevation_tx))

    @property
    def num_rx(self) -> int:
        if self.array is not None:
            return len(self.array.rx_mm)
        return RADAR_PRESETS[self.antenna_preset].num_rx

    @property
    def tdm_cycle_s(self) -> float:
        return self.num_tx_active * self.chirp_repetition_s

    @property
    def max_velocity_mps(self) -> float:
        """Unambiguous radial velocity (+-) of the TDM-MIMO Doppler processing."""
        return c / (4.0 * self.f_c_hz * self.tdm_cycle_s)

    @property
    def velocity_resolution_mps(self) -> float:
        return c / (2.0 * self.f_c_hz * self.tdm_cycle_s * self.chirps_per_tx)


@dataclass(frozen=True)
class FrontEndConfig(Evolvable):
    """One RTS front end on the arc: an Rx and a Tx antenna on a module tangent to the arc.

    The antennas sit at signed offsets ``rx_offset_mm``/``tx_offset_mm`` = [t, h] in the
    module's frame (t along the tangent, positive towards larger azimuth; h up); the shorthand
    ``rx_tx_separation_m = s`` means rx [s/2, 0], tx [-s/2, 0] (Rx at the larger azimuth).
    Mounting errors move the whole module and turn it (yaw, pitch) about its centre.
    """

    angle_rad: float = spec("angle_deg", "float", "azimuth theta_q on the arc", unit="deg",
                            lo=-90.0, hi=90.0, scale=_DEG)
    rx_tx_separation_m: float = spec("rx_tx_separation_m", "float", "Rx/Tx antenna separation "
                                     "along the tangent", 0.02, unit="m", lo=0.0, hi=0.5)
    rx_offset_m: tuple[float, float] | None = spec(
        "rx_offset_mm", "vec", "Rx antenna [t, h] on the module (signed; with tx_offset_mm, "
        "instead of rx_tx_separation_m)", None, n=2, unit="mm", lo=-250.0, hi=250.0, scale=1e-3)
    tx_offset_m: tuple[float, float] | None = spec(
        "tx_offset_mm", "vec", "Tx antenna [t, h] on the module (signed; with rx_offset_mm)",
        None, n=2, unit="mm", lo=-250.0, hi=250.0, scale=1e-3)
    yaw_offset_rad: float = spec("yaw_offset_deg", "float", "mounting rotation about the "
                                 "vertical (azimuth sense)", 0.0, unit="deg", lo=-30.0, hi=30.0,
                                 scale=_DEG)
    pitch_offset_rad: float = spec("pitch_offset_deg", "float", "mounting rotation about the "
                                   "tangent (positive: boresight up)", 0.0, unit="deg",
                                   lo=-30.0, hi=30.0, scale=_DEG)
    radial_offset_m: float = spec("radial_offset_mm", "float", "mounting error, radial",
                                  0.0, unit="mm", lo=-50.0, hi=50.0, scale=1e-3)
    tangential_offset_m: float = spec("tangential_offset_mm", "float", "mounting error, "
                                      "tangential", 0.0, unit="mm", lo=-50.0, hi=50.0, scale=1e-3)
    height_offset_m: float = spec("height_offset_mm", "float", "mounting error, height", 0.0,
                                  unit="mm", lo=-50.0, hi=50.0, scale=1e-3)
    gain_offset_db: float = spec("gain_offset_db", "float", "hardware gain error of this RTS "
                                 "channel (unknown to the RTS)", 0.0, unit="dB", lo=-40.0, hi=40.0)
    phase_offset_rad: float = spec("phase_offset_deg", "float", "hardware phase error of this "
                                   "RTS channel", 0.0, unit="deg", lo=-360.0, hi=360.0, scale=_DEG)
    cable_length_m: float = spec("cable_length_m", "float", "coax between front end and back "
                                 "end", 1.0, unit="m", lo=0.0, hi=100.0)
    cable_velocity_factor: float = spec("cable_velocity_factor", "float", "cable velocity "
                                        "factor", 0.7, lo=0.1, hi=1.0)
    cable_loss_db: float = spec("cable_loss_db", "float", "cable loss, one way, whole cable",
                                0.5, unit="dB", lo=0.0, hi=100.0)
    return_loss_fe_db: float | None = spec("return_loss_fe_db", "float", "mismatch at the front "
                                           "end; unset = no cable ghosts", None, unit="dB",
                                           lo=0.0, hi=100.0, lo_open=True)
    return_loss_be_db: float | None = spec("return_loss_be_db", "float", "mismatch at the back "
                                           "end; unset = no cable ghosts", None, unit="dB",
                                           lo=0.0, hi=100.0, lo_open=True)
    # -- front ends on a sphere: elevation on the sphere about the arc centre ------------------
    elevation_rad: float = spec("elevation_deg", "float", "elevation epsilon_q on the sphere "
                                "about the arc centre (0: on the arc; any non-zero one makes "
                                "the sheet a spherical cap)", 0.0, unit="deg", lo=-60.0,
                                hi=60.0, scale=_DEG)

    def antenna_offsets_m(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """Signed (t, h) of the Rx and the Tx antenna on the module (m): the explicit offsets,
        else the shorthand rx (s/2, 0), tx (-s/2, 0)."""
        if self.rx_offset_m is not None and self.tx_offset_m is not None:
            return tuple(self.rx_offset_m), tuple(self.tx_offset_m)
        half = 0.5 * self.rx_tx_separation_m
        return (half, 0.0), (-half, 0.0)


@dataclass(frozen=True)
class RtsConfig(Evolvable):
    """The radar target simulator: arc of front ends and a digital back end (paper "Measurement").

    ``f_rts_hz`` is the IF at which the RTS delay acts on the phase (eq. 7); ``f_s_hz`` the
    back-end sample rate (delay buffer step ``1/f_s``); with ``fractional_delay`` a fractional-
    delay FIR refines the delay to ``fractional_delay_step_s``.
    """

    arc_radius_m: float = spec("arc_radius_m", "float", "arc radius R_c", unit="m", lo=0.05,
                               hi=100.0)
    arc_center_m: tuple[float, float, float] | None = spec(
        "arc_center_m", "vec", "arc centre (world)",
        Derived("the RuT's phase centre radar.position_m", lambda v: None), n=3, unit="m",
        lo=-1e3, hi=1e3)
    front_ends: tuple[FrontEndConfig, ...] = spec(
        "front_ends", "tables", "[[rts.front_ends]], ordered by strictly increasing angle_deg "
        "(by (angle_deg, elevation_deg) where elevations differ)",
        cls=FrontEndConfig, max_items=MAX_FRONT_ENDS, min_items=1, item="front end")
    f_rts_hz: float = spec("f_rts_hz", "float", "IF at which the RTS delay acts (eq. 7)",
                           unit="Hz", lo=0.0, hi=100e9)
    f_s_hz: float = spec("f_s_hz", "float", "back-end sample rate (delay buffer step 1/f_s)",
                         unit="Hz", lo=1e6, hi=1e12)
    fractional_delay: bool = spec("fractional_delay", "bool", "fractional-delay FIR refines "
                                  "the delay", True)
    fractional_delay_step_s: float = spec("fractional_delay_step_s", "float", "delay step of "
                                          "the FIR (<= 1/f_s_hz)", 1e-12, unit="s", lo=1e-15,
                                          hi=1e-6)
    fractional_delay_taps: int = spec("fractional_delay_taps", "int", "FIR taps", 33,
                                      lo=3, hi=1025)
    compensate_air_path: bool = spec("compensate_air_path", "bool", "the RTS subtracts the "
                                     "nominal 2 R_c / c0 (false: the echoes lie R_c further; "
                                     "the AoA synthesis and the studies on it refuse it, "
                                     "run --amplitudes nearest runs)", True)
    aoa_mode: str = spec("aoa_mode", "str", "how target angles are set (see the AoA modes)",
                         "exact", choices=tuple(AOA_MODES))
    calibration_span_s: tuple[float, float] = spec(
        "calibration_span_ns", "vec", "sweep of the delay offset [start, stop] (>= one period)",
        (-0.5, 1.0), n=2, unit="ns", lo=-1e3, hi=1e3, scale=1e-9)
    calibration_step_s: float = spec("calibration_step_ps", "float", "step of the calibration "
                                     "sweep", 25.0, unit="ps", lo=0.001, hi=1e4, scale=1e-12)
    max_targets_per_channel: int | None = spec(
        "max_targets_per_channel", "int", "targets one channel (front end) can synthesize at "
        "once; unset = no limit. Under a budget the planner merges the targets the RuT cannot "
        "resolve (one range-Doppler cell, within its angular resolution) into one, as the "
        "truth twin sees their coherent sum, then drops the weakest (docs/objects.md)", None,
        unit="", lo=1, hi=MAX_TARGETS)
    allow_wide_spacing: bool = spec(
        "allow_wide_spacing", "bool", "force synthesis modes with targets between front ends "
        "wider apart than the RuT's angular resolution (paper eq. 24 violated)", False)
    fractional_delay_filter: str = spec(
        "fractional_delay_filter", "str", "model of the fractional-delay FIR: windowed-sinc (its "
        "real response along the IF sweep, rts.fir_if_gain) or ideal (a pure delay)",
        "windowed-sinc", choices=("windowed-sinc", "ideal"))
    pattern: PatternConfig = spec("pattern", "table", "[rts.pattern] pattern of every "
                                  "front-end antenna (Rx and Tx; boresight at the arc centre)",
                                  {}, cls=PatternConfig)
    link: RtsLinkConfig = spec("link", "table", "[rts.link] each channel's gains, noise figure "
                               "and back-end full scale (used with [radar.link])", {},
                               cls=RtsLinkConfig)

    @property
    def delay_resolution_s(self) -> float:
        return self.fractional_delay_step_s if self.fractional_delay else 1.0 / self.f_s_hz


@dataclass(frozen=True)
class SheetConfig(Evolvable):
    """Curved metal sheet, coaxial with the arc, with a round cutout at each front end."""

    enabled: bool = spec("enabled", "bool", "model the sheet", True)
    radius_offset_m: float = spec("radius_offset_m", "float", "inner face radius = arc radius "
                                  "+ offset", 0.0, unit="m", lo=-0.5, hi=0.5)
    thickness_m: float = spec("thickness_m", "float", "sheet thickness", 0.002, unit="m",
                              lo=1e-5, hi=0.1)
    height_m: float = spec("height_m", "float", "sheet height", 0.3, unit="m", lo=0.01, hi=10.0)
    angle_min_rad: float = spec("angle_min_deg", "float", "sheet extent, start", -15.0,
                                unit="deg", lo=-180.0, hi=180.0, scale=_DEG)
    angle_max_rad: float = spec("angle_max_deg", "float", "sheet extent, end (> angle_min_deg)",
                                30.0, unit="deg", lo=-180.0, hi=180.0, scale=_DEG)
    cutout_diameter_m: float = spec("cutout_diameter_m", "float", "cutout per front end", 0.05,
                                    unit="m", lo=0.0, hi=2.0, lo_open=True)
    material: str = spec("material", "material", "radio material (Sionna RT)", "itu_metal",
                         max_chars=MAX_NAME_CHARS)
    reflection_loss_db: float = spec("reflection_loss_db", "float", "extra loss per reflection "
                                     "off the sheet (an absorber covering it), on every "
                                     "ray-traced path that bounces off it and on the sheet's "
                                     "physical-optics echo", 0.0, unit="dB", lo=0.0, hi=100.0)


@dataclass(frozen=True)
class RaytraceConfig(Evolvable):
    """Sionna RT settings for ``--paths raytrace`` (see ``paths/raytrace.py``)."""

    max_depth: int = spec("max_depth", "int", "reflections per path", 2, lo=0, hi=10)
    samples_per_src: int = spec("samples_per_src", "int", "rays shot per source (memory grows "
                                "with elements x this)", 10_000, lo=100, hi=10_000_000)
    los: bool = spec("los", "bool", "line-of-sight paths", True)
    specular_reflection: bool = spec("specular_reflection", "bool", "specular reflections", True)
    diffuse_reflection: bool = spec("diffuse_reflection", "bool", "diffuse reflections", False)
    refraction: bool = spec("refraction", "bool", "refraction", False)
    min_gain_db: float = spec("min_gain_db", "float", "drop paths weaker than this (amplitude)",
                              -200.0, unit="dB", lo=-400.0, hi=0.0)


@dataclass(frozen=True)
class TargetConfig(Evolvable):
    """A virtual target as the RuT should see it: range, radial velocity, RCS and azimuth.

    Positive ``velocity_mps`` is a receding target (range increasing).
    """

    range_m: float = spec("range_m", "float", "range (within what the processing resolves)",
                          unit="m", lo=0.0, hi=1e4, lo_open=True)
    velocity_mps: float = spec("velocity_mps", "float", "radial velocity, positive receding "
                               "(within what the processing resolves)", 0.0, unit="m/s",
                               lo=-500.0, hi=500.0)
    rcs_dbsm: float = spec("rcs_dbsm", "float", "radar cross-section", 10.0, unit="dBsm",
                           lo=-100.0, hi=100.0)
    angle_rad: float = spec("angle_deg", "float", "azimuth seen from the RuT", 0.0, unit="deg",
                            lo=-90.0, hi=90.0, scale=_DEG)
    # -- targets in elevation: synthesized by a cell of front ends on a sphere -----------------
    elevation_rad: float = spec("elevation_deg", "float", "elevation seen from the RuT (needs "
                                "front ends at elevations and a RuT with elevation)", 0.0,
                                unit="deg", lo=-60.0, hi=60.0, scale=_DEG)
    # -- an extended object: many scatterers placed at the entry's range and azimuth -----------
    scatterers: tuple[tuple[float, float, float, float], ...] | None = spec(
        "scatterers", "rows", "an extended object: [x_m, y_m, z_m, rcs_dbsm] per scatterer in "
        "its own frame (x right, y away from the RuT, z up, at heading 0), placed at this "
        "entry's range and azimuth and turned by heading_deg; the entry's rcs_dbsm is then "
        "unused (docs/objects.md)", None, n=4, columns=SCATTERER_COLUMNS, min_items=1,
        max_items=MAX_SCATTERERS)
    mesh: str | None = spec(
        "mesh", "str", "an extended object from a mesh file (any format trimesh reads, metres, "
        "in the object's frame; relative to the scene's folder): its facets facing the RuT, "
        "each one's physical-optics return, merged to the radar's resolution", None,
        max_chars=1000)
    heading_rad: float = spec("heading_deg", "float", HEADING_DOC, 0.0, unit="deg",
                              lo=-180.0, hi=180.0, scale=_DEG)
    #: the extended object (index into ``Scene.objects``) this point belongs to; -1: none
    object_index: int = -1

    @property
    def rcs_m2(self) -> float:
        return 10.0 ** (self.rcs_dbsm / 10.0)


@dataclass(frozen=True)
class StructureConfig:
    """An extra mesh in the ray-traced scene (``[[structure]]``)."""

    mesh: str = spec("mesh", "str", "mesh file, relative to the scene's folder and inside it")
    material: str = spec("material", "material", "radio material (Sionna RT)", "itu_metal",
                         max_chars=MAX_NAME_CHARS)
    reflection_loss_db: float = spec("reflection_loss_db", "float", "extra loss per reflection "
                                     "off this structure (an absorber covering it), on every "
                                     "ray-traced path that bounces off it", 0.0, unit="dB",
                                     lo=0.0, hi=100.0)


