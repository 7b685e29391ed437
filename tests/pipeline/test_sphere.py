"""Front ends on a sphere: positions, the spherical-cap sheet, elevation 0 unchanged."""

import numpy as np
import pytest

from rtsgeom._lib.arcmath import ModuleLayout, antenna_positions, module_axes, sphere_frame
from rtsgeom.geometry import build_setup
from rtsgeom.geometry.sheet import segments_blocked
from rtsgeom.errors import SceneError
from rtsgeom.scene import load_scene

SCENE = "scenes/diewald2022.toml"


def corners(scene, az_deg, el_deg, radius=None, height=None):
    """The scene with four front ends at the corners (az x el) of one cell."""
    if height is not None:
        scene = scene.evolve(sheet=scene.sheet.evolve(height_m=height))
    fe0 = scene.rts.front_ends[0]
    fes = tuple(fe0.evolve(angle_rad=np.radians(a), elevation_rad=np.radians(e))
                for a in az_deg for e in el_deg)
    rts = scene.rts.evolve(front_ends=fes, **({} if radius is None else
                                             {"arc_radius_m": radius}))
    # off the horizontal plane the RuT must beamform in 2-D (the scene rule asks for it)
    return scene.evolve(rts=rts, targets=(),
                        radar=scene.radar.evolve(elevation_processing=True))


@pytest.mark.parametrize("layout", [None, "rotated"])
def test_elevation_zero_is_bit_identical(layout):
    rng = np.random.default_rng(1)
    ang = rng.uniform(-1, 1, 7)
    sep = rng.uniform(0, 0.05, 7)
    off = rng.normal(0, 1e-3, (5, 7, 3))
    kw = {} if layout is None else dict(yaw_rad=rng.normal(0, .01, 7),
                                        pitch_rad=rng.normal(0, .01, 7))
    ref = antenna_positions(np.array([0.1, -0.2, 0.3]), 1.3, ang, sep, off,
                            layout=ModuleLayout(**kw))
    got = antenna_positions(np.array([0.1, -0.2, 0.3]), 1.3, ang, sep, off,
                            elevation_rad=np.zeros(7), layout=ModuleLayout(**kw))
    for a, b in zip(ref, got):
        assert np.array_equal(a, b)


@pytest.mark.parametrize("radius", [0.4, 1.0, 3.0])
@pytest.mark.parametrize("el_deg", [-30.0, -5.0, 2.0, 20.0])
def test_positions_on_the_sphere(radius, el_deg):
    az = np.radians(np.array([-40.0, 0.0, 10.0, 60.0]))
    el = np.full(4, np.radians(el_deg))
    centre = np.array([0.2, 0.1, -0.3])
    rx, tx, mod = antenna_positions(centre, radius, az, np.full(4, 0.02), elevation_rad=el)
    d = mod - centre
    assert np.allclose(np.linalg.norm(d, axis=-1), radius, atol=1e-12)
    assert np.allclose(d[:, 2] / radius, np.sin(el))  # u_el = sin el
    assert np.allclose(d[:, 0] / radius, np.sin(az) * np.cos(el))  # u_az = sin az cos el
    # the antennas sit on the module's tangent, 0.02 m apart, both at the module's distance
    assert np.allclose(np.linalg.norm(rx - tx, axis=-1), 0.02)
    r, t, up = sphere_frame(az, el)
    assert np.allclose(np.einsum("fk,fk->f", rx - tx, r), 0)
    assert np.allclose(np.einsum("fk,fk->f", t, up), 0) and np.allclose(np.einsum(
        "fk,fk->f", r, up), 0)
    _, uu, bb = module_axes(az, elevation_rad=el)
    assert np.allclose(bb, -r) and np.allclose(uu, up)


@pytest.mark.parametrize("radius", [0.6, 1.0, 2.0])
@pytest.mark.parametrize("half", [(2.0, 2.0), (4.0, 3.0), (3.0, 6.0)])
def test_cap_sheet_cutouts(radius, half):
    scene = load_scene(SCENE)
    az = (7.0 - half[0], 7.0 + half[0])
    el = (-half[1], half[1])
    if 2 * radius * np.radians(min(half)) < 0.052:
        with pytest.raises(SceneError, match="closer"):  # the cutouts would overlap
            corners(scene, az, el, radius, 0.8)
        return
    scene = corners(scene, az, el, radius, 0.8)
    setup = build_setup(scene)
    mesh = setup.sheet
    assert mesh.is_watertight and mesh.is_volume
    # the RuT sees every antenna through its cutout, and the sheet blocks between them
    src = np.repeat(setup.rut.tx_world[:1], 4, 0)
    assert not segments_blocked(mesh, src, setup.fe.rx).any()
    assert not segments_blocked(mesh, src, setup.fe.tx).any()
    r_hat = sphere_frame(np.radians(7.0), np.radians(0.0))[0]
    mid = setup.fe.arc_centre + 1.5 * radius * r_hat  # between the four cutouts
    if radius * np.radians(min(half)) > 0.05:  # the cell is wider than one cutout
        assert segments_blocked(mesh, setup.rut.tx_world[:1], mid[None]).all()


def test_cylinder_sheet_when_all_elevations_zero():
    scene = load_scene(SCENE)
    setup = build_setup(scene)
    z = setup.sheet.vertices[:, 2]
    assert np.isclose(z.max() - z.min(), scene.sheet.height_m)  # straight walls, as today
    assert setup.fe.elevation_rad is None


def test_rules_for_the_sphere():
    scene = load_scene(SCENE)
    with pytest.raises(SceneError, match="elevation_deg"):
        corners(scene, (5.0, 9.0), (-20.0, 20.0))  # beyond the 0.3 m tall cap
    with pytest.raises(SceneError, match="closer"):
        corners(scene, (5.0, 6.0), (-1.0, 1.0))  # cutouts overlap
    ok = corners(scene, (5.0, 9.0), (-3.0, 3.0))
    assert [round(np.degrees(f.elevation_rad), 9) for f in ok.rts.front_ends] == [-3, 3, -3, 3]


def test_all_elevations_zero_keeps_the_1d_pipeline():
    """The default scene: no N-channel planner, the azimuth-only beamformer, the arc, and a
    scene with every elevation written out as 0 builds the same bits."""
    from rtsgeom.pipeline.plan import uses_cells
    from rtsgeom.radar.steering import Steering
    scene = load_scene(SCENE)
    assert not uses_cells(scene)
    setup = build_setup(scene)
    auto = Steering.auto(setup.rut, scene.radar)
    ref = Steering.build(setup.rut, scene.radar)
    assert auto.dims == 1 and np.array_equal(auto.positions_m, ref.positions_m)
    assert np.array_equal(auto.taper, ref.taper)
    zero = scene.evolve(rts=scene.rts.evolve(front_ends=tuple(
        f.evolve(elevation_rad=0.0) for f in scene.rts.front_ends)),
        targets=tuple(t.evolve(elevation_rad=0.0) for t in scene.targets))
    s0 = build_setup(zero)
    for a, b in ((setup.fe.rx, s0.fe.rx), (setup.fe.tx, s0.fe.tx),
                 (setup.fe.module, s0.fe.module), (setup.sheet.vertices, s0.sheet.vertices)):
        assert np.array_equal(a, b)


@pytest.mark.slow
def test_default_scene_run_unchanged_with_explicit_zero_elevations():
    """The whole run (pair calibration, synthesis, detection) with every elevation written out
    as 0 gives the same detections and calibration as the scene without the keys."""
    from rtsgeom.pipeline.run import run_scene
    scene = load_scene(SCENE)
    zero = scene.evolve(rts=scene.rts.evolve(front_ends=tuple(
        f.evolve(elevation_rad=0.0) for f in scene.rts.front_ends)),
        targets=tuple(t.evolve(elevation_rad=0.0) for t in scene.targets))
    a, b = run_scene(scene), run_scene(zero)
    assert a.detections.elevation_rad is None and b.detections.elevation_rad is None
    for name in ("range_m", "velocity_mps", "angle_rad", "power_db"):
        assert np.array_equal(getattr(a.detections, name), getattr(b.detections, name))
    assert a.calibration == b.calibration
    assert all("elevation_deg" not in m["set"] for m in a.matches)


@pytest.mark.parametrize("command", ["linearity", "tolerance"])
@pytest.mark.parametrize("pair", [("0", "1"), ("0", "2"), ("1", "0"), ("all",)])
def test_pair_commands_refuse_2d_cells(command, pair, capsys):
    """A scene of 2-D cells has no pairs on an arc: the pair studies exit 2 naming the
    argument and the cell commands (they used to exit 0 with an inf residual or a span of
    zero width), for one pair and for all."""
    from rtsgeom.cli import main
    assert main([command, "scenes/sphere4.toml", "--pair", *pair, "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "--pair " in err and "2-D cells" in err and "--grid" in err


def test_calibrate_takes_the_cells_neighbouring_pairs(capsys):
    """The calibration is measured pair by pair in 2-D too: ``--pair 0 1`` (stacked in
    elevation) calibrates through the full chain in the RuT's 2-D beamformer, to the
    geometry's +29 ps (``tests/calibration/test_cell_calibration.py``); a pair that is not neighbours
    in the cells exits 2 naming the pairs there are."""
    from rtsgeom.cli import main
    assert main(["calibrate", "scenes/sphere4.toml", "--pair", "1", "2", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "--pair 1 2: not neighbours" in err and "0 1, 0 2" in err


@pytest.mark.heavy
def test_calibrate_measures_a_cells_pair_through_the_full_chain(capsys):
    """``--pair 1 0`` of sphere4 (stacked in elevation): calibrated through the full chain in
    the RuT's 2-D beamformer to the geometry's +29 ps (a minute of 2-D sweeps)."""
    import json
    from rtsgeom.cli import main
    assert main(["calibrate", "scenes/sphere4.toml", "--pair", "1", "0", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["pair"] == [0, 1] and out["dims"] == 2 and out["method"] == "full-chain"
    assert abs(out["delta_tau_s"] - 29.05e-12) < 3e-12
