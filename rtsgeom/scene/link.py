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

from .presets import PRESETS
from .evolve import Evolvable
from .schema import Derived, spec

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


#: Each antenna preset's link values and where each comes from: the ``link`` of its entry in
#: :data:`rtsgeom.scene.presets.PRESETS` (one entry per radar: its array and its link together;
#: rtsgeom.radar.link.radar_link fills the unset [radar.link] fields from them).
RADAR_LINK_PRESETS: dict[str, dict] = {name: p.link for name, p in PRESETS.items()}

