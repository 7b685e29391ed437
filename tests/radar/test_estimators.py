"""The RuT's direction estimator is a choice: Bartlett (eq. 14), Capon (MVDR) and
MUSIC, with forward-backward spatial smoothing (``radar.angle_estimator``,
``radar.angle_subarray``; ``rtsgeom/radar/estimators.py``).

Closed forms: one plane wave peaks at its angle for every estimator; on one unsmoothed snapshot
Capon and MUSIC are Bartlett (Sherman-Morrison); two incoherent sources below the Rayleigh
limit are resolved by Capon and MUSIC and not by Bartlett; smoothing decorrelates two coherent
ones. The synthesis: where it holds for each estimator and where it breaks, on a grid of
front-end spacings against the array's resolution; ``exact`` solves against the chosen
estimator and the detections use it.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from conftest import ROOT, make_scene
from rtsgeom.analysis.estimators import pair_snapshots, pair_sweep
from rtsgeom.errors import AngleUnreachable
from rtsgeom.synthesis.model import ChannelModel
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.radar import estimators as est
from rtsgeom.radar import process
from rtsgeom.radar.frame import simulate
from rtsgeom.radar.steering import Steering
from rtsgeom.rts.channels import RtsProgram, requested_delay
from rtsgeom.errors import SceneError
from rtsgeom.scene import TargetConfig

PRESETS = ("awr1843boost", "awr2944")  # 8 and 12 elements in the azimuth row, lambda/2


def _no_targets(doc):
    doc["targets"] = []
    doc["rts"]["aoa_mode"] = "nearest"


def steering(preset="awr1843boost", window="none", estimator="bartlett", subarray=0,
             **radar):
    scene = make_scene(_no_targets, antenna_preset=preset, angle_window=window, **radar)
    rut = build_setup(scene).rut
    st = Steering.build(rut, scene.radar)
    return dataclasses.replace(st, estimator=estimator, subarray=subarray), rut.num_virtual


def plane_waves(st, u, n_virtual, amps=None) -> np.ndarray:
    """Snapshot(s) (..., V) of plane waves from direction cosines u (..., S) summed."""
    u = np.atleast_1d(np.asarray(u, float))
    amps = np.ones(u.shape[-1]) if amps is None else np.asarray(amps)
    k = st.wavevector[:, 0]
    x = np.zeros(u.shape[:-1] + (n_virtual,), complex)
    x[..., st.mask] = np.sum(amps[:, None] * np.exp(-1j * k * u[..., :, None]), axis=-2)
    return x


def resolution_u(st) -> float:
    """The Rayleigh resolution lambda / (N d) in u of the row."""
    return float(st.wavelength_m / st.aperture_m[0])


CASES = [("bartlett", 0), ("capon", 0), ("music", 0), ("capon", 4), ("music", 4),
         ("capon", 6), ("music", 6)]


@pytest.mark.parametrize("preset", PRESETS)
@pytest.mark.parametrize("estimator,subarray", CASES)
@pytest.mark.parametrize("window", ["none", "hann"])
def test_one_plane_wave_peaks_at_its_angle(preset, estimator, subarray, window):
    """Every estimator, smoothed or not, with or without a taper, finds one plane wave at its
    angle over the visible region, and its spectrum has no larger value elsewhere."""
    st, nv = steering(preset, window, estimator, subarray)
    az = np.radians(np.arange(-60.0, 60.1, 7.5))
    x = plane_waves(st, np.sin(az)[:, None], nv)
    assert np.max(np.abs(np.degrees(st.search(x) - az))) < 1e-5
    u, ok = st.peak(x, np.sin(az + 0.01)[:, None])
    assert ok.all() and np.max(np.abs(np.degrees(np.arcsin(u[:, 0]) - az))) < 1e-5
    grid = st.directions(np.radians(np.linspace(-89, 89, 713)))
    p_src = np.diagonal(st.spectrum(x, st.directions(az)))
    assert np.all(st.spectrum(x, grid) <= p_src[:, None] * (1 + 1e-9))


def test_smoothing_averages_duplicate_elements():
    """The cascade's 144 azimuth elements fill 86 grid positions (duplicates averaged): a
    plane wave is found by smoothed Capon and MUSIC as by Bartlett."""
    scene = make_scene(_no_targets, antenna_preset="awr2243-cascade")
    rut = build_setup(scene).rut
    base = Steering.build(rut, scene.radar)
    assert base.size == 144 and est.uniform_cells(base.positions_m[:, 0], base.pitch_m)[1] == 86
    az = np.radians([-30.0, 0.3, 17.0])
    for kind in ("capon", "music"):
        st = dataclasses.replace(base, estimator=kind, subarray=57)
        x = plane_waves(st, np.sin(az)[:, None], rut.num_virtual)
        assert np.max(np.abs(np.degrees(st.search(x) - az))) < 1e-5


@pytest.mark.parametrize("window", ["none", "hamming"])
def test_rank_one_capon_and_music_are_bartlett(window):
    """One unsmoothed snapshot: R = x x^H is rank 1, and Sherman-Morrison gives
    a^H (R + delta I)^-1 a = (L - |a^H x|^2 / (delta + |x|^2)) / delta and
    a^H E_n E_n^H a = L - |a^H x|^2 / |x|^2: both spectra peak where Bartlett's does, for
    arbitrary (not plane-wave) snapshots, in 1-D and 2-D."""
    rng = np.random.default_rng(5)
    for elevation in (False, True):
        scene = make_scene(_no_targets, angle_window=window, use_elevation_tx=True)
        base = Steering.build(build_setup(scene).rut, scene.radar, elevation=elevation)
        x = rng.normal(size=(12, 12)) + 1j * rng.normal(size=(12, 12))
        grid = (base.directions(np.radians(np.linspace(-80, 80, 641))) if not elevation
                else base.grid())
        p_b = base.power(x, grid)
        xt = base.weighted(x)
        a = base.manifold(grid)
        ax2 = np.abs(np.conj(a) @ xt.T).T ** 2  # |a^H x|^2 (n, G)
        n2 = np.sum(np.abs(xt) ** 2, -1)[:, None]
        big_l = base.size
        assert np.allclose(ax2, p_b, rtol=1e-10)
        for kind in ("capon", "music"):
            st = dataclasses.replace(base, estimator=kind)
            assert not st.smoothing
            q = est.quadratic(est.kernel(st.covariance(x), kind), a)
            if kind == "capon":
                delta = est.CAPON_LOADING * n2 / big_l
                closed = (big_l - ax2 / (delta + n2)) / delta
            else:
                closed = big_l - ax2 / n2
            assert np.allclose(q, closed, rtol=1e-6, atol=1e-9 * big_l)
            assert np.array_equal(np.argmax(st.spectrum(x, grid), -1), np.argmax(p_b, -1))
            assert np.array_equal(st.search(x), base.search(x))


@pytest.mark.parametrize("spacing", [0.35, 0.5, 0.7])
def test_two_incoherent_sources_below_rayleigh_resolved(spacing):
    """Incoherent sources (R = a_1 a_1^H + a_2 a_2^H + sigma^2 I, 30 dB SNR) closer than the
    Rayleigh resolution: MUSIC's spectrum peaks at both (to 0.05 of the spacing) and Capon's
    has two peaks, Bartlett's one in between."""
    st, _ = steering("awr2944")
    du = spacing * resolution_u(st)
    u_src = np.array([0.1 - du / 2, 0.1 + du / 2])
    a_src = st.manifold(u_src[:, None])  # (2, L)
    r = a_src.T @ np.conj(a_src) + 1e-3 * np.eye(st.size)
    u = np.linspace(-0.3, 0.5, 8001)
    a = st.manifold(u[:, None])

    def peaks(spec):
        i = np.flatnonzero((spec[1:-1] > spec[:-2]) & (spec[1:-1] > spec[2:])) + 1
        return u[i[np.argsort(spec[i])[::-1]]]

    bartlett = est.quadratic(-r, a) * -1
    assert len(peaks(bartlett)) >= 1 and abs(peaks(bartlett)[0] - 0.1) < 0.1 * du
    music = 1 / est.quadratic(est.kernel(r, "music"), a)
    assert np.allclose(np.sort(peaks(music)[:2]), u_src, atol=0.05 * du)
    capon = 1 / est.quadratic(est.kernel(r, "capon"), a)
    assert np.all(np.abs(np.sort(peaks(capon)[:2]) - u_src) < 0.25 * du)


@pytest.mark.parametrize("spacing", [0.5, 0.8])
def test_smoothing_decorrelates_two_coherent_sources(spacing):
    """One snapshot of two *coherent* plane waves: without smoothing every estimator sees one
    peak between them; forward-backward smoothing (L = 6 of 8) makes the covariance rank 2 and
    noise-free MUSIC peaks exactly at the stronger source (either one)."""
    st, nv = steering()
    du = spacing * resolution_u(st)
    u_src = np.array([-du / 2, du / 2])
    x = plane_waves(st, u_src, nv, amps=[1.0, 0.6])
    for kind in ("bartlett", "capon", "music"):
        one = dataclasses.replace(st, estimator=kind)
        assert u_src[0] + 0.1 * du < np.sin(one.search(x)) < u_src[1] - 0.1 * du
    sm = dataclasses.replace(st, estimator="music", subarray=6)
    lam = np.linalg.eigvalsh(sm.covariance(x))
    assert lam[-2] > 1e-6 * lam[-1] and lam[-3] < 1e-12 * lam[-1]
    assert abs(np.sin(sm.search(x)) - u_src[0]) < 1e-8
    # both nulls are unbounded peaks: the stronger source is reported, whichever it is
    swapped = plane_waves(st, u_src, nv, amps=[0.6, 1.0])
    assert abs(np.sin(sm.search(swapped)) - u_src[1]) < 1e-8


SPACINGS = (0.2, 0.4, 0.6, 0.8, 1.0)  # front-end spacing / the row's Rayleigh resolution


@pytest.mark.parametrize("preset", PRESETS)
def test_where_the_synthesized_angle_holds_for_each_estimator(preset):
    """The far-field pair swept over the amplitude ratio (``analysis.estimators``): on a grid
    of front-end spacings, Bartlett and the unsmoothed Capon and MUSIC move the peak
    continuously from one front end to the other (and identically); a smoothed estimator
    holds for closely spaced front ends and breaks (its peak jumps from one front end to the
    other: it resolves them) beyond a spacing, and stays broken for wider spacings; where it
    holds, Capon's angle for a given ratio differs from Bartlett's (the synthesis depends on
    the estimator, so ``exact`` must solve against it); MUSIC holds only while its signal
    subspace has one dimension, and there it is within 1 % of the span of Bartlett's."""
    base, nv = steering(preset)
    res = resolution_u(base)
    ref = {s: pair_sweep(base, nv, s * res, 0.05) for s in SPACINGS}
    assert all(r.holds for r in ref.values())
    n = base.size
    for kind in ("capon", "music"):
        assert all(np.array_equal(pair_sweep(dataclasses.replace(base, estimator=kind), nv,
                                             s * res, 0.05).t, ref[s].t) for s in SPACINGS)
        for sub in (n // 2, (2 * n) // 3, n - 1):
            st = dataclasses.replace(base, estimator=kind, subarray=sub)
            holds = [pair_sweep(st, nv, s * res, 0.05) for s in SPACINGS]
            ok = [h.holds for h in holds]
            assert ok[0] and not ok[-1], (kind, sub, ok)
            assert ok == sorted(ok, reverse=True), (kind, sub, ok)  # once broken, broken
            diff = max(np.max(np.abs(h.t - ref[s].t)) for h, s in zip(holds, SPACINGS)
                       if h.holds)
            if kind == "capon":  # holds to wider spacings, on its own curve
                assert ok[1] and diff > 0.005, (kind, sub, ok, diff)
            else:  # holds only while the signal subspace is one-dimensional: ~Bartlett
                assert diff < 0.01, (kind, sub, diff)


@pytest.fixture(scope="module")
def default_pair():
    scene = make_scene()
    setup = build_setup(scene)
    return setup, exact_paths(setup)


@pytest.mark.parametrize("kind", ["capon", "music"])
def test_exact_solves_against_the_chosen_estimator(default_pair, kind):
    """``exact`` (``ChannelModel.solve``) on the default pair (8.8 deg apart, 0.6 of the
    resolution) with smoothing over 7 of 8 elements: each reachable set angle is detected by
    the chosen estimator where it was set (1e-6 deg); Bartlett's design would miss it under
    that estimator; the unreachable ones are reported, not silently wrong."""
    setup, paths = default_pair
    target = TargetConfig(33.5)
    bart = ChannelModel.build(setup, paths, (0, 1), target)
    m = dataclasses.replace(bart, steering=dataclasses.replace(bart.steering, estimator=kind,
                                                              subarray=7))
    ph = (0.0, float(m.pair_phase(np.radians([5.6, 10.6]))))
    miss, solved = [], 0
    for a in np.radians(np.arange(5.0, 12.01, 1.0)):
        try:
            w = m.pair_weights(m.pair_ratio(a, ph), ph)
        except AngleUnreachable as exc:
            assert "jumps" in str(exc) or "outside" in str(exc)
            continue
        solved += 1
        assert abs(np.degrees(m.direction(w) - a)) < 1e-6
        miss.append(abs(np.degrees(m.direction(bart.pair_weights(bart.pair_ratio(a, ph), ph))
                                   - a)))
    assert solved >= 3
    assert max(miss) > 0.01


def test_detections_use_the_estimator(default_pair):
    """The ADC-cube chain (CFAR, TDM compensation, the cube's steering) detects a two-channel
    target where the channel model says the scene's estimator puts it, and not where Bartlett
    would."""
    scene = make_scene(angle_estimator="capon", angle_subarray=6)
    setup = build_setup(scene)
    paths = exact_paths(setup)
    target = TargetConfig(33.5)
    m = ChannelModel.build(setup, paths, (0, 1), target)
    assert m.steering.smoothing
    bart = dataclasses.replace(m, steering=dataclasses.replace(m.steering, subarray=0))
    tau = float(requested_delay(scene, target.range_m))
    apart = []
    for rho in (0.5, 1.0, 2.0):
        prog = RtsProgram.build([0, 0], [0, 1], [tau, tau], [0.0, 0.0], [1.0, rho])
        _, cube = simulate(setup, paths, prog)
        assert cube.steering.estimator == "capon" and cube.steering.subarray == 6
        rd, det = process(cube)
        k = int(np.argmax(det.power_db))
        want = float(m.direction(np.array([1.0, rho])))
        assert abs(np.degrees(det.angle_rad[k] - want)) < 0.005
        apart.append(abs(np.degrees(bart.direction(np.array([1.0, rho])) - want)))
    assert max(apart) > 0.02


def test_bad_estimator_settings_are_named_errors():
    """Smoothing with Bartlett, with 2-D processing, a one-element subarray, one longer than
    the row, or a row with gaps: a SceneError naming radar.angle_subarray."""
    for kw in (dict(angle_subarray=4), dict(angle_estimator="capon", angle_subarray=1),
               dict(angle_estimator="music", angle_subarray=4, elevation_processing=True,
                    use_elevation_tx=True)):
        with pytest.raises(SceneError, match="radar.angle_subarray"):
            make_scene(_no_targets, **kw)
    scene = make_scene(_no_targets, angle_estimator="music", angle_subarray=9)
    with pytest.raises(SceneError, match=r"radar.angle_subarray = 9: must be in \[2, 8\]"):
        Steering.build(build_setup(scene).rut, scene.radar)
    st, _ = steering(estimator="music", subarray=3)
    sparse = dataclasses.replace(st, mask=st.mask.copy(), positions_m=st.positions_m * [[1.0]])
    pos = sparse.positions_m.copy()
    pos[pos[:, 0] == pos[:, 0].max(), 0] += 2 * st.pitch_m  # a gap before the last element
    sparse = dataclasses.replace(sparse, positions_m=pos)
    with pytest.raises(SceneError, match="radar.angle_subarray = 3: must be 0 for this array"):
        sparse._check_smoothing()
    with pytest.raises(SceneError, match="angle_estimator"):
        make_scene(_no_targets, angle_estimator="esprit")


def test_pair_snapshots_are_the_coherent_far_field(default_pair):
    """The sweep's snapshots: channel i alone peaks at u_i, j alone at u_j, and at rho = 1
    Bartlett's peak is the midpoint (symmetry)."""
    st, nv = steering()
    x = pair_snapshots(st, nv, -0.05, 0.07, np.array([1.0]))
    assert abs(np.sin(st.search(x)[0]) - 0.01) < 1e-9


@pytest.mark.parametrize("kind", ["capon", "music"])
def test_near_field_parallax_keeps_smoothing_from_resolving_the_front_ends(kind):
    """On the paper's 1 m arc the default pair (0.6 of the resolution apart) stays one
    synthesized target under a smoothed Capon or MUSIC (L = 7 of 8): the RuT's physical
    aperture (Tx and Rx groups, ~3 cm) in the near field adds a curved, non-shift-invariant
    phase that smoothing cannot decorrelate. Moved out to a 5 m arc (the same angles), the
    same estimator resolves the two front ends: the detected angle jumps by degrees at one
    ratio, as in the far-field sweep. (The front ends' Rx/Tx separation, 20 mm on the default
    scene, has the same effect in a smaller measure: with it, Capon's jump at 5 m is
    ~0.5 deg.)"""
    steps = {}
    for radius in (1.0, 5.0):
        def mutate(doc, radius=radius):
            doc["rts"]["arc_radius_m"] = radius
            for fe in doc["rts"]["front_ends"]:  # co-located Rx and Tx: the parallax alone
                fe["rx_tx_separation_m"] = 0.0
        scene = make_scene(mutate, angle_estimator=kind, angle_subarray=7)
        setup = build_setup(scene)
        m = ChannelModel.build(setup, exact_paths(setup), (0, 1), TargetConfig(33.5))
        ph = (0.0, float(m.pair_phase(np.radians([7.8]))))
        rho = np.exp(np.linspace(-5, 5, 201))
        a = np.degrees(m.direction(m.pair_weights(rho, ph)))
        steps[radius] = float(np.max(np.abs(np.diff(a))))
    assert steps[1.0] < 0.2 < 2.0 < steps[5.0], steps


def test_smoothed_search_gives_nan_for_a_nan_snapshot():
    """A snapshot with NaN (the calibration sweep's steps that have no design) gives a NaN
    angle, the others theirs."""
    st, nv = steering(estimator="capon", subarray=5)
    x = plane_waves(st, np.array([[0.1], [0.2]]), nv)
    x[0, st.mask.nonzero()[0][0]] = np.nan
    a = st.search(x)
    assert np.isnan(a[0]) and abs(np.sin(a[1]) - 0.2) < 1e-9


def test_run_cli_offers_the_registry_estimators(tmp_path, capsys):
    """``run --estimator`` takes its choices from ``registry.ANGLE_ESTIMATORS``; the override
    is validated like the scene file (exit 2 naming the field)."""
    from rtsgeom.cli import main
    from rtsgeom.scene.registry import ANGLE_ESTIMATORS
    scene = str(ROOT / "scenes" / "diewald2022.toml")
    with pytest.raises(SystemExit) as exc:
        main(["run", scene, "--out", str(tmp_path / "a"), "--estimator", "esprit"])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert all(k in err for k in ANGLE_ESTIMATORS)
    rc = main(["run", scene, "--out", str(tmp_path / "b"), "--estimator", "bartlett",
               "--subarray", "4", "--quiet"])
    assert rc == 2 and "radar.angle_subarray = 4" in capsys.readouterr().err


@pytest.mark.parametrize("estimator", ["capon", "music"])
def test_the_tolerance_model_refuses_a_smoothed_estimator(estimator, capsys):
    """The tolerance model (tolerance, design, coverage design) designs for the beamformer's
    peak and estimates the draws' angles there; a smoothed Capon or MUSIC peaks elsewhere
    (they had reported NaN statistics, "composite splits" and 0 mm tolerances): a named
    error, while without smoothing (rank one: they peak where Bartlett does) it runs."""
    from rtsgeom.analysis.tolerance.phasors import ChannelPhasors
    smoothed = make_scene(angle_estimator=estimator, angle_subarray=5)
    with pytest.raises(SceneError, match=rf"radar.angle_estimator = {estimator} with "
                                         r"radar.angle_subarray = 5"):
        ChannelPhasors.build(build_setup(smoothed), (0, 1), points=3)
    plain = make_scene(angle_estimator=estimator, angle_subarray=0)
    assert np.isfinite(ChannelPhasors.build(build_setup(plain), (0, 1), points=3).amplitudes).all()


@pytest.mark.parametrize("pitch", [1.95e-3, 0.5, 7.0])
def test_uniform_cells_hold_a_filled_grid_to_a_millionth_of_its_pitch(pitch):
    """Cells of a filled uniform row (any order, repeated positions), its N; a position off
    the grid by more than 1e-6 pitch is not on it, within that it is; a missing cell is a
    gap, counted."""
    x = np.array([3, 0, 1, 2, 1, 3], float) * pitch + 0.25
    cell, n = est.uniform_cells(x, pitch)
    assert n == 4 and list(cell) == [3, 0, 1, 2, 1, 3]
    near = x.copy()
    near[2] += 0.5e-6 * pitch
    assert est.uniform_cells(near, pitch)[1] == 4
    off = x.copy()
    off[2] += 2e-6 * pitch
    with pytest.raises(ValueError) as exc:
        est.uniform_cells(off, pitch)
    assert str(exc.value) == "the azimuth row's elements are not on a uniform grid"
    with pytest.raises(ValueError) as exc:
        est.uniform_cells(np.array([0, 1, 4, 5, 9], float) * pitch, pitch)
    assert str(exc.value) == "the azimuth row has gaps (5 of 10 grid positions filled)"


def test_bad_smoothing_settings_are_refused_word_for_word():
    from conftest import assert_refused
    assert_refused(lambda: make_scene(_no_targets, angle_subarray=4),
                   'test.toml: radar.angle_subarray = 4: must be 0 with radar.angle_estimator = '
                   '"bartlett" (eq. 14 beamforms the whole array; spatial smoothing is for capon '
                   'and music)', SceneError)
    assert_refused(lambda: make_scene(_no_targets, angle_estimator="music", angle_subarray=4,
                                      elevation_processing=True, use_elevation_tx=True),
                   "test.toml: radar.angle_subarray = 4: must be 0 with "
                   "radar.elevation_processing = true: spatial smoothing is implemented for the "
                   "1-D azimuth row only (2-D arrays need 2-D subarrays, not implemented); "
                   "without smoothing capon and music peak where bartlett does", SceneError)
    for sub in (9, 1):
        scene = make_scene(_no_targets, angle_estimator="music", angle_subarray=8)
        st = dataclasses.replace(Steering.build(build_setup(scene).rut, scene.radar),
                                 subarray=sub)
        assert_refused(st._check_smoothing,
                       f"radar.angle_subarray = {sub}: must be in [2, 8] (the azimuth row has 8 "
                       "distinct positions), or 0 for no smoothing", SceneError)
    st, _ = steering(estimator="music", subarray=3)
    for k in (2, 8):
        dataclasses.replace(st, subarray=k)._check_smoothing()  # the edges are taken
    shifted = st.positions_m.copy()
    shifted[:, 0] += 1e-5 * (shifted[:, 0] > shifted[:, 0].min())
    assert_refused(dataclasses.replace(st, positions_m=shifted)._check_smoothing,
                   "radar.angle_subarray = 3: must be 0 for this array: the azimuth row's "
                   "elements are not on a uniform grid (spatial smoothing needs a filled uniform "
                   "row; a sparse row has no shifted subarrays)", SceneError)
    flat = dataclasses.replace(st, positions_m=np.c_[st.positions_m, np.zeros(st.size)])
    assert_refused(flat._check_smoothing,
                   "radar.angle_subarray = 3: must be 0 with 2-D (azimuth x elevation) "
                   "processing: spatial smoothing is implemented for the 1-D azimuth row only",
                   SceneError)


@pytest.mark.parametrize("n", [2, 3, 4])
def test_music_leaves_at_least_one_noise_eigenvector(n):
    """rtsgeom.radar.estimators' MUSIC kernel on R = V diag(lam) V^H with k = 1..n eigenvalues
    within SIGNAL_EIGEN_DB of the largest (the rest 60 dB below): the projector onto the
    n - min(k, n - 1) smallest eigenvectors, so a full-rank, well-conditioned R (k = n) still
    keeps one noise eigenvector (rank 1, trace 1), over a batch of covariances."""
    rng = np.random.default_rng(n)
    q, _ = np.linalg.qr(rng.normal(size=(n, n, n)) + 1j * rng.normal(size=(n, n, n)))
    covs, want = [], []
    for k in range(1, n + 1):
        v = q[k - 1]
        lam = np.r_[np.full(n - k, 1e-6), np.linspace(0.5, 1.0, k)]  # ascending
        covs.append((v * lam) @ v.conj().T)
        m = n - min(k, n - 1)
        want.append(v[:, :m] @ v[:, :m].conj().T)
    got = est.kernel(np.stack(covs), "music")
    np.testing.assert_allclose(got, np.stack(want), rtol=0, atol=1e-9)
    assert np.allclose(np.trace(got, axis1=-2, axis2=-1).real,
                       [n - min(k, n - 1) for k in range(1, n + 1)], atol=1e-9)
    assert np.linalg.matrix_rank(got[-1], tol=1e-6) == 1
