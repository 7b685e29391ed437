"""Tests written for the survivors of a fresh mutation sample in ``aoa/`` (``python -m
benchmarks.mutation --sample 160 --seed 3``); the other modules' are in
``test_physics_core.py``, whose docstring says how these tests are built (closed forms and
invariants on grids, through public functions, no module-scoped fixtures).
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from conftest import make_scene
from test_physics_core import _small_noiseless


# -- aoa.synthesis.array_factor ----------------------------------------------------------


@pytest.mark.parametrize("n", [2, 4, 7, 8, 16])
def test_array_factor_of_filled_positions_is_the_dirichlet_kernel(n):
    """``array_factor`` with the positions of a filled lambda/2 array equals its closed form
    sin(n pi u/2) / (n sin(pi u/2)) (docstring), for any u, also past the grating lobes."""
    from rtsgeom.synthesis.closed_form import array_factor
    u = np.linspace(-1.9, 1.9, 381)
    closed = array_factor(u, n)
    for offset in (0.0, 3.25):  # the centroid is removed: a shifted array has the same AF
        got = array_factor(u, positions_wl=offset + 0.5 * np.arange(n))
        np.testing.assert_allclose(got, closed, atol=1e-12)
    # a sparse array is not that kernel (here: 2 elements 2 lambda apart, cos(2 pi u))
    np.testing.assert_allclose(array_factor(u, positions_wl=[0.0, 2.0]), np.cos(2 * np.pi * u),
                               atol=1e-12)


# -- calibration.fit.fit_centre --------------------------------------------------------------


@pytest.mark.parametrize("true_ps", [-3.0, 0.0, 7.4])
@pytest.mark.parametrize("bad_rows", [(), (2,), (0, 5, 11)])
@pytest.mark.parametrize("vertex_deg", [0.0, 0.01])
def test_fit_centre_finds_the_centre_of_symmetry_despite_lost_steps_and_biased_vertices(
        true_ps, bad_rows, vertex_deg):
    """Probe errors even about delta_0 with a second harmonic, e_p = c_p (1 - cos) + d_p
    sin^2 + v_p, their vertices v_p off zero in opposite directions (a mounting offset's
    amplitude error): the centre of symmetry is delta_0 within 0.01 ps, also when some
    steps lost a probe (NaN: no detection; only that probe's step is dropped), while the
    probes' RMS minimum is not (it is pulled towards the deeper vertex)."""
    from rtsgeom.calibration.fit import fit_centre
    period, step = 1.0e-9, 25e-12
    near = 0.0
    d = near + np.arange(-10, 11) * step
    th = 2 * np.pi * (d - true_ps * 1e-12) / period
    v = np.radians(vertex_deg)
    e = np.stack([0.8 * (1 - np.cos(th)) + 0.05 * np.sin(th) ** 2 - v,
                  -0.5 * (1 - np.cos(th)) + 2 * v], axis=1) * np.radians(0.1)
    for r in bad_rows:
        e[r, r % 2] = np.nan
    got = fit_centre(d, e, period, near, search_s=period / 8)
    assert got == pytest.approx(true_ps * 1e-12, abs=0.01e-12)


# -- aoa.calibration.fir_effect -------------------------------------------------------------


def _fir_scene(taps, model):
    def mutate(doc):
        doc["radar"].pop("snr_db", None)
        doc["rts"]["fractional_delay_taps"] = taps
        doc["rts"]["fractional_delay_filter"] = model
    return make_scene(mutate)


@pytest.mark.parametrize("taps", [5, 9])
def test_fir_effect_predicts_the_coherence_shift_in_picoseconds(taps):
    """``fir_effect``'s predicted shift (ps) of the coherence point, turned into the phase it
    adds to channel J relative to I (360 f_if shift), explains the phase measured on the
    phasor model with the filter against without it at fractional delay settings across a
    period: the least-squares gain measured / predicted is 1 within 30 % (first order in
    the filter's phase ripple), and a short filter shifts the point measurably."""
    from rtsgeom.calibration.fir import fir_effect
    from rtsgeom.calibration.probes import if_phase_slope_hz, probe_ranges, probe_total_delay
    from rtsgeom.synthesis.model import ChannelModel
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.scene import TargetConfig
    ideal = build_setup(_fir_scene(taps, "ideal"))
    fir = build_setup(_fir_scene(taps, "windowed-sinc"))
    paths = exact_paths(ideal)
    ranges = probe_ranges(ideal, 2)
    f_if = if_phase_slope_hz(fir.scene, probe_total_delay(fir, ranges))
    measured, predicted = [], []
    for d in (0.1e-9, 0.37e-9, 0.63e-9, 0.81e-9):
        z = 0j
        for r in ranges:
            m0 = ChannelModel.build(ideal, paths, (0, 1), TargetConfig(float(r)), (0.0, d))
            m1 = ChannelModel.build(fir, paths, (0, 1), TargetConfig(float(r)), (0.0, d))
            z += np.exp(1j * (m1.pair_phase([0.1]) - m0.pair_phase([0.1])))
        measured.append(np.degrees(np.angle(z)))
        predicted.append(fir_effect(fir, d)["predicted_shift_ps"] * 1e-12 * 360 * f_if)
    m, p = np.array(measured), np.array(predicted)
    assert np.max(np.abs(p)) > 0.1  # deg: 5 taps ~5 deg, 9 taps ~0.15 deg
    gain = float(np.sum(m * p) / np.sum(p * p))
    assert 0.7 < gain < 1.3


# -- aoa.plan: the calibration's progress report ---------------------------------------------


def test_plan_reports_each_pairs_calibration_delay_in_picoseconds():
    """``run``'s progress line for a calibrated pair gives delta_tau in ps: the value
    the calibration record holds (s) times 1e12, within the printed precision."""
    from rtsgeom.pipeline.plan import plan_targets
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths

    def mutate(doc):
        doc["radar"].pop("snr_db", None)
        doc["radar"].update(chirps_per_tx=32, samples_per_chirp=128, adc_rate_hz=12.5e6)
        doc["rts"]["front_ends"][1]["radial_offset_mm"] = 0.4
    setup = build_setup(make_scene(mutate))
    lines = []
    _, record, _ = plan_targets(setup, exact_paths(setup), "exact", progress=lines.append)
    shown = [float(m.group(1)) for m in
             (re.search(r"delta_tau (-?[0-9.]+) ps", s) for s in lines) if m]
    assert len(shown) == 1
    cal = record["pairs"][0] if "pairs" in record else record
    want_ps = float(cal["delta_tau_s"]) * 1e12
    assert abs(want_ps) > 1.0  # the 0.4 mm offset moves the point by ~2.7 ps
    assert shown[0] == pytest.approx(want_ps, abs=0.051)


# -- aoa.cells / aoa.ncal: cells and the pairs an N-channel calibration measures ------------


@pytest.mark.parametrize("count", [2, 3, 5])
def test_enclosing_interval_is_the_adjacent_pair_in_one_dimension(count):
    """1-D cells: a direction between two neighbouring front ends (in any index order) is
    enclosed by exactly that pair, also with only two front ends; outside the span none."""
    from rtsgeom.errors import CellUnreachable
    from rtsgeom.synthesis.cells import enclosing_cell
    rng = np.random.default_rng(count)
    x = np.sort(rng.uniform(-0.5, 0.5, count))
    perm = rng.permutation(count)
    pts = x[perm][:, None]
    for k in range(count - 1):
        for f in (0.0, 0.3, 0.99):
            u = x[k] + f * (x[k + 1] - x[k])
            got = enclosing_cell([u], pts)
            assert sorted(perm[list(got)]) == [k, k + 1]  # channel q sits at rank perm[q]
    for u in (x[0] - 0.01, x[-1] + 0.01):
        with pytest.raises(CellUnreachable):
            enclosing_cell([u], pts)


@pytest.mark.parametrize("grid", [(2, 1), (4, 1), (2, 2), (3, 2), (3, 3)])
def test_pair_edges_are_neighbours_in_1d_and_delaunay_edges_in_2d(grid):
    """The pairs an N-channel calibration sweeps: in 1-D the F - 1 neighbours by direction
    (whatever the channel numbering); in 2-D the edges of the Delaunay triangulation, 3 F - 3
    - h of them for F points with h on the hull (Euler), each joining two given channels."""
    from rtsgeom.calibration.channels import pair_edges
    n_a, n_e = grid
    rng = np.random.default_rng(n_a * 10 + n_e)
    az = np.arange(n_a) * 0.1 + rng.uniform(-0.01, 0.01, n_a)
    if n_e == 1:
        u = az[:, None]
        perm = rng.permutation(n_a)
        u_fe = np.empty_like(u)
        u_fe[perm] = u  # channel perm[k] sits at the k-th direction
        edges = pair_edges(u_fe, range(n_a))
        want = sorted(tuple(sorted((int(perm[k]), int(perm[k + 1])))) for k in range(n_a - 1))
        assert sorted(edges) == want
        return
    el = np.arange(n_e) * 0.08
    u_fe = np.array([(a, e) for a in az for e in el]) + rng.uniform(-0.003, 0.003, (n_a * n_e, 2))
    f = len(u_fe)
    from scipy.spatial import ConvexHull
    h = len(ConvexHull(u_fe).vertices)
    edges = pair_edges(u_fe, range(f))
    assert len(edges) == len(set(edges)) == 3 * f - 3 - h
    assert all(0 <= i < j < f for i, j in edges)
    # a subset of channels: only edges among them
    sub = [0, 1, f - 1]
    assert {q for e in pair_edges(u_fe, sub) for q in e} == set(sub)


@pytest.mark.parametrize("fe, dr_mm", [(1, -0.097), (0, -0.3)])
def test_nd_pair_calibration_lands_on_the_coherence_point(fe, dr_mm):
    """The N-channel pair sweep (``ncal.calibrate_pair_nd``, full ADC-cube chain at each
    step, a parabola through the points around the minimum) lands within 3 ps of the
    phasor model's coherence point for a radial offset that puts the point half a coarse
    step (100 ps) off the sweep grid, on either front end; its period is 1/(f_rts + S t_mid
    - S tau) as the pair calibration's."""
    from rtsgeom.calibration.pair import pair_coherence
    from rtsgeom.calibration.probes import probe_angles, probe_front_ends
    from rtsgeom.calibration.pair import calibrate_pair
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.geometry.farfield import two_way_lengths
    setup = build_setup(_small_noiseless(
        lambda d: d["rts"]["front_ends"][fe].update(radial_offset_mm=dr_mm)))
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, 1)
    got = calibrate_pair(setup, paths, (0, 1), probe, seed=1, span_s=(-0.3e-9, 0.3e-9),
                         step_s=100e-12).to_dict()
    point = pair_coherence(setup, paths, (0, 1),
                           alphas=probe_angles(*probe.angle_rad[[0, 1]])).continuous_s
    period = got["period_s"]
    dist = (got["delta_tau_s"] - point + period / 2) % period - period / 2
    assert abs(dist) < 3e-12
    assert got["residual_error_deg"] < 0.05
    # the range offset the pair's echoes get: half the path of J's delay plus its air-path
    # excess over I (each front end's two-way line-of-sight length, mean over the elements)
    air = two_way_lengths(setup.rut, setup.fe.rx, setup.fe.tx).mean(axis=1)
    assert got["range_offset_m"] == pytest.approx(
        0.5 * (299792458.0 * got["delta_tau_s"] + air[1] - air[0]), abs=1e-9)


def test_channel_calibration_of_one_channel_is_its_own_reference():
    from rtsgeom.calibration.probes import probe_front_ends
    from rtsgeom.calibration.channels import calibrate_channels
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    setup = build_setup(_small_noiseless())
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, 1)
    for q in (0, 1):
        cal = calibrate_channels(setup, paths, [q], probe)
        assert cal.reference == q and np.all(cal.offsets_s == 0.0) and cal.tree == []
        assert cal.gain_correction == pytest.approx(tuple(probe.gain_correction))


# -- the 2-D linearity (error map) through the ADC-cube chain -------------------------------


def test_2d_error_map_exact_mode_puts_every_grid_point_on_its_direction():
    """sphere4 as built = nominal (no errors, noiseless): ``exact`` amplitudes synthesize
    every grid point inside the four front ends' cell at its (azimuth, elevation) through
    the whole chain (1e-4 deg); ``array-factor`` (closed form, no near field) is off by a
    finite amount. The n x n grid inside a rectangular cell keeps all n^2 points."""
    from rtsgeom.analysis.linearity import linearity
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.scene import load_scene
    sc = load_scene("scenes/sphere4.toml")
    sc = sc.evolve(radar=sc.radar.evolve(snr_db=None, samples_per_chirp=128, chirps_per_tx=32,
                                         adc_rate_hz=12.5e6))
    setup = build_setup(sc)
    paths = exact_paths(setup)
    em = linearity(setup, paths, None, "exact", points=2, calibrate=False, seed=1)
    assert em.set_deg.shape == (4, 2)
    assert max(em.max_abs_error_deg) < 1e-4
    af = linearity(setup, paths, None, "array-factor", points=2, calibrate=False, seed=1)
    assert 0.05 < max(af.max_abs_error_deg) < 1.0


# -- the N-channel closed form does not depend on a common phase -------------------------


@pytest.mark.parametrize("common", [0.0, 0.7, -2.1, 3.0])
def test_closed_form_amplitudes_ignore_a_common_phase(common):
    """Adding one phase to every channel's programmed phase changes nothing physical (the
    beamformer output rotates as a whole): the ``array-factor`` amplitudes on sphere4's four
    front ends are the same for phases + c as for phases, over set points in the cell."""
    from rtsgeom.radar.steering import Steering
    from rtsgeom.synthesis.model import ChannelModel
    from rtsgeom.synthesis.closed_form import closed_form_amplitudes
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.scene import TargetConfig, load_scene
    setup = build_setup(load_scene("scenes/sphere4.toml"))
    cs = ChannelModel.build(setup, exact_paths(setup), (0, 1, 2, 3), TargetConfig(25.0),
                            steering=Steering.auto(setup.rut, setup.scene.radar))
    st = cs.steering
    u_fe = setup.fe_direction_cosines()
    lo, hi = u_fe.min(0), u_fe.max(0)
    phases = np.array([0.3, -1.2, 2.0, 0.4])
    for fx, fz in ((0.3, 0.4), (0.7, 0.8), (0.5, 0.2)):
        u = lo + np.array([fx, fz]) * (hi - lo)
        a = closed_form_amplitudes(st, u_fe, u, phases)
        b = closed_form_amplitudes(st, u_fe, u, phases + common)
        np.testing.assert_allclose(b, a, rtol=1e-9, atol=1e-12)
        assert np.max(a) == pytest.approx(1.0)


# -- aoa.linearity: the closed forms with measured end angles ---------------------------------


@pytest.mark.parametrize("mode", ["array-factor", "paper"])
def test_measured_end_angles_equal_geometric_ones_in_the_ideal_far_field(mode):
    """In the ideal far field (50 m, no Rx/Tx separation) each front end alone is detected
    at its geometric angle, so the closed forms with measured end angles program the same
    ratios as with the geometric ones: the same detected angles through the chain."""
    from rtsgeom.calibration.probes import probe_front_ends
    from rtsgeom.analysis.linearity import linearity
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths

    from conftest import far_field

    def far(doc):
        far_field(doc)
        doc["targets"] = [{"range_m": 60.0, "angle_deg": 7.0}]
    setup = build_setup(_small_noiseless(far))
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, 1)
    geo = linearity(setup, paths, (0, 1), mode, probe, None, 5, 1, end_angles="geometric")
    meas = linearity(setup, paths, (0, 1), mode, probe, None, 5, 1, end_angles="measured")
    assert np.all(np.isfinite(meas.error_deg))
    np.testing.assert_allclose(meas.error_deg, geo.error_deg, atol=0.02)


# -- aoa.model: the RuT's pose in the channel model ------------------------------------------


@pytest.mark.parametrize("h_mm", [-3.0, 0.5, 4.0])
def test_raising_the_rut_equals_lowering_every_front_end(h_mm):
    """Only relative geometry matters: the legs with the RuT raised by h (a RuT position
    error alone, no yaw) equal those with every front end lowered by h (height offset -h),
    for both channels of the pair; and they differ from the nominal legs."""
    from rtsgeom.analysis.tolerance.phasors import ChannelPhasors
    from rtsgeom.geometry import build_setup
    model = ChannelPhasors.build(build_setup(make_scene()), (0, 1), 3)
    h = h_mm * 1e-3
    zero = np.zeros((2, 3))
    raised = model.air_legs(zero, {"rut_offset_m": np.array([0.0, 0.0, h])})
    lowered = model.air_legs(np.array([[0.0, 0.0, -h]] * 2))
    nominal = model.air_legs(zero)
    for a, b, n in zip(raised, lowered, nominal):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-18)
        assert np.max(np.abs(a - n)) > 1e-16


# -- aoa.calibration: the paper's procedure reports the exact period ------------------------


def test_paper_procedure_reports_the_exact_period_at_its_target():
    """``calibrate_pair_paper`` (one target at one set angle) reports the period
    1/(f_rts + S t_mid - S tau) at its target's delay, as the pair calibration does at its
    probes' (not eq. 27's 1/(f_rts + B/2))."""
    from scipy.constants import c
    from rtsgeom.calibration.paper import calibrate_pair_paper
    from rtsgeom.calibration.probes import probe_front_ends, probe_ranges
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    for f_rts in (500e6, 300e6):
        setup = build_setup(_small_noiseless(lambda d, f=f_rts: d["rts"].update(f_rts_hz=f)))
        paths = exact_paths(setup)
        probe = probe_front_ends(setup, paths, 1)
        cal = calibrate_pair_paper(setup, paths, (0, 1), probe, 1, span_s=(0.0, 50e-12),
                                   step_s=25e-12)
        r = setup.scene.radar
        t_mid = r.adc_start_s + 0.5 * (r.samples_per_chirp - 1) / r.adc_rate_hz
        s = r.bandwidth_hz / r.chirp_duration_s
        tau = 2 * float(probe_ranges(setup, 1)[0]) / c
        assert cal.period_s == pytest.approx(1 / (f_rts + s * t_mid - s * tau), rel=1e-4)


# -- aoa.pair_design.design_ratio: the closed-form exact design ------------------------------------


@pytest.mark.parametrize("angle_window", ["none", "hann", "hamming", "blackman"])
@pytest.mark.parametrize("radius", [0.5, 1.0, 3.0])
def test_closed_form_design_is_scale_free_and_puts_the_peak_on_the_set_angle(angle_window,
                                                                            radius):
    """``design_ratio``: the ratio whose composite x_i + rho e^{j phase} x_j peaks at the set
    angle. Its beamformer peak is there (searched), and the ratio does not depend on the
    echoes' common scale (volts or sqrt(W), 1e-6 or 1e6: P'' < 0 is a sign, not a level)."""
    from rtsgeom.synthesis.model import ChannelModel
    from rtsgeom.synthesis.pair import design_ratio
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.scene import TargetConfig

    def mutate(doc):
        doc["radar"]["angle_window"] = angle_window
        doc["rts"]["arc_radius_m"] = radius
    setup = build_setup(make_scene(mutate))
    cm = ChannelModel.build(setup, exact_paths(setup), (0, 1), TargetConfig(20.0))
    st = cm.steering
    x_i, x_j = cm.phasors
    th = np.sort(st.search(cm.phasors))
    phase = float(cm.pair_phase(th[0] + np.array([0.25, 0.75]) * (th[1] - th[0])))
    alphas = th[0] + np.array([0.15, 0.4, 0.6, 0.85]) * (th[1] - th[0])
    rho = design_ratio(st, x_i, x_j, alphas, phase)
    assert np.all(np.isfinite(rho)) and np.all(rho >= 0)
    comp = x_i[None] + (rho * np.exp(1j * phase))[:, None] * x_j[None]
    np.testing.assert_allclose(st.search(comp), alphas, atol=1e-7)
    for scale in (1e-6, 1e-3, 1e3, 1e6):
        np.testing.assert_allclose(design_ratio(st, scale * x_i, scale * x_j, alphas, phase),
                                   rho, rtol=1e-9)


# -- aoa.sweep: the calibration's noise model against the ADC-cube chain -----------------------


@pytest.mark.parametrize("snr_db", [-10.0, 0.0])
def test_calibration_sweep_noise_is_the_adc_chains_within_a_factor_of_a_few(snr_db):
    """The phasor sweep adds receiver noise of the scene's SNR to each step's spectra (what
    sizes the frames per step and ``one_frame_scatter_ps``); the full ADC-cube chain adds it
    to the samples. Near the coherence point both give the probes' angles a noise variance
    (noisy minus noiseless squared error, 6 seeds x 2 steps x 2 probes, each seed its own
    noise realisation in both); they agree within a
    factor 5 (measured: the phasor model's is 1.4-1.5 times the chain's at SNR -10 and 0 dB),
    where a noise level off by the windows' sum w^2 (thousands) would not."""
    from rtsgeom.calibration.pair import calibrate_pair
    from rtsgeom.calibration.probes import probe_front_ends
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths

    def scene(snr):
        def m(doc):
            doc["radar"].pop("snr_db", None)
            if snr is not None:
                doc["radar"]["snr_db"] = snr
            doc["radar"]["chirps_per_tx"] = 32
            for fe in doc["rts"]["front_ends"]:
                fe.pop("return_loss_fe_db", None)
                fe.pop("return_loss_be_db", None)
        return build_setup(make_scene(m))
    clean = scene(None)
    paths = exact_paths(clean)
    probe = probe_front_ends(clean, paths, 1)
    kw = dict(span_s=(0.0, 25e-12), step_s=25e-12, frames=1)  # two steps at coherence
    e0 = {fc: calibrate_pair(clean, paths, (0, 1), probe, seed=1, full_chain=fc,
                             **kw).sweep_error_deg for fc in (False, True)}
    noisy = scene(snr_db)
    var = {}
    for fc in (False, True):
        d = [calibrate_pair(noisy, paths, (0, 1), probe, seed=s, full_chain=fc,
                            **kw).sweep_error_deg ** 2 - e0[fc] ** 2 for s in range(6)]
        var[fc] = float(np.mean(d))
        # each seed its own noise: no two seeds share a realisation
        assert len({np.asarray(x).round(12).tobytes() for x in d}) == len(d)
    assert var[True] > 0 and var[False] > 0
    assert 0.2 < var[False] / var[True] < 5.0


@pytest.mark.parametrize("taps", [9, 11, 17])
def test_fir_effect_reports_its_filter_and_a_small_passband_ripple(taps):
    """``fir_effect`` names the filter it evaluated ("none" without a fractional delay, where
    nothing ripples) and a windowed-sinc FIR's gain ripple along the chirp's IF sweep: a
    passband ripple, positive and below 1 dB from 9 taps on, that a twice as long filter does not increase."""
    from rtsgeom.calibration.fir import fir_effect
    from rtsgeom.geometry import build_setup
    fir = fir_effect(build_setup(_fir_scene(taps, "windowed-sinc")), 0.37e-9)
    assert fir["model"] == "windowed-sinc"
    assert 0.0 < fir["gain_ripple_db"] < 1.0 and 0.0 < fir["phase_ripple_deg"] < 10.0
    longer = fir_effect(build_setup(_fir_scene(2 * taps + 1, "windowed-sinc")), 0.37e-9)
    assert longer["gain_ripple_db"] <= fir["gain_ripple_db"] * 1.05

    def off(doc):
        doc["rts"].update(fractional_delay=False, calibration_step_ps=250.0)
    none = fir_effect(build_setup(make_scene(off)), 0.37e-9)
    assert none == {"model": "none", "gain_ripple_db": 0.0, "phase_ripple_deg": 0.0,
                    "predicted_shift_ps": 0.0}
