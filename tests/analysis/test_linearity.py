"""Tests of ``rtsgeom.analysis.linearity``: closed forms and invariants on grids of inputs."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT, small_noiseless

from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths


def test_2d_error_map_exact_mode_puts_every_grid_point_on_its_direction():
    """sphere4 as built = nominal (no errors, noiseless): ``exact`` amplitudes synthesize
    every grid point inside the four front ends' cell at its (azimuth, elevation) through
    the whole chain (1e-4 deg); ``array-factor`` (closed form, no near field) is off by a
    finite amount. The n x n grid inside a rectangular cell keeps all n^2 points."""
    from rtsgeom.analysis.linearity import linearity
    from rtsgeom.scene import load_scene
    sc = load_scene(ROOT / "scenes" / "sphere4.toml")
    sc = sc.evolve(radar=sc.radar.evolve(snr_db=None, samples_per_chirp=128, chirps_per_tx=32,
                                         adc_rate_hz=12.5e6))
    setup = build_setup(sc)
    paths = exact_paths(setup)
    told = []
    em = linearity(setup, paths, None, "exact", points=2, calibrate=False, seed=1,
                   progress=told.append)
    assert em.set_deg.shape == (4, 2)
    assert told == [f"set-point {k}/4" for k in range(1, 5)]  # one line per grid point
    assert max(em.max_abs_error_deg) < 1e-4
    af = linearity(setup, paths, None, "array-factor", points=2, calibrate=False, seed=1)
    assert 0.05 < max(af.max_abs_error_deg) < 1.0


@pytest.mark.parametrize("mode", ["array-factor", "paper"])
def test_measured_end_angles_equal_geometric_ones_in_the_ideal_far_field(mode):
    """In the ideal far field (50 m, no Rx/Tx separation) each front end alone is detected
    at its geometric angle, so the closed forms with measured end angles program the same
    ratios as with the geometric ones: the same detected angles through the chain."""
    from conftest import far_field

    from rtsgeom.analysis.linearity import linearity
    from rtsgeom.calibration.probes import probe_front_ends

    def far(doc):
        far_field(doc)
        doc["targets"] = [{"range_m": 60.0, "angle_deg": 7.0}]
    setup = build_setup(small_noiseless(far))
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, 1)
    geo = linearity(setup, paths, (0, 1), mode, probe, None, 5, 1, end_angles="geometric")
    meas = linearity(setup, paths, (0, 1), mode, probe, None, 5, 1, end_angles="measured")
    assert np.all(np.isfinite(meas.error_deg))
    np.testing.assert_allclose(meas.error_deg, geo.error_deg, atol=0.02)


def test_linearity_sweeps_the_inner_span_and_reports_relative_amplitudes(cal_setup, calibrated):
    """Set angles at k/(points + 1) of the span, each detected near it (exact amplitudes on a
    calibrated pair), amplitudes in dB relative to the largest (max 0 dB)."""
    from rtsgeom.analysis.linearity import linearity
    setup, paths = cal_setup
    probe, cal = calibrated
    lin = linearity(setup, paths, (0, 1), "exact", probe, cal, points=3)
    meas = np.sort(probe.angle_rad)
    geo = np.sort(setup.fe_azimuth_rad())
    lo, hi = max(meas[0], geo[0]), min(meas[1], geo[1])
    np.testing.assert_allclose(np.radians(lin.set_deg), lo + np.array([1, 2, 3]) / 4 * (hi - lo),
                               rtol=1e-12)
    assert lin.max_abs_error_deg < 0.05
    amp_db = np.asarray(lin.amplitude_db)
    assert amp_db.max() == 0.0 and np.all(amp_db <= 0.0)
    # 20 log10 of the programmed amplitudes relative to the largest
    from rtsgeom.calibration.probes import probe_angles, probe_ranges
    from rtsgeom.calibration.phasor import PairChannels
    from rtsgeom.pipeline.pair import pair_design
    from rtsgeom.scene import TargetConfig
    rng = float(probe_ranges(setup, 1)[0])
    channels = PairChannels((0, 1), (0.0, cal.delta_tau_s), probe.gain_correction[[0, 1]])
    amps = np.array([pair_design(setup, paths, channels, TargetConfig(rng, 0.0, 10.0, float(a)),
                                 "exact", probe_angles(*probe.angle_rad[[0, 1]]),
                                 cal.quantisation_residual_s)[:2]
                     for a in np.radians(lin.set_deg)]).T
    np.testing.assert_allclose(amp_db, 20 * np.log10(amps / amps.max()), atol=1e-9)
    # the channels trade amplitude across the span: A_J grows, A_I falls
    assert np.all(np.diff(amp_db[1]) > 0) and np.all(np.diff(amp_db[0]) < 0)


# -- the result as it shows itself: summary, table, files, in full ---------------------------


def _pair_result(**over):
    from rtsgeom.analysis.linearity import Linearity
    fields = dict(mode="paper", calibrated=True, set_deg=np.array([4.0, 6.0, 8.0, 10.0]),
                  detected_deg=np.array([4.25, 5.5, np.nan, 10.125]),
                  amplitude_db=np.array([[0.0, -1.0, -2.0, -3.0], [-3.0, -2.0, -1.0, 0.0]]),
                  end_angles="measured", channels=(1, 2))
    fields.update(over)
    return Linearity(**fields)


def _cell_result(**over):
    from rtsgeom.analysis.linearity import Linearity
    fields = dict(mode="exact", calibrated=False,
                  set_deg=np.array([[1.0, -2.0], [3.0, 2.0], [5.0, 0.5]]),
                  detected_deg=np.array([[1.5, -2.25], [np.nan, np.nan], [4.0, 0.625]]),
                  channels=(0, 1, 2, 3))
    fields.update(over)
    return Linearity(**fields)


@pytest.mark.parametrize("calibrated", [True, False])
def test_a_pairs_linearity_summary_and_table_in_full(calibrated):
    """Title (mode, pair, calibrated or not), the set-points with how many were detected,
    the worst |error| ignoring the undetected one, the set angles, errors and end angles; the
    table's columns in order, one amplitude column per channel named by the channel."""
    from rtsgeom._lib.results import brief
    lin = _pair_result(calibrated=calibrated)
    assert lin.dims == 1 and lin.max_abs_error_deg == 0.5
    title, rows = lin._summary()
    assert title == f"paper synthesis over pair (1, 2), {'' if calibrated else 'un'}calibrated"
    assert [(k, v if isinstance(v, str) else brief(v)) for k, v in rows] == [
        ("set-points", "4 (3 detected)"), ("max_abs_error_deg", "0.5"),
        ("set_deg", "array (4): 4 .. 10"), ("error_deg", "array (4): -0.5 .. 0.25, 1 not finite"),
        ("end_angles", "measured")]
    cols = lin._columns()
    assert list(cols) == ["set_deg", "detected_deg", "error_deg", "amplitude_1_db",
                          "amplitude_2_db"]
    np.testing.assert_array_equal(cols["error_deg"], [0.25, -0.5, np.nan, 0.125])
    np.testing.assert_array_equal(cols["detected_deg"], lin.detected_deg)
    np.testing.assert_array_equal(cols["set_deg"], lin.set_deg)
    np.testing.assert_array_equal(cols["amplitude_2_db"], [-3.0, -2.0, -1.0, 0.0])
    assert list(_pair_result(channels=())._columns())[3:] == ["amplitude_0_db",
                                                              "amplitude_1_db"]
    assert list(_pair_result(amplitude_db=None)._columns()) == ["set_deg", "detected_deg",
                                                                "error_deg"]


def test_a_cells_linearity_summary_and_table_in_full():
    """A cell's worst error in azimuth and in elevation, its rows of set azimuths and
    elevations (no end angles), its six columns."""
    from rtsgeom._lib.results import brief
    lin = _cell_result()
    assert lin.dims == 2 and lin.max_abs_error_deg == (1.0, 0.25)
    title, rows = lin._summary()
    assert title == "exact synthesis over cell (0, 1, 2, 3), uncalibrated"
    assert [(k, v if isinstance(v, str) else brief(v)) for k, v in rows] == [
        ("set-points", "3 (2 detected)"), ("max_abs_error_deg", "azimuth 1, elevation 0.25"),
        ("set azimuth_deg", "array (3): 1 .. 5"), ("set elevation_deg", "array (3): -2 .. 2")]
    cols = lin._columns()
    assert list(cols) == ["set_azimuth_deg", "set_elevation_deg", "detected_azimuth_deg",
                          "detected_elevation_deg", "azimuth_error_deg", "elevation_error_deg"]
    want = [lin.set_deg[:, 0], lin.set_deg[:, 1], lin.detected_deg[:, 0],
            lin.detected_deg[:, 1], [0.5, np.nan, -1.0], [-0.25, np.nan, 0.125]]
    for name, w in zip(cols, want):
        np.testing.assert_array_equal(cols[name], w, err_msg=name)
    one_off = _cell_result(detected_deg=np.array([[1.5, -2.0], [3.0, np.nan], [5.0, 0.5]]))
    assert one_off._summary()[1][0] == ("set-points", "3 (2 detected)")  # both angles needed


@pytest.mark.parametrize("make, stem", [(_pair_result, "linearity"),
                                        (_cell_result, "linearity_grid")])
def test_a_linearity_writes_its_figure_and_json(tmp_path, monkeypatch, make, stem):
    """<stem>.png (its plot(), saved) and <stem>.json (its to_dict()); the figure itself is
    not drawn here (its own tests do)."""
    import json

    from rtsgeom.analysis.linearity import Linearity
    monkeypatch.setattr(Linearity, "plot", lambda self: f"figure of {self.mode}")
    monkeypatch.setattr("rtsgeom.viz.figures.save_figure",
                        lambda fig, path: path.write_text(fig))
    lin = make()
    assert lin.write(tmp_path) == [f"{stem}.png", f"{stem}.json"]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([f"{stem}.png", f"{stem}.json"])
    assert (tmp_path / f"{stem}.png").read_text() == f"figure of {lin.mode}"
    assert json.loads((tmp_path / f"{stem}.json").read_text()) == json.loads(
        json.dumps(lin.to_dict()))


def test_unknown_end_angles_are_refused_naming_the_choices(default_scene):
    from rtsgeom.analysis.linearity import END_ANGLES, linearity
    from rtsgeom.errors import ParameterError
    assert END_ANGLES == ("geometric", "measured")
    setup = build_setup(default_scene)
    with pytest.raises(ParameterError) as exc:
        linearity(setup, None, (0, 1), "paper", probe=object(), end_angles="nominal")
    assert str(exc.value) == ("end_angles = 'nominal': must be one of ('geometric', "
                              "'measured')")


@pytest.mark.parametrize("n", [2, 3])
def test_the_cell_grid_is_n_by_n_at_fractions_of_the_corners_extent_inside_the_hull(n):
    """A square cell keeps all n^2 points at (k + 1) / (n + 1) of each angle's extent,
    azimuth-major; a triangle (its upper-right corner cut) drops those outside."""
    from rtsgeom.analysis.linearity import cell_grid
    from rtsgeom.radar.steering import Steering

    class _Steering:  # a 2-D beamformer's angles and direction cosines, nothing else
        dims = 2
        angles = staticmethod(Steering.angles)
        directions = Steering.directions
    corners = np.radians([[-10.0, -6.0], [10.0, -6.0], [10.0, 6.0], [-10.0, 6.0]])
    st = _Steering()
    u = st.directions(corners)
    f = np.arange(1, n + 1) / (n + 1)
    want = np.stack(np.meshgrid(np.radians(-10 + 20 * f), np.radians(-6 + 12 * f),
                                indexing="ij"), -1).reshape(-1, 2)
    np.testing.assert_allclose(cell_grid(st, u, n), want, atol=1e-12)
    tri = cell_grid(st, u[[0, 1, 3]], n)
    assert 0 < len(tri) < n * n
