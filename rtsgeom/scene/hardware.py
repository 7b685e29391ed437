"""Scene sections that describe a lab's hardware: a custom RuT array
(``[radar.array]``) and antenna patterns (``[radar.pattern]``, ``[rts.pattern]``), declared once
like every scene field (:func:`rtsgeom.scene.schema.spec`), and the two loader checks that need the
file's own keys or its folder: a front end's layout given once (shorthand or signed offsets),
and pattern tables resolved inside the scene's folder. ``rtsgeom.scene.scene`` uses them."""

from __future__ import annotations

import csv
import dataclasses
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import SceneError
from .registry import PATTERN_KINDS
from .evolve import Evolvable
from .schema import spec
from .schema import fmt as _fmt

__all__ = ["PatternConfig", "ArrayConfig", "check_layout_keys", "resolve_pattern_tables",
           "PATTERN_GAIN_RANGE_DB", "MAX_PATTERN_BYTES"]

#: a pattern table's gain_db values (dB), and its file's size
PATTERN_GAIN_RANGE_DB = (-300.0, 100.0)
MAX_PATTERN_BYTES = 64 << 20


@dataclass(frozen=True)
class PatternConfig(Evolvable):
    """An antenna pattern (``geometry.patterns``): ``isotropic``, ``cos`` (power cos^q off
    boresight with half-power beamwidth ``hpbw_deg``, optionally its own ``hpbw_el_deg``) or a
    ``table`` (CSV inside the scene's folder: azimuth_deg, elevation_deg, gain_db, phase_deg).
    It multiplies the exact paths' amplitudes, and so the amplitude calibration and synthesis."""

    kind: str = spec("kind", "str", "pattern model", "isotropic",
                     choices=tuple(PATTERN_KINDS))
    hpbw_deg: float | None = spec("hpbw_deg", "float", "half-power beamwidth (kind cos)", None,
                                  unit="deg", lo=0.0, hi=180.0, lo_open=True, hi_open=True)
    hpbw_el_deg: float | None = spec("hpbw_el_deg", "float", "elevation half-power beamwidth "
                                     "(kind cos; unset = hpbw_deg, rotationally symmetric)",
                                     None, unit="deg", lo=0.0, hi=180.0, lo_open=True,
                                     hi_open=True)
    peak_gain_db: float = spec("peak_gain_db", "float", "boresight gain (kind cos)", 0.0,
                               unit="dB", lo=-100.0, hi=100.0)
    table: str | None = spec("table", "str", "CSV file relative to the scene's folder and "
                             "inside it (kind table)", None)


@dataclass(frozen=True)
class ArrayConfig(Evolvable):
    """A custom RuT array in board coordinates (x lateral towards larger azimuth, z up), in
    millimetres; replaces the preset. Virtual element (slot, rx) sits at p_tx + p_rx; sparse and
    non-uniform arrays work, duplicate virtual positions are combined."""

    tx_mm: tuple[tuple[float, float], ...] = spec(
        "tx_mm", "points", "every Tx antenna [x, z]", n=2, unit="mm", lo=-1000.0, hi=1000.0,
        min_items=1, max_items=64)
    rx_mm: tuple[tuple[float, float], ...] = spec(
        "rx_mm", "points", "every Rx antenna [x, z]", n=2, unit="mm", lo=-1000.0, hi=1000.0,
        min_items=1, max_items=64)
    tx_order: tuple[int, ...] = spec(
        "tx_order", "ints", "Tx index (0-based, into tx_mm) transmitting in each TDM slot, each "
        "Tx at most once", lo=0, hi=63, min_items=1, max_items=64)


def check_layout_keys(data: dict, source: str) -> None:
    """A front end's layout is either the shorthand rx_tx_separation_m or both signed offsets."""
    fes = data.get("rts", {}).get("front_ends", []) if isinstance(data.get("rts"), dict) else []
    if not isinstance(fes, list):
        return
    for i, fe in enumerate(fes):
        if not isinstance(fe, dict):
            continue
        given = [k for k in ("rx_offset_mm", "tx_offset_mm") if k in fe]
        if given and "rx_tx_separation_m" in fe:
            raise SceneError(f"{source}: rts.front_ends[{i}].rx_tx_separation_m = "
                             f"{_fmt(fe['rx_tx_separation_m'])}: must be left out when "
                             f"{' and '.join(given)} is given (the separation is the shorthand "
                             "for rx_offset_mm = [s/2, 0], tx_offset_mm = [-s/2, 0])")
        if len(given) == 1:
            other = ({"rx_offset_mm", "tx_offset_mm"} - set(given)).pop()
            raise SceneError(f"{source}: rts.front_ends[{i}].{other} is missing: must be given "
                             f"together with {given[0]} (both antennas' [t, h] in mm)")


def resolve_pattern_tables(scene, source: str, base_dir: Path | None):
    """Pattern CSV paths resolved against the scene's folder and kept inside it (as meshes)."""
    base = base_dir or Path.cwd()

    def resolve(cfg, where):
        if cfg.kind != "table":
            return cfg
        rel = cfg.table
        if rel is None:
            raise SceneError(f"{source}: {where}.table is missing: must be a CSV path when "
                             f"{where}.kind = \"table\"")
        p = Path(rel)
        if p.is_absolute() or ".." in p.parts or "\0" in rel:
            raise SceneError(f"{source}: {where}.table = {_fmt(rel)}: must be a relative path "
                             "inside the scene's folder (no absolute path, no '..')")
        p = base / p
        try:
            ok = p.is_file() and p.resolve().is_relative_to(base.resolve())
        except (OSError, ValueError, RuntimeError):
            ok = False
        if not ok:
            raise SceneError(f"{source}: {where}.table = {_fmt(rel)}: must be an existing CSV "
                             "file inside the scene's folder")
        try:
            read_pattern_table(p)  # its contents checked
        except ValueError as exc:
            raise SceneError(f"{source}: {where}.table = {_fmt(rel)}: {exc}") from None
        return dataclasses.replace(cfg, table=str(p.resolve()))

    for cfg, where in ((scene.radar.pattern, "radar.pattern"), (scene.rts.pattern, "rts.pattern")):
        if cfg.kind == "cos" and cfg.hpbw_deg is None:
            raise SceneError(f"{source}: {where}.hpbw_deg is missing: must be in (0, 180) deg "
                             f"when {where}.kind = \"cos\"")
    radar = dataclasses.replace(scene.radar, pattern=resolve(scene.radar.pattern, "radar.pattern"))
    rts = dataclasses.replace(scene.rts, pattern=resolve(scene.rts.pattern, "rts.pattern"))
    return dataclasses.replace(scene, radar=radar, rts=rts)


def check_pattern_grid(azimuth_rad, elevation_rad, gain_db, phase_rad):
    """A pattern table's grid as float arrays, checked: two strictly increasing axes of at
    least two values within [-180, 180] deg, gain (dB) and phase (rad) finite over the full
    grid (N_az, N_el). ``ValueError`` naming what is wrong."""
    az = np.asarray(azimuth_rad, float)
    el = np.asarray(elevation_rad, float)
    g = np.asarray(gain_db, float)
    ph = np.asarray(phase_rad, float)
    for name, axis in (("azimuth_deg", az), ("elevation_deg", el)):
        if axis.ndim != 1 or axis.size < 2 or np.any(np.diff(axis) <= 0):
            raise ValueError(f"pattern table {name}: at least two strictly increasing values "
                             "needed")
        if np.any(np.abs(axis) > np.pi + 1e-9):
            raise ValueError(f"pattern table {name}: values must lie in [-180, 180] deg")
    if g.shape != (az.size, el.size) or ph.shape != g.shape:
        raise ValueError(f"pattern table: gain_db and phase_deg must cover the full "
                         f"{az.size} x {el.size} azimuth x elevation grid")
    if not (np.all(np.isfinite(g)) and np.all(np.isfinite(ph))):
        raise ValueError("pattern table: gain_db and phase_deg must be finite")
    lo, hi = PATTERN_GAIN_RANGE_DB
    if np.any((g < lo) | (g > hi)):  # 1e5 dB overflowed the amplitudes to inf, then NaN
        k = int(np.argmax((g < lo) | (g > hi)))
        raise ValueError(f"pattern table: gain_db = {g.flat[k]:g}: must be in [{lo:g}, {hi:g}] "
                         "dB (an antenna's gain relative to its peak or in dBi)")
    return az, el, g, ph


def pattern_grid(azimuth_deg, elevation_deg, gain_db, phase_deg, source: str = "table"):
    """The regular grid (azimuth_rad (N_az,), elevation_rad (N_el,), gain_db, phase_rad
    (N_az, N_el)) of flat samples (degrees at this I/O edge), checked
    (:func:`check_pattern_grid`); every (azimuth, elevation) point present once."""
    az_u, ia = np.unique(np.asarray(azimuth_deg, float), return_inverse=True)
    el_u, ie = np.unique(np.asarray(elevation_deg, float), return_inverse=True)
    n = az_u.size * el_u.size
    if len(ia) != n or np.unique(ia * el_u.size + ie).size != n:
        raise ValueError(f"pattern table {source}: the samples must form a full regular "
                         f"azimuth x elevation grid, each point once ({az_u.size} x "
                         f"{el_u.size} = {n} points expected, {len(ia)} given)")
    g = np.empty((az_u.size, el_u.size))
    ph = np.empty_like(g)
    g[ia, ie] = gain_db
    ph[ia, ie] = np.radians(np.asarray(phase_deg, float))
    return check_pattern_grid(np.radians(az_u), np.radians(el_u), g, ph)


def read_pattern_table(path):
    """A pattern CSV with columns ``azimuth_deg, elevation_deg, gain_db, phase_deg`` (one row
    per grid point, any order) as its checked grid (:func:`pattern_grid`)."""
    path = Path(path)
    try:
        if path.stat().st_size > MAX_PATTERN_BYTES:
            raise ValueError(f"pattern table {path}: {path.stat().st_size} bytes: must be at "
                             f"most {MAX_PATTERN_BYTES} bytes")
        with path.open(newline="", encoding="utf-8") as fh:
            rows = list(csv.DictReader(fh))
    except OSError as e:
        raise ValueError(f"pattern table {path}: cannot read ({e.strerror})") from None
    except (csv.Error, UnicodeDecodeError) as e:  # a field over csv's limit, binary bytes
        raise ValueError(f"pattern table {path}: not a CSV table ({str(e)[:100]})") from None
    need = ("azimuth_deg", "elevation_deg", "gain_db", "phase_deg")
    if not rows or any(k not in rows[0] for k in need):
        raise ValueError(f"pattern table {path}: needs the columns {', '.join(need)}")
    try:
        a = np.array([[float(r[k]) for k in need] for r in rows])
    except (TypeError, ValueError):
        raise ValueError(f"pattern table {path}: every value must be a number") from None
    return pattern_grid(*a.T, source=str(path))
