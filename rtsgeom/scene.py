"""Scene files: TOML -> validated, frozen :class:`Scene`.

All defaults and units live here. Inside the package everything is SI (metres, seconds, hertz,
radians); degrees, millimetres and dBsm appear only as field names in the file (``angle_deg``,
``radial_offset_mm``, ``rcs_dbsm``) and are converted on load.

Coordinate frame (world): ``x`` lateral, ``y`` forward (the RuT's boresight at yaw 0), ``z`` up.
Azimuth angles are measured from ``+y`` towards ``+x``: the unit vector of azimuth ``theta`` is
``(sin theta, cos theta, 0)``.

Every error names the file, the field (dotted path), the value and what is allowed; unknown keys
are rejected so a typo never silently falls back to a default.
"""

from __future__ import annotations

import hashlib
import math
import reprlib
import stat
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from scipy.constants import c

__all__ = [
    "SceneError",
    "RadarConfig",
    "CfarConfig",
    "FrontEndConfig",
    "RtsConfig",
    "SheetConfig",
    "TargetConfig",
    "RaytraceConfig",
    "Scene",
    "load_scene",
    "loads_scene",
    "parse_scene",
]

_REQUIRED = object()

ANTENNA_PRESETS = ("awr1843boost",)
WINDOWS = ("none", "hann", "hamming", "blackman")
CFAR_KINDS = ("ca", "os")
AOA_MODES = ("exact", "array-factor", "paper", "nearest")

# Resource limits: a scene file is a few kB; these stop a hostile or mistyped file from asking
# for gigabytes of memory or hours of work before anything is computed.
MAX_SCENE_BYTES = 4 << 20  # size of a scene file
MAX_NAME_CHARS = 200  # ``name`` (printed, may end up in file names)
MAX_STRING_CHARS = 10_000  # any other string (description, mesh paths)
MAX_FRONT_ENDS = 256
MAX_TARGETS = 1024
MAX_CALIBRATION_STEPS = 100_000  # calibration_span / calibration_step
MAX_ADC_SAMPLES = 1 << 27  # samples_per_chirp * chirps_per_tx * virtual elements (2 GiB complex)


class SceneError(ValueError):
    """A scene file (or a value derived from one) is invalid. The message names the field."""


# --------------------------------------------------------------------------------------------
# Typed, immutable configuration objects
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class CfarConfig:
    """Cell-averaging (``ca``) or ordered-statistic (``os``) CFAR on the range-Doppler map."""

    kind: str = "ca"
    guard_cells: tuple[int, int] = (2, 2)  # (range, Doppler), each side
    training_cells: tuple[int, int] = (8, 4)  # (range, Doppler), each side
    threshold_db: float = 15.0  # detection threshold above the noise estimate
    os_rank: float = 0.75  # OS-CFAR: the quantile of the training cells


@dataclass(frozen=True)
class RadarConfig:
    """The radar under test (RuT): an FMCW TDM-MIMO radar (paper section "Signal Model").

    ``f_c_hz`` is the lower band edge (paper: f_c), ``bandwidth_hz`` the swept bandwidth B over a
    ramp of ``chirp_duration_s`` (paper: T), so the slope is ``S = B / T``. The ADC takes
    ``samples_per_chirp`` complex samples at ``adc_rate_hz`` starting ``adc_start_s`` after the
    ramp start (default: the sampling window centred in the ramp, so the window's centre
    frequency is ``f_c + B/2`` as the paper's eq. (16) assumes).
    """

    f_c_hz: float
    bandwidth_hz: float
    chirp_duration_s: float
    chirp_repetition_s: float
    samples_per_chirp: int
    adc_rate_hz: float
    adc_start_s: float
    chirps_per_tx: int
    antenna_preset: str = "awr1843boost"
    use_elevation_tx: bool = False
    element_spacing_m: float = 0.0  # lambda/2 at the centre frequency unless given
    position_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    yaw_rad: float = 0.0
    range_window: str = "hann"
    doppler_window: str = "hann"
    angle_window: str = "none"
    cfar: CfarConfig = field(default_factory=CfarConfig)
    snr_db: float | None = None  # per-sample SNR of the strongest echo; None = noiseless

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
        return 3 if self.use_elevation_tx else 2

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
class FrontEndConfig:
    """One RTS front end on the arc: an Rx and a Tx antenna on a module tangent to the arc.

    The Rx antenna sits ``rx_tx_separation_m/2`` along the tangent towards larger azimuth, the
    Tx antenna the same distance towards smaller azimuth. Mounting errors move the whole module.
    """

    angle_rad: float
    rx_tx_separation_m: float = 0.02
    radial_offset_m: float = 0.0
    tangential_offset_m: float = 0.0
    height_offset_m: float = 0.0
    gain_offset_db: float = 0.0  # hardware gain error of this RTS channel (unknown to the RTS)
    phase_offset_rad: float = 0.0  # hardware phase error of this RTS channel
    cable_length_m: float = 1.0
    cable_velocity_factor: float = 0.7
    cable_loss_db: float = 0.5  # one way, whole cable
    return_loss_fe_db: float | None = None  # None: no cable ghosts
    return_loss_be_db: float | None = None


@dataclass(frozen=True)
class RtsConfig:
    """The radar target simulator: arc of front ends and a digital back end (paper "Measurement").

    ``f_rts_hz`` is the IF at which the RTS delay acts on the phase (eq. 7); ``f_s_hz`` the
    back-end sample rate (delay buffer step ``1/f_s``); with ``fractional_delay`` a fractional-
    delay FIR refines the delay to ``fractional_delay_step_s``.
    """

    arc_radius_m: float
    arc_center_m: tuple[float, float, float] | None
    front_ends: tuple[FrontEndConfig, ...]
    f_rts_hz: float
    f_s_hz: float
    fractional_delay: bool = True
    fractional_delay_step_s: float = 1e-12
    fractional_delay_taps: int = 33
    compensate_air_path: bool = True
    aoa_mode: str = "exact"
    calibration_span_s: tuple[float, float] = (-0.5e-9, 1.0e-9)
    calibration_step_s: float = 25e-12
    # the fractional-delay filter's model: "windowed-sinc" (its real frequency response over
    # the IF sweep, rts.fir_if_gain) or "ideal" (a pure delay)
    fractional_delay_filter: str = "windowed-sinc"

    @property
    def delay_resolution_s(self) -> float:
        return self.fractional_delay_step_s if self.fractional_delay else 1.0 / self.f_s_hz


@dataclass(frozen=True)
class SheetConfig:
    """Curved metal sheet, coaxial with the arc, with a round cutout at each front end."""

    enabled: bool = True
    radius_offset_m: float = 0.0  # inner face radius = arc radius + offset
    thickness_m: float = 0.002
    height_m: float = 0.3
    angle_min_rad: float = math.radians(-15.0)
    angle_max_rad: float = math.radians(30.0)
    cutout_diameter_m: float = 0.05
    material: str = "itu_metal"


@dataclass(frozen=True)
class RaytraceConfig:
    """Sionna RT settings for ``--paths raytrace`` (see ``paths/raytrace.py``)."""

    max_depth: int = 2  # reflections per path
    samples_per_src: int = 10_000  # rays shot per source (memory grows with elements x this)
    los: bool = True
    specular_reflection: bool = True
    diffuse_reflection: bool = False
    refraction: bool = False
    min_gain_db: float = -200.0  # drop paths weaker than this (amplitude, dB)


@dataclass(frozen=True)
class TargetConfig:
    """A virtual target as the RuT should see it: range, radial velocity, RCS and azimuth.

    Positive ``velocity_mps`` is a receding target (range increasing).
    """

    range_m: float
    velocity_mps: float = 0.0
    rcs_dbsm: float = 10.0
    angle_rad: float = 0.0

    @property
    def rcs_m2(self) -> float:
        return 10.0 ** (self.rcs_dbsm / 10.0)


@dataclass(frozen=True)
class Scene:
    name: str
    radar: RadarConfig
    rts: RtsConfig
    sheet: SheetConfig
    targets: tuple[TargetConfig, ...]
    raytrace: RaytraceConfig = field(default_factory=RaytraceConfig)
    seed: int = 0
    source: str | None = None
    sha256: str = ""
    description: str = ""
    extra_meshes: tuple[tuple[str, str], ...] = ()  # (absolute path, material)


# --------------------------------------------------------------------------------------------
# Field reader: type and range checks with the field's dotted path in every message
# --------------------------------------------------------------------------------------------


_REPR = reprlib.Repr()
_REPR.maxstring, _REPR.maxother, _REPR.maxlong = 60, 60, 40
_REPR.maxlist, _REPR.maxdict, _REPR.maxlevel = 12, 8, 3


def _fmt(v: Any) -> str:
    """The value as written in an error message: short even for huge or deeply nested input."""
    return _REPR.repr(v) if not isinstance(v, float) else f"{v:g}"


def _as_float(v: int | float) -> float | None:
    """``float(v)``, or None for an integer too large for a float (TOML integers are unbounded)."""
    try:
        return float(v)
    except OverflowError:
        return None


class _Table:
    def __init__(self, data: Any, where: str, source: str):
        self.where = where
        self.source = source
        if not isinstance(data, dict):
            self.fail(where or "<top level>", data, "a table")
        self.data = dict(data)
        self.used: set[str] = set()

    def path(self, key: str) -> str:
        return f"{self.where}.{key}" if self.where else key

    def fail(self, fieldname: str, value: Any, allowed: str) -> None:
        raise SceneError(f"{self.source}: {fieldname} = {_fmt(value)}: must be {allowed}")

    def _get(self, key: str, default: Any) -> Any:
        self.used.add(key)
        if key in self.data:
            return self.data[key]
        if default is _REQUIRED:
            raise SceneError(f"{self.source}: {self.path(key)} is missing (required)")
        return default

    def num(self, key, default=_REQUIRED, lo=None, hi=None, lo_open=False, hi_open=False,
            unit="") -> float:
        v = self._get(key, default)
        if v is default and default is not _REQUIRED:
            return v
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            self.fail(self.path(key), v, f"a number{' in ' + unit if unit else ''}")
        rng = _range_text(lo, hi, lo_open, hi_open, unit)
        f = _as_float(v)
        if f is None or not math.isfinite(f):
            self.fail(self.path(key), v, f"a finite number {rng}".rstrip())
        v = f
        if lo is not None and (v < lo or (lo_open and v == lo)):
            self.fail(self.path(key), v, rng)
        if hi is not None and (v > hi or (hi_open and v == hi)):
            self.fail(self.path(key), v, rng)
        return v

    def opt_num(self, key, **kw) -> float | None:
        if key not in self.data:
            self.used.add(key)
            return None
        return self.num(key, **kw)

    def integer(self, key, default=_REQUIRED, lo=None, hi=None) -> int:
        v = self._get(key, default)
        if v is default and default is not _REQUIRED:
            return v
        if isinstance(v, bool) or not isinstance(v, int):
            self.fail(self.path(key), v, f"an integer {_range_text(lo, hi, False, False, '')}".rstrip())
        if (lo is not None and v < lo) or (hi is not None and v > hi):
            self.fail(self.path(key), v, _range_text(lo, hi, False, False, ""))
        return int(v)

    def boolean(self, key, default=_REQUIRED) -> bool:
        v = self._get(key, default)
        if not isinstance(v, bool):
            self.fail(self.path(key), v, "true or false")
        return v

    def string(self, key, default=_REQUIRED, choices=None, max_chars=MAX_STRING_CHARS,
               printable=False) -> str:
        v = self._get(key, default)
        if not isinstance(v, str):
            self.fail(self.path(key), v, "a string" + (f": one of {', '.join(choices)}" if choices else ""))
        if choices is not None and v not in choices:
            self.fail(self.path(key), v, f"one of {', '.join(choices)}")
        if len(v) > max_chars:
            self.fail(self.path(key), v, f"a string of at most {max_chars} characters "
                                         f"(it has {len(v)})")
        if printable and not v.isprintable():
            self.fail(self.path(key), v, "a string of printable characters (no newlines, tabs "
                                         "or control characters)")
        return v

    def material(self, key) -> str:
        mat = self.string(key, default="itu_metal", max_chars=MAX_NAME_CHARS)
        if not mat.replace("_", "").isalnum():
            self.fail(self.path(key), mat, "a radio material name such as itu_metal")
        return mat

    def vector(self, key, n, default=_REQUIRED, unit="m", lo=-1e3, hi=1e3) -> tuple[float, ...]:
        v = self._get(key, default)
        if v is default and default is not _REQUIRED:
            return v
        if (not isinstance(v, list) or len(v) != n
                or any(isinstance(x, bool) or not isinstance(x, (int, float)) for x in v)):
            self.fail(self.path(key), v, f"a list of {n} numbers in {unit}")
        out = tuple(_as_float(x) for x in v)
        if not all(x is not None and math.isfinite(x) and lo <= x <= hi for x in out):
            self.fail(self.path(key), v, f"{n} finite numbers in [{lo:g}, {hi:g}] {unit}")
        return out

    def table(self, key, required=False) -> "_Table":
        v = self._get(key, _REQUIRED if required else {})
        return _Table(v, self.path(key), self.source)

    def tables(self, key, required=True) -> list["_Table"]:
        v = self._get(key, _REQUIRED if required else [])
        if not isinstance(v, list) or not all(isinstance(t, dict) for t in v):
            self.fail(self.path(key), v, "an array of tables ([[...]])")
        return [_Table(t, f"{self.path(key)}[{i}]", self.source) for i, t in enumerate(v)]

    def done(self) -> None:
        unknown = sorted(set(self.data) - self.used)
        if unknown:
            allowed = ", ".join(sorted(self.used))
            key = unknown[0]
            if len(key) > 60 or not key.isprintable():  # show a hostile key abbreviated, quoted
                key = _fmt(key)
            raise SceneError(f"{self.source}: {self.path(key)} is not a known field "
                             f"(allowed here: {allowed})")


def _range_text(lo, hi, lo_open, hi_open, unit) -> str:
    u = f" {unit}" if unit else ""
    if lo is not None and hi is not None:
        return f"in {'(' if lo_open else '['}{lo:g}, {hi:g}{')' if hi_open else ']'}{u}"
    if lo is not None:
        return f"{'>' if lo_open else '>='} {lo:g}{u}"
    if hi is not None:
        return f"{'<' if hi_open else '<='} {hi:g}{u}"
    return ""


# --------------------------------------------------------------------------------------------
# Parsing
# --------------------------------------------------------------------------------------------


def _parse_radar(t: _Table) -> RadarConfig:
    f_c = t.num("f_c_hz", lo=1e9, hi=300e9, unit="Hz")
    bw = t.num("bandwidth_hz", lo=1e6, hi=10e9, unit="Hz")
    t_ramp = t.num("chirp_duration_s", lo=1e-7, hi=1e-2, unit="s")
    t_rep = t.num("chirp_repetition_s", default=t_ramp, lo=1e-7, hi=1e-1, unit="s")
    if t_rep < t_ramp:
        t.fail(t.path("chirp_repetition_s"), t_rep,
               f">= radar.chirp_duration_s ({t_ramp:g} s): a chirp cannot repeat before it ends")
    n_s = t.integer("samples_per_chirp", lo=16, hi=8192)
    f_adc = t.num("adc_rate_hz", lo=1e5, hi=1e9, unit="Hz")
    window = n_s / f_adc
    if window > t_ramp:
        t.fail(t.path("samples_per_chirp"), n_s,
               f"<= {math.floor(t_ramp * f_adc)}: samples_per_chirp / adc_rate_hz "
               f"= {window:g} s exceeds chirp_duration_s = {t_ramp:g} s")
    adc_start = t.num("adc_start_s", default=0.5 * (t_ramp - window), lo=0.0,
                      hi=t_ramp - window, unit="s")
    n_chirps = t.integer("chirps_per_tx", lo=2, hi=4096)
    preset = t.string("antenna_preset", default="awr1843boost", choices=ANTENNA_PRESETS)
    elev = t.boolean("use_elevation_tx", default=False)
    spacing = t.num("element_spacing_m", default=0.0, lo=0.0, hi=0.1, unit="m")
    pos = t.vector("position_m", 3, default=(0.0, 0.0, 0.0))
    yaw = math.radians(t.num("yaw_deg", default=0.0, lo=-90.0, hi=90.0, unit="deg"))
    rwin = t.string("range_window", default="hann", choices=WINDOWS)
    dwin = t.string("doppler_window", default="hann", choices=WINDOWS)
    awin = t.string("angle_window", default="none", choices=WINDOWS)
    snr = t.opt_num("snr_db", lo=-60.0, hi=200.0, unit="dB")
    ct = t.table("cfar")
    kind = ct.string("kind", default="ca", choices=CFAR_KINDS)
    guard = ct.vector("guard_cells", 2, default=(2.0, 2.0), unit="cells", lo=0, hi=64)
    train = ct.vector("training_cells", 2, default=(8.0, 4.0), unit="cells", lo=1, hi=256)
    thr = ct.num("threshold_db", default=15.0, lo=0.0, hi=100.0, unit="dB")
    rank = ct.num("os_rank", default=0.75, lo=0.0, hi=1.0, lo_open=True)
    for name, vec in (("guard_cells", guard), ("training_cells", train)):
        if any(x != int(x) for x in vec):
            ct.fail(ct.path(name), list(vec), "two whole numbers of cells")
    ct.done()
    cfar = CfarConfig(kind, tuple(int(x) for x in guard), tuple(int(x) for x in train), thr, rank)
    t.done()
    return RadarConfig(
        f_c_hz=f_c, bandwidth_hz=bw, chirp_duration_s=t_ramp, chirp_repetition_s=t_rep,
        samples_per_chirp=n_s, adc_rate_hz=f_adc, adc_start_s=adc_start, chirps_per_tx=n_chirps,
        antenna_preset=preset, use_elevation_tx=elev, element_spacing_m=spacing,
        position_m=pos, yaw_rad=yaw, range_window=rwin, doppler_window=dwin, angle_window=awin,
        cfar=cfar, snr_db=snr,
    )


def _parse_front_end(t: _Table) -> FrontEndConfig:
    ang = math.radians(t.num("angle_deg", lo=-90.0, hi=90.0, unit="deg"))
    sep = t.num("rx_tx_separation_m", default=0.02, lo=0.0, hi=0.5, unit="m")
    mm = {k: t.num(k, default=0.0, lo=-50.0, hi=50.0, unit="mm") * 1e-3
          for k in ("radial_offset_mm", "tangential_offset_mm", "height_offset_mm")}
    gain = t.num("gain_offset_db", default=0.0, lo=-40.0, hi=40.0, unit="dB")
    phase = math.radians(t.num("phase_offset_deg", default=0.0, lo=-360.0, hi=360.0, unit="deg"))
    cable_len = t.num("cable_length_m", default=1.0, lo=0.0, hi=100.0, unit="m")
    vf = t.num("cable_velocity_factor", default=0.7, lo=0.1, hi=1.0, unit="")
    loss = t.num("cable_loss_db", default=0.5, lo=0.0, hi=100.0, unit="dB")
    rl_fe = t.opt_num("return_loss_fe_db", lo=0.0, hi=100.0, lo_open=True, unit="dB")
    rl_be = t.opt_num("return_loss_be_db", lo=0.0, hi=100.0, lo_open=True, unit="dB")
    t.done()
    return FrontEndConfig(ang, sep, mm["radial_offset_mm"], mm["tangential_offset_mm"],
                          mm["height_offset_mm"], gain, phase, cable_len, vf, loss, rl_fe, rl_be)


def _parse_rts(t: _Table) -> RtsConfig:
    radius = t.num("arc_radius_m", lo=0.05, hi=100.0, lo_open=False, unit="m")
    centre = t.vector("arc_center_m", 3, default=None)
    fe_tables = t.tables("front_ends")
    if len(fe_tables) > MAX_FRONT_ENDS:
        t.fail(t.path("front_ends"), f"<{len(fe_tables)} front ends>",
               f"a list of at most {MAX_FRONT_ENDS} front ends")
    fes = tuple(_parse_front_end(ft) for ft in fe_tables)
    if not fes:
        t.fail(t.path("front_ends"), [], "a list of at least one front end")
    f_rts = t.num("f_rts_hz", lo=0.0, hi=100e9, unit="Hz")
    f_s = t.num("f_s_hz", lo=1e6, hi=1e12, unit="Hz")
    frac = t.boolean("fractional_delay", default=True)
    step = t.num("fractional_delay_step_s", default=1e-12, lo=1e-15, hi=1.0 / f_s, unit="s")
    taps = t.integer("fractional_delay_taps", default=33, lo=3, hi=1025)
    fir = t.string("fractional_delay_filter", default="windowed-sinc",
                   choices=("windowed-sinc", "ideal"))
    comp = t.boolean("compensate_air_path", default=True)
    mode = t.string("aoa_mode", default="exact", choices=AOA_MODES)
    span = t.vector("calibration_span_ns", 2, default=(-0.5, 1.0), unit="ns", lo=-1e3, hi=1e3)
    if span[1] <= span[0]:
        t.fail(t.path("calibration_span_ns"), list(span), "[start, stop] with stop > start")
    cal_step = t.num("calibration_step_ps", default=25.0, lo=0.001, hi=1e4, unit="ps")
    t.done()
    angles = [fe.angle_rad for fe in fes]
    if any(b <= a for a, b in zip(angles, angles[1:])):
        t.fail(t.path("front_ends"), [round(math.degrees(a), 6) for a in angles],
               "ordered by strictly increasing angle_deg")
    return RtsConfig(radius, centre, fes, f_rts, f_s, frac, step, taps, comp, mode,
                     (span[0] * 1e-9, span[1] * 1e-9), cal_step * 1e-12,
                     fractional_delay_filter=fir)


def _parse_sheet(t: _Table) -> SheetConfig:
    enabled = t.boolean("enabled", default=True)
    off = t.num("radius_offset_m", default=0.0, lo=-0.5, hi=0.5, unit="m")
    thick = t.num("thickness_m", default=0.002, lo=1e-5, hi=0.1, unit="m")
    height = t.num("height_m", default=0.3, lo=0.01, hi=10.0, unit="m")
    a0 = t.num("angle_min_deg", default=-15.0, lo=-180.0, hi=180.0, unit="deg")
    a1 = t.num("angle_max_deg", default=30.0, lo=-180.0, hi=180.0, unit="deg")
    if a1 <= a0:
        t.fail(t.path("angle_max_deg"), a1, f"> sheet.angle_min_deg ({a0:g} deg)")
    diam = t.num("cutout_diameter_m", default=0.05, lo=0.0, hi=2.0, lo_open=True, unit="m")
    mat = t.material("material")
    t.done()
    return SheetConfig(enabled, off, thick, height, math.radians(a0), math.radians(a1), diam, mat)


def _parse_raytrace(t: _Table) -> RaytraceConfig:
    out = RaytraceConfig(
        max_depth=t.integer("max_depth", default=2, lo=0, hi=10),
        samples_per_src=t.integer("samples_per_src", default=10_000, lo=100, hi=10_000_000),
        los=t.boolean("los", default=True),
        specular_reflection=t.boolean("specular_reflection", default=True),
        diffuse_reflection=t.boolean("diffuse_reflection", default=False),
        refraction=t.boolean("refraction", default=False),
        min_gain_db=t.num("min_gain_db", default=-200.0, lo=-400.0, hi=0.0, unit="dB"),
    )
    t.done()
    return out


def _parse_target(t: _Table) -> TargetConfig:
    rng = t.num("range_m", lo=0.0, hi=1e4, lo_open=True, unit="m")
    vel = t.num("velocity_mps", default=0.0, lo=-500.0, hi=500.0, unit="m/s")
    rcs = t.num("rcs_dbsm", default=10.0, lo=-100.0, hi=100.0, unit="dBsm")
    ang = math.radians(t.num("angle_deg", default=0.0, lo=-90.0, hi=90.0, unit="deg"))
    t.done()
    return TargetConfig(rng, vel, rcs, ang)


def front_end_module_m(centre, radius_m: float, fe: FrontEndConfig) -> tuple[float, float, float]:
    """World position of a front end's module centre (mounting offsets applied).

    The scalar twin of ``geometry.arc.antenna_positions`` for the checks below (this module
    cannot import the geometry package, which imports it).
    """
    s, co = math.sin(fe.angle_rad), math.cos(fe.angle_rad)
    r = radius_m + fe.radial_offset_m
    t = fe.tangential_offset_m
    return (centre[0] + r * s + t * co, centre[1] + r * co - t * s, centre[2] + fe.height_offset_m)


def azimuth_from_radar_rad(radar: RadarConfig, point) -> float:
    """Azimuth of a world point seen from the RuT's phase centre, in the radar frame."""
    p = radar.position_m
    return math.remainder(math.atan2(point[0] - p[0], point[1] - p[1]) - radar.yaw_rad,
                          2.0 * math.pi)


def arc_centre_m(scene: Scene) -> tuple[float, float, float]:
    """The arc centre: ``rts.arc_center_m``, by default the RuT's phase centre."""
    c0 = scene.rts.arc_center_m
    return c0 if c0 is not None else scene.radar.position_m


def _check_consistency(scene: Scene, source: str) -> None:
    """Physical consistency between sections; each error names the field it blames."""
    rts, sheet, radar = scene.rts, scene.sheet, scene.radar

    def fail(fieldname, value, allowed):
        raise SceneError(f"{source}: {fieldname} = {_fmt(value)}: must be {allowed}")

    if sheet.enabled and sheet.cutout_diameter_m >= sheet.height_m:
        fail("sheet.cutout_diameter_m", sheet.cutout_diameter_m,
             f"< sheet.height_m ({sheet.height_m:g} m): the cutouts would cut the sheet in two")

    # Cutouts of neighbouring front ends must not overlap (the sheet would fall apart), and each
    # cutout must hold its front end's two antennas.
    r_sheet = rts.arc_radius_m + sheet.radius_offset_m
    if sheet.enabled:
        if r_sheet <= 0.05:
            fail("sheet.radius_offset_m", sheet.radius_offset_m,
                 f"> {0.05 - rts.arc_radius_m:g} m (the sheet radius must stay positive)")
        for i, fe in enumerate(rts.front_ends):
            if fe.rx_tx_separation_m >= sheet.cutout_diameter_m:
                fail(f"rts.front_ends[{i}].rx_tx_separation_m", fe.rx_tx_separation_m,
                     f"< sheet.cutout_diameter_m ({sheet.cutout_diameter_m:g} m) so both "
                     "antennas look through the cutout")
            half = math.asin(min(1.0, 0.5 * sheet.cutout_diameter_m / r_sheet))
            if fe.angle_rad - half < sheet.angle_min_rad or fe.angle_rad + half > sheet.angle_max_rad:
                fail(f"rts.front_ends[{i}].angle_deg", math.degrees(fe.angle_rad),
                     f"within the sheet [{math.degrees(sheet.angle_min_rad + half):g}, "
                     f"{math.degrees(sheet.angle_max_rad - half):g}] deg (sheet extent minus "
                     "half a cutout)")
        for i in range(1, len(rts.front_ends)):
            a, b = rts.front_ends[i - 1], rts.front_ends[i]
            chord = 2.0 * r_sheet * math.sin(0.5 * (b.angle_rad - a.angle_rad))
            if chord < sheet.cutout_diameter_m:
                min_deg = math.degrees(2.0 * math.asin(min(1.0, 0.5 * sheet.cutout_diameter_m / r_sheet)))
                fail(f"rts.front_ends[{i}].angle_deg", math.degrees(b.angle_rad),
                     f">= {math.degrees(a.angle_rad) + min_deg:.4g} deg: front ends "
                     f"{i - 1} and {i} are closer ({chord * 1e3:.1f} mm) than their cutouts "
                     f"({sheet.cutout_diameter_m * 1e3:.1f} mm) allow")
    # The RuT sits inside the arc (and inside the sheet), and every front end is in front of it.
    centre = arc_centre_m(scene)
    pos = radar.position_m
    dist = math.dist(pos, centre)
    r_in, what = rts.arc_radius_m, "rts.arc_radius_m"
    if sheet.enabled and r_sheet < r_in:
        r_in, what = r_sheet, "the sheet's inner radius rts.arc_radius_m + sheet.radius_offset_m"
    if dist >= r_in:
        fail("radar.position_m", list(pos),
             f"inside the arc: less than {what} = {r_in:g} m from rts.arc_center_m "
             f"{list(centre)} (it is {dist:.4g} m away)")
    modules = [front_end_module_m(centre, rts.arc_radius_m, fe) for fe in rts.front_ends]
    for i, (fe, mod) in enumerate(zip(rts.front_ends, modules)):
        az = math.degrees(azimuth_from_radar_rad(radar, mod))
        if not -90.0 < az < 90.0:
            fail(f"rts.front_ends[{i}].angle_deg", math.degrees(fe.angle_rad),
                 f"an angle that puts the front end in front of the radar: seen from "
                 f"radar.position_m {list(pos)} with radar.yaw_deg = "
                 f"{math.degrees(radar.yaw_rad):g} it is at azimuth {az:.4g} deg, outside "
                 "(-90, 90) deg")
    # The RTS delay must be able to take the calibration's steps, and the calibration sweep must
    # cover one period of the phase it calibrates (paper: 1 / (f_rts + B/2) = 1 ns).
    step = rts.calibration_step_s
    if rts.delay_resolution_s > step * (1.0 + 1e-9):
        how = (f"rts.fractional_delay = true with rts.fractional_delay_step_s = "
               f"{rts.fractional_delay_step_s:g} s: use a finer fractional_delay_step_s"
               if rts.fractional_delay else
               "rts.fractional_delay = false: the delay moves in whole back-end samples "
               "1/rts.f_s_hz; set rts.fractional_delay = true")
        fail("rts.calibration_step_ps", step * 1e12,
             f">= the RTS delay resolution {rts.delay_resolution_s * 1e12:g} ps ({how})")
    span = rts.calibration_span_s[1] - rts.calibration_span_s[0]
    period = 1.0 / (rts.f_rts_hz + 0.5 * radar.bandwidth_hz)
    span_ns = [round(x * 1e9, 9) for x in rts.calibration_span_s]
    if span < period * (1.0 - 1e-9):
        fail("rts.calibration_span_ns", span_ns,
             f"at least one period 1/(rts.f_rts_hz + radar.bandwidth_hz/2) = "
             f"{period * 1e9:.4g} ns wide (it spans {span * 1e9:.4g} ns)")
    if span / step > MAX_CALIBRATION_STEPS:
        fail("rts.calibration_step_ps", step * 1e12,
             f">= {span / MAX_CALIBRATION_STEPS * 1e12:.4g} ps: rts.calibration_span_ns "
             f"{span_ns} would take {span / step:.4g} steps (at most {MAX_CALIBRATION_STEPS})")
    n_adc = radar.samples_per_chirp * radar.chirps_per_tx * radar.num_tx_active * 4
    if n_adc > MAX_ADC_SAMPLES:
        fail("radar.chirps_per_tx", radar.chirps_per_tx,
             f"<= {MAX_ADC_SAMPLES // (radar.samples_per_chirp * radar.num_tx_active * 4)}: "
             f"samples_per_chirp x chirps_per_tx x virtual elements = {n_adc} ADC samples "
             f"(at most {MAX_ADC_SAMPLES})")
    # Targets must be inside the radar's unambiguous range (the beat of the echo includes any air
    # path the RTS does not subtract) and velocity.
    if len(scene.targets) > MAX_TARGETS:
        fail("targets", f"<{len(scene.targets)} targets>", f"at most {MAX_TARGETS} targets")
    d_air = max(math.dist(pos, m) for m in modules)
    extra = max(0.0, d_air - rts.arc_radius_m) if rts.compensate_air_path else d_air
    r_max = radar.max_range_m - extra
    for i, tg in enumerate(scene.targets):
        if tg.range_m >= r_max:
            air = (f" minus the air path {extra:.4g} m the RTS does not subtract "
                   f"(rts.compensate_air_path = {str(rts.compensate_air_path).lower()})"
                   if extra > 0 else "")
            fail(f"targets[{i}].range_m", tg.range_m,
                 f"< {r_max:.4g} m, the radar's unambiguous range {radar.max_range_m:.4g} m "
                 f"(adc_rate_hz * c / (2 * slope)){air}")
        if abs(tg.velocity_mps) >= radar.max_velocity_mps:
            fail(f"targets[{i}].velocity_mps", tg.velocity_mps,
                 f"in (-{radar.max_velocity_mps:.4g}, {radar.max_velocity_mps:.4g}) m/s, the "
                 "radar's unambiguous TDM-MIMO velocity")
        if rts.compensate_air_path and tg.range_m <= rts.arc_radius_m:
            fail(f"targets[{i}].range_m", tg.range_m,
                 f"> rts.arc_radius_m ({rts.arc_radius_m:g} m): the RTS cannot emit before the "
                 "radar signal reached it")


def parse_scene(data: dict, source: str = "<scene>", base_dir: Path | None = None,
                sha256: str = "") -> Scene:
    """Build a validated :class:`Scene` from a parsed TOML document."""
    top = _Table(data, "", source)
    name = top.string("name", default=Path(source).stem if source != "<scene>" else "scene",
                      max_chars=MAX_NAME_CHARS, printable=True)
    if not name.strip():
        top.fail("name", name, "a non-empty string")
    desc = top.string("description", default="")
    seed = top.integer("seed", default=0, lo=0, hi=2**63 - 1)
    radar = _parse_radar(top.table("radar", required=True))
    rts = _parse_rts(top.table("rts", required=True))
    sheet = _parse_sheet(top.table("sheet"))
    targets = tuple(_parse_target(t) for t in top.tables("targets", required=False))
    raytrace = _parse_raytrace(top.table("raytrace"))
    meshes = []
    for mt in top.tables("structure", required=False):
        rel = mt.string("mesh")
        mat = mt.material("material")
        mt.done()
        p = Path(rel)
        if not p.is_absolute():
            p = (base_dir or Path.cwd()) / p
        try:
            exists = p.is_file()
        except (OSError, ValueError):  # e.g. a name too long for the file system
            exists = False
        if not exists:
            mt.fail(mt.path("mesh"), rel, f"an existing mesh file (resolved to {_fmt(str(p))})")
        meshes.append((str(p), mat))
    top.done()
    scene = Scene(name, radar, rts, sheet, targets, raytrace, seed, source, sha256, desc,
                  tuple(meshes))
    _check_consistency(scene, source)
    return scene


def loads_scene(raw: bytes | str, source: str = "<scene>", base_dir: Path | None = None
                ) -> Scene:
    """Parse and validate scene text (TOML). Every failure is a :class:`SceneError`.

    ``base_dir`` is the folder relative mesh paths are resolved against (default: the current
    directory). A UTF-8 byte-order mark is accepted.
    """
    if isinstance(raw, str):
        raw = raw.encode("utf-8", "surrogatepass")
    if len(raw) > MAX_SCENE_BYTES:
        raise SceneError(f"{source}: scene file too large ({len(raw)} bytes; at most "
                         f"{MAX_SCENE_BYTES})")
    try:
        data = tomllib.loads(raw.decode("utf-8-sig"))
    except UnicodeDecodeError as exc:
        raise SceneError(f"{source}: not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    except ValueError as exc:  # TOMLDecodeError, or an integer of more than 4300 digits
        raise SceneError(f"{source}: not valid TOML ({str(exc)[:200]})") from None
    except RecursionError:
        raise SceneError(f"{source}: not valid TOML (arrays or tables nested too deeply)") from None
    return parse_scene(data, source, base_dir, hashlib.sha256(raw).hexdigest())


def load_scene(path: str | Path) -> Scene:
    """Load and validate a scene file (TOML, parsed with the standard library's safe loader)."""
    p = Path(path)
    try:
        st = p.stat()
        if stat.S_ISDIR(st.st_mode):
            raise SceneError(f"{p}: cannot read scene file (it is a directory)")
        if not stat.S_ISREG(st.st_mode):
            raise SceneError(f"{p}: cannot read scene file (not a regular file)")
        with p.open("rb") as fh:
            raw = fh.read(MAX_SCENE_BYTES + 1)
        base = p.resolve().parent
    except SceneError:
        raise
    except OSError as exc:
        raise SceneError(f"{p}: cannot read scene file ({exc.strerror or exc})") from None
    except (ValueError, RuntimeError) as exc:  # embedded NUL byte; symlink loop
        raise SceneError(f"{_fmt(str(p))}: cannot read scene file ({exc})") from None
    return loads_scene(raw, str(p), base)

