"""The physical link budget: powers, noise figures, IF filters and ADC limits (RuT and RTS).

Without ``[radar.link]`` the signal model works in relative amplitudes (transmit power 1,
isotropic antennas) and the noise comes from ``snr_db``. With it, every echo becomes a power at
the RuT's receiver input (antenna port, the reference plane of the noise figure)::

    P_r = P_t G_t G_r lambda^2 sigma / ((4 pi)^3 R^4)          (radar equation)

which the RTS realises (paper eq. 3, ``A = sqrt(sigma) / R^2`` up to the constants) through its
own chain: RuT Tx -> free space -> FE Rx antenna -> receive gain -> back-end ADC -> attenuation
-> DAC -> transmit gain -> FE Tx antenna -> free space -> RuT Rx. The program's amplitude
(``rts.target_amplitude / rts.nominal_link_gain``) is the field gain between the front end's
antenna ports with isotropic antennas; divided by the front-end antenna gains it is the
channel's electronic gain, which must lie between the back end's maximum (no attenuation) and
the attenuation at which the echo sinks into the DAC's quantisation floor
(:func:`channel_table`; :func:`check_channels` raises :class:`LinkError` naming the target).

The RuT's IF chain acts on each echo at its beat frequency ``f_b = S tau + f_D``: a first-order
high-pass (the AWR devices' HPF1) times a Butterworth low-pass (anti-alias), magnitude and
phase (:func:`if_response`). Thermal noise ``k T0 F f_adc`` per complex sample (plus the RTS
channels' own output noise, re-radiated to the RuT, :func:`channel_noise_w`) is added before the
IF chain, so it is shaped by the same response (:func:`shaped_noise`); the ADC then clips each
rail at full scale and quantises (:func:`adc_convert`).

Values of the presets are datasheet values where a source (document and section) is named,
assumptions where marked ``[assumed]``, and values not yet verified against the datasheet's text
where marked ``[re-check]`` (:data:`rtsgeom.scene.link.RADAR_LINK_PRESETS` says what was tried).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.constants import c, k as K_BOLTZMANN

from ..scene.link import FE_ANTENNA_GAIN_DBI, RADAR_LINK_PRESETS
from ..rts.channels import Echoes, RtsProgram
from ..errors import LinkError
from ..geometry import build_setup
from ..geometry.patterns import AntennaPatterns, ISOTROPIC, scene_patterns
from ..paths.exact import leg_pattern_gains

__all__ = ["RADAR_LINK_PRESETS", "RadarLink", "LinkError", "radar_link", "if_response",
           "apply_radar_link", "thermal_noise_w", "shaped_noise", "adc_convert", "channel_table",
           "check_channels", "channel_noise_w", "dbm", "relative_noise_power", "pattern_gains",
           "fe_gain_db", "beat_hz"]

def dbm(p_w) -> np.ndarray:
    """Power in dBm of a power in watts (-inf for 0)."""
    with np.errstate(divide="ignore"):
        return 10.0 * np.log10(np.asarray(p_w, float)) + 30.0


def _w(p_dbm: float) -> float:
    return 10.0 ** ((p_dbm - 30.0) / 10.0)


@dataclass(frozen=True)
class RadarLink:
    """The RuT's resolved link values (SI, linear powers), the scene's over the preset's."""

    tx_power_w: float
    tx_gain: float  # power gain, peak
    rx_gain: float
    noise_figure: float  # linear
    if_highpass_hz: float
    if_lowpass_hz: float
    if_lowpass_order: int
    adc_bits: int
    adc_full_scale_w: float
    temperature_k: float
    sources: dict = field(default_factory=dict, compare=False)

    @property
    def rail(self) -> float:
        """Clip level of each of the I and Q rails (sqrt W): a full-scale tone's amplitude."""
        return float(np.sqrt(self.adc_full_scale_w))

    @property
    def lsb(self) -> float:
        return 2.0 * self.rail / 2 ** self.adc_bits

    @property
    def quantisation_noise_w(self) -> float:
        """Uniform quantisation noise per complex sample: ``2 LSB^2 / 12`` (both rails)."""
        return 2.0 * self.lsb ** 2 / 12.0


def radar_link(radar) -> RadarLink:
    """The RuT's link from ``radar.link`` (unset values: the antenna preset's, with sources)."""
    preset = RADAR_LINK_PRESETS[radar.antenna_preset]
    cfg = radar.link
    v = dict(preset["values"])
    src = dict(preset["sources"])
    if _has_pattern(radar):  # the paths carry the pattern's gain toward each front end
        for name in ("tx_antenna_gain_dbi", "rx_antenna_gain_dbi"):
            v[name], src[name] = 0.0, ("[radar.pattern]: its gain toward each front end (in the "
                                       "paths, its dB read as dBi) is the antenna's; 0 dBi on top")
    if cfg is not None:
        for name in v:
            x = getattr(cfg, name)
            if x is not None:
                v[name], src[name] = x, "scene ([radar.link])"
    return RadarLink(
        tx_power_w=_w(v["tx_power_dbm"]), tx_gain=10 ** (v["tx_antenna_gain_dbi"] / 10),
        rx_gain=10 ** (v["rx_antenna_gain_dbi"] / 10), noise_figure=10 ** (v["noise_figure_db"] / 10),
        if_highpass_hz=float(v["if_highpass_hz"]), if_lowpass_hz=float(v["if_lowpass_hz"]),
        if_lowpass_order=int(v["if_lowpass_order"]), adc_bits=int(v["adc_bits"]),
        adc_full_scale_w=_w(v["adc_full_scale_dbm"]),
        temperature_k=cfg.temperature_k if cfg is not None else 290.0, sources=src)


def _has_pattern(section) -> bool:
    """A ``[radar.pattern]`` / ``[rts.pattern]`` other than isotropic."""
    p = getattr(section, "pattern", None)
    return p is not None and p.kind != "isotropic"


def fe_gain_db(scene) -> tuple[float, float]:
    """The front ends' scalar antenna gains (Rx, Tx) in dBi, on top of ``[rts.pattern]`` (which
    the paths carry): the scene's ``[rts.link]`` values, else 10 dBi, or 0 dBi with a pattern
    (the pattern's gain toward the RuT is then the antenna's)."""
    rl = scene.rts.link
    dflt = 0.0 if _has_pattern(scene.rts) else FE_ANTENNA_GAIN_DBI
    return (dflt if rl.fe_rx_antenna_gain_dbi is None else float(rl.fe_rx_antenna_gain_dbi),
            dflt if rl.fe_tx_antenna_gain_dbi is None else float(rl.fe_tx_antenna_gain_dbi))


def pattern_gains(scene, setup=None) -> dict:
    """Per front end (F,): the patterns' power gains ``|f|^2`` that the exact paths carry (the
    same :func:`rtsgeom.paths.exact.leg_pattern_gains`), each antenna toward the other, averaged
    over the RuT's elements: ``rut_tx``/``rut_rx`` (the RuT's pattern toward front end q),
    ``fe_rx``/``fe_tx`` (front end q's pattern toward the RuT). Ones where isotropic (no setup
    is built then); ``setup`` defaults to ``build_setup(scene)``."""
    n = len(scene.rts.front_ends)
    pats = scene_patterns(scene)
    out = {k: np.ones(n) for k in ("rut_tx", "rut_rx", "fe_rx", "fe_tx")}
    if pats.isotropic:
        return out
    if setup is None:
        setup = build_setup(scene)
    rut_only = AntennaPatterns(rut_tx=pats.rut_tx, rut_rx=pats.rut_rx)
    fe_only = AntennaPatterns(fe_rx=pats.fe_rx, fe_tx=pats.fe_tx, rut_tx=ISOTROPIC,
                              rut_rx=ISOTROPIC)
    for (tx_key, rx_key), p in ((("rut_tx", "rut_rx"), rut_only), (("fe_rx", "fe_tx"), fe_only)):
        g_tx, g_rx = leg_pattern_gains(setup, p)
        out[tx_key] = np.mean(np.abs(g_tx) ** 2, axis=1)
        out[rx_key] = np.mean(np.abs(g_rx) ** 2, axis=1)
    return out


def if_response(link: RadarLink, f_hz) -> np.ndarray:
    """Complex response of the IF chain at beat frequencies ``f_hz`` (any shape; negative
    frequencies give the conjugate, as for a real filter): ``H_hp(f) H_lp(f)`` with
    ``H_hp = j f/f_h / (1 + j f/f_h)`` and ``H_lp`` an analog Butterworth of order n:
    ``prod_k (-p_k) / (j f/f_l - p_k)`` with the poles ``p_k = exp(j pi (2k + n - 1) / 2n)``,
    k = 1..n (unit DC gain; the same filter as ``scipy.signal.butter(n, 2 pi f_l, analog=True)``,
    tested against it -- written out so that ``rtsgeom info`` need not import scipy.signal,
    0.4 s)."""
    f = np.asarray(f_hz, float)
    h = np.ones(f.shape, complex)
    if link.if_highpass_hz > 0:
        x = 1j * f / link.if_highpass_hz
        h = h * x / (1.0 + x)
    n = int(link.if_lowpass_order)
    poles = np.exp(1j * np.pi * (2 * np.arange(1, n + 1) + n - 1) / (2 * n))
    s = (1j * f / link.if_lowpass_hz)[..., None]
    return h * np.prod(-poles / (s - poles), axis=-1)


def beat_hz(echoes: Echoes, radar) -> np.ndarray:
    """Beat frequency of each echo on each virtual channel, (E, V): ``S tau + f_D``."""
    return radar.slope_hz_per_s * echoes.tau_s + echoes.doppler_hz[:, None]


def apply_radar_link(echoes: Echoes, scene, link: RadarLink | None = None) -> Echoes:
    """Echoes as amplitudes (sqrt W) after the RuT's IF chain, referred to the receiver input:
    times ``sqrt(P_t G_t G_r)`` and the IF response at each echo's beat frequency. Absorbers
    (``sheet.reflection_loss_db``, ``[[structure]] reflection_loss_db``) are already in the
    path gains, per bounce off the surface that carries them (the ray tracer, the sheet's
    physical-optics echo)."""
    link = link or radar_link(scene.radar)
    if len(echoes) == 0:
        return echoes
    g = np.sqrt(link.tx_power_w * link.tx_gain * link.rx_gain)
    return echoes.scaled(g * if_response(link, beat_hz(echoes, scene.radar)))


def thermal_noise_w(radar, link: RadarLink | None = None) -> float:
    """Receiver noise per complex sample at the receiver input: ``k T0 F f_adc``."""
    link = link or radar_link(radar)
    return float(K_BOLTZMANN * link.temperature_k * link.noise_figure * radar.adc_rate_hz)


def relative_noise_power(scene, amp_power, beat_hz) -> np.ndarray:
    """The link's noise per complex sample in the signal model's *relative* units (transmit
    power 1, isotropic RuT, before the IF chain): what ``snr_db`` would otherwise set, for the
    models that work in those units (the calibration's phasor sweep).

    An echo of relative amplitude ``a`` reaches the ADC as ``a sqrt(P_t G_t G_r) H(f_b)``; the
    noise there is ``(N_th + N_ch) |H(f_b)|^2 + N_q`` (thermal and RTS channel noise shaped by
    the IF chain, quantisation after it). Referred back::

        N_rel = (N_th + N_ch) / (P_t G_t G_r) + N_q / (P_t G_t G_r |H(f_b)|^2)

    ``amp_power``: the sum of the programmed RTS rows' squared amplitudes (any shape; the
    channels' re-radiated noise :func:`channel_noise_w` is linear in it); ``beat_hz``: the
    echo's beat frequency (broadcast against ``amp_power``)."""
    link = radar_link(scene.radar)
    g = link.tx_power_w * link.tx_gain * link.rx_gain
    unit = RtsProgram.build([0], [0], [0.0], [0.0], [1.0])
    n_ch = channel_noise_w(scene, unit, link) * np.asarray(amp_power, float)  # front end 0's patterns
    h2 = np.abs(if_response(link, beat_hz)) ** 2
    with np.errstate(divide="ignore"):
        return (thermal_noise_w(scene.radar, link) + n_ch) / g + link.quantisation_noise_w / (g * h2)


def shaped_noise(shape, power_w: float, link: RadarLink, radar, rng: np.random.Generator
                 ) -> np.ndarray:
    """White complex Gaussian noise of ``power_w`` per sample at the receiver input, passed
    through the IF chain along fast time (``H`` at the bin frequencies ``k f_adc / N`` in
    [0, f_adc), where the beats lie), complex64. Deterministic for a seed (numpy's FFT)."""
    n = rng.standard_normal(tuple(shape) + (2,), dtype=np.float32)
    n *= np.float32(np.sqrt(power_w / 2))
    x = n.view(np.complex64)[..., 0]
    f = np.arange(shape[-1]) * radar.adc_rate_hz / shape[-1]
    return np.fft.ifft(np.fft.fft(x, axis=-1) * if_response(link, f), axis=-1).astype(np.complex64)


def adc_convert(data: np.ndarray, link: RadarLink) -> tuple[np.ndarray, int]:
    """The ADC: each rail clipped at full scale and rounded to the LSB (mid-tread).
    Returns the converted samples (complex64) and the number of clipped samples."""
    a, q = np.float32(link.rail), np.float32(link.lsb)
    re, im = data.real, data.imag
    clipped = int(np.count_nonzero((np.abs(re) > a) | (np.abs(im) > a)))
    re = np.round(np.clip(re, -a, a) / q) * q
    im = np.round(np.clip(im, -a, a) / q) * q
    return (re + 1j * im).astype(np.complex64), clipped


# ------------------------------------------------------------------------------------------
# The RTS channel
# ------------------------------------------------------------------------------------------


def channel_table(scene, program: RtsProgram, link: RadarLink | None = None,
                  setup=None) -> dict:
    """Per front end and per program row: the RTS channel's levels and the attenuation
    realising eq. (3).

    ``input_dbm`` (F,): the RuT's chirp at each back end's ADC (RuT Tx EIRP toward front end q
    over the nominal arc radius, FE Rx antenna toward the RuT, receive gain; the antennas' gains
    are the scalars times the patterns' :func:`pattern_gains`); ``level_dbfs`` (F,) that over
    the ADC's full scale; per row ``electronic_gain_db``: the programmed field gain without the
    FE antennas' scalar gains (their patterns are in the paths, so not in the program);
    ``attenuation_db``: what the back end applies, ``rx + tx gain + DAC FS - ADC FS -
    electronic gain``; ``max_attenuation_db`` (per row; ``max_attenuation_fe_db`` per front
    end): down to the DAC's quantisation floor (``6.02 bits + 1.76`` dB below full scale) from
    the level the ADC delivers, counted in the RuT's IF bandwidth (the DAC's noise spreads over
    ``f_s / 2``, the RuT samples ``f_adc`` of it: ``+ 10 log10(f_s / (2 f_adc))``). Feasible
    when ``0 <= attenuation_db <= max_attenuation_db``.
    """
    link = link or radar_link(scene.radar)
    rl = scene.rts.link
    fe_rx_db, fe_tx_db = fe_gain_db(scene)
    pg = pattern_gains(scene, setup)
    lam = c / scene.radar.f_center_hz
    path_db = 20 * np.log10(lam / (4 * np.pi * scene.rts.arc_radius_m))
    eirp_dbm = dbm(link.tx_power_w * link.tx_gain * pg["rut_tx"])  # (F,) toward each FE
    input_dbm = eirp_dbm + path_db + fe_rx_db + 10 * np.log10(pg["fe_rx"]) + rl.rx_gain_db
    level_dbfs = input_dbm - rl.adc_full_scale_dbm
    with np.errstate(divide="ignore"):
        amp_db = 20 * np.log10(np.abs(program.amplitude))
    elec = amp_db - fe_rx_db - fe_tx_db
    max_gain = rl.rx_gain_db + rl.tx_gain_db + rl.dac_full_scale_dbm - rl.adc_full_scale_dbm
    # the echo must stay above the DAC's quantisation noise inside the RuT's IF bandwidth: the
    # noise (6.02 b + 1.76 dB below full scale) spreads over f_s/2; the RuT sees f_adc of it
    dr = (6.02 * rl.dac_bits + 1.76
          + 10 * np.log10(scene.rts.f_s_hz / (2 * scene.radar.adc_rate_hz)))
    mx_fe = dr + np.minimum(level_dbfs, 0.0)
    return {"input_dbm": input_dbm, "level_dbfs": level_dbfs, "electronic_gain_db": elec,
            "attenuation_db": max_gain - elec,
            "max_attenuation_db": mx_fe[np.asarray(program.front_end, int)],
            "max_attenuation_fe_db": mx_fe, "max_gain_db": max_gain,
            "fe_antenna_gain_dbi": (fe_rx_db, fe_tx_db), "pattern_gains": pg}


def check_channels(scene, program: RtsProgram, link: RadarLink | None = None,
                   setup=None) -> dict:
    """:func:`channel_table`, raising :class:`LinkError` where the back end clips on the RuT's
    chirp or a target's RCS at its range is beyond the channel's gain range."""
    t = channel_table(scene, program, link, setup)
    src = scene.source or "<scene>"
    if np.any(t["level_dbfs"] > 0):
        q = int(np.argmax(t["level_dbfs"]))
        raise LinkError(f"{src}: rts.link.rx_gain_db = {scene.rts.link.rx_gain_db:g}: must be "
                        f"<= {scene.rts.link.rx_gain_db - t['level_dbfs'][q]:.1f} dB: the RuT's "
                        f"chirp reaches front end {q}'s back-end ADC at {t['input_dbm'][q]:.1f} "
                        f"dBm, above its full scale rts.link.adc_full_scale_dbm")
    att, mx = t["attenuation_db"], t["max_attenuation_db"]
    # too little attenuation on any row: the RCS is too large; too much on a target's
    # strongest row: too small (a weak AoA-weight row below the DAC floor is only imprecise)
    strongest = np.zeros(len(att), bool)
    for i in np.unique(program.target):
        rows = np.flatnonzero(program.target == i)
        strongest[rows[np.argmin(att[rows])]] = True
    for row in np.flatnonzero(np.isfinite(att) & ((att < 0) | ((att > mx) & strongest))):
        i = int(program.target[row])
        tg = scene.targets[i] if i < len(scene.targets) else None
        rcs = tg.rcs_dbsm if tg is not None else float("nan")
        lo, hi = rcs - (mx[row] - att[row]), rcs + att[row]  # amplitude ~ sqrt(sigma): dB for dB
        rng = tg.range_m if tg is not None else float("nan")
        from ..scene.objects import target_field, target_labels
        name = (target_field(target_labels(scene)[i], "rcs_dbsm") if tg is not None
                else f"targets[{i}].rcs_dbsm")
        raise LinkError(f"{src}: {name} = {rcs:g}: must be in [{lo:.1f}, "
                        f"{hi:.1f}] dBsm at range_m = {rng:g} on RTS channel "
                        f"{int(program.front_end[row])} (attenuation {att[row]:.1f} dB needed; "
                        f"the back end offers [0, {mx[row]:.1f}] dB with rts.link gains, full scales "
                        f"and dac_bits)")
    return t


def channel_noise_w(scene, program: RtsProgram, link: RadarLink | None = None,
                    setup=None) -> float:
    """Output noise of the programmed RTS channels at the RuT's receiver input, per sample:
    ``k T0 F_ch f_adc`` at the FE Rx port, times each row's electronic gain squared, the FE Tx
    antenna, the nominal FE -> RuT path and the RuT's Rx antenna (scalars times the patterns'
    :func:`pattern_gains` of the row's front end). Rows are independent noise (different
    delays), so powers add."""
    link = link or radar_link(scene.radar)
    if len(program) == 0:
        return 0.0
    rl = scene.rts.link
    fe_rx_db, _ = fe_gain_db(scene)
    pg = pattern_gains(scene, setup)
    lam = c / scene.radar.f_center_hz
    leg = (lam / (4 * np.pi * scene.rts.arc_radius_m)) ** 2
    n_in = K_BOLTZMANN * link.temperature_k * 10 ** (rl.noise_figure_db / 10) * scene.radar.adc_rate_hz
    # |electronic gain|^2 x FE Tx scalar = |programmed amplitude|^2 / FE Rx scalar
    q = np.asarray(program.front_end, int)
    g2 = (np.abs(program.amplitude) ** 2 / 10 ** (fe_rx_db / 10)
          * pg["fe_tx"][q] * pg["rut_rx"][q])
    return float(n_in * np.sum(g2) * leg * link.rx_gain)

