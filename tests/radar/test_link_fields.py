"""Each ``[radar.link]`` and ``[rts.link]`` field, varied, moves the physics it should, by the
closed form (docs/testing.md's field table).

``[radar.link]``: transmit power and antenna gains move a target's power at the ADC dB for dB
(SNR and clip margin with it); noise figure and temperature set the simulated noise floor
``k T F f_adc |H|^2``; the IF corners and order shape an echo and the noise by ``|H(f)|^2``; the
ADC's bits set the quantisation floor ``FS - 6.02 b - 1.76 dB`` and its full scale the clip
margin (and the onset of clipping in the simulated samples). ``[rts.link]``: the gains and full
scales move the attenuation realising eq. (3) dB for dB, the DAC's bits its range by 6.02 dB a
bit, the channel's noise figure the noise it re-radiates.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import make_scene
from scipy.constants import c
from scipy.constants import k as K_B

from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.radar import budget
from rtsgeom.radar import link as lk
from rtsgeom.radar.fmcw import synthesize
from rtsgeom.radar.frame import simulate
from rtsgeom.rts.channels import build_echoes, program_nearest, setup_echoes

from .test_link import _setup_paths, _tone, linked_doc

TARGET = [{"range_m": 20.0, "rcs_dbsm": 10.0, "angle_deg": 0.0}]


def _scene(link=None, rts_link=None, targets=TARGET):
    def mut(d):
        linked_doc(d, link=link)
        d["targets"] = list(targets)  # linked_doc takes [] for its default target
        if rts_link:
            d["rts"]["link"] = dict(rts_link)
    return make_scene(mut)


def _target_budget(scene):
    """The run's chain for ``scene``: (budget, noise-free cube, echoes, setup)."""
    setup = build_setup(scene)
    program = program_nearest(scene, setup)
    rl = lk.radar_link(scene.radar)
    echoes = lk.apply_radar_link(build_echoes(setup, exact_paths(setup), program), scene, rl)
    b = budget.link_budget(scene, echoes, program, linked=True)
    return b, synthesize(echoes, scene.radar, setup.rut).data, echoes, setup


def _db(x):
    return 10 * np.log10(x)


@pytest.mark.parametrize("field", ["tx_power_dbm", "tx_antenna_gain_dbi", "rx_antenna_gain_dbi"])
@pytest.mark.parametrize("delta_db", [3.0, -7.5])
def test_power_and_antenna_gains_move_the_adc_power_db_for_db(field, delta_db):
    """P_r = P_t G_t G_r lambda^2 sigma / ((4 pi)^3 R^4): +d dB on any of the three is +d dB of
    the target's power at the ADC (budget and simulated samples), -d dB of clip margin, and
    +d dB of SNR where the noise does not move with it (Tx power, Tx gain)."""
    base_val = lk.RADAR_LINK_PRESETS["awr1843boost"]["values"][field]
    b0, x0, e0, _ = _target_budget(_scene())
    b1, x1, e1, _ = _target_budget(_scene({field: base_val + delta_db}))
    t0, t1 = b0.targets[0], b1.targets[0]
    assert t1["adc_power_dbm"] - t0["adc_power_dbm"] == pytest.approx(delta_db, abs=1e-9)
    assert t1["clip_margin_db"] - t0["clip_margin_db"] == pytest.approx(-delta_db, abs=1e-9)
    f_b = float(np.mean(lk.beat_hz(e0, _scene().radar)[0]))
    radar = _scene().radar
    measured = _db(np.mean(np.abs(_tone(x1, f_b, radar)) ** 2)
                   / np.mean(np.abs(_tone(x0, f_b, radar)) ** 2))
    assert measured == pytest.approx(delta_db, abs=1e-6)
    d_snr = t1["snr_after_fft_db"] - t0["snr_after_fft_db"]
    if field == "rx_antenna_gain_dbi":
        # the RTS channels' re-radiated noise comes in through the same Rx antenna
        assert 0.0 < d_snr / delta_db < 1.0
    else:
        assert d_snr == pytest.approx(delta_db, abs=1e-9)


def _noise_only(link, seed=3):
    """A run's ADC cube without targets (no RTS channel noise): thermal noise + ADC only."""
    scene = _scene(link, targets=[])
    setup = build_setup(scene)
    program = program_nearest(scene, setup)
    _, cube = simulate(setup, exact_paths(setup), program, seed=seed)
    return scene, cube.data


@pytest.mark.parametrize("nf_db,t_k", [(6.0, 290.0), (12.0, 290.0), (15.0, 290.0),
                                       (12.0, 77.0)])
def test_noise_figure_and_temperature_set_the_noise_floor(nf_db, t_k):
    """The simulated noise per complex sample is k T F f_adc mean_k |H(f_k)|^2 (the IF response
    over the FFT bins) within 2 %: +3 dB of noise figure is +3 dB of noise floor, -3 dB of SNR
    for a thermal-limited echo (24-bit ADC: quantisation negligible)."""
    link = {"noise_figure_db": nf_db, "temperature_k": t_k, "adc_bits": 24}
    scene, x = _noise_only(link)
    radar = scene.radar
    rl = lk.radar_link(radar)
    f = np.arange(radar.samples_per_chirp) * radar.adc_rate_hz / radar.samples_per_chirp
    expect = K_B * t_k * 10 ** (nf_db / 10) * radar.adc_rate_hz * np.mean(
        np.abs(lk.if_response(rl, f)) ** 2)
    assert np.mean(np.abs(x) ** 2) == pytest.approx(expect, rel=0.02)
    b = budget.link_budget(scene, setup_echoes(build_setup(scene), _setup_paths(
        build_setup(scene), 2 * 5.0 / c, 1e-4)), program_nearest(scene, build_setup(scene)),
        linked=True)
    assert b.radar["thermal_noise_dbm_per_sample"] == pytest.approx(
        float(lk.dbm(K_B * t_k * 10 ** (nf_db / 10) * radar.adc_rate_hz)), abs=1e-9)
    # the SNR of a thermal-limited echo falls dB for dB with the noise figure
    b3 = budget.link_budget(_scene(dict(link, noise_figure_db=nf_db + 3.0), targets=[]),
                        *_setup_args(scene), linked=True)
    d = b3.setup_echoes[0]["snr_after_fft_db"] - b.setup_echoes[0]["snr_after_fft_db"]
    assert d == pytest.approx(-3.0, abs=1e-3)  # the 24-bit quantisation floor: 5e-5 dB


def _setup_args(scene):
    setup = build_setup(scene)
    return (setup_echoes(setup, _setup_paths(setup, 2 * 5.0 / c, 1e-4)),
            program_nearest(scene, setup))


@pytest.mark.parametrize("hpf_hz,lpf_hz,order", [(1e6, 4e6, 4), (300e3, 2e6, 2), (0.0, 5e6, 6),
                                                 (700e3, 3e6, 1)])
def test_if_corners_and_order_shape_the_noise_spectrum(hpf_hz, lpf_hz, order):
    """The simulated noise's mean periodogram per fast-time bin follows k T F f_adc |H(f_k)|^2
    (first-order HPF x Butterworth LPF of the given order) within 15 % per bin (averaged over
    chirps, channels and 8 frames)."""
    link = {"if_highpass_hz": hpf_hz, "if_lowpass_hz": lpf_hz, "if_lowpass_order": order,
            "adc_bits": 24}
    spectra = []
    for seed in range(8):
        scene, x = _noise_only(link, seed)
        spectra.append(np.mean(np.abs(np.fft.fft(x, axis=-1)) ** 2, axis=(0, 1)))
    radar = scene.radar
    n = radar.samples_per_chirp
    psd = np.mean(spectra, axis=0) / n  # per-sample power per bin
    rl = lk.radar_link(radar)
    f = np.arange(n) * radar.adc_rate_hz / n
    expect = lk.thermal_noise_w(radar, rl) * np.abs(lk.if_response(rl, f)) ** 2
    ok = expect > 1e-3 * expect.max()  # leave out the deep stop band (float32 round-off)
    np.testing.assert_allclose(psd[ok], expect[ok], rtol=0.15)
    if hpf_hz > 0:  # the bins below the corner really are attenuated
        low = (f > 0) & (f < 0.3 * hpf_hz)
        if np.any(low):
            assert np.all(psd[low] < 0.2 * expect.max())


@pytest.mark.parametrize("ratio", [0.5, 1.0, 2.0])
@pytest.mark.parametrize("order", [2, 4])
def test_if_lowpass_attenuates_an_echo_by_its_response(ratio, order):
    """A setup echo at beat f_b, low-pass corner f_b / ratio: its power at the ADC is
    1 / (1 + ratio^(2 n)) of the unfiltered one (Butterworth), budget and samples."""
    dist = 10.0
    tau = 2 * dist / c
    radar = _scene(targets=[]).radar
    f_b = radar.slope_hz_per_s * tau
    out = {}
    for name, lpf in (("ref", 1e10), ("lpf", f_b / ratio)):
        scene = _scene({"if_lowpass_hz": lpf, "if_lowpass_order": order, "if_highpass_hz": 0.0},
                       targets=[])
        setup = build_setup(scene)
        raw = setup_echoes(setup, _setup_paths(setup, tau, 1e-4))
        e = lk.apply_radar_link(raw, scene)
        x = synthesize(e, scene.radar, setup.rut).data
        b = budget.link_budget(scene, raw, program_nearest(scene, setup), linked=False)
        out[name] = (np.mean(np.abs(_tone(x, f_b, scene.radar)) ** 2),
                     b.setup_echoes[0]["adc_power_dbm"])
    expect = 1.0 / (1.0 + ratio ** (2 * order))
    assert out["lpf"][0] / out["ref"][0] == pytest.approx(expect, rel=1e-6)
    assert out["lpf"][1] - out["ref"][1] == pytest.approx(_db(expect), abs=1e-6)


@pytest.mark.parametrize("bits", [6, 8, 10, 12, 14])
@pytest.mark.parametrize("fs_dbm", [-40.0, -25.0, -10.0])
def test_adc_bits_set_the_quantisation_floor(bits, fs_dbm):
    """Quantisation noise per complex sample = FS - 6.02 b - 1.76 dB (both rails uniform): the
    budget's value, and the error power of the ADC on a busy signal (Gaussian at -12 dBFS)
    within 3 %."""
    scene = _scene({"adc_bits": bits, "adc_full_scale_dbm": fs_dbm})
    rl = lk.radar_link(scene.radar)
    closed = fs_dbm - 6.0206 * bits - 1.7609
    assert float(lk.dbm(rl.quantisation_noise_w)) == pytest.approx(closed, abs=1e-3)
    b, *_ = _target_budget(scene)
    assert b.to_dict()["quantisation_noise_dbm"] == pytest.approx(closed, abs=1e-3)
    rng = np.random.default_rng(bits)
    p = 10 ** ((fs_dbm - 12.0 - 30) / 10)
    x = (rng.standard_normal(200_000) + 1j * rng.standard_normal(200_000)) * np.sqrt(p / 2)
    y, clipped = lk.adc_convert(x.astype(np.complex64), rl)
    err = np.mean(np.abs(y.astype(complex) - x.astype(np.complex64)) ** 2)
    assert clipped < 100  # 4.0 sigma per rail
    assert _db(err) + 30 == pytest.approx(closed, abs=0.13)


@pytest.mark.parametrize("fs_dbm", [-40.0, -25.0, -10.0])
@pytest.mark.parametrize("margin_db", [-0.5, 0.5, 6.0])
def test_adc_full_scale_sets_the_clip_margin(fs_dbm, margin_db):
    """A setup echo whose power at the ADC is FS - margin: the budget's clip margin is the
    margin, and the simulated ADC clips samples exactly when it is negative (a complex tone
    of power P reaches sqrt(P) on each rail, the rail's clip level is sqrt(FS))."""
    tau = 2 * 3.0 / c
    scene = _scene({"adc_full_scale_dbm": fs_dbm, "if_highpass_hz": 0.0}, targets=[])
    setup = build_setup(scene)
    rl = lk.radar_link(scene.radar)
    h2 = abs(lk.if_response(rl, scene.radar.slope_hz_per_s * tau)) ** 2
    p_adc = 10 ** ((fs_dbm - margin_db - 30) / 10)
    g = np.sqrt(p_adc / (rl.tx_power_w * rl.tx_gain * rl.rx_gain * h2))
    raw = setup_echoes(setup, _setup_paths(setup, tau, g))
    b = budget.link_budget(scene, raw, program_nearest(scene, setup), linked=False)
    assert b.setup_echoes[0]["clip_margin_db"] == pytest.approx(margin_db, abs=1e-6)
    _, n = lk.adc_convert(synthesize(lk.apply_radar_link(raw, scene, rl), scene.radar,
                                     setup.rut).data, rl)
    assert (n > 0) == (margin_db < 0)


# ------------------------------------------------------------------------------------------
# [rts.link]
# ------------------------------------------------------------------------------------------

RTS_DEFAULTS = {"fe_rx_antenna_gain_dbi": 10.0, "fe_tx_antenna_gain_dbi": 10.0,
                "rx_gain_db": 30.0, "tx_gain_db": 20.0, "noise_figure_db": 12.0,
                "adc_full_scale_dbm": 1.0, "dac_full_scale_dbm": 0.0, "dac_bits": 14}
# d(attenuation)/d(field) of channel_table: rx + tx gain + DAC FS - ADC FS - (A - G_fe,rx - G_fe,tx)
ATTENUATION_SLOPE = {"fe_rx_antenna_gain_dbi": 1, "fe_tx_antenna_gain_dbi": 1, "rx_gain_db": 1,
                     "tx_gain_db": 1, "adc_full_scale_dbm": -1, "dac_full_scale_dbm": 1,
                     "noise_figure_db": 0, "dac_bits": 0}


def _channels(rts_link, targets=TARGET):
    scene = _scene(rts_link=rts_link, targets=targets)
    setup = build_setup(scene)
    program = program_nearest(scene, setup)
    return scene, program, lk.channel_table(scene, program), lk.channel_noise_w(scene, program)


@pytest.mark.parametrize("field", sorted(RTS_DEFAULTS))
@pytest.mark.parametrize("delta", [2, -3])
def test_rts_link_fields_move_the_channel_budget(field, delta):
    """Per [rts.link] field: the attenuation realising the target moves by its closed-form
    slope (gains and full scales dB for dB); the back end's input level by the FE Rx gain,
    receive gain and -ADC full scale; the attenuation range by 6.02 dB per DAC bit (and by
    the input level when that clips); the re-radiated channel noise by the noise figure and
    -FE Rx gain (the noise enters behind the Rx antenna) dB for dB. The programmed amplitude,
    what the RuT receives, does not move."""
    s0, p0, t0, n0 = _channels({})
    s1, p1, t1, n1 = _channels({field: RTS_DEFAULTS[field] + delta})
    np.testing.assert_allclose(p1.amplitude, p0.amplitude, rtol=0, atol=0)
    d_att = t1["attenuation_db"] - t0["attenuation_db"]
    np.testing.assert_allclose(d_att, ATTENUATION_SLOPE[field] * delta, atol=1e-9)
    in_slope = {"fe_rx_antenna_gain_dbi": 1, "rx_gain_db": 1, "adc_full_scale_dbm": -1}
    d_lvl = t1["level_dbfs"] - t0["level_dbfs"]  # (F,)
    np.testing.assert_allclose(d_lvl, in_slope.get(field, 0) * delta, atol=1e-9)
    dr = 6.02 * delta if field == "dac_bits" else 0.0  # channel_table's 6.02 b + 1.76 dB
    d_max = t1["max_attenuation_fe_db"] - t0["max_attenuation_fe_db"]
    clip = np.minimum(t1["level_dbfs"], 0.0) - np.minimum(t0["level_dbfs"], 0.0)
    np.testing.assert_allclose(d_max, dr + clip, atol=1e-9)
    noise_slope = {"noise_figure_db": 1, "fe_rx_antenna_gain_dbi": -1}
    assert _db(n1 / n0) == pytest.approx(noise_slope.get(field, 0) * delta, abs=1e-9)
    # the reported feasible RCS window moves with the attenuation (amplitude ~ sqrt(sigma))
    hi0 = s0.targets[0].rcs_dbsm + float(np.min(t0["attenuation_db"]))
    hi1 = s1.targets[0].rcs_dbsm + float(np.min(t1["attenuation_db"]))
    assert hi1 - hi0 == pytest.approx(ATTENUATION_SLOPE[field] * delta, abs=1e-9)
