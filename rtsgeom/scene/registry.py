"""Registries of the named choices a scene or the CLI can make: one entry per choice.

Adding an AoA mode, a paths method, a radar preset, a window or a CFAR kind means adding ONE
entry here; the scene schema (``scene.py``), the generated ``docs/scene-format.md`` and the
CLI's ``choices=`` all read these dictionaries. This module imports only numpy so that every
stage, the scene loader included, can import it (one-way imports).
"""

from __future__ import annotations

from dataclasses import dataclass


__all__ = ["AoaMode", "AOA_MODES", "SYNTHESIS_MODES", "PathMethod", "PATH_METHODS",
           "RADAR_PRESETS", "Window", "WINDOWS", "CFAR_KINDS", "PATTERN_KINDS",
           "ANGLE_ESTIMATORS", "MAP_FORMATS"]


@dataclass(frozen=True)
class AoaMode:
    """How the RTS sets a target's angle of arrival."""

    doc: str
    synthesis: bool  # True: interpolates between two front ends (amplitude ratio, eq. 18-23)


AOA_MODES: dict[str, AoaMode] = {
    "exact": AoaMode("amplitude ratio from the exact per-element model of the pair", True),
    "array-factor": AoaMode("amplitude ratio from the array factor of the RuT (closed form)", True),
    "paper": AoaMode("amplitude ratio from the paper's closed form g(theta) (eq. 23)", True),
    "nearest": AoaMode("no synthesis: each target on the nearest front end", False),
}
SYNTHESIS_MODES: tuple[str, ...] = tuple(k for k, m in AOA_MODES.items() if m.synthesis)

@dataclass(frozen=True)
class PathMethod:
    """How the propagation paths are computed: ``compute`` returns the :class:`Paths` table,
    ``draw`` what the 3D view draws (the table plus each reflection's hit points). Both are
    ``"module:function"`` names, imported only when used (Sionna loads only for ray tracing)."""

    doc: str
    compute: str
    draw: str


PATH_METHODS: dict[str, PathMethod] = {
    "exact": PathMethod("exact line-of-sight distances per element",
                        "rtsgeom.paths.exact:exact_paths", "rtsgeom.paths.exact:exact_paths"),
    "raytrace": PathMethod("Sionna RT ray tracing (reflections off the sheet and structures)",
                           "rtsgeom.paths.raytrace:raytrace_paths",
                           "rtsgeom.paths.raytrace:trace"),
}


# The radar boards: one registry, the documented layouts with their sources (a leaf module).
from .presets import PRESETS as RADAR_PRESETS  # noqa: E402


@dataclass(frozen=True)
class Window:
    """A taper (scipy.signal.get_window name) and its main-lobe half width in FFT bins."""

    doc: str
    mainlobe_half_bins: int  # first null of the window's spectrum, in bins of the FFT


WINDOWS: dict[str, Window] = {
    "none": Window("rectangular", 1),
    "hann": Window("Hann", 2),
    "hamming": Window("Hamming", 2),
    "blackman": Window("Blackman", 3),
}

PATTERN_KINDS: dict[str, str] = {
    "isotropic": "field gain 1 in every direction",
    "cos": "power cos^q of the angle off boresight, q from the half-power beamwidth hpbw_deg",
    "table": "a CSV of azimuth_deg, elevation_deg, gain_db, phase_deg (a full regular grid)",
}

#: The RuT's direction estimators (``radar.angle_estimator``; ``radar.estimators``). Capon and
#: MUSIC differ from Bartlett only with spatial smoothing (``radar.angle_subarray``): on one
#: snapshot the covariance is rank 1 and all three peak at the same direction.
ANGLE_ESTIMATORS: dict[str, str] = {
    "bartlett": "the beamformer |sum_v w_v x_v e^{j k p_v . u}|^2 (eq. 14)",
    "capon": "minimum variance (MVDR) 1 / a^H (R + delta I)^-1 a, diagonal loading delta",
    "music": "MUSIC 1 / a^H E_n E_n^H a on the noise subspace of R",
}

CFAR_KINDS: dict[str, str] = {
    "ca": "cell averaging: the mean of the training ring",
    "os": "ordered statistic: the os_rank quantile of the training ring",
}

#: The RuT's own channel compensation (``[radar.channels] compensation``; ``radar.channels``).
COMPENSATIONS: dict[str, str] = {
    "none": "the virtual channels are processed as received",
    "boresight": "each virtual channel divided by what the radar measured on a reflector at "
                 "boresight (the SDK's Rx-channel phase and gain compensation)",
}

#: the maps' array formats ``run --maps`` may write (``pipeline.output.maps_arrays``): npz
#: (numpy), mat (MATLAB), nc (NetCDF); npz by default
MAP_FORMATS: tuple[str, ...] = ("npz", "mat", "nc")
