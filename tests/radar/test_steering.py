"""One steering model: the beamformer's closed forms on grids of directions, windows
and arrays (1-D azimuth, 2-D azimuth + elevation, a custom planar array), and the one coherent
phase that the tolerance study and the channel model share for every angle window."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import make_scene

from rtsgeom.analysis.tolerance.phasors import ChannelPhasors
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.radar.processing import angle_spectrum, estimate_angles, refine_angles
from rtsgeom.radar.steering import Steering
from rtsgeom.scene import TargetConfig
from rtsgeom.synthesis.model import ChannelModel

WINDOWS = ("none", "hann", "hamming", "blackman")


def plane_wave(st: Steering, u, n_virtual: int, mask=None) -> np.ndarray:
    """Snapshot (..., V) of a unit plane wave from directions u (..., D): exp(-j k p . u) on
    the elements that take part (zero elsewhere)."""
    x = np.zeros(np.shape(u)[:-1] + (n_virtual,), complex)
    x[..., st.mask] = np.exp(-1j * np.sum(st.wavevector * np.asarray(u)[..., None, :], axis=-1))
    return x


@pytest.mark.parametrize("window", WINDOWS)
def test_azimuth_peak_power_and_search_on_plane_waves(window):
    """Plane waves over the visible region: the Bartlett power at the source is (sum w)^2 and
    no direction has more; ``peak`` (Newton) and ``search`` (grid) both find the source."""
    scene = make_scene(angle_window=window)
    rut = build_setup(scene).rut
    st = Steering.build(rut, scene.radar)
    az = np.radians(np.linspace(-60, 60, 25))
    x = plane_wave(st, st.directions(az), rut.num_virtual)
    p_src = np.diagonal(st.power(x, st.directions(az)))
    assert np.allclose(p_src, np.sum(st.taper) ** 2, rtol=1e-12)
    grid = st.directions(np.radians(np.linspace(-89, 89, 1001)))
    assert np.all(st.power(x, grid) <= p_src[:, None] * (1 + 1e-12))
    u, ok = st.peak(x, st.directions(az + np.radians(1.0)))
    assert ok.all()
    assert np.max(np.abs(np.degrees(np.arcsin(u[:, 0]) - az))) < 1e-8
    assert np.max(np.abs(np.degrees(st.search(x) - az))) < 1e-5
    # the processing wrappers are the same model
    assert np.array_equal(angle_spectrum(x, rut, scene.radar, az), st.power(x, st.directions(az)))
    assert np.array_equal(estimate_angles(x, rut, scene.radar), st.search(x))
    assert np.array_equal(refine_angles(x, rut, scene.radar, az + np.radians(1.0)),
                          np.arcsin(u[:, 0]))


def test_taper_follows_the_window_over_sorted_positions():
    for window in WINDOWS:
        scene = make_scene(angle_window=window)
        st = Steering.build(build_setup(scene).rut, scene.radar)
        order = np.argsort(st.positions_m[:, 0])
        w = st.taper[order]
        assert np.allclose(w, w[::-1])  # symmetric windows
        assert (window == "none") == np.allclose(w, 1.0)


@pytest.mark.parametrize("elevation_deg", [-20.0, 0.0, 15.0])
def test_two_dimensional_peak_on_the_radar_with_elevation(elevation_deg):
    """D = 2 (azimuth + elevation over all virtual elements): Newton in two dimensions finds
    plane waves over a grid of azimuths at the given elevation."""
    scene = make_scene(use_elevation_tx=True)
    rut = build_setup(scene).rut
    st = Steering.build(rut, scene.radar, elevation=True)
    assert st.dims == 2 and st.size == rut.num_virtual
    ang = np.stack(np.broadcast_arrays(np.radians(np.linspace(-50, 50, 11)),
                                       np.radians(elevation_deg)), axis=-1)
    u_src = st.directions(ang)
    x = plane_wave(st, u_src, rut.num_virtual)
    u, ok = st.peak(x, u_src + 0.01)
    assert ok.all()
    assert np.max(np.abs(u - u_src)) < 1e-9


def test_custom_planar_array_is_only_other_positions():
    """A 4 x 4 uniform planar array at lambda/2 with a Hann taper: the same model, the same
    closed forms (peak at the source, power (sum w)^2)."""
    lam = 3.9e-3
    gx, gz = np.meshgrid(np.arange(4) * lam / 2, np.arange(4) * lam / 2, indexing="ij")
    pos = np.stack([gx.ravel(), gz.ravel()], axis=-1)
    hann = np.hanning(6)[1:-1]
    st = Steering(np.ones(16, bool), pos, np.outer(hann, hann).ravel(), lam,
                  np.array([4, 4]) * lam / 2)
    rng = np.random.default_rng(3)
    r = np.sqrt(rng.uniform(0, 0.7 ** 2, 40))
    phi = rng.uniform(0, 2 * np.pi, 40)
    u_src = np.stack([r * np.cos(phi), r * np.sin(phi)], axis=-1)
    x = plane_wave(st, u_src, 16)
    assert np.allclose(np.einsum("nn->n", st.power(x, u_src)), np.sum(st.taper) ** 2)
    u, ok = st.peak(x, np.clip(u_src + rng.normal(0, 0.02, u_src.shape), -0.99, 0.99))
    assert ok.all()
    assert np.max(np.abs(u - u_src)) < 1e-9


@pytest.fixture(scope="module", params=WINDOWS)
def windowed(request):
    scene = make_scene(angle_window=request.param)
    setup = build_setup(scene)
    tol = ChannelPhasors.build(setup, (0, 1), points=3)
    pm = ChannelModel.build(tol.setup, exact_paths(tol.setup), (0, 1), TargetConfig(tol.range_m))
    return tol, pm


def test_tolerance_and_channel_model_share_the_coherent_phase(windowed):
    """The phase the tolerance study calibrates to and the one the channel model (ChannelModel,
    used by the calibration and the exact mode) designs for are the same for every angle
    window (only the tolerance model used to apply the taper: 0.030 deg apart with hamming on
    the default scene)."""
    tol, pm = windowed
    a = float(tol.procedure.coherence_phase(tol, tol.x_nominal))
    b = float(pm.pair_phase(tol.procedure.probe_rad))
    assert abs(np.degrees(np.angle(np.exp(1j * (a - b))))) < 1e-9


def test_coherent_phase_maximises_the_radars_own_beam(windowed):
    """At a single probe the coherent phase maximises the power that the RuT's processing
    (``angle_spectrum``, with its taper) sees of the two channels' sum: 1e-4 rad either side
    has less."""
    tol, pm = windowed
    rut, radar = pm.setup.rut, pm.setup.scene.radar
    x = tol.x_nominal
    for probe in tol.procedure.probe_rad:
        phi = float(pm.pair_phase(np.array([probe])))
        p = [angle_spectrum(x[0] + np.exp(1j * (phi + d)) * x[1], rut, radar,
                            np.array([probe]))[0] for d in (-1e-4, 0.0, 1e-4)]
        assert p[1] > p[0] and p[1] > p[2]


def build_setup_of(scene):
    from rtsgeom.geometry import build_setup
    return build_setup(scene)



@pytest.mark.parametrize("preset", ["awr1843boost", "iwr6843isk", "awr2944"])
@pytest.mark.parametrize("window", ["none", "hann", "hamming", "blackman"])
def test_2d_search_is_independent_of_the_targets_phase(preset, window):
    """A target's echo carries an arbitrary phase (range, RCS): multiplying a plane wave's
    snapshot by e^{j phi} must not move the 2-D beamformer peak, for every taper and array:
    the same (azimuth, elevation) for phases all around the circle, at the plane wave's
    direction."""
    from rtsgeom.radar.steering import Steering
    from rtsgeom.scene import load_scene
    sc = load_scene("scenes/diewald2022.toml")
    radar = sc.radar.evolve(antenna_preset=preset, use_elevation_tx=True, angle_window=window,
                            elevation_processing=True)
    rut = build_setup_of(sc.evolve(radar=radar, targets=())).rut
    st = Steering.auto(rut, radar)
    assert st.dims == 2
    rng = np.random.default_rng(11)
    ae = np.radians(np.column_stack([rng.uniform(-40, 40, 12), rng.uniform(-20, 20, 12)]))
    x = np.zeros((ae.shape[0], rut.num_virtual), complex)
    x[:, st.mask] = np.exp(-1j * (st.wavevector @ st.directions(ae).T)).T
    for phi in np.linspace(0, 2 * np.pi, 7, endpoint=False):
        got = st.search(x * np.exp(1j * (phi + rng.uniform(0, 0.2))))
        assert np.degrees(np.abs(got - ae)).max() < 1e-6


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


def test_steering_search_in_two_dimensions_returns_azimuth_and_elevation():
    """The D = 2 grid search returns (az, el) per snapshot: a plane wave from
    (5, 3) deg is found there (tests/radar/test_elevation.py checks a grid of directions)."""
    from rtsgeom.radar.steering import Steering
    s = make_scene(use_elevation_tx=True)
    rut = build_setup(s).rut
    st = Steering.build(rut, s.radar, elevation=True)
    ae = np.radians([[5.0, 3.0]])
    x = np.zeros((1, rut.num_virtual), complex)
    x[:, st.mask] = np.exp(-1j * (st.wavevector @ st.directions(ae).T)).T
    got = st.search(x)
    assert got.shape == (1, 2)
    np.testing.assert_allclose(np.degrees(got), [[5.0, 3.0]], atol=1e-6)


#: evolutions of the scene's radar that change its beamformer: the wavelength, the array
#: (the elevation Tx's virtual elements, the element spacing) and the taper
RADAR_CHANGES = [{"f_c_hz": 78e9}, {"use_elevation_tx": True}, {"element_spacing_m": 2.1e-3},
                 {"angle_window": "blackman"}]


@pytest.mark.parametrize("change", RADAR_CHANGES)
def test_the_kept_beamformer_follows_an_evolved_radar(change):
    """``Steering.build`` keeps its last beamformers per RuT and radar object; after
    ``Scene.evolve`` of the radar or its array the beamformer is the evolved one's (as built
    afresh), never the one kept for the scene before, which stays what it was."""
    scene = make_scene()
    rut = build_setup(scene).rut
    before = Steering.build(rut, scene.radar)
    assert Steering.build(rut, scene.radar) is before  # kept: the cache is in use
    evolved = scene.evolve(radar=scene.radar.evolve(**change))
    rut2 = build_setup(evolved).rut
    after = Steering.build(rut2, evolved.radar)
    fresh = Steering._build(rut2, evolved.radar, False)
    fields = ("mask", "positions_m", "taper", "aperture_m", "wavelength_m", "pitch_m")
    for name in fields:
        np.testing.assert_array_equal(getattr(after, name), getattr(fresh, name), name)
    assert not all(np.array_equal(getattr(after, n), getattr(before, n)) for n in fields)
    assert Steering.build(rut, scene.radar) is before
    # one object new, the other kept: still the pair's own beamformer
    for r, radar in ((rut, evolved.radar), (rut2, scene.radar)):
        got, own = Steering.build(r, radar), Steering._build(r, radar, False)
        for name in fields:
            np.testing.assert_array_equal(getattr(got, name), getattr(own, name), name)


def test_the_beamformers_memo_past_its_size_keeps_the_last_and_builds_the_same(monkeypatch):
    """More (rut, radar) objects than the memo holds: it keeps at most ``_BUILT_MAX`` entries
    (the oldest dropped first), the last one built is found again (the same object), and every
    beamformer equals one built afresh."""
    import dataclasses

    from rtsgeom.radar import steering as st
    monkeypatch.setattr(st, "_BUILT", {})
    monkeypatch.setattr(st, "_BUILT_MAX", 3)
    scene = make_scene()
    rut = build_setup(scene).rut
    radars = [dataclasses.replace(scene.radar) for _ in range(5)]  # equal, not the same
    built = []
    for radar in radars:
        for elevation in (False, True):
            built.append(Steering.build(rut, radar, elevation))
            assert len(st._BUILT) <= 3
            assert Steering.build(rut, radar, elevation) is built[-1]
    assert list(st._BUILT) == [(id(rut), id(radars[-2]), True), (id(rut), id(radars[-1]), False),
                               (id(rut), id(radars[-1]), True)]
    for k, s in enumerate(built):
        fresh = Steering._build(rut, radars[k // 2], bool(k % 2))
        for f in dataclasses.fields(Steering):
            a, b = getattr(s, f.name), getattr(fresh, f.name)
            assert np.array_equal(a, b) if isinstance(a, np.ndarray) else a == b, f.name
    assert Steering.build(rut, radars[0], False) is not built[0]  # dropped, built again
