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
where marked ``[re-check]`` (:data:`rtsgeom.link_config.RADAR_LINK_PRESETS` says what was tried).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.constants import c, k as K_BOLTZMANN

from .link_config import FE_ANTENNA_GAIN_DBI, RADAR_LINK_PRESETS
from .rts import KIND_DIRECT, KIND_SETUP, Echoes, RtsProgram
from .schema import SceneError

__all__ = ["RADAR_LINK_PRESETS", "RadarLink", "LinkError", "LinkBudget", "radar_link",
           "if_response", "apply_radar_link", "thermal_noise_w", "shaped_noise", "adc_convert",
           "channel_table", "check_channels", "channel_noise_w", "window_snr_loss",
           "link_budget", "dbm", "link_warnings", "relative_noise_power"]

class LinkError(SceneError):
    """A target the RTS cannot produce with its gains and dynamic range (names the field)."""


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
    from .geometry.patterns import ISOTROPIC, AntennaPatterns, scene_patterns
    n = len(scene.rts.front_ends)
    pats = scene_patterns(scene)
    out = {k: np.ones(n) for k in ("rut_tx", "rut_rx", "fe_rx", "fe_tx")}
    if pats.isotropic:
        return out
    if setup is None:
        from .geometry import build_setup
        setup = build_setup(scene)
    from .paths.exact import leg_pattern_gains
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
        raise LinkError(f"{src}: targets[{i}].rcs_dbsm = {rcs:g}: must be in [{lo:.1f}, "
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


# ------------------------------------------------------------------------------------------
# The budget
# ------------------------------------------------------------------------------------------


def window_snr_loss(name: str, n: int) -> float:
    """SNR factor of a taper on a coherent sum of n samples: ``(sum w)^2 / (n sum w^2)``."""
    from .radar.processing import window
    w = np.asarray(window(name, n), float)
    return float(w.sum() ** 2 / (n * np.sum(w ** 2)))


@dataclass(frozen=True)
class LinkBudget:
    """Link budget of a run (see :func:`link_budget`); ``to_dict`` is ``summary.json``'s."""

    modelled: bool
    noise_source: str
    noise_w: float  # per sample at the receiver input (thermal + RTS channels), before the IF
    quantisation_noise_w: float
    fft_gain_db: float
    radar: dict
    front_ends: list
    targets: list
    setup_echoes: list

    def to_dict(self) -> dict:
        """Plain JSON: a level that is not finite (no noise, no echo: -inf dBm) is None."""
        return _json_safe(self._raw_dict())

    def _raw_dict(self) -> dict:
        return {"modelled": self.modelled, "noise_source": self.noise_source,
                "noise_dbm_per_sample": float(dbm(self.noise_w)),
                "quantisation_noise_dbm": float(dbm(self.quantisation_noise_w)),
                "fft_gain_db": self.fft_gain_db, "radar": self.radar,
                "front_ends": self.front_ends, "targets": self.targets,
                "setup_echoes": self.setup_echoes}


def _json_safe(x):
    if isinstance(x, dict):
        return {k: _json_safe(v) for k, v in x.items()}
    if isinstance(x, list):
        return [_json_safe(v) for v in x]
    if isinstance(x, float) and not np.isfinite(x):
        return None
    return x


def _entry(p_in_w, h2, noise_w, nq, fs_w, gain_db) -> dict:
    """Levels of one echo: power at the ADC (referred to the receiver input, after the IF
    chain), SNR after the range and Doppler FFTs, margin to full scale."""
    p_adc = p_in_w * h2
    n = noise_w * h2 + nq
    with np.errstate(divide="ignore"):
        snr = 10 * np.log10(p_adc / n) + gain_db if n > 0 else float("inf")
    return {"adc_power_dbm": float(dbm(p_adc)), "if_response_db": float(10 * np.log10(h2)),
            "snr_after_fft_db": float(snr), "clip_margin_db": float(dbm(fs_w) - dbm(p_adc))}


def link_budget(scene, echoes: Echoes, program: RtsProgram, linked: bool,
                noise_override_w: float | None = None,
                estimated_setup: Echoes | None = None, predict: bool = False,
                setup=None) -> LinkBudget:
    """The budget per target (its direct echoes, summed coherently over its channels per
    virtual channel, power averaged over the virtual channels), per setup echo and per front
    end. ``echoes`` are the run's: already through :func:`apply_radar_link` when ``linked``
    (the scene has ``[radar.link]``), else relative ones that are taken through the preset's
    link here, so the budget is shown either way. ``noise_override_w``: ``snr_db``'s noise.
    ``estimated_setup``: relative setup echoes not in the signal (the sheet by
    :func:`sheet_paths` under ``--paths exact``), listed with ``"in_signal": false``.
    ``predict``: what a real RuT with these values would show (thermal noise and the ADC's
    quantisation even where the signal model has neither)."""
    radar = scene.radar
    link = radar_link(radar)
    raw = echoes
    e = echoes if linked else apply_radar_link(echoes, scene, link)
    f_b = beat_hz(raw, radar)
    # the IF response per echo (|H|^2 averaged over the virtual channels)
    h2 = np.mean(np.abs(if_response(link, f_b)) ** 2, axis=1) if len(raw) else np.zeros(0)
    with np.errstate(invalid="ignore", divide="ignore"):
        p_in = np.mean(np.abs(e.amplitude) ** 2, axis=1) / np.where(h2 > 0, h2, 1.0)
    n_th = thermal_noise_w(radar, link)
    n_ch = channel_noise_w(scene, program, link, setup) if len(program) else 0.0
    if noise_override_w is not None:
        noise, src = noise_override_w, ("snr_db override: fixed per-sample SNR of the strongest "
                                        "target echo (not the physical noise)")
    else:
        noise = n_th + n_ch
        src = "thermal k T0 F f_adc + RTS channel noise"
        if not linked:
            src += (" (prediction: the scene has no [radar.link])" if predict else
                    "; not in the signal (no [radar.link], no snr_db)")
    nq = link.quantisation_noise_w if linked or predict else 0.0  # no ADC in the relative model
    gain_db = float(10 * np.log10(radar.samples_per_chirp * radar.chirps_per_tx
                                  * window_snr_loss(radar.range_window, radar.samples_per_chirp)
                                  * window_snr_loss(radar.doppler_window, radar.chirps_per_tx)))
    targets = []
    for i, t in enumerate(scene.targets):
        sel = (raw.target == i) & (raw.kind == KIND_DIRECT)
        if not np.any(sel):
            targets.append({"index": i, "adc_power_dbm": None, "snr_after_fft_db": None,
                            "clip_margin_db": None})
            continue
        amp = e.amplitude[sel].sum(axis=0)
        hh = float(np.mean(h2[sel]))
        ent = _entry(float(np.mean(np.abs(amp) ** 2)) / hh, hh, noise, nq,
                     link.adc_full_scale_w, gain_db)
        targets.append({"index": i, "range_m": t.range_m, "rcs_dbsm": t.rcs_dbsm,
                        "beat_hz": float(np.mean(f_b[sel])), **ent})
    rows_setup = []
    for j in np.flatnonzero(raw.kind == KIND_SETUP):
        ent = _entry(float(p_in[j]), float(h2[j]), noise, nq, link.adc_full_scale_w, gain_db)
        rows_setup.append({"index": len(rows_setup), "range_m": float(np.mean(raw.tau_s[j]) * c / 2),
                      "beat_hz": float(np.mean(f_b[j])), "in_signal": True, **ent})
    if estimated_setup is not None and len(estimated_setup):
        est = apply_radar_link(estimated_setup, scene, link)
        fe_b = beat_hz(estimated_setup, radar)
        hh = np.mean(np.abs(if_response(link, fe_b)) ** 2, axis=1)
        for j in range(len(est)):
            p = float(np.mean(np.abs(est.amplitude[j]) ** 2)) / hh[j]
            ent = _entry(p, float(hh[j]), noise, nq, link.adc_full_scale_w, gain_db)
            rows_setup.append({"index": len(rows_setup), "range_m": float(np.mean(
                estimated_setup.tau_s[j]) * c / 2), "beat_hz": float(np.mean(fe_b[j])),
                "in_signal": False, "source": "sheet, physical-optics estimate", **ent})
    fes = []
    if len(scene.rts.front_ends):
        tab = channel_table(scene, program, link, setup)
        pg, (fe_rx_db, fe_tx_db) = tab["pattern_gains"], tab["fe_antenna_gain_dbi"]
        for q in range(len(scene.rts.front_ends)):
            rows = program.front_end == q
            fes.append({"index": q, "rut_chirp_at_adc_dbm": float(tab["input_dbm"][q]),
                        "adc_level_dbfs": float(tab["level_dbfs"][q]),
                        "max_attenuation_db": float(tab["max_attenuation_fe_db"][q]),
                        "attenuation_db": [float(a) for a in tab["attenuation_db"][rows]],
                        # each antenna's gain toward the other (scalar x pattern), dBi
                        "rut_tx_gain_dbi": float(10 * np.log10(link.tx_gain * pg["rut_tx"][q])),
                        "rut_rx_gain_dbi": float(10 * np.log10(link.rx_gain * pg["rut_rx"][q])),
                        "fe_rx_gain_dbi": float(fe_rx_db + 10 * np.log10(pg["fe_rx"][q])),
                        "fe_tx_gain_dbi": float(fe_tx_db + 10 * np.log10(pg["fe_tx"][q]))})
    rad = {"tx_power_dbm": float(dbm(link.tx_power_w)),
           "tx_antenna_gain_dbi": float(10 * np.log10(link.tx_gain)),
           "rx_antenna_gain_dbi": float(10 * np.log10(link.rx_gain)),
           "noise_figure_db": float(10 * np.log10(link.noise_figure)),
           "if_highpass_hz": link.if_highpass_hz, "if_lowpass_hz": link.if_lowpass_hz,
           "adc_bits": link.adc_bits, "adc_full_scale_dbm": float(dbm(link.adc_full_scale_w)),
           "thermal_noise_dbm_per_sample": float(dbm(n_th)),
           "rts_noise_dbm_per_sample": float(dbm(n_ch)), "sources": link.sources}
    return LinkBudget(linked, src, float(noise), nq, gain_db, rad, fes, targets, rows_setup)


def link_warnings(budget: LinkBudget, threshold_db: float) -> list[str]:
    """``run``'s warnings: an echo that clips the ADC, or one whose post-FFT SNR is below the
    CFAR threshold (below the noise for detection)."""
    out = []
    for kind, rows in (("target", budget.targets), ("setup echo", budget.setup_echoes)):
        for r in rows:
            if r.get("clip_margin_db") is None:
                continue
            if r["clip_margin_db"] < 0:
                out.append(f"link: {kind} {r['index']} clips the RuT's ADC by "
                           f"{-r['clip_margin_db']:.1f} dB ({r['adc_power_dbm']:.1f} dBm at "
                           f"full scale {budget.radar['adc_full_scale_dbm']:.1f} dBm)")
            if kind == "target" and r["snr_after_fft_db"] < threshold_db:
                out.append(f"link: target {r['index']} is {r['snr_after_fft_db']:.1f} dB above "
                           f"the noise after the FFTs, below the CFAR threshold "
                           f"{threshold_db:g} dB")
    return out


def sheet_paths(setup, step_m: float | None = None):
    """The sheet's specular echo per RuT Tx/Rx element pair as ``rut_to_rut`` path rows, by
    physical optics (:func:`rtsgeom.paths.crosscheck.po_sheet_response`, lambda/4 grid by
    default), for the budget when the exact paths carry no setup reflections. The delay is the
    path via the sheet point straight ahead of the pair's midpoint (the stationary point of a
    RuT near the arc centre); the gain is the PO response with that delay's phase removed."""
    from .paths.crosscheck import po_sheet_response
    from .paths.table import RUT_TO_RUT, Paths
    scene, rut = setup.scene, setup.rut
    if not scene.sheet.enabled:
        return None
    f = scene.radar.f_center_hz
    r0 = setup.fe.arc_radius_m + scene.sheet.radius_offset_m
    centre = np.asarray(setup.fe.arc_centre, float)
    step = step_m or c / f / 4
    rows = []
    for m in np.unique(rut.virtual_tx):
        for k in np.unique(rut.virtual_rx):
            a, b = rut.tx_world[m], rut.rx_world[k]
            mid = 0.5 * (a + b) - centre
            az = np.clip(np.arctan2(mid[0], mid[1]) if np.any(mid[:2]) else 0.0,
                         scene.sheet.angle_min_rad, scene.sheet.angle_max_rad)
            p = centre + r0 * np.array([np.sin(az), np.cos(az), 0.0])
            tau = (np.linalg.norm(a - p) + np.linalg.norm(b - p)) / c
            g = po_sheet_response(setup, a, b, f, step) * np.exp(2j * np.pi * f * tau)
            rows.append((m, k, tau, g))
    m, k, tau, g = (np.array(x) for x in zip(*rows))
    return Paths.build(front_end=np.full(m.size, -1), direction=np.full(m.size, RUT_TO_RUT),
                       rut_tx=m, rut_rx=k, delay_s=tau, gain=g, bounces=np.ones(m.size, int),
                       method="po")


def static_budget(setup) -> LinkBudget:
    """The budget without a run (``rtsgeom info``): each target on its nearest front end over
    the exact paths, the sheet by physical optics, thermal noise (``snr_db`` ignored)."""
    from .paths import exact_paths
    from .rts import build_echoes, program_nearest, setup_echoes
    scene = setup.scene
    program = program_nearest(scene, setup)
    echoes = build_echoes(setup, exact_paths(setup), program)
    est = None
    if scene.radar.link is not None:  # the sheet's physical-optics estimate costs ~1 s
        sp = sheet_paths(setup)
        est = setup_echoes(setup, sp) if sp is not None else None
    return link_budget(scene, echoes, program, False, None, est, predict=True, setup=setup)


def _f1(x) -> str:
    return "-" if x is None else f"{x:.1f}"


def format_budget(b: dict) -> list[str]:
    """Text lines of a budget dict (:meth:`LinkBudget.to_dict`) for ``rtsgeom info``."""
    r = b["radar"]
    lines = [f"link budget ({'modelled in the signal' if b['modelled'] else 'not modelled in the signal: no [radar.link]'}):",
             f"  RuT Tx {_f1(r['tx_power_dbm'])} dBm, antennas {_f1(r['tx_antenna_gain_dbi'])}/"
             f"{_f1(r['rx_antenna_gain_dbi'])} dBi, NF {_f1(r['noise_figure_db'])} dB, IF "
             f"HPF {r['if_highpass_hz'] / 1e3:.0f} kHz / LPF {r['if_lowpass_hz'] / 1e6:.2f} MHz, "
             f"ADC {r['adc_bits']} bit, full scale {_f1(r['adc_full_scale_dbm'])} dBm",
             f"  noise {_f1(b['noise_dbm_per_sample'])} dBm per sample ({b['noise_source']}), "
             f"quantisation {_f1(b['quantisation_noise_dbm'])} dBm, FFT gain "
             f"{_f1(b['fft_gain_db'])} dB"]
    for fe in b["front_ends"]:
        att = ", ".join(_f1(a) for a in fe["attenuation_db"]) or "-"
        lines.append(f"  front end {fe['index']}: RuT chirp at the back end's ADC "
                     f"{_f1(fe['rut_chirp_at_adc_dbm'])} dBm ({_f1(fe['adc_level_dbfs'])} dBFS), "
                     f"attenuation {att} dB of at most {_f1(fe['max_attenuation_db'])} dB; "
                     f"antennas toward each other: RuT {_f1(fe.get('rut_tx_gain_dbi'))}/"
                     f"{_f1(fe.get('rut_rx_gain_dbi'))} dBi, front end "
                     f"{_f1(fe.get('fe_rx_gain_dbi'))}/{_f1(fe.get('fe_tx_gain_dbi'))} dBi")
    for kind, rows in (("target", b["targets"]), ("setup echo", b["setup_echoes"])):
        for t in rows:
            if t.get("adc_power_dbm") is None:
                continue
            lines.append(f"  {kind} {t['index']} ({t['range_m']:.2f} m): {_f1(t['adc_power_dbm'])} "
                         f"dBm at the ADC (IF {_f1(t['if_response_db'])} dB), SNR after the FFTs "
                         f"{_f1(t['snr_after_fft_db'])} dB, clip margin {_f1(t['clip_margin_db'])} dB"
                         + ("  CLIPS" if (t["clip_margin_db"] or 0) < 0 else ""))
    return lines
