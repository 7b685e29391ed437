"""Scene fields of the radar under test's own channel errors: ``[radar.channels]``.

Declared once (:func:`rtsgeom.scene.schema.spec`) like every scene field; the physics that uses
them is :mod:`rtsgeom.radar.channels`. A real MIMO radar's transmit and receive chains differ in
gain and phase (chip-to-chip, trace lengths, a power cycle's PLL state); the radar's processing
then forms its beams from a virtual array whose element ``v = (Tx t, Rx r)`` carries the complex
gain ``g_tx[t] g_rx[r]``. Absent (or all zero with no compensation), the radar is ideal and
every output is bit-identical to a scene without the section. The lengths (one value per
antenna of the preset or the custom array) are checked by the scene's rules.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .registry import COMPENSATIONS, RADAR_PRESETS
from .evolve import Evolvable
from .schema import spec

__all__ = ["RadarChannelsConfig", "MAX_GAIN_ERROR_DB", "MAX_CHANNELS", "antenna_counts",
           "channel_rules"]

MAX_GAIN_ERROR_DB = 20.0  # a chain more than 20 dB off is broken, not miscalibrated
MAX_CHANNELS = 64  # antennas per side, as [radar.array]
_DEG = math.pi / 180.0


def _per_antenna(key: str, what: str, unit: str, lo: float, hi: float, scale: float = 1.0):
    side = "Tx" if key.startswith("tx") else "Rx"
    which = "every physical Tx, the elevated ones included" if side == "Tx" else "every Rx"
    return spec(key, "floats", f"{what} of each {side} antenna, in the order of the preset's "
                f"or [radar.array]'s antennas ({which}); empty = 0 for all", (), unit=unit,
                lo=lo, hi=hi, min_items=0, max_items=MAX_CHANNELS, scale=scale)


@dataclass(frozen=True)
class RadarChannelsConfig(Evolvable):
    """The RuT's per-antenna complex gain errors and its own compensation: virtual element
    (Tx t, Rx r) receives ``g_tx[t] g_rx[r]`` times the ideal signal, ``g = 10^(gain_db / 20)
    e^(j phase)``, after the Rx antennas' mutual coupling (``rx_coupling_db``: each Rx also
    receives that fraction of its nearest neighbours' signals); ``compensation = "boresight"``
    divides each virtual channel by what the radar measured on a reflector at boresight (the
    SDK's range-bias and Rx-channel phase compensation), at ``compensation_range_m`` (unset:
    in the far field).

    Attributes
    ----------
    tx_gain_db, tx_phase_rad, rx_gain_db, rx_phase_rad : tuple of float
        Per antenna.
    rx_coupling_db, rx_coupling_phase_rad : optional
    compensation : str
        ``none`` or ``boresight``.
    """

    tx_gain_db: tuple[float, ...] = _per_antenna("tx_gain_db", "gain error", "dB",
                                                 -MAX_GAIN_ERROR_DB, MAX_GAIN_ERROR_DB)
    tx_phase_rad: tuple[float, ...] = _per_antenna("tx_phase_deg", "phase error", "deg",
                                                   -180.0, 180.0, _DEG)
    rx_gain_db: tuple[float, ...] = _per_antenna("rx_gain_db", "gain error", "dB",
                                                 -MAX_GAIN_ERROR_DB, MAX_GAIN_ERROR_DB)
    rx_phase_rad: tuple[float, ...] = _per_antenna("rx_phase_deg", "phase error", "deg",
                                                   -180.0, 180.0, _DEG)
    rx_coupling_db: float | None = spec(
        "rx_coupling_db", "float", "mutual coupling between neighbouring Rx antennas (those "
        "one smallest spacing apart): each receives this fraction of its neighbours' signals; "
        "unset = none", None, unit="dB", lo=-80.0, hi=-3.0)
    rx_coupling_phase_rad: float = spec("rx_coupling_phase_deg", "float", "phase of the Rx "
                                        "coupling coefficient", 0.0, unit="deg", lo=-180.0,
                                        hi=180.0, scale=_DEG)
    compensation: str = spec(
        "compensation", "str", "the radar's own channel compensation: none, or boresight (the "
        "vector measured on a reflector at boresight, applied by the radar's processing)",
        "none", choices=tuple(COMPENSATIONS))
    compensation_range_m: float | None = spec(
        "compensation_range_m", "float", "range of the boresight reflector the compensation was "
        "measured on (its wavefront's curvature is taken for a channel error); unset = far "
        "field", None, unit="m", lo=0.1, hi=1e4)

    @property
    def ideal(self) -> bool:
        """Whether the radar's channels are ideal: no error and no compensation that could
        add one (a far-field boresight compensation of an ideal radar is 1)."""
        zero = not any(any(v) for v in (self.tx_gain_db, self.tx_phase_rad, self.rx_gain_db,
                                        self.rx_phase_rad))
        return (zero and self.rx_coupling_db is None
                and (self.compensation == "none" or self.compensation_range_m is None))


def antenna_counts(radar) -> tuple[int, int]:
    """Physical Tx and Rx antennas of the preset or the custom array (every Tx, the elevated
    ones included, whether or not they transmit)."""
    if radar.array is not None:
        return len(radar.array.tx_mm), len(radar.array.rx_mm)
    p = RADAR_PRESETS[radar.antenna_preset]
    return len(p.tx_units), p.num_rx


def channel_rules(scene, fail) -> None:
    """[radar.channels]: each list empty (no error) or one value per antenna of the array."""
    ch = scene.radar.channels
    if ch is None:
        return
    if ch.compensation_range_m is not None and ch.compensation == "none":
        fail("radar.channels.compensation_range_m", ch.compensation_range_m,
             'left out with radar.channels.compensation = "none" (it is the range of the '
             'boresight compensation\'s reflector)')
    if ch.rx_coupling_phase_rad != 0.0 and ch.rx_coupling_db is None:
        fail("radar.channels.rx_coupling_phase_deg", round(math.degrees(ch.rx_coupling_phase_rad),
                                                           9),
             "left out without radar.channels.rx_coupling_db (it is the phase of that "
             "coupling, which is unset: no coupling)")
    n_tx, n_rx = antenna_counts(scene.radar)
    board = ("[radar.array]" if scene.radar.array is not None
             else f"the {scene.radar.antenna_preset} preset")
    for key, name, n, scale in (("tx_gain_db", "tx_gain_db", n_tx, 1.0),
                                ("tx_phase_rad", "tx_phase_deg", n_tx, 180 / math.pi),
                                ("rx_gain_db", "rx_gain_db", n_rx, 1.0),
                                ("rx_phase_rad", "rx_phase_deg", n_rx, 180 / math.pi)):
        v = getattr(ch, key)
        if len(v) not in (0, n):
            side = "Tx" if key.startswith("tx") else "Rx"
            fail(f"radar.channels.{name}", [round(x * scale, 9) for x in v],
                 f"a list of {n} values, one per {side} antenna of {board} (it has {len(v)}), "
                 "or empty for none")
