"""Tests of ``rtsgeom.analysis.linearity``: closed forms and invariants on grids of inputs."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import small_noiseless

from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths


def test_2d_error_map_exact_mode_puts_every_grid_point_on_its_direction():
    """sphere4 as built = nominal (no errors, noiseless): ``exact`` amplitudes synthesize
    every grid point inside the four front ends' cell at its (azimuth, elevation) through
    the whole chain (1e-4 deg); ``array-factor`` (closed form, no near field) is off by a
    finite amount. The n x n grid inside a rectangular cell keeps all n^2 points."""
    from rtsgeom.analysis.linearity import linearity
    from rtsgeom.scene import load_scene
    sc = load_scene("scenes/sphere4.toml")
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
