"""Mounting-tolerance Monte Carlo: the phasor model against the exact
spectrum and the ADC cube, calibration physics, reproducibility, the CLI."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rtsgeom.synthesis.model import ChannelModel
from rtsgeom.analysis.tolerance.phasors import CASES, NOMINAL_AMPLITUDES, ChannelPhasors
from rtsgeom.analysis.tolerance.draws import draw_offsets
from rtsgeom.analysis.tolerance.search import max_sigma_for_yield
from rtsgeom.analysis.tolerance.montecarlo import monte_carlo
from rtsgeom.cli import main
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.radar import process
from rtsgeom.radar.processing import estimate_angles, refine_angles, tdm_compensate
from rtsgeom.rts.channels import RtsProgram, requested_delay
from rtsgeom.radar.frame import simulate
from rtsgeom.scene import TargetConfig

from conftest import (DEFAULT_SCENE, ROOT, SETUP_ERRORS, make_scene, scenes_with_and_without_error,
                      two_front_end_pair)

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
    from rtsgeom.analysis.tolerance.draws import draw_chunks, standard_draws, subbin_draws
    sigma = np.array([1.0, 2.0, 3.0]) * 1e-4
    parts = list(draw_chunks(5, 300, 2, distribution, chunk, positions=9, centre=4))
    assert [p.k for p in parts] == [min(chunk, 300 - s) for s in range(0, 300, chunk)]
    offsets = np.concatenate([p.offsets() for p in parts]) * sigma
    subbin = np.concatenate([p.subbin() for p in parts])
    assert np.array_equal(offsets, np.concatenate(list(standard_draws(5, 300, distribution))) * sigma)
    assert np.array_equal(subbin, np.concatenate(list(subbin_draws(5, 300, 9))))
    centre = draw_chunks(5, 300, 2, distribution, chunk, positions=None, centre=4)
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


_HEAP_POLICY = """
import ctypes, numpy as np
from rtsgeom._lib.parallel import retain_freed_memory
class MallInfo2(ctypes.Structure):
    _fields_ = [(n, ctypes.c_size_t) for n in ("arena", "ordblks", "smblks", "hblks", "hblkhd",
                                                "usmblks", "fsmblks", "uordblks", "fordblks",
                                                "keepcost")]
libc = ctypes.CDLL(None)
libc.mallinfo2.restype = MallInfo2
libc.mallopt(-3, 128 * 1024)  # M_MMAP_THRESHOLD fixed: every block above 128 KiB mapped
out = []
for retain in (False, True):
    if retain:
        assert retain_freed_memory()
    h0 = libc.mallinfo2().hblkhd
    a = np.ones(3_500_000)  # 28 MiB
    out.append(libc.mallinfo2().hblkhd - h0)
    arena = libc.mallinfo2().arena
    del a
    out.append(arena - libc.mallinfo2().arena)
print(*out)
"""


def test_retained_memory_is_reused_not_mapped_afresh():
    """``parallel.retain_freed_memory`` (glibc): a 28 MiB block that glibc maps afresh and
    unmaps on every allocation (a design's tables and temporaries: ~7 000 page faults a
    design) comes from the heap instead and stays there when freed (a fresh process: a
    forked one inherits this process's heap, whose free blocks would serve it anyway)."""
    import subprocess
    import sys
    if not _glibc():
        pytest.skip("glibc's mallopt/mallinfo2 needed")
    run = subprocess.run([sys.executable, "-c", _HEAP_POLICY], capture_output=True, text=True,
                         check=True, cwd=ROOT)
    mapped, _, mapped_after, trimmed = map(int, run.stdout.split())
    assert mapped >= 28e6  # before: a fresh mapping
    assert mapped_after == 0 and trimmed == 0  # after: from the heap, and kept there


def _worker_retains() -> bool:
    import rtsgeom._lib.parallel as parallel
    return getattr(parallel, "_test_retained", False)


def test_fork_pool_workers_retain_freed_memory(monkeypatch):
    """Every ForkPool worker runs ``retain_freed_memory`` when it starts."""
    import rtsgeom._lib.parallel as parallel
    if not parallel._can_fork():
        pytest.skip("no fork on this platform")

    def spy():
        parallel._test_retained = True
        return True
    monkeypatch.setattr(parallel, "retain_freed_memory", spy)
    with parallel.ForkPool(2) as pool:
        assert pool.map(lambda _: _worker_retains(), [0, 1, 2]) == [True] * 3
    assert not getattr(parallel, "_test_retained", False)  # (the parent's module untouched)


def _glibc() -> bool:
    import platform
    return platform.libc_ver()[0] == "glibc"


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
    inv = max_sigma_for_yield(model, [1e-4] * 3, 400, seed=4, target_yield=0.9, spec_deg=0.1,
                              case="uncalibrated", rel_tol=0.02)
    sig = inv["sigma_mm"]["radial"]
    assert inv["sigma_mm"]["tangential"] == sig == inv["sigma_mm"]["height"]
    assert inv["yield"] >= 0.9 and not inv["capped"]
    ev = sorted((e["scale_mm"], e["yield"]) for e in inv["evaluations"])
    assert all(y1 >= y2 for (_, y1), (_, y2) in zip(ev, ev[1:]))  # monotone in sigma
    above = [y for s, y in ev if s > sig]
    assert above and max(above) < 0.9
    # one axis: height errors are second order (both legs grow by dz^2 / 2R): never the limit
    h = max_sigma_for_yield(model, [1e-5] * 3, 200, seed=4, target_yield=0.9, spec_deg=0.1,
                            case="calibrated", axis="height", cap_m=2e-3)
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


@pytest.mark.slow
def test_dask_local_cluster_gives_bit_identical_results():
    """A small study on a 2-worker LocalCluster equals the single-process run bit for bit."""
    pytest.importorskip("dask.distributed")
    import functools

    from rtsgeom.analysis.tolerance.phasors import ChannelPhasors
    from rtsgeom.analysis.tolerance.montecarlo import monte_carlo
    from rtsgeom.geometry import build_setup
    from rtsgeom._lib.parallel import dask_client, map_chunks
    setup = build_setup(make_scene())
    model = ChannelPhasors.build(setup, (0, 1), points=7)
    sigma = np.array([0.2, 0.2, 0.2]) * 1e-3
    local = monte_carlo(model, sigma, 3000, 11, chunk=500)
    with dask_client(workers=2) as client:
        remote = monte_carlo(model, sigma, 3000, 11, chunk=500,
                             mapper=functools.partial(map_chunks, client=client))
    for case in local.worst_error_deg:
        assert np.array_equal(local.worst_error_deg[case], remote.worst_error_deg[case])
    assert np.array_equal(local.delay_s, remote.delay_s)


def test_chunk_mapper_fork_pool_every_draw_mode():
    """``--workers N``'s forked pool (chunk_mapper without a scheduler) equals one process bit
    for bit, with uneven chunks, for normal and uniform draws and both sub-bin modes."""
    from rtsgeom.analysis.tolerance.phasors import ChannelPhasors
    from rtsgeom.analysis.tolerance.montecarlo import monte_carlo
    from rtsgeom.geometry import build_setup
    from rtsgeom._lib.parallel import chunk_mapper
    model = ChannelPhasors.build(build_setup(make_scene()), (0, 1), points=5)
    sigma = np.array([0.3, 0.2, 0.5]) * 1e-3
    for distribution, subbin in (("normal", True), ("uniform", False)):
        local = monte_carlo(model, sigma, 1300, 7, distribution, chunk=300, subbin=subbin)
        with chunk_mapper(None, 2) as mapper:
            assert mapper is not None
            pooled = monte_carlo(model, sigma, 1300, 7, distribution, chunk=300,
                                 mapper=mapper, subbin=subbin)
        for case in local.worst_error_deg:
            assert np.array_equal(local.worst_error_deg[case], pooled.worst_error_deg[case])
        assert np.array_equal(local.delay_s, pooled.delay_s)
        assert np.array_equal(local.range_offset_m, pooled.range_offset_m)
        assert local.fallbacks == pooled.fallbacks and local.off_bin == pooled.off_bin
    with chunk_mapper(None, 1) as mapper:
        assert mapper is None  # one worker: this process


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
