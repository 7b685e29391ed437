"""Front-end antenna layout and orientation on the arc and the sign of the single-front-end
near-field bias it implies."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from conftest import make_scene

from rtsgeom.analysis.nearfield import with_arc_radius
from rtsgeom.analysis.nearfield_terms import (
    group_azimuth_rad,
    single_front_end_angles_rad,
)
from rtsgeom.calibration.probes import probe_ranges
from rtsgeom.geometry import Setup, build_setup
from rtsgeom.geometry.arrays import rut_array
from rtsgeom._lib.arcmath import ModuleLayout
from rtsgeom.geometry.frontends import (
    antenna_positions,
    front_ends,
    module_axes,
    radial_tangent,
)
from rtsgeom.paths import exact_paths
from rtsgeom.scene.presets import preset

CENTRE = np.array([0.01, -0.02, 0.005])
ANGLES = np.radians([-20.0, -3.0, 0.0, 7.5, 31.0])


def _grid_offsets(seed=1, n=4):
    rng = np.random.default_rng(seed)
    return rng.normal(0, 1e-3, (n, ANGLES.size, 3))


@pytest.mark.parametrize("radius", [0.3, 1.0, 4.0])
@pytest.mark.parametrize("sep", [0.0, 0.012, 0.02, 0.045])
def test_separation_is_the_symmetric_signed_layout(radius, sep):
    off = _grid_offsets()
    s = np.full(ANGLES.size, sep)
    rx0, tx0, m0 = antenna_positions(CENTRE, radius, ANGLES, s, off)
    ro = np.tile([sep / 2, 0.0], (ANGLES.size, 1))
    rx, tx, m = antenna_positions(CENTRE, radius, ANGLES, None, off, layout=ModuleLayout(ro, -ro))
    assert np.allclose(rx, rx0, atol=1e-15) and np.allclose(tx, tx0, atol=1e-15)
    assert np.array_equal(m, m0)
    # Rx towards larger azimuth, as seen from the arc centre; a mirrored module flips it
    az = lambda p: np.arctan2(p[..., 0] - CENTRE[0], p[..., 1] - CENTRE[1])  # noqa: E731
    if sep > 0:
        assert np.all(az(rx) > az(m)) and np.all(az(tx) < az(m))
        rxm, txm, _ = antenna_positions(CENTRE, radius, ANGLES, None, off, layout=ModuleLayout(-ro, ro))
        assert np.all(az(rxm) < az(m)) and np.all(az(txm) > az(m))


@pytest.mark.parametrize("yaw_deg", [-5.0, 0.0, 2.0, 30.0])
@pytest.mark.parametrize("pitch_deg", [-3.0, 0.0, 10.0])
def test_mounting_rotations_are_rigid_about_the_module_centre(yaw_deg, pitch_deg):
    yaw = np.full(ANGLES.size, np.radians(yaw_deg))
    pitch = np.full(ANGLES.size, np.radians(pitch_deg))
    ro = np.tile([0.011, 0.004], (ANGLES.size, 1))
    to = np.tile([-0.009, -0.002], (ANGLES.size, 1))
    rx, tx, mod = antenna_positions(CENTRE, 1.0, ANGLES, None, None, layout=ModuleLayout(ro, to, yaw, pitch))
    assert np.allclose(np.linalg.norm(rx - mod, axis=-1), np.hypot(0.011, 0.004))
    assert np.allclose(np.linalg.norm(tx - mod, axis=-1), np.hypot(0.009, 0.002))
    assert np.allclose(np.linalg.norm(rx - tx, axis=-1), np.hypot(0.020, 0.006))
    t, up, b = module_axes(ANGLES, yaw, pitch)
    r_hat, t_hat = radial_tangent(ANGLES)
    # closed forms: boresight tilts up by the pitch and turns by the yaw (azimuth sense)
    assert np.allclose(b[:, 2], np.sin(pitch))
    assert np.allclose(np.einsum("fk,fk->f", b, -r_hat), np.cos(yaw) * np.cos(pitch))
    assert np.allclose(np.einsum("fk,fk->f", t, t_hat), np.cos(yaw))
    assert np.allclose(np.einsum("fk,fk->f", t, -r_hat), np.sin(yaw))
    # orthonormal, right-handed (tangent, up, boresight) -> t x up = -b for this convention
    for u, v in ((t, up), (t, b), (up, b)):
        assert np.allclose(np.einsum("fk,fk->f", u, v), 0, atol=1e-15)
    assert np.allclose(np.cross(b, up), -t)
    if pitch_deg == 0.0:  # yaw alone: rx - mod = t_r (cos y t_hat + sin y (-r_hat)) + h z
        want = (0.011 * (np.cos(yaw)[:, None] * t_hat - np.sin(yaw)[:, None] * r_hat)
                + 0.004 * np.array([0, 0, 1.0]))
        assert np.allclose(rx - mod, want)


def test_rotations_and_layouts_broadcast_over_draws():
    rng = np.random.default_rng(5)
    off = rng.normal(0, 1e-3, (6, ANGLES.size, 3))
    yaw = rng.normal(0, 0.02, (6, ANGLES.size))
    pitch = rng.normal(0, 0.02, (6, ANGLES.size))
    ro = np.tile([0.01, 0.0], (ANGLES.size, 1))
    rx, tx, mod = antenna_positions(CENTRE, 0.8, ANGLES, None, off, layout=ModuleLayout(ro, -ro, yaw, pitch))
    assert rx.shape == tx.shape == mod.shape == (6, ANGLES.size, 3)
    for k in range(6):
        r1, t1, m1 = antenna_positions(CENTRE, 0.8, ANGLES, None, off[k], layout=ModuleLayout(ro, -ro, yaw[k], pitch[k]))
        assert np.allclose(rx[k], r1) and np.allclose(tx[k], t1) and np.allclose(mod[k], m1)


def test_front_ends_from_todays_scene_unchanged_and_explicit_layout(default_scene):
    setup = build_setup(default_scene)
    fe = setup.fe
    rx, tx, mod = antenna_positions(fe.arc_centre, fe.arc_radius_m, fe.angle_rad,
                                    fe.separation_m, fe.offsets_m)
    assert np.array_equal(fe.rx, rx) and np.array_equal(fe.tx, tx)
    assert fe.rx_offset_m is None and fe.yaw_rad is None
    # boresight at the arc centre, antenna frame right-handed with y the boresight
    frame = fe.antenna_frame()
    nominal = fe.arc_centre + fe.arc_radius_m * radial_tangent(fe.angle_rad)[0]
    unit = (fe.arc_centre - nominal) / np.linalg.norm(fe.arc_centre - nominal, axis=1)[:, None]
    assert np.allclose(frame[:, :, 1], unit)
    assert np.allclose(np.linalg.det(frame), 1.0)
    # explicit mirrored layout + yaw on one front end
    n = fe.count
    s = fe.separation_m
    mirrored = front_ends(default_scene, fe.arc_centre, rx_offset_m=np.c_[-s / 2, np.zeros(n)],
                          tx_offset_m=np.c_[s / 2, np.zeros(n)],
                          yaw_rad=np.r_[np.radians(2.0), np.zeros(n - 1)])
    assert np.allclose(mirrored.separation_m, -s)
    assert np.allclose(mirrored.rx[1:], fe.tx[1:]) and np.allclose(mirrored.tx[1:], fe.rx[1:])
    assert not np.allclose(mirrored.rx[0], fe.tx[0])
    with pytest.raises(ValueError, match="rx_offset_m"):
        front_ends(default_scene, fe.arc_centre, rx_offset_m=np.zeros((n + 1, 2)))


# ------------------------------------------------------------------------------------------
# Near-field sign: the front end's own Rx/Tx split biases the detected angle towards its Rx
# ------------------------------------------------------------------------------------------


def _slope_shares(rut):
    """Least-squares beamformer slope shares of the Tx and Rx positions (sum to 1)."""
    m = rut.azimuth_mask
    xt = rut.tx_local[rut.virtual_tx[m], 0]
    xr = rut.rx_local[rut.virtual_rx[m], 0]
    xv = xt + xr
    w = (xv - xv.mean()) / np.sum((xv - xv.mean()) ** 2)
    return float(np.sum(w * xt)), float(np.sum(w * xr))


def _bias_deg(scene, rx_off, tx_off):
    base = build_setup(scene)
    n = base.fe.count
    fe = front_ends(scene, base.fe.arc_centre, rx_offset_m=np.tile(rx_off, (n, 1)),
                    tx_offset_m=np.tile(tx_off, (n, 1)))
    setup = Setup(scene, base.rut, fe)
    rng = float(probe_ranges(base, 1)[0])
    det = single_front_end_angles_rad(setup, exact_paths(setup), rng)
    return np.degrees(det - setup.fe_azimuth_rad())


LAYOUTS = {  # (rx (t, h), tx (t, h)) in metres
    "rx-larger": ((0.01, 0.0), (-0.01, 0.0)),
    "rx-smaller": ((-0.01, 0.0), (0.01, 0.0)),
    "asymmetric": ((0.015, 0.0), (-0.004, 0.0)),
    "rx-only-offset": ((0.0, 0.0), (-0.012, 0.0)),
}


@pytest.mark.parametrize("radius", [0.5, 1.0, 3.0])
def test_single_front_end_bias_sign_follows_the_layout_and_flips_when_mirrored(radius):
    scene = with_arc_radius(make_scene(lambda d: d["sheet"].update(enabled=False)), radius)
    w_tx, w_rx = _slope_shares(build_setup(scene).rut)
    zero = _bias_deg(scene, (0.0, 0.0), (0.0, 0.0))  # the RuT's own Tx/Rx-group parallax
    parts = {}
    for name, (ro, to) in LAYOUTS.items():
        part = _bias_deg(scene, ro, to) - zero
        # far-field closed form: the Tx see the FE's Rx, the Rx its Tx -> shares of the slope
        want = np.degrees((w_tx * ro[0] + w_rx * to[0]) / radius)
        assert np.all(np.sign(part) == np.sign(want))
        assert part == pytest.approx(np.full_like(part, want), rel=0.03, abs=2e-3)
        parts[name] = part
    # the mirrored module gives the opposite split bias
    assert np.allclose(parts["rx-smaller"], -parts["rx-larger"], rtol=0.02, atol=1e-3)
    # the AWR1843's Tx carry most of the slope, so Rx at the larger azimuth biases upwards
    assert w_tx > w_rx and np.all(parts["rx-larger"] > 0)
    # the RuT's own board-gap parallax has the same sign (Rx group right of the Tx group)
    assert np.all(zero > 0)


@pytest.mark.parametrize("radius", [0.5, 1.0, 3.0])
def test_board_gap_is_a_near_field_parallax_not_a_shift(radius):
    # The gap between the RuT's Tx and Rx groups leaves the virtual array unchanged but moves
    # the single-front-end angle (zero Rx/Tx split): the group-parallax closed form follows it.
    scene = with_arc_radius(make_scene(lambda d: d["sheet"].update(enabled=False)), radius)
    base = build_setup(scene)
    d = base.rut.spacing_m
    lam = base.rut.wavelength_m
    n = base.fe.count
    fe = front_ends(scene, base.fe.arc_centre, rx_offset_m=np.zeros((n, 2)),
                    tx_offset_m=np.zeros((n, 2)))
    rng = float(probe_ranges(base, 1)[0])
    biases = []
    for gap in (0.0, 3 * lam, 6 * lam):
        rut = rut_array(scene.radar, preset("awr1843boost").spec(d, board_gap_m=gap))
        assert np.allclose(rut.virtual_local, base.rut.virtual_local, atol=1e-15)
        setup = Setup(scene, rut, fe)
        det = single_front_end_angles_rad(setup, exact_paths(setup), rng)
        geo = setup.fe_azimuth_rad()
        closed = group_azimuth_rad(rut, fe.rx, fe.tx) - geo
        assert det - geo == pytest.approx(closed, rel=0.03, abs=1e-5)
        biases.append(np.degrees(det - geo))
    assert np.all(np.diff(np.array(biases), axis=0) > 0)  # a wider gap, a larger parallax



def test_front_end_layout_fields_read_per_front_end():
    """Front ends whose configs carry explicit (t, h) offsets and rotations (the library
    layer; some may leave them unset, i.e. default): placed by those, not the shorthand."""
    from rtsgeom.geometry.frontends import front_ends
    base = make_scene().rts.front_ends
    fes = [SimpleNamespace(**{k: getattr(f, k) for k in f.__dataclass_fields__}) for f in base]
    fes[0].rx_offset_m, fes[0].tx_offset_m = (0.004, 0.001), (-0.006, 0.0)
    fes[1].rx_offset_m, fes[1].tx_offset_m = None, None  # default: both at the module centre
    scene = SimpleNamespace(rts=SimpleNamespace(front_ends=fes, arc_radius_m=1.0))
    fe = front_ends(scene, np.zeros(3))
    t0 = np.array([np.cos(fes[0].angle_rad), -np.sin(fes[0].angle_rad), 0.0])
    np.testing.assert_allclose(fe.rx[0] - fe.module[0], 0.004 * t0 + [0, 0, 0.001], atol=1e-12)
    np.testing.assert_allclose(fe.tx[0] - fe.module[0], -0.006 * t0, atol=1e-12)
    np.testing.assert_allclose(fe.rx[1], fe.module[1], atol=1e-12)


@pytest.mark.parametrize("kw, name, shape, got", [
    ({"rx_offset_m": np.zeros((3, 2))}, "rx_offset_m", (2, 2), (3, 2)),
    ({"tx_offset_m": np.zeros(2)}, "tx_offset_m", (2, 2), (2,)),
    ({"yaw_rad": np.zeros(3)}, "yaw_offset_rad", (2,), (3,)),
    ({"pitch_rad": np.zeros((2, 1))}, "pitch_offset_rad", (2,), (2, 1)),
])
def test_a_layout_or_rotation_of_another_shape_is_refused(default_scene, kw, name, shape, got):
    from conftest import assert_refused
    from rtsgeom.geometry.frontends import front_ends
    assert_refused(lambda: front_ends(default_scene, np.zeros(3), **kw),
                   f"front ends: {name} must have shape {shape}, got {got}", ValueError)


def test_rotations_given_as_zeros_are_kept_and_the_antenna_frame(default_scene):
    """Zero rotations given explicitly are kept (a draw of rotations); the scene's own zero
    rotations are none. The antenna frame: columns (boresight x up, boresight, up),
    right-handed, x towards smaller azimuth, the boresight at the arc centre."""
    from rtsgeom.geometry.frontends import front_ends
    centre = np.array([0.1, -0.2, 0.3])
    given = front_ends(default_scene, centre, yaw_rad=np.zeros(2), pitch_rad=np.zeros(2))
    assert given.yaw_rad is not None and given.pitch_rad is not None
    plain = front_ends(default_scene, centre)
    assert plain.yaw_rad is None and plain.pitch_rad is None and plain.count == 2
    np.testing.assert_array_equal(given.rx, plain.rx)
    f = plain.antenna_frame()
    assert f.shape == (2, 3, 3)
    for q in range(2):
        np.testing.assert_allclose(f[q].T @ f[q], np.eye(3), atol=1e-15)
        assert np.linalg.det(f[q]) == pytest.approx(1.0)
        a = plain.angle_rad[q]
        np.testing.assert_allclose(f[q][:, 1], [-np.sin(a), -np.cos(a), 0.0], atol=1e-15)
        np.testing.assert_allclose(f[q][:, 2], [0.0, 0.0, 1.0], atol=1e-15)
        np.testing.assert_allclose(f[q][:, 0], [-np.cos(a), np.sin(a), 0.0], atol=1e-15)
    np.testing.assert_array_equal(plain.arc_centre, centre)
    assert plain.arc_radius_m == default_scene.rts.arc_radius_m


@pytest.mark.parametrize("radial_m", [0.0, 3e-3])
def test_front_ends_on_a_sphere_sit_at_their_elevation(sphere_scene, default_scene, radial_m):
    """scenes/sphere4.toml (+-5 deg elevation): each module centre is the arc centre plus
    (R + dr) (cos el sin az, cos el cos az, sin el); its Rx and Tx lie on the sphere's
    tangent plane there, sep/2 either side of it, its boresight at the centre; the setup keeps
    the elevations. A scene all on the arc keeps none (the arc's arithmetic)."""
    from rtsgeom.geometry.frontends import front_ends as fe_of
    n = len(sphere_scene.rts.front_ends)
    az = np.array([f.angle_rad for f in sphere_scene.rts.front_ends])
    el = np.array([f.elevation_rad for f in sphere_scene.rts.front_ends])
    assert np.ptp(el) > 0.1
    centre = np.array([0.1, -0.2, 0.05])
    off = np.zeros((n, 3))
    off[:, 0] = radial_m
    fe = fe_of(sphere_scene, centre, offsets_m=off)
    np.testing.assert_array_equal(fe.elevation_rad, el)
    r_hat = np.stack([np.cos(el) * np.sin(az), np.cos(el) * np.cos(az), np.sin(el)], -1)
    r = sphere_scene.rts.arc_radius_m + radial_m
    np.testing.assert_allclose(fe.module, centre + r * r_hat, rtol=0, atol=1e-12)
    for ant in (fe.rx, fe.tx):
        d = ant - fe.module
        np.testing.assert_allclose(np.einsum("fi,fi->f", d, r_hat), 0.0, atol=1e-12)
        np.testing.assert_allclose(np.linalg.norm(d, axis=-1), fe.separation_m / 2,
                                   rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(fe.axes()[2], -r_hat, atol=1e-12)
    flat = build_setup(default_scene).fe
    assert flat.elevation_rad is None and np.all(flat.module[:, 2] == flat.arc_centre[2])
