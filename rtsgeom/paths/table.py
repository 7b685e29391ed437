"""The :class:`Paths` table: one row per propagation path per antenna-element pair.

Three directions exist:

* ``tx_to_fe``   RuT Tx element -> front end's Rx antenna (``rut_tx`` set, ``rut_rx = -1``)
* ``fe_to_rx``   front end's Tx antenna -> RuT Rx element (``rut_rx`` set, ``rut_tx = -1``)
* ``rut_to_rut`` RuT Tx element -> (setup) -> RuT Rx element, e.g. the sheet reflection of the
  RuT's own chirp (``front_end = -1``)

``gain`` is the complex path amplitude *without* the propagation phase ``exp(-j 2 pi f tau)``:
the FMCW model applies the delay itself at every instantaneous frequency of the chirp.
For a line-of-sight path it is the free-space amplitude ``lambda / (4 pi d)``.
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass

import numpy as np
from scipy.constants import c

from .._lib.util import frozen

__all__ = ["DIRECTIONS", "Paths"]

DIRECTIONS = ("tx_to_fe", "fe_to_rx", "rut_to_rut")
TX_TO_FE, FE_TO_RX, RUT_TO_RUT = 0, 1, 2


@dataclass(frozen=True)
class Paths:
    """The propagation paths of a setup, one row per element pair and path (a table of equal-
    length arrays; ``to_csv()`` is ``rtsgeom paths``'s output).

    Attributes
    ----------
    front_end, rut_tx, rut_rx : (P,) int
        The front end (-1 for RuT to RuT) and the RuT's elements (-1 where not applicable).
    direction : (P,) int8
        Index into ``DIRECTIONS`` (RuT to front end, front end to RuT, RuT to RuT).
    delay_s : (P,) float
    gain : (P,) complex
        Free-space amplitude and antenna gains, without the propagation phase.
    bounces : (P,) int
        0: line of sight; a reflection counts its bounces (ray tracing).
    method : str
        ``exact`` or ``raytrace``.
    """

    front_end: np.ndarray  # (P,) int, -1 for rut_to_rut
    direction: np.ndarray  # (P,) int8 index into DIRECTIONS
    rut_tx: np.ndarray  # (P,) int, -1 where not applicable
    rut_rx: np.ndarray  # (P,) int
    delay_s: np.ndarray  # (P,) float64
    gain: np.ndarray  # (P,) complex128, no propagation phase
    bounces: np.ndarray  # (P,) int, 0 = line of sight
    interactions: np.ndarray  # (P,) str, e.g. "los", "specular", "specular+specular"
    surfaces: np.ndarray  # (P,) str, what each bounce hit, e.g. "sheet+structure[0]"; "" for LOS
    method: str = "exact"

    def __post_init__(self):
        n = self.delay_s.shape[0]
        for name in ("front_end", "direction", "rut_tx", "rut_rx", "gain", "bounces",
                     "interactions", "surfaces"):
            if getattr(self, name).shape != (n,):
                raise ValueError(f"Paths.{name} must have shape ({n},)")

    @classmethod
    def build(cls, front_end, direction, rut_tx, rut_rx, delay_s, gain, bounces=None, *,
              interactions=None, method="exact", surfaces=None) -> "Paths":
        """The table from columns (each (P,)). ``bounces`` default 0 (line of sight);
        ``interactions`` default ``los`` / ``reflection``; ``surfaces`` (what each bounce hit,
        ``+``-joined in the order of the bounces) default ``""`` for line of sight and
        ``unknown`` for a reflection whose producer did not say."""
        delay = np.asarray(delay_s, float).ravel()
        n = delay.size
        b = np.zeros(n, int) if bounces is None else np.asarray(bounces, int).ravel()
        k = (np.where(b == 0, "los", "reflection") if interactions is None
             else np.asarray(interactions, str).ravel())
        sf = (np.where(b == 0, "", "unknown") if surfaces is None
              else np.asarray(surfaces, str).ravel())
        return cls(frozen(np.asarray(front_end, int).ravel()),
                   frozen(np.asarray(direction, np.int8).ravel()),
                   frozen(np.asarray(rut_tx, int).ravel()), frozen(np.asarray(rut_rx, int).ravel()),
                   frozen(delay), frozen(np.asarray(gain, complex).ravel()), frozen(b), frozen(k),
                   frozen(sf), method)

    @classmethod
    def concat(cls, tables: list["Paths"]) -> "Paths":
        names = ("front_end", "direction", "rut_tx", "rut_rx", "delay_s", "gain", "bounces",
                 "interactions", "surfaces")
        cols = {n: np.concatenate([getattr(t, n) for t in tables]) for n in names}
        return cls.build(**cols, method="+".join(sorted({t.method for t in tables})))

    def __len__(self) -> int:
        return int(self.delay_s.size)

    @property
    def length_m(self) -> np.ndarray:
        return self.delay_s * c

    def select(self, mask: np.ndarray) -> "Paths":
        m = np.asarray(mask, bool)
        return Paths.build(self.front_end[m], self.direction[m], self.rut_tx[m], self.rut_rx[m],
                           self.delay_s[m], self.gain[m], self.bounces[m],
                           interactions=self.interactions[m], method=self.method,
                           surfaces=self.surfaces[m])

    def leg(self, front_end: int, direction: int, element: int) -> "Paths":
        """All rows of one leg: (front end, direction, RuT element)."""
        col = self.rut_tx if direction == TX_TO_FE else self.rut_rx
        return self.select((self.front_end == front_end) & (self.direction == direction)
                           & (col == element))

    def to_csv(self) -> str:
        """CSV text: ``front_end, direction, rut_element, length_m, delay_s`` plus gain,
        interaction and surface columns (``surfaces``: what each bounce hit). ``rut_element`` is ``tx<i>``, ``rx<k>`` or ``tx<i>-rx<k>``."""
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(["front_end", "direction", "rut_element", "length_m", "delay_s",
                    "gain_db", "gain_phase_deg", "bounces", "interactions", "surfaces"])
        for i in range(len(self)):
            d = int(self.direction[i])
            if d == TX_TO_FE:
                el = f"tx{self.rut_tx[i]}"
            elif d == FE_TO_RX:
                el = f"rx{self.rut_rx[i]}"
            else:
                el = f"tx{self.rut_tx[i]}-rx{self.rut_rx[i]}"
            g = self.gain[i]
            w.writerow([int(self.front_end[i]), DIRECTIONS[d], el, f"{self.length_m[i]:.12f}",
                        f"{self.delay_s[i]:.15e}", f"{20 * np.log10(max(abs(g), 1e-300)):.4f}",
                        f"{np.degrees(np.angle(g)):.4f}", int(self.bounces[i]),
                        self.interactions[i], self.surfaces[i]])
        return buf.getvalue()
