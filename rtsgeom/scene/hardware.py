"""Scene sections that describe a lab's hardware (issue 14): a custom RuT array
(``[radar.array]``) and antenna patterns (``[radar.pattern]``, ``[rts.pattern]``), declared once
like every scene field (:func:`rtsgeom.scene.schema.spec`), and the two loader checks that need the
file's own keys or its folder: a front end's layout given once (shorthand or signed offsets),
and pattern tables resolved inside the scene's folder. ``rtsgeom.scene.scene`` uses them."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

from .registry import PATTERN_KINDS
from .schema import Evolvable, spec
from ..errors import SceneError
from .schema import fmt as _fmt

__all__ = ["PatternConfig", "ArrayConfig", "check_layout_keys", "resolve_pattern_tables"]


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
        from ..geometry.patterns import TablePattern  # validates the table's contents
        try:
            TablePattern.from_csv(p)
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
