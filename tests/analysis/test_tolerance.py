"""Mounting-tolerance Monte Carlo: the phasor model against the exact
spectrum and the ADC cube, calibration physics, reproducibility, the CLI."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from conftest import (
    DEFAULT_SCENE,
    ROOT,
    SETUP_ERRORS,
    make_scene,
    scenes_with_and_without_error,
    small_quiet,
    two_front_end_pair,
)
from scipy.constants import c

from rtsgeom.analysis.tolerance.config import MonteCarlo
from rtsgeom.analysis.tolerance.draws import draw_offsets
from rtsgeom.analysis.tolerance.montecarlo import monte_carlo
from rtsgeom.analysis.tolerance.phasors import CASES, NOMINAL_AMPLITUDES, ChannelPhasors
from rtsgeom.analysis.tolerance.search import max_sigma_for_yield
from rtsgeom.analysis.tolerance.study import ToleranceStudy
from rtsgeom.cli import main
from rtsgeom.errors import ParameterError
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.radar import process
from rtsgeom.radar.frame import simulate
from rtsgeom.radar.processing import estimate_angles, refine_angles, tdm_compensate
from rtsgeom.rts.channels import RtsProgram, requested_delay
from rtsgeom.scene import TargetConfig
from rtsgeom.synthesis.model import ChannelModel

ZERO = np.zeros((2, 3))


@pytest.fixture(scope="module")
def scene():
    return make_scene()


@pytest.fixture(scope="module")
def model(scene):
    return ChannelPhasors.build(build_setup(scene), (0, 1))


def worst(err):
    return np.take_along_axis(err, np.argmax(np.abs(err), axis=-1)[..., None], axis=-1)[..., 0]


# -- refine_angles ----------------------------------------------------------------------------


def test_refine_angles_agrees_with_the_grid_search(model):
    rut, radar = model.setup.rut, model.setup.scene.radar
    rng = np.random.default_rng(3)
    # synthesized targets with random phase errors (up to destructive) and amplitude ratios
    x = model.x_nominal
    rho = np.exp(rng.uniform(-3, 3, 400))
    phase = rng.uniform(-np.pi, np.pi, 400)
    snaps = x[0] + (rho * np.exp(1j * phase))[:, None] * x[1]
    start = np.full(400, np.radians(8.0))
    got, ok = refine_angles(snaps, rut, radar, start, return_converged=True)
    ref = estimate_angles(snaps, rut, radar)
    assert np.max(np.abs(np.degrees(got - ref))) < 2e-5  # the grid search's own precision
    assert ok.mean() > 0.95  # the restart from the coarse grid catches far peaks
    # a peak far from the start (the other lobe) is still found, never a local one
    far = refine_angles(x[1], rut, radar, np.radians(-40.0))
    assert abs(np.degrees(far - estimate_angles(x[1], rut, radar))) < 2e-5


# -- the phasor model -------------------------------------------------------------------------


def test_phasor_model_matches_bin_response_on_drawn_setups(scene, model):
    """Per element and channel, the first-order phasor against the exact spectrum
    (``bin_response`` through ChannelModel) of the drawn setup, with and without the
    calibration delay on channel J. The neglected terms are the range window's curvature
    (quadratic in the echo's sub-bin shift S dtau N / f_adc ~ 4e-3 bins here: ~1e-5) and
    -S dtau^2/2."""
    offsets = draw_offsets(7, 3, [3e-4] * 3)
    res = model.delay_resolution_s
    for off in offsets:
        setup = build_setup(scene, offsets_m=off)
        paths = exact_paths(setup)
        x, shift = model.channel_phasors(off, return_shift=True)
        k = int(model.calibration_steps(x)[1])
        assert k != 0
        for delta in (0.0, k * res):
            pm = ChannelModel.build(setup, paths, (0, 1), TargetConfig(model.range_m),
                                    (0.0, delta))
            exact = tdm_compensate(pm.responses[1], 0.0, setup.rut, scene.radar)
            want = x.copy()
            if delta:
                i = k + model.procedure.max_steps
                want[1] *= model.procedure.delay_factor[i] * np.exp(model.procedure.delay_log_slope[i] * shift[1])
            assert np.max(np.abs(want / exact - 1)) < 5e-5
            assert np.max(np.abs(np.angle(want / exact))) < 1e-7


def test_design_puts_the_set_points_on_their_angles(model):
    """The one channel model's design (``solve`` and ``amplitudes`` for the calibrated phase):
    each set-point's combined target is detected at its set angle and is as strong at its peak
    as one channel alone (the target keeps its RCS); the pair's closed form of the same
    engine (used by the calibration and the exact mode) gives the same ratios."""
    ch = model.channels
    w = model.amplitudes * np.exp(1j * ch.coherent_phases(ch.steering.directions(model.procedure.probe_rad)))
    assert np.max(np.abs(np.degrees(ch.direction(w) - model.set_rad))) < 1e-5
    st = ch.steering
    p_set = np.diagonal(st.power(ch.snapshot(w), st.directions(model.set_rad)))
    single = ch.snapshot(np.array([ch.unit_gain, 0.0]))
    p_one = st.power(single, st.directions(np.array([st.search(single)])))[0]
    assert np.allclose(p_set, p_one, rtol=1e-9)
    phases = (0.0, float(ch.pair_phase(model.procedure.probe_rad)))
    for m in (0, 7, 20):
        rho = ch.pair_ratio(float(model.set_rad[m]), phases)
        assert model.amplitudes[m, 1] / model.amplitudes[m, 0] == pytest.approx(rho, rel=1e-9)


def test_redesign_for_the_delay_matches_pair_model(model):
    """The operator's redesign for the calibration delay (J's amplitude over the delay's loss at
    the bin, first order) against the channel model built with that delay (its range offset
    included, solved exactly)."""
    pm_paths = exact_paths(model.setup)
    rut, radar = model.setup.rut, model.setup.scene.radar
    for k in (150, -400):
        pm = ChannelModel.build(model.setup, pm_paths, (0, 1), TargetConfig(model.range_m),
                                (0.0, k * model.delay_resolution_s))
        delayed = tdm_compensate(pm.responses[1], 0.0, rut, radar)
        phase = float(model.procedure.coherence_phase(model, delayed))
        gain = 1 / abs(model.procedure.delay_factor[k + model.procedure.max_steps][rut.azimuth_mask].mean())
        assert gain > 1.0  # the echo left the bin centre
        for m in (0, 10, 20):
            rho = pm.pair_ratio(float(model.set_rad[m]), (0.0, phase))
            mine = model.amplitudes[m, 1] * gain / model.amplitudes[m, 0]
            assert mine == pytest.approx(rho, rel=1e-4)


def test_agrees_with_the_adc_cube(scene, model):
    """The phasor level against the full chain: drawn setup, ADC cube (noise-free), FFTs, CFAR,
    beamforming, with the same delay offset on channel J and the same amplitudes (gain
    correction and the redesign for the delay included)."""
    tau = float(requested_delay(scene, model.range_m))
    az = model.setup.rut.azimuth_mask
    sets = [0, 10, 20]
    for off in draw_offsets(11, 3, [3e-4] * 3):
        setup = build_setup(scene, offsets_m=off)
        paths = exact_paths(setup)
        x = model.channel_phasors(off)
        k = int(model.calibration_steps(x)[1])
        g = model.gain_correction(x)
        redesign = 1 / abs(model.procedure.delay_factor[k + model.procedure.max_steps][az].mean())
        for case in CASES + (NOMINAL_AMPLITUDES,):
            phasor = model.angle_errors(off, case)[sets]
            cal = case != "uncalibrated"
            gi, gj = (g[0], g[1] * (redesign if case == "calibrated" else 1.0)) if cal else (1, 1)
            delay = k * model.delay_resolution_s if cal else 0.0
            for m, want in zip(sets, phasor):
                a_i, a_j = model.amplitudes[m]
                prog = RtsProgram.build([0, 0], [0, 1], [tau, tau + delay], [0.0, 0.0],
                                        [a_i * gi, a_j * gj])
                _, cube = simulate(setup, paths, prog)
                rd, det = process(cube)
                near = np.abs(det.range_m - model.range_m) < 2 * scene.radar.range_resolution_m
                n = np.flatnonzero(near)[np.argmax(det.power_db[near])]
                got = np.degrees(det.angle_rad[n] - model.set_rad[m])
                assert abs(got - want) < 1e-3, (case, m, got, want)  # required: 0.02 deg


# -- physics of the Monte Carlo -----------------------------------------------------------------


def test_sigma_zero_reproduces_the_nominal_error_exactly(model):
    res = monte_carlo(model, [0.0, 0.0, 0.0], 40, seed=5, chunk=16, subbin=False)
    for case in CASES:
        nominal = model.angle_errors(ZERO, case)
        w = res.worst_error_deg[case]
        assert np.all(w == w[0])  # bit-equal across draws (and chunks)
        # the drawn path goes through the general geometry (signed offsets, rotations, RuT
        # pose) and the nominal one through the shorthand: equal to rounding, not bit for bit
        assert w[0] == pytest.approx(worst(nominal), rel=1e-9, abs=1e-15)
        # the nominal error itself, with the grid-search estimator
        steps = None if case == "uncalibrated" else model.calibration_steps(model.x_nominal)[1]
        snaps = model.procedure.snapshots(model, model.x_nominal, steps)
        ref = np.degrees(estimate_angles(snaps, model.setup.rut, model.setup.scene.radar)
                         - model.set_rad)
        assert np.max(np.abs(nominal - ref)) < 2e-5
    per_point = model.angle_errors(np.zeros((6, 2, 3)), "calibrated")
    assert np.all(per_point == per_point[0])
    assert np.max(np.abs(per_point[0])) < 1e-4  # exact amplitudes, calibrated: ~3e-6 deg
    assert np.all(res.delay_s == res.delay_s[0])


def _sensitivities(model):
    """d alpha / d phi_J (first and second order) and d alpha / d ln A_J of the calibrated
    nominal synthesis, max over the set-points (deg per rad, deg per rad^2, deg)."""
    x0 = model.x_nominal
    k0 = model.calibration_steps(x0)[1]

    def rotated(phi=0.0, ln_a=0.0):
        f = model.procedure.delay_factor[k0 + model.procedure.max_steps]
        a = model.amplitudes
        snaps = (a[:, 0, None] * x0[0] + a[:, 1, None] * np.exp(ln_a + 1j * phi) * x0[1] * f)
        ang = refine_angles(snaps, model.channels.steering, None, model.set_rad)
        return np.degrees(ang - model.set_rad)
    h = 1e-3
    e0, ep, em = rotated(), rotated(h), rotated(-h)
    s1 = np.max(np.abs(ep - em) / (2 * h))
    s2 = np.max(np.abs(ep - 2 * e0 + em) / h ** 2) / 2
    sa = np.max(np.abs(rotated(ln_a=h) - rotated(ln_a=-h)) / (2 * h))
    return s1, s2, sa


def test_radial_errors_are_calibrated_back_to_the_nominal(model):
    """A radial error changes both legs of a front end by the same length to first order: a
    common phase per channel, which the delay calibration takes out. What is left, per draw:

    * quantisation: the applied phase misses the needed one by eps (|eps| <= pi (f_rts + B/2)
      dtau_res = 3.1 mrad, the table refinement's residual), so the error moves by at most
      S1 (|eps| + |eps_0|) + S2 (eps^2 + eps_0^2) from the nominal one (eps_0: the nominal's);
    * the calibration delay's range offset: the echo of J sits off the bin centre, where the
      draw's own air delay change dtau_J slides it along the window (J's amplitude off by
      d ln|W| / dtau * dtau_J, which the operator's model cannot know): S_A |ln a|;
    * geometry: the non-common part of the phase change (the radial direction is not the line
      of sight of every element), whose least-squares slope over the array moves the peak by
      at most (ptp / 2) sum|x - mean| / (k sum (x - mean)^2) in sin(alpha).
    """
    s1, s2, sa = _sensitivities(model)
    rut = model.setup.rut
    az = rut.azimuth_mask
    xv = rut.virtual_local[az, 0] - rut.virtual_local[az, 0].mean()
    slope_gain = 0.5 * np.sum(np.abs(xv)) / (2 * np.pi / rut.wavelength_m * np.sum(xv ** 2))
    table_phase = np.angle(model.procedure.delay_factor[:, az].mean(axis=1))

    def eps(x, k):
        need = model.procedure.coherence_phase(model, x)
        return np.angle(np.exp(1j * (table_phase[k + model.procedure.max_steps] - need)))

    x0 = model.x_nominal
    e_nom = model.angle_errors(ZERO, "calibrated")
    eps0 = eps(x0, model.calibration_steps(x0)[1])
    assert abs(eps0) <= np.pi * model.cal_slope_hz * model.delay_resolution_s * 1.01
    off = draw_offsets(21, 300, [2e-4, 0.0, 0.0])
    x, shift = model.channel_phasors(off, return_shift=True)
    k = model.calibration_steps(x)[..., 1]
    e = eps(x, k)
    quant = s1 * (np.abs(e) + abs(eps0)) + s2 * (e ** 2 + eps0 ** 2)
    i = k + model.procedure.max_steps
    ln_a = np.abs(np.log(np.abs(np.exp(model.procedure.delay_log_slope[i][:, az] * shift[:, 1][:, az])
                                .mean(axis=1))))
    psi = np.angle(x / x0)[..., az]
    geo = np.degrees(slope_gain * np.max(np.ptp(psi, axis=-1), axis=-1)
                     / np.cos(model.set_rad).min())
    bound = quant + sa * ln_a + geo
    dev = np.max(np.abs(model.angle_errors(off, "calibrated") - e_nom), axis=-1)
    assert np.all(dev <= bound)
    assert np.max(bound) < 0.02  # tight: 0.2 mm radial errors
    assert np.max(quant) < 1e-4  # at coherence the angle is stationary in the phase
    # uncalibrated, the same errors cost far more
    dev_unc = np.max(np.abs(model.angle_errors(off, "uncalibrated")
                            - model.angle_errors(ZERO, "uncalibrated")), axis=-1)
    assert np.median(dev_unc) > 20 * np.median(dev)


def test_same_seed_gives_identical_results(model):
    a = monte_carlo(model, [1e-4] * 3, 300, seed=9, chunk=64)
    b = monte_carlo(model, [1e-4] * 3, 300, seed=9, chunk=1000)
    c = monte_carlo(model, [1e-4] * 3, 300, seed=10)
    for case in CASES:
        assert np.array_equal(a.worst_error_deg[case], b.worst_error_deg[case])
        assert not np.array_equal(a.worst_error_deg[case], c.worst_error_deg[case])
    assert np.array_equal(a.delay_s, b.delay_s)
    assert a.to_dict() == b.to_dict()


@pytest.mark.parametrize("distribution", ["normal", "uniform"])
@pytest.mark.parametrize("chunk", [1, 7, 64, 1000])
def test_draw_chunks_regenerate_the_streams_bit_for_bit(distribution, chunk):
    """The chunks a cluster is sent (stream states, not draws) rebuild exactly the draws of
    standard_draws / subbin_draws, whatever the chunk size."""
    from rtsgeom.analysis.tolerance.draws import (
        DrawStreams,
        draw_chunks,
        standard_draws,
        subbin_draws,
    )
    sigma = np.array([1.0, 2.0, 3.0]) * 1e-4
    parts = list(draw_chunks(5, 300, 2, distribution, chunk, DrawStreams(positions=9, centre=4)))
    assert [p.k for p in parts] == [min(chunk, 300 - s) for s in range(0, 300, chunk)]
    offsets = np.concatenate([p.offsets() for p in parts]) * sigma
    subbin = np.concatenate([p.subbin() for p in parts])
    assert np.array_equal(offsets, np.concatenate(list(standard_draws(5, 300, distribution))) * sigma)
    assert np.array_equal(subbin, np.concatenate(list(subbin_draws(5, 300, 9))))
    centre = draw_chunks(5, 300, 2, distribution, chunk, DrawStreams(positions=None, centre=4))
    assert np.array_equal(np.concatenate([p.subbin() for p in centre]), np.full(300, 4))


@pytest.mark.parametrize("radius_m", [0.5, 2.0])
def test_pair_study_bits_do_not_depend_on_the_chunk_on_other_radii(radius_m):
    """The same bits whatever the chunk (1 draw, odd sizes, all at once), also at 0.5 m where the
    multi-degree uncalibrated errors once differed by 2e-15 deg between chunk sizes (the
    numpy Newton/grid check on the chunk's batch, before the per-row compiled kernels)."""
    _, two = two_front_end_pair(radius_m)
    sigma = np.array([0.3, 0.2, 0.2]) * 1e-3
    whole = monte_carlo(two, sigma, 120, 4, "normal", 0.05, chunk=120)
    for chunk in (1, 7, 40):
        part = monte_carlo(two, sigma, 120, 4, "normal", 0.05, chunk=chunk)
        for case in CASES:
            assert np.array_equal(part.worst_error_deg[case], whole.worst_error_deg[case])
        assert np.array_equal(part.delay_s, whole.delay_s)


def test_fork_pool_gives_bit_identical_results(model):
    """--workers N (a forked process pool) equals the single-process run bit for bit."""
    import functools

    from rtsgeom._lib.parallel import _can_fork, fork_map
    if not _can_fork():
        pytest.skip("no fork on this platform")
    local = monte_carlo(model, [1e-4] * 3, 300, seed=9, chunk=64)
    pooled = monte_carlo(model, [1e-4] * 3, 300, seed=9, chunk=64,
                         mapper=functools.partial(fork_map, workers=2))
    for case in CASES:
        assert np.array_equal(local.worst_error_deg[case], pooled.worst_error_deg[case])
    assert np.array_equal(local.delay_s, pooled.delay_s)
    assert local.to_dict() == pooled.to_dict()


def test_fork_pool_is_kept_across_studies_of_one_model(model):
    """chunk_mapper's ForkPool forks once for a command's studies of one model (a yield
    search: many Monte Carlos), forks anew for another model, and every study equals the
    single-process run bit for bit."""
    from rtsgeom._lib.parallel import ForkPool, _can_fork
    if not _can_fork():
        pytest.skip("no fork on this platform")
    other = ChannelPhasors.build(build_setup(make_scene()), (0, 1), points=3)
    with ForkPool(2) as pool:
        pids = []
        for m, sigma in ((model, 1e-4), (model, 3e-4), (other, 2e-4)):
            local = monte_carlo(m, [sigma] * 3, 200, seed=5, chunk=50)
            pooled = monte_carlo(m, [sigma] * 3, 200, seed=5, chunk=50, mapper=pool.map)
            assert local.to_dict() == pooled.to_dict()
            for case in CASES:
                assert np.array_equal(local.worst_error_deg[case], pooled.worst_error_deg[case])
            pids.append(sorted(p.pid for p in pool._pool._pool))
        assert pids[0] == pids[1] != pids[2]
    assert pool._pool is None


def test_larger_sigma_gives_larger_p95(model):
    p95 = {case: [] for case in CASES}
    for sigma in (0.03e-3, 0.1e-3, 0.3e-3):
        res = monte_carlo(model, [sigma] * 3, 400, seed=2)
        for case in CASES:
            p95[case].append(res.stats(case)["angle_error_deg"]["p95"])
    for case in CASES:
        assert np.all(np.diff(p95[case]) > 0), (case, p95[case])
    assert p95["uncalibrated"][1] > 5 * p95["calibrated"][1]


def test_uniform_draws_stay_within_their_bounds():
    off = draw_offsets(4, 2000, [1e-4, 2e-4, 3e-4], "uniform")
    assert np.all(np.abs(off) <= np.array([1e-4, 2e-4, 3e-4]))
    assert np.all(np.abs(off).max(axis=(0, 1)) > 0.99 * np.array([1e-4, 2e-4, 3e-4]))


def test_inversion_finds_the_sigma_at_the_yield(model):
    inv = max_sigma_for_yield(model, [1e-4] * 3, MonteCarlo(draws=400, seed=4), target_yield=0.9,
                              spec_deg=0.1, case="uncalibrated", rel_tol=0.02)
    sig = inv["sigma_mm"]["radial"]
    assert inv["sigma_mm"]["tangential"] == sig == inv["sigma_mm"]["height"]
    assert inv["yield"] >= 0.9 and not inv["capped"]
    ev = sorted((e["scale_mm"], e["yield"]) for e in inv["evaluations"])
    assert all(y1 >= y2 for (_, y1), (_, y2) in zip(ev, ev[1:]))  # monotone in sigma
    above = [y for s, y in ev if s > sig]
    assert above and max(above) < 0.9
    # one axis: height errors are second order (both legs grow by dz^2 / 2R): never the limit
    h = max_sigma_for_yield(model, [1e-5] * 3, MonteCarlo(draws=200, seed=4), target_yield=0.9,
                            spec_deg=0.1, case="calibrated", axis="height", cap_m=2e-3)
    assert h["capped"] and h["sigma_mm"]["radial"] == pytest.approx(0.01)


# -- CLI ------------------------------------------------------------------------------------


def test_cli_json_contract(tmp_path, capsys):
    rc = main(["tolerance", str(DEFAULT_SCENE), "--pair", "0", "1", "--sigma-radial-mm", "0.1",
               "--sigma-tangential-mm", "0.1", "--sigma-height-mm", "0.1", "--draws", "300",
               "--seed", "3", "--json", "--quiet", "--invert-yield", "0.9", "--out",
               str(tmp_path)])
    assert rc == 0
    out = json.loads(capsys.readouterr().out)
    assert out["draws"] == 300
    for case in CASES:
        assert set(out[case]["angle_error_deg"]) == {"p50", "p95", "p99", "max"}
        assert 0.0 <= out[case]["yield"] <= 1.0
        assert out["inversion"][case]["sigma_mm"]["radial"] > 0
    p95 = {case: out[case]["angle_error_deg"]["p95"] for case in CASES}
    assert p95["uncalibrated"] > p95["calibrated"]
    assert (tmp_path / "tolerance.png").stat().st_size > 1000
    assert json.loads((tmp_path / "tolerance.json").read_text()) == out


@pytest.mark.parametrize("args, needle", [
    (["--sigma-radial-mm", "-0.1"], "outside the allowed range"),
    (["--draws", "0"], "outside the allowed range"),
    (["--distribution", "cauchy"], "invalid choice"),
    (["--invert-yield", "1.5"], "outside the allowed range"),
])
def test_cli_rejects_bad_arguments(args, needle, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["tolerance", str(DEFAULT_SCENE), "--quiet", *args])
    assert exc.value.code == 2
    assert needle in capsys.readouterr().err


def test_cli_rejects_a_non_adjacent_pair(capsys):
    assert main(["tolerance", str(DEFAULT_SCENE), "--pair", "0", "3", "--quiet"]) == 2
    assert "adjacent" in capsys.readouterr().err


def test_cli_says_the_scenes_own_errors_are_not_the_starting_point(tmp_path, capsys):
    """The study draws about the nominal setup (the same statistics with or without the
    scene's own mounting errors); the CLI says so instead of silently ignoring them."""
    text = DEFAULT_SCENE.read_text()
    moved = tmp_path / "moved.toml"
    moved.write_text(text.replace("[[rts.front_ends]]\n",
                                  "[[rts.front_ends]]\nradial_offset_mm = 0.3\n", 1))
    args = ["--draws", "200", "--points", "3", "--json", "--quiet"]
    outs = []
    for path in (DEFAULT_SCENE, moved):
        assert main(["tolerance", str(path), *args]) == 0
        cap = capsys.readouterr()
        outs.append(json.loads(cap.out))
        assert ("each draw replaces them" in cap.err) is (path == moved), cap.err
        assert ("rts.front_ends[0].radial_offset_mm" in cap.err) is (path == moved)
    for case in CASES:
        assert outs[0][case] == outs[1][case]


@pytest.mark.parametrize("scene_file", ["diewald2022.toml", "custom-array.toml"])
@pytest.mark.parametrize("section, key, value", SETUP_ERRORS)
def test_the_scenes_own_errors_do_not_enter_the_study(scene_file, section, key, value):
    """Every mounting, channel and RuT pose error a scene can carry is dropped from the
    tolerance model (``nominal_setup``), which the draws then perturb: the model's tables,
    designs and a Monte Carlo are the same bits with or without it, on two scenes; and
    ``setup_errors`` names it (what the CLI's warning prints)."""
    from rtsgeom.geometry.setup import setup_errors
    clean, moved = scenes_with_and_without_error(ROOT / "scenes" / scene_file, section, key,
                                                 value)
    assert setup_errors(clean) == []
    assert setup_errors(moved) == [(f"rts.front_ends[1].{key}" if section == "fe"
                                    else f"radar.{key}")]
    a, b = (ChannelPhasors.build(build_setup(s), (0, 1), points=3) for s in (clean, moved))
    for name in ("table", "set_rad"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    for name in ("design_amplitudes", "fe_angle_rad"):
        assert np.array_equal(getattr(a.procedure, name), getattr(b.procedure, name)), name
    ra, rb = (monte_carlo(m, [2e-4] * 3, 60, seed=3) for m in (a, b))
    assert ra.to_dict() == rb.to_dict()



@pytest.mark.parametrize("t_star", [0.013, 0.7, 3.0, 41.0])
@pytest.mark.parametrize("rel_tol", [0.2, 0.02, 1e-3])
def test_largest_passing_scale_stops_when_the_bracket_is_within_rel_tol(t_star, rel_tol):
    """A yield that passes for t <= t*: the search returns lo <= t* within rel_tol of it and
    stops as soon as the bracket is that narrow, so its cost is the doublings plus
    ceil(log2(log(hi/lo) / log(1 + rel_tol))) + 1 geometric bisections, not all of them."""
    from rtsgeom.analysis.tolerance.search import largest_passing_scale
    calls = []

    def yield_at(t):
        calls.append(t)
        return 1.0 if t <= t_star else 0.5

    start = 0.1
    t, y, capped = largest_passing_scale(yield_at, 1.0, 0.9, start, 1e6, rel_tol)
    assert not capped and y == 1.0
    assert t <= t_star and t_star - t <= rel_tol * t_star * (1 + rel_tol)
    doublings = max(0, math.ceil(math.log2(t_star / start)))
    lo = start * 2 ** (doublings - 1) if doublings else 0.0
    hi = start * 2 ** doublings
    ratio = math.log(hi / lo) / math.log(1 + rel_tol) if lo > 0 else hi / (rel_tol * t_star)
    bound = doublings + 1 + math.ceil(math.log2(max(ratio, 1.0))) + 2
    assert len(calls) <= bound, (len(calls), bound)


def test_largest_passing_scale_caps():
    from rtsgeom.analysis.tolerance.search import largest_passing_scale
    for cap in (0.5, 3.0, 10.0):
        t, y, capped = largest_passing_scale(lambda t: 1.0, 1.0, 0.9, 0.1, cap, 0.01)
        assert capped and t == cap and y == 1.0


def test_monte_carlo_without_draws_has_no_errors_and_no_yield():
    """Zero draws: every case's error array is empty and its yield undefined (NaN), never a
    phantom draw with zero error (a 100 % yield)."""
    from rtsgeom.analysis.tolerance.montecarlo import monte_carlo
    from rtsgeom.analysis.tolerance.phasors import ChannelPhasors
    from rtsgeom.geometry import build_setup
    model = ChannelPhasors.build(build_setup(make_scene()), (0, 1), 3)
    res = monte_carlo(model, [1e-4, 1e-4, 1e-4], 0, 1)
    for case, e in res.worst_error_deg.items():
        assert e.shape == (0,)
        assert math.isnan(res.yield_(case))
    full = monte_carlo(model, [1e-4, 1e-4, 1e-4], 7, 1)
    assert all(e.shape == (7,) for e in full.worst_error_deg.values())


@pytest.mark.parametrize("distribution, level", [("normal", 3.0), ("normal", 2.0),
                                                 ("uniform", 3.0)])
def test_bounds_from_tolerances_scale_every_field(distribution, level):
    """A tolerance t is a normal draw's t / sigma_level standard deviation and a uniform
    draw's bound t, for every field (front-end offsets and rotations, the RuT's position
    and yaw); a field left out is 0."""
    from rtsgeom.analysis.tolerance.draws import Bounds
    tol = {"offsets_m": (1e-4, 2e-4, 3e-4), "yaw_rad": 0.01, "pitch_rad": 0.02,
           "rut_position_m": (4e-4, 5e-4, 6e-4), "rut_yaw_rad": 0.03}
    k = 1.0 / level if distribution == "normal" else 1.0
    b = Bounds.from_tolerances(tol, distribution, level)
    assert b.offsets_m == pytest.approx(tuple(k * v for v in tol["offsets_m"]))
    assert (b.yaw_rad, b.pitch_rad, b.rut_yaw_rad) == pytest.approx((0.01 * k, 0.02 * k,
                                                                      0.03 * k))
    assert b.rut_position_m == pytest.approx(tuple(k * v for v in tol["rut_position_m"]))
    only = Bounds.from_tolerances({"rut_yaw_rad": 0.03}, distribution, level)
    assert only.rut_yaw_rad == pytest.approx(0.03 * k) and only.rut_pose and not only.rotations
    assert only.offsets_m == (0.0, 0.0, 0.0) and only.rut_position_m == (0.0, 0.0, 0.0)


@pytest.mark.parametrize("distribution", ["normal", "uniform"])
def test_arc_draws_do_not_depend_on_the_chunk(distribution):
    """The unit draws are the same whatever the chunk size (each stream from its own
    generator), with the documented shapes; uniform ones fill [-1, 1], normal ones have unit
    variance."""
    from rtsgeom.analysis.tolerance.draws import Bounds, DrawStreams, draw_chunks
    draws, count = 400, 3
    ref = None
    unit = Bounds((1.0,) * 3, 1.0, 1.0, (1.0,) * 3, 1.0)
    for chunk in (1, 37, 400, 10_000):
        parts = list(draw_chunks(5, draws, count, distribution, chunk,
                                 DrawStreams(rotations=True, rut=True)))
        assert len(parts) == -(-draws // chunk)
        errs = [p.errors(unit) for p in parts]
        got = {"offsets": np.concatenate([e["offsets_m"] for e in errs]),
               "rotations": np.concatenate([np.stack([e["yaw_rad"], e["pitch_rad"]], -1)
                                            for e in errs]),
               "rut": np.concatenate([np.column_stack([e["rut_offset_m"], e["rut_yaw_rad"]])
                                      for e in errs])}
        assert got["offsets"].shape == (draws, count, 3)
        assert got["rotations"].shape == (draws, count, 2) and got["rut"].shape == (draws, 4)
        if ref is None:
            ref = got
        for k in ref:
            np.testing.assert_array_equal(got[k], ref[k])
    x = ref["offsets"].ravel()
    assert np.unique(x).size == x.size  # independent draws, not one value broadcast
    if distribution == "uniform":
        assert x.min() >= -1.0 and x.max() <= 1.0 and x.min() < -0.98 and x.max() > 0.98
    else:
        assert np.std(x) == pytest.approx(1.0, abs=0.05)


def test_arc_yield_search_stops_at_zero_when_the_nominal_arc_fails():
    """When even the arc without errors misses the spec, the largest passing scale is 0 and
    its yield is the nominal one (0); with a reachable spec the scale is positive."""
    from rtsgeom.analysis.tolerance import ChannelPhasors, ToleranceModel
    from rtsgeom.analysis.tolerance.draws import Bounds
    from rtsgeom.analysis.tolerance.search import max_scale_for_yield
    from rtsgeom.geometry import build_setup
    setup = build_setup(make_scene())
    models = ToleranceModel.arc([ChannelPhasors.build(setup, (0, 1), 3)], 2)
    b = Bounds((1e-4, 1e-4, 1e-4))
    # the nominal calibrated synthesis is exact to ~1e-5 deg: a spec below that fails at 0
    res = max_scale_for_yield(models, b, MonteCarlo(draws=20, seed=1), 0.9, spec_deg=1e-12,
                              case="uncalibrated")
    assert res["factor"] == 0.0 and res["yield"] == 0.0 and not res["capped"]
    ok = max_scale_for_yield(models, b, MonteCarlo(draws=20, seed=1), 0.9, spec_deg=0.1,
                             case="calibrated", rel_tol=0.1)
    assert ok["factor"] > 0 and ok["yield"] >= 0.9


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


def test_tolerance_table_spans_half_a_calibration_period():
    """The delay table of the tolerance model covers +-(half a period 1/(f_rts + B/2)) in
    delay-resolution steps, plus 4 for the refinement."""
    from rtsgeom.analysis.tolerance.phasors import ChannelPhasors
    scene = small_quiet([])
    model = ChannelPhasors.build(build_setup(scene), (0, 1), points=3)
    slope = scene.rts.f_rts_hz + 0.5 * scene.radar.bandwidth_hz
    assert model.procedure.max_steps == int(np.ceil(0.5 / (slope * scene.rts.delay_resolution_s))) + 4


@pytest.mark.parametrize("sigma", [[-1e-4, 0, 0], [0, float("nan"), 0], [0, 0, float("inf")]])
def test_monte_carlo_refuses_negative_or_non_finite_sigmas(sigma):
    from rtsgeom.analysis.tolerance.montecarlo import monte_carlo
    from rtsgeom.analysis.tolerance.phasors import ChannelPhasors
    model = ChannelPhasors.build(build_setup(small_quiet([])), (0, 1), points=3)
    with pytest.raises(ValueError, match="sigma_m"):
        monte_carlo(model, sigma, 4, seed=0)


def test_monte_carlo_maps_its_chunks_through_the_mapper_and_times_itself():
    from rtsgeom.analysis.tolerance.montecarlo import monte_carlo
    from rtsgeom.analysis.tolerance.phasors import ChannelPhasors
    model = ChannelPhasors.build(build_setup(small_quiet([])), (0, 1), points=3)
    calls = []

    def mapper(func, chunks):
        calls.append(len(chunks))
        return [func(ch) for ch in chunks]
    a = monte_carlo(model, [1e-4] * 3, 30, seed=3, chunk=10, mapper=mapper)
    b = monte_carlo(model, [1e-4] * 3, 30, seed=3, chunk=10)
    assert calls == [3]
    for case in a.worst_error_deg:
        assert np.array_equal(a.worst_error_deg[case], b.worst_error_deg[case])
    elapsed = [getattr(a, f) for f in a.__dataclass_fields__ if "time" in f or f.endswith("_s")
               and isinstance(getattr(a, f), float)]
    assert elapsed and all(e > 0 for e in elapsed)


def test_yield_inversion_says_when_the_nominal_setup_misses_the_spec():
    from rtsgeom.analysis.tolerance.phasors import ChannelPhasors
    from rtsgeom.analysis.tolerance.search import max_sigma_for_yield
    model = ChannelPhasors.build(build_setup(small_quiet([])), (0, 1), points=3)
    res = max_sigma_for_yield(model, [1e-4] * 3, MonteCarlo(draws=20, seed=0), 0.95,
                              spec_deg=1e-9, case="uncalibrated")
    assert "misses the spec" in str(res.get("note"))


def test_range_offset_is_half_c_times_the_mean_delay_mismatch():
    """range_offsets_m = c0/2 (element-mean air delay of J + its steps - that of I)."""
    from rtsgeom.analysis.tolerance.phasors import ChannelPhasors
    model = ChannelPhasors.build(build_setup(small_quiet([])), (0, 1), points=3)
    off = np.zeros((2, 3))
    off[1, 0] = 2e-3  # 2 mm radial on J: both legs longer by 2 mm
    a_i, a_j = model.air_legs(off)
    base = model.range_offsets_m(np.zeros((1, 2, 3)), [[0, 0]])[0, 1]
    got = model.range_offsets_m(off[None], [[0, 7]])[0, 1]
    assert got - base == pytest.approx(0.5 * c * (2 * 2e-3 / c + 7 * model.delay_resolution_s),
                                       rel=1e-3)



@pytest.mark.parametrize("value", [0.0, -0.5, 1.5, math.nan])
def test_a_bad_invert_yield_is_named(value):
    with pytest.raises(ParameterError, match=r"invert_yield"):
        ToleranceStudy(invert_yield=value)


# -- the pair's procedure against its closed forms (on the module's model: no second build) --


def test_the_pairs_tables_are_laid_out_as_their_closed_forms_say(model):
    """The set-points at k / (points + 1) and the probes at 1/4, 3/4 of the span between the
    front ends each detected alone; eq. (27)'s slope f_rts + B/2; the calibration's reach
    ceil(1 / (2 slope dtau)) + 4 steps; J's IF period at the target in steps; the table's
    rows (every sub-bin position, calibration delay and period, +2) and bins (the reach of
    J's echo in bins, +1 either side), each row the channel's response at that delay."""
    from rtsgeom.analysis.tolerance.pair import PROBE_FRACTIONS
    from rtsgeom.analysis.tolerance.tables import response_table
    from rtsgeom.calibration.probes import if_phase_slope_hz
    pr, ch = model.procedure, model.channels
    nom, radar, rts = model.setup, model.setup.scene.radar, model.setup.scene.rts
    th = ch.direction(np.eye(2))
    np.testing.assert_allclose(pr.fe_angle_rad, th, atol=1e-12)
    np.testing.assert_allclose(model.set_rad, th[0] + np.arange(1, 22) / 22 * (th[1] - th[0]),
                               atol=1e-12)
    assert PROBE_FRACTIONS == (0.25, 0.75)
    np.testing.assert_allclose(pr.probe_rad, [0.75 * th[0] + 0.25 * th[1],
                                              0.25 * th[0] + 0.75 * th[1]], atol=1e-12)
    res = model.delay_resolution_s
    assert res == rts.delay_resolution_s
    slope = rts.f_rts_hz + radar.bandwidth_hz / 2
    assert model.cal_slope_hz == slope
    ms = math.ceil(0.5 / (slope * res)) + 4
    assert pr.max_steps == ms and pr.delay_factor.shape == (2 * ms + 1, 8)
    period = 1 / float(if_phase_slope_hz(nom.scene, 2 * model.range_m / c))
    assert pr.period_steps == round(period / res)
    n_bin = model.subbin_steps.size
    assert np.array_equal(model.subbin_steps, np.arange(n_bin) - n_bin // 2)
    z = n_bin // 2 + ms + pr.period_steps + 2
    reach = max(1, math.floor((n_bin // 2 + ms) / n_bin + 0.5))
    reach_far = max(1, math.floor((n_bin // 2 + ms + pr.period_steps) / n_bin + 0.5))
    assert (pr.design.reach, pr.reach_far) == (reach, reach_far)
    nb = reach_far + 1
    assert model.table_zero == z and model.table.shape == (2, 2 * z + 1, 2 * nb + 1, 8)
    assert pr.design.i0 == z - n_bin // 2 - 1
    target = TargetConfig(model.range_m)
    paths = exact_paths(nom)
    d = np.array([-z, -3, 0, 17, z])
    np.testing.assert_allclose(model.table[1, z + d], response_table(
        nom, paths, 1, target, res, d, nb), rtol=1e-12, atol=1e-12)
    # channel I only sits at the sub-bin positions (+-1 row): the rows beyond are its edge's
    near = np.clip(d, -(n_bin // 2) - 1, n_bin // 2 + 1)
    np.testing.assert_allclose(model.table[0, z + d], response_table(
        nom, paths, 0, target, res, near, nb), rtol=1e-12, atol=1e-12)


def test_the_pairs_derived_tables_are_their_definitions(model):
    """J's delay response at the bin centre relative to no delay (1 at 0), the log slopes as
    central differences of ln|table| in the delay (one-sided at the ends), each channel's power
    over the elements, the probes' beams, channel I alone at its peak (a dense search),
    the beams at the set angles for I's rows from i0 on."""
    from rtsgeom.analysis.tolerance.pair import _set_beams
    pr, ds = model.procedure, model.procedure.design
    t, z, ms = model.table, model.table_zero, model.procedure.max_steps
    res = model.delay_resolution_s
    nb = t.shape[2] // 2
    np.testing.assert_allclose(pr.delay_factor, t[1, z - ms:z + ms + 1, nb] / t[1, z, nb],
                               rtol=1e-13)
    np.testing.assert_allclose(pr.delay_factor[ms], 1.0, rtol=0, atol=1e-15)
    ln = np.log(np.abs(t[1, :, nb]))
    slope = model.table_log_slope
    for row in (z - ms, z, z + 5):
        np.testing.assert_allclose(slope[1, row, nb], (ln[row + 1] - ln[row - 1]) / (2 * res),
                                   rtol=1e-9)
    np.testing.assert_allclose(slope[1, 0, nb], (ln[1] - ln[0]) / res, rtol=1e-9)
    np.testing.assert_allclose(pr.delay_log_slope, slope[1, z - ms:z + ms + 1, nb], rtol=0)
    np.testing.assert_allclose(ds.power, np.sum(np.abs(t) ** 2, -1), rtol=1e-12)
    st = model.channels.steering
    np.testing.assert_allclose(ds.probe_beams, st.beam(t[:, :, nb], st.directions(pr.probe_rad)),
                               rtol=1e-12)
    assert ds.unit_gain == model.channels.unit_gain
    sub = model.subbin_steps
    for u in (0, sub.size // 2, sub.size - 1):
        rows = t[0, z + sub[u]]
        one = rows[np.argmax(np.sum(np.abs(rows) ** 2, -1))]
        grid = np.linspace(pr.fe_angle_rad[0] - 0.02, pr.fe_angle_rad[0] + 0.02, 4001)
        dense = np.max(np.abs(st.beam(one, st.directions(grid))) ** 2)
        assert ds.p_one[u] == pytest.approx(dense, rel=1e-6)
        assert ds.p_one[u] >= dense * (1 - 1e-12)  # the refined peak, not below the grid's
    rows = np.array([ds.i0, z, z + sub[-1] + 1])
    np.testing.assert_allclose(ds.beams_i[rows - ds.i0], _set_beams(st, t[0, rows],
                                                                    model.set_rad), rtol=1e-12)
    assert ds.beams_i.shape[0] == 2 * (sub.size // 2) + 3
    np.testing.assert_allclose(ds.beams_j[[0, z, -1]], _set_beams(st, t[1, [0, z, -1]],
                                                                  model.set_rad), rtol=1e-12)
    np.testing.assert_array_equal(model.amplitudes, pr.design_amplitudes[model.subbin_zero])


def test_the_pairs_calibration_phase_and_steps_follow_eq_27(model):
    """The design's phase is the circular mean over the probes of I's beam times J's
    conjugate; the calibration's steps are eq. (27)'s delay for the coherence phase, refined
    to the table's phase within +-3 steps: turning J's phasors by phi moves them by
    phi / (2 pi slope dtau) steps (to one step)."""
    pr, ds = model.procedure, model.procedure.design
    z = model.table_zero
    rows_i, rows_j = np.array([z, z - 7, z + 3]), np.array([z, z + 11, z - 40])
    zz = ds.probe_beams[0][rows_i] * np.conj(ds.probe_beams[1][rows_j])
    want = np.angle(np.sum(zz / np.abs(zz), -1))
    np.testing.assert_allclose(ds.phase(rows_i, rows_j), want, atol=1e-12)
    x = model.x_nominal
    phi = np.radians([-150.0, -40.0, 0.0, 25.0, 170.0])
    xq = np.stack([x] * phi.size)
    xq[:, 1] *= np.exp(1j * phi)[:, None]
    coh = pr.coherence_phase(model, xq)
    np.testing.assert_allclose(coh, model.channels.pair_phase(pr.probe_rad, xq), atol=1e-12)
    steps = pr.calibration_steps(model, xq)
    per_step = 2 * np.pi * model.cal_slope_hz * model.delay_resolution_s
    k0 = np.round(coh / per_step).astype(int)
    table_phase = np.angle(pr.delay_factor[:, model.channels.steering.mask].mean(axis=1))
    for k, c0, p in zip(steps, k0, coh):
        cand = np.arange(c0 - 3, c0 + 4)
        miss = np.abs(np.angle(np.exp(1j * (p - table_phase[cand + pr.max_steps]))))
        assert k == cand[np.argmin(miss)]
    moved = steps - steps[2]
    # eq. (27) with f_rts + B/2; the table has the exact IF slope at the target (0.4 % off)
    np.testing.assert_allclose(moved, np.angle(np.exp(1j * (coh - coh[2]))) / per_step,
                               rtol=0.01, atol=1.5)
    assert np.all(np.diff(moved) < 0)  # J turned ahead: the delay shrinks


@pytest.mark.parametrize("redesign", [True, False])
def test_the_pairs_bin_centre_snapshots_are_the_programmed_sum(model, redesign):
    """Uncalibrated: A_I x_I + A_J x_J per set-point; calibrated: J delayed by its steps
    (the delay's factor on its elements), both gain-corrected, J's amplitude divided by the
    delay's loss when redesigned."""
    pr = model.procedure
    rng = np.random.default_rng(4)
    x = model.x_nominal
    xq = x * (1 + 0.05 * rng.normal(size=(3, 2, 1)))
    a = model.amplitudes
    got = pr.snapshots(model, xq)
    want = a[None, :, 0, None] * xq[:, None, 0] + a[None, :, 1, None] * xq[:, None, 1]
    np.testing.assert_allclose(got, want, rtol=1e-12)
    steps = np.array([0, 5, -9])
    g = model.gain_correction(xq)
    f = pr.delay_factor[steps + pr.max_steps]
    gj = g[:, 1] / (np.abs(f[:, model.channels.steering.mask].mean(-1)) if redesign else 1.0)
    got = pr.snapshots(model, xq, steps, redesign=redesign)
    want = ((a[None, :, 0] * g[:, 0, None])[..., None] * xq[:, None, 0]
            + (a[None, :, 1] * gj[:, None])[..., None] * (xq[:, 1] * f)[:, None])
    np.testing.assert_allclose(got, want, rtol=1e-12)


@pytest.mark.parametrize("offset", [-4, -3, -1, 0, 2, 3, 4])
def test_the_pairs_calibration_refines_at_most_three_steps(model, offset):
    """A delay table whose phase is eq. (27)'s line moved by ``offset`` steps: the refinement
    follows it up to 3 steps either side of eq. (27)'s own step, no further."""
    import dataclasses
    pr = model.procedure
    per_step = 2 * np.pi * model.cal_slope_hz * model.delay_resolution_s
    k = np.arange(-pr.max_steps, pr.max_steps + 1)
    line = np.exp(1j * per_step * (k - offset))[:, None] * np.ones(pr.delay_factor.shape[1])
    moved = dataclasses.replace(pr, delay_factor=line)
    x = model.x_nominal
    phi = np.radians([-120.0, -10.0, 0.0, 33.0, 100.0])
    xq = np.stack([x] * phi.size)
    xq[:, 1] *= np.exp(1j * phi)[:, None]
    k0 = np.round(pr.coherence_phase(model, xq) / per_step).astype(int)
    np.testing.assert_array_equal(moved.calibration_steps(model, xq),
                                  k0 + int(np.clip(offset, -3, 3)))
