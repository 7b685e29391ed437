"""Tests of ``rtsgeom.analysis.coverage``: closed forms and invariants on grids of inputs."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import make_scene


def test_arc_scene_copies_the_first_front_end_without_its_errors():
    """``arc_scene`` places copies of the first front end (layout, cables) at the given angles
    on the given radius with none of its mounting or channel errors: the modules sit exactly
    on the arc at their angles, unrotated, whatever errors the template had."""
    from rtsgeom.analysis.coverage import arc_scene
    from rtsgeom.geometry import build_setup

    def errors(doc):
        fe = doc["rts"]["front_ends"][0]
        fe.update(radial_offset_mm=0.4, tangential_offset_mm=-0.3, height_offset_mm=0.7,
                  yaw_offset_deg=1.5, pitch_offset_deg=-2.0, gain_offset_db=3.0,
                  phase_offset_deg=20.0)
    scene = make_scene(errors)
    angles = np.radians([-6.0, 2.0, 10.0])
    for radius in (1.0, 2.5):
        variant, _ = arc_scene(scene, radius, angles)
        clean, _ = arc_scene(make_scene(), radius, angles)
        assert len(variant.rts.front_ends) == 3
        for fe in variant.rts.front_ends:
            assert (fe.radial_offset_m, fe.tangential_offset_m, fe.height_offset_m,
                    fe.yaw_offset_rad, fe.pitch_offset_rad, fe.gain_offset_db,
                    fe.phase_offset_rad) == (0.0,) * 7
            assert fe.cable_length_m == scene.rts.front_ends[0].cable_length_m
        s, s0 = build_setup(variant), build_setup(clean)
        np.testing.assert_allclose(s.fe.module, s0.fe.module, atol=1e-12)
        np.testing.assert_allclose(s.fe_azimuth_rad(), angles, atol=1e-9)
        d = np.linalg.norm(s.fe.module - s.fe.arc_centre, axis=-1)
        np.testing.assert_allclose(d, radius, atol=1e-12)


def test_planned_arc_reports_the_outer_front_ends_near_field_bias():
    """``plan_arc``'s outer bias is each outer front end's detected minus module angle (the
    near-field bias, README ~+0.57 deg at 1 m with 20 mm separation): positive, first order
    in 1/R (half at twice the radius), and what ``evaluate_arc`` carries over; the arc's
    calibrated nominal synthesis is exact."""
    from rtsgeom.analysis.coverage import evaluate_arc, plan_arc
    scene = make_scene()
    cov = (math.radians(0.0), math.radians(12.0))
    p1, p2 = plan_arc(scene, cov, 1.0), plan_arc(scene, cov, 2.0)
    b1, b2 = np.array(p1.outer_bias_deg), np.array(p2.outer_bias_deg)
    assert np.all(b1 > 0.3) and np.all(b1 < 0.9)
    np.testing.assert_allclose(b1 / b2, 2.0, rtol=0.1)
    ev = evaluate_arc(p2, draws=20, points=3)
    assert ev.plan.outer_bias_deg == p2.outer_bias_deg and ev.problem is None
    assert ev.worst_calibrated_deg < 1e-3
    assert 0.0 <= ev.tolerance_yield <= 1.0 and ev.sigma_mm > 0


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
    seen = []
    out = coverage_designs(scene, (0.0, 12.0), [2.0], draws=2, points=3, extras=(0,),
                           progress=lambda done, total: seen.append((done, total)))
    assert out.coverage_deg == (0.0, 12.0) and len(out.designs) == 1
    assert seen == [(1, 1)]  # progress(done, total) after each design
    # the table: one row per design, each column the design's value under its own name
    df = out.to_dataframe()
    row = out.designs[0].to_dict()
    assert len(df) == 1 and set(df.columns) <= set(row), set(df.columns) - set(row)
    for k in df.columns:
        assert df[k].iloc[0] == row[k] or (row[k] is None and df[k].isna().iloc[0]), k
    assert {"worst_calibrated_deg", "worst_uncalibrated_deg", "sigma_mm"} <= set(df.columns)
    for r, d in zip((2.0,), out.designs):
        ref = plan_arc(scene, (0.0, math.radians(12.0)), r)
        assert d.plan.radius_m == r
        assert d.plan.angles_deg == pytest.approx(ref.angles_deg, abs=1e-12)


def test_a_scene_with_its_own_errors_gets_the_whole_warning(default_scene):
    from conftest import DRAWS_REPLACE_TEXT, moved_front_end, the_warnings
    from rtsgeom.analysis.coverage import coverage_designs
    from rtsgeom.errors import NominalSetupWarning
    assert the_warnings(lambda: coverage_designs(moved_front_end(default_scene), (-10.0, 10.0),
                                                 [1.0], draws=20, points=5),
                        NominalSetupWarning) == ["design " + DRAWS_REPLACE_TEXT]


def test_coverage_refuses_unknown_options_in_full_words(default_scene):
    from conftest import assert_refused
    from rtsgeom.analysis.coverage import coverage_designs
    assert_refused(lambda: coverage_designs(default_scene, (-10.0, 10.0), [1.0], foo=1, bar=2),
                   "coverage_designs: no option foo, bar (points, extras, progress, workers)")
