"""RuT arrays: presets against their documented layouts, custom sparse/non-uniform arrays,
duplicate virtual positions, aperture, resolution and grating lobes."""

from __future__ import annotations

import dataclasses
import itertools

import numpy as np
import pytest
from conftest import make_scene
from scipy.constants import c

from rtsgeom.geometry import build_setup
from rtsgeom.geometry.arrays import (
    ArraySpec,
    array_from_spec,
    array_spec,
    awr1843boost_layout,
    posed_positions,
    rut_array,
)
from rtsgeom.geometry.farfield import (
    angular_resolution_rad,
    aperture_m,
    array_factor,
    coarray_period_m,
    fraunhofer_distance_m,
    grating_lobe_directions_rad,
    smallest_spacing_m,
    unambiguous_half_width_rad,
)
from rtsgeom.radar.processing import estimate_angles
from rtsgeom.scene.presets import PRESETS, preset

LAM = c / 77e9
D = LAM / 2


def _build(spec, lam=LAM):
    return array_from_spec(spec, lam)


def _units(rut):
    return rut.azimuth_positions_m / rut.spacing_m


# ------------------------------------------------------------------------------------------
# Presets against their documents
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", list(PRESETS))
@pytest.mark.parametrize("elev", [False, True])
def test_preset_virtual_array_is_documented_filled_grid(name, elev):
    p = PRESETS[name]
    rut = _build(p.spec(D, elev))
    order = p.tx_order_elevation if elev else p.tx_order
    assert rut.num_virtual == len(order) * p.rx_units.shape[0]
    # distinct azimuth positions: the documented count, consecutive multiples of d
    assert rut.num_azimuth_unique == p.num_azimuth_unique
    u = _units(rut)
    assert np.allclose(u - u[0], np.arange(u.size), atol=1e-9)
    assert aperture_m(rut) == pytest.approx(p.num_azimuth_unique * D, rel=1e-12)
    assert angular_resolution_rad(rut) == pytest.approx(1.22 * LAM / (p.num_azimuth_unique * D))
    assert fraunhofer_distance_m(rut) == pytest.approx(2 * (p.num_azimuth_unique * D) ** 2 / LAM)
    # a lambda/2 grid: period d, no grating lobe anywhere in the visible region
    assert coarray_period_m(rut) == pytest.approx(D, rel=1e-9)
    for steer in np.radians([-60, -20, 0, 35, 70]):
        assert grating_lobe_directions_rad(rut, steer).size == 0
    assert unambiguous_half_width_rad(rut) == pytest.approx(np.pi / 2)
    # the phase centre is the mean of the azimuth virtual elements
    assert np.allclose(rut.virtual_local[rut.azimuth_mask].mean(axis=0), 0.0, atol=1e-15)


def test_awr1843boost_documented_positions():
    tx, rx = PRESETS["awr1843boost"].positions_m(D)
    # TX1-TX3 2 lambda apart in azimuth, TX2 lambda/2 up and lambda right of TX1, Rx at lambda/2
    assert tx[2, 0] - tx[0, 0] == pytest.approx(2 * LAM)
    assert tx[1] - tx[0] == pytest.approx([LAM, LAM / 2])
    assert np.allclose(np.diff(rx[:, 0]), LAM / 2) and np.allclose(rx[:, 1], 0)
    assert rx[0, 0] - tx[:, 0].max() == pytest.approx(3 * LAM)  # the (assumed) board gap
    # the elevated row: 4 virtual elements lambda/2 up, at azimuth units 2..5 of the 8
    rut = _build(PRESETS["awr1843boost"].spec(D, True))
    el = rut.virtual_local[~rut.azimuth_mask]
    assert np.allclose(el[:, 2], D)
    x0 = rut.azimuth_positions_m[0]
    assert np.allclose(np.sort((el[:, 0] - x0) / D), [2, 3, 4, 5])


def test_cascade_86_positions_from_144_azimuth_elements_and_elevation_rows():
    p = preset("awr2243-cascade")
    tx, rx = p.positions_m(D)
    az_tx = tx[list(p.tx_order)]
    assert np.allclose(np.diff(np.sort(az_tx[:, 0])), 2 * LAM)  # azimuth Tx 2 lambda apart
    assert np.allclose(az_tx[:, 1], 0) and np.allclose(rx[:, 1], 0)
    rut = _build(p.spec(D, True))
    assert rut.num_virtual == 192 and np.count_nonzero(rut.azimuth_mask) == 144
    assert rut.num_azimuth_unique == 86
    # brute force: distinct (tx + rx) sums of the azimuth Tx and all Rx
    sums = {round((a + b) / D) for a in az_tx[:, 0] for b in rx[:, 0]}
    assert len(sums) == 86 and sums == set(range(86))
    # multiplicity: 144 elements on 86 positions
    counts = np.bincount(rut.virtual_unique[rut.azimuth_mask])
    assert counts[counts > 0].sum() == 144 and np.count_nonzero(counts) == 86
    # elevation: the master's three Tx at 1, 4 and 6 x lambda/2 over the azimuth row
    z = np.unique(np.round(rut.virtual_local[:, 2] / D, 9))
    assert np.allclose(z, [0, 1, 4, 6])
    assert p.board_gap_units is None
    with pytest.raises(ValueError, match="board_gap"):
        p.positions_m(D, board_gap_m=0.01)


def test_default_scene_is_the_awr1843_preset_spec():
    scene = make_scene()
    rut = rut_array(scene.radar)
    d = c / scene.radar.f_center_hz / 2
    tx, rx = awr1843boost_layout(d)
    assert np.array_equal(rut.tx_local - rut.tx_local[0], tx - tx[0])
    assert np.array_equal(rut.rx_local - rut.tx_local[0], rx - tx[0])
    assert rut.name == "awr1843boost" and rut.spacing_m == d


@pytest.mark.parametrize("gap_lam", [0.0, 1.0, 3.0, 7.5])
def test_board_gap_moves_the_groups_not_the_virtual_array(gap_lam):
    ref = _build(PRESETS["awr1843boost"].spec(D, board_gap_m=3 * LAM))
    rut = _build(PRESETS["awr1843boost"].spec(D, board_gap_m=gap_lam * LAM))
    assert np.allclose(rut.virtual_local, ref.virtual_local, atol=1e-15)
    sep = rut.rx_local[:, 0].mean() - rut.tx_local[rut.tx_order, 0].mean()
    assert sep == pytest.approx(ref.rx_local[:, 0].mean() - ref.tx_local[ref.tx_order, 0].mean()
                                + (gap_lam - 3) * LAM)


def test_array_spec_from_radar_fields():
    scene = make_scene()
    radar = dataclasses.replace(scene.radar, antenna_preset="awr2944", use_elevation_tx=True)
    spec = array_spec(radar)
    assert spec.name == "awr2944" and spec.tx_order == (0, 1, 2, 3)
    custom = ArraySpec.from_mm([[0, 0], [5, 0]], [[0, 0], [2, 0]], [1, 0])
    assert array_spec(radar, array=custom) is custom
    cfg = dataclasses.make_dataclass("Cfg", ["tx_mm", "rx_mm", "tx_order"])(
        [[0, 0], [5, 0]], [[0, 0], [2, 0]], [1, 0])
    got = array_spec(dataclasses.replace(radar), array=cfg)
    assert np.array_equal(got.tx_m, custom.tx_m) and got.tx_order == (1, 0)
    with pytest.raises(ValueError, match="antenna_preset"):
        array_spec(dataclasses.replace(scene.radar, antenna_preset="nope"))


# ------------------------------------------------------------------------------------------
# Custom arrays: sparse, non-uniform, duplicates
# ------------------------------------------------------------------------------------------


def _random_specs(n=12, seed=3):
    rng = np.random.default_rng(seed)
    for _ in range(n):
        n_tx, n_rx = rng.integers(1, 5), rng.integers(1, 6)
        tx = rng.choice(12, n_tx, replace=False) * D
        rx = rng.choice(9, n_rx, replace=False) * D
        tz = rng.choice([0.0, 0.0, D], n_tx)
        yield ArraySpec(np.c_[tx, tz], np.c_[rx, np.zeros(n_rx)],
                        tuple(rng.permutation(n_tx)))


@pytest.mark.parametrize("spec", list(_random_specs()))
def test_custom_virtual_positions_and_duplicates_match_brute_force(spec):
    rut = _build(spec)
    # every virtual element is (slot's Tx) + (Rx), all pairs present
    want = {(t, r) for t in spec.tx_order for r in range(spec.num_rx)}
    assert set(zip(rut.virtual_tx.tolist(), rut.virtual_rx.tolist())) == want
    # the unique map reproduces every virtual position, and distinct indices are distinct places
    assert np.allclose(rut.unique_local[rut.virtual_unique], rut.virtual_local, atol=1e-12)
    keys = {tuple(np.round(p[[0, 2]] / D, 6)) for p in rut.virtual_local}
    assert len(keys) == rut.unique_local.shape[0]
    # the azimuth row is the fullest virtual row
    zs = np.round(rut.virtual_local[:, 2] / D, 6)
    vals, counts = np.unique(zs, return_counts=True)
    assert np.count_nonzero(rut.azimuth_mask) == counts.max()
    # aperture: span of distinct azimuth positions plus one grid cell
    x = rut.azimuth_positions_m
    assert aperture_m(rut) == pytest.approx(np.ptp(x) + rut.spacing_m, rel=1e-9)
    assert rut.spacing_m == pytest.approx(smallest_spacing_m(rut) if x.size > 1 else LAM / 2)


def test_custom_mm_layout_3tx_4rx_nonuniform_beamformer_finds_the_angle():
    # 3 Tx x 4 Rx, non-uniform: Rx at 0, 1, 3, 4 lambda/2 (mm at 77 GHz), Tx 5 lambda/2 apart,
    # one elevated; the beamformer steers on the actual virtual positions.
    dmm = D * 1e3
    spec = ArraySpec.from_mm([[0, 0], [5 * dmm, 0], [10 * dmm, 0.5 * dmm]],
                             [[20 * dmm, 0], [21 * dmm, 0], [23 * dmm, 0], [24 * dmm, 0]],
                             [0, 1, 2])
    scene = make_scene()
    radar = scene.radar
    rut = array_from_spec(spec, c / radar.f_center_hz)
    assert rut.num_virtual == 12 and np.count_nonzero(rut.azimuth_mask) == 8
    assert np.allclose(_units(rut) - _units(rut)[0], [0, 1, 3, 4, 5, 6, 8, 9], atol=1e-6)
    k = 2 * np.pi / rut.wavelength_m
    for deg in (-40.0, -7.3, 0.0, 12.5, 33.0):
        th = np.radians(deg)
        snap = np.exp(-1j * k * rut.virtual_local[:, 0] * np.sin(th))
        assert np.degrees(estimate_angles(snap, rut, radar)) == pytest.approx(deg, abs=1e-4)


def test_cascade_beamformer_combines_duplicates():
    scene = make_scene()
    radar = scene.radar
    rut = array_from_spec(preset("awr2243-cascade").spec(c / radar.f_center_hz / 2),
                          c / radar.f_center_hz)
    k = 2 * np.pi / rut.wavelength_m
    for deg in (-50.0, -1.1, 0.0, 0.7, 25.0):
        snap = np.exp(-1j * k * rut.virtual_local[:, 0] * np.sin(np.radians(deg)))
        assert np.degrees(estimate_angles(snap, rut, radar)) == pytest.approx(deg, abs=1e-4)


# ------------------------------------------------------------------------------------------
# Resolution and grating lobes against the array factor
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", list(PRESETS))
def test_resolution_tracks_the_array_factor_main_lobe(name):
    rut = _build(PRESETS[name].spec(D))
    u = np.linspace(0, 0.5, 200001)
    af = array_factor(rut, u)
    half = u[np.argmax(af < np.sqrt(0.5))]  # half-power point of the main lobe
    hpbw = 2 * half
    # uniform ULA: HPBW = 0.886 lambda / d_A; the cascade's overlaps taper it (wider); both are
    # of the order of the 1.22 lambda / d_A resolution
    ratio = hpbw * aperture_m(rut) / LAM
    assert 0.85 < ratio < 1.22
    if name != "awr2243-cascade":
        assert ratio == pytest.approx(0.886, abs=0.01)


@pytest.mark.parametrize("step_units,steer_deg",
                         list(itertools.product([2, 3, 4], [0.0, 10.0, -25.0])))
def test_grating_lobes_of_sparse_arrays_are_where_the_array_factor_repeats(step_units, steer_deg):
    # Rx every step * lambda/2, one Tx: a sparse ULA with period step * d
    spec = ArraySpec(np.array([[0.0, 0.0]]), np.c_[np.arange(5) * step_units * D, np.zeros(5)],
                     (0,))
    rut = _build(spec)
    g = coarray_period_m(rut)
    assert g == pytest.approx(step_units * D, rel=1e-9)
    steer = np.radians(steer_deg)
    lobes = grating_lobe_directions_rad(rut, steer)
    expect = [np.sin(steer) + m * LAM / g for m in range(-8, 9) if m != 0]
    expect = np.sort([np.clip(e, -1, 1) for e in expect if abs(e) <= 1 + 1e-9])
    assert np.allclose(np.sin(lobes), expect)
    assert lobes.size >= 1
    assert np.allclose(array_factor(rut, np.sin(lobes), np.sin(steer)), 1.0, atol=1e-9)
    # between main lobe and grating lobes the array factor is below its peak
    mid = np.sin(steer) + np.array([-0.5, 0.5]) * LAM / g  # half-way to the nearest lobes
    assert np.all(array_factor(rut, mid, np.sin(steer)) < 0.5)
    assert unambiguous_half_width_rad(rut) == pytest.approx(np.arcsin(min(1, LAM / (2 * g))))


def test_nonuniform_minimum_redundancy_has_period_d_and_no_grating_lobe():
    # positions 0, 1, 4, 6 (x d): gaps 1, 3, 2 -> period d, no grating lobe, aperture 7 d
    spec = ArraySpec(np.array([[0.0, 0.0]]), np.c_[np.array([0, 1, 4, 6]) * D, np.zeros(4)],
                     (0,))
    rut = _build(spec)
    assert coarray_period_m(rut) == pytest.approx(D)
    assert grating_lobe_directions_rad(rut).size == 0
    assert aperture_m(rut) == pytest.approx(7 * D)
    # incommensurate positions: no exact period
    spec2 = ArraySpec(np.array([[0.0, 0.0]]), np.c_[np.array([0, 1, np.sqrt(2) * 3]) * D,
                                                     np.zeros(3)], (0,))
    assert coarray_period_m(_build(spec2)) is None
    assert grating_lobe_directions_rad(_build(spec2)).size == 0


# ------------------------------------------------------------------------------------------
# Pose errors and bad input
# ------------------------------------------------------------------------------------------


def test_pose_errors_broadcast_and_match_a_posed_array():
    scene = make_scene()
    rut = rut_array(scene.radar)
    tx0, rx0 = posed_positions(rut)
    assert np.allclose(tx0, rut.tx_world) and np.allclose(rx0, rut.rx_world)
    rng = np.random.default_rng(0)
    off = rng.normal(0, 1e-3, (7, 3))
    yaw = rng.normal(0, 0.02, 7)
    tx, rx = posed_positions(rut, off, yaw)
    assert tx.shape == (7, 3, 3) and rx.shape == (7, 4, 3)
    for i in range(7):
        one = rut_array(scene.radar, position_offset_m=off[i], yaw_offset_rad=yaw[i])
        assert np.allclose(tx[i], one.tx_world, atol=1e-15)
        assert np.allclose(rx[i], one.rx_world, atol=1e-15)
        # rigid: distances to the (moved) phase centre kept
        assert np.allclose(np.linalg.norm(rx[i] - one.position, axis=1),
                           np.linalg.norm(rut.rx_world - rut.position, axis=1))


@pytest.mark.parametrize("kwargs,field", [
    ({"tx_m": [[0, 0, 0]], "rx_m": [[0, 0]], "tx_order": (0,)}, "array.tx_m"),
    ({"tx_m": [[0, 0]], "rx_m": [[0, 0], [0, 0]], "tx_order": (0,)}, "array.rx_m"),
    ({"tx_m": [[0, 0]], "rx_m": [[0, 0]], "tx_order": (1,)}, "array.tx_order"),
    ({"tx_m": [[0, 0], [1e-3, 0]], "rx_m": [[0, 0]], "tx_order": (0, 0)}, "array.tx_order"),
    ({"tx_m": [[np.nan, 0]], "rx_m": [[0, 0]], "tx_order": (0,)}, "array.tx_m"),
    ({"tx_m": [[0, 0]], "rx_m": [[0, 0]], "tx_order": (0,), "spacing_m": -1.0}, "array.spacing_m"),
])
def test_bad_array_specs_name_the_field(kwargs, field):
    with pytest.raises(ValueError, match=field.replace(".", r"\.")):
        ArraySpec(**kwargs)


def test_the_preset_list_and_info_say_how_many_tx_transmit():
    """The awr2944 is a 4 Tx x 4 Rx board with 12 virtual elements: its elevated Tx is off
    unless radar.use_elevation_tx (the list said "4 Tx x 4 Rx" only, info "12 virtual
    elements"; only the 3D view's "Tx3 (off)" explained it)."""
    import tomllib

    from conftest import DEFAULT_SCENE

    from rtsgeom.pipeline.info import format_info, scene_info
    from rtsgeom.scene import parse_scene
    from rtsgeom.scene.presets import PRESETS
    assert PRESETS["awr2944"].doc.startswith(
        "4 Tx x 4 Rx board: 12 virtual elements (3 Tx in TDM x 4 Rx), 16 with the 1 elevated Tx")
    assert PRESETS["awr1843boost"].doc.startswith(
        "3 Tx x 4 Rx board: 8 virtual elements (2 Tx in TDM x 4 Rx), 12 with the 1 elevated Tx")
    for elevation, line in ((False, "RuT  awr2944: 4 Tx (Tx order [0, 1, 2]; Tx 3 off: "),
                            (True, "RuT  awr2944: 4 Tx (Tx order [0, 1, 2, 3]), 4 Rx: 16 "
                                   "virtual elements (4 Tx x 4 Rx; ")):
        doc = tomllib.loads(DEFAULT_SCENE.read_text())
        doc["radar"].update(antenna_preset="awr2944", use_elevation_tx=elevation)
        doc["targets"] = doc["targets"][:1]
        info = scene_info(build_setup(parse_scene(doc, "awr2944.toml")))
        assert info["radar"]["num_tx"] == 4
        text = format_info(info)
        assert line in text, text.splitlines()[1]
        if not elevation:
            assert "4 Rx: 12 virtual elements (3 Tx x 4 Rx; 12 in azimuth)" in text



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


def test_smallest_spacing_of_a_single_position_is_infinite():
    from rtsgeom.geometry.arrays import array_from_spec
    from rtsgeom.geometry.farfield import smallest_spacing_m
    from rtsgeom.scene.presets import ArraySpec
    lam = 3.9e-3
    one = array_from_spec(ArraySpec(((0.0, 0.0),), ((0.0, 0.0),), (0,)), lam)
    assert smallest_spacing_m(one) == float("inf")
    two = array_from_spec(ArraySpec(((0.0, 0.0),), ((0.0, 0.0), (0.7 * lam, 0.0)), (0,)), lam)
    assert smallest_spacing_m(two) == pytest.approx(0.7 * lam, rel=1e-12)


# -- the array's frame, rows and aperture in closed form -----------------------------------


@pytest.mark.parametrize("yaw", [-1.0, -0.1, 0.0, 0.3, 2.5])
def test_the_yaw_turns_like_an_azimuth_and_the_frames_round_trip(yaw):
    """yaw_matrix: boresight +y to (sin yaw, cos yaw, 0), up kept, orthonormal; a point at
    azimuth a in the world is at a - yaw seen by a RuT yawed by yaw, at the same distance."""
    from rtsgeom.geometry.arrays import array_from_spec, yaw_matrix
    from rtsgeom.scene.presets import ArraySpec
    m = yaw_matrix(yaw)
    np.testing.assert_allclose(m @ [0.0, 1.0, 0.0], [np.sin(yaw), np.cos(yaw), 0.0], atol=1e-15)
    np.testing.assert_allclose(m @ [0.0, 0.0, 1.0], [0.0, 0.0, 1.0], atol=0)
    np.testing.assert_allclose(m @ m.T, np.eye(3), atol=1e-15)
    assert np.linalg.det(m) == pytest.approx(1.0)
    lam = 3.9e-3
    pos = np.array([0.2, -0.1, 0.05])
    rut = array_from_spec(ArraySpec(((0.0, 0.0),), ((0.0, 0.0), (lam / 2, 0.0)), (0,)), lam,
                          pos, yaw)
    a = np.array([-0.5, 0.0, 0.2, 0.7])
    pts = pos + 2.0 * np.stack([np.sin(a), np.cos(a), np.zeros(4)], -1)
    np.testing.assert_allclose(rut.azimuth_of(pts), np.angle(np.exp(1j * (a - yaw))),
                               atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(rut.to_local(pts), axis=-1), 2.0, rtol=1e-12)
    np.testing.assert_allclose(rut.to_local(pts) @ rut.rotation.T + pos, pts, atol=1e-12)
    # the antennas: local positions turned and moved
    np.testing.assert_allclose(rut.rx_world, rut.rx_local @ m.T + pos, atol=1e-15)
    np.testing.assert_allclose(rut.tx_world, rut.tx_local @ m.T + pos, atol=1e-15)
    assert (rut.num_rx, rut.num_virtual, rut.name) == (2, 2, "custom")


def test_the_azimuth_row_is_the_fullest_its_centre_the_phase_centre():
    """Two rows of 4 and one of 2 virtual elements: the azimuth row the fuller one nearer
    z = 0 (a tie), the origin the mean Tx-Rx midpoint of that row; aperture (N cells + 1) d
    on the grid, span + d off it."""
    from rtsgeom.geometry.arrays import array_from_spec
    from rtsgeom.scene.presets import ArraySpec
    lam, d = 3.9e-3, 1.95e-3
    rx = tuple((k * d, 0.0) for k in range(4))
    spec = ArraySpec(((0.0, 2 * d), (0.0, -d), (0.0, 5 * d)), rx, (0, 1), spacing_m=d)
    rut = array_from_spec(spec, lam)
    z = rut.virtual_local[:, 2]
    # rows at tx z + rx z: 2d (slot 0) and -d (slot 1): a tie of 4; the lower |z| wins: -d
    assert rut.azimuth_mask.tolist() == [False] * 4 + [True] * 4
    mid = 0.5 * (np.array([[0.0, 0.0, -d]] * 4) + np.array([[k * d, 0, 0] for k in range(4)]))
    centre = mid.mean(0)
    np.testing.assert_allclose(rut.tx_local, np.array([[0, 0, 2 * d], [0, 0, -d], [0, 0, 5 * d]])
                               - centre, atol=1e-15)
    np.testing.assert_allclose(z[rut.azimuth_mask], 0.0, atol=1e-15)  # the phase centre's row
    np.testing.assert_allclose(z[~rut.azimuth_mask], 3 * d, atol=1e-15)
    assert rut.aperture_m == pytest.approx(4 * d, rel=1e-12)
    np.testing.assert_allclose(rut.azimuth_positions_m, np.arange(4) * d - 1.5 * d, atol=1e-15)
    off_grid = array_from_spec(ArraySpec(((0.0, 0.0),), ((0.0, 0.0), (0.75 * d, 0.0),
                                                         (2.0 * d, 0.0)), (0,), spacing_m=d),
                               lam)
    assert off_grid.aperture_m == pytest.approx(2.0 * d + d, rel=1e-12)
    odd = array_from_spec(ArraySpec(((0.0, 0.0),), ((0.0, 0.0), (1.3 * d, 0.0)), (0,),
                                    spacing_m=d), lam)
    assert odd.aperture_m == pytest.approx(1.3 * d + d, rel=1e-12)
    # the grid unit from the positions where the spec has none: the smallest gap
    free = array_from_spec(ArraySpec(((0.0, 0.0),), ((0.0, 0.0), (0.6 * d, 0.0),
                                                     (2.0 * d, 0.0)), (0,)), lam)
    assert free.spacing_m == pytest.approx(0.6 * d, rel=1e-9)
    single = array_from_spec(ArraySpec(((0.0, 0.0),), ((0.0, 0.0),), (0,)), lam)
    assert single.spacing_m == lam / 2 and single.aperture_m == pytest.approx(lam / 2)
