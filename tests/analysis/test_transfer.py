"""transfer's working memory: the percentiles partition one copy in place, and the study's
(1 + 2B, P) errors are one array filled in place (benchmarks/transfer_memory.py measures the
peak at the documented maximum)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from rtsgeom.analysis.transfer import TransferStudy, percentiles
from rtsgeom.errors import ParameterError


def test_percentiles_are_numpys_and_leave_the_input_alone():
    rng = np.random.default_rng(0)
    for shape in [(7,), (40, 13), (3, 1001)]:
        x = rng.normal(size=shape)
        x.flat[::5] = np.nan
        keep = x.copy()
        got = percentiles(x)
        a = np.abs(x[np.isfinite(x)])
        assert got == {"p50": float(np.percentile(a, 50)), "p95": float(np.percentile(a, 95)),
                       "max": float(a.max())}
        assert np.array_equal(x, keep, equal_nan=True)
    assert percentiles(np.full(4, np.nan)) == {"p50": None, "p95": None, "max": None}



@pytest.mark.parametrize("pairs", [((0,),), ((0, 1), (2,)), ((0, 1, 2),)])
def test_a_transfer_pair_is_two_front_ends(pairs):
    with pytest.raises(ParameterError, match=r"pairs\[\d\]"):
        TransferStudy(pairs=pairs)


# -- the study's config: each declared range enforced exactly at its edges, in full words --

TRANSFER_BOUNDS = [
    ("radars", [1, 100_000], [(0, "transfer: radars = 0: must be in [1, 100000]"),
                              (100_001, "transfer: radars = 100001: must be in [1, 100000]")]),
    ("sigma_phase_deg", [0.0, 90.0],
     [(-0.5, "transfer: sigma_phase_deg = -0.5: must be in [0, 90] deg"),
      (90.5, "transfer: sigma_phase_deg = 90.5: must be in [0, 90] deg")]),
    ("sigma_gain_db", [0.0, 6.0],
     [(-0.5, "transfer: sigma_gain_db = -0.5: must be in [0, 6] dB"),
      (6.5, "transfer: sigma_gain_db = 6.5: must be in [0, 6] dB")]),
    ("points", [1, 201], [(0, "transfer: points = 0: must be in [1, 201]"),
                          (202, "transfer: points = 202: must be in [1, 201]")]),
    ("mode", ["exact", "array-factor", "paper"],
     [("nearest", "transfer: mode = 'nearest': must be one of exact, array-factor, paper")]),
    ("seed", [0, 2 ** 63 - 1],
     [(-1, "transfer: seed = -1: must be in [0, 9.22337e+18]"),
      (2 ** 63, "transfer: seed = 9223372036854775808: must be in [0, 9.22337e+18]")]),
    ("spec_deg", [1e-6, 90.0], [(0.0, "transfer: spec_deg = 0: must be in [1e-06, 90] deg"),
                                (90.5, "transfer: spec_deg = 90.5: must be in [1e-06, 90] deg")]),
    ("pairs", [((0, 1),), [[3, 4], (10_000, 9_999)]],
     [((), "transfer: pairs = (): must be a non-empty tuple of front-end pairs (i, i + 1)"),
      ((0, 1), "transfer: pairs = (0, 1): must be a non-empty tuple of front-end pairs "
               "(i, i + 1)"),
      ("01", "transfer: pairs = '01': must be a non-empty tuple of front-end pairs (i, i + 1)"),
      (((0,),), "transfer: pairs[0] = [0]: must be a list (at least 2 and at most 2 entries) "
                "of integers in [0, 10000]"),
      (((0, 1), (1, 2, 3)), "transfer: pairs[1] = [1, 2, 3]: must be a list (at least 2 and at "
                            "most 2 entries) of integers in [0, 10000]"),
      (((0, 10_001),), "transfer: pairs[0][1] = 10001: must be in [0, 10000]")]),
]


@pytest.mark.parametrize("name, ok, bad", TRANSFER_BOUNDS, ids=[r[0] for r in TRANSFER_BOUNDS])
def test_transfer_study_enforces_each_range_at_its_edges(name, ok, bad):
    from conftest import assert_bounds
    assert_bounds(lambda v: TransferStudy(**{name: v}), ok, bad)


def test_transfer_study_normalises_its_values():
    """numpy scalars become int / float, -0.0 becomes 0, pairs a tuple of int tuples; the
    defaults are the documented ones."""
    s = TransferStudy(radars=np.int64(7), sigma_phase_deg=np.float64(-0.0), sigma_gain_db=-0.0,
                      points=np.int32(3), seed=np.uint8(5), spec_deg=np.float32(0.5),
                      pairs=[[np.int64(1), 2]])
    assert (s.radars, s.points, s.seed, s.pairs) == (7, 3, 5, ((1, 2),))
    assert type(s.radars) is int and type(s.points) is int and type(s.seed) is int
    assert type(s.pairs[0][0]) is int
    for v in (s.sigma_phase_deg, s.sigma_gain_db, s.spec_deg):
        assert type(v) is float
    assert np.copysign(1.0, s.sigma_phase_deg) == 1.0 and np.copysign(1.0, s.sigma_gain_db) == 1.0
    d = TransferStudy()
    assert (d.radars, d.sigma_phase_deg, d.sigma_gain_db, d.points, d.pairs, d.spec_deg,
            d.mode, d.seed) == (100, 5.0, 0.0, 11, None, None, "exact", 0)


@pytest.mark.parametrize("radars, points, pairs", [(100_000, 201, 1), (1, 201, 100_000),
                                                   (50_000, 201, 2), (20_100, 10, 100)])
def test_transfer_set_points_are_capped_at_the_documented_memory(radars, points, pairs):
    """radars x points x pairs <= MAX_RADAR_POINTS (20.1 million) is taken, one more radar is
    refused with the whole sentence naming the counts."""
    from rtsgeom.analysis.transfer import MAX_RADAR_POINTS
    assert MAX_RADAR_POINTS == 20_100_000 and radars * points * pairs == MAX_RADAR_POINTS
    assert TransferStudy(radars=radars, points=points).set_points(pairs) == points * pairs
    if radars + 1 > 100_000:
        return
    with pytest.raises(ParameterError) as exc:
        TransferStudy(radars=radars + 1, points=points).set_points(pairs)
    assert str(exc.value) == (
        f"transfer: radars = {radars + 1} x {points * pairs} set-points ({points} points x "
        f"{pairs} pairs): must be at most 2.01e+07 radar set-points (the study's results hold "
        "3 x 8 bytes each; fewer radars or points)")


# -- the result: closed forms on hand-made arrays --

def _transfer(error, compensated, own, spec=None, golden=(0.0,), ideal=(0.0,)):
    from rtsgeom.analysis.transfer import Transfer
    e, c, o = (np.atleast_2d(np.asarray(x, float)) for x in (error, compensated, own))
    b, p = e.shape
    return Transfer(((0, 1),), np.zeros(p, int), np.linspace(-4, 4, p),
                    np.asarray(golden, float), np.asarray(ideal, float), e, c, o, (1.5,),
                    np.zeros((p, 4)), np.zeros((b, 2)), np.zeros((b, 2)), 10.0, 5.0, 0.5, spec,
                    "bench")


@pytest.mark.parametrize("spec", [0.05, 0.1, 0.2, 0.3, 0.4, 1.0])
def test_transfer_verdict_is_the_first_case_whose_p95_meets_the_spec(spec):
    """The verdict names the first of transfers / boresight / recalibrate whose p95 of |error|
    is at most the spec (equal meets it), else 'radar'; a verdict's spec argument overrides the
    study's, and none without a spec."""
    ones = np.ones((4, 5))
    res = _transfer(0.3 * ones, -0.2 * ones, 0.1 * ones, spec)
    want = ("transfers" if spec >= 0.3 else "boresight" if spec >= 0.2 else
            "recalibrate" if spec >= 0.1 else "radar")
    assert res.verdict() == want
    assert res.to_dict()["verdict"] == want and res.to_dict()["spec_deg"] == spec
    assert _transfer(0.3 * ones, -0.2 * ones, 0.1 * ones).verdict(spec) == want
    assert _transfer(0.3 * ones, -0.2 * ones, 0.1 * ones).verdict() is None


def test_transfer_excess_absorbed_and_the_dict_are_differences_and_percentiles():
    rng = np.random.default_rng(3)
    e, c, o = (rng.normal(size=(6, 4)) for _ in range(3))
    g, i = rng.normal(size=4), rng.normal(size=4)
    res = _transfer(e, c, o, 0.5, golden=g, ideal=i)
    assert np.array_equal(res.excess_deg, e - o)
    assert np.array_equal(res.absorbed_deg, i - g)
    d = res.to_dict()
    assert (d["radars"], d["set_points"], d["pairs"]) == (6, 4, [[0, 1]])
    assert (d["sigma_phase_deg"], d["sigma_gain_db"], d["absorbed_offset_ps"]) == (5.0, 0.5, [1.5])
    for key, x in (("angle_error_deg", e), ("compensated_angle_error_deg", c),
                   ("own_angle_error_deg", o), ("excess_angle_error_deg", e - o),
                   ("golden_angle_error_deg", g), ("absorbed_deg", i - g)):
        assert d[key] == percentiles(x), key
    df = res.to_dataframe()  # the golden radar's rows (-1) first, then radar by radar
    assert len(df) == 28
    assert np.array_equal(df["radar"], np.r_[np.full(4, -1), np.repeat(np.arange(6), 4)])
    assert np.array_equal(df["error_deg"], np.r_[g, e.ravel()])
    assert np.array_equal(df["set_deg"], np.tile(res.set_deg, 7))
    assert np.array_equal(df["pair"], np.zeros(28))
    assert np.array_equal(df["compensated_error_deg"], np.r_[np.full(4, np.nan), c.ravel()],
                          equal_nan=True)
    assert np.array_equal(df["own_error_deg"], np.r_[np.full(4, np.nan), o.ravel()],
                          equal_nan=True)


def test_transfer_summary_names_the_counts_sigmas_and_verdict():
    res = _transfer(np.full((3, 2), 0.25), np.full((3, 2), 0.125), np.full((3, 2), 0.0625), 0.2)
    title, rows = res._summary()
    assert title == "bench: 3 radars x 2 set-points, sigma 5 deg / 0.5 dB"
    assert rows == [("|angle error| (deg)", "p50 0.2500, p95 0.2500, max 0.2500"),
                    ("with boresight compensation", "p50 0.1250, p95 0.1250, max 0.1250"),
                    ("on a real target", "p50 0.0625, p95 0.0625, max 0.0625"),
                    ("calibration absorbed (ps)", (1.5,)),
                    ("verdict for 0.2 deg", "boresight")]
    assert len(_transfer(np.ones((1, 1)), np.ones((1, 1)), np.ones((1, 1)))._summary()[1]) == 4


@pytest.mark.parametrize("seed, sphase, sgain", [(0, 0.1, 0.0), (4, 0.0, 1.5), (9, 0.3, 0.7)])
def test_drawn_channel_gains_are_tx_times_rx_of_independent_normal_draws(small_setup, seed,
                                                                         sphase, sgain):
    """g[b, v] = 10^((G_t + G_r) / 20) e^{j (phi_t + phi_r)} of the virtual element's Tx t
    and Rx r; the phases drawn first, then the gains, each N(0, sigma), Tx columns first."""
    from rtsgeom.analysis.transfer import draw_channel_gains
    rut = small_setup[0].rut
    n_tx, n_rx = rut.tx_local.shape[0], rut.rx_local.shape[0]
    g, ph, gd = draw_channel_gains(rut, 5, sphase, sgain, seed)
    rng = np.random.default_rng(seed)
    assert np.array_equal(ph, rng.normal(0.0, sphase, (5, n_tx + n_rx)))
    assert np.array_equal(gd, rng.normal(0.0, sgain, (5, n_tx + n_rx)))
    t, r = rut.virtual_tx, n_tx + rut.virtual_rx
    want = 10 ** ((gd[:, t] + gd[:, r]) / 20) * np.exp(1j * (ph[:, t] + ph[:, r]))
    assert g.shape == (5, rut.num_virtual)
    assert np.allclose(g, want, rtol=1e-12, atol=0)


@pytest.mark.parametrize("n, size", [(0, 3), (1, 1), (7, 3), (9, 3), (10, 100)])
def test_transfer_chunks_cover_the_range_once_in_order(n, size):
    from rtsgeom.analysis.transfer import _chunks
    parts = list(_chunks(n, size))
    assert [i for s in parts for i in range(n)[s]] == list(range(n))
    assert all(len(range(n)[s]) == size for s in parts[:-1])
    assert len(parts) == -(-n // size)


def test_set_angles_split_the_shared_span_into_equal_steps(small_setup):
    """points angles at k / (points + 1) of the intersection of the measured and geometric
    spans (either order of the pair's angles), ends excluded."""
    from types import SimpleNamespace
    from rtsgeom.analysis.transfer import set_angles
    setup = small_setup[0]
    geo = setup.fe_azimuth_rad()
    for shift, points in ((0.01, 1), (-0.02, 4), (0.0, 7)):
        meas = geo + shift
        for pair in ((0, 1), (1, 0)):
            got = set_angles(setup, SimpleNamespace(angle_rad=meas), pair, points)
            a, b = sorted(geo[[0, 1]])
            lo, hi = max(a, min(meas[[0, 1]])), min(b, max(meas[[0, 1]]))
            assert np.allclose(got, lo + (hi - lo) * np.arange(1, points + 1) / (points + 1),
                               rtol=0, atol=1e-15)


def test_ideal_radar_drops_the_channels_and_keeps_an_ideal_setup(small_setup):
    """The same bench with [radar.channels] removed (the paths are the same: channels move
    none); a setup without them is returned as it is."""
    from conftest import make_scene, quiet
    from rtsgeom.analysis.transfer import ideal_radar
    from rtsgeom.geometry import build_setup
    setup = small_setup[0]
    assert ideal_radar(setup) is setup

    def mutate(doc):
        quiet(doc, small=True)
        doc["radar"]["channels"] = {"rx_phase_deg": [0.0, 10.0, 0.0, 5.0]}
    real = build_setup(make_scene(mutate))
    ideal = ideal_radar(real)
    assert real.scene.radar.channels is not None and ideal.scene.radar.channels is None
    assert np.array_equal(ideal.fe_azimuth_rad(), real.fe_azimuth_rad())
    assert ideal.scene.rts == real.scene.rts


def test_radars_without_spread_are_the_ideal_golden_radar(default_scene):
    """sigma 0: every drawn radar is ideal, as the scene's (no [radar.channels]): each sees
    what the golden radar sees, its compensation changes nothing, a real target reads its own
    angle (to 1e-9 deg), the calibration absorbs nothing; the set-points split the pair's span
    in equal steps."""
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    setup = build_setup(default_scene)
    r = TransferStudy(radars=3, points=4, sigma_phase_deg=0.0, seed=1)(setup,
                                                                      exact_paths(setup))
    assert r.error_deg.shape == (3, 4) and r.pairs == ((0, 1),)
    for b in range(3):
        assert np.array_equal(r.error_deg[b], r.golden_error_deg)
        assert np.array_equal(r.compensated_error_deg[b], r.golden_error_deg)
    assert np.max(np.abs(r.own_error_deg)) < 1e-9
    assert r.offset_shift_ps == (0.0,) and np.array_equal(r.absorbed_deg, np.zeros(4))
    assert np.allclose(np.diff(r.set_deg), np.diff(r.set_deg)[0], rtol=1e-9)
    assert np.max(np.abs(r.golden_error_deg)) < 0.01
    assert list(r.pair_index) == [0, 0, 0, 0] and r.range_m > 0
    assert r.draw_phase_rad.shape == (3, setup.rut.tx_local.shape[0] + setup.rut.rx_local.shape[0])
    assert not np.any(r.draw_phase_rad) and not np.any(r.draw_gain_db)
    assert (r.sigma_phase_deg, r.sigma_gain_db, r.spec_deg, r.scene_name) == (
        0.0, 0.0, None, default_scene.name)


def test_the_study_tells_each_pair_it_calibrates_and_indexes_its_set_points(crossing_bench):
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    setup = build_setup(crossing_bench)
    told = []
    r = TransferStudy(radars=2, points=2, pairs=((1, 2), (3, 4)))(setup, exact_paths(setup),
                                                                  progress=told.append)
    assert told == ["calibrating pair (1, 2) with the golden radar",
                    "calibrating pair (3, 4) with the golden radar"]
    assert r.pairs == ((1, 2), (3, 4)) and list(r.pair_index) == [0, 0, 1, 1]
    fe = np.degrees(setup.fe_azimuth_rad())
    assert fe[1] < r.set_deg[0] < r.set_deg[1] < fe[2] < fe[3] < r.set_deg[2] < r.set_deg[3] < fe[4]
    assert r.error_deg.shape == (2, 4) and r.programs.shape == (4, 4)


@pytest.mark.parametrize("radars, spec", [(3, 0.2), (45, None)])
def test_the_transfer_figure_draws_the_radars_their_band_and_the_histograms(radars, spec):
    """Left: up to 40 radars' errors over the set angles (grey), the 5-95 % band of the radars
    and of the compensated ones, the golden radar, the compensated median, +-spec; right: the
    |error| histograms over 30 bins from 0 to the largest, the spec."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import PolyCollection
    rng = np.random.default_rng(radars)
    e, c = rng.normal(0, 0.1, (radars, 5)), rng.normal(0, 0.03, (radars, 5))
    g = rng.normal(0, 0.05, 5)
    res = _transfer(e, c, rng.normal(0, 0.01, (radars, 5)), spec, golden=g)
    fig = res.plot()
    ax, bx = fig.axes[:2]
    lines = ax.get_lines()
    grey = [ln for ln in lines if ln.get_color() == "0.75"]
    assert len(grey) == min(radars, 40)
    for k, ln in enumerate(grey):
        assert np.array_equal(ln.get_xdata(), res.set_deg)
        assert np.array_equal(ln.get_ydata(), e[k])
    golden = next(ln for ln in lines if ln.get_label() == "golden radar A (calibrated with)")
    assert np.array_equal(golden.get_ydata(), g) and golden.get_linewidth() == 2
    med = next(ln for ln in lines
               if ln.get_label() == "radars B with boresight compensation, 5-95 %")
    assert np.allclose(med.get_ydata(), np.median(c, axis=0), rtol=0, atol=1e-15)
    bands = [p for p in ax.collections if isinstance(p, PolyCollection)]
    assert len(bands) == 2 and bands[0].get_label() == "radars B, 5-95 %"
    for band, x in zip(bands, (e, c)):
        verts = band.get_paths()[0].vertices
        lo, hi = np.percentile(x, [5, 95], axis=0)
        for k, s in enumerate(res.set_deg):  # the band's edges at each set angle
            at = np.isclose(verts[:, 0], s, rtol=0, atol=1e-12)
            assert np.isclose(verts[at, 1].min(), lo[k]) and np.isclose(verts[at, 1].max(), hi[k])
    specs = [ln for ln in lines if ln.get_color() == "C3"]
    assert sorted(float(ln.get_ydata()[0]) for ln in specs) == ([-spec, spec] if spec else [])
    assert ax.get_title() == ("bench: calibrated with radar A, testing radar B (sigma 5 deg, "
                              "0.5 dB)")
    bars = bx.patches
    assert len(bars) == 2 * 29
    top = np.max(np.abs(e))
    counts_b = [p.get_height() for p in bars[:29]]
    want, _ = np.histogram(np.abs(e).ravel(), np.linspace(0, top, 30))
    assert counts_b == list(want)
    want_c, _ = np.histogram(np.abs(c).ravel(), np.linspace(0, top, 30))
    assert [p.get_height() for p in bars[29:]] == list(want_c)
    for a in (ax, bx):  # the legends' small print
        assert {t.get_fontsize() for t in a.get_legend().get_texts()} == {8.0}
    vlines = [ln for ln in bx.get_lines() if ln.get_label() == "spec"]
    assert [float(ln.get_xdata()[0]) for ln in vlines] == ([spec] if spec else [])
    plt.close(fig)


def test_a_2d_rut_and_a_single_front_end_are_refused_in_full_sentences():
    """The study covers an arc of pairs seen by a RuT that beamforms in azimuth: a RuT that
    beamforms in 2-D, and an arc of one front end, are each refused with the whole sentence
    (a ParameterError; the CLI prints it as one line)."""
    from conftest import ROOT
    from rtsgeom.geometry import build_setup
    from rtsgeom.scene import load_scene
    scene = load_scene(ROOT / "scenes" / "diewald2022.toml")
    two_d = scene.evolve(radar=scene.radar.evolve(use_elevation_tx=True,
                                                  elevation_processing=True), targets=())
    with pytest.raises(ParameterError) as exc:
        TransferStudy()(build_setup(two_d), None)
    assert str(exc.value) == ("transfer: the RuT beamforms in azimuth and elevation; the study "
                              "covers a RuT that beamforms in azimuth (an arc of pairs)")
    one = scene.evolve(rts=scene.rts.evolve(front_ends=scene.rts.front_ends[:1]), targets=())
    with pytest.raises(ParameterError) as exc:
        TransferStudy()(build_setup(one), None)
    assert str(exc.value) == "transfer: the arc needs at least two front ends"


# -- the study against its primitives: a golden radar with channel errors, drawn radars --

def _channels_setup(compensation, **more):
    from conftest import make_scene, quiet
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths

    def mutate(doc):
        quiet(doc, small=True, samples_per_chirp=512)
        doc["radar"]["channels"] = {"rx_phase_deg": [0.0, 10.0, 0.0, 5.0],
                                    "tx_gain_db": [0.0, -0.5, 0.3],
                                    "compensation": compensation, **more}
    setup = build_setup(make_scene(mutate))
    return setup, exact_paths(setup)


@pytest.fixture(scope="module")
def golden_with_errors():
    setup, paths = _channels_setup("none", rx_coupling_db=-20.0)
    study = TransferStudy(radars=4, points=2, pairs=((0, 1),), sigma_phase_deg=3.0,
                          sigma_gain_db=0.5, seed=2, spec_deg=0.05)
    return setup, paths, study, study(setup, paths)


def test_the_study_draws_measures_and_calibrates_as_its_primitives_say(golden_with_errors):
    """A golden radar with its own channel errors (no compensation): the draws are
    draw_channel_gains' (sigma in radians, the study's seed), the set-points set_angles' on
    the probe, the range the first probe's, the calibration's shift the golden minus the ideal
    radar's delay (ps), each radar's error the snapshot of the planned programme seen through
    its gains (with its boresight compensation: those gains compensated), its own error
    plane_wave_errors' at the set angles."""
    from rtsgeom.analysis.transfer import (draw_channel_gains, ideal_radar, own_angle_errors,
                                           set_angles, snapshot_angles)
    from rtsgeom.calibration.pair import calibrate_pair
    from rtsgeom.calibration.probes import probe_front_ends, probe_ranges
    from rtsgeom.radar.channels import channel_coupling, channel_gain, compensation_vector
    from rtsgeom.radar.steering import Steering
    from rtsgeom.scene import TargetConfig
    from rtsgeom.synthesis.model import ChannelModel
    setup, paths, study, r = golden_with_errors
    radar, rut = setup.scene.radar, setup.rut
    g, ph, gd = draw_channel_gains(rut, 4, np.radians(3.0), 0.5, 2)
    assert np.array_equal(r.draw_phase_rad, ph) and np.array_equal(r.draw_gain_db, gd)
    probe = probe_front_ends(setup, paths, 2)
    assert np.array_equal(r.set_deg, np.degrees(set_angles(setup, probe, (0, 1), 2)))
    assert r.range_m == float(probe_ranges(setup, 1)[0])
    ideal = ideal_radar(setup)
    assert ideal is not setup
    cal = calibrate_pair(setup, paths, (0, 1), probe, seed=2)
    cal0 = calibrate_pair(ideal, paths, (0, 1), probe_front_ends(ideal, paths, 2), seed=2)
    assert r.offset_shift_ps == ((cal.delta_tau_s - cal0.delta_tau_s) * 1e12,)
    assert r.offset_shift_ps[0] != 0.0
    st = Steering.build(rut, radar)
    coupling = channel_coupling(radar, rut)
    comp = g * compensation_vector(g, rut, radar.channels.compensation_range_m, coupling)
    gold = channel_gain(radar, rut)
    for p, (a_i, a_j, off_i, off_j) in enumerate(r.programs):
        assert off_i == 0.0 and (a_i, a_j) != (0.0, 0.0)
        t = TargetConfig(r.range_m, 0.0, 10.0, float(np.radians(r.set_deg[p])))
        model = ChannelModel.build(ideal, paths, (0, 1), t, (0.0, off_j), steering=st)
        w = np.array([a_i, a_j])
        for got, gains in ((r.error_deg[:, p], g), (r.compensated_error_deg[:, p], comp),
                           (r.golden_error_deg[p:p + 1], gold[None])):
            want = np.degrees(snapshot_angles(model, w, gains, coupling) - t.angle_rad)
            assert np.allclose(got, want, rtol=0, atol=1e-12), p
    own = np.degrees(own_angle_errors(st, g, np.radians(r.set_deg), coupling))
    assert np.allclose(r.own_error_deg, own, rtol=0, atol=1e-9)
    assert not np.allclose(r.error_deg, r.compensated_error_deg, rtol=0, atol=1e-6)
    assert not np.allclose(r.ideal_cal_error_deg, r.golden_error_deg, rtol=0, atol=1e-9)
    assert (r.sigma_phase_deg, r.sigma_gain_db, r.spec_deg, r.range_m > 0) == (3.0, 0.5, 0.05,
                                                                                True)
    assert coupling is not None
    assert r.pair_index.tolist() == [0, 0] and r.scene_name == setup.scene.name


def test_radars_that_compensate_at_boresight_are_measured_compensated():
    """A golden radar that runs the boresight compensation (at its reflector's range): every
    drawn radar of the type runs it too, so its error is its compensated one, and on a real
    target too."""
    from rtsgeom.analysis.transfer import draw_channel_gains, own_angle_errors
    from rtsgeom.radar.channels import channel_coupling, compensation_vector
    from rtsgeom.radar.steering import Steering
    setup, paths = _channels_setup("boresight", compensation_range_m=4.0)
    r = TransferStudy(radars=3, points=1, sigma_phase_deg=4.0, seed=5)(setup, paths)
    assert np.array_equal(r.error_deg, r.compensated_error_deg)
    assert r.pairs == ((0, 1),) and r.error_deg.shape == (3, 1)
    rut, radar = setup.rut, setup.scene.radar
    g = draw_channel_gains(rut, 3, np.radians(4.0), 0.0, 5)[0]
    coupling = channel_coupling(radar, rut)
    g = g * compensation_vector(g, rut, 4.0, coupling)
    own = own_angle_errors(Steering.build(rut, radar), g, np.radians(r.set_deg), coupling)
    assert np.allclose(r.own_error_deg, np.degrees(own), rtol=0, atol=1e-9)
    assert not np.allclose(compensation_vector(g, rut, None, coupling),
                           compensation_vector(g, rut, 4.0, coupling))


@pytest.mark.parametrize("channels, why", [
    (None, ""),
    (SimpleNamespace(tx_gain_db=(0.0, 1.0), rx_gain_db=(0.5,)), ""),
    (SimpleNamespace(tx_gain_db=(-3.0, 1.0), rx_gain_db=(0.0, -1.5)),
     "; radar.channels.tx_gain_db / rx_gain_db lower the channels by up to 4.5 dB"),
    (SimpleNamespace(tx_gain_db=(), rx_gain_db=(-2.0, 0.0)),
     "; radar.channels.tx_gain_db / rx_gain_db lower the channels by up to 2 dB"),
])
def test_front_ends_the_radar_does_not_see_alone_are_refused_naming_them(monkeypatch,
                                                                         channels, why):
    from rtsgeom.analysis import transfer
    seen = []
    probe = SimpleNamespace(angle_rad=np.array([0.1, np.nan, 0.2, np.inf]),
                            clipping_note=lambda: " (NOTE)")
    monkeypatch.setattr(transfer, "probe_front_ends",
                        lambda setup, paths, seed: seen.append(seed) or probe)
    setup = SimpleNamespace(scene=SimpleNamespace(radar=SimpleNamespace(channels=channels)))
    with pytest.raises(ParameterError) as exc:
        transfer._probe(setup, None, 11)
    assert str(exc.value) == (
        "front end(s) [1, 3] not detected alone by the scene's radar at their probe ranges "
        f"(below the CFAR threshold, or clipped) (NOTE){why}: transfer calibrates each pair on "
        "its front ends' measured angles")
    probe.angle_rad = np.array([0.1, 0.2])
    assert transfer._probe(setup, None, 11) is probe and seen == [11, 11]


def test_the_result_writes_its_json_and_figure(tmp_path, monkeypatch):
    """transfer.json (to_dict's) and transfer.png (the figure plot() draws), their names."""
    import json
    from rtsgeom.analysis.transfer import Transfer
    from rtsgeom.viz import figures
    saved = []
    monkeypatch.setattr(Transfer, "plot", lambda self: ("figure of", self))
    monkeypatch.setattr(figures, "save_figure", lambda fig, path: saved.append((fig, path)))
    res = _transfer(np.full((3, 2), 0.25), np.full((3, 2), 0.125), np.full((3, 2), 0.0625), 0.2)
    assert res.write(tmp_path) == ["transfer.json", "transfer.png"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["transfer.json"]
    assert json.loads((tmp_path / "transfer.json").read_text()) == json.loads(
        json.dumps(res.to_dict()))
    assert saved == [(("figure of", res), tmp_path / "transfer.png")]
