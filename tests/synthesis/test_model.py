"""The channel model's refusals word for word: modes, a ratio of more than a pair, the paper's
closed form on a cell, set angles outside the span a pair or a closed form reaches (the
span's numbers the setup's), an RTS that does not subtract the air path."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import assert_refused
from rtsgeom.errors import AngleUnreachable, ParameterError, SceneError
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.scene import TargetConfig
from rtsgeom.synthesis.model import ChannelModel, require_air_path_compensation


@pytest.fixture(scope="module")
def pair(default_scene):
    setup = build_setup(default_scene)
    return setup, ChannelModel.build(setup, exact_paths(setup), (0, 1), TargetConfig(20.0))


@pytest.mark.parametrize("mode", ["paper", "array-factor"])
def test_a_closed_form_addresses_the_geometric_span_ends_included(pair, mode):
    setup, cm = pair
    lo, hi = np.sort(setup.fe_azimuth_rad()[[0, 1]])
    for a in (lo, hi, 0.5 * (lo + hi)):
        assert np.isfinite(cm.pair_ratio(a, mode=mode))
    for a in (hi + 1e-3, lo - 1e-3):
        assert_refused(lambda: cm.pair_ratio(a, mode=mode), (
            f"angle {np.degrees(a):.4f} deg is outside the span the {mode} closed form can "
            f"address: the front ends' geometric angles [{np.degrees(lo):.4f}, "
            f"{np.degrees(hi):.4f}] deg (use the exact mode for the measured span)"),
            AngleUnreachable)


def test_the_exact_mode_names_the_span_the_pair_reaches(pair):
    setup, cm = pair
    a = setup.fe_azimuth_rad()[1] + 0.05
    with pytest.raises(AngleUnreachable) as exc:
        cm.pair_ratio(a, mode="exact")
    got = str(exc.value)
    # the span: the detected angle of either channel nearly alone (ratio e^-12, e^12)
    ends = [float(cm.direction(cm.pair_weights(np.exp(s * 12.0), None))) for s in (-1, 1)]
    assert got == (f"angle {np.degrees(a):.4f} deg is outside the span this front-end pair "
                   f"can synthesize [{np.degrees(min(ends)):.4f}, "
                   f"{np.degrees(max(ends)):.4f}] deg")
    head = (f"angle {np.degrees(a):.4f} deg is outside the span this front-end pair can "
            "synthesize [")
    assert got.startswith(head) and got.endswith("] deg")
    lo, hi = (float(x) for x in got[len(head):-len("] deg")].split(", "))
    # the measured span: the detected angles of each front end alone, near the geometric ones
    geo = np.degrees(np.sort(setup.fe_azimuth_rad()[[0, 1]]))
    assert abs(lo - geo[0]) < 1.0 and abs(hi - geo[1]) < 1.0 and lo < hi < np.degrees(a)


def test_modes_and_channel_counts_are_refused_by_name(pair, crossing_bench):
    _, cm = pair
    for call in (lambda: cm.pair_ratio(0.1, mode="x"), lambda: cm.solve(0.1, mode="x")):
        assert_refused(call, "mode 'x': must be one of exact, array-factor, paper")
    setup = build_setup(crossing_bench)
    three = ChannelModel.build(setup, exact_paths(setup), (0, 1, 2), TargetConfig(20.0))
    assert_refused(lambda: three.pair_ratio(0.0), "pair_ratio: 3 channels; a ratio needs a pair")
    assert_refused(lambda: three.solve(np.array([0.0]), mode="paper"),
                   "mode 'paper': eq. 23 is defined for a pair of front ends in azimuth only; "
                   "use exact or array-factor")


def test_an_rts_that_does_not_subtract_the_air_path_is_refused(default_scene):
    require_air_path_compensation(default_scene)
    bare = default_scene.evolve(rts=default_scene.rts.evolve(compensate_air_path=False))
    assert_refused(lambda: require_air_path_compensation(bare), (
        "rts.compensate_air_path = false: the AoA synthesis, its calibration and the studies "
        "built on them (calibrate, run and adc with synthesized amplitudes, tolerance, design, "
        "nearfield, linearity) assume the RTS subtracts the air path, so that each echo lies at "
        "its set range's bin; without it the echoes lie about R_c = 1 m further, which they do "
        "not model yet: set it to true, or run the plain program (run --amplitudes nearest)"),
        SceneError)


@pytest.mark.parametrize("seed", [0, 1])
def test_drawn_mounting_rotations_move_both_air_legs_as_the_setup_built_with_them(seed):
    """``air_legs`` with drawn offsets, yaws and pitches of the front ends (added to the
    scene's own) = the exact paths of ``build_setup`` with those offsets and rotations, on
    both legs (RuT Tx -> FE Rx, FE Tx -> RuT Rx), and each drawn rotation alone moves them."""
    from conftest import ROOT
    from rtsgeom.paths.table import FE_TO_RX, TX_TO_FE
    from rtsgeom.scene import loads_scene
    # the Rx off the module's centre in azimuth and in height: a yaw and a pitch both move it
    text = (ROOT / "scenes" / "custom-array.toml").read_text()
    scene = loads_scene(text.replace("rx_offset_mm = [-15.0, 0.0]", "rx_offset_mm = [-15.0, 6.0]"),
                        "x.toml")
    setup = build_setup(scene)
    n = setup.fe.count
    model = ChannelModel.build(setup, exact_paths(setup), tuple(range(n)), TargetConfig(12.0))
    rng = np.random.default_rng(seed)
    off = rng.normal(0, 3e-4, (n, 3))
    yaw, pitch = rng.normal(0, 0.02, n), rng.normal(0, 0.02, n)
    t_a, t_b = model.air_legs(off, yaw_rad=yaw, pitch_rad=pitch)
    own = [np.zeros(n) if a is None else a for a in (setup.fe.yaw_rad, setup.fe.pitch_rad)]
    assert np.any(own[0] != 0)  # the scene's own yaw (2 deg), which the draw adds to
    moved = build_setup(scene, offsets_m=off, yaw_rad=own[0] + yaw, pitch_rad=own[1] + pitch)
    p = exact_paths(moved)
    rut = setup.rut
    want_a = p.delay_s[p.direction == TX_TO_FE].reshape(n, -1)[:, rut.virtual_tx]
    want_b = p.delay_s[p.direction == FE_TO_RX].reshape(n, -1)[:, rut.virtual_rx]
    np.testing.assert_allclose(t_a, want_a, rtol=0, atol=1e-18)
    np.testing.assert_allclose(t_b, want_b, rtol=0, atol=1e-18)
    for drawn in ({"yaw_rad": yaw}, {"pitch_rad": pitch}):  # each rotation alone counts
        a, b = model.air_legs(off, **drawn)
        plain_a, plain_b = model.air_legs(off)
        assert np.max(np.abs(a - plain_a)) + np.max(np.abs(b - plain_b)) > 1e-15


@pytest.fixture(scope="module")
def sphere_model(sphere_scene):
    setup = build_setup(sphere_scene)
    assert setup.fe.elevation_rad is not None and np.ptp(setup.fe.elevation_rad) > 0.1
    return setup, ChannelModel.build(setup, exact_paths(setup), tuple(range(setup.fe.count)),
                                     TargetConfig(12.0))


@pytest.mark.parametrize("scale_m", [0.0, 2e-3])
def test_air_legs_on_a_sphere_are_the_distances_to_the_elevated_front_ends(sphere_model,
                                                                             scale_m):
    """Front ends on a sphere (scenes/sphere4.toml, +-5 deg elevation): ``air_legs`` with
    mounting offsets = |FE Rx - RuT Tx| / c0 and |FE Tx - RuT Rx| / c0 per virtual element,
    the FE positions ``build_setup``'s with those offsets (its elevated antennas), and the
    channels taken in any order."""
    from scipy.constants import c
    setup, model = sphere_model
    n, rut = setup.fe.count, setup.rut
    off = np.random.default_rng(7).normal(0, scale_m, (n, 3)) if scale_m else np.zeros((n, 3))
    moved = build_setup(setup.scene, offsets_m=off) if scale_m else setup
    t_a, t_b = model.air_legs(off)
    want_a = np.linalg.norm(moved.fe.rx[:, None] - rut.tx_world[None], axis=-1) / c
    want_b = np.linalg.norm(moved.fe.tx[:, None] - rut.rx_world[None], axis=-1) / c
    np.testing.assert_allclose(t_a, want_a[:, rut.virtual_tx], rtol=1e-13, atol=0)
    np.testing.assert_allclose(t_b, want_b[:, rut.virtual_rx], rtol=1e-13, atol=0)
    # the elevation lifts the antennas well off the arc's plane (what a flat arc would give)
    flat_z = np.abs(moved.fe.rx[:, 2] - setup.fe.arc_centre[2])
    assert np.all(flat_z > 0.05 * setup.fe.arc_radius_m)
    # a reordered channel tuple gives the same legs, reordered
    rev = ChannelModel.build(setup, exact_paths(setup), tuple(reversed(range(n))),
                             TargetConfig(12.0))
    r_a, r_b = rev.air_legs(off[::-1])
    np.testing.assert_allclose(r_a, t_a[::-1], rtol=1e-13, atol=0)
    np.testing.assert_allclose(r_b, t_b[::-1], rtol=1e-13, atol=0)


def test_direction_cosines_without_a_start_are_the_searched_angles(pair, sphere_model):
    """``direction_cosines(w)`` (no ``u0``): D = 1, (..., 1) = sin of the searched azimuth;
    D = 2 (scenes/sphere4.toml), (..., 2) = (sin az cos el, sin el) of the searched
    (az, el), over a batch of weights."""
    _, cm = pair
    w = cm.pair_weights(np.array([[0.5, 1.0, 2.0], [0.8, 1.3, 0.3]]))
    u = cm.direction_cosines(w)
    assert cm.dims == 1 and u.shape == (2, 3, 1)
    np.testing.assert_array_equal(u[..., 0], np.sin(cm.direction(w)))
    from rtsgeom.radar.steering import Steering
    setup, flat = sphere_model
    steer = Steering.auto(setup.rut, setup.scene.radar)
    sm = ChannelModel.build(setup, exact_paths(setup), flat.channels, TargetConfig(12.0),
                            steering=steer)
    rng = np.random.default_rng(5)
    w2 = sm.weights(rng.uniform(0.3, 1.0, (3, sm.count)))
    u2 = sm.direction_cosines(w2)
    assert sm.dims == 2 and u2.shape == (3, 2)
    az, el = np.moveaxis(sm.direction(w2), -1, 0)
    np.testing.assert_allclose(u2, np.stack([np.sin(az) * np.cos(el), np.sin(el)], -1),
                               rtol=0, atol=1e-15)
    assert np.ptp(u2[:, 1]) > 1e-4  # the batch's elevations differ: not a constant read
