"""Tests of ``rtsgeom.radar.frame``: closed forms and invariants on grids of inputs."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import make_scene, small_noiseless, small_quiet

from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.radar import process
from rtsgeom.radar.frame import simulate
from rtsgeom.radar.processing import range_angle_map
from rtsgeom.rts.channels import program_nearest


def test_linked_frame_noise_is_the_receivers_thermal_noise_through_the_if_chain():
    """With ``[radar.link]`` and no ``snr_db`` the frame's noise per sample is k T0 F f_adc at
    the receiver input (no RTS channel programmed here) through the IF chain (mean |H|^2 over
    the bins) plus the ADC's quantisation, for a grid of noise figures (within 5 %); the
    seed decides the realisation."""
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.radar import link as lk
    from rtsgeom.radar.frame import simulate
    from rtsgeom.rts.channels import program_nearest

    def linked(nf_db):
        def m(doc):
            doc["radar"].pop("snr_db", None)
            doc["radar"].update(chirps_per_tx=32, samples_per_chirp=128, adc_rate_hz=12.5e6)
            doc["radar"]["link"] = {"noise_figure_db": nf_db}
            doc["targets"] = []
            for fe in doc["rts"]["front_ends"]:
                fe.pop("return_loss_fe_db", None)
                fe.pop("return_loss_be_db", None)
        return make_scene(m)
    for nf in (12.0, 18.0, 24.0):
        scene = linked(nf)
        radar = scene.radar
        setup = build_setup(scene)
        paths = exact_paths(setup)
        prog = program_nearest(scene, setup)
        assert len(prog) == 0
        _, cube = simulate(setup, paths, prog, seed=4)
        _, again = simulate(setup, paths, prog, seed=4)
        _, other = simulate(setup, paths, prog, seed=5)
        assert np.array_equal(cube.data, again.data) and not np.array_equal(cube.data, other.data)
        rl = lk.radar_link(radar)
        n = radar.samples_per_chirp
        h2 = np.mean(np.abs(lk.if_response(rl, np.arange(n) * radar.adc_rate_hz / n)) ** 2)
        want = lk.thermal_noise_w(radar, rl) * h2 + rl.quantisation_noise_w
        assert np.mean(np.abs(cube.data.astype(complex)) ** 2) == pytest.approx(want, rel=0.05)


@pytest.mark.parametrize("preset", ["awr1843boost", "iwr6843isk"])
def test_a_silent_cube_has_no_detections_and_empty_angles(preset):
    """No echo (an empty program, no noise): CFAR finds nothing and every column of the
    detection list is empty, the angles included (D = 1 and D = 2 arrays)."""
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.radar.frame import simulate
    from rtsgeom.radar.processing import process
    from rtsgeom.rts.channels import RtsProgram
    setup = build_setup(small_noiseless(lambda d: d["radar"].update(antenna_preset=preset)))
    _, cube = simulate(setup, exact_paths(setup), RtsProgram.build([], [], [], [], []))
    rd, det = process(cube)
    assert len(det) == 0
    for name in ("range_m", "velocity_mps", "angle_rad", "power_db", "snr_db"):
        assert getattr(det, name).shape == (0,), name
    da = rd.to_xarray()
    assert da.attrs["description"] == "sum over virtual channels of |X|^2"
    assert da.dims == ("range_m", "velocity_mps") and da.shape == rd.power.shape


def test_range_angle_map_peaks_at_each_detection_angle():
    scene = small_quiet()
    setup = build_setup(scene)
    _, cube = simulate(setup, exact_paths(setup), program_nearest(scene, setup))
    rd, det = process(cube)
    grid = np.radians(np.linspace(-30, 30, 601))
    ram = range_angle_map(rd, cube, grid)
    assert ram.shape == (rd.power.shape[0], grid.size)
    for k in range(len(det)):
        if det.doppler_bin[k] != np.argmax(rd.power[det.range_bin[k]]):
            continue  # the map takes each range bin at its strongest Doppler bin
        peak = grid[np.argmax(ram[det.range_bin[k]])]
        # grid step 0.1 deg; the map compensates TDM at the bin's Doppler, not the refined one
        assert np.degrees(abs(peak - det.angle_rad[k])) < 0.12


def test_the_range_angle_array_defaults_to_minus_60_to_60_deg_in_quarter_degrees():
    """``range_angle_to_xarray`` without angles: the grid -60..60 deg in 0.25 deg steps (481
    angles), its values ``range_angle_map`` there; with angles given, those angles."""
    scene = small_quiet()
    setup = build_setup(scene)
    _, cube = simulate(setup, exact_paths(setup), program_nearest(scene, setup))
    rd, _ = process(cube)
    da = rd.range_angle_to_xarray(cube)
    ang = da.coords["angle_deg"].values
    assert ang.size == 481 and ang[0] == -60.0 and ang[-1] == 60.0
    np.testing.assert_array_equal(np.diff(ang), 0.25)
    np.testing.assert_array_equal(da.values, range_angle_map(rd, cube, np.radians(ang)))
    assert da.dims == ("range_m", "angle_deg")
    np.testing.assert_array_equal(da.coords["range_m"].values, rd.range_m)
    given = rd.range_angle_to_xarray(cube, [-5.0, 0.0, 7.5])
    np.testing.assert_array_equal(given.coords["angle_deg"].values, [-5.0, 0.0, 7.5])
    # both arrays whole: name, dims, every coordinate, attrs, values
    assert (da.name, da.attrs) == ("power", {"long_name": "beamformer power"})
    assert set(da.coords) == {"range_m", "angle_deg"} and given.attrs == da.attrs
    np.testing.assert_array_equal(given.values,
                                  range_angle_map(rd, cube, np.radians([-5.0, 0.0, 7.5])))
    rdx = rd.to_xarray()
    assert (rdx.name, rdx.dims, rdx.attrs) == (
        "power", ("range_m", "velocity_mps"),
        {"long_name": "range-Doppler power", "description": "sum over virtual channels of |X|^2"})
    assert set(rdx.coords) == {"range_m", "velocity_mps", "doppler_hz"}
    assert rdx.coords["doppler_hz"].dims == ("velocity_mps",)
    for name, want in (("range_m", rd.range_m), ("velocity_mps", rd.velocity_mps),
                       ("doppler_hz", rd.doppler_hz)):
        np.testing.assert_array_equal(rdx.coords[name].values, want)
    np.testing.assert_array_equal(rdx.values, rd.power)


def test_the_detection_table_is_the_detections_whole():
    """``Detections.to_dataframe``: its columns in order, each the detection list's own field
    (degrees from radians, 0 elevation and rank 0 on an azimuth-only array)."""
    scene = small_quiet()
    setup = build_setup(scene)
    _, cube = simulate(setup, exact_paths(setup), program_nearest(scene, setup))
    _, det = process(cube)
    df = det.to_dataframe()
    assert list(df.columns) == ["range_m", "velocity_mps", "angle_deg", "elevation_deg",
                                "power_db", "snr_db", "range_bin", "doppler_bin", "angle_peak"]
    assert len(df) == len(det) >= 2 and det.elevation_rad is None
    want = {"range_m": det.range_m, "velocity_mps": det.velocity_mps,
            "angle_deg": np.degrees(det.angle_rad), "elevation_deg": np.zeros(len(det)),
            "power_db": det.power_db, "snr_db": det.snr_db, "range_bin": det.range_bin,
            "doppler_bin": det.doppler_bin,
            "angle_peak": (np.zeros(len(det), int) if det.angle_peak is None
                           else det.angle_peak)}
    for k, v in want.items():
        np.testing.assert_array_equal(df[k].to_numpy(), v, err_msg=k)
    assert np.array_equal(det.primary, np.asarray(want["angle_peak"]) == 0)
