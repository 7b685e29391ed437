"""Geometry and exact paths against closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import make_scene
from scipy.constants import c

from rtsgeom.geometry import antenna_positions, build_setup
from rtsgeom.geometry.farfield import (
    angular_resolution_rad,
    apparent_azimuth_rad,
    curvature_phase_error_rad,
    fraunhofer_distance_m,
)
from rtsgeom.paths import exact_paths
from rtsgeom.paths.exact import leg_delays
from rtsgeom.paths.table import FE_TO_RX, TX_TO_FE


def test_angular_resolution_matches_paper(default_scene):
    # Paper, section "Measurement": 8 virtual elements at lambda/2 -> 17.5 deg (eq. 24).
    rut = build_setup(default_scene).rut
    assert rut.num_virtual == 8
    assert np.degrees(angular_resolution_rad(rut)) == pytest.approx(17.48, abs=0.01)
    assert fraunhofer_distance_m(rut) == pytest.approx(2 * (8 * rut.spacing_m) ** 2 / rut.wavelength_m)


def test_virtual_array_is_uniform_half_wavelength(default_scene):
    rut = build_setup(default_scene).rut
    x = np.sort(rut.virtual_local[:, 0])
    assert np.allclose(np.diff(x), rut.wavelength_m / 2, rtol=1e-12)
    assert abs(x.mean()) < 1e-15  # the phase centre is the origin of the radar frame
    assert np.allclose(rut.virtual_local[:, 2], 0.0)


def test_elevation_tx_adds_an_elevated_row():
    scene = make_scene(use_elevation_tx=True)
    rut = build_setup(scene).rut
    assert rut.tx_order == (0, 1, 2) and rut.num_virtual == 12
    assert np.count_nonzero(rut.azimuth_mask) == 8
    assert np.allclose(rut.virtual_local[~rut.azimuth_mask, 2], rut.spacing_m)
    assert np.allclose(rut.virtual_local[rut.azimuth_mask, 2], 0.0)


def test_path_difference_approaches_d_sin_theta_in_far_field():
    # Exact path differences between adjacent Rx elements -> d sin(theta) as R_c grows (eq. 13).
    errs = []
    for radius in (1.0, 10.0, 100.0):
        def mutate(doc, radius=radius):
            doc["rts"]["arc_radius_m"] = radius
            doc["sheet"]["enabled"] = False
            doc["targets"] = []
        setup = build_setup(make_scene(mutate))
        _, tau_rx = leg_delays(setup.rut.tx_world, setup.rut.rx_world, setup.fe.rx, setup.fe.tx)
        diff = -np.diff(tau_rx, axis=1) * c  # adjacent Rx, per front end
        theta = setup.rut.azimuth_of(setup.fe.tx)
        ideal = setup.rut.spacing_m * np.sin(theta)[:, None]
        errs.append(np.max(np.abs(diff - ideal)))
    # converges like 1/R: ten times smaller per decade of radius
    assert errs[0] / errs[1] == pytest.approx(10.0, rel=0.05)
    assert errs[1] / errs[2] == pytest.approx(10.0, rel=0.05)
    assert errs[2] < 2e-4 * setup.rut.spacing_m  # (x_k^2 - x_{k-1}^2) / 2R with x ~ 12 mm


def test_radial_mounting_error_lengthens_both_paths():
    dr = 1e-3

    def mutate(doc):
        doc["rts"]["front_ends"][1]["radial_offset_mm"] = dr * 1e3
    base = exact_paths(build_setup(make_scene()))
    moved = exact_paths(build_setup(make_scene(mutate)))
    delta = moved.length_m - base.length_m
    fe1 = base.front_end == 1
    assert np.allclose(delta[fe1], dr, atol=1e-6)  # to 1 um, both directions
    assert set(base.direction[fe1]) == {TX_TO_FE, FE_TO_RX}
    assert np.all(delta[~fe1] == 0.0)


def test_mounting_errors_broadcast_over_draws(default_scene):
    setup = build_setup(default_scene)
    draws = np.random.default_rng(0).normal(0, 1e-3, (5, setup.fe.count, 3))
    rx, tx, mod = antenna_positions(setup.fe.arc_centre, setup.fe.arc_radius_m,
                                    setup.fe.angle_rad, setup.fe.separation_m, draws)
    assert rx.shape == (5, setup.fe.count, 3)
    one = build_setup(default_scene, offsets_m=draws[3])
    assert np.allclose(one.fe.rx, rx[3]) and np.allclose(one.fe.tx, tx[3])


def test_front_end_separation_and_apparent_angle(default_scene):
    setup = build_setup(default_scene)
    sep = np.linalg.norm(setup.fe.rx - setup.fe.tx, axis=1)
    assert np.allclose(sep, setup.fe.separation_m)
    # Rx sits towards larger azimuth; zero separation -> apparent == geometric angle
    assert np.all(setup.rut.azimuth_of(setup.fe.rx) > setup.rut.azimuth_of(setup.fe.tx))

    def no_sep(doc):
        for fe in doc["rts"]["front_ends"]:
            fe["rx_tx_separation_m"] = 0.0
    s0 = build_setup(make_scene(no_sep))
    app = apparent_azimuth_rad(s0.rut, s0.fe.rx, s0.fe.tx)
    assert np.allclose(app, s0.fe_azimuth_rad(), atol=1e-12)


def test_curvature_error_shrinks_with_radius():
    vals = []
    for radius in (0.5, 2.0, 8.0):
        def mutate(doc, radius=radius):
            doc["rts"]["arc_radius_m"] = radius
            doc["sheet"]["enabled"] = False
            doc["targets"] = []
        vals.append(curvature_phase_error_rad(build_setup(make_scene(mutate))).max())
    # quadratic phase-front error ~ 1/R
    assert vals[0] / vals[1] == pytest.approx(4.0, rel=0.05)
    assert vals[1] / vals[2] == pytest.approx(4.0, rel=0.05)


def test_sheet_is_watertight_with_cutouts(default_scene):
    setup = build_setup(default_scene)
    m = setup.sheet
    assert m.is_watertight and m.is_winding_consistent and m.volume > 0
    cfg = default_scene.sheet
    r = default_scene.rts.arc_radius_m
    full = (cfg.angle_max_rad - cfg.angle_min_rad) * r * cfg.height_m * cfg.thickness_m
    holes = setup.fe.count * np.pi * (cfg.cutout_diameter_m / 2) ** 2 * cfg.thickness_m
    assert m.volume == pytest.approx(full - holes, rel=2e-3)
    # the line of sight to each antenna passes through its cutout
    from rtsgeom.geometry.sheet import segments_blocked
    origins = np.repeat(setup.rut.position[None], 2 * setup.fe.count, 0)
    targets = np.vstack([setup.fe.rx, setup.fe.tx])
    assert not segments_blocked(m, origins, targets).any()
    # ...while a point on the sheet between the cutouts is hidden behind it
    mid = np.radians(7.8)
    behind = setup.fe.arc_centre + 1.01 * np.array([np.sin(mid), np.cos(mid), 0.0])
    assert segments_blocked(m, setup.rut.position, behind).all()


def test_exact_paths_table_and_csv(default_scene, tmp_path):
    setup = build_setup(default_scene)
    p = exact_paths(setup)
    n_f, n_t, n_r = setup.fe.count, setup.rut.tx_world.shape[0], setup.rut.rx_world.shape[0]
    assert len(p) == n_f * (n_t + n_r)
    assert np.allclose(p.gain, setup.rut.wavelength_m / (4 * np.pi * p.length_m))
    leg = p.leg(1, FE_TO_RX, 2)
    assert len(leg) == 1
    assert leg.length_m[0] == pytest.approx(np.linalg.norm(setup.fe.tx[1] - setup.rut.rx_world[2]),
                                            abs=1e-12)
    header = p.to_csv().splitlines()[0].split(",")
    assert header[:5] == ["front_end", "direction", "rut_element", "length_m", "delay_s"]
    assert header[-2:] == ["interactions", "surfaces"]
    rows = [r.split(",") for r in p.to_csv().splitlines()[1:]]
    assert all(r[-2:] == ["los", ""] for r in rows)  # exact paths: line of sight, no surface


def test_export_formats(default_scene, tmp_path):
    import trimesh

    from rtsgeom.geometry.export import export_setup
    setup = build_setup(default_scene)
    for ext in ("glb", "ply", "obj"):
        out = export_setup(setup, tmp_path / f"setup.{ext}")
        loaded = trimesh.load(out)
        assert loaded.bounds[1][1] > 0.99  # reaches the sheet at ~R_c
    with pytest.raises(ValueError, match="unsupported"):
        export_setup(setup, tmp_path / "setup.xyz")


def test_rut_pose_rotates_and_translates():
    def mutate(doc):
        doc["radar"]["position_m"] = [0.1, -0.2, 0.05]
        doc["radar"]["yaw_deg"] = 5.0
        doc["rts"]["arc_center_m"] = [0.1, -0.2, 0.05]
    setup = build_setup(make_scene(mutate))
    # the arc is fixed in the world, the radar yawed by +5 deg: front ends appear 5 deg lower
    assert np.allclose(np.degrees(setup.fe_azimuth_rad()), [3.4 - 5.0, 12.2 - 5.0], atol=1e-9)



@pytest.mark.parametrize("yaw_deg", [-3.0, 0.5, 10.0])
@pytest.mark.parametrize("radar_yaw_deg", [0.0, 7.0])
def test_rut_yaw_error_rotates_the_array_about_its_position(yaw_deg, radar_yaw_deg):
    """``build_setup(rut_yaw_rad=y)`` turns every RuT element about the vertical axis through
    the RuT's position by y (distances to it kept, azimuths shifted by y), the front ends
    unmoved."""
    from rtsgeom.geometry import build_setup
    scene = make_scene(lambda d: d["radar"].update(yaw_deg=radar_yaw_deg))
    y = math.radians(yaw_deg)
    s0, s1 = build_setup(scene), build_setup(scene, rut_yaw_rad=y)
    p = np.asarray(scene.radar.position_m, float)
    rot = np.array([[math.cos(y), -math.sin(y), 0], [math.sin(y), math.cos(y), 0], [0, 0, 1]])
    for w0, w1 in ((s0.rut.tx_world, s1.rut.tx_world), (s0.rut.rx_world, s1.rut.rx_world)):
        r0, r1 = w0 - p, w1 - p
        np.testing.assert_allclose(np.linalg.norm(r1, axis=1), np.linalg.norm(r0, axis=1),
                                   atol=1e-12)
        assert np.allclose(r1, r0 @ rot.T, atol=1e-12) or np.allclose(r1, r0 @ rot, atol=1e-12)
        assert not np.allclose(r1, r0, atol=1e-9)
    np.testing.assert_array_equal(s1.fe.module, s0.fe.module)
