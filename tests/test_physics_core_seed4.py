"""Tests written for the survivors of the second fresh mutation sample (``python -m
benchmarks.mutation --sample 160 --seed 4``), built as ``test_physics_core.py``'s
(closed forms and invariants on grids, through public functions, no module-scoped fixtures:
mutmut attributes a shared fixture to the first test that built it).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import ROOT, make_scene
from scipy.constants import c
from test_physics_core import _small_noiseless

# -- analysis.coverage: the binding constraint of a planned arc ------------------------------


@pytest.mark.parametrize("cov_deg", [(0.0, 12.0), (-20.0, 20.0), (0.0, 34.5), (0.0, 34.9)])
def test_planned_arc_is_bound_by_resolution_when_the_fewest_front_ends_suffice(cov_deg):
    """Without extra front ends the arc has at least n_bare = ceil(span / res) + 1 front ends
    (res = 1.22 lambda / d_A, eq. 24); its binding constraint is the resolution exactly when it
    has n_bare, the near-field bias when widening the span by the outer biases needs more."""
    from rtsgeom.analysis.coverage import plan_arc
    from rtsgeom.geometry import build_setup
    from rtsgeom.geometry.farfield import angular_resolution_rad
    scene = make_scene()
    a, b = (math.radians(x) for x in cov_deg)
    res = angular_resolution_rad(build_setup(scene).rut)
    n_bare = max(2, math.ceil((b - a) / res * (1 - 1e-12)) + 1)
    p = plan_arc(scene, (a, b), 1.0)
    assert p.front_ends >= n_bare
    assert p.binding[0] == ("resolution" if p.front_ends == n_bare else "near-field bias")
    assert p.resolution_deg == pytest.approx(math.degrees(res), rel=1e-12)


def test_coverage_designs_plan_every_radius_for_the_coverage_in_degrees():
    """``coverage_designs`` takes the coverage in degrees: each design's plan is
    ``plan_arc`` of the same coverage in radians at its radius."""
    from rtsgeom.analysis.coverage import coverage_designs, plan_arc
    scene = make_scene()
    out = coverage_designs(scene, (0.0, 12.0), [2.0], draws=2, points=3, extras=(0,))
    assert out.coverage_deg == (0.0, 12.0) and len(out.designs) == 1
    for r, d in zip((2.0,), out.designs):
        ref = plan_arc(scene, (0.0, math.radians(12.0)), r)
        assert d.plan.radius_m == r
        assert d.plan.angles_deg == pytest.approx(ref.angles_deg, abs=1e-12)


# -- geometry.setup: the RuT's yaw error ------------------------------------------------------


@pytest.mark.parametrize("yaw_deg", [-3.0, 0.5, 10.0])
@pytest.mark.parametrize("radar_yaw_deg", [0.0, 7.0])
def test_rut_yaw_error_rotates_the_array_about_its_position(yaw_deg, radar_yaw_deg):
    """``build_setup(rut_yaw_rad=y)`` turns every RuT element about the vertical axis through
    the RuT's position by y (distances to it kept, azimuths shifted by y), the front ends
    unmoved."""
    from rtsgeom.geometry import build_setup
    scene = make_scene(lambda d: d["radar"].update(yaw_deg=radar_yaw_deg))
    y = math.radians(yaw_deg)
    s0, s1 = build_setup(scene), build_setup(scene, rut_yaw_rad=y)
    p = np.asarray(scene.radar.position_m, float)
    rot = np.array([[math.cos(y), -math.sin(y), 0], [math.sin(y), math.cos(y), 0], [0, 0, 1]])
    for w0, w1 in ((s0.rut.tx_world, s1.rut.tx_world), (s0.rut.rx_world, s1.rut.rx_world)):
        r0, r1 = w0 - p, w1 - p
        np.testing.assert_allclose(np.linalg.norm(r1, axis=1), np.linalg.norm(r0, axis=1),
                                   atol=1e-12)
        assert np.allclose(r1, r0 @ rot.T, atol=1e-12) or np.allclose(r1, r0 @ rot, atol=1e-12)
        assert not np.allclose(r1, r0, atol=1e-9)
    np.testing.assert_array_equal(s1.fe.module, s0.fe.module)


# -- geometry.patterns: the power gain of a pattern --------------------------------------------


@pytest.mark.parametrize("hpbw_deg, peak_db", [(60.0, 0.0), (30.0, 6.0), (120.0, -3.0)])
def test_pattern_gain_db_is_twenty_log_of_the_field_and_finite_behind(hpbw_deg, peak_db):
    """``gain_db_towards`` is 20 log10 |field| (field gain, so the power gain in dB) on a grid
    of directions: peak_gain_db at boresight, -3 dB at half the half-power beamwidth, and a
    finite floor (not -inf) behind the antenna, where the field is 0."""
    from rtsgeom.geometry.patterns import CosinePattern
    pat = CosinePattern(math.radians(hpbw_deg), peak_gain_db=peak_db)
    th = np.radians(np.linspace(-89.0, 89.0, 37))
    v = np.stack([np.sin(th), np.cos(th), np.zeros_like(th)], -1)
    g = pat.gain_db_towards(v)
    np.testing.assert_allclose(g, 20 * np.log10(np.abs(pat.field(v))), atol=1e-9)
    half = math.radians(hpbw_deg / 2)
    edge = pat.gain_db_towards(np.array([math.sin(half), math.cos(half), 0.0]))
    assert float(edge) == pytest.approx(peak_db - 10 * math.log10(2), abs=1e-6)
    assert float(pat.gain_db_towards(np.array([0.0, 1.0, 0.0]))) == pytest.approx(peak_db)
    behind = pat.gain_db_towards(np.array([[0.0, -1.0, 0.0], [0.3, -0.9, 0.0]]))
    assert np.all(np.isfinite(behind)) and np.all(behind < -1000)


# -- radar.processing / capture: empty detections, the xarray export, bad captures ----------


@pytest.mark.parametrize("preset", ["awr1843boost", "iwr6843isk"])
def test_a_silent_cube_has_no_detections_and_empty_angles(preset):
    """No echo (an empty program, no noise): CFAR finds nothing and every column of the
    detection list is empty, the angles included (D = 1 and D = 2 arrays)."""
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.radar.frame import simulate
    from rtsgeom.radar.processing import process
    from rtsgeom.rts.channels import RtsProgram
    setup = build_setup(_small_noiseless(lambda d: d["radar"].update(antenna_preset=preset)))
    _, cube = simulate(setup, exact_paths(setup), RtsProgram.build([], [], [], [], []))
    rd, det = process(cube)
    assert len(det) == 0
    for name in ("range_m", "velocity_mps", "angle_rad", "power_db", "snr_db"):
        assert getattr(det, name).shape == (0,), name
    da = rd.to_xarray()
    assert da.attrs["description"] == "sum over virtual channels of |X|^2"
    assert da.dims == ("range_m", "velocity_mps") and da.shape == rd.power.shape


@pytest.mark.parametrize("bad", ["real", "2d"])
def test_a_capture_that_is_not_a_complex_3d_cube_is_refused(tmp_path, bad):
    """``read_capture`` refuses a ``.npy`` whose data is real (a 3-D cube of floats) or complex
    but not 3-D, naming the file."""
    from rtsgeom.geometry import build_setup
    from rtsgeom.identify.capture import read_capture, simulate_capture, write_capture
    setup = build_setup(_small_noiseless())
    cap = simulate_capture(setup, 0, seed=1)
    out = tmp_path / "cap.npy"
    write_capture(cap, setup.rut, out, "npy")
    data = np.real(cap.data) if bad == "real" else cap.data[0]
    np.save(out, data)
    with pytest.raises(ValueError, match="cap.npy: expected a complex"):
        read_capture(out)


# -- rts.channel_echoes: every path combination of the two legs --------------------------------


@pytest.mark.parametrize("extra_tx, extra_rx", [(1, 0), (0, 2), (2, 1)])
def test_channel_echoes_pair_every_path_of_one_leg_with_every_path_of_the_other(extra_tx,
                                                                              extra_rx):
    """A leg with Pa paths (Tx -> front end) and one with Pb (front end -> Rx) give Pa x Pb
    direct echoes per channel and virtual element, with delays tau_a + tau_b (+ the RTS's)
    and amplitudes conj(g_a g_b G): here the line-of-sight legs plus copies 0.1 ns later each
    and half as strong, so the echoes' delays are the LoS one plus 0.1 ns x (m + n)."""
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.paths.table import FE_TO_RX, TX_TO_FE, Paths
    from rtsgeom.rts.channels import KIND_DIRECT, RtsProgram, channel_echoes
    setup = build_setup(_small_noiseless())
    los = exact_paths(setup)
    extra = []
    for direction, count in ((TX_TO_FE, extra_tx), (FE_TO_RX, extra_rx)):
        leg = los.select(los.direction == direction)
        for m in range(1, count + 1):
            extra.append(Paths.build(leg.front_end, leg.direction, leg.rut_tx, leg.rut_rx,
                                     leg.delay_s + m * 0.1e-9, leg.gain * 0.5 ** m,
                                     np.ones(len(leg), int)))
    paths = Paths.concat([los, *extra])
    prog = RtsProgram.build([0, 1], [0, 1], [1e-7, 1.2e-7], [0.0, 0.0], [1.0, 0.5])
    ref = channel_echoes(setup, los, prog)
    ref = ref.select(ref.kind == KIND_DIRECT)
    got = channel_echoes(setup, paths, prog)
    got = got.select(got.kind == KIND_DIRECT)
    pa, pb = 1 + extra_tx, 1 + extra_rx
    assert len(got) == len(ref) * pa * pb
    for k in range(len(prog)):
        r = np.flatnonzero(ref.target == k)[0]
        rows = np.flatnonzero(got.target == k)
        assert rows.size == pa * pb
        lag = got.tau_air_s[rows] - ref.tau_air_s[r]  # (Pa Pb, V): 0.1 ns x (m + n)
        steps = np.round(lag / 0.1e-9)
        np.testing.assert_allclose(lag, steps * 0.1e-9, atol=1e-15)
        expect = sorted(m + n for m in range(pa) for n in range(pb))
        assert sorted(steps[:, 0].astype(int).tolist()) == expect
        np.testing.assert_allclose(got.amplitude[rows], ref.amplitude[r] * 0.5 ** steps,
                                   rtol=1e-12)


# -- radar.steering.peak: what did not converge falls back to the grid search -----------------


@pytest.mark.parametrize("angles_deg", [(-20.0, 5.0), (3.0,), (0.0, 12.0, -40.0)])
def test_unconverged_peaks_fall_back_to_the_search_and_the_others_keep_newton(angles_deg):
    """A batch of plane waves and silent snapshots (no power: Newton cannot converge): each
    plane wave's u is sin(alpha) and converged; each silent one is not converged and its u is
    the grid search's (``Steering.search``), in its own place of the batch."""
    from rtsgeom.geometry import build_setup
    from rtsgeom.radar.steering import Steering
    scene = make_scene()
    st = Steering.build(build_setup(scene).rut, scene.radar)
    u_true = np.sin(np.radians(angles_deg))
    waves = np.exp(-1j * np.outer(u_true, st.wavevector[:, 0]))  # (A, V_s) plane waves
    silent_rows = np.zeros((2, waves.shape[1]), complex)
    full = np.concatenate([waves, silent_rows])[[0, -1, *range(1, len(u_true)), -2]]
    assert st.dims == 1
    u, ok = st.peak(full, 0.0)
    silent = np.all(full == 0, axis=1)
    assert np.array_equal(ok, ~silent)
    np.testing.assert_allclose(u[~silent, 0], u_true, atol=1e-6)
    np.testing.assert_allclose(u[silent, 0], np.sin(st.search(full[silent])), atol=1e-12)


# -- calibration.fit.fit_centre: the search half-width -----------------------------------------


@pytest.mark.parametrize("offset_steps", [-3.2, 2.6, 4.0])
def test_fit_centre_searches_the_half_width_it_is_given(offset_steps):
    """The curves' centre ``offset_steps`` sweep steps from the coarse minimum: the default
    search (1.5 steps either side) stops at its edge, a ``search_s`` of 5 steps finds the
    centre within 0.05 ps."""
    from rtsgeom.calibration.fit import fit_centre
    period, step = 1.0e-9, 25e-12
    d = np.arange(-20, 21) * step
    true = offset_steps * step
    th = 2 * np.pi * (d - true) / period
    e = np.stack([0.8 * (1 - np.cos(th)), -0.5 * (1 - np.cos(th))], axis=1)
    near = fit_centre(d, e, period, 0.0)
    assert near == pytest.approx(math.copysign(1.5 * step, offset_steps), abs=0.051e-12)
    wide = fit_centre(d, e, period, 0.0, search_s=5 * step)
    assert wide == pytest.approx(true, abs=0.051e-12)


# -- aoa.calibration.calibrate_pair: probe placement and frames per step -----------------------


@pytest.mark.parametrize("dr_mm", [0.0, -0.2])
def test_pair_calibration_places_its_probes_over_the_fine_window_and_reports_its_frames(dr_mm):
    """Step 2 of ``calibrate_pair``: the probes' ranges are where ``sweep.place_probes`` puts
    them for the window +-period/4 around the coarse minimum (the fine sweep's centre), not
    for one delay of it; a noiseless sweep averages one frame per step, ``frames`` sets it."""
    from rtsgeom.calibration.pair import calibrate_pair
    from rtsgeom.paths import nominal_model
    from rtsgeom.calibration.probes import probe_angles, probe_front_ends, probe_ranges
    from rtsgeom.calibration.phasor import place_probes
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    setup = build_setup(_small_noiseless(
        lambda d: d["rts"]["front_ends"][1].update(radial_offset_mm=dr_mm)))
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, 0)
    span = (-0.6e-9, 0.6e-9)
    cal = calibrate_pair(setup, paths, (0, 1), probe, span_s=span)
    assert cal.frames_per_step == 1
    near = cal.refine_delta_tau_s[cal.refine_delta_tau_s.size // 2]
    half, step = cal.period_s / 4, setup.scene.rts.calibration_step_s
    alphas = np.asarray(probe_angles(probe.angle_rad[0], probe.angle_rad[1]))
    expect = place_probes(setup, paths, nominal_model(setup, paths), (0, 1),
                          probe_ranges(setup, 2), alphas, near + np.arange(-half, half + 1e-15, step),
                          (0.0, 0.0), tuple(probe.gain_correction[[0, 1]]))
    np.testing.assert_allclose(cal.probe_ranges_m, expect, rtol=1e-12)
    assert calibrate_pair(setup, paths, (0, 1), probe, span_s=span, frames=3).frames_per_step == 3


# -- aoa.plan / plan_cells: the calibration record and the programmed Doppler ------------------


def test_plan_record_says_where_its_calibration_came_from():
    """Measured front-end angles (no calibration file): the record's source is "measured"."""
    from rtsgeom.pipeline.plan import plan_targets
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    setup = build_setup(_small_noiseless())
    _, record, _ = plan_targets(setup, exact_paths(setup), "array-factor", calibrate=False)
    assert record["source"] == "measured"


@pytest.mark.parametrize("velocity_mps", [-5.0, 0.0, 3.0])
def test_cell_plan_programs_the_doppler_of_each_targets_velocity(velocity_mps):
    """Front ends on a sphere (N channels per target): every channel of target k is programmed
    with the Doppler 2 f_c v_k / c0 of its set velocity."""
    import tomllib

    from rtsgeom.pipeline.plan import plan_targets, uses_cells
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.scene import parse_scene
    doc = tomllib.loads((ROOT / "scenes" / "sphere4.toml").read_text())
    for k, t in enumerate(doc["targets"]):
        t["velocity_mps"] = velocity_mps * (k + 1) / len(doc["targets"])
    scene = parse_scene(doc, str(ROOT / "scenes" / "sphere4.toml"))
    assert uses_cells(scene)
    setup = build_setup(scene)
    prog, _, _ = plan_targets(setup, exact_paths(setup), "array-factor", calibrate=False)
    for k, t in enumerate(scene.targets):
        rows = np.asarray(prog.target) == k
        assert rows.sum() >= 3
        np.testing.assert_allclose(prog.doppler_hz[rows], 2 * scene.radar.f_c_hz * t.velocity_mps
                                   / c, rtol=1e-12, atol=1e-9)


# -- analysis.ghosts: a strong ghost outside the CFAR window is detected ----------------------


@pytest.mark.parametrize("cable_m", [3.0, 6.0, 9.0])
def test_strong_cable_ghosts_outside_the_cfar_window_are_reported_as_detected(cable_m):
    """A badly matched cable (6 dB return loss at both ends, no loss): ghost n lies n L / VF
    behind the target; ``cfar_detected`` is whether the run's CFAR list has a detection within
    one bin of the ghost, and the first ghost (-6 dB, beyond the CFAR ring once L / VF exceeds
    it) is one."""
    from rtsgeom.analysis.ghosts import ghost_analysis

    def m(doc):
        doc["radar"].update(chirps_per_tx=32, samples_per_chirp=128, adc_rate_hz=12.5e6)
        doc.update(targets=[{"range_m": 12.0, "angle_deg": 3.4}])
        doc["rts"]["front_ends"][0].update(cable_length_m=cable_m, return_loss_fe_db=6.0,
                                           return_loss_be_db=6.0, cable_loss_db=0.0)
    scene = make_scene(m)
    rep = ghost_analysis(scene, simulate=True)
    rd, det = rep.result.rd, rep.result.detections
    bin_m = rd.range_m[1] - rd.range_m[0]
    vf = scene.rts.front_ends[0].cable_velocity_factor
    ghosts = [g for g in rep.simulated[0]["ghosts"] if not g.get("beyond_max_range")]
    for g in ghosts:
        if g["level_db"] > -30:  # well above the range sidelobes: where it was predicted
            assert g["offset_from_target_m"] == pytest.approx(g["order"] * cable_m / vf,
                                                              abs=1.5 * bin_m)
        near = np.any(np.abs(det.range_m - g["range_m"]) <= 1.5 * bin_m)
        assert g["cfar_detected"] is bool(near), g
    first = ghosts[0]
    ring = scene.radar.cfar.guard_cells[0] + scene.radar.cfar.training_cells[0]
    if cable_m / vf > (ring + 1) * bin_m:
        assert first["order"] == 1 and first["cfar_detected"] is True
        assert not first["within_cfar_window_of_target"]


# -- aoa.ncal: the scene seed enters every noise draw modulo 2^32 -----------------------------


@pytest.mark.parametrize("seed", [3, 5])
def test_channel_calibration_depends_on_the_seed_modulo_2_to_the_32(seed):
    """``scene.seed`` may be up to 2^63 - 1; every noise draw of the calibration (the pair
    sweeps and the residual check at the cell centre) takes it modulo 2^32, so seeds 2^32
    apart give the same calibration and residual, and neighbouring seeds different noise."""
    from rtsgeom.calibration.probes import probe_front_ends
    from rtsgeom.calibration.channels import calibrate_channels
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    setup = build_setup(make_scene(lambda d: d["radar"].update(
        chirps_per_tx=32, samples_per_chirp=128, adc_rate_hz=12.5e6, snr_db=20.0)))
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, 1)

    def cal(s):
        return calibrate_channels(setup, paths, (0, 1), probe, seed=s, span_s=(-0.3e-9, 0.3e-9),
                                  step_s=100e-12)
    a = cal(seed)
    for k in (1, 2 ** 8):
        b = cal(seed + k * 2 ** 32)
        assert np.array_equal(a.offsets_s, b.offsets_s) and a.residual_deg == b.residual_deg
    assert cal(seed + 1).residual_deg != a.residual_deg


# -- radar.steering.build: the 2-D aperture of an explicit array -------------------------------


@pytest.mark.parametrize("unit", [2, 4, 16])
@pytest.mark.parametrize("n_rx, n_tx", [(4, 2), (3, 3)])
def test_2d_steering_aperture_counts_distinct_positions_in_grid_units(unit, n_rx, n_tx):
    """An explicit array (Tx stacked in z, Rx in a row in x, both on a lambda/2 lattice) with
    the grid unit d = lambda / ``unit``: the 2-D beamformer's aperture per axis is the number
    of distinct virtual positions on that axis times d (n_rx d in x, n_tx d in z), whatever d
    (the global check's grid density follows it)."""
    from rtsgeom.geometry.arrays import array_from_spec
    from rtsgeom.radar.steering import Steering
    from rtsgeom.scene.presets import ArraySpec
    scene = make_scene()
    lam = c / scene.radar.f_c_hz
    tx = tuple((0.0, k * lam / 2) for k in range(n_tx))
    rx = tuple((k * lam / 2, 0.0) for k in range(n_rx))
    rut = array_from_spec(ArraySpec(tx, rx, tuple(range(n_tx)), spacing_m=lam / unit), lam)
    st = Steering.build(rut, scene.radar, elevation=True)
    np.testing.assert_allclose(st.aperture_m, np.array([n_rx, n_tx]) * lam / unit, rtol=1e-12)
    n_grid = [int(np.ceil(16 * a / lam)) + 1 for a in st.aperture_m]
    assert st.grid().shape[0] <= n_grid[0] * n_grid[1]
