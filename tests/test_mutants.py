"""Tests written for the survivors of the mutation run (``python -m benchmarks.mutation``).

Each test names the behaviour a surviving mutant changed without any test noticing; the
mutants themselves are listed in ``benchmarks/mutation-report.md``. Small cubes and quiet
channels keep them fast.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
import trimesh
from scipy.constants import c

from conftest import make_scene
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.paths.table import RUT_TO_RUT, Paths
from rtsgeom.radar import process
from rtsgeom.radar.frame import simulate
from rtsgeom.radar.processing import range_angle_map
from rtsgeom.radar.steering import parabolic
from rtsgeom.rts import KIND_SETUP, program_nearest, requested_delay, setup_echoes

SMALL = dict(chirps_per_tx=32, samples_per_chirp=128, adc_rate_hz=12.5e6)


def small_quiet(targets=None, **radar):
    def mutate(doc):
        doc["radar"].pop("snr_db", None)
        doc["radar"].update(SMALL)
        doc["radar"].update(radar)
        for fe in doc["rts"]["front_ends"]:
            fe.pop("return_loss_fe_db", None)
            fe.pop("return_loss_be_db", None)
        doc["targets"] = targets if targets is not None else [
            {"range_m": 30.0, "angle_deg": 7.0}, {"range_m": 45.0, "velocity_mps": 2.0,
                                                  "angle_deg": 10.0}]
    return make_scene(mutate)


# -- radar.steering / processing ------------------------------------------------------------


@pytest.mark.parametrize("vertex", [-0.49, -0.2, 0.0, 0.13, 0.4])
@pytest.mark.parametrize("curv", [-0.3, -2.0, -40.0])
def test_parabolic_offset_is_the_vertex_of_the_parabola(vertex, curv):
    y = curv * (np.array([-1.0, 0.0, 1.0]) - vertex) ** 2 + 5.0
    assert float(parabolic(*y)) == pytest.approx(vertex, abs=1e-12)


@pytest.mark.parametrize("y", [(1.0, 0.8, 1.1), (1.0, 0.5, 0.9), (0.0, 0.0, 0.0), (2.0, 1.0, 0.0)])
def test_parabolic_is_zero_where_the_middle_sample_is_no_peak(y):
    """Convex or flat samples (y0 - 2 y1 + y2 >= 0) have no vertex to move to: offset 0."""
    assert float(parabolic(*y)) == 0.0


def test_range_angle_map_peaks_at_each_detection_angle():
    scene = small_quiet()
    setup = build_setup(scene)
    _, cube = simulate(setup, exact_paths(setup), program_nearest(scene, setup))
    rd, det = process(cube)
    grid = np.radians(np.linspace(-30, 30, 601))
    ram = range_angle_map(rd, cube, grid)
    assert ram.shape == (rd.power.shape[0], grid.size)
    for k in range(len(det)):
        if det.doppler_bin[k] != np.argmax(rd.power[det.range_bin[k]]):
            continue  # the map takes each range bin at its strongest Doppler bin
        peak = grid[np.argmax(ram[det.range_bin[k]])]
        # grid step 0.1 deg; the map compensates TDM at the bin's Doppler, not the refined one
        assert np.degrees(abs(peak - det.angle_rad[k])) < 0.12


# -- geometry -------------------------------------------------------------------------------


def test_smallest_spacing_of_a_single_position_is_infinite():
    from rtsgeom.geometry.arrays import array_from_spec
    from rtsgeom.geometry.farfield import smallest_spacing_m
    from rtsgeom.radar_presets import ArraySpec
    lam = 3.9e-3
    one = array_from_spec(ArraySpec(((0.0, 0.0),), ((0.0, 0.0),), (0,)), lam)
    assert smallest_spacing_m(one) == float("inf")
    two = array_from_spec(ArraySpec(((0.0, 0.0),), ((0.0, 0.0), (0.7 * lam, 0.0)), (0,)), lam)
    assert smallest_spacing_m(two) == pytest.approx(0.7 * lam, rel=1e-12)


def test_pattern_tables_may_span_the_whole_circle():
    from rtsgeom.geometry.patterns import TablePattern
    az = np.radians(np.linspace(-180, 180, 9))
    el = np.radians([-90.0, 0.0, 90.0])
    p = TablePattern(az, el, np.zeros((9, 3)), np.zeros((9, 3)))
    assert p is not None
    with pytest.raises(ValueError, match="azimuth_deg"):
        TablePattern(np.radians(np.linspace(-181, 180, 9)), el, np.zeros((9, 3)), np.zeros((9, 3)))


def test_cos_pattern_from_config_without_an_elevation_beamwidth():
    from rtsgeom.geometry.patterns import CosinePattern, pattern_from_config
    p = pattern_from_config("cos", hpbw_deg=60.0)
    assert isinstance(p, CosinePattern) and p.hpbw_el_rad is None
    q = pattern_from_config("cos", hpbw_deg=60.0, hpbw_el_deg=30.0)
    assert q.hpbw_el_rad == pytest.approx(np.radians(30.0))


def test_segments_through_a_triangle_edge_are_blocked():
    """A segment through an edge of a facet counts as blocked (barycentric u or v == 0)."""
    from rtsgeom.geometry.sheet import segments_blocked
    tri = trimesh.Trimesh(vertices=[[0, 0, 0], [1, 0, 0], [0, 1, 0]], faces=[[0, 1, 2]],
                          process=False)
    for x, y in [(0.5, 0.0), (0.0, 0.5), (0.5, 0.5), (0.25, 0.25)]:
        assert segments_blocked(tri, np.array([[x, y, -1.0]]), np.array([[x, y, 1.0]]))[0]
    assert not segments_blocked(tri, np.array([[0.6, 0.6, -1.0]]), np.array([[0.6, 0.6, 1.0]]))[0]


def test_front_end_layout_fields_read_per_front_end():
    """Front ends whose configs carry explicit (t, h) offsets and rotations (the library
    layer; some may leave them unset, i.e. default): placed by those, not the shorthand."""
    from rtsgeom.geometry.arc import front_ends
    base = make_scene().rts.front_ends
    fes = [SimpleNamespace(**{k: getattr(f, k) for k in (
        "angle_rad", "rx_tx_separation_m", "radial_offset_m", "tangential_offset_m",
        "height_offset_m")}) for f in base]
    fes[0].rx_offset_m, fes[0].tx_offset_m = (0.004, 0.001), (-0.006, 0.0)
    fes[1].rx_offset_m, fes[1].tx_offset_m = None, None  # default: both at the module centre
    scene = SimpleNamespace(rts=SimpleNamespace(front_ends=fes, arc_radius_m=1.0))
    fe = front_ends(scene, np.zeros(3))
    t0 = np.array([np.cos(fes[0].angle_rad), -np.sin(fes[0].angle_rad), 0.0])
    np.testing.assert_allclose(fe.rx[0] - fe.module[0], 0.004 * t0 + [0, 0, 0.001], atol=1e-12)
    np.testing.assert_allclose(fe.tx[0] - fe.module[0], -0.006 * t0, atol=1e-12)
    np.testing.assert_allclose(fe.rx[1], fe.module[1], atol=1e-12)


# -- rts ------------------------------------------------------------------------------------


def test_setup_echoes_are_the_rut_to_rut_rows_conjugated():
    """Static reflections of the RuT's own chirp: per virtual element each RUT_TO_RUT row of
    its (Tx, Rx) pair becomes an echo with that delay and the conjugate gain; other rows and
    other pairs add nothing."""
    scene = small_quiet([])
    setup = build_setup(scene)
    rut = setup.rut
    rows = []
    rng = np.random.default_rng(4)
    for m in range(rut.tx_world.shape[0]):
        for k in range(rut.rx_world.shape[0]):
            for _ in range(1 + (m + k) % 2):
                rows.append((m, k, rng.uniform(5e-9, 9e-9), rng.normal() + 1j * rng.normal()))
    m_, k_, d_, g_ = map(np.array, zip(*rows))
    paths = Paths.build(np.full(len(rows), -1), np.full(len(rows), RUT_TO_RUT), m_, k_, d_, g_,
                        bounces=np.ones(len(rows), int))
    ech = setup_echoes(setup, paths)
    assert np.all(ech.kind == KIND_SETUP) and np.all(ech.tau_if_s == 0)
    assert ech.amplitude.dtype.kind == "c"
    for v in range(rut.num_virtual):
        sel = (m_ == rut.virtual_tx[v]) & (k_ == rut.virtual_rx[v])
        got = sorted(zip(ech.tau_air_s[:, v][ech.amplitude[:, v] != 0],
                         ech.amplitude[:, v][ech.amplitude[:, v] != 0]), key=lambda x: x[0])
        want = sorted(zip(d_[sel], np.conj(g_[sel])), key=lambda x: x[0])
        assert len(got) == len(want)
        for (a, b), (x, y) in zip(got, want):
            assert a == x and b == y
    # no RUT_TO_RUT rows: no echoes
    assert len(setup_echoes(setup, exact_paths(setup))) == 0


# -- aoa ------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def small_setup():
    # 512 samples: the probes' 3 m spacing (probe_ranges) must clear the CA-CFAR ring of
    # 2 + 8 range bins; with 128 samples (0.6 m bins) it does not and one probe is masked
    scene = small_quiet(samples_per_chirp=512)
    setup = build_setup(scene)
    return setup, exact_paths(setup)


def test_probe_finds_each_front_end_at_the_model_angle_with_unit_gain_correction(small_setup):
    """Each front end alone, measured in the noise-free chain: at the exact model's angle of
    that front end (the beamformer peak of its own phasors), and with a gain correction of 1
    where the setup is the nominal one (the model then is the measurement)."""
    from rtsgeom.aoa.calibration import probe_front_ends, probe_ranges
    from rtsgeom.aoa.model import ChannelModel
    from rtsgeom.scene import TargetConfig
    setup, paths = small_setup
    probe = probe_front_ends(setup, paths)
    ranges = probe_ranges(setup, setup.fe.count)
    assert np.all(np.diff(ranges) > 0)
    for q in range(setup.fe.count):
        cm = ChannelModel.build(setup, paths, (q,), TargetConfig(float(ranges[q])))
        want = cm.direction(np.array([1.0]))
        assert np.degrees(abs(probe.angle_rad[q] - want)) < 2e-3
    np.testing.assert_allclose(probe.gain_correction, 1.0, rtol=2e-3)
    assert np.all(np.isfinite(probe.power_db))


@pytest.mark.parametrize("mode", ["exact", "array-factor", "paper"])
def test_plan_programs_two_channels_per_target_at_the_set_range_and_doppler(small_setup, mode):
    """``plan_targets`` without calibration: per target the bracketing pair, each at the
    requested delay and Doppler 2 f_c v / c0, positive amplitudes; with exact amplitudes on the
    nominal setup the chain detects each target at its set angle."""
    from rtsgeom.aoa.plan import plan_targets
    setup, paths = small_setup
    scene = setup.scene
    prog, record, warnings = plan_targets(setup, paths, mode, calibrate=False)
    assert len(prog) == 2 * len(scene.targets) and not warnings
    assert record["mode"] == mode and record["pairs"] == []
    for k, t in enumerate(scene.targets):
        rows = prog.target == k
        assert sorted(prog.front_end[rows].tolist()) == [0, 1]
        np.testing.assert_allclose(prog.delay_s[rows], requested_delay(scene, t.range_m),
                                   rtol=1e-12)
        np.testing.assert_allclose(prog.doppler_hz[rows], 2 * scene.radar.f_c_hz * t.velocity_mps / c,
                                   rtol=1e-12)
        assert np.all(np.abs(prog.amplitude[rows]) > 0)
    if mode == "exact":
        _, cube = simulate(setup, paths, prog)
        rd, det = process(cube)
        from rtsgeom.run import match_targets
        for e in match_targets(scene, det, rd):
            assert abs(e["error"]["angle_deg"]) < 0.05


# -- analysis -------------------------------------------------------------------------------


def test_tolerance_table_spans_half_a_calibration_period():
    """The delay table of the tolerance model covers +-(half a period 1/(f_rts + B/2)) in
    delay-resolution steps, plus 4 for the refinement."""
    from rtsgeom.analysis.tolerance import PairPhasors
    scene = small_quiet([])
    model = PairPhasors.build(build_setup(scene), (0, 1), points=3)
    slope = scene.rts.f_rts_hz + 0.5 * scene.radar.bandwidth_hz
    assert model.max_steps == int(np.ceil(0.5 / (slope * scene.rts.delay_resolution_s))) + 4


@pytest.mark.parametrize("sigma", [[-1e-4, 0, 0], [0, float("nan"), 0], [0, 0, float("inf")]])
def test_monte_carlo_refuses_negative_or_non_finite_sigmas(sigma):
    from rtsgeom.analysis.tolerance import PairPhasors, monte_carlo
    model = PairPhasors.build(build_setup(small_quiet([])), (0, 1), points=3)
    with pytest.raises(ValueError, match="sigma_m"):
        monte_carlo(model, sigma, 4, seed=0)
