"""Calibration that holds across setups, the pair order, the gain offset and the calibration
period."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.constants import c

from rtsgeom.calibration.pair import calibrate_pair, pair_coherence
from rtsgeom.calibration.probes import (if_phase_slope_hz, probe_angles, probe_front_ends,
                                        probe_ranges, probe_total_delay)
from rtsgeom.cli import main
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.rts.channels import RtsProgram, channel_echoes
from rtsgeom.geometry.warnings import height_phase_deg, scene_warnings

from conftest import DEFAULT_SCENE, CoherenceShift, make_scene


def _noiseless(radius_m=1.0, f_rts_hz=None, offsets=None):
    def mutate(doc):
        doc["radar"].pop("snr_db", None)
        doc["rts"]["arc_radius_m"] = radius_m
        if f_rts_hz is not None:
            doc["rts"]["f_rts_hz"] = f_rts_hz
        for k, v in (offsets or {}).items():
            doc["rts"]["front_ends"][k]["radial_offset_mm"] = v
    return make_scene(mutate)


# ---------------------------------------------------------------- height warning

@pytest.mark.parametrize("r", [0.3, 1.0, 3.0])
@pytest.mark.parametrize("dz_mm", [0.5, 2.0, 10.0, 40.0])
def test_height_phase_is_second_order(r, dz_mm):
    dz = dz_mm * 1e-3
    lam = 3.9e-3
    closed = 360.0 * (dz * dz / r) / lam  # both legs grow by dz^2 / 2R
    assert height_phase_deg(dz, r, lam) == pytest.approx(closed, rel=2 * (dz / r) ** 2 + 1e-9)
    assert height_phase_deg(-dz, r, lam) == height_phase_deg(dz, r, lam)


def test_height_warning_only_where_the_second_order_phase_is_large():
    def with_height(dz_mm, radius):
        def mutate(doc):
            doc["rts"]["arc_radius_m"] = radius
            doc["sheet"]["enabled"] = False  # cutouts would not fit at 0.3 m
            doc["rts"]["front_ends"][0]["height_offset_mm"] = dz_mm
        return scene_warnings(make_scene(mutate))

    # 2 mm at 1 m: 2 * dz^2 / 2R = 4 um of path, 0.37 deg: no height warning (the old text
    # claimed "up to 180 deg")
    assert not [w for w in with_height(2.0, 1.0) if "height_offset_mm" in w]
    # 30 mm at 0.3 m: 3 mm of two-way path, ~277 deg: warned, with the real size
    hits = [w for w in with_height(30.0, 0.3) if "dz^2 / 2R" in w]
    assert len(hits) == 1
    lam = build_setup(make_scene()).rut.wavelength_m
    expected = height_phase_deg(30e-3, 0.3, lam)
    assert 180 < expected < 400
    assert f"{expected:.4g} deg" in hits[0]


# ---------------------------------------------------------------- pair order

def test_pair_order_does_not_change_the_result(tmp_path, capsys):
    outs = []
    for pair in (["0", "1"], ["1", "0"]):
        assert main(["linearity", str(DEFAULT_SCENE), "--pair", *pair, "--uncalibrated",
                     "--points", "3", "--json", "--quiet"]) == 0
        outs.append(json.loads(capsys.readouterr().out))
    assert outs[0] == outs[1]


# ---------------------------------------------------------------- gain offset

@pytest.mark.parametrize("fe, offset_db", [(1, 6.0), (0, -6.0)])
def test_gain_offset_scales_the_echo_and_comes_back_as_gain_correction(fe, offset_db):
    def mutate(doc):
        doc["radar"].pop("snr_db", None)
        doc["rts"]["front_ends"][fe]["gain_offset_db"] = offset_db
    base, off = build_setup(_noiseless()), build_setup(make_scene(mutate))
    prog = RtsProgram.build([0, 1], [0, 1], [1e-7, 1e-7], [0.0, 0.0], [1.0, 1.0])
    e0 = channel_echoes(base, exact_paths(base), prog)
    e1 = channel_echoes(off, exact_paths(off), prog)
    ratio = np.abs(e1.amplitude) / np.abs(e0.amplitude)
    sel = e0.front_end == fe
    assert np.allclose(ratio[sel], 10 ** (offset_db / 20), rtol=1e-12)  # amplitude, not power
    assert np.allclose(ratio[~sel], 1.0, rtol=1e-12)
    g0 = probe_front_ends(base, exact_paths(base), 1).gain_correction
    g1 = probe_front_ends(off, exact_paths(off), 1).gain_correction
    assert g1[fe] / g0[fe] == pytest.approx(10 ** (-offset_db / 20), rel=2e-3)
    assert g1[1 - fe] / g0[1 - fe] == pytest.approx(1.0, rel=2e-3)


# ---------------------------------------------------------------- coherence point

@pytest.mark.parametrize("radius", [0.5, 3.0])
def test_coherence_point_moves_by_the_closed_form(radius):
    """The phasor model's coherence point shifts by -(f_c + S t_mid - S tau) /
    (f_rts + S t_mid - S tau) * 2 dr / c0 for a radial offset dr of front end J (and the
    opposite way for I)."""
    nom = build_setup(_noiseless(radius))
    shift = CoherenceShift(nom, probe_front_ends(nom, exact_paths(nom), 1))
    for fe, dr_mm in ((1, 0.3), (0, -0.7), (1, -0.45)):
        s = build_setup(_noiseless(radius, offsets={fe: dr_mm}))
        d = pair_coherence(s, exact_paths(s), (0, 1), alphas=shift.alphas,
                           near_s=shift.d0).continuous_s
        assert abs(shift.wrapped(d, fe, dr_mm)) < 1e-12  # 1st order in dr: 0.6 ps at 0.7 mm on 0.5 m


# ---------------------------------------------------------------- period (items 2, 22)

@pytest.mark.parametrize("radius, f_rts", [(1.0, 500e6), (3.0, 250e6), (0.5, 800e6)])
def test_period_is_the_exact_closed_form(radius, f_rts):
    setup = build_setup(_noiseless(radius, f_rts))
    paths = exact_paths(setup)
    cal = calibrate_pair(setup, paths, (0, 1), probe_front_ends(setup, paths, 1), seed=1,
                         span_s=(0.0, 1e-12), step_s=1e-12)  # two steps: only the period
    r = setup.scene.radar
    t_mid = r.adc_start_s + 0.5 * (r.samples_per_chirp - 1) / r.adc_rate_hz
    s = r.bandwidth_hz / r.chirp_duration_s
    ranges = probe_ranges(setup, 2)
    # total delay: the set range's 2 R / c0 (the RTS compensates the nominal air path) plus
    # the difference of the real air path from the nominal one (below a ps here)
    tau = 2 * np.mean(ranges) / c
    expected = 1 / (f_rts + s * t_mid - s * tau)
    assert cal.period_s == pytest.approx(expected, rel=1e-5)
    assert abs(cal.period_s - 1 / (f_rts + r.bandwidth_hz / 2)) > 1e-3 * cal.period_s


@pytest.mark.slow
@pytest.mark.parametrize("radius, f_rts", [(1.0, 500e6), (3.0, 500e6)])
def test_minima_are_one_exact_period_apart(radius, f_rts):
    """Two calibrations, one near the first minimum and one a period later (noiseless, each
    refined to 1 ps): their distance is the reported period. (At f_rts = 250 MHz a period
    moves channel J by 1.3 range bins and the second minimum lands 8 ps late, J's echo
    straddling a range-bin boundary; hence 500 MHz here.)"""
    setup = build_setup(_noiseless(radius, f_rts))
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, 1)
    first = calibrate_pair(setup, paths, (0, 1), probe, seed=1)
    p = first.period_s
    near = first.delta_tau_s + p
    second = calibrate_pair(setup, paths, (0, 1), probe, seed=1,
                            span_s=(near - 0.1e-9, near + 0.1e-9))
    spacing = second.delta_tau_s - first.delta_tau_s
    assert spacing == pytest.approx(p, abs=2e-12)


# ---------------------------------------------------------------- fractional-delay FIR

def _fir_scene(taps, model, snr=False):
    def mutate(doc):
        if not snr:
            doc["radar"].pop("snr_db", None)
        doc["rts"]["fractional_delay_taps"] = taps
        doc["rts"]["fractional_delay_filter"] = model
    return make_scene(mutate)


@pytest.mark.parametrize("taps", [3, 9, 33, 129])
def test_fir_is_the_delay_it_is_set_to_at_low_frequency_and_exact_at_integer_settings(taps):
    from rtsgeom.rts.fir import fir_error_response, fractional_delay_fir
    mu = np.array([0.0, 0.13, 0.5, 0.87])
    h = fractional_delay_fir(mu, taps)
    assert np.allclose(h.sum(1), 1.0)
    assert np.allclose(h[0], np.eye(taps)[(taps - 1) // 2])  # integer setting: a pure delay
    f = np.linspace(0.0, 1.5e9, 31)[None].repeat(4, 0)
    e = fir_error_response(mu, taps, 4e9, f)
    assert np.allclose(e[0], 1.0)
    assert np.allclose(e[:, 0], 1.0)  # DC: unit gain, no phase error
    assert np.abs(e[1:] - 1).max() > 1e-6  # fractional settings are not ideal


def test_fir_ripple_falls_with_the_number_of_taps():
    from rtsgeom.rts.fir import fir_error_response
    f = np.linspace(0.5e9, 1.5e9, 101)[None]
    worst = [np.abs(np.angle(fir_error_response([0.5], t, 4e9, f))).max() for t in (5, 17, 65)]
    assert worst[0] > worst[1] > worst[2]


def test_ideal_filter_reproduces_the_pure_delay_and_integer_settings_match_it():
    from rtsgeom.radar.fmcw import synthesize
    from rtsgeom.rts.channels import build_echoes
    ideal, fir = build_setup(_fir_scene(33, "ideal")), build_setup(_fir_scene(33, "windowed-sinc"))
    paths = exact_paths(ideal)
    ts = 1 / ideal.scene.rts.f_s_hz
    whole = RtsProgram.build([0, 0], [0, 1], [400 * ts, 401 * ts], [0.0, 0.0], [1.0, 0.5])
    e_i, e_f = build_echoes(ideal, paths, whole), build_echoes(fir, paths, whole)
    assert e_i.fast_gain is None
    r, rut = ideal.scene.radar, ideal.rut
    assert np.allclose(synthesize(e_i, r, rut).data, synthesize(e_f, r, rut).data, atol=1e-7)
    frac = RtsProgram.build([0, 0], [0, 1], [400.3 * ts, 401.6 * ts], [0.0, 0.0], [1.0, 0.5])
    e_i, e_f = build_echoes(ideal, paths, frac), build_echoes(fir, paths, frac)
    x_i, x_f = synthesize(e_i, r, rut).data, synthesize(e_f, r, rut).data
    assert np.abs(x_f - x_i).max() > 1e-4 * np.abs(x_i).max()  # fractional: ripple
    # ... and the cube differs from the ideal one by exactly the FIR's gain along the chirp
    assert np.abs(x_f - x_i).max() <= np.abs(e_f.fast_gain - 1).max() * np.abs(x_i).max() * 1.01


@pytest.mark.parametrize("taps", [5, 9, 33])
def test_fir_moves_the_coherence_point_by_its_phase_ripple(taps):
    """The channels' coherent phase with the FIR minus without it, at programmed delays
    across a period, equals -2 pi f_if times the shift `fir_effect` predicts from the
    filter's own response (window-weighted phase at each probe's bin)."""
    from rtsgeom.calibration.fir import fir_effect
    from rtsgeom.synthesis.model import ChannelModel
    from rtsgeom.scene import TargetConfig
    ideal, fir = build_setup(_fir_scene(taps, "ideal")), build_setup(_fir_scene(taps, "windowed-sinc"))
    paths = exact_paths(ideal)
    ranges = probe_ranges(ideal, 2)
    for d in (0.0, 0.1e-9, 0.37e-9, 0.81e-9):
        z = 0j
        for r in ranges:
            m0 = ChannelModel.build(ideal, paths, (0, 1), TargetConfig(float(r)), (0.0, d))
            m1 = ChannelModel.build(fir, paths, (0, 1), TargetConfig(float(r)), (0.0, d))
            z += np.exp(1j * (m1.pair_phase([0.1]) - m0.pair_phase([0.1])))
        measured = np.degrees(np.angle(z))
        f_if = if_phase_slope_hz(fir.scene, probe_total_delay(fir, ranges))
        eff = fir_effect(fir, d)
        predicted = eff["predicted_shift_ps"] * 1e-12 * 360 * f_if
        # first order in the filter's phase ripple: measured 10 % off with 5 taps (14 deg
        # ripple), 0.03 deg off with 33 taps (0.2 deg ripple): within a quarter of the ripple
        assert abs(measured - predicted) <= 0.25 * eff["phase_ripple_deg"]
        assert abs(measured) <= eff["phase_ripple_deg"]
    assert fir_effect(ideal, 0.1e-9)["predicted_shift_ps"] == 0.0


# ---------------------------------------------------------------- paper procedure

@pytest.mark.slow
def test_paper_procedure_minima_are_one_period_apart_and_its_optimum_is_off_coherence():
    """The paper's sweep as written (fixed eq. 23 amplitudes, one set angle, 25 ps steps) on
    the perfect default setup: its minima repeat about every period_s, the second pulled
    late because a period of delay moves J's echo by 1.3 range bins and the fixed amplitudes
    do not know it (measured: 1.10 ns apart); its optimum is not the coherence point (the
    fixed design's own error is traded against phase)."""
    from rtsgeom.calibration.paper import calibrate_pair_paper
    setup = build_setup(make_scene())
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, 1)
    cal = calibrate_pair_paper(setup, paths, (0, 1), probe, seed=1, span_s=(-0.5e-9, 1.5e-9))
    t, e = cal.sweep_delta_tau_s, cal.sweep_error_deg
    inner = np.arange(1, len(e) - 1)
    mins = inner[(e[inner] < e[inner - 1]) & (e[inner] <= e[inner + 1])]
    deep = sorted(mins, key=lambda k: e[k])[:2]
    step = t[1] - t[0]
    spacing = abs(t[deep[1]] - t[deep[0]])
    assert cal.period_s - step <= spacing <= cal.period_s + 0.15e-9
    coherent = pair_coherence(setup, paths, (0, 1), alphas=probe_angles(*probe.angle_rad[[0, 1]]),
                              near_s=cal.delta_tau_s).continuous_s
    assert abs(cal.delta_tau_s - coherent) > 2 * step  # measured: about 200 ps


# ---------------------------------------------------- calibration at the detected bin (13.1, 17)

def _offset_scene(radius_m, fe, dr_mm, tangential_mm=0.0, snr=True):
    def mutate(doc):
        if not snr:
            doc["radar"].pop("snr_db", None)
        doc["rts"]["arc_radius_m"] = radius_m
        doc["rts"]["front_ends"][fe]["radial_offset_mm"] = dr_mm
        if tangential_mm:
            doc["rts"]["front_ends"][1 - fe]["tangential_offset_mm"] = tangential_mm
    return make_scene(mutate)


def _closed_form_point(radius_m, fe, dr_mm, probe, snr=True):
    """The coherence point of the nominal setup (phasor model) moved by the closed form
    -(f_c + S t_mid - S tau) / (f_rts + S t_mid - S tau) * 2 dr / c0 (J; opposite for I)."""
    shift = CoherenceShift(build_setup(_offset_scene(radius_m, fe, 0.0, snr=snr)), probe)
    return shift.predicted(fe, dr_mm), shift.period



def _calibrated_off_coherence(radius_m, fe, dr_mm):
    """Calibrate pair (0, 1) of the offset setup: (setup, paths, probe, calibration, distance
    of the calibrated delay from the closed-form coherence point, wrapped into one period)."""
    setup = build_setup(_offset_scene(radius_m, fe, dr_mm))
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, setup.scene.seed)
    cal = calibrate_pair(setup, paths, (0, 1), probe, seed=setup.scene.seed)
    point, period = _closed_form_point(radius_m, fe, dr_mm, probe)
    return setup, paths, probe, cal, (cal.delta_tau_s - point + period / 2) % period - period / 2


# the grid's worst cases (75 ps off at +-0.75 mm on 0.5 and 1 m before the fix: CHANGELOG) and
# a 3 m arc; the full grid: python -m benchmarks.calibration_grid
@pytest.mark.slow
@pytest.mark.parametrize("radius, fe, dr_mm", [(0.5, 0, 0.75), (0.5, 1, -0.75), (1.0, 0, 0.75),
                                               (1.0, 1, -0.75), (3.0, 0, -0.6), (3.0, 1, 1.0)])
def test_calibration_lands_on_the_coherence_point(radius, fe, dr_mm):
    setup, paths, probe, cal, dist = _calibrated_off_coherence(radius, fe, dr_mm)
    assert abs(dist) < 10e-12
    assert cal.residual_error_deg < 0.02  # the full-chain confirmation at the chosen delay
    assert cal.frames_per_step >= 1 and cal.method == "phasor"


def test_closed_form_design_matches_the_root_finder():
    """The exact ratio in closed form (dP/du = 0 at the set angle, a quadratic in rho) is
    the root finder's on the searched beamformer peak, on a grid of radii, delays and
    angles."""
    from rtsgeom.synthesis.model import ChannelModel
    from rtsgeom.scene import TargetConfig
    for radius in (0.5, 1.0, 3.0):
        setup = build_setup(_noiseless(radius))
        paths = exact_paths(setup)
        th = np.sort(probe_front_ends(setup, paths, 1).angle_rad[[0, 1]])
        for delay in (0.0, 150e-12):
            for a in th[0] + np.array([0.1, 0.35, 0.6, 0.9]) * (th[1] - th[0]):
                m = ChannelModel.build(setup, paths, (0, 1), TargetConfig(20.0, 0.0, 10.0, a),
                                       (0.0, delay))
                ph = (0.0, float(m.pair_phase(probe_angles(*th))))
                fast = m._solve_pair_closed(a, ph)
                ref = m._solve_pair(a, ph, 12.0)
                assert fast == pytest.approx(ref, rel=1e-6)
                assert float(m.direction(m.pair_weights(fast, ph))) == pytest.approx(a, abs=1e-8)


@pytest.mark.slow
@pytest.mark.parametrize("radius, fe, dr_mm", [(0.5, 0, 0.75), (1.0, 1, -0.75)])
def test_exact_linearity_after_calibration_on_straddling_setups(radius, fe, dr_mm):
    from rtsgeom.analysis.linearity import linearity
    setup = build_setup(_offset_scene(radius, fe, dr_mm))
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, setup.scene.seed)
    cal = calibrate_pair(setup, paths, (0, 1), probe, seed=setup.scene.seed)
    lin = linearity(setup, paths, (0, 1), "exact", probe, cal, 11, setup.scene.seed)
    assert lin.max_abs_error_deg <= 0.02


@pytest.mark.slow
@pytest.mark.parametrize("offsets", [None, (0, 0.75, 0.5)])
def test_fast_calibration_agrees_with_the_full_chain(offsets):
    """The phasor-model sweep and every step through the ADC-cube chain choose
    the same delay (default scene, and one with radial and tangential mounting offsets)."""
    scene = make_scene() if offsets is None else _offset_scene(1.0, *offsets)
    setup = build_setup(scene)
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, scene.seed)
    fast = calibrate_pair(setup, paths, (0, 1), probe, seed=scene.seed)
    chain = calibrate_pair(setup, paths, (0, 1), probe, seed=scene.seed, full_chain=True)
    assert chain.method == "full-chain"
    assert abs(fast.delta_tau_s - chain.delta_tau_s) < 3e-12
    # the per-step criteria agree too (same design; independent one-frame noise of ~0.005 deg
    # per probe on each side, so no bias and a noise-sized spread). The fine windows are
    # centred on each sweep's own coarse minimum: compare on the common delays, near the
    # chosen one (+-period/8)
    t_f, t_c = fast.refine_delta_tau_s, chain.refine_delta_tau_s
    common = np.intersect1d(np.round(t_f * 1e15), np.round(t_c * 1e15))
    near = np.abs(common * 1e-15 - fast.delta_tau_s) < fast.period_s / 8
    ef = fast.refine_error_deg[np.isin(np.round(t_f * 1e15), common[near])]
    ec = chain.refine_error_deg[np.isin(np.round(t_c * 1e15), common[near])]
    assert ef.size >= 10
    diff = ef - ec
    assert abs(np.mean(diff)) < 0.002
    assert np.max(np.abs(diff)) < 0.03


def test_calibration_file_round_trip(tmp_path, capsys):
    """calibrate --out DIR writes DIR/calibration.json; run --calibration FILE uses it and
    gives what a run that calibrates itself gives; a foreign file is a clean exit 2."""
    out = tmp_path / "cal"
    assert main(["calibrate", str(DEFAULT_SCENE), "--out", str(out), "--quiet"]) == 0
    f = out / "calibration.json"
    doc = json.loads(f.read_text())
    assert doc["format"] == "rtsgeom-calibration" and len(doc["gain_correction"]) == 2
    assert main(["run", str(DEFAULT_SCENE), "--out", str(tmp_path / "a"), "--quiet",
                 "--no-report"]) == 0
    assert main(["run", str(DEFAULT_SCENE), "--out", str(tmp_path / "b"), "--quiet",
                 "--no-report", "--calibration", str(f)]) == 0
    a = json.loads((tmp_path / "a" / "summary.json").read_text())
    b = json.loads((tmp_path / "b" / "summary.json").read_text())
    assert b["calibration"]["source"] == "file"
    assert not any("another setup" in w for w in b["warnings"]), b["warnings"]
    assert a["calibration"]["channel_delay_offsets_s"] == b["calibration"]["channel_delay_offsets_s"]
    assert a["targets"] == b["targets"]
    assert main(["adc", str(DEFAULT_SCENE), "--out", str(tmp_path / "c.npy"), "--quiet",
                 "--calibration", str(f)]) == 0
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"pair": [0, 1]}))
    capsys.readouterr()
    assert main(["run", str(DEFAULT_SCENE), "--out", str(tmp_path / "d"), "--quiet",
                 "--calibration", str(bad)]) == 2
    assert "calibration" in capsys.readouterr().err
    # values no calibration gives are refused naming the field, not run into (a gain of -1
    # ran with targets 3 deg off, a delay of 1 s detected nothing, NaN ended in a traceback)
    for key, value, field in (("gain_correction", [-1.0, 1.0], "gain_correction[0] = -1"),
                              ("gain_correction", [1.0, float("nan")], "gain_correction[1]"),
                              ("gain_correction", [1.0, 1e300], "gain_correction[1]"),
                              ("delta_tau_s", 1.0, "pairs[0].delta_tau_s = 1 s"),
                              ("delta_tau_s", float("nan"), "pairs[0].delta_tau_s = nan")):
        wrong = dict(doc, **{key: value})
        bad.write_text(json.dumps(wrong))
        assert main(["run", str(DEFAULT_SCENE), "--out", str(tmp_path / "e"), "--quiet",
                     "--calibration", str(bad)]) == 2, key
        assert field in capsys.readouterr().err


@pytest.mark.slow
def test_one_frame_per_step_keeps_the_noise_pull_below_2_ps():
    """The fitted minimum takes receiver noise linearly: with the frames the calibration
    chooses (one on the default scene), sweeps with different noise land within 2 ps of the
    noiseless sweep (same front-end probe, so only the sweep's noise differs)."""
    setup = build_setup(make_scene())
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, 1)
    quiet = build_setup(_noiseless())
    ref = calibrate_pair(quiet, exact_paths(quiet), (0, 1), probe, seed=1).delta_tau_s
    got = []
    for seed in range(5):
        cal = calibrate_pair(setup, paths, (0, 1), probe, seed=seed)
        assert (2 * cal.one_frame_scatter_ps / np.sqrt(cal.frames_per_step)) <= 2.0
        got.append(cal.delta_tau_s)
    assert np.max(np.abs(np.array(got) - ref)) < 2e-12


# ------------------------------------------- the chosen delay is one the RTS can set (13.4)

@pytest.mark.parametrize("res_ps, fractional", [(1.0, True), (5.0, True), (25.0, True),
                                                (50.0, True), (250.0, False)])
def test_calibrated_delay_is_realisable_and_the_residual_is_reported(res_ps, fractional):
    """On a grid of RTS delay resolutions (fractional-delay steps of 1 to 50 ps, and whole
    4 GSPS samples without the FIR): every fine-sweep step and the chosen delay are whole
    multiples of the resolution, the RTS realises the chosen offset exactly on both probes'
    delays, the reported residual is the fit's optimum minus the chosen delay (at most half
    a step), and the chosen delay is the realisable one nearest the coherence point."""
    from rtsgeom.calibration.steps import realisable
    from rtsgeom.rts.fir import realised_delay
    from rtsgeom.rts.channels import requested_delay

    def mutate(doc):
        doc["radar"].pop("snr_db", None)
        doc["rts"]["fractional_delay"] = fractional
        doc["rts"]["fractional_delay_step_s"] = res_ps * 1e-12 if fractional else 1e-12
        doc["rts"]["calibration_step_ps"] = max(25.0, res_ps)
    setup = build_setup(make_scene(mutate))
    rts = setup.scene.rts
    res = rts.delay_resolution_s
    assert res == pytest.approx(res_ps * 1e-12)
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, 1)
    cal = calibrate_pair(setup, paths, (0, 1), probe, seed=1)
    assert cal.delay_resolution_s == res
    steps = np.concatenate([[cal.delta_tau_s], cal.refine_delta_tau_s]) / res
    assert np.allclose(steps, np.round(steps), rtol=0, atol=1e-6)
    assert abs(cal.quantisation_residual_s) <= res / 2 * (1 + 1e-9)
    tau = requested_delay(setup.scene, np.asarray(cal.probe_ranges_m))
    moved = (realised_delay(tau + cal.delta_tau_s, rts.f_s_hz, rts.fractional_delay,
                            rts.fractional_delay_step_s)
             - realised_delay(tau, rts.f_s_hz, rts.fractional_delay, rts.fractional_delay_step_s))
    assert np.allclose(moved, cal.delta_tau_s, rtol=0, atol=1e-16)
    # the coherence point on the same geometry with a (near) continuous delay: the model of a
    # coarse RTS rounds every delay it is given, which makes its phase a staircase
    fine = build_setup(make_scene(lambda doc: doc["rts"].update(fractional_delay_step_s=1e-15)))
    point = pair_coherence(fine, exact_paths(fine), (0, 1),
                           alphas=probe_angles(*probe.angle_rad[[0, 1]]),
                           near_s=cal.delta_tau_s).continuous_s
    fitted = cal.delta_tau_s + cal.quantisation_residual_s
    assert cal.delta_tau_s == pytest.approx(float(realisable(fitted, res)), abs=1e-18)
    # the fit finds the coherence point to a few ps whatever the step; at 250 ps (3 fine
    # points) the chosen delay is the sweep's realisable point nearest it
    assert abs(fitted - point) <= (5e-12 if res < 100e-12 else res / 2)
    assert abs(cal.delta_tau_s - point) <= res / 2 + 5e-12
    round_trip = type(cal).from_dict(json.loads(json.dumps(cal.to_dict())))
    assert round_trip.quantisation_residual_s == cal.quantisation_residual_s
    assert round_trip.delay_resolution_s == res


# ------------------------------ the FIR moves the calibration and linearity as predicted (13.4)

def _fir_pair(taps, radius_m=1.0):
    """Ideal and windowed-sinc variants of one noiseless setup with a (near) continuous delay
    step, so that the calibration's rounding does not hide sub-ps shifts."""
    def scene(model):
        def mutate(doc):
            doc["radar"].pop("snr_db", None)
            doc["rts"].update(fractional_delay_taps=taps, fractional_delay_filter=model,
                              fractional_delay_step_s=1e-15, arc_radius_m=radius_m)
        return make_scene(mutate)
    return build_setup(scene("ideal")), build_setup(scene("windowed-sinc"))


@pytest.mark.parametrize("taps, radius_m", [(3, 1.0), (4, 0.5), (5, 1.0), (5, 3.0)])
def test_fir_calibration_lands_on_the_filtered_setups_coherence_point(taps, radius_m):
    """With a short fractional-delay FIR the calibrated (fitted) delay lands on the coherence
    point of the setup with that filter (``pair_coherence``, Newton on the phase mismatch,
    no sweep): within 0.3 ps plus 12 % of the filter's phase ripple as a delay (the ripple
    cycles with the setting every 1/f_s and bends the sweep's curves: 3.4 ps at 5 taps and
    1 m, 36 ps at 4 taps and 0.5 m, where the fit sits 4 ps off), and within 0.3 ps without
    a filter. Before the sweep's fit took the filter's setting-dependent phase out, the 5-tap
    calibration landed 33 ps off."""
    from rtsgeom.calibration.fir import fir_effect
    from rtsgeom.calibration.pair import pair_coherence
    ideal, fir = _fir_pair(taps, radius_m)
    paths = exact_paths(ideal)
    probe = probe_front_ends(ideal, paths, 1)
    c_i = calibrate_pair(ideal, paths, (0, 1), probe, seed=1)
    c_f = calibrate_pair(fir, paths, (0, 1), probe, seed=1)
    p_i = pair_coherence(ideal, paths, (0, 1), probe, near_s=c_i.fit_s).continuous_s
    p_f = pair_coherence(fir, paths, (0, 1), probe, near_s=c_f.fit_s).continuous_s
    eff = fir_effect(fir, c_f.delta_tau_s, ranges=c_f.probe_ranges_m)
    ripple_s = eff["phase_ripple_deg"] / 360 * c_f.period_s  # the ripple as a delay
    assert abs(c_i.fit_s - p_i) <= 0.3e-12
    assert abs(c_f.fit_s - p_f) <= 0.3e-12 + 0.12 * ripple_s
    assert fir_effect(ideal, c_i.delta_tau_s)["predicted_shift_ps"] == 0.0


@pytest.mark.parametrize("taps", [3, 5])
def test_fir_changes_linearity_by_no_more_than_its_phase_ripple_explains(taps):
    """Exact-mode linearity after calibration, with the FIR minus without it, at every
    set-point: at most what a phase error of J as large as the filter's phase swing at the
    bin over all its settings (``fir_bin_gain``, mu in [0, 1)) would cause at that set-point
    on the ideal model (the error is second order in the phase near coherence). With 33 taps
    both are below 1e-5 deg. Before the fit and ``pair_design`` accounted for the setting-
    dependent phase, the 5-tap change was 0.041 deg, ten times this bound."""
    from rtsgeom.calibration.probes import mean_air_delay
    from rtsgeom.calibration.fir import fir_bin_gain
    from rtsgeom.analysis.linearity import linearity
    from rtsgeom.calibration.phasor import PairChannels
    from rtsgeom.pipeline.pair import pair_design
    from rtsgeom.synthesis.model import ChannelModel
    from rtsgeom.rts.channels import requested_delay
    from rtsgeom.scene import TargetConfig
    ideal, fir = _fir_pair(taps)
    paths = exact_paths(ideal)
    probe = probe_front_ends(ideal, paths, 1)
    c_i = calibrate_pair(ideal, paths, (0, 1), probe, seed=1)
    c_f = calibrate_pair(fir, paths, (0, 1), probe, seed=1)
    l_i = linearity(ideal, paths, (0, 1), "exact", probe, c_i, 7, 1)
    l_f = linearity(fir, paths, (0, 1), "exact", probe, c_f, 7, 1)
    change = l_f.error_deg - l_i.error_deg
    # the filter's phase at the bin over all its settings (one sample period of delay)
    scene = fir.scene
    rng = float(probe_ranges(fir, 1)[0])
    tau = float(requested_delay(scene, rng)) + float(np.mean(mean_air_delay(fir)))
    d = float(requested_delay(scene, rng)) + np.linspace(0, 1 / scene.rts.f_s_hz, 64)
    psi = np.unwrap(np.angle(fir_bin_gain(scene, d, np.full(d.size, tau))))
    swing = float(np.ptp(psi))
    assert swing > np.radians(1.0)  # a filter with something to show
    alphas = probe_angles(*probe.angle_rad[[0, 1]])
    for k, a in enumerate(np.radians(l_i.set_deg)):
        t = TargetConfig(rng, 0.0, 10.0, float(a))
        _, _, rho, off_j = pair_design(ideal, paths,
                                       PairChannels((0, 1), (0.0, c_i.delta_tau_s),
                                                    probe.gain_correction[[0, 1]]),
                                       t, "exact", alphas)
        m = ChannelModel.build(ideal, paths, (0, 1), t, (0.0, off_j))
        ph = float(m.pair_phase(alphas))
        worst = max(abs(float(m.direction(m.pair_weights(rho, (0.0, ph + s))))
                        - float(m.direction(m.pair_weights(rho, (0.0, ph)))))
                    for s in np.linspace(-swing, swing, 9))
        assert abs(change[k]) <= np.degrees(worst) + 2e-5
    assert np.max(np.abs(change)) > 0  # the filter is in the chain


# --------------------------------- the 0.05 mm offset grid, sampled

def _grid_sample(n_random=2):
    """Setups of the committed full grid (``python -m benchmarks.calibration_grid
    --linearity 11``: radial offsets -1..1 mm in 0.05 mm steps on either front end at
    R_c = 0.5, 1, 3 m): per radius the one with the largest linearity error there, and
    ``n_random`` more drawn with a fixed seed."""
    from pathlib import Path
    doc = json.loads((Path(__file__).resolve().parents[2] / "benchmarks"
                      / "calibration_grid_linearity.json").read_text())
    rows = doc["rows"]
    assert doc["summary"]["step_mm"] == 0.05 and len(rows) == 246
    worst = [max((r for r in rows if r["radius_m"] == rc), key=lambda r: r["linearity_max_abs_deg"])
             for rc in (0.5, 1.0, 3.0)]
    pick = np.random.default_rng(13).choice(len(rows), n_random, replace=False)
    return [(r["radius_m"], r["front_end"], r["radial_offset_mm"])
            for r in worst + [rows[k] for k in pick]]


@pytest.mark.parametrize("radius, fe, dr_mm", _grid_sample())
def test_grid_sample_calibrates_to_coherence_and_linearity_within_spec(radius, fe, dr_mm):
    """The calibrated delay within 10 ps of the closed-form coherence point and exact-mode
    linearity (11 set-points, receiver noise on) at or below 0.02 deg at every set-point
    (about 1.3 s of CPU per setup)."""
    from rtsgeom.analysis.linearity import linearity
    setup, paths, probe, cal, dist = _calibrated_off_coherence(radius, fe, dr_mm)
    assert abs(dist) < 10e-12
    lin = linearity(setup, paths, (0, 1), "exact", probe, cal, 11, setup.scene.seed)
    assert np.all(np.isfinite(lin.detected_deg))
    assert lin.max_abs_error_deg <= 0.02


@pytest.mark.parametrize("samples,adc_rate_hz", [(128, 12.5e6), (256, 25e6)])
@pytest.mark.parametrize("training", [4, 8, 12])
def test_probes_clear_each_others_cfar_window(samples, adc_rate_hz, training):
    """probe_front_ends puts each front end alone at its own range; the probes are spaced by
    more than the CFAR window (guard + training cells) on any cube, so every front end is
    detected (on a 128-sample cube 8 bins used to leave front end 1 undetected: a silent NaN,
    now a RuntimeWarning)."""
    import warnings

    from rtsgeom.calibration.probes import probe_ranges

    def small(doc):
        doc["radar"].pop("snr_db", None)
        doc["radar"].update(chirps_per_tx=32, samples_per_chirp=samples, adc_rate_hz=adc_rate_hz)
        doc["radar"]["cfar"] = {"training_cells": [training, 4], "guard_cells": [2, 2]}
    setup = build_setup(make_scene(small))
    radar = setup.scene.radar
    ranges = probe_ranges(setup, setup.fe.count)
    assert np.min(np.diff(ranges)) / radar.range_resolution_m > 2 + training
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        probe = probe_front_ends(setup, exact_paths(setup))
    assert np.all(np.isfinite(probe.angle_rad))


def test_calibration_file_names_the_setup_it_was_made_on():
    """A calibration is a measurement of one setup: its fingerprint (``setup_sha256``) moves
    with the arc, a front end's mounting or channel and the RuT's chirp, not with the
    scenario (targets, seed, SNR); a file made before a front end was moved is applied with
    a warning (applied silently, such a file gave -3.7 deg errors and exit 0)."""
    from rtsgeom.calibration.file import calibration_mismatch, setup_fingerprint
    from rtsgeom.pipeline.plan import plan_targets

    def fe1(**kw):
        return lambda d: d["rts"]["front_ends"][1].update(kw)
    base = setup_fingerprint(make_scene())
    same = [make_scene(lambda d: d.update(seed=7)), make_scene(snr_db=5.0),
            make_scene(lambda d: d["targets"].pop()),
            # how many targets a cell reports or a channel carries: not what is measured
            # (these moved every bundled scene's fingerprint when they were added)
            make_scene(angle_peaks_max=4), make_scene(angle_peak_threshold=0.2),
            make_scene(lambda d: d["rts"].update(max_targets_per_channel=2))]
    assert all(setup_fingerprint(s) == base for s in same)
    moved = [make_scene(fe1(radial_offset_mm=0.2)), make_scene(fe1(phase_offset_deg=30.0)),
             make_scene(lambda d: d["rts"].update(arc_radius_m=1.2)),
             make_scene(f_c_hz=77.5e9)]
    assert len({setup_fingerprint(s) for s in moved} | {base}) == len(moved) + 1
    doc = {"setup_sha256": base}
    assert calibration_mismatch(doc, same[0]) is None
    assert calibration_mismatch({}, moved[0]) is None  # a file from before the fingerprint
    nominal = build_setup(make_scene())
    paths = exact_paths(nominal)
    probe = probe_front_ends(nominal, paths)
    cal = calibrate_pair(nominal, paths, (0, 1), probe)
    doc = {"pairs": [cal.to_dict()], "front_end_angles_deg": np.degrees(probe.angle_rad),
           "setup_sha256": base}
    for scene, warned in ((make_scene(), False), (moved[0], True)):
        setup = build_setup(scene)
        _, _, warnings = plan_targets(setup, exact_paths(setup), "exact", calibration=doc)
        assert any("made on another setup" in w for w in warnings) is warned, warnings


def test_calibration_fingerprint_follows_file_contents_not_paths(tmp_path):
    """The same scene and antenna table in two folders: one fingerprint (a moved project
    keeps its calibrations); an edited table: another. The sheet, the ray tracing, the
    calibration procedure's steps and the RTS's noise are not the setup measured."""
    from rtsgeom.calibration.file import setup_fingerprint
    from rtsgeom.scene import load_scene
    text = DEFAULT_SCENE.read_text().replace(
        "[radar.cfar]", '[radar.pattern]\nkind = "table"\ntable = "pat.csv"\n\n[radar.cfar]')

    def scene_in(folder, gain_db):
        folder.mkdir()
        rows = ["azimuth_deg,elevation_deg,gain_db,phase_deg"]
        rows += [f"{a},{e},{gain_db},0" for a in range(-90, 91, 10) for e in range(-90, 91, 10)]
        (folder / "pat.csv").write_text("\n".join(rows))
        (folder / "s.toml").write_text(text)
        return load_scene(folder / "s.toml")
    a, b, c = (scene_in(tmp_path / n, g) for n, g in (("a", 0.0), ("b", 0.0), ("c", -3.0)))
    assert setup_fingerprint(a) == setup_fingerprint(b) != setup_fingerprint(c)
    base = setup_fingerprint(make_scene())
    for mut in (lambda d: d["sheet"].update(enabled=False),
                lambda d: d["rts"].update(calibration_step_ps=10.0)):
        assert setup_fingerprint(make_scene(mut)) == base


def test_fine_sweep_is_fitted_up_to_its_first_jump_either_side():
    """``continuous_steps``: a column that jumps (a probe's bin changing part-way) keeps the
    steps between the jumps around the centre, a smooth column (any curvature) all of them;
    the fitted centre of the kept curve is its centre of symmetry again."""
    from rtsgeom.calibration.fit import CentreFit, continuous_steps, fit_centre
    period = 1e-9
    d = np.arange(-25, 26) * 10e-12  # +-period/4 in 10 ps steps, centre at index 25
    s0 = 7e-12
    smooth = 0.02 * (1 - np.cos(2 * np.pi * (d - s0) / period)) + 1e-3
    jumped = smooth.copy()
    jumped[:8] += 0.013  # a jump between steps 7 and 8 and one between 41 and 42
    jumped[42:] -= 0.021
    e = np.column_stack([smooth, jumped])
    kept = continuous_steps(e, 25)
    np.testing.assert_array_equal(kept[:, 0], smooth)
    assert np.isnan(kept[:8, 1]).all() and np.isnan(kept[42:, 1]).all()
    np.testing.assert_array_equal(kept[8:42, 1], jumped[8:42])
    assert fit_centre(d, kept, period, 0.0, CentreFit(search_s=30e-12)) == pytest.approx(
        s0, abs=0.3e-12)
    # without the cut the jumps pull the fitted centre off
    assert abs(fit_centre(d, e, period, 0.0, CentreFit(search_s=30e-12)) - s0) > 1e-12
    assert continuous_steps(e[:5], 2).shape == (5, 2)  # too few steps: as they are


def test_fine_sweep_cut_drops_a_one_step_excursion_whatever_the_noise():
    """``continuous_steps``: a probe detected in the other bin at one step only is a one-step
    excursion, two jumps in a row whose departures are equal but for the noise; the cut starts
    at the excursion's step on either side of the centre, never one step later (which kept
    it and moved the fitted centre by 5 ps on sphere4's side-by-side pair), for every draw
    of noise far below the excursion."""
    from rtsgeom.calibration.fit import continuous_steps
    period = 1e-9
    d = np.arange(-25, 26) * 10e-12
    smooth = 0.02 * (1 - np.cos(2 * np.pi * (d - 7e-12) / period))
    rng = np.random.default_rng(5)
    for _ in range(40):
        e = smooth + 1e-4 * rng.standard_normal(smooth.size)
        e[28] += 0.018  # above the centre (index 25)
        e[20] -= 0.018  # below it
        kept = continuous_steps(e[:, None], 25)[:, 0]
        assert np.isnan(kept[28:]).all() and np.isfinite(kept[21:28]).all()
        assert np.isnan(kept[:21]).all()


def test_every_pair_figure_names_its_pair_and_quotes_the_printed_residual(tmp_path, capsys,
                                                                         monkeypatch):
    """calibrate --pair all --out DIR: each pair's figure is titled with the scene and its pair
    and marks the chosen delay at the residual stdout and calibration.json give (its figures
    were titled "Phase coherency calibration" alone and quoted the sweep interpolated at the
    chosen delay, 0.0038 deg where stdout said 0.0010 deg)."""
    import rtsgeom.viz.figures as figures
    saved = {}
    real = figures.save_figure

    def keep(fig, path):
        saved[path.name] = (fig.axes[0].get_title(),
                            [t.get_text() for t in fig.axes[0].get_legend().get_texts()])
        return real(fig, path)
    monkeypatch.setattr(figures, "save_figure", keep)
    out = tmp_path / "cal"
    assert main(["calibrate", str(DEFAULT_SCENE), "--pair", "all", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    doc = json.loads((out / "calibration.json").read_text())
    assert len(saved) == len(doc["pairs"]) >= 1
    for cal in doc["pairs"]:
        i, j = cal["pair"]
        title, labels = saved[f"calibration_sweep_{i}_{j}.png"]
        assert title == f"{DEFAULT_SCENE.stem}: phase coherency calibration, front ends {i}-{j}"
        res = f"{cal['residual_error_deg']:.4f} deg"
        assert f"pair ({i}, {j}): " in printed and res in printed
        assert [lab for lab in labels if lab.startswith("chosen:")] == [
            f"chosen: {cal['delta_tau_s'] * 1e12:.1f} ps (residual {res})"]
