"""Antenna layouts of the radars people put in front of an RTS, and explicit custom arrays.

A leaf module (numpy only) so the scene loader can read :data:`PRESETS` and build or validate
an :class:`ArraySpec` without importing the geometry package.

Board coordinates: ``x`` lateral (looking at the antenna side of the board, ``x`` grows towards
larger azimuth in the radar frame), ``z`` up. Presets are stored in **units of d**, the
half-wavelength at the board's design frequency (TI boards are laid out in lambda/2 steps at
the band centre); :meth:`ArrayPreset.spec` scales them by the physical element spacing ``d``
(by default lambda/2 at the radar's centre frequency, as ``radar.element_spacing_m = 0``
always meant). A custom array (:class:`ArraySpec`) is given directly in metres.

The virtual element ``(m, k)`` sits at ``p_tx(m) + p_rx(k)`` (the position whose projection on
the arrival direction gives the two-way far-field phase, paper eq. 13), so the azimuth virtual
array of a preset is a set of integer multiples of ``d``.

Sources (TI document numbers) and what was checked is stated per preset; a layout that could
not be verified from a readable source says so in its ``note``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import SceneError

__all__ = ["ArrayPreset", "ArraySpec", "CaptureLayout", "PRESETS", "preset", "LAYOUT_DEFAULT"]


def _frozen(a) -> np.ndarray:
    a = np.array(a, dtype=float)
    a.setflags(write=False)
    return a


@dataclass(frozen=True)
class ArraySpec:
    """An explicit RuT antenna array in board coordinates, metres.

    Parameters
    ----------
    tx_m : (N_tx, 2) ``[x, z]`` of every physical Tx antenna (metres).
    rx_m : (N_rx, 2) ``[x, z]`` of every Rx antenna (metres).
    tx_order : Tx index transmitting in each TDM slot (every slot a distinct Tx).
    spacing_m : the array's grid unit ``d`` (for the resolution, the angle-search grid and the
        grating-lobe check); ``None``: the smallest gap between distinct azimuth virtual
        positions.
    name : label for reports (the preset's name, or ``"custom"``).

    Errors name the field and the allowed range (``ValueError``), so a scene loader can pass
    them through.
    """

    tx_m: np.ndarray
    rx_m: np.ndarray
    tx_order: tuple[int, ...]
    spacing_m: float | None = None
    name: str = "custom"

    def __post_init__(self):
        for fname in ("tx_m", "rx_m"):
            a = np.asarray(getattr(self, fname), dtype=float)
            if a.ndim != 2 or a.shape[1] != 2 or a.shape[0] < 1:
                raise SceneError(f"array.{fname}: expected a list of [x, z] pairs (at least "
                                 f"one), got shape {a.shape}")
            if not np.all(np.isfinite(a)) or np.any(np.abs(a) > 1.0):
                raise SceneError(f"array.{fname}: coordinates must be finite and within +-1 m")
            object.__setattr__(self, fname, _frozen(a))
        order = tuple(int(i) for i in self.tx_order)
        n_tx = self.tx_m.shape[0]
        if not order or any(i < 0 or i >= n_tx for i in order) or len(set(order)) != len(order):
            raise SceneError(f"array.tx_order: distinct Tx indices in [0, {n_tx - 1}] (at least "
                             f"one), got {list(self.tx_order)}")
        object.__setattr__(self, "tx_order", order)
        if self.spacing_m is not None and not (0.0 < float(self.spacing_m) <= 0.1):
            raise SceneError(f"array.spacing_m: must lie in (0, 0.1] m, got {self.spacing_m}")
        for fname, a in (("tx_m", self.tx_m), ("rx_m", self.rx_m)):
            u = np.unique(np.round(a * 1e9).astype(np.int64), axis=0)
            if u.shape[0] != a.shape[0]:
                raise SceneError(f"array.{fname}: two antennas at the same position")

    @property
    def num_tx(self) -> int:
        return int(self.tx_m.shape[0])

    @property
    def num_rx(self) -> int:
        return int(self.rx_m.shape[0])

    def azimuth_virtual_x_m(self) -> np.ndarray:
        """Distinct azimuth virtual positions x (board frame, m, ascending): the fullest virtual
        row (ties: the lowest |z|), as ``geometry.arrays.array_from_spec`` chooses it."""
        order = np.asarray(self.tx_order)
        vx = (self.tx_m[order, 0][:, None] + self.rx_m[None, :, 0]).ravel()
        vz = np.round((self.tx_m[order, 1][:, None] + self.rx_m[None, :, 1]).ravel() * 1e9)
        rows, counts = np.unique(vz, return_counts=True)
        best = rows[counts == counts.max()]
        row = vz == best[np.argmin(np.abs(best))]
        return np.unique(np.round(vx[row] * 1e9)) * 1e-9

    def azimuth_aperture_m(self) -> float:
        """Azimuth aperture d_A: span of the distinct azimuth virtual positions plus one grid
        cell d (``spacing_m``, else the smallest gap; paper eq. 24 convention)."""
        x = self.azimuth_virtual_x_m()
        gaps = np.diff(x)
        d = float(self.spacing_m) if self.spacing_m else (float(gaps.min()) if gaps.size else 0.0)
        return float(np.ptp(x) + d) if d > 0 else 0.0

    @classmethod
    def from_mm(cls, tx_mm, rx_mm, tx_order, name: str = "custom") -> "ArraySpec":
        """The scene's ``[radar.array]`` form: ``tx_mm``/``rx_mm`` in millimetres."""
        return cls(np.asarray(tx_mm, float) * 1e-3, np.asarray(rx_mm, float) * 1e-3,
                   tuple(tx_order), name=name)


@dataclass(frozen=True)
class CaptureLayout:
    """How the board's raw ADC samples reach a DCA1000 capture file (TI SWRA581, "Mmwave Radar
    Device ADC Raw Data Capture", sections 5, 6 and 9): real-only or complex (I/Q) samples and
    the number of LVDS data lanes, which sets the interleaving (:mod:`rtsgeom.radar.dca1000`).

    ``name`` is what the capture's sidecar records as its ``format``.
    """

    family: str  # the device family as the format name says it (xwr18xx, awr2944, ...)
    complex: bool  # I/Q (complex baseband) samples, else real-only
    lanes: int  # LVDS data lanes: 2 (xWR16xx/18xx/68xx/2944) or 4 (xWR12xx/14xx/22xx)
    source: str  # the documents that say so

    def __post_init__(self):
        if self.lanes not in (2, 4):
            raise SceneError(f"capture layout lanes = {self.lanes}: must be 2 or 4 (the "
                             "DCA1000's LVDS layouts)")

    @property
    def adc(self) -> str:
        """``"complex"`` or ``"real"``."""
        return "complex" if self.complex else "real"

    @property
    def name(self) -> str:
        """The sidecar's ``format``, e.g. ``dca1000-awr2944-real-2lane``."""
        return f"dca1000-{self.family}-{self.adc}-{self.lanes}lane"


_SWRA581_2LANE = ("TI SWRA581B (Mmwave Radar Device ADC Raw Data Capture), sec. 6 'xWR16xx and "
                  "IWR6843 with DCA1000 data format' and sec. 9 (readDCA1000): 2 LVDS lanes; "
                  "per chirp Rx 0..3 one after the other; complex samples stored I0 I1 Q0 Q1, "
                  "real samples in order")
_SWRA581_4LANE = ("TI SWRA581B, sec. 5 'xWR12xx and xWR14xx with DCA1000 data format' and sec. "
                  "9: 4 LVDS lanes, one Rx per lane, per sample the lanes' I then their Q "
                  "(reshape(adcData, numLanes*2, [])); real: the lanes' samples in turn")

#: the layout of a capture whose sidecar names no layout (captures written before layouts were
#: per preset): the xWR18xx's complex 2-lane format
LAYOUT_DEFAULT = CaptureLayout("xwr18xx", True, 2, _SWRA581_2LANE)


@dataclass(frozen=True)
class ArrayPreset:
    """A documented radar board layout, positions in units of ``d`` (lambda/2 at the design
    frequency).

    ``rx_units`` of a board with separate Tx and Rx groups (``board_gap_units`` not None) are
    relative to the Rx group's first element; :meth:`positions` places that element
    ``board_gap`` to the right of the right-most Tx. The gap is the lateral distance between the
    groups: it does not change the virtual array but it does change the near field, because the
    Tx group sees a front end's Rx antenna and the Rx group its Tx antenna from different places
    (the parallax of ``analysis.nearfield``: +0.27 deg at R_c = 1 m for the AWR1843BOOST with
    3 lambda). Boards whose Tx and Rx interleave (the cascade) have ``board_gap_units = None``
    and absolute ``rx_units``.
    """

    name: str
    tx_units: np.ndarray  # (N_tx, 2) [x, z] in units of d
    rx_units: np.ndarray  # (N_rx, 2)
    tx_order: tuple[int, ...]  # default TDM slots: the azimuth Tx only
    tx_order_elevation: tuple[int, ...]  # all Tx, elevated ones included
    board_gap_units: float | None  # lateral Tx-group -> Rx-group gap, units of d
    design_frequency_hz: float
    source: str  # cited documents
    note: str = ""  # what is verified, what is assumed
    num_azimuth_unique: int = 0  # documented number of distinct azimuth virtual positions
    labels: tuple[str, ...] = field(default=())  # Tx names in index order
    link: dict = field(default_factory=dict)  # [radar.link] values and their sources
    capture: CaptureLayout = LAYOUT_DEFAULT  # the board's raw-capture layout (DCA1000)

    def __post_init__(self):
        object.__setattr__(self, "tx_units", _frozen(self.tx_units))
        object.__setattr__(self, "rx_units", _frozen(self.rx_units))

    def positions_m(self, spacing_m: float, board_gap_m: float | None = None
                    ) -> tuple[np.ndarray, np.ndarray]:
        """Tx and Rx ``[x, z]`` positions in metres for element spacing ``d = spacing_m``.

        ``board_gap_m``: the lateral gap from the right-most Tx to the Rx group's first
        element (``None``: the preset's documented or assumed gap, ``board_gap_units * d``).
        """
        d = float(spacing_m)
        tx = self.tx_units * d
        rx = self.rx_units * d
        if self.board_gap_units is None:
            if board_gap_m is not None:
                raise SceneError(f"radar.board_gap_m: the {self.name} preset has interleaved Tx "
                                 "and Rx antennas, so no board gap applies")
            return tx, rx
        gap = self.board_gap_units * d if board_gap_m is None else float(board_gap_m)
        if not (0.0 <= gap <= 0.5):
            raise SceneError(f"radar.board_gap_m: must lie in [0, 0.5] m, got {gap:g}")
        rx[:, 0] += tx[:, 0].max() + gap  # same operations as the original AWR1843 layout
        return tx, rx

    @property
    def doc(self) -> str:
        """One line for registries and generated docs."""
        n_tx, n_rx = len(self.tx_units), len(self.rx_units)
        n_az, n_all = len(self.tx_order), len(self.tx_order_elevation)
        virtual = f"{n_az * n_rx} virtual elements ({n_az} Tx in TDM x {n_rx} Rx)"
        if n_all > n_az:
            virtual += (f", {n_all * n_rx} with the {n_all - n_az} elevated Tx "
                        "(radar.use_elevation_tx = true)")
        return (f"{n_tx} Tx x {n_rx} Rx board: {virtual}; captures {self.capture.name} "
                f"({self.source.split(';')[0]})")

    @property
    def num_rx(self) -> int:
        return int(len(self.rx_units))

    def active_tx_order(self, use_elevation_tx: bool = False) -> tuple[int, ...]:
        """The TDM slots: the azimuth Tx, or all Tx with ``use_elevation_tx``."""
        return self.tx_order_elevation if use_elevation_tx else self.tx_order

    def azimuth_aperture_units(self, use_elevation_tx: bool = False) -> float:
        """Aperture d_A / d of the azimuth virtual row (paper eq. 24): the span of the distinct
        azimuth virtual positions plus one cell (N_A for a filled lambda/2 row)."""
        order = self.active_tx_order(use_elevation_tx)
        tx = self.tx_units[list(order)]
        row = tx[:, 1] == tx[:, 1].min()  # the lowest (azimuth) Tx row
        x = (tx[row, 0][:, None] + self.rx_units[:, 0][None, :]).ravel()
        return float(x.max() - x.min() + 1.0)

    def default_board_gap_m(self, spacing_m: float) -> float | None:
        return None if self.board_gap_units is None else self.board_gap_units * spacing_m

    def spec(self, spacing_m: float, use_elevation_tx: bool = False,
             board_gap_m: float | None = None, tx_order=None) -> ArraySpec:
        """The :class:`ArraySpec` of this board for element spacing ``d = spacing_m``.

        ``board_gap_m`` (metres) overrides the preset's gap; ``tx_order`` overrides the TDM
        slots (else the azimuth Tx, or all Tx with ``use_elevation_tx``).
        """
        tx, rx = self.positions_m(spacing_m, board_gap_m)
        order = (tx_order if tx_order is not None
                 else self.tx_order_elevation if use_elevation_tx else self.tx_order)
        return ArraySpec(tx, rx, tuple(order), spacing_m=spacing_m, name=self.name)


# Each preset's link values ([radar.link]) and where each comes from
# (rtsgeom.radar.link.radar_link fills the unset [radar.link] fields from them). Checked against
# the TI datasheets' HTML editions in the project's search corpus (ti.com document viewer) on
# 2026-11-23: a value with a document and section is verified there; "[re-check]" marks one that
# could not be (what was tried is said); "[assumed]" one that no datasheet states. The RF specification tables of the AWR1843
# (SWRS222D), IWR6843 (SWRS219E/F), AWR2243 (SWRS223D) and AWR2944 (SWRS273D) were listed in the
# corpus but their table text was not retrievable (only the contents came back, queries on the
# table rows included), so those devices' Tx power and noise figure stay [re-check].
_RECHECK_RF = ("[re-check]: the device's RF Specification table was not retrievable from the "
               "search corpus (only its table of contents)")
_HPF = ("HPF1 corner, one of 175/235/350/700 kHz (hpfCornerFreq1 of rlProfileCfg_t, TI mmWave "
        "DFP; the codes 0-3 as listed in TI mmWave Studio's cascade Lua scripts); the "
        "datasheets' receive-subsystem section: 'configurable lower cutoff frequencies above "
        "175 kHz'; the lowest is taken. Modelled as one first-order stage (HPF2, 350 kHz and "
        "up, is not modelled)")
_FS = ("[assumed] receiver-input power of a full-scale tone at a mid Rx gain (~30 dB of the "
       "24-48 dB range): not in the datasheet; check with the device's Rx saturation monitor")
_LPF_ORDER = "[assumed] 4th-order Butterworth anti-alias response"
_ADC_CFG = ("[re-check] 12 bits: the mmWave SDK's adcCfg numADCBits (0 = 12, 1 = 14, 2 = 16 "
            "bit output formats); the datasheet's ADC resolution row was not retrievable")

_AWR1843BOOST_LINK = {
    "values": {"tx_power_dbm": 12.0, "tx_antenna_gain_dbi": 10.5,
               "rx_antenna_gain_dbi": 10.5, "noise_figure_db": 15.0,
               "if_highpass_hz": 175e3, "if_lowpass_hz": 10e6, "if_lowpass_order": 4,
               "adc_bits": 12, "adc_full_scale_dbm": -25.0},
    "sources": {"tx_power_dbm": "TI AWR1843 datasheet (SWRS222), RF Specification: TX "
                                f"power 12 dBm {_RECHECK_RF}",
                "tx_antenna_gain_dbi": "TI xWR1843BOOST user's guide (SPRUIM4): antenna peak "
                                       "gain > 10.5 dBi (76-81 GHz) [re-check: not in the "
                                       "corpus]",
                "rx_antenna_gain_dbi": "as tx_antenna_gain_dbi",
                "noise_figure_db": "TI AWR1843 datasheet (SWRS222), RF Specification: RX "
                                   "noise figure 14 dB (76-77 GHz), 15 dB (77-81 GHz); 15 "
                                   f"dB taken {_RECHECK_RF}",
                "if_highpass_hz": _HPF,
                "if_lowpass_hz": "10 MHz: TI IWR1843AOP datasheet (JAJSRC0), Receive "
                                 "Subsystem: 'bandwidths up to 10 MHz' (the AWR1843's own "
                                 "section was not retrievable [re-check])",
                "if_lowpass_order": _LPF_ORDER,
                "adc_bits": _ADC_CFG,
                "adc_full_scale_dbm": _FS}}
_IWR6843ISK_LINK = {
    "values": {"tx_power_dbm": 12.0, "tx_antenna_gain_dbi": 7.0, "rx_antenna_gain_dbi": 7.0,
               "noise_figure_db": 12.0, "if_highpass_hz": 175e3, "if_lowpass_hz": 10e6,
               "if_lowpass_order": 4, "adc_bits": 12, "adc_full_scale_dbm": -25.0},
    "sources": {"tx_power_dbm": f"TI IWR6843 datasheet (SWRS219): TX power 12 dBm {_RECHECK_RF}",
                "tx_antenna_gain_dbi": "[assumed] ~7 dBi patch array of the ISK module",
                "rx_antenna_gain_dbi": "[assumed] as tx_antenna_gain_dbi",
                "noise_figure_db": "TI IWR6843 datasheet (SWRS219): RX noise figure 12 dB "
                                   + _RECHECK_RF,
                "if_highpass_hz": _HPF + "; TI IWR6843 datasheet (SWRS219E), Receive "
                                         "Subsystem: 'lower cutoff frequencies above 175 kHz'",
                "if_lowpass_hz": "TI IWR6843 datasheet (SWRS219E), Receive Subsystem: "
                                 "'bandwidths up to 10 MHz'",
                "if_lowpass_order": _LPF_ORDER, "adc_bits": _ADC_CFG,
                "adc_full_scale_dbm": _FS}}
_AWR2944_LINK = {
    # A real-only receiver (SWRS273/JAJSNB2A, Receive Subsystem): the signal model's complex
    # baseband is an approximation for it (no image band, the noise of one rail).
    "values": {"tx_power_dbm": 13.5, "tx_antenna_gain_dbi": 10.0,
               "rx_antenna_gain_dbi": 10.0, "noise_figure_db": 12.0,
               "if_highpass_hz": 350e3, "if_lowpass_hz": 15e6, "if_lowpass_order": 4,
               "adc_bits": 16, "adc_full_scale_dbm": -25.0},
    "sources": {"tx_power_dbm": "13.5 dBm: TI IWR2944 datasheet (SWRS330), RF "
                                "Specifications table, Transmitter output power (the "
                                "industrial variant; the AWR2944's own table, SWRS273D "
                                "6.8, was not retrievable [re-check])",
                "tx_antenna_gain_dbi": "[assumed]", "rx_antenna_gain_dbi": "[assumed]",
                "noise_figure_db": "12 dB: TI IWR2944 datasheet (SWRS330), RF Specifications "
                                   "table, Receiver noise figure (as tx_power_dbm "
                                   "[re-check] for the AWR2944)",
                "if_highpass_hz": "350 kHz: TI AWR2944 datasheet (JAJSNB2A), Receive "
                                  "Subsystem: 'configurable cutoff frequencies above 350 "
                                  "kHz' (the IWR2944's table, SWRS330, note 2: a "
                                  "second-order HPF, -6 dB corners 300/350/700/1400 kHz; "
                                  "modelled as one first-order stage)",
                "if_lowpass_hz": "TI AWR2944 datasheet (JAJSNB2A), Receive Subsystem: "
                                 "'bandwidths up to 15 MHz'",
                "if_lowpass_order": _LPF_ORDER,
                "adc_bits": "16 bits: TI IWR2944 datasheet (SWRS330), RF Specifications "
                            "table, ADC resolution [re-check] for the AWR2944",
                "adc_full_scale_dbm": _FS}}
_AWR2243_CASCADE_LINK = {
    "values": {"tx_power_dbm": 13.0, "tx_antenna_gain_dbi": 10.0,
               "rx_antenna_gain_dbi": 10.0, "noise_figure_db": 14.0,
               "if_highpass_hz": 175e3, "if_lowpass_hz": 20e6, "if_lowpass_order": 4,
               "adc_bits": 12, "adc_full_scale_dbm": -25.0},
    "sources": {"tx_power_dbm": f"TI AWR2243 datasheet (SWRS223): TX power 13 dBm {_RECHECK_RF}",
                "tx_antenna_gain_dbi": "[assumed]", "rx_antenna_gain_dbi": "[assumed]",
                "noise_figure_db": "TI AWR2243 datasheet (SWRS223): RX noise figure "
                                   f"12-14 dB; 14 dB taken {_RECHECK_RF}",
                "if_highpass_hz": _HPF + "; TI AWR2243 datasheet (SWRS223D), Receive "
                                         "Subsystem: 'lower cutoff frequencies above 175 kHz'",
                "if_lowpass_hz": "TI AWR2243 datasheet (SWRS223D), Receive Subsystem: "
                                 "'bandwidths up to 20 MHz'",
                "if_lowpass_order": _LPF_ORDER, "adc_bits": _ADC_CFG,
                "adc_full_scale_dbm": _FS}}

_RX4 = [[0, 0], [1, 0], [2, 0], [3, 0]]

PRESETS: dict[str, ArrayPreset] = {p.name: p for p in (
    ArrayPreset(
        name="awr1843boost", link=_AWR1843BOOST_LINK,
        capture=CaptureLayout("xwr18xx", True, 2, _SWRA581_2LANE + "; TI AWR1843 datasheet "
                              "(SWRS222): complex baseband receiver"),
        tx_units=[[0, 0], [2, 1], [4, 0]], rx_units=_RX4,
        tx_order=(0, 2), tx_order_elevation=(0, 1, 2), board_gap_units=6.0,
        design_frequency_hz=77e9, num_azimuth_unique=8, labels=("TX1", "TX2", "TX3"),
        source="TI xWR1843BOOST EVM user's guide (SPRUIM4); TI mmWave SDK xWR18xx "
               "out-of-box demo antenna geometry",
        note="RX1..RX4 at lambda/2; TX1 and TX3 2 lambda apart in azimuth (8-element lambda/2 "
             "azimuth virtual array with the 4 Rx); TX2 elevated by lambda/2, lambda right of "
             "TX1 (4 elevated virtual elements). The Tx-Rx board gap (3 lambda, right edge of "
             "TX3 to RX1) is an ASSUMPTION of this project, not a documented value."),
    ArrayPreset(
        name="iwr6843isk", link=_IWR6843ISK_LINK,
        capture=CaptureLayout("iwr6843", True, 2, _SWRA581_2LANE + "; TI AWR6843 datasheet "
                              "(SWRS248D), LVDS: two data lanes"),
        tx_units=[[0, 0], [2, 1], [4, 0]], rx_units=_RX4,
        tx_order=(0, 2), tx_order_elevation=(0, 1, 2), board_gap_units=6.0,
        design_frequency_hz=62e9, num_azimuth_unique=8, labels=("TX1", "TX2", "TX3"),
        source="TI IWR6843ISK antenna module user's guide (SWRU546); the same 3 Tx x 4 Rx "
               "pattern is written out in TI SWRU585 (IWR6843L EVM, sec. 4.1)",
        note="Rx at D = lambda/2; TX1-TX2 lambda apart in azimuth and lambda/2 in elevation, "
             "TX2-TX3 lambda in azimuth and lambda/2 in elevation (TX1, TX3 on one row, TX2 "
             "elevated), lambda at 62 GHz. The board gap is ASSUMED (3 lambda), not documented."),
    ArrayPreset(
        name="awr2944", link=_AWR2944_LINK,
        capture=CaptureLayout("awr2944", False, 2, _SWRA581_2LANE + "; TI AWR2944 datasheet "
                              "(SWRS273A), LVDS: '2-data lane'; (JAJSNB2A), Receive "
                              "Subsystem: 'The device supports a real-only receiver'; TI "
                              "AWR2944EVM user's guide (SPRUJ22A): streams to the DCA1000"),
        tx_units=[[0, 0], [4, 0], [8, 0], [2, 1]], rx_units=_RX4,
        tx_order=(0, 1, 2), tx_order_elevation=(0, 1, 2, 3), board_gap_units=6.0,
        design_frequency_hz=77e9, num_azimuth_unique=12, labels=("TX1", "TX2", "TX3", "TX4"),
        source="TI AWR2944EVM user's guide (SPRUJ22); TI TIDEP-01027 design guide (TIDUF01, "
               "fig. 2-3); TI mmWave MCU+ SDK DDMA Doppler DPU (NUM_TXANT_AZIM 3, "
               "NUM_TXANT_ELEV 1 for SOC_AWR2944)",
        note="4 Tx x 4 Rx with 3 azimuth Tx and 1 elevated Tx is verified (SDK constants); the "
             "positions are NOT verified (the user's guide gives them only as a figure): modelled "
             "as Rx at lambda/2, the azimuth Tx 2 lambda apart (a filled 12-element lambda/2 "
             "azimuth virtual array), the elevated Tx lambda/2 up and lambda right of TX1, and "
             "a 3 lambda board gap (assumed). Use a custom [radar.array] for the real board."),
    ArrayPreset(
        name="awr2243-cascade", link=_AWR2243_CASCADE_LINK,
        capture=CaptureLayout("awr2243", True, 4, _SWRA581_4LANE + "; TI AWR2243 datasheet "
                              "(SWRS223D), Receive Subsystem: complex baseband (I and Q "
                              "outputs). [assumed] the four devices' streams one after the "
                              "other per chirp (Rx 0-3, 4-7, 8-11, 12-15), each in the 4-lane "
                              "layout: the cascade board records through the MMWCAS-DSP-EVM, "
                              "one file per device, not a DCA1000"),
        tx_units=[[11, 6], [10, 4], [9, 1], [32, 0], [28, 0], [24, 0], [20, 0], [16, 0],
                  [12, 0], [8, 0], [4, 0], [0, 0]],
        rx_units=[[x, 0] for x in (*range(11, 15), *range(50, 54), *range(46, 50),
                                   *range(0, 4))],
        tx_order=tuple(range(3, 12)), tx_order_elevation=tuple(range(11, -1, -1)),
        board_gap_units=None, design_frequency_hz=76.8e9, num_azimuth_unique=86,
        labels=tuple(f"TX{i}" for i in range(1, 13)),
        source="TI TIDEP-01012 imaging radar using cascaded mmWave sensors design guide "
               "(TIDUEN5, figs. 5-7); MMWCAS-RF-EVM user's guide (SWRU553); TI mmWave Studio "
               "cascade MATLAB processing (TI_Cascade_TX/RX_position_azi/_ele, 76.8 GHz)",
        note="12 Tx x 16 Rx of four AWR2243. TX1..TX3 (master) elevated at 6, 4, 1 x lambda/2 "
             "(minimum-redundancy elevation array); TX4..TX12 on the azimuth row 2 lambda apart; "
             "Rx groups at 0-3, 11-14, 46-49 and 50-53 x lambda/2. The 9 x 16 = 144 azimuth "
             "virtual elements cover 86 distinct lambda/2 positions (0..85; the rest overlap). "
             "Verified against the cited numbers. Tx and Rx interleave: no board gap."),
)}


def preset(name: str) -> ArrayPreset:
    """The preset called ``name``; a clear error listing the known ones otherwise."""
    try:
        return PRESETS[name]
    except KeyError:
        raise SceneError(f"radar.antenna_preset: unknown preset '{name}' (known: "
                         f"{', '.join(PRESETS)})") from None
