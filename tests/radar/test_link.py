"""The physical link budget (rtsgeom.radar.link): radar equation through the RTS, IF chain, ADC."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.constants import c, k as K_B

from conftest import make_scene
from rtsgeom.radar import budget, link as lk
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.paths.table import RUT_TO_RUT, Paths
from rtsgeom.radar.fmcw import fast_time_s, synthesize
from rtsgeom.radar.windows import window
from rtsgeom.rts.channels import build_echoes, program_nearest, setup_echoes


def linked_doc(doc, link=None, n_s=128, n_c=32, targets=None):
    """A small one-front-end scene with [radar.link] (no snr_db)."""
    doc["radar"].pop("snr_db", None)
    doc["radar"].update(samples_per_chirp=n_s, chirps_per_tx=n_c, adc_rate_hz=12.5e6)
    doc["radar"]["link"] = dict(link or {})
    doc["rts"]["front_ends"] = doc["rts"]["front_ends"][:1]
    doc["rts"]["front_ends"][0]["angle_deg"] = 0.0
    doc["rts"]["front_ends"][0].pop("return_loss_fe_db", None)
    doc["rts"]["front_ends"][0].pop("return_loss_be_db", None)
    doc["rts"]["fractional_delay_filter"] = "ideal"
    doc["rts"]["aoa_mode"] = "nearest"
    doc["sheet"]["angle_min_deg"], doc["sheet"]["angle_max_deg"] = -15.0, 15.0
    doc["targets"] = targets or [{"range_m": 20.0, "rcs_dbsm": 10.0, "angle_deg": 0.0}]


def _tone(x, f_hz, radar):
    """Windowed projection of (L, V, N) samples onto a tone at f_hz (no scalloping): (V,)."""
    n_l, _, n = x.shape
    w = window(radar.range_window, n)[None, None, :] * window(radar.doppler_window, n_l)[:, None, None]
    e = np.exp(-2j * np.pi * f_hz * fast_time_s(radar))[None, None, :]
    return np.sum(w * e * x, axis=(0, 2))


@pytest.mark.parametrize("range_m", [8.0, 20.0, 45.0])
@pytest.mark.parametrize("rcs_dbsm", [-10.0, 10.0, 25.0])
def test_post_fft_snr_is_the_radar_equation_through_the_rts(range_m, rcs_dbsm):
    """Measured SNR after the (windowed) range and Doppler FFTs, signal from the simulated
    chain and noise from the simulated noise + ADC, equals the closed-form radar equation with
    k T0 F f_adc noise (+ quantisation) within 0.5 dB."""
    scene = make_scene(lambda d: linked_doc(d, targets=[{"range_m": range_m,
                                                         "rcs_dbsm": rcs_dbsm}]))
    radar = scene.radar
    setup = build_setup(scene)
    program = program_nearest(scene, setup)
    rl = lk.radar_link(radar)
    lk.check_channels(scene, program, rl)
    echoes = lk.apply_radar_link(build_echoes(setup, exact_paths(setup), program), scene, rl)
    f_b = float(np.mean(lk.beat_hz(echoes, radar)[0]))
    sig = synthesize(echoes, radar, setup.rut).data
    x_s = _tone(sig, f_b, radar)
    p_noise = lk.thermal_noise_w(radar, rl) + lk.channel_noise_w(scene, program, rl)
    rng = np.random.default_rng(1)
    noise = lk.shaped_noise((4096,) + sig.shape[1:], p_noise, rl, radar, rng)
    noise_q, _ = lk.adc_convert(noise, rl)
    x_n = np.concatenate([_tone(noise_q[i:i + radar.chirps_per_tx], f_b, radar)
                          for i in range(0, 4096, radar.chirps_per_tx)])
    measured = 10 * np.log10(np.mean(np.abs(x_s) ** 2) / np.mean(np.abs(x_n) ** 2))
    # closed form
    lam = c / radar.f_center_hz
    p_r = (rl.tx_power_w * rl.tx_gain * rl.rx_gain * lam ** 2 * 10 ** (rcs_dbsm / 10)
           / ((4 * np.pi) ** 3 * range_m ** 4))
    h2 = abs(lk.if_response(rl, f_b)) ** 2
    n0 = K_B * 290.0 * rl.noise_figure * radar.adc_rate_hz + lk.channel_noise_w(scene, program, rl)
    gain = (radar.samples_per_chirp * radar.chirps_per_tx
            * budget.window_snr_loss(radar.range_window, radar.samples_per_chirp)
            * budget.window_snr_loss(radar.doppler_window, radar.chirps_per_tx))
    closed = 10 * np.log10(p_r * h2 / (n0 * h2 + rl.quantisation_noise_w) * gain)
    assert measured == pytest.approx(closed, abs=0.5)
    # and the budget reports the same
    b = budget.link_budget(scene, echoes, program, linked=True)
    assert b.targets[0]["snr_after_fft_db"] == pytest.approx(closed, abs=0.5)
    assert b.targets[0]["adc_power_dbm"] == pytest.approx(float(lk.dbm(p_r * h2)), abs=0.3)


def _setup_paths(setup, tau_s, gain):
    rut = setup.rut
    tx, rx = np.meshgrid(np.unique(rut.virtual_tx), np.unique(rut.virtual_rx), indexing="ij")
    n = tx.size
    return Paths.build(front_end=np.full(n, -1), direction=np.full(n, RUT_TO_RUT),
                       rut_tx=tx.ravel(), rut_rx=rx.ravel(), delay_s=np.full(n, tau_s),
                       gain=np.full(n, gain), bounces=np.ones(n, int))


@pytest.mark.parametrize("dist_m,hpf_hz,loss_db", [(0.5, 175e3, 0.0), (1.0, 175e3, 0.0),
                                                    (1.0, 700e3, 10.0), (3.0, 235e3, 20.0),
                                                    (20.0, 0.0, 0.0)])
def test_setup_reflection_follows_path_gain_and_if_response(dist_m, hpf_hz, loss_db):
    """A setup echo's level at the ADC = P_t G_t G_r |g|^2 |H(S tau)|^2, in the budget and in
    the synthesised samples (tone projection). The path gain g carries any absorber (the path
    producers apply it: test_sheet_absorber_scales_the_po_echo, tests/geometry/test_absorbers.py), so
    the link must not apply the sheet's loss a second time: a hand-made path keeps its level
    whatever sheet.reflection_loss_db says."""
    def mut(d):
        linked_doc(d, link={"if_highpass_hz": hpf_hz})
        d["sheet"]["reflection_loss_db"] = loss_db
    scene = make_scene(mut)
    radar, setup = scene.radar, build_setup(scene)
    tau = 2 * dist_m / c
    g = c / radar.f_center_hz / (4 * np.pi * 2 * dist_m)  # an image source at 2 d
    raw = setup_echoes(setup, _setup_paths(setup, tau, g))
    rl = lk.radar_link(radar)
    f_b = radar.slope_hz_per_s * tau
    h = lk.if_response(rl, f_b)
    if hpf_hz > 0:
        x = f_b / hpf_hz
        assert abs(h) ** 2 == pytest.approx(x * x / (1 + x * x) / (1 + (f_b / rl.if_lowpass_hz) ** 8),
                                            rel=1e-9)
    expect = rl.tx_power_w * rl.tx_gain * rl.rx_gain * g ** 2 * abs(h) ** 2
    e = lk.apply_radar_link(raw, scene, rl)
    assert np.allclose(np.abs(e.amplitude) ** 2, expect, rtol=1e-9)
    cube = synthesize(e, radar, setup.rut).data
    x = _tone(cube, f_b, radar)
    w_sum = window(radar.range_window, radar.samples_per_chirp).sum() * window(
        radar.doppler_window, radar.chirps_per_tx).sum()
    assert np.allclose(np.abs(x) ** 2 / w_sum ** 2, expect, rtol=1e-3)
    empty = program_nearest(scene.evolve(targets=()), setup)
    b = budget.link_budget(scene, raw, empty, linked=False)
    assert b.setup_echoes[0]["adc_power_dbm"] == pytest.approx(float(lk.dbm(expect)), abs=1e-6)
    assert b.setup_echoes[0]["if_response_db"] == pytest.approx(20 * np.log10(abs(h)), abs=1e-9)


def _sheet_budget(link, loss_db):
    def mut(d):
        linked_doc(d, link=link)
        d["sheet"]["reflection_loss_db"] = loss_db
    scene = make_scene(mut)
    setup = build_setup(scene)
    program = program_nearest(scene, setup)
    raw = setup_echoes(setup, budget.sheet_paths(setup))
    return budget.link_budget(scene, raw, program, linked=False).setup_echoes, scene, setup, raw


@pytest.mark.parametrize("radius_m,offset_m", [(1.0, 0.0), (2.0, 0.05)])
def test_sheet_absorber_scales_the_po_echo(radius_m, offset_m):
    """sheet.reflection_loss_db = L: the sheet's physical-optics echo (sheet_paths, the budget's
    estimate) is 10^(-L/20) of the uncovered one per element pair, phase unchanged; through
    the link the power drops by exactly L dB."""
    def scene_with(loss):
        def mut(d):
            linked_doc(d)
            d["rts"]["arc_radius_m"] = radius_m
            d["sheet"]["radius_offset_m"] = offset_m
            d["sheet"]["reflection_loss_db"] = loss
        return make_scene(mut)
    lam = c / scene_with(0.0).radar.f_center_hz
    ref = budget.sheet_paths(build_setup(scene_with(0.0)), step_m=lam)
    for loss in (7.0, 20.0, 43.0):
        scene = scene_with(loss)
        setup = build_setup(scene)
        p = budget.sheet_paths(setup, step_m=lam)
        np.testing.assert_allclose(p.delay_s, ref.delay_s, rtol=0, atol=0)
        np.testing.assert_allclose(p.gain, ref.gain * 10 ** (-loss / 20), rtol=1e-12)
        e0 = lk.apply_radar_link(setup_echoes(setup, ref), scene)
        e1 = lk.apply_radar_link(setup_echoes(setup, p), scene)
        drop = 10 * np.log10(np.abs(e0.amplitude) ** 2 / np.abs(e1.amplitude) ** 2)
        np.testing.assert_allclose(drop, loss, atol=1e-9)


def test_uncovered_sheet_at_1m_on_an_awr1843():
    """The sheet at 1 m (physical optics) with the AWR1843 preset: its beat (~160 kHz) sits
    below the 175 kHz HPF corner (about 3 dB suppression reported); at the highest Rx gain
    (48 dB: full scale 18 dB lower than the preset's 30-dB point) it clips the ADC, and with
    a 20 dB absorber it does not."""
    rows, _, _, _ = _sheet_budget({}, 0.0)
    assert rows and all(r["beat_hz"] < 175e3 for r in rows)
    assert all(-4.0 < r["if_response_db"] < -2.5 for r in rows)
    hi_gain = {"adc_full_scale_dbm": -25.0 - 18.0}
    rows, _, _, _ = _sheet_budget(hi_gain, 0.0)
    assert min(r["clip_margin_db"] for r in rows) < 0
    warns = budget.link_warnings(budget.LinkBudget(True, "", 0, 0, 0, {"adc_full_scale_dbm": -43.0},
                                           [], [], rows), 15.0)
    assert any("clips" in w for w in warns)
    rows, _, _, _ = _sheet_budget(hi_gain, 20.0)
    assert min(r["clip_margin_db"] for r in rows) > 0


def test_uncovered_sheet_clips_the_simulated_adc():
    """The same sheet echo through the signal chain: the ADC clips samples without the
    absorber and none with it."""
    for loss, clips in ((0.0, True), (20.0, False)):
        _, scene, setup, raw = _sheet_budget({"adc_full_scale_dbm": -43.0}, loss)
        rl = lk.radar_link(scene.radar)
        e = lk.apply_radar_link(raw, scene, rl)
        _, n = lk.adc_convert(synthesize(e, scene.radar, setup.rut).data, rl)
        assert (n > 0) == clips


def test_rcs_beyond_the_channel_is_a_clear_error():
    def mut(d):
        linked_doc(d, targets=[{"range_m": 5.0, "rcs_dbsm": 60.0}])
    scene = make_scene(mut)
    setup = build_setup(scene)
    with pytest.raises(lk.LinkError, match=r"targets\[0\]\.rcs_dbsm = 60: must be in \["):
        lk.check_channels(scene, program_nearest(scene, setup))
    # the reported upper limit is feasible, just above it is not
    msg = str(pytest.raises(lk.LinkError, lk.check_channels, scene,
                            program_nearest(scene, setup)).value)
    hi = float(msg.split("must be in [")[1].split(",")[1].split("]")[0])
    ok = scene.evolve(targets=(scene.targets[0].evolve(rcs_dbsm=hi - 0.1),))
    lk.check_channels(ok, program_nearest(ok, setup))


@pytest.mark.parametrize("bits", [8, 12])
def test_adc_clips_and_quantises(bits):
    rl = lk.radar_link(make_scene(lambda d: linked_doc(d, link={"adc_bits": bits})).radar)
    x = (np.linspace(-2, 2, 4001) * rl.rail).astype(np.complex64) * (1 + 1j)
    y, n = lk.adc_convert(x, rl)
    assert n == np.count_nonzero(np.abs(x.real) > rl.rail)
    assert np.max(np.abs(y.real)) <= rl.rail * (1 + 1e-6)
    inside = np.abs(x.real) < rl.rail
    assert np.max(np.abs(y.real - x.real)[inside]) <= rl.lsb / 2 * (1 + 1e-4)


def test_default_scene_unchanged_and_budget_states_the_override(default_scene):
    """No [radar.link]: the signal keeps its relative model; the budget says snr_db rules."""
    from rtsgeom.pipeline.run import run_scene, summary
    assert default_scene.radar.link is None
    r = run_scene(default_scene.evolve(targets=default_scene.targets[:1]), aoa_mode="nearest")
    s = summary(r, "exact")
    lb = s["link_budget"]
    assert lb["modelled"] is False and lb["noise_source"].startswith("snr_db override")
    assert set(lb["targets"][0]) >= {"index", "adc_power_dbm", "snr_after_fft_db",
                                     "clip_margin_db"}
    # without [radar.link] no physical-optics sheet estimate is made (it costs ~1 s a run)
    assert lb["setup_echoes"] == []
    assert s["adc_clipped_samples"] == 0
    import json
    json.dumps(s, allow_nan=False)  # summary.json is strict JSON (no -inf dBm)


def test_linked_run_warns_on_clipping_and_reports_the_budget():
    """run_scene with [radar.link]: the budget is 'modelled', thermal noise is named, the
    sheet (estimated) clips at the highest Rx gain and run warns; same seed, same bytes."""
    from rtsgeom.pipeline.run import run_scene, summary
    scene = make_scene(lambda d: linked_doc(d, link={"adc_full_scale_dbm": -43.0}))
    r = run_scene(scene, aoa_mode="nearest")
    lb = summary(r, "exact")["link_budget"]
    assert lb["modelled"] is True and lb["noise_source"].startswith("thermal")
    assert any("setup echo 0 clips" in w for w in r.warnings)
    assert r.matches[0]["detection"] is not None
    r2 = run_scene(scene, aoa_mode="nearest")
    assert r.cube.data.tobytes() == r2.cube.data.tobytes()


@pytest.mark.parametrize("order", [1, 2, 3, 4, 6])
def test_if_lowpass_is_scipys_butterworth(order):
    """The written-out Butterworth equals scipy.signal.butter(analog=True) via freqs_zpk."""
    from scipy.signal import butter, freqs_zpk
    rl = lk.radar_link(make_scene(lambda d: linked_doc(d, link={"if_lowpass_order": order,
                                                                "if_highpass_hz": 0.0})).radar)
    f = np.linspace(-3, 3, 61) * rl.if_lowpass_hz
    z, p, k = butter(order, 2 * np.pi * rl.if_lowpass_hz, analog=True, output="zpk")
    _, ref = freqs_zpk(z, p, k, worN=2 * np.pi * f)
    np.testing.assert_allclose(lk.if_response(rl, f), ref, rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("linked", [False, True])
def test_info_budget_says_whether_the_scene_models_the_link(linked):
    """``rtsgeom info``'s budget (``static_budget``, computed from relative echoes) reports
    ``modelled`` from the scene: with [radar.link] the link is in the signal, its noise
    thermal; without, a prediction (it used to say "no [radar.link]" on a linked scene). The
    target's ADC power is the same prediction either way."""
    def mut(doc):
        linked_doc(doc)
        if not linked:
            del doc["radar"]["link"]
            doc["radar"]["snr_db"] = 30.0
    b = budget.static_budget(build_setup(make_scene(mut)))
    assert b.to_dict()["modelled"] is linked
    assert ("prediction" in b.to_dict()["noise_source"]) is (not linked)
    assert b.to_dict()["targets"][0]["adc_power_dbm"] is not None


def test_a_front_end_lost_to_clipping_says_so():
    """A linked scene whose probe frame clips (ADC full scale far below the echoes): the
    probe's note names the clipping and its remedies, and the planner's error carries it (it
    used to say 'blocked line of sight' for a sheet reflection that clipped the ADC)."""
    import warnings

    from rtsgeom.calibration.probes import probe_front_ends
    clipping = build_setup(make_scene(lambda d: linked_doc(d, {"adc_full_scale_dbm": -90.0})))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # the lost front end warns as well
        probe = probe_front_ends(clipping, exact_paths(clipping))
    assert probe.adc_clipped > 0
    note = probe.clipping_note()
    assert "ADC clipped" in note and "reflection_loss_db" in note
    clean = build_setup(make_scene(linked_doc))
    unclipped = probe_front_ends(clean, exact_paths(clean))
    assert unclipped.adc_clipped == 0 and unclipped.clipping_note() == ""


def test_info_budget_names_front_ends_without_a_target():
    """``info`` puts each target on its nearest front end; a front end carrying none says so
    instead of ``attenuation - dB`` (which read as a missing attenuation on a front end the
    synthesis does use)."""
    from conftest import DEFAULT_SCENE
    from rtsgeom.scene import load_scene
    setup = build_setup(load_scene(DEFAULT_SCENE.parent / "custom-array.toml"))
    b = budget.static_budget(setup).to_dict()
    carrying = set(int(q) for q in program_nearest(setup.scene, setup).front_end)
    assert carrying and carrying != set(range(len(b["front_ends"])))
    for fe, line in zip(b["front_ends"], [ln for ln in budget.format_budget(b)
                                          if ln.startswith("  front end ")]):
        assert bool(fe["attenuation_db"]) is (fe["index"] in carrying)
        assert ("no target on it" in line) is (fe["index"] not in carrying), line
        assert " - dB" not in line


@pytest.mark.parametrize("gain_db", [45.0, 60.0])
def test_a_back_end_the_ruts_chirp_clips_is_refused_with_its_limit(gain_db):
    """The chirp's level at the back-end ADC grows dB for dB with rts.link.rx_gain_db: the
    message names the gain, its largest value and the input power; just below that limit the
    channels pass."""
    from rtsgeom.rts.channels import program_nearest

    def mut(d, g=gain_db):
        linked_doc(d)
        d["rts"]["link"] = {"rx_gain_db": g}
    scene = make_scene(mut)
    setup = build_setup(scene)
    t = lk.channel_table(scene, program_nearest(scene, setup))
    assert t["level_dbfs"][0] > 0
    limit = gain_db - t["level_dbfs"][0]
    with pytest.raises(lk.LinkError) as exc:
        lk.check_channels(scene, program_nearest(scene, setup))
    assert str(exc.value) == (
        f"test.toml: rts.link.rx_gain_db = {gain_db:g}: must be <= {limit:.1f} dB: the RuT's "
        f"chirp reaches front end 0's back-end ADC at {t['input_dbm'][0]:.1f} dBm, above its "
        "full scale rts.link.adc_full_scale_dbm")
    below = make_scene(lambda d: mut(d, limit - 0.1))
    t2 = lk.check_channels(below, program_nearest(below, setup))
    assert t2["level_dbfs"][0] == pytest.approx(-0.1, abs=1e-9)


@pytest.mark.parametrize("rcs_dbsm", [60.0, -80.0])
def test_an_rcs_beyond_the_channel_is_refused_whole_from_its_channel_table(rcs_dbsm):
    """Too large (attenuation below 0) or too small (above the back end's range on the
    target's strongest row): the message's limits, attenuation and range from
    ``channel_table``, whole."""
    from rtsgeom.rts.channels import program_nearest

    def mut(d):
        linked_doc(d, targets=[{"range_m": 5.0, "rcs_dbsm": rcs_dbsm}])
    scene = make_scene(mut)
    setup = build_setup(scene)
    prog = program_nearest(scene, setup)
    t = lk.channel_table(scene, prog)
    att, mx = t["attenuation_db"], t["max_attenuation_db"]
    bad = np.flatnonzero((att < 0) | (att > mx))
    assert bad.size, (att, mx)
    row = int(bad[0])
    lo, hi = rcs_dbsm - (mx[row] - att[row]), rcs_dbsm + att[row]
    assert (hi < rcs_dbsm) == (rcs_dbsm > 0) and (lo > rcs_dbsm) == (rcs_dbsm < 0)
    with pytest.raises(lk.LinkError) as exc:
        lk.check_channels(scene, prog)
    assert str(exc.value) == (
        f"test.toml: targets[0].rcs_dbsm = {rcs_dbsm:g}: must be in [{lo:.1f}, {hi:.1f}] dBsm "
        f"at range_m = 5 on RTS channel {int(prog.front_end[row])} (attenuation "
        f"{att[row]:.1f} dB needed; the back end offers [0, {mx[row]:.1f}] dB with rts.link "
        "gains, full scales and dac_bits)")
