"""Tests of ``rtsgeom.analysis.coverage``: closed forms and invariants on grids of inputs."""

from __future__ import annotations

import dataclasses
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


# -- the grid of candidate arcs as a result: summary, table, best pick, maps, folder ----------

def _arc(r, n, extra, cal, unc=0.3, sigma=0.2, problem=None):
    from rtsgeom.analysis.coverage import ArcDesign, ArcPlan
    plan = ArcPlan(None, r, n, tuple(np.linspace(-10, 10, n)), 20 / (n - 1), 17.5, 3.0,
                   (0.1, -0.1), "kept", "sheet kept", ("resolution",), extra)
    return ArcDesign(plan, cal, unc, sigma, False, problem, 0.02, 0.97, 0.5, 0.3, 0.95)


def _grid(designs, radii=(0.5, 1.0), spec=0.1):
    from rtsgeom.analysis.coverage import CoverageDesign
    return CoverageDesign((-10.0, 12.5), np.array(radii), spec, 0.95, 100, tuple(designs),
                          "bench")


@pytest.mark.parametrize("designs, best", [
    # both meet the spec (the bound itself meets it): the fewest front ends
    ([_arc(0.5, 3, 0, 0.1), _arc(0.5, 4, 1, 0.01)], [(0.5, 3)]),
    # the fewer misses by a hair: the other
    ([_arc(0.5, 3, 0, 0.1000001), _arc(0.5, 4, 1, 0.01)], [(0.5, 4)]),
    # equal counts: the larger tolerance
    ([_arc(0.5, 3, 0, 0.05, sigma=0.2), _arc(0.5, 3, 1, 0.05, sigma=0.4)], [(0.5, 3, 0.4)]),
    # none meets it: the smallest worst error
    ([_arc(0.5, 3, 0, 0.3), _arc(0.5, 4, 1, 0.2)], [(0.5, 4)]),
    # a problem or a NaN error is no candidate; a radius without one is left out
    ([_arc(0.5, 3, 0, 0.01, problem="x"), _arc(0.5, 4, 1, math.nan), _arc(1.0, 5, 0, 0.2)],
     [(1.0, 5)]),
])
def test_the_best_arc_per_radius_is_the_fewest_front_ends_meeting_the_spec(designs, best):
    from rtsgeom.analysis.coverage import best_per_radius
    got = best_per_radius(_grid(designs))
    assert [(d.plan.radius_m, d.plan.front_ends, d.sigma_mm)[:len(b)] for d, b in
            zip(got, best)] == best and len(got) == len(best)


def test_the_coverage_grids_summary_and_table_in_full():
    grid = _grid([_arc(0.5, 3, 0, 0.01234, 0.5678, 0.25), _arc(0.5, 4, 1, math.nan,
                                                              problem="missed"),
                  _arc(1.0, 3, 0, 0.2, 0.3, 0.125), _arc(1.0, 4, 1, 0.05, 0.25, 0.5)])
    title, rows = grid._summary()
    assert title == "arcs covering -10..12.5 deg: 2 radii x 2 candidates"
    assert rows == [
        ("spec", "0.1 deg, 95 % of whole arcs, 100 draws"),
        ("R_c 0.5 m", "3 front ends 10 deg apart, worst 0.0123 deg calibrated (0.568 "
                      "uncalibrated), sigma 0.25 mm"),
        ("R_c 1 m", "4 front ends 6.67 deg apart, worst 0.05 deg calibrated (0.25 "
                    "uncalibrated), sigma 0.5 mm")]
    df = grid.to_dataframe()
    assert list(df.columns) == ["radius_m", "front_ends", "extra", "spacing_deg", "sheet",
                                "worst_calibrated_deg", "worst_uncalibrated_deg", "sigma_mm",
                                "problem"]
    assert df["radius_m"].tolist() == [0.5, 0.5, 1.0, 1.0]
    assert df["front_ends"].tolist() == [3, 4, 3, 4]
    assert df["extra"].tolist() == [0, 1, 0, 1]
    assert df["spacing_deg"].tolist() == pytest.approx([10.0, 20 / 3, 10.0, 20 / 3])
    assert df["sheet"].tolist() == ["kept"] * 4
    assert df["worst_calibrated_deg"].tolist()[::2] == [0.01234, 0.2]
    assert math.isnan(df["worst_calibrated_deg"][1])
    assert df["worst_uncalibrated_deg"].tolist() == [0.5678, 0.3, 0.3, 0.25]
    assert df["sigma_mm"].tolist() == [0.25, 0.2, 0.125, 0.5]
    assert [p if isinstance(p, str) else None for p in df["problem"]] == [None, "missed", None,
                                                                            None]
    assert df["problem"].isna().tolist() == [True, False, True, True]


@pytest.mark.parametrize("name, label, what, floor", [
    ("worst_calibrated_deg", "worst |angle error| (deg)", "Calibrated, over the coverage",
     0.001),
    ("worst_uncalibrated_deg", "worst |angle error| (deg)", "Uncalibrated, over the coverage",
     0.001),
    ("sigma_mm", "mounting sigma (mm)", "Tolerance for the yield (whole arc)", None),
    ("front_ends", "front ends", "Number of front ends", None),
])
def test_each_coverage_map_draws_its_values_with_its_labels(monkeypatch, name, label, what,
                                                            floor):
    import rtsgeom.viz.figures as figures
    seen = {}
    monkeypatch.setattr(figures, "design_heatmap_figure",
                        lambda *a, **kw: seen.update(args=a, kw=kw) or "fig")
    designs = [_arc(0.5, 3, 0, 0.01, 0.5, 0.25), _arc(0.5, 4, 1, math.nan, problem="p"),
               _arc(1.0, 3, 0, 0.2, 0.3, 0.125), _arc(1.0, 5, 2, 0.05, 0.25, 0.5)]
    grid = _grid(designs)
    assert grid.plot(name) == "fig"
    x, y, z, xl, yl, zl, title = seen["args"]
    assert x.tolist() == [0.5, 1.0] and y.tolist() == [0.0, 1.0, 2.0]
    want = np.full((3, 2), np.nan)
    for d in designs:
        v = getattr(d, name) if name != "front_ends" else d.plan.front_ends
        want[d.plan.extra, int(d.plan.radius_m == 1.0)] = v
    np.testing.assert_array_equal(z, want)
    assert (xl, yl, zl) == ("arc radius R_c (m)", "front ends beyond the fewest", label)
    assert title == (f"bench: {what}\ncoverage -10..12.5 deg, spec 0.1 deg, 95 % yield, "
                     "100 draws")
    assert seen["kw"] == {"contour_floor": floor, "integer_y": True,
                          "integer_z": name == "front_ends"}
    unnamed = dataclasses.replace(grid, scene_name="")
    unnamed.plot(name)
    assert seen["args"][-1].startswith(f"{what}\ncoverage")


def test_an_unknown_coverage_map_is_refused_naming_the_maps():
    from rtsgeom.errors import ParameterError
    with pytest.raises(ParameterError) as e:
        _grid([_arc(0.5, 3, 0, 0.01)]).plot("yield")
    assert str(e.value) == ("map 'yield': one of worst_calibrated_deg, worst_uncalibrated_deg, "
                            "sigma_mm, front_ends")


def test_the_coverage_folder_is_a_map_per_name_and_the_json(monkeypatch, tmp_path):
    import json

    import rtsgeom.viz.figures as figures
    saved = []
    monkeypatch.setattr(figures, "design_heatmap_figure", lambda *a, **kw: a[-1])
    monkeypatch.setattr(figures, "save_figure", lambda fig, path: saved.append((fig, path)))
    grid = _grid([_arc(0.5, 3, 0, 0.01), _arc(1.0, 4, 1, math.nan, problem="p")])
    names = grid.write(tmp_path)
    maps = ["worst_calibrated_deg", "worst_uncalibrated_deg", "sigma_mm", "front_ends"]
    assert names == [f"coverage_{m}.png" for m in maps] + ["coverage.json"]
    assert [p for _, p in saved] == [tmp_path / f"coverage_{m}.png" for m in maps]
    assert [f.split("\n")[0] for f, _ in saved] == [
        "bench: Calibrated, over the coverage", "bench: Uncalibrated, over the coverage",
        "bench: Tolerance for the yield (whole arc)", "bench: Number of front ends"]
    d = json.loads((tmp_path / "coverage.json").read_text())
    assert d == json.loads(json.dumps(grid.to_dict()))
    assert d["designs"][1]["worst_calibrated_deg"] is None  # NaN written as null
    assert [b["radius_m"] for b in d["best"]] == [0.5]
    assert (d["coverage_deg"], d["radius_m"], d["spec_deg"], d["yield"], d["draws"]) == (
        [-10.0, 12.5], [0.5, 1.0], 0.1, 0.95, 100)


@pytest.mark.parametrize("sheet, enabled, spacing_deg, text", [
    ("kept", True, 5.0, "sheet kept"),
    ("widened", True, 5.0, "sheet widened to [-20.50, 31.25] deg"),
    ("disabled", True, 2.5, "sheet REMOVED: cutouts of 50 mm need 2.87 deg spacing, the design "
                            "has 2.50 deg"),
    ("disabled", True, 3.0, "sheet REMOVED (its cutouts cannot hold the antennas or it would not "
                            "enclose the RuT)"),
    ("disabled", False, 2.5, "no sheet in the scene"),
])
def test_what_an_arc_did_to_the_sheet_in_words(sheet, enabled, spacing_deg, text):
    from types import SimpleNamespace

    from rtsgeom.analysis.coverage import _sheet_text
    scene = SimpleNamespace(sheet=SimpleNamespace(enabled=enabled, cutout_diameter_m=0.05))
    variant = SimpleNamespace(sheet=SimpleNamespace(angle_min_rad=math.radians(-20.5),
                                                    angle_max_rad=math.radians(31.25)))
    cut = 2 * math.asin(0.025)  # 50 mm at 1 m
    assert _sheet_text(scene, variant, sheet, math.radians(spacing_deg), cut) == text
    # the spacing exactly at the cutouts' need is not "too close"
    if sheet == "disabled" and enabled:
        assert _sheet_text(scene, variant, sheet, cut, cut).startswith("sheet REMOVED (its")
