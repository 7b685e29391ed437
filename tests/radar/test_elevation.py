"""The RuT's 2-D beamformer: the D = 2 grid search and detections' elevation."""

import numpy as np
import pytest

from rtsgeom.geometry import build_setup
from rtsgeom.radar.processing import Detections
from rtsgeom.radar.steering import Steering
from rtsgeom.scene import load_scene

SCENE = "scenes/diewald2022.toml"


def steering(preset, elevation_tx, window="none"):
    sc = load_scene(SCENE)
    radar = sc.radar.evolve(antenna_preset=preset, use_elevation_tx=elevation_tx,
                            angle_window=window, elevation_processing=True)
    setup = build_setup(sc.evolve(radar=radar, targets=()))
    return setup.rut, Steering.auto(setup.rut, radar)


def plane_waves(st, rut, ae):
    """Far-field snapshots (P, V) of sources at (az, el) (P, 2): phase -k p . u."""
    x = np.zeros((ae.shape[0], rut.num_virtual), complex)
    x[:, st.mask] = np.exp(-1j * (st.wavevector @ st.directions(ae).T)).T
    return x


@pytest.mark.parametrize("preset", ["awr1843boost", "iwr6843isk", "awr2944", "awr2243-cascade"])
@pytest.mark.parametrize("window", ["none", "hann", "hamming", "blackman"])
def test_2d_search_finds_plane_waves(preset, window):
    rut, st = steering(preset, True, window)
    assert st.dims == 2 and Steering.has_elevation(rut)
    rng = np.random.default_rng(3)
    # inside the unambiguous region of the array in both axes
    ae = np.radians(np.column_stack([rng.uniform(-45, 45, 40), rng.uniform(-25, 25, 40)]))
    got = st.search(plane_waves(st, rut, ae))
    assert got.shape == (40, 2)
    assert np.degrees(np.abs(got - ae)).max() < 1e-6
    assert np.allclose(st.azimuth(plane_waves(st, rut, ae)), got[:, 0])


def test_azimuth_only_array_stays_1d():
    rut, st = steering("awr1843boost", False)
    assert st.dims == 1 and not Steering.has_elevation(rut)
    ref = Steering.build(rut, load_scene(SCENE).radar)
    assert np.array_equal(st.positions_m, ref.positions_m)


def test_detections_elevation_defaults_to_zero():
    z = np.zeros(3)
    det = Detections(z + 1, z, z, z, z, z.astype(int), z.astype(int))
    assert np.array_equal(det.elevation_deg, z)
    assert list(det.to_dataframe().columns)[:4] == ["range_m", "velocity_mps", "angle_deg",
                                                   "elevation_deg"]


def test_elevation_processing_is_opt_in_and_required_off_the_plane():
    """2-D beamforming only with radar.elevation_processing (a flat arc's pair designs solve on
    the azimuth row, which a 2-D RuT would see ~0.2 deg off); a front end off the horizontal
    plane without it is a scene error naming the field."""
    from rtsgeom.errors import SceneError
    sc = load_scene(SCENE)
    radar = sc.radar.evolve(use_elevation_tx=True)
    rut = build_setup(sc.evolve(radar=radar, targets=())).rut
    assert Steering.has_elevation(rut)
    assert Steering.auto(rut, radar).dims == 1
    assert Steering.auto(rut, radar.evolve(elevation_processing=True)).dims == 2
    fes = (sc.rts.front_ends[0].evolve(elevation_rad=np.radians(3.0)),) + sc.rts.front_ends[1:]
    with pytest.raises(SceneError, match="radar.elevation_processing"):
        sc.evolve(radar=radar, rts=sc.rts.evolve(front_ends=fes))
