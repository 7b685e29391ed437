"""The link budget (``radar.budget``) of a target on two RTS channels (a synthesized one): its
power is the coherent sum the RuT's range-Doppler cell sees, each channel's echo with its own
beat phase (the two front ends reach the RuT over different air paths)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import make_scene
from scipy.constants import c

from rtsgeom.calibration.probes import probe_ranges
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.radar.budget import link_budget
from rtsgeom.radar.link import relative_noise_power
from rtsgeom.radar.phasors import bin_response
from rtsgeom.radar.windows import window
from rtsgeom.rts.channels import KIND_DIRECT, RtsProgram, build_echoes, requested_delay


def linked_scene(nf_db=12.0, fs_dbm=-25.0, target_m=None, **radar):
    """The paper's bench with a physical link and no snr_db; ``target_m``: one target of 10
    dBsm at that range in front end 0's direction (what ``rtsgeom info`` budgets)."""
    def mut(d):
        d["radar"].pop("snr_db", None)
        d["radar"].update(radar)
        d["radar"]["link"] = {"noise_figure_db": nf_db, "adc_full_scale_dbm": fs_dbm}
        if target_m is not None:
            d["targets"] = [{"range_m": target_m, "velocity_mps": 0.0, "angle_deg": 3.4,
                             "rcs_dbsm": 10.0}]
    return make_scene(mut)


def scalloping_db(radar, range_m: float) -> float:
    """The range window's gain (dB) at the target's fractional bin against the bin centre
    (``|sum w_n e^{j 2 pi d n / N}| / sum w_n``, d the offset from the nearest bin)."""
    n = radar.samples_per_chirp
    frac = range_m * 2 * radar.slope_hz_per_s / c * n / radar.adc_rate_hz
    d = frac - round(frac)
    w = window(radar.range_window, n)
    return 20 * math.log10(abs(np.sum(w * np.exp(2j * np.pi * d * np.arange(n) / n)))
                           / np.sum(w))


@pytest.mark.parametrize("ratio", [0.3, 1.0, 3.0])
@pytest.mark.parametrize("off_j_ps", [0.0, 5.0, -10.0])
def test_a_synthesized_targets_budget_snr_is_its_cells(ratio, off_j_ps):
    """Front ends 0 and 1 (8.8 deg apart) programmed with amplitudes (1, ratio) and J's delay
    moved by ``off_j_ps``: the budget's post-FFT SNR is the cell's (the windowed DFTs of every
    echo with its phase, ``radar.phasors.bin_response``, at the strongest range bin) over the
    link's noise through the same windows, within 0.05 dB once the range window's scalloping
    is counted (the budget counts the bin centre; J's delay offsets of tens of ps, which move
    its tone by a tenth of a bin and turn its windowed DFT's phase, leave 0.1-0.2 dB). Before,
    the budget summed the channels' echo amplitudes without their beat phases: 0.85 to 1.25
    dB high."""
    rng_m = float(probe_ranges(build_setup(linked_scene()), 1)[0])
    scene = linked_scene(target_m=rng_m)
    radar = scene.radar
    setup = build_setup(scene)
    tau = float(requested_delay(scene, rng_m))
    amps = 10.0 * np.array([1.0, ratio])  # about the paper target's programme (50 dB)
    prog = RtsProgram.build([0, 0], [0, 1], [tau, tau + off_j_ps * 1e-12], [0.0, 0.0],
                            list(amps))
    echoes = build_echoes(setup, exact_paths(setup), prog)
    b = link_budget(scene, echoes, prog, linked=False, predict=True, setup=setup)
    direct = echoes.select(echoes.kind == KIND_DIRECT)
    r0 = round(rng_m * 2 * radar.slope_hz_per_s / c * radar.samples_per_chirp
               / radar.adc_rate_hz)
    rbins = np.arange(r0 - 1, r0 + 2)
    cell = bin_response(direct, radar, setup.rut, rbins,
                        np.full(3, radar.chirps_per_tx // 2)).sum(axis=1)  # (K, V)
    p_cell = float(np.max(np.mean(np.abs(cell) ** 2, axis=-1)))
    n_rel = float(relative_noise_power(scene, float(np.sum(amps ** 2)),
                                       radar.slope_hz_per_s * 2 * rng_m / c))
    g = (np.sum(window(radar.range_window, radar.samples_per_chirp) ** 2)
         * np.sum(window(radar.doppler_window, radar.chirps_per_tx) ** 2))
    cell_db = 10 * math.log10(p_cell / (n_rel * g))
    assert b.targets[0]["snr_after_fft_db"] + scalloping_db(radar, rng_m) == \
        pytest.approx(cell_db, abs=0.05)


def _budget(targets, setup_echoes, adc_fs_dbm=-43.0):
    from rtsgeom.radar.budget import LinkBudget
    return LinkBudget(True, "src", 1e-12, 1e-15, 40.0, {"adc_full_scale_dbm": adc_fs_dbm}, [],
                      targets, setup_echoes)


def test_link_warnings_are_each_clipping_and_each_target_below_the_threshold_whole():
    """``link_warnings``: a negative clip margin warns (0 does not), for targets and setup
    echoes; a target's SNR below the threshold warns (at it, not; a setup echo never);
    rows without levels are skipped."""
    from rtsgeom.radar.budget import link_warnings
    tg = [{"index": 0, "clip_margin_db": 0.0, "adc_power_dbm": -43.0, "snr_after_fft_db": 15.0},
          {"index": 1, "clip_margin_db": -2.5, "adc_power_dbm": -40.5,
           "snr_after_fft_db": 14.96},
          {"index": 2, "clip_margin_db": None, "adc_power_dbm": None, "snr_after_fft_db": None}]
    se = [{"index": 0, "clip_margin_db": -0.25, "adc_power_dbm": -42.75,
           "snr_after_fft_db": -30.0},
          {"index": 1, "clip_margin_db": 3.0, "adc_power_dbm": -46.0, "snr_after_fft_db": 1.0}]
    assert link_warnings(_budget(tg, se), 15.0) == [
        "link: target 1 clips the RuT's ADC by 2.5 dB (-40.5 dBm at full scale -43.0 dBm)",
        "link: target 1 is 15.0 dB above the noise after the FFTs, below the CFAR threshold "
        "15 dB",
        "link: setup echo 0 clips the RuT's ADC by 0.2 dB (-42.8 dBm at full scale -43.0 dBm)"]
    assert link_warnings(_budget(tg[:1] + tg[2:], se[1:]), 15.0) == []


def test_the_budget_text_is_every_level_of_its_dict_whole():
    """``format_budget``: the header (modelled or not), the radar's line, the noise line, one
    line per front end (with or without attenuations) and per target / setup echo with levels
    (CLIPS where its margin is negative; '-' for a missing level)."""
    from rtsgeom.radar.budget import format_budget
    radar = {"tx_power_dbm": 12.0, "tx_antenna_gain_dbi": 10.04, "rx_antenna_gain_dbi": 9.96,
             "noise_figure_db": 15.0, "if_highpass_hz": 175e3, "if_lowpass_hz": 15e6,
             "adc_bits": 12, "adc_full_scale_dbm": -43.0}
    fe = {"index": 1, "rut_chirp_at_adc_dbm": -20.04, "adc_level_dbfs": -10.0,
          "attenuation_db": [30.0, 31.25], "max_attenuation_db": 70.0,
          "rut_tx_gain_dbi": 10.0, "rut_rx_gain_dbi": 9.0, "fe_rx_gain_dbi": 5.0}
    b = {"modelled": False, "radar": radar, "noise_dbm_per_sample": -100.0,
         "noise_source": "thermal", "quantisation_noise_dbm": None, "fft_gain_db": 42.1,
         "front_ends": [fe, {**fe, "index": 2, "attenuation_db": []}],
         "targets": [{"index": 0, "range_m": 20.004, "adc_power_dbm": -60.0,
                      "if_response_db": -1.0, "snr_after_fft_db": 30.0, "clip_margin_db": 17.0},
                     {"index": 1, "adc_power_dbm": None}],
         "setup_echoes": [{"index": 0, "range_m": 1.5, "adc_power_dbm": -40.0,
                           "if_response_db": -20.0, "snr_after_fft_db": 60.0,
                           "clip_margin_db": -3.0}]}
    fe_tail = ("the back end attenuates at most 70.0 dB; antennas toward each other: RuT "
               "10.0/9.0 dBi, front end 5.0/- dBi")
    want = [
        "link budget (not modelled in the signal: no [radar.link]):",
        "  RuT Tx 12.0 dBm, antennas 10.0/10.0 dBi, NF 15.0 dB, IF HPF 175 kHz / LPF 15.00 MHz,"
        " ADC 12 bit, full scale -43.0 dBm",
        "  noise -100.0 dBm per sample (thermal), quantisation - dBm, FFT gain 42.1 dB",
        "  front end 1: RuT chirp at the back end's ADC -20.0 dBm (-10.0 dBFS), attenuation "
        f"30.0, 31.2 dB; {fe_tail}",
        "  front end 2: RuT chirp at the back end's ADC -20.0 dBm (-10.0 dBFS), no target on it "
        "in this budget (each target on its nearest front end: run's summary.json has the "
        f"synthesis' attenuations); {fe_tail}",
        "  target 0 (20.00 m): -60.0 dBm at the ADC (IF -1.0 dB), SNR after the FFTs 30.0 dB, "
        "clip margin 17.0 dB",
        "  setup echo 0 (1.50 m): -40.0 dBm at the ADC (IF -20.0 dB), SNR after the FFTs 60.0 "
        "dB, clip margin -3.0 dB  CLIPS"]
    assert format_budget(b) == want
    assert format_budget({**b, "modelled": True})[0] == "link budget (modelled in the signal):"


def test_a_budget_dict_is_its_fields_with_levels_in_dbm_and_no_infinite_level():
    """``LinkBudget.to_dict``: every field under its key, the noise levels in dBm; a level
    that is not finite (nested anywhere) is None."""
    from rtsgeom.radar.budget import LinkBudget
    from rtsgeom.radar.link import dbm
    b = LinkBudget(False, "src", 2e-12, 0.0, 41.5, {"x": float("inf"), "y": [1.0, -np.inf]},
                   [{"index": 0}], [{"snr_after_fft_db": float("nan")}], [])
    assert b.to_dict() == {
        "modelled": False, "noise_source": "src", "noise_dbm_per_sample": float(dbm(2e-12)),
        "quantisation_noise_dbm": None, "fft_gain_db": 41.5, "radar": {"x": None,
                                                                       "y": [1.0, None]},
        "front_ends": [{"index": 0}], "targets": [{"snr_after_fft_db": None}],
        "setup_echoes": []}


@pytest.mark.parametrize("snr_db", [None, 17.5])
def test_the_budget_says_where_its_noise_comes_from_whole(snr_db):
    """``_noise``'s source for each case: the snr_db override; thermal plus the RTS channels,
    modelled, predicted for a scene without a link (and the simulation's snr_db beside it) or
    not in the signal; the noise itself thermal + channels (no channels here: thermal)."""
    from rtsgeom.radar.budget import _noise
    from rtsgeom.radar.link import radar_link, thermal_noise_w
    from rtsgeom.rts.channels import RtsProgram
    scene = make_scene(lambda d: d["radar"].update(snr_db=snr_db) if snr_db else
                       d["radar"].pop("snr_db", None))
    link, empty = radar_link(scene.radar), RtsProgram.build([], [], [], [], [])
    th = thermal_noise_w(scene.radar, link)
    base = "thermal k T0 F f_adc + RTS channel noise"
    sim = ("" if snr_db is None else f"; the simulation's noise is radar.snr_db = {snr_db:g} "
           "dB per sample for the strongest echo, not this")
    cases = {(True, False): base, (True, True): base + sim,
             (False, True): base + " (prediction: the scene has no [radar.link])" + sim,
             (False, False): base + "; not in the signal (no [radar.link], no snr_db)"}
    for (modelled, predict), src in cases.items():
        assert _noise(scene, empty, link, None, None, modelled, predict) == (th, src, th, 0.0)
        assert _noise(scene, empty, link, None, 3e-13, modelled, predict) == (
            3e-13, "snr_db override: fixed per-sample SNR of the strongest target echo (not "
                   "the physical noise)", th, 0.0)
