"""The spec a datasheet is checked against (``rtsgeom kpi --spec SPEC.toml``).

Every key is optional; a key left out is not checked. The file is read by the scene's schema
machinery (:func:`rtsgeom.scene.schema.read`): an unknown key, a wrong type or a value out of
range stops with one line naming the file, the key, the value and what is allowed. Each key
declares how the datasheet's value meets it (``at least`` or ``at most`` the limit), and
:func:`check_spec` turns the datasheet's values into one :class:`SpecCheck` per key given: the
value, the limit, the margin (positive: met with that much to spare, in the key's unit) and
pass or fail.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from ...scene.schema import read, spec, specs

__all__ = ["KpiSpec", "SpecCheck", "load_spec", "loads_spec", "check_spec", "SPEC_SENSE"]

#: the largest spec file read (bytes): a handful of numbers
MAX_SPEC_BYTES = 64 * 1024


@dataclass(frozen=True)
class KpiSpec:
    """The test device's requirements (every field optional; None: not checked). Units in the
    keys, file units kept (degrees, metres, dB).

    Attributes
    ----------
    angle_accuracy_deg : float, optional
        |error| + U (k = 2) of the synthesized angle after calibration, worst over
        ``azimuth_deg``.
    azimuth_deg : (float, float), optional
        The azimuth span the setup must reach without a gap.
    min_range_m, max_range_m : float, optional
        The nearest and farthest range it must emulate.
    max_velocity_mps : float, optional
        The largest |radial velocity| it must emulate.
    range_accuracy_m, velocity_accuracy_mps : float, optional
        The largest range and velocity errors the RuT may see on the scene's targets.
    targets : int, optional
        Simultaneous targets it must emulate.
    resolution_deg : float, optional
        The minimum resolvable separation of two targets as the RuT sees them.
    """

    angle_accuracy_deg: float | None = spec(
        "angle_accuracy_deg", "float", "|error| + U (k = 2) of the synthesized angle after "
        "calibration, worst over azimuth_deg (or the whole field of view); where the GUM and "
        "the Monte Carlo differ by more than 10 %, the Monte Carlo's 95 % interval", None,
        unit="deg", lo=0.0, hi=90.0, lo_open=True)
    azimuth_deg: tuple[float, float] | None = spec(
        "azimuth_deg", "vec", "the azimuth span [lo, hi] the setup must reach without a gap "
        "(and hold angle_accuracy_deg over)", None, n=2, unit="deg", lo=-90.0, hi=90.0)
    min_range_m: float | None = spec(
        "min_range_m", "float", "the nearest range it must emulate (met if the setup's "
        "minimum range is at most this)", None, unit="m", lo=0.0, hi=1e4)
    max_range_m: float | None = spec(
        "max_range_m", "float", "the farthest range it must emulate (met if the setup's "
        "maximum range is at least this)", None, unit="m", lo=0.0, hi=1e4, lo_open=True)
    max_velocity_mps: float | None = spec(
        "max_velocity_mps", "float", "the largest |radial velocity| it must emulate", None,
        unit="m/s", lo=0.0, hi=500.0, lo_open=True)
    range_accuracy_m: float | None = spec(
        "range_accuracy_m", "float", "largest |range error| the RuT may see on the scene's "
        "targets", None, unit="m", lo=0.0, hi=100.0, lo_open=True)
    velocity_accuracy_mps: float | None = spec(
        "velocity_accuracy_mps", "float", "largest |velocity error| the RuT may see on the "
        "scene's targets", None, unit="m/s", lo=0.0, hi=100.0, lo_open=True)
    targets: int | None = spec(
        "targets", "int", "simultaneous targets (in total) it must emulate", None, lo=1,
        hi=1_000_000)
    resolution_deg: float | None = spec(
        "resolution_deg", "float", "minimum resolvable separation of two targets as the RuT "
        "sees them on the RTS (met if the setup's is at most this)", None, unit="deg",
        lo=0.0, hi=180.0, lo_open=True)
    ghost_suppression_db: float | None = spec(
        "ghost_suppression_db", "float", "strongest ghost (cable ghosts, the sheet's echo) at "
        "least this far below its target", None, unit="dB", lo=0.0, hi=300.0)


#: per key: ("max": the value must be at most the limit | "min": at least), what the value is
SPEC_SENSE = {
    "angle_accuracy_deg": ("max", "worst |error| + U (k = 2) over the span"),
    "azimuth_deg": ("min", "the span's uncovered part (deg; 0 when covered)"),
    "min_range_m": ("max", "the setup's minimum range"),
    "max_range_m": ("min", "the setup's maximum range"),
    "max_velocity_mps": ("min", "the setup's largest |velocity|"),
    "range_accuracy_m": ("max", "largest |range error| on the scene's targets"),
    "velocity_accuracy_mps": ("max", "largest |velocity error| on the scene's targets"),
    "targets": ("min", "simultaneous targets in total"),
    "resolution_deg": ("max", "minimum resolvable separation on the RTS"),
    "ghost_suppression_db": ("min", "strongest ghost below its target"),
}


@dataclass(frozen=True)
class SpecCheck:
    """One KPI against its limit: ``margin`` is positive where it is met (in the key's unit;
    for ``azimuth_deg`` the uncovered degrees, negated), ``passed`` None where the datasheet
    has no value for it (``note`` says why)."""

    kpi: str
    value: float | None
    limit: object
    margin: float | None
    passed: bool | None
    note: str = ""

    def to_dict(self) -> dict:
        return {"kpi": self.kpi, "value": self.value, "limit": self.limit,
                "margin": self.margin, "pass": self.passed, "note": self.note}


def loads_spec(text: str | bytes, source: str = "<spec>") -> KpiSpec:
    """A spec from TOML text (:class:`KpiSpec`).

    Parameters
    ----------
    text : str or bytes
        The spec's TOML.
    source : str
        Its name in errors.

    Returns
    -------
    KpiSpec

    Raises
    ------
    SceneError
        Bad TOML, an unknown key or a value outside its range, naming the key.
    """
    from ...scene.file import decode_toml
    data, _ = decode_toml(text, source)
    return read(KpiSpec, data, source)


def load_spec(path: str | Path) -> KpiSpec:
    """A spec file (:func:`loads_spec`).

    Parameters
    ----------
    path : str or Path
        The spec's TOML file.

    Returns
    -------
    KpiSpec

    Raises
    ------
    SceneError
        A file over the size limit, a value :func:`loads_spec` refuses, or an
        ``azimuth_deg`` whose low end is not below its high end.
    """
    path = Path(path)
    with open(path, "rb") as fh:
        raw = fh.read(MAX_SPEC_BYTES + 1)
    if len(raw) > MAX_SPEC_BYTES:
        from ...errors import SceneError
        raise SceneError(f"{path}: spec file too large (at most {MAX_SPEC_BYTES} bytes)")
    spec_ = loads_spec(raw, str(path))
    if spec_.azimuth_deg is not None and spec_.azimuth_deg[0] >= spec_.azimuth_deg[1]:
        from ...errors import SceneError
        raise SceneError(f"{path}: azimuth_deg = {list(spec_.azimuth_deg)}: must be [lo, hi] "
                         "with lo < hi")
    return spec_


def check_spec(kpi_spec: KpiSpec, values: dict) -> list[SpecCheck]:
    """One :class:`SpecCheck` per key the spec gives, in the declaration's order. ``values``:
    key -> the datasheet's value (None: not available, with ``values['<key>_note']`` saying
    why); ``azimuth_deg``'s value is the uncovered part of the span (deg)."""
    out = []
    for name, s in specs(KpiSpec):
        limit = getattr(kpi_spec, name)
        if limit is None:
            continue
        value = values.get(name)
        note = values.get(name + "_note", "")
        if value is None or (isinstance(value, float) and not math.isfinite(value)):
            out.append(SpecCheck(name, None, _limit(limit), None, None,
                                 note or "not available for this scene"))
            continue
        if name == "azimuth_deg":  # the uncovered part must be 0
            margin = 0.0 - float(value) if value > 0 else 0.0
            out.append(SpecCheck(name, float(value), list(limit), margin, value <= 1e-9, note))
            continue
        sense = SPEC_SENSE[name][0]
        margin = float(limit) - float(value) if sense == "max" else float(value) - float(limit)
        out.append(SpecCheck(name, float(value), _limit(limit), margin, margin >= 0, note))
    return out


def _limit(limit):
    return list(limit) if isinstance(limit, tuple) else limit
