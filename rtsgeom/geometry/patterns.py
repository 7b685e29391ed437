"""Antenna patterns: the complex field gain of an antenna towards a direction in its own frame.

Antenna frame (as the RuT's radar frame): ``y`` boresight, ``z`` up, ``x = y x z`` lateral.
Azimuth ``phi = atan2(x, y)`` (from boresight towards +x), elevation ``el = asin(z / |v|)``.
A pattern returns the *field* (amplitude) gain, complex, 1 at boresight unless a peak gain is
given; a path's amplitude is multiplied by the gains of both antennas of its leg
(``paths.exact``), so the power pattern is ``|g|^2``.

* :class:`Isotropic` -- 1 everywhere (what the project assumed so far).
* :class:`CosinePattern` -- power ``cos^q`` of the angle off boresight, ``q`` from the
  half-power beamwidth (closed form ``q = ln(1/2) / ln cos(HPBW/2)``), zero behind the antenna;
  optionally separable with its own elevation beamwidth.
* :class:`TablePattern` -- a measured or simulated table (azimuth, elevation, gain dB, phase
  deg), interpolated linearly in the complex field with scipy's ``RegularGridInterpolator``
  (complex interpolation keeps phase wraps harmless); zero outside the table.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..scene.hardware import check_pattern_grid, pattern_grid, read_pattern_table

__all__ = ["AntennaPatterns", "CosinePattern", "ISOTROPIC", "Isotropic", "Pattern",
           "TablePattern", "cos_power_exponent", "direction_angles", "pattern_from_config",
           "scene_patterns"]


def direction_angles(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Azimuth and elevation (rad) of direction vectors ``v`` (..., 3) in an antenna frame."""
    v = np.asarray(v, float)
    rho = np.linalg.norm(v, axis=-1)
    el = np.arcsin(np.clip(v[..., 2] / np.where(rho > 0, rho, 1.0), -1.0, 1.0))
    return np.arctan2(v[..., 0], v[..., 1]), el


def cos_power_exponent(hpbw_rad: float) -> float:
    """``q`` of the power pattern ``cos^q(theta)`` whose half-power beamwidth is ``hpbw_rad``:
    ``cos^q(HPBW/2) = 1/2``, so ``q = ln(1/2) / ln(cos(HPBW/2))``."""
    h = float(hpbw_rad)
    if not (0.0 < h < np.pi):
        raise ValueError(f"pattern.hpbw_deg: must lie in (0, 180) deg, got {np.degrees(h):g}")
    return float(np.log(0.5) / np.log(np.cos(0.5 * h)))


class Pattern:
    """Interface: :meth:`field` (complex field gain) of directions in the antenna frame."""

    isotropic = False

    def field(self, direction: np.ndarray) -> np.ndarray:  # pragma: no cover - interface
        raise NotImplementedError

    def gain_db_towards(self, direction: np.ndarray) -> np.ndarray:
        """Power gain (dB) towards ``direction``."""
        return 20.0 * np.log10(np.maximum(np.abs(self.field(direction)), 1e-300))


@dataclass(frozen=True)
class Isotropic(Pattern):
    isotropic = True

    def field(self, direction: np.ndarray) -> np.ndarray:
        return np.ones(np.shape(direction)[:-1], complex)


ISOTROPIC = Isotropic()


@dataclass(frozen=True)
class CosinePattern(Pattern):
    """Power pattern ``cos^q(theta)``, theta off boresight, half-power beamwidth ``hpbw_rad``.

    With ``hpbw_el_rad`` the pattern is separable: ``cos^qa(az) cos^qe(el)`` (az, el in the
    antenna frame), for patches whose azimuth and elevation beams differ. Zero behind the
    antenna (|az| or theta >= 90 deg). ``peak_gain_db`` scales the boresight field gain (0 dB:
    normalised; the directivity of the symmetric pattern is ``2 (q + 1)``, :attr:`directivity`).
    """

    hpbw_rad: float
    hpbw_el_rad: float | None = None
    peak_gain_db: float = 0.0

    def __post_init__(self):
        cos_power_exponent(self.hpbw_rad)  # validates
        if self.hpbw_el_rad is not None:
            cos_power_exponent(self.hpbw_el_rad)

    @property
    def q(self) -> float:
        return cos_power_exponent(self.hpbw_rad)

    @property
    def q_el(self) -> float:
        return self.q if self.hpbw_el_rad is None else cos_power_exponent(self.hpbw_el_rad)

    @property
    def directivity(self) -> float:
        """Peak directivity of the rotationally symmetric cos^q power pattern: 2 (q + 1)."""
        return 2.0 * (self.q + 1.0)

    def field(self, direction: np.ndarray) -> np.ndarray:
        v = np.asarray(direction, float)
        amp = 10.0 ** (self.peak_gain_db / 20.0)
        if self.hpbw_el_rad is None:
            cos_t = v[..., 1] / np.maximum(np.linalg.norm(v, axis=-1), 1e-300)
            p = np.clip(cos_t, 0.0, None) ** (0.5 * self.q)
        else:
            az, el = direction_angles(v)
            p = (np.clip(np.cos(az), 0.0, None) ** (0.5 * self.q)
                 * np.clip(np.cos(el), 0.0, None) ** (0.5 * self.q_el))
        return (amp * p).astype(complex)


@dataclass(frozen=True, eq=False)
class TablePattern(Pattern):
    """A pattern table on a regular (azimuth, elevation) grid, radians, gain in dB and phase in
    radians of shape (N_az, N_el); linear interpolation of the complex field, 0 outside."""

    azimuth_rad: np.ndarray
    elevation_rad: np.ndarray
    gain_db: np.ndarray
    phase_rad: np.ndarray
    # scipy's RegularGridInterpolator (imported where it is built)
    _interp: object = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        az, el, g, ph = check_pattern_grid(self.azimuth_rad, self.elevation_rad, self.gain_db,
                                           self.phase_rad)
        values = 10.0 ** (g / 20.0) * np.exp(1j * ph)
        # imported here: scipy.interpolate costs ~0.5 s of imports that only tables need
        from scipy.interpolate import RegularGridInterpolator
        interp = RegularGridInterpolator((az, el), values, method="linear", bounds_error=False,
                                         fill_value=0.0)
        object.__setattr__(self, "_interp", interp)

    def field(self, direction: np.ndarray) -> np.ndarray:
        az, el = direction_angles(direction)
        pts = np.stack([az, el], -1)
        return self._interp(pts.reshape(-1, 2)).reshape(az.shape)

    @classmethod
    def from_csv(cls, path: str | Path) -> "TablePattern":
        """Read a CSV with columns ``azimuth_deg, elevation_deg, gain_db, phase_deg`` (one row
        per grid point, any order; every (azimuth, elevation) pair of the grid present once):
        :func:`rtsgeom.scene.hardware.read_pattern_table`."""
        return cls(*read_pattern_table(path))

    @classmethod
    def from_samples(cls, azimuth_deg, elevation_deg, gain_db, phase_deg, source="table"
                     ) -> "TablePattern":
        """Build from flat samples (degrees at this I/O edge) of a full regular grid."""
        return cls(*pattern_grid(azimuth_deg, elevation_deg, gain_db, phase_deg, source))


@dataclass(frozen=True)
class AntennaPatterns:
    """The patterns of the four antenna roles of a setup (all isotropic by default).

    ``fe_rx``/``fe_tx`` may be one pattern for every front end or a tuple with one per front end.
    """

    rut_tx: Pattern = ISOTROPIC
    rut_rx: Pattern = ISOTROPIC
    fe_rx: Pattern | tuple[Pattern, ...] = ISOTROPIC
    fe_tx: Pattern | tuple[Pattern, ...] = ISOTROPIC

    @property
    def isotropic(self) -> bool:
        roles = [self.rut_tx, self.rut_rx]
        for p in (self.fe_rx, self.fe_tx):
            roles += list(p) if isinstance(p, tuple) else [p]
        return all(r.isotropic for r in roles)


def pattern_from_config(kind: str, hpbw_deg: float | None = None,
                        hpbw_el_deg: float | None = None, table: str | Path | None = None,
                        peak_gain_db: float = 0.0) -> Pattern:
    """A pattern from scene-style values: ``kind`` ``isotropic`` | ``cos`` (``hpbw_deg``,
    optional ``hpbw_el_deg``, ``peak_gain_db``) | ``table`` (CSV path)."""
    if kind == "isotropic":
        return ISOTROPIC
    if kind == "cos":
        if hpbw_deg is None:
            raise ValueError("pattern.hpbw_deg: required for a 'cos' pattern, in (0, 180) deg")
        return CosinePattern(np.radians(hpbw_deg),
                             None if hpbw_el_deg is None else np.radians(hpbw_el_deg),
                             peak_gain_db)
    if kind == "table":
        if table is None:
            raise ValueError("pattern.table: a CSV path is required for a 'table' pattern")
        return TablePattern.from_csv(table)
    raise ValueError(f"pattern.kind: one of isotropic, cos, table; got '{kind}'")


@functools.lru_cache(maxsize=32)
def _from_scene_config(cfg) -> Pattern:
    return pattern_from_config(cfg.kind, cfg.hpbw_deg, cfg.hpbw_el_deg, cfg.table,
                               cfg.peak_gain_db)


def scene_patterns(scene) -> AntennaPatterns:
    """The patterns a scene declares: ``[radar.pattern]`` for every RuT element (Tx and Rx),
    ``[rts.pattern]`` for every front-end antenna (Rx and Tx). Isotropic where unset (a scene
    without pattern keys gives :attr:`AntennaPatterns.isotropic`, so nothing is multiplied)."""
    radar = getattr(scene.radar, "pattern", None)
    fe = getattr(scene.rts, "pattern", None)
    rut_p = ISOTROPIC if radar is None else _from_scene_config(radar)
    fe_p = ISOTROPIC if fe is None else _from_scene_config(fe)
    return AntennaPatterns(rut_tx=rut_p, rut_rx=rut_p, fe_rx=fe_p, fe_tx=fe_p)
