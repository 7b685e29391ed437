"""The batched planning of a drive and the pruned angle-peak refinement give what the
one-by-one computations give: the channel models of ``synthesis.batch.build_models`` are
``ChannelModel.build``'s bit for bit, ``plan_pairs``' plans are ``plan_pair``'s, and
``angle_peaks`` reports the same peaks with and without skipping the grid candidates its
bound rules out."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from conftest import make_scene
from rtsgeom.calibration.probes import probe_angles
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths, nominal_model
from rtsgeom.calibration.phasor import PairChannels
from rtsgeom.pipeline.pair import plan_pair, plan_pairs
from rtsgeom.radar import peaks
from rtsgeom.radar.steering import Steering
from rtsgeom.scene import TargetConfig
from rtsgeom.synthesis.batch import build_models
from rtsgeom.synthesis.model import ChannelModel


def _setup(window: str, fir: str, separation_m: float = 0.0, estimator: str | None = None):
    def mutate(doc):
        if estimator is not None:
            doc["radar"]["angle_estimator"] = estimator
            doc["radar"]["angle_subarray"] = 6
        doc["radar"]["range_window"] = window
        doc["radar"]["doppler_window"] = window
        doc["rts"]["fractional_delay_filter"] = fir
        for fe in doc["rts"]["front_ends"]:
            fe["rx_tx_separation_m"] = separation_m
    setup = build_setup(make_scene(mutate))
    return setup, exact_paths(setup)


def _targets(setup, n: int, seed: int) -> list[TargetConfig]:
    """``n`` targets inside the arc's span at ranges and velocities over the radar's axes."""
    rng = np.random.default_rng(seed)
    th = setup.fe_azimuth_rad()
    radar = setup.scene.radar
    return [TargetConfig(range_m=float(rng.uniform(5.0, 0.8 * radar.max_range_m)),
                         velocity_mps=float(rng.uniform(-0.8, 0.8) * radar.max_velocity_mps),
                         rcs_dbsm=float(rng.uniform(-5, 20)),
                         angle_rad=float(rng.uniform(th.min(), th.max())))
            for _ in range(n)]


def _pair_of(setup, t) -> tuple[int, int]:
    th = setup.fe_azimuth_rad()
    i = int(np.clip(np.searchsorted(th, t.angle_rad) - 1, 0, th.size - 2))
    return i, i + 1


@pytest.mark.parametrize("window,fir,separation_m", [
    ("hann", "windowed-sinc", 0.0), ("none", "ideal", 0.0), ("hamming", "windowed-sinc", 0.02)])
@pytest.mark.parametrize("half_bins", [1, 2])
def test_batched_channel_models_are_the_single_builds(window, fir, separation_m, half_bins):
    setup, paths = _setup(window, fir, separation_m)
    nom, nom_paths = nominal_model(setup, paths)
    targets = _targets(setup, 12, 3)
    pairs = [_pair_of(setup, t) for t in targets]
    dtau = np.random.default_rng(4).normal(0.0, 2e-10, (len(targets), 2))
    many = build_models(nom, nom_paths, pairs, targets, dtau, half_bins)
    for m, p, t, d in zip(many, pairs, targets, dtau):
        one = ChannelModel.build(nom, nom_paths, p, t, d, half_bins)
        np.testing.assert_array_equal(m.responses, one.responses)
        assert (m.channels, m.doppler_hz, m.unit_gain, m.range_m) == (
            one.channels, one.doppler_hz, one.unit_gain, one.range_m)
    assert build_models(nom, nom_paths, [], [], np.zeros((0, 2))) == []


@pytest.mark.parametrize("window,fir,estimator", [
    ("hann", "windowed-sinc", None), ("none", "ideal", None), ("hann", "ideal", "capon")])
def test_batched_plans_are_plan_pairs(window, fir, estimator):
    """Every row ``plan_pairs`` settles is ``plan_pair``'s plan, bit for bit; ``plan_pair``
    plans the rows it leaves open (None) itself. Bartlett, and a smoothed Capon (whose ratio
    is a bisection on its own peak)."""
    setup, paths = _setup(window, fir, estimator=estimator)
    th = setup.fe_azimuth_rad()
    rng = np.random.default_rng(8)
    rows = []
    for t in _targets(setup, 16, 5):
        i, j = _pair_of(setup, t)
        rows.append(((i, j), t, probe_angles(th[i], th[j]),
                     tuple(rng.normal(0.0, 3e-10, 2)), np.array([1.0, rng.uniform(0.9, 1.1)]),
                     float(rng.normal(0.0, 2e-13))))
    got = plan_pairs(setup, paths, "exact", rows)
    assert sum(p is not None for p in got) >= 12
    for plan, row in zip(got, rows):
        want = plan_pair(setup, paths, PairChannels(row[0], row[3], row[4]), row[1], "exact",
                         row[2], row[5])
        if plan is None:  # plan_pair tries the periods either side
            continue
        assert plan.period_offset == want.period_offset == 0
        for f in ("offset_j_s", "realised_difference_s", "planned_difference_s",
                  "quantisation_residual_s", "if_hz", "rho"):
            assert getattr(plan, f) == getattr(want, f), f
        np.testing.assert_array_equal([plan.a_i, plan.a_j], [want.a_i, want.a_j])
    assert plan_pairs(setup, paths, "array-factor", rows[:2]) == [None, None]


@pytest.mark.parametrize("threshold", [0.1, 0.3, 0.5, 0.9])
@pytest.mark.parametrize("window", ["none", "hann"])
def test_pruned_angle_candidates_change_no_peak(threshold, window, monkeypatch):
    """Snapshots of two to four plane waves at random angles and powers, with noise: the peaks
    and levels with the bound's pruning equal those with every candidate refined, and the
    bound does prune (weak sidelobes)."""
    scene = make_scene(angle_window=window)
    setup = build_setup(scene)
    st = Steering.build(setup.rut, scene.radar)
    rng = np.random.default_rng(11)
    n = 60
    snaps = np.zeros((n, st.mask.size), complex)
    for r in range(n):
        for _ in range(rng.integers(2, 5)):
            u = np.sin(rng.uniform(-1.2, 1.2))
            a = 10 ** (rng.uniform(-1.5, 0) / 2) * np.exp(1j * rng.uniform(0, 2 * np.pi))
            snaps[r, st.mask] += a * np.exp(1j * st.wavevector[:, 0] * u)
        snaps[r] += 0.03 * (rng.normal(size=st.mask.size) + 1j * rng.normal(size=st.mask.size))
    pruned = peaks.angle_peaks(st, snaps, 4, threshold)
    kept = []
    real = peaks._may_pass

    def spy(*a):
        out = real(*a)
        kept.append(out)
        return np.ones_like(out)
    monkeypatch.setattr(peaks, "_may_pass", spy)
    every = peaks.angle_peaks(st, snaps, 4, threshold)
    for a, b in zip(pruned, every):
        np.testing.assert_array_equal(a, b)
    cand, _ = peaks._candidates_1d(st, snaps)
    assert (~kept[0] & np.isfinite(cand)).sum() > 0  # the bound rules some out
    # the bound itself: every candidate's refined power is within it (a bound of 0 reach, or
    # one that forgot the zooms' reach, fails here)
    _, refined = peaks._refine_1d(st, snaps, cand)
    _, val = peaks._candidates_1d(st, snaps)
    for j in np.flatnonzero(np.isfinite(refined).any(axis=0)):
        rows = np.isfinite(refined[:, j])
        ok = real(st, snaps[rows], val[rows], refined[rows, j])[:, j]
        assert ok.all()


def test_plays_estimate_runs_no_frame(monkeypatch):
    """``play``'s line before the drive names the frames, modes and targets without running
    a frame through the chain (which measured the process's one-time costs, not a frame's)."""
    from rtsgeom.analysis.playback import Playback, frames
    from rtsgeom.cli import play
    from rtsgeom.scene import load_scene
    from conftest import ROOT

    def refuse(*a, **k):
        raise AssertionError("the estimate ran a frame")
    monkeypatch.setattr(frames, "detect_frame", refuse)
    scene = load_scene(ROOT / "scenes" / "crossing.toml")
    n = scene.scenario.frame_times().size
    line = play._estimate(scene, Playback())
    assert line.startswith(f"{n} frames x 2 mode(s) of 1 targets, 1 worker(s)")
    assert play._estimate(scene, Playback(baseline=False)).startswith(f"{n} frames x 1 mode(s)")


def test_steering_is_built_once_per_rut_and_radar():
    """``Steering.build`` returns the beamformer it built for the same (immutable) RuT and
    radar objects, and a new one for another radar (another taper) or the 2-D case; a
    beamformer it refuses is refused every time."""
    from rtsgeom.errors import SceneError
    scene = make_scene()
    setup = build_setup(scene)
    a = Steering.build(setup.rut, scene.radar)
    assert Steering.build(setup.rut, scene.radar) is a
    other = dataclasses.replace(scene.radar, angle_window="hann")
    b = Steering.build(setup.rut, other)
    assert b is not a and not np.array_equal(a.taper, b.taper)
    np.testing.assert_array_equal(b.taper, Steering._build(setup.rut, other, False).taper)
    assert Steering.build(setup.rut, scene.radar, elevation=True).dims == 2
    bad = dataclasses.replace(scene.radar, angle_estimator="capon", angle_subarray=999)
    for _ in range(2):
        with pytest.raises(SceneError, match="angle_subarray"):
            Steering.build(setup.rut, bad)
