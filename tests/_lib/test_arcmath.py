"""The arc's and the sphere's arithmetic (``rtsgeom._lib.arcmath``) against rotation matrices
built in the test: the sphere's frame, a module's axes after pitch then yaw, and each
antenna's position from the module centre, its mounting errors and its layout."""

from __future__ import annotations

import numpy as np
import pytest

from rtsgeom._lib.arcmath import (ModuleLayout, antenna_positions, layout_offsets,
                                  module_axes, radial_tangent, sphere_frame)

ANGLES = np.radians([-30.0, 0.0, 7.5, 95.0])
ELEVATIONS = np.radians([-20.0, 0.0, 4.0, 60.0])


def _rot_z(yaw):
    """World rotation turning like an azimuth (from +y towards +x) by ``yaw``."""
    c, s = np.cos(yaw), np.sin(yaw)
    return np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])


def _axis_angle(axis, angle):
    """Rodrigues' rotation matrix about unit ``axis``."""
    k = np.asarray(axis, float)
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * kx + (1 - np.cos(angle)) * kx @ kx


def test_the_sphere_frame_in_closed_form():
    """r = (cos e sin a, cos e cos a, sin e), t = (cos a, -sin a, 0), up = dr/de; an
    orthonormal frame with t = r x up; no elevation: the arc's radial and tangent and +z."""
    a, e = np.meshgrid(ANGLES, ELEVATIONS, indexing="ij")
    r, t, up = sphere_frame(a, e)
    np.testing.assert_allclose(r, np.stack([np.cos(e) * np.sin(a), np.cos(e) * np.cos(a),
                                            np.sin(e)], -1), atol=1e-15)
    np.testing.assert_allclose(t, np.stack([np.cos(a), -np.sin(a), 0 * a], -1), atol=1e-15)
    np.testing.assert_allclose(up, np.stack([-np.sin(e) * np.sin(a), -np.sin(e) * np.cos(a),
                                             np.cos(e)], -1), atol=1e-15)
    np.testing.assert_allclose(np.cross(r, up), t, atol=1e-15)
    r0, t0, z0 = sphere_frame(ANGLES)
    rr, tt = radial_tangent(ANGLES)
    np.testing.assert_array_equal(r0, rr)
    np.testing.assert_array_equal(t0, tt)
    np.testing.assert_array_equal(z0, np.tile([0.0, 0.0, 1.0], (4, 1)))
    a0, t_a0, u0 = sphere_frame(ANGLES, np.zeros(4))
    np.testing.assert_allclose(a0, rr, atol=0)
    np.testing.assert_allclose(u0, z0, atol=0)


def test_layout_offsets_are_half_the_separation_either_way():
    rx, tx = layout_offsets(np.array([[0.02, -0.01], [0.0, 0.05]]))
    np.testing.assert_array_equal(rx, [[[0.01, 0.0], [-0.005, 0.0]], [[0.0, 0.0], [0.025, 0.0]]])
    np.testing.assert_array_equal(tx, -rx)


@pytest.mark.parametrize("yaw, pitch, elevated", [
    (0.0, 0.0, False), (0.1, 0.0, False), (0.0, -0.2, False), (0.05, 0.15, False),
    (0.0, 0.0, True), (-0.07, 0.12, True)])
def test_a_modules_axes_are_pitch_then_yaw(yaw, pitch, elevated):
    """Unrotated: tangent, up (the sphere's elevation direction, else +z) and the boresight
    at the centre; pitch turns the boresight up about the tangent (by the world's +z and
    radial), then yaw turns all three about the world's vertical."""
    el = ELEVATIONS if elevated else None
    r, t0, z = sphere_frame(ANGLES, el) if elevated else (*radial_tangent(ANGLES),
                                                          np.tile([0, 0, 1.0], (4, 1)))
    got_t, got_up, got_b = module_axes(ANGLES, np.full(4, yaw) if yaw else None,
                                       np.full(4, pitch) if pitch else None, el)
    for q in range(4):
        b, up, t = -r[q], z[q], t0[q]
        if pitch:
            zw = np.array([0.0, 0.0, 1.0]) if not elevated else z[q]
            b, up = np.cos(pitch) * b + np.sin(pitch) * zw, np.cos(pitch) * zw + np.sin(pitch) * r[q]
        if yaw:
            m = _rot_z(yaw)
            t, up, b = m @ t, m @ up, m @ b
        np.testing.assert_allclose(got_t[q], t, atol=1e-15)
        np.testing.assert_allclose(got_up[q], up, atol=1e-15)
        np.testing.assert_allclose(got_b[q], b, atol=1e-15)
        frame = np.stack([got_t[q], got_up[q], got_b[q]])
        np.testing.assert_allclose(frame @ frame.T, np.eye(3), atol=1e-14)
    if not elevated and pitch:
        # pitch is a rotation about the tangent, the boresight up for pitch > 0
        for q in range(4):
            m = _axis_angle(t0[q], -pitch)
            np.testing.assert_allclose(m @ -r[q], module_axes(ANGLES, None,
                                                              np.full(4, pitch))[2][q],
                                       atol=1e-15)
        assert np.all(module_axes(ANGLES, None, np.full(4, pitch))[2][:, 2] * pitch > 0)


@pytest.mark.parametrize("elevated", [False, True])
def test_antenna_positions_from_the_centre_the_errors_and_the_layout(elevated):
    """Module centre c + R r + dr r + dt t + dh up; each antenna at (t, h) of the module's
    (rotated) tangent and up; the symmetric layout s/2 along the tangent; draws broadcast."""
    centre = np.array([0.3, -0.4, 0.2])
    el = ELEVATIONS if elevated else None
    r, t, z = sphere_frame(ANGLES, el) if elevated else (*radial_tangent(ANGLES),
                                                         np.tile([0, 0, 1.0], (4, 1)))
    off = np.random.default_rng(1).standard_normal((3, 4, 3)) * 1e-3  # 3 draws
    sep = np.array([0.02, -0.02, 0.01, 0.03])
    rx, tx, mod = antenna_positions(centre, 1.5, ANGLES, sep, off, elevation_rad=el)
    want_mod = (centre + 1.5 * r + off[..., 0:1] * r + off[..., 1:2] * t
                + off[..., 2:3] * z)
    np.testing.assert_allclose(mod, want_mod, atol=1e-15)
    np.testing.assert_allclose(rx, want_mod + 0.5 * sep[:, None] * t, atol=1e-15)
    np.testing.assert_allclose(tx, want_mod - 0.5 * sep[:, None] * t, atol=1e-15)
    ro = np.array([[0.01, 0.002], [-0.01, 0.0], [0.0, -0.003], [0.004, 0.001]])
    yaw, pitch = np.array([0.0, 0.1, -0.05, 0.02]), np.array([0.1, 0.0, 0.03, -0.2])
    rx2, tx2, mod2 = antenna_positions(centre, 1.5, ANGLES, sep, off, elevation_rad=el,
                                       layout=ModuleLayout(ro, None, yaw, pitch))
    ax_t, ax_up, _ = module_axes(ANGLES, yaw, pitch, el)
    np.testing.assert_array_equal(mod2, mod)
    np.testing.assert_allclose(rx2, mod + ro[:, 0:1] * ax_t + ro[:, 1:2] * ax_up, atol=1e-15)
    np.testing.assert_allclose(tx2, mod - 0.5 * sep[:, None] * ax_t, atol=1e-15)
    rx0, _, mod0 = antenna_positions(centre, 1.5, ANGLES, sep)
    np.testing.assert_allclose(mod0, centre + 1.5 * radial_tangent(ANGLES)[0], atol=1e-15)
    flat = antenna_positions(centre, 1.5, ANGLES, sep, off, elevation_rad=np.zeros(4))
    np.testing.assert_array_equal(flat[0], antenna_positions(centre, 1.5, ANGLES, sep, off)[0])


def test_a_layout_without_a_separation_or_both_offsets_is_refused():
    from conftest import assert_refused
    assert_refused(lambda: antenna_positions(np.zeros(3), 1.0, ANGLES, None,
                                             layout=ModuleLayout(rx_offset_m=np.zeros((4, 2)))),
                   "antenna_positions: give separation_m or both rx_offset_m and tx_offset_m",
                   ValueError)
    both = antenna_positions(np.zeros(3), 1.0, ANGLES, None,
                             layout=ModuleLayout(np.zeros((4, 2)), np.zeros((4, 2))))
    np.testing.assert_array_equal(both[0], both[2])
