"""The calibration file: what a lab measures once and reuses for every scenario on the same
setup (``rtsgeom calibrate --out DIR`` writes DIR/calibration.json; ``run`` and ``adc`` read it
with ``--calibration FILE``), and the fingerprint of the setup it was made on.
"""

from __future__ import annotations

import numpy as np

from ..errors import SceneError
from ..scene.schema import Spec, check_record
from .sweep import Calibration
from .probes import FrontEndProbe

__all__ = ["CALIBRATION_FORMAT", "setup_fingerprint", "calibration_mismatch",
           "load_calibration"]

CALIBRATION_FORMAT = "rtsgeom-calibration"
GAIN_RANGE = (0.1, 10.0)  # a gain correction beyond +-20 dB is not a front end's tolerance
#: one pair's entry of a calibration file, declared like the scene's fields (the delay's range
#: is the scene's calibration span, checked below)
PAIR_FIELDS = {
    "pair": Spec("pair", "ints", "the two front ends", lo=0, hi=10_000, min_items=2,
                 max_items=2),
    "delta_tau_s": Spec("delta_tau_s", "float", "the pair's calibration delay", unit="s",
                        lo=-1.0, hi=1.0),
}


def setup_fingerprint(scene) -> str:
    """SHA-256 of what a calibration is a measurement of: the RTS's arc, front ends (their
    mounting and channel fields) and delay hardware, and the RuT (array, pose, chirp,
    processing). Not the scenario (targets, seed, name), not what only changes noise or
    levels (the RuT's ``snr_db``, ``link`` and CFAR, ``rts.link``), not how many targets a
    cell or a channel reports or carries (``angle_peaks_max``, ``angle_peak_threshold``,
    ``rts.max_targets_per_channel``: a calibration measures one target), not the calibration
    procedure's own settings (``rts.calibration_span_ns``/``calibration_step_ps``) or the
    AoA mode, and not the sheet or ray tracing (``calibrate`` measures on exact paths).
    Files the scene names (antenna pattern tables) count by their content, not their path,
    so a moved or copied project keeps its fingerprint and an edited table changes it.
    ``calibrate`` writes it as ``setup_sha256``; ``run``/``adc --calibration`` warn when the
    scene's differs (a calibration made before a front end was moved)."""
    import dataclasses
    import hashlib
    from pathlib import Path

    def canonical(v):
        if isinstance(v, dict):
            return {k: canonical(x) for k, x in v.items()}
        if isinstance(v, (list, tuple)):
            return [canonical(x) for x in v]
        if isinstance(v, str) and Path(v).is_absolute() and Path(v).is_file():
            return "sha256:" + hashlib.sha256(Path(v).read_bytes()).hexdigest()
        if isinstance(v, (int, float)) and not isinstance(v, bool):
            return float(v)  # 1, 1.0 and np.float64(1.0) alike
        return v
    radar = dataclasses.asdict(scene.radar)
    for key in ("snr_db", "link", "cfar", "angle_peaks_max", "angle_peak_threshold"):
        radar.pop(key, None)
    ch = scene.radar.channels
    if ch is None or ch.ideal:  # an ideal radar: the fingerprint it always had
        radar.pop("channels", None)
    rts = dataclasses.asdict(scene.rts)
    for key in ("link", "aoa_mode", "calibration_span_s", "calibration_step_s",
                "max_targets_per_channel"):
        rts.pop(key, None)
    return hashlib.sha256(repr(canonical((radar, rts))).encode()).hexdigest()


def calibration_mismatch(doc: dict, scene) -> str | None:
    """The warning for a calibration file made on another setup (:func:`setup_fingerprint`),
    None where it matches or the file predates the fingerprint."""
    made = doc.get("setup_sha256")
    if made is None or made == setup_fingerprint(scene):
        return None
    return ("--calibration: the file was made on another setup (the arc, a front end's "
            "mounting or channel, the RuT or the RTS's delays differ from this scene's): "
            "applied as it is; run `rtsgeom calibrate` on this scene if the setup changed")


def load_calibration(doc: dict, setup) -> tuple[FrontEndProbe, dict]:
    """The front-end probe and pair calibrations of a calibration file (``rtsgeom calibrate
    --out DIR`` writes DIR/calibration.json): what a lab measures once and reuses for every
    scenario on the same setup. Raises ``SceneError`` naming the field when the file does
    not fit the setup."""
    n = setup.fe.count
    where = "calibration file"
    try:
        ang = np.radians(np.asarray(doc["front_end_angles_deg"], float))
        gain = np.asarray(doc.get("gain_correction", np.ones(n)), float)
        pairs = doc["pairs"] if "pairs" in doc else [doc]
        if not isinstance(pairs, list) or not pairs:
            raise SceneError(f"{where}: pairs = {pairs!r:.60}: must be a list of pair "
                             "calibrations")
        cals = {}
        for k, p in enumerate(pairs):
            check_record(PAIR_FIELDS, p, where, where=f"pairs[{k}]")
            cal = Calibration.from_dict(p)
            cals[cal.pair] = cal
    except SceneError:
        raise
    except (KeyError, TypeError, ValueError, IndexError, AttributeError, OverflowError) as exc:
        raise SceneError(f"{where}: not an rtsgeom calibration ({exc!s}): write one with "
                         "`rtsgeom calibrate SCENE --out DIR`") from None
    if ang.shape != (n,) or gain.shape != (n,):
        raise SceneError(f"{where}: front_end_angles_deg has {ang.size} entries, gain_correction "
                         f"{gain.size}: the scene has {n} front ends (calibrated on another "
                         "setup?)")
    bad = np.flatnonzero(~(np.isfinite(gain) & (gain >= GAIN_RANGE[0]) & (gain <= GAIN_RANGE[1])))
    if bad.size:
        raise SceneError(f"{where}: gain_correction[{bad[0]}] = {gain[bad[0]]:g}: must be in "
                         f"[{GAIN_RANGE[0]:g}, {GAIN_RANGE[1]:g}] (a front end's measured over "
                         "modelled amplitude, +-20 dB)")
    if not np.all(np.isfinite(ang)):
        raise SceneError(f"{where}: front_end_angles_deg: must be finite")
    span = setup.scene.rts.calibration_span_s
    for k, ((i, j), cal) in enumerate(cals.items()):
        if not (0 <= i < n and 0 <= j < n):
            raise SceneError(f"{where}: pair ({i}, {j}): must be front-end indices in "
                             f"[0, {n - 1}]")
        period = cal.period_s if np.isfinite(cal.period_s) else 1.0 / setup.scene.rts.f_rts_hz
        lo, hi = span[0] - period, span[1] + period
        if not (np.isfinite(cal.delta_tau_s) and lo <= cal.delta_tau_s <= hi):
            raise SceneError(f"{where}: pairs[{k}].delta_tau_s = {cal.delta_tau_s:g} s: must be "
                             f"in [{lo * 1e9:.3f}, {hi * 1e9:.3f}] ns (the scene's "
                             "calibration span, rts.calibration_span_ns, and a period either "
                             "side: what a sweep can find)")
    probe = FrontEndProbe(ang, np.full(n, np.nan), gain)
    return probe, cals
