"""The fast path (rtsgeom.radar.windowed) against the full chain, on a grid of radars: every
detection the association can use (each cell within the gate plus one of a target) is found
by both, at the same cells, within 1 mm, 1e-3 m/s and 1e-3 deg; outside the fast path the frame
says why and the full chain runs."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.radar.cfar import cfar_mask
from rtsgeom.radar.frame import fast_path_excluded, observe
from rtsgeom.radar.windowed import MARGIN_DB, MapAxes, cell_centres
from rtsgeom.radar.processing import spectrum_axes
from rtsgeom.rts.channels import apparent_range, program_nearest
from rtsgeom.scene import CfarConfig

from conftest import make_scene, quiet

GATE = 2
PRESETS = (("awr1843boost", False), ("iwr6843isk", True), ("awr2944", False),
           ("awr2243-cascade", True))
WINDOWS = (("hann", "hann"), ("none", "blackman"), ("hamming", "none"))
#: every preset with every window pair; the CFAR kind, the noise, the angle peaks per cell
#: and the cube size rotate through the cases, so each value meets several radars
CASES = [(p, e, w, ("ca", "os")[i % 2], (None, 18.0, 30.0)[i % 3], 1 + i % 2, i % 4 == 3)
         for i, ((p, e), w) in enumerate(itertools.product(PRESETS, WINDOWS))]


def _scene(preset, elevation, windows, cfar, snr_db, peaks, odd=False):
    def mutate(doc):
        quiet(doc, small=True, antenna_preset=preset, elevation_processing=elevation,
              range_window=windows[0], doppler_window=windows[1], angle_peaks_max=peaks)
        if odd:  # odd cube sides: the fftshifted Doppler axis and the windows' centres
            doc["radar"].update(chirps_per_tx=31, samples_per_chirp=127)
        doc["radar"]["cfar"] = {"kind": cfar}
        if snr_db is not None:
            doc["radar"]["snr_db"] = snr_db
        # velocities every preset's unambiguous TDM-MIMO span holds, and a fifth target in
        # the first one's range-Doppler cell, 9 deg away
        for t, v in zip(doc["targets"], (0.0, 1.0, -0.5, -1.2)):
            t["velocity_mps"] = v
        doc["targets"].append(dict(doc["targets"][0], angle_deg=-2.0))
        doc["radar"].pop("use_elevation_tx", None)
        doc["rts"]["aoa_mode"] = "nearest"  # (the programme is the nearest front end's)
    return make_scene(mutate)


def _looks(scene, seed=3):
    setup = build_setup(scene)
    paths = exact_paths(setup)
    program = program_nearest(scene, setup)
    ts = scene.targets
    centres = cell_centres(scene.radar, apparent_range(scene, [t.range_m for t in ts]),
                           [t.velocity_mps for t in ts])
    look = {ch: observe(setup, paths, program, seed, scene.radar.snr_db, centres, GATE, ch)
            for ch in ("fast", "full")}
    return look, centres


def _in_windows(det, centres, n_r, n_d):
    """The full chain's detections at cells within GATE + 1 of a centre (cyclic)."""
    def near(idx, c, n):
        d = np.abs(np.asarray(idx)[:, None] - np.rint(c)[None, :]) % n
        return np.minimum(d, n - d) <= GATE + 1
    keep = (near(det.range_bin, centres[:, 0], n_r) & near(det.doppler_bin, centres[:, 1], n_d)
            ).any(axis=1)
    return np.flatnonzero(keep)


@pytest.mark.parametrize("preset, elevation, windows, cfar, snr_db, peaks, odd", CASES)
def test_the_fast_path_finds_the_full_chains_detections(preset, elevation, windows, cfar,
                                                        snr_db, peaks, odd):
    scene = _scene(preset, elevation, windows, cfar, snr_db, peaks, odd)
    look, centres = _looks(scene)
    fast, full = look["fast"], look["full"]
    assert fast.fallback is None and full.fallback is None
    assert isinstance(fast.rd, MapAxes) and fast.rd.range_m.size == full.rd.range_m.size
    n_r, n_d = full.rd.power.shape
    keep = _in_windows(full.detections, centres, n_r, n_d)
    f, d = fast.detections, full.detections
    assert len(keep) >= 3  # not an empty comparison
    key = lambda x, i: (x.range_bin[i], x.doppler_bin[i], x.peak_rank[i])  # noqa: E731
    assert [key(d, i) for i in keep] == [key(f, i) for i in range(len(f))]
    np.testing.assert_allclose(f.range_m, d.range_m[keep], rtol=0, atol=1e-3)
    np.testing.assert_allclose(f.velocity_mps, d.velocity_mps[keep], rtol=0, atol=1e-3)
    np.testing.assert_allclose(f.angle_deg, d.angle_deg[keep], rtol=0, atol=1e-3)
    np.testing.assert_allclose(f.elevation_deg, d.elevation_deg[keep], rtol=0, atol=1e-3)
    np.testing.assert_allclose(f.snr_db, d.snr_db[keep], rtol=0, atol=1e-3)
    assert (f.elevation_rad is None) == (d.elevation_rad is None)


def test_noise_is_the_full_chains_realisation():
    """With noise the fast path's detections move with the seed exactly as the full chain's
    (the same draws), not merely with the same statistics."""
    scene = _scene("awr1843boost", False, ("hann", "hann"), "ca", 12.0, 1)
    for seed in (1, 2):
        look, centres = _looks(scene, seed)
        f, d = look["fast"].detections, look["full"].detections
        keep = _in_windows(d, centres, *look["full"].rd.power.shape)
        np.testing.assert_allclose(f.angle_deg, d.angle_deg[keep], rtol=0, atol=1e-3)
        np.testing.assert_allclose(f.range_m, d.range_m[keep], rtol=0, atol=1e-3)
    a, _ = _looks(scene, 1)
    b, _ = _looks(scene, 2)
    assert not np.allclose(a["fast"].detections.angle_deg[:3], b["fast"].detections.angle_deg[:3],
                           atol=1e-3)


def test_a_linked_radar_takes_the_full_chain_and_says_why():
    """[radar.link]'s ADC clips and quantises: not linear, so the full chain runs."""
    scene = make_scene(lambda d: (quiet(d, small=True), d["radar"].update(
        link={"noise_figure_db": 12.0})))
    assert "not linear" in fast_path_excluded(scene)
    look, _ = _looks(scene)
    assert "not linear" in look["fast"].fallback and look["full"].fallback is None
    assert look["fast"].detections.range_m.tolist() == look["full"].detections.range_m.tolist()


def test_a_cell_at_its_threshold_takes_the_full_chain():
    """A cell under test within MARGIN_DB of its CFAR threshold (rounding could decide it):
    the threshold set where the strongest target's cell lies, the frame falls back."""
    scene = _scene("awr1843boost", False, ("hann", "hann"), "ca", None, 1)
    look, centres = _looks(scene)
    d = look["full"].detections
    t = float(np.max(d.snr_db))  # the strongest cell over its CFAR noise estimate
    for off, falls in ((0.3 * MARGIN_DB, True), (-50 * MARGIN_DB, False)):
        s2 = scene.evolve(radar=scene.radar.evolve(cfar=CfarConfig(
            kind="ca", threshold_db=t + off)))
        look2, _ = _looks(s2)
        assert (look2["fast"].fallback is not None) == falls
        if falls:
            assert "CFAR threshold" in look2["fast"].fallback


def test_windows_beside_each_other_are_cfar_on_their_own():
    """cfar_mask over (R, D, T) windows side by side equals each window on its own."""
    rng = np.random.default_rng(0)
    p = rng.exponential(size=(40, 20, 3))
    p[20, 10] *= 1e3
    for kind in ("ca", "os"):
        cfg = CfarConfig(kind=kind)
        m, n = cfar_mask(p, cfg, map_shape=(40, 20))
        for t in range(3):
            m1, n1 = cfar_mask(p[:, :, t], cfg)
            np.testing.assert_array_equal(m[:, :, t], m1)
            np.testing.assert_allclose(n[:, :, t], n1, rtol=1e-12)


def test_cell_centres_are_the_maps_bins():
    """A range and velocity on the map's axes give their own bin indices back."""
    scene = _scene("awr1843boost", False, ("hann", "hann"), "ca", None, 1)
    axes = MapAxes.of(scene.radar)
    r_i, d_i = np.array([3, 50, 127]), np.array([0, 16, 31])
    c = cell_centres(scene.radar, axes.range_m[r_i], axes.velocity_mps[d_i])
    np.testing.assert_allclose(c, np.c_[r_i, d_i], atol=1e-9)
    np.testing.assert_array_equal(axes.range_m, spectrum_axes(scene.radar)[0])


def test_many_targets_take_the_full_chain_and_say_why():
    """Targets whose windows together hold more cells than the map: the full chain is cheaper
    (the windows' products grow as targets x echoes; 100 targets on the cascade took 4x the
    full chain's CPU and 1.3 GB), so the frame falls back and says why."""
    rng = np.random.default_rng(1)
    targets = [{"range_m": float(r), "angle_deg": float(a), "velocity_mps": float(v)}
               for r, a, v in zip(rng.uniform(5, 60, 40), rng.uniform(-20, 20, 40),
                                  rng.uniform(-2, 2, 40))]
    scene = make_scene(lambda d: (quiet(d, small=True), d.update(targets=targets),
                                  d["rts"].update(aoa_mode="nearest")))
    look, _ = _looks(scene)
    assert "more cells than the map" in look["fast"].fallback
    assert look["fast"].detections.range_m.tolist() == look["full"].detections.range_m.tolist()


def test_the_windows_in_blocks_of_targets_are_the_same(monkeypatch):
    """The windows' factors formed a block of targets at a time (memory): one target per
    block gives the same detections as all at once."""
    from rtsgeom.radar import windowed
    scene = _scene("awr1843boost", False, ("hann", "hann"), "ca", 18.0, 2)
    whole, _ = _looks(scene)
    monkeypatch.setattr(windowed, "BLOCK_ELEMENTS", 1)
    single, _ = _looks(scene)
    a, b = whole["fast"].detections, single["fast"].detections
    assert len(a) >= 3 and a.range_m.tolist() == b.range_m.tolist()
    assert a.angle_deg.tolist() == b.angle_deg.tolist()
