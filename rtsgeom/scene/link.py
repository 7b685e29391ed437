"""Scene fields of the physical link budget: ``[radar.link]`` and ``[rts.link]``.

Declared once (:func:`rtsgeom.scene.schema.spec`) like every scene field; the physics that uses them
is :mod:`rtsgeom.radar.link`. Kept apart from ``scene.py`` so that module stays small and the link's
fields sit in one place. ``[radar.link]`` is optional: absent, the signal model keeps its
relative amplitudes (transmit power 1, isotropic RuT) and its noise from ``snr_db``; present
(even empty), the echoes are powers at the RuT's receiver input, filtered by the IF chain,
with thermal noise and an ADC that clips and quantises. Unset values come from the antenna
preset's datasheet values (``rtsgeom.radar.link.RADAR_LINK_PRESETS``, with their sources).
"""

from __future__ import annotations

from dataclasses import dataclass

from .schema import Derived, Evolvable, spec

__all__ = ["RadarLinkConfig", "RtsLinkConfig", "RADAR_LINK_PRESETS", "FE_ANTENNA_GAIN_DBI"]

_PRESET = Derived("the antenna preset's value (rtsgeom.radar.link.RADAR_LINK_PRESETS)", lambda v: None)
_RUT_GAIN = Derived("the preset's peak gain; 0 with a [radar.pattern]: the pattern's gain toward "
                    "each front end (its dB read as dBi) is the antenna's", lambda v: None)
_FE_GAIN = Derived("10; 0 with a [rts.pattern]: the pattern's gain toward the RuT (its dB read "
                   "as dBi) is the antenna's", lambda v: None)
FE_ANTENNA_GAIN_DBI = 10.0  # the scalar default without a front-end pattern


@dataclass(frozen=True)
class RadarLinkConfig(Evolvable):
    """The RuT's transmitter, receiver, IF chain and ADC (radar equation and thermal noise).

    Powers are referred to the antenna ports (the receiver input); the ADC's full scale is the
    power of a tone at the receiver input that just reaches full scale (at the Rx gain set)."""

    tx_power_dbm: float | None = spec("tx_power_dbm", "float", "transmit power per Tx at the "
                                      "antenna port", _PRESET, unit="dBm", lo=-50.0, hi=50.0)
    tx_antenna_gain_dbi: float | None = spec("tx_antenna_gain_dbi", "float", "gain of a Tx "
                                             "antenna on top of [radar.pattern] (which the "
                                             "paths carry toward each front end)", _RUT_GAIN,
                                             unit="dBi", lo=-20.0, hi=50.0)
    rx_antenna_gain_dbi: float | None = spec("rx_antenna_gain_dbi", "float", "gain of an Rx "
                                             "antenna on top of [radar.pattern]", _RUT_GAIN,
                                             unit="dBi", lo=-20.0, hi=50.0)
    noise_figure_db: float | None = spec("noise_figure_db", "float", "receiver noise figure",
                                         _PRESET, unit="dB", lo=0.0, hi=50.0)
    if_highpass_hz: float | None = spec("if_highpass_hz", "float", "IF high-pass corner "
                                        "(first order); 0 = none", _PRESET, unit="Hz",
                                        lo=0.0, hi=1e9)
    if_lowpass_hz: float | None = spec("if_lowpass_hz", "float", "IF low-pass / anti-alias "
                                       "corner", _PRESET, unit="Hz", lo=1e3, hi=1e10)
    if_lowpass_order: int | None = spec("if_lowpass_order", "int", "order of the Butterworth "
                                        "IF low-pass", _PRESET, lo=1, hi=12)
    adc_bits: int | None = spec("adc_bits", "int", "ADC resolution per I and Q rail", _PRESET,
                                lo=2, hi=24)
    adc_full_scale_dbm: float | None = spec("adc_full_scale_dbm", "float", "receiver-input "
                                            "power of a tone at ADC full scale", _PRESET,
                                            unit="dBm", lo=-100.0, hi=50.0)
    temperature_k: float = spec("temperature_k", "float", "noise reference temperature T0",
                                290.0, unit="K", lo=1.0, hi=1000.0)


@dataclass(frozen=True)
class RtsLinkConfig(Evolvable):
    """One RTS channel's link: front-end antennas, receive and transmit gain, noise figure and
    the back end's ADC/DAC full scale (used when ``[radar.link]`` is given).

    Defaults are assumptions for a front end like the paper's with an RFSoC back end
    (ADC full scale +1 dBm, 14-bit DAC: Xilinx DS926 class); set them from your hardware."""

    fe_rx_antenna_gain_dbi: float | None = spec("fe_rx_antenna_gain_dbi", "float", "front-end "
                                                "Rx antenna gain on top of [rts.pattern]",
                                                _FE_GAIN, unit="dBi", lo=-20.0, hi=50.0)
    fe_tx_antenna_gain_dbi: float | None = spec("fe_tx_antenna_gain_dbi", "float", "front-end "
                                                "Tx antenna gain on top of [rts.pattern]",
                                                _FE_GAIN, unit="dBi", lo=-20.0, hi=50.0)
    rx_gain_db: float = spec("rx_gain_db", "float", "gain from the Rx antenna port to the back "
                             "end's ADC input (LNA, down-conversion, cable)", 30.0, unit="dB",
                             lo=-50.0, hi=150.0)
    tx_gain_db: float = spec("tx_gain_db", "float", "gain from the DAC output to the Tx antenna "
                             "port (up-conversion, PA, cable)", 20.0, unit="dB", lo=-50.0,
                             hi=150.0)
    noise_figure_db: float = spec("noise_figure_db", "float", "channel noise figure at the Rx "
                                  "antenna port", 12.0, unit="dB", lo=0.0, hi=50.0)
    adc_full_scale_dbm: float = spec("adc_full_scale_dbm", "float", "back-end ADC full scale "
                                     "(input power of a full-scale tone)", 1.0, unit="dBm",
                                     lo=-60.0, hi=40.0)
    dac_full_scale_dbm: float = spec("dac_full_scale_dbm", "float", "back-end DAC output power "
                                     "of a full-scale tone", 0.0, unit="dBm", lo=-60.0, hi=40.0)
    dac_bits: int = spec("dac_bits", "int", "DAC resolution (sets the attenuation range: the "
                         "echo must stay above the DAC's quantisation floor)", 14, lo=2, hi=24)


# The RuT presets' link values and where each comes from (rtsgeom.radar.link.radar_link fills the
# unset [radar.link] fields from them). Checked against the TI datasheets' HTML editions in the
# project's search corpus (ti.com document viewer) on 2026-11-23: a value with a document and
# section is verified there; "[re-check]" marks one that could not be (what was tried is said);
# "[assumed]" one that no datasheet states. The RF specification tables of the AWR1843
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

# One entry per antenna preset: the values and where each comes from.
RADAR_LINK_PRESETS: dict[str, dict] = {
    "awr1843boost": {
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
                    "adc_full_scale_dbm": _FS}},
    "iwr6843isk": {
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
                    "adc_full_scale_dbm": _FS}},
    "awr2944": {
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
                    "adc_full_scale_dbm": _FS}},
    "awr2243-cascade": {
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
                    "adc_full_scale_dbm": _FS}},
}
