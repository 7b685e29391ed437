"""Signal chain against closed forms."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.constants import c

from rtsgeom.geometry import build_setup
from rtsgeom.geometry.farfield import apparent_azimuth_rad
from rtsgeom.paths import exact_paths
from rtsgeom.radar import process, synthesize
from rtsgeom.radar.dca1000 import from_dca1000, to_dca1000
from rtsgeom.radar.phasors import bin_response
from rtsgeom.radar.processing import estimate_angles, tdm_compensate
from rtsgeom.rts.channels import Echoes, RtsProgram, build_echoes, program_nearest
from rtsgeom.rts.fir import realised_delay
from rtsgeom.radar.frame import simulate
from rtsgeom.pipeline.matching import match_targets

from conftest import make_scene


def quiet(doc):
    """No noise, no ghosts: a clean channel for closed-form checks."""
    doc["radar"].pop("snr_db", None)
    for fe in doc["rts"]["front_ends"]:
        fe.pop("return_loss_fe_db", None)
        fe.pop("return_loss_be_db", None)


def one_echo(tau_s, v=8, doppler_hz=0.0):
    z = np.zeros(1)
    return Echoes(np.full((1, v), tau_s), z, z, np.full(1, doppler_hz), np.ones((1, v), complex),
                  np.zeros(1, int), np.zeros(1, int), np.zeros(1, int), np.zeros(1, int))


def test_beat_frequency_is_slope_times_delay():
    scene = make_scene(quiet)
    setup = build_setup(scene)
    r = scene.radar
    tau = 2 * 23.456 / c
    cube = synthesize(one_echo(tau), r, setup.rut)
    spec = np.abs(np.fft.fft(cube.data[0, 0] * np.hanning(r.samples_per_chirp)))
    f_peak = np.argmax(spec) * r.adc_rate_hz / r.samples_per_chirp
    assert abs(f_peak - r.bandwidth_hz / r.chirp_duration_s * tau) <= r.adc_rate_hz / r.samples_per_chirp / 2
    rd, det = process(cube)
    assert len(det) == 1
    assert det.range_m[0] == pytest.approx(c * tau / 2, abs=0.1 * r.range_resolution_m)


def first_target_delayed(extras_s):
    """The quiet default scene's first target alone, its RTS delay increased by each extra:
    yields (scene, range-Doppler, detections) per extra."""
    scene = make_scene(quiet)
    setup = build_setup(scene)
    paths = exact_paths(setup)
    base = program_nearest(scene, setup)
    keep = np.array([0])
    for extra in extras_s:
        prog = RtsProgram.build(base.target[keep], base.front_end[keep], base.delay_s[keep] + extra,
                                base.doppler_hz[keep], base.amplitude[keep])
        _, cube = simulate(setup, paths, prog)
        yield (scene, *process(cube))


def test_extra_rts_delay_moves_range_by_c_dtau_over_2():
    dtau = 2.0e-9
    ranges = []
    for scene, _, det in first_target_delayed((0.0, dtau)):
        ranges.append(det.range_m[np.argmax(det.power_db)])
    assert ranges[1] - ranges[0] == pytest.approx(c * dtau / 2, abs=0.05 * scene.radar.range_resolution_m)


@pytest.mark.parametrize("velocity", [-7.3, -2.0, 0.0, 4.0, 9.1])
def test_doppler_bin_of_a_moving_target(velocity):
    def mutate(doc):
        quiet(doc)
        doc["targets"] = [{"range_m": 30.0, "velocity_mps": velocity, "angle_deg": 3.4}]
    scene = make_scene(mutate)
    setup = build_setup(scene)
    _, cube = simulate(setup, exact_paths(setup), program_nearest(scene, setup))
    rd, det = process(cube)
    k = np.argmax(det.power_db)
    dv = scene.radar.velocity_resolution_mps
    expected_bin = int(round(velocity / dv)) + scene.radar.chirps_per_tx // 2
    assert det.doppler_bin[k] == expected_bin
    assert det.velocity_mps[k] == pytest.approx(velocity, abs=0.1 * dv)


def test_single_front_end_detected_at_its_geometric_angle_in_far_field():
    # no Rx/Tx separation and a distant arc: what is left is the parallax of the RuT's own Tx
    # and Rx groups, ~2.5 d cos^2(theta) / R = 0.014 deg at 20 m
    def mutate(doc):
        quiet(doc)
        doc["rts"]["arc_radius_m"] = 20.0
        doc["sheet"]["enabled"] = False
        for fe in doc["rts"]["front_ends"]:
            fe["rx_tx_separation_m"] = 0.0
        doc["targets"] = [{"range_m": 30.0, "angle_deg": 3.4}, {"range_m": 40.0, "angle_deg": 12.2}]
    scene = make_scene(mutate)
    setup = build_setup(scene)
    _, cube = simulate(setup, exact_paths(setup), program_nearest(scene, setup))
    rd, det = process(cube)
    m = match_targets(scene, det, rd)
    for entry, geo in zip(m, np.degrees(setup.fe_azimuth_rad())):
        assert entry["detection"]["angle_deg"] == pytest.approx(geo, abs=0.02)


def test_single_front_end_bias_at_1m_matches_geometry(default_scene):
    # at R_c = 1 m the RuT sees each front end off its module angle (Rx/Tx separation and the
    # RuT's own Tx/Rx parallax); the detected angle must equal the exact per-element model's
    # beamformer peak, and the far-field closed form explains the separation part.
    scene = make_scene(quiet)
    setup = build_setup(scene)
    paths = exact_paths(setup)
    prog = program_nearest(scene, setup)
    ech, cube = simulate(setup, paths, prog)
    rd, det = process(cube)
    m = match_targets(scene, det, rd)
    for entry, q in zip(m, prog.front_end):
        sub = ech.select(ech.target == entry["index"])
        # phasor-level prediction at the detection's own bins
        k = int(np.argmin(np.abs(det.range_m - entry["detection"]["range_m"])))
        snap = bin_response(sub, scene.radar, setup.rut, [det.range_bin[k]], [det.doppler_bin[k]]).sum(1)
        snap = tdm_compensate(snap, sub.doppler_hz[0], setup.rut, scene.radar)
        predicted = np.degrees(estimate_angles(snap, setup.rut, scene.radar))[0]
        assert entry["detection"]["angle_deg"] == pytest.approx(predicted, abs=0.005)
        closed = np.degrees(apparent_azimuth_rad(setup.rut, setup.fe.rx[q], setup.fe.tx[q]))
        geo = np.degrees(setup.fe_azimuth_rad()[q])
        assert closed - geo == pytest.approx(0.30, abs=0.02)  # separation part, 20 mm at 1 m
        assert predicted - geo > closed - geo  # plus the RuT's own Tx/Rx parallax


def test_phase_slope_of_rts_delay_is_f_rts_plus_half_bandwidth():
    # eq. (27): d phi / d tau_rts = 2 pi (f_rts + B/2) -> calibration period 1 ns in the paper
    d = 20e-12
    phases, bins = [], None
    for scene, rd, det in first_target_delayed((0.0, d)):
        if bins is None:  # the same bin for both (adjacent bins differ by pi)
            k = np.argmax(det.power_db)
            bins = det.range_bin[k], det.doppler_bin[k]
        phases.append(np.angle(rd.spectrum[bins[0], bins[1], 0]))
    slope = np.angle(np.exp(1j * (phases[1] - phases[0]))) / d
    expected = 2 * np.pi * (scene.rts.f_rts_hz + scene.radar.bandwidth_hz / 2)
    assert slope == pytest.approx(expected, rel=0.01)
    assert 1 / (scene.rts.f_rts_hz + scene.radar.bandwidth_hz / 2) == pytest.approx(1e-9)


def test_delay_quantisation():
    ts = 1 / 4e9
    assert realised_delay(1.2345e-9, 4e9, False, 1e-12) == pytest.approx(5 * ts)
    assert realised_delay(1.2345e-9, 4e9, True, 1e-12) == pytest.approx(1.234e-9, abs=1e-15)


def test_table1_targets_on_nearest_front_end(default_scene):
    setup = build_setup(default_scene)
    paths = exact_paths(setup)
    prog = program_nearest(default_scene, setup)
    _, cube = simulate(setup, paths, prog, seed=1, snr_db=default_scene.radar.snr_db)
    rd, det = process(cube)
    m = match_targets(default_scene, det, rd)
    for entry in m:
        e = entry["error"]
        assert e is not None
        assert abs(e["range_bins"]) < 1 and abs(e["doppler_bins"]) < 1


def test_phasor_model_matches_fft_chain(default_scene):
    setup = build_setup(default_scene)
    ech = build_echoes(setup, exact_paths(setup), program_nearest(default_scene, setup))
    cube = synthesize(ech, default_scene.radar, setup.rut)
    rd, det = process(cube)
    b = bin_response(ech, default_scene.radar, setup.rut, det.range_bin, det.doppler_bin).sum(1)
    ref = rd.spectrum[det.range_bin, det.doppler_bin]
    assert np.max(np.abs(b - ref)) < 1e-5 * np.max(np.abs(ref))


def test_cable_ghost_lies_l_over_vf_behind_target():
    def mutate(doc):
        doc["radar"].pop("snr_db", None)
        doc["targets"] = [{"range_m": 30.0, "angle_deg": 3.4}]
    scene = make_scene(mutate)
    setup = build_setup(scene)
    ech, cube = simulate(setup, exact_paths(setup), program_nearest(scene, setup))
    rd, det = process(cube)
    fe = scene.rts.front_ends[0]
    offset = fe.cable_length_m / fe.cable_velocity_factor
    assert offset == pytest.approx(1.43, abs=0.005)
    # the first ghost is 9.5 range bins behind: inside its own target's CFAR training ring, so
    # look for it in the range-Doppler map as a person does
    k = int(np.argmax(det.power_db))
    prof = rd.power_db[:, det.doppler_bin[k]]
    near = np.abs(rd.range_m - (det.range_m[k] + offset)) < 2 * scene.radar.range_resolution_m
    j = np.flatnonzero(near)[np.argmax(prof[near])]
    assert 0 < j < len(prof) - 1 and prof[j] > prof[j - 1] and prof[j] > prof[j + 1]
    refined = rd.range_m[j] + 0.5 * (prof[j - 1] - prof[j + 1]) / (prof[j - 1] - 2 * prof[j] + prof[j + 1]) * (rd.range_m[1] - rd.range_m[0])
    assert refined - det.range_m[k] == pytest.approx(offset, abs=0.2 * scene.radar.range_resolution_m)
    g = ech.select(ech.kind == 1)
    rho = 2 * 10 ** (-(fe.return_loss_fe_db + fe.return_loss_be_db + 2 * fe.cable_loss_db) / 20)
    assert np.allclose(np.abs(g.amplitude[g.order == 1]) / np.abs(ech.amplitude[ech.kind == 0]), rho)
    assert prof[j] - det.power_db[k] == pytest.approx(20 * np.log10(rho), abs=1.0)


def test_noise_is_seeded(default_scene):
    setup = build_setup(default_scene)
    paths = exact_paths(setup)
    prog = program_nearest(default_scene, setup)
    a = simulate(setup, paths, prog, seed=7, snr_db=10.0)[1].data
    b = simulate(setup, paths, prog, seed=7, snr_db=10.0)[1].data
    c_ = simulate(setup, paths, prog, seed=8, snr_db=10.0)[1].data
    assert np.array_equal(a, b) and not np.array_equal(a, c_)
    assert a.dtype == np.complex64


def test_dca1000_layout_round_trip(default_scene):
    setup = build_setup(default_scene)
    _, cube = simulate(setup, exact_paths(setup), program_nearest(default_scene, setup))
    raw, scale = to_dca1000(cube)
    n_l, n_v, n_s = cube.shape
    n_rx = setup.rut.num_rx
    assert len(raw) == n_l * n_v * n_s * 2 * 2
    back = from_dca1000(raw, n_l * (n_v // n_rx), n_rx, n_s) / scale
    expect = cube.data.reshape(n_l * (n_v // n_rx), n_rx, n_s)  # transmit order
    assert np.max(np.abs(back - expect)) <= 0.71 / scale
    words = np.frombuffer(raw, "<i2")
    assert np.max(np.abs(words)) == 32767  # full scale, no clipping
    first = np.round(cube.data[0, 0, :2] * scale)
    assert list(words[:4]) == [first[0].real, first[1].real, first[0].imag, first[1].imag]


def test_fast_synthesis_matches_the_per_echo_reference(default_scene):
    from rtsgeom.radar.fmcw import synthesize_exact
    setup = build_setup(default_scene)
    ech = build_echoes(setup, exact_paths(setup), program_nearest(default_scene, setup))
    fast = synthesize(ech, default_scene.radar, setup.rut).data
    ref = synthesize_exact(ech, default_scene.radar, setup.rut).data
    scale = np.max(np.abs(ref))
    assert np.max(np.abs(fast - ref)) < 1e-5 * scale  # complex64 precision


def test_range_migration_in_the_exact_mode():
    # an RTS delay drifting at 2 v / c0 moves the echo by v * frame time: over many frames
    from rtsgeom.radar.fmcw import synthesize_exact
    def mutate(doc):
        quiet(doc)
        doc["radar"]["chirps_per_tx"] = 16
        doc["targets"] = [{"range_m": 30.0, "angle_deg": 3.4}]
    scene = make_scene(mutate)
    setup = build_setup(scene)
    ech = build_echoes(setup, exact_paths(setup), program_nearest(scene, setup))
    v = 500.0  # fast, so the migration within the frame is visible (m/s)
    frame = scene.radar.tdm_cycle_s * scene.radar.chirps_per_tx
    cube = synthesize_exact(ech, scene.radar, setup.rut, delay_rate=np.full(len(ech), 2 * v / c))
    first = np.argmax(np.abs(np.fft.fft(cube.data[0, 0] * np.hanning(scene.radar.samples_per_chirp))))
    last = np.argmax(np.abs(np.fft.fft(cube.data[-1, 0] * np.hanning(scene.radar.samples_per_chirp))))
    moved = (last - first) * scene.radar.range_resolution_m  # range bin spacing
    assert moved == pytest.approx(v * frame * (1 - 1 / 16), abs=scene.radar.range_resolution_m)
