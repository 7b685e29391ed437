"""Results that claim to hold for any taper, checked for every window.

The windows are ``none``, ``hann``, ``hamming``, ``blackman`` (``registry.WINDOWS``) and appear
three times in a scene: ``radar.range_window``, ``radar.doppler_window``, ``radar.angle_window``.
The tests here use small cubes (32 chirp loops, 128 samples) so the grid stays fast. The
amplitude modes (``exact``, ``array-factor``, ``paper``) are checked at phasor level on the
channel model, where each claim is made.
"""

from __future__ import annotations

import numpy as np
import pytest

from conftest import CoherenceShift, far_field, make_scene, quiet
from rtsgeom.synthesis.model import ChannelModel
from rtsgeom.analysis.tolerance.phasors import CASES, ChannelPhasors
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.radar import process, synthesize
from rtsgeom.radar.frame import simulate
from rtsgeom.radar.phasors import bin_response
from rtsgeom.radar.processing import estimate_angles, range_doppler, refine_angles
from rtsgeom.radar.windows import window
from rtsgeom.scene.registry import WINDOWS as WINDOW_REGISTRY
from rtsgeom.rts.channels import Echoes, build_echoes, program_nearest
from rtsgeom.pipeline.matching import match_targets
from rtsgeom.scene import TargetConfig

WINDOWS = tuple(WINDOW_REGISTRY)


def test_the_grid_covers_every_registered_window():
    assert set(WINDOWS) == {"none", "hann", "hamming", "blackman"}


def _quiet(doc, **radar):
    quiet(doc, small=True, **radar)


def _far(doc, **radar):
    _quiet(doc, **radar)
    far_field(doc)
    doc["targets"] = []


@pytest.mark.parametrize("range_window", WINDOWS)
@pytest.mark.parametrize("doppler_window", WINDOWS)
def test_on_bin_echo_has_the_windows_coherent_gain(range_window, doppler_window):
    """An echo on the range and Doppler bin grid peaks in its own cell with power
    V |a|^2 (sum w_r)^2 (sum w_d)^2 for every pair of windows, and is found there by CFAR at
    its range and velocity."""
    scene = make_scene(lambda d: _quiet(d, range_window=range_window,
                                        doppler_window=doppler_window)
                       or d.update(targets=[]))
    r = scene.radar
    rut = build_setup(scene).rut
    k, m = 23, 5  # range bin, Doppler bin (DFT index)
    tau = k * r.adc_rate_hz / (r.slope_hz_per_s * r.samples_per_chirp)
    f_d = m / (r.chirps_per_tx * r.tdm_cycle_s)
    z = np.zeros(1)
    ech = Echoes(np.full((1, rut.num_virtual), tau), z, z, np.full(1, f_d),
                 np.full((1, rut.num_virtual), 0.5 + 0.0j), np.zeros(1, int), np.zeros(1, int),
                 np.zeros(1, int), np.zeros(1, int))
    # the beat carries f_D too: keep the range bin exact by removing it from the beat
    ech = Echoes(ech.tau_air_s - f_d / r.slope_hz_per_s, *[getattr(ech, n) for n in (
        "tau_if_s", "f_if_hz", "doppler_hz", "amplitude", "target", "front_end", "kind",
        "order")])
    cube = synthesize(ech, r, rut)
    rd = range_doppler(cube)
    d_bin = m + r.chirps_per_tx // 2
    w_r, w_d = window(range_window, r.samples_per_chirp), window(doppler_window, r.chirps_per_tx)
    want = rut.num_virtual * 0.25 * np.sum(w_r) ** 2 * np.sum(w_d) ** 2
    assert np.unravel_index(np.argmax(rd.power), rd.power.shape) == (k, d_bin)
    assert rd.power[k, d_bin] == pytest.approx(want, rel=1e-4)


@pytest.mark.parametrize("range_window,doppler_window,angle_window",
                         [(w, w, w) for w in WINDOWS] + [("none", "blackman", "hann"),
                                                         ("hamming", "none", "blackman")])
def test_phasor_model_matches_the_fft_chain(range_window, doppler_window, angle_window):
    """``bin_response`` (the phasor model every design uses) equals the FFT chain's spectrum at
    each detection for every window, and so do the angles beamformed from it."""
    scene = make_scene(lambda d: _quiet(d, range_window=range_window,
                                        doppler_window=doppler_window,
                                        angle_window=angle_window))
    setup = build_setup(scene)
    ech = build_echoes(setup, exact_paths(setup), program_nearest(scene, setup))
    cube = synthesize(ech, scene.radar, setup.rut)
    rd, det = process(cube)
    assert len(det) >= len(scene.targets)
    b = bin_response(ech, scene.radar, setup.rut, det.range_bin, det.doppler_bin).sum(1)
    ref = rd.spectrum[det.range_bin, det.doppler_bin]
    assert np.max(np.abs(b - ref)) < 2e-5 * np.max(np.abs(ref))


@pytest.mark.parametrize("angle_window", WINDOWS)
def test_single_front_end_bias_falls_like_one_over_r_for_every_taper(angle_window):
    """Far field, no Rx/Tx split: each front end alone is detected off its geometric angle
    mainly by the RuT's group parallax, which is first order in 1/R for any taper (the taper
    changes its size, README): 4x the radius, a quarter of the bias, and below 0.03 deg at
    40 m."""
    bias = []
    for radius in (10.0, 40.0):
        def mutate(doc):
            _far(doc, angle_window=angle_window)
            doc["rts"]["arc_radius_m"] = radius
            doc["targets"] = [{"range_m": 50.0, "angle_deg": 3.4},
                              {"range_m": 60.0, "angle_deg": 12.2}]
        scene = make_scene(mutate)
        setup = build_setup(scene)
        _, cube = simulate(setup, exact_paths(setup), program_nearest(scene, setup))
        rd, det = process(cube)
        got = [e["detection"]["angle_deg"] for e in match_targets(scene, det, rd)]
        bias.append(np.asarray(got) - np.degrees(setup.fe_azimuth_rad()))
    assert np.all(np.abs(bias[1]) < 0.03)
    np.testing.assert_allclose(bias[1] * 4, bias[0], rtol=0.2)  # + a range-dependent beat term


@pytest.fixture(scope="module", params=WINDOWS)
def far_model(request):
    scene = make_scene(lambda d: _far(d, angle_window=request.param))
    setup = build_setup(scene)
    cm = ChannelModel.build(setup, exact_paths(setup), (0, 1), TargetConfig(20.0))
    th = setup.fe_azimuth_rad()
    phases = (0.0, float(cm.pair_phase(th[0] + np.array([0.25, 0.75]) * (th[1] - th[0]))))
    return request.param, cm, np.linspace(th[0], th[1], 7)[1:-1], phases


def _worst_deg(cm, alphas, phases, mode):
    return max(abs(np.degrees(cm.direction(cm.pair_weights(cm.pair_ratio(a, phases, mode), phases))
                              - a)) for a in alphas)


def test_exact_mode_puts_every_set_point_on_its_angle(far_model):
    """``exact`` solves the ratio on the modelled beamformer, taper included: exact for any
    angle window."""
    _, cm, alphas, phases = far_model
    assert _worst_deg(cm, alphas, phases, "exact") < 1e-6


def test_array_factor_mode_in_the_ideal_far_field(far_model):
    """``array-factor``'s closed form is the RuT's own (tapered) array factor, so it stays
    within 0.025 deg in the ideal far field for every angle window (README); with the
    untapered Dirichlet kernel a taper put it 0.14 (hamming) to 0.24 deg (blackman) off."""
    window_name, cm, alphas, phases = far_model
    assert _worst_deg(cm, alphas, phases, "array-factor") < 0.025


def test_paper_mode_is_exact_only_at_the_midpoint(far_model):
    """``paper``'s sinc is not the 8-element beam: off in between (0.1-0.35 deg) for every
    window, exact at the symmetric mid-point only for the untapered beam it was derived for."""
    window_name, cm, alphas, phases = far_model
    err = _worst_deg(cm, alphas, phases, "paper")
    assert 0.1 < err < 0.35
    mid = float(np.mean(cm.setup.fe_azimuth_rad()))
    mid_err = abs(np.degrees(cm.direction(cm.pair_weights(cm.pair_ratio(mid, phases, "paper"),
                                                          phases)) - mid))
    if window_name == "none":
        assert mid_err < 0.05


@pytest.fixture(scope="module", params=WINDOWS)
def pair_phasors(request):
    scene = make_scene(lambda d: _quiet(d, angle_window=request.param))
    return ChannelPhasors.build(build_setup(scene), (0, 1), points=5)


def test_tolerance_refine_matches_the_grid_search_and_calibrates_to_zero(pair_phasors):
    """The tolerance study's Newton refinement agrees with the grid search, and its nominal
    calibrated synthesis (exact amplitudes) is on the set angles, for every angle window."""
    model = pair_phasors
    rut, radar = model.setup.rut, model.setup.scene.radar
    x = model.x_nominal
    rng = np.random.default_rng(1)
    rho = np.exp(rng.uniform(-2, 2, 50))
    snaps = x[0] + (rho * np.exp(1j * rng.uniform(-1, 1, 50)))[:, None] * x[1]
    got = refine_angles(snaps, rut, radar, np.full(50, np.radians(8.0)))
    ref = estimate_angles(snaps, rut, radar)
    assert np.max(np.abs(np.degrees(got - ref))) < 2e-5
    zero = np.zeros((2, 3))
    assert np.max(np.abs(model.angle_errors(zero, "calibrated"))) < 1e-4
    assert set(CASES) >= {"uncalibrated", "calibrated"}


@pytest.mark.parametrize("range_window", WINDOWS)
@pytest.mark.parametrize("doppler_window", WINDOWS)
def test_fft_snr_gain_is_the_link_budgets_window_loss(range_window, doppler_window):
    """White noise and an on-bin tone through ``range_doppler``: the SNR gain of the windowed
    range and Doppler FFTs is N L (sum w)^2 / (N sum w^2) per axis, the factor the link budget
    (``link.window_snr_loss``) and the calibration's noise model use, for every pair of
    windows (noise power per cell sum w_r^2 sum w_d^2 sigma^2, tone (sum w_r)^2 (sum w_d)^2)."""
    import dataclasses
    from rtsgeom.radar.budget import window_snr_loss
    scene = make_scene(lambda d: _quiet(d, range_window=range_window,
                                        doppler_window=doppler_window) or d.update(targets=[]))
    r = scene.radar
    rut = build_setup(scene).rut
    n_l, n_s, v = r.chirps_per_tx, r.samples_per_chirp, rut.num_virtual
    k, m = 17, 3
    tone = 0.01 * np.exp(2j * np.pi * (k * np.arange(n_s) / n_s
                                       + m * np.arange(n_l)[:, None] / n_l))[:, None, :]
    ech = Echoes(np.zeros((0, v)), *[np.zeros(0)] * 3, np.zeros((0, v), complex),
                 *[np.zeros(0, int)] * 4)
    empty = synthesize(ech, r, rut)
    rng = np.random.default_rng(7)
    sigma2 = 2.0
    frames = 8
    noise_power = []
    for _ in range(frames):
        z = np.sqrt(sigma2 / 2) * (rng.standard_normal((n_l, v, n_s))
                                   + 1j * rng.standard_normal((n_l, v, n_s)))
        noise_power.append(range_doppler(dataclasses.replace(empty, data=z.astype(np.complex64))
                                         ).power.mean() / v)
    sig = range_doppler(dataclasses.replace(
        empty, data=np.broadcast_to(tone, (n_l, v, n_s)).astype(np.complex64)))
    p_sig = sig.power[k, m + n_l // 2] / v
    gain = (p_sig / np.mean(noise_power)) / (0.01 ** 2 / sigma2)
    closed = n_s * n_l * window_snr_loss(range_window, n_s) * window_snr_loss(doppler_window, n_l)
    w_r, w_d = window(range_window, n_s), window(doppler_window, n_l)
    assert np.mean(noise_power) == pytest.approx(sigma2 * np.sum(w_r ** 2) * np.sum(w_d ** 2),
                                                 rel=0.03)
    assert gain == pytest.approx(closed, rel=0.03)


@pytest.mark.parametrize("angle_window", WINDOWS)
@pytest.mark.parametrize("radius", [0.5, 1.0, 3.0])
def test_exact_mode_hits_the_set_angle_in_the_near_field_for_every_taper(angle_window, radius):
    """``exact`` solves the pair's ratio on the modelled (tapered) beamformer of the real
    near-field geometry: at a calibration delay offset too, every set-point between the two
    front ends' detected angles is the modelled peak, for every angle window and radius."""
    def mutate(doc):
        _quiet(doc, angle_window=angle_window)
        doc["rts"]["arc_radius_m"] = radius
    scene = make_scene(mutate)
    setup = build_setup(scene)
    paths = exact_paths(setup)
    for delay in (0.0, 150e-12):
        cm = ChannelModel.build(setup, paths, (0, 1), TargetConfig(20.0), (0.0, delay))
        th = np.sort(cm.steering.search(cm.phasors))
        phases = (0.0, float(cm.pair_phase(th[0] + np.array([0.25, 0.75]) * (th[1] - th[0]))))
        for a in th[0] + np.array([0.1, 0.35, 0.6, 0.9]) * (th[1] - th[0]):
            w = cm.pair_weights(cm.pair_ratio(a, phases, "exact"), phases)
            assert float(cm.direction(w)) == pytest.approx(a, abs=1e-8)


@pytest.mark.parametrize("angle_window", WINDOWS)
def test_n_channel_exact_mode_hits_cell_points_for_every_taper(angle_window):
    """The N-channel exact mode (sphere4, four front ends in azimuth and elevation): the
    modelled 2-D peak at each set point inside the cell, for every angle window."""
    from rtsgeom.radar.steering import Steering
    from rtsgeom.synthesis.model import ChannelModel
    from rtsgeom.scene import load_scene
    scene = load_scene("scenes/sphere4.toml")
    scene = scene.evolve(radar=scene.radar.evolve(angle_window=angle_window))
    setup = build_setup(scene)
    cs = ChannelModel.build(setup, exact_paths(setup), (0, 1, 2, 3), TargetConfig(25.0),
                            steering=Steering.auto(setup.rut, scene.radar))
    u_fe = setup.fe_direction_cosines()
    lo, hi = u_fe.min(0), u_fe.max(0)
    for fx, fz in ((0.2, 0.5), (0.5, 0.15), (0.8, 0.85), (0.5, 0.5)):
        u = lo + np.array([fx, fz]) * (hi - lo)
        w = cs.solve(u)
        assert np.abs(cs.direction_cosines(w, u) - u).max() < 1e-9


@pytest.mark.parametrize("angle_window", WINDOWS)
@pytest.mark.parametrize("radius", [0.5, 3.0])
def test_coherence_point_moves_by_the_closed_form_for_every_taper(angle_window, radius):
    """The calibration's target, the phasor model's coherence point, shifts by
    -(f_c + S t_mid - S tau) / (f_rts + S t_mid - S tau) * 2 dr / c0 for a radial offset dr
    of front end J (the opposite way for I), whatever the angle window: the taper weights the
    elements, not the channels' relative phase."""
    from rtsgeom.calibration.pair import pair_coherence
    from rtsgeom.calibration.probes import probe_front_ends

    def scene(offsets=None):
        def mutate(doc):
            _quiet(doc, angle_window=angle_window)
            # 256 samples: on the 128-sample cube probe_front_ends returns NaN for front end
            # 1 without an error (probe at 20.3 m not found; an open finding, aoa/calibration.py)
            doc["radar"].update(samples_per_chirp=256, adc_rate_hz=25e6)
            doc["rts"]["arc_radius_m"] = radius
            for k, v in (offsets or {}).items():
                doc["rts"]["front_ends"][k]["radial_offset_mm"] = v
        return build_setup(make_scene(mutate))
    nom = scene()
    shift = CoherenceShift(nom, probe_front_ends(nom, exact_paths(nom), 1))
    for fe, dr_mm in ((1, 0.3), (0, -0.7)):
        s = scene({fe: dr_mm})
        d = pair_coherence(s, exact_paths(s), (0, 1), alphas=shift.alphas,
                           near_s=shift.d0).continuous_s
        assert abs(shift.wrapped(d, fe, dr_mm)) < 1e-12


@pytest.mark.parametrize("name", ["hann", "hamming", "blackman", "none", "bartlett"])
@pytest.mark.parametrize("n", [0, 1, 2, 5, 16])
def test_windows_are_scipys_symmetric_windows_bit_for_bit(name, n):
    from scipy.signal import get_window
    from rtsgeom.radar.windows import window
    got = window(name, n)
    want = np.ones(n) if name == "none" or n <= 1 else get_window(name, n, fftbins=False)
    assert got.shape == (n,) and np.array_equal(got, want)


def test_a_taper_follows_the_elements_positions():
    """1-D: the window over the elements sorted by position, whatever their order; 2-D: the
    product of one window per distinct row and per distinct column, an axis whose window has
    zero ends (a Hann over two rows is (0, 0)) taking the middle of one two points longer."""
    from rtsgeom.radar.windows import taper, window
    x = np.array([[0.3], [0.0], [0.2], [0.1]])
    assert np.array_equal(taper("hamming", x), window("hamming", 4)[[3, 0, 2, 1]])
    xs, zs = np.meshgrid([0.0, 0.1, 0.2, 0.3, 0.4], [0.0, 0.05], indexing="ij")
    pos = np.c_[xs.ravel(), zs.ravel()]
    w = taper("hann", pos)
    want = np.outer(window("hann", 7)[1:-1], window("hann", 4)[1:-1]).ravel()
    assert np.allclose(w, want, rtol=0, atol=1e-15) and np.all(w > 0)
    assert np.array_equal(taper("none", pos), np.ones(10))
    ham = np.outer(window("hamming", 5), window("hamming", 2)).ravel()  # no zero ends: as is
    assert np.allclose(taper("hamming", pos), ham, rtol=0, atol=1e-15)
