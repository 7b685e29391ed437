"""Tests written for the survivors of the second fresh mutation sample (``python -m
benchmarks.mutation --sample 160 --seed 4``, issue 22), built as ``test_physics_core.py``'s
(closed forms and invariants on grids, through public functions, no module-scoped fixtures:
mutmut attributes a shared fixture to the first test that built it).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.constants import c

from conftest import ROOT, make_scene
from test_physics_core import _small_noiseless


# -- analysis.coverage: the binding constraint of a planned arc ------------------------------


@pytest.mark.parametrize("cov_deg", [(0.0, 12.0), (-20.0, 20.0), (0.0, 34.5), (0.0, 34.9)])
def test_planned_arc_is_bound_by_resolution_when_the_fewest_front_ends_suffice(cov_deg):
    """Without extra front ends the arc has at least n_bare = ceil(span / res) + 1 front ends
    (res = 1.22 lambda / d_A, eq. 24); its binding constraint is the resolution exactly when it
    has n_bare, the near-field bias when widening the span by the outer biases needs more."""
    from rtsgeom.analysis.coverage import plan_arc
    from rtsgeom.geometry import build_setup
    from rtsgeom.geometry.farfield import angular_resolution_rad
    scene = make_scene()
    a, b = (math.radians(x) for x in cov_deg)
    res = angular_resolution_rad(build_setup(scene).rut)
    n_bare = max(2, math.ceil((b - a) / res * (1 - 1e-12)) + 1)
    p = plan_arc(scene, (a, b), 1.0)
    assert p.front_ends >= n_bare
    assert p.binding[0] == ("resolution" if p.front_ends == n_bare else "near-field bias")
    assert p.resolution_deg == pytest.approx(math.degrees(res), rel=1e-12)


def test_coverage_designs_plan_every_radius_for_the_coverage_in_degrees():
    """``coverage_designs`` takes the coverage in degrees: each design's plan is
    ``plan_arc`` of the same coverage in radians at its radius."""
    from rtsgeom.analysis.coverage import coverage_designs, plan_arc
    scene = make_scene()
    out = coverage_designs(scene, (0.0, 12.0), [2.0], draws=2, points=3, extras=(0,))
    assert out.coverage_deg == (0.0, 12.0) and len(out.designs) == 1
    for r, d in zip((2.0,), out.designs):
        ref = plan_arc(scene, (0.0, math.radians(12.0)), r)
        assert d.plan.radius_m == r
        assert d.plan.angles_deg == pytest.approx(ref.angles_deg, abs=1e-12)


# -- geometry.setup: the RuT's yaw error ------------------------------------------------------


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


# -- geometry.patterns: the power gain of a pattern --------------------------------------------


@pytest.mark.parametrize("hpbw_deg, peak_db", [(60.0, 0.0), (30.0, 6.0), (120.0, -3.0)])
def test_pattern_gain_db_is_twenty_log_of_the_field_and_finite_behind(hpbw_deg, peak_db):
    """``gain_db_towards`` is 20 log10 |field| (field gain, so the power gain in dB) on a grid
    of directions: peak_gain_db at boresight, -3 dB at half the half-power beamwidth, and a
    finite floor (not -inf) behind the antenna, where the field is 0."""
    from rtsgeom.geometry.patterns import CosinePattern
    pat = CosinePattern(math.radians(hpbw_deg), peak_gain_db=peak_db)
    th = np.radians(np.linspace(-89.0, 89.0, 37))
    v = np.stack([np.sin(th), np.cos(th), np.zeros_like(th)], -1)
    g = pat.gain_db_towards(v)
    np.testing.assert_allclose(g, 20 * np.log10(np.abs(pat.field(v))), atol=1e-9)
    half = math.radians(hpbw_deg / 2)
    edge = pat.gain_db_towards(np.array([math.sin(half), math.cos(half), 0.0]))
    assert float(edge) == pytest.approx(peak_db - 10 * math.log10(2), abs=1e-6)
    assert float(pat.gain_db_towards(np.array([0.0, 1.0, 0.0]))) == pytest.approx(peak_db)
    behind = pat.gain_db_towards(np.array([[0.0, -1.0, 0.0], [0.3, -0.9, 0.0]]))
    assert np.all(np.isfinite(behind)) and np.all(behind < -1000)


# -- radar.processing / capture: empty detections, the xarray export, bad captures ----------


@pytest.mark.parametrize("preset", ["awr1843boost", "iwr6843isk"])
def test_a_silent_cube_has_no_detections_and_empty_angles(preset):
    """No echo (an empty program, no noise): CFAR finds nothing and every column of the
    detection list is empty, the angles included (D = 1 and D = 2 arrays)."""
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.radar.frame import simulate
    from rtsgeom.radar.processing import process
    from rtsgeom.rts import RtsProgram
    setup = build_setup(_small_noiseless(lambda d: d["radar"].update(antenna_preset=preset)))
    _, cube = simulate(setup, exact_paths(setup), RtsProgram.build([], [], [], [], []))
    rd, det = process(cube)
    assert len(det) == 0
    for name in ("range_m", "velocity_mps", "angle_rad", "power_db", "snr_db"):
        assert getattr(det, name).shape == (0,), name
    da = rd.to_xarray()
    assert da.attrs["description"] == "sum over virtual channels of |X|^2"
    assert da.dims == ("range_m", "velocity_mps") and da.shape == rd.power.shape


@pytest.mark.parametrize("bad", ["real", "2d"])
def test_a_capture_that_is_not_a_complex_3d_cube_is_refused(tmp_path, bad):
    """``read_capture`` refuses a ``.npy`` whose data is real (a 3-D cube of floats) or complex
    but not 3-D, naming the file."""
    from rtsgeom.geometry import build_setup
    from rtsgeom.radar.capture import read_capture, simulate_capture, write_capture
    setup = build_setup(_small_noiseless())
    cap = simulate_capture(setup, 0, seed=1)
    out = tmp_path / "cap.npy"
    write_capture(cap, setup.rut, out, "npy")
    data = np.real(cap.data) if bad == "real" else cap.data[0]
    np.save(out, data)
    with pytest.raises(ValueError, match="cap.npy: expected a complex"):
        read_capture(out)
