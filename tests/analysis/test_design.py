"""Arc design map: radius x front-end spacing."""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest
from conftest import (
    DEFAULT_SCENE,
    ROOT,
    SETUP_ERRORS,
    make_scene,
    scenes_with_and_without_error,
    small_quiet,
)

from rtsgeom.analysis.design import (
    METRICS,
    DesignSpec,
    design_grid,
    evaluate_design,
    two_front_end_scene,
)
from rtsgeom.analysis.design_study import DesignStudy
from rtsgeom.analysis.tolerance.config import MonteCarlo
from rtsgeom.analysis.tolerance.phasors import ChannelPhasors
from rtsgeom.cli import main
from rtsgeom.errors import ParameterError
from rtsgeom.geometry import build_setup
from rtsgeom.geometry.farfield import angular_resolution_rad


@pytest.fixture(scope="module")
def scene():
    return make_scene()


@pytest.fixture(scope="module")
def grid(scene):
    return design_grid(scene, (0, 1), [0.5, 1.0, 2.0], [8.8, 19.0],
                       DesignSpec(draws=200, seed=1, points=11))


def test_output_shapes(grid):
    assert grid.radius_m.shape == (3,) and grid.spacing_deg.shape == (2,)
    for name in METRICS:
        assert grid.metrics[name].shape == (2, 3)
    assert grid.exceeds_resolution.shape == (2, 3)
    assert len(grid.designs) == 6
    d = grid.to_dict()
    assert len(d["designs"]) == 6 and d["radius_m"] == [0.5, 1.0, 2.0]
    json.dumps(d, allow_nan=False)


def test_spacing_above_the_angular_resolution_is_flagged(scene, grid):
    res = math.degrees(angular_resolution_rad(build_setup(scene).rut))
    assert res == pytest.approx(17.5, abs=0.05)
    assert not grid.exceeds_resolution[0].any()  # 8.8 deg
    assert grid.exceeds_resolution[1].all()  # 19 deg
    # where it is allowed, the calibrated synthesis is exact (exact amplitudes, no noise) and
    # tolerates more than the uncalibrated one
    m = grid.metrics
    assert np.all(m["worst_error_deg"][0] < 1e-3)
    # (by less with the target's sub-bin position drawn per draw: where the
    # calibration delay moves J's echo across a bin boundary the design misses; 3x measured)
    assert np.all(m["sigma_calibrated_mm"][0] > 2 * m["sigma_uncalibrated_mm"][0])


def test_near_field_bias_shrinks_with_radius(grid):
    bias = grid.metrics["near_field_bias_deg"]
    assert np.all(bias > 0) and np.all(np.diff(bias, axis=1) < 0)
    # both parts (Rx/Tx separation, Tx/Rx-group parallax) are first order in 1/R
    assert bias[0, 0] / bias[0, 2] == pytest.approx(4.0, rel=0.05)
    # and the tangential tolerance of the calibrated synthesis grows like R
    sig = grid.metrics["sigma_calibrated_mm"][0]
    assert sig[2] / sig[0] == pytest.approx(4.0, rel=0.15)


def test_synthesis_beyond_the_first_null_with_one_phase(scene):
    """16 deg is beyond the beam's first null (lambda/d_A = 14.3 deg) but within eq. 24: near
    the span's ends the other front end's beam is in its first sidelobe. Designed for the one
    phase the calibration sets, every set-point is still reached."""
    variant, sheet, problem = two_front_end_scene(scene, (0, 1), 1.0, math.radians(16.0))
    assert problem is None and sheet == "kept"
    model = ChannelPhasors.build(build_setup(variant), (0, 1), 11)
    assert np.max(np.abs(model.angle_errors(np.zeros((2, 3)), "calibrated"))) < 1e-3


@pytest.mark.parametrize("spacing_deg", [8.0, 20.0])
def test_bin_centre_solved_later_is_the_same_model(scene, spacing_deg):
    """``evaluate_design`` builds without the bin-centre root finder and adds it
    (``ChannelPhasors.solved``) only where the calibrated plan exists: the model it then has is
    the eagerly built one, bit for bit (beyond the resolution, 20 deg, the root finder runs;
    at 8 deg the closed form leaves nothing to solve)."""
    variant, _, problem = two_front_end_scene(scene, (0, 1), 1.0, math.radians(spacing_deg))
    assert problem is None
    setup = build_setup(variant)
    eager = ChannelPhasors.build(setup, (0, 1), 9)
    lazy = ChannelPhasors.build(setup, (0, 1), 9, solve_bin_centre=False)
    c0 = eager.subbin_zero
    unsolved = ~np.isfinite(lazy.procedure.design_amplitudes[c0]).all(-1)
    assert unsolved.any() == (spacing_deg > 10)
    assert np.all(np.isfinite(eager.amplitudes))
    done = lazy.procedure.solved(lazy)
    assert np.array_equal(done.amplitudes, eager.amplitudes, equal_nan=True)
    assert np.array_equal(done.procedure.design_amplitudes, eager.procedure.design_amplitudes,
                          equal_nan=True)
    # only the bin centre's unsolved set-points change
    assert np.array_equal(np.delete(done.procedure.design_amplitudes, c0, 0),
                          np.delete(lazy.procedure.design_amplitudes, c0, 0), equal_nan=True)


def test_variant_scene_and_sheet(scene):
    variant, sheet, problem = two_front_end_scene(scene, (0, 1), 0.5, math.radians(4.0))
    assert problem is None
    assert sheet == "disabled"  # 35 mm between cutouts of 50 mm
    assert not variant.sheet.enabled and variant.targets == ()
    a = [f.angle_rad for f in variant.rts.front_ends]
    assert math.degrees(a[1] - a[0]) == pytest.approx(4.0)
    assert math.degrees(0.5 * (a[0] + a[1])) == pytest.approx(7.8)
    wide, sheet, _ = two_front_end_scene(scene, (0, 1), 1.0, math.radians(50.0))
    assert sheet == "widened" and wide.sheet.angle_min_rad < math.radians(-17.2 - 1.4)


def test_cli(tmp_path, capsys):
    rc = main(["design", str(DEFAULT_SCENE), "--radius-m", "1:2:2", "--spacing-deg", "8:8:1",
               "--draws", "100", "--points", "5", "--json", "--quiet", "--out", str(tmp_path)])
    assert rc == 0
    out = json.loads(capsys.readouterr().out)
    assert [d["radius_m"] for d in out["designs"]] == [1.0, 2.0]
    assert out["designs"][0]["exceeds_resolution"] is False
    for name in METRICS:
        assert (tmp_path / f"design_{name}.png").stat().st_size > 1000
    assert json.loads((tmp_path / "design.json").read_text()) == out


def test_the_table_names_the_calibration_range_offset_and_the_map_is_the_tolerance(grid,
                                                                                    capsys):
    """The text table's offset column is the calibration's range offset (it read "offset mm",
    taken for a mounting offset), its values under it; ``DesignGrid.plot()`` draws the
    calibrated mounting tolerance (it drew worst_error_deg, about 1e-5 deg everywhere)."""
    assert main(["design", str(DEFAULT_SCENE), "--radius-m", "1:2:2", "--spacing-deg", "8:8:1",
                 "--draws", "100", "--points", "5", "--quiet"]) == 0
    lines = capsys.readouterr().out.splitlines()
    head = lines[1]
    assert "cal range offset mm" in head and "offset mm" not in head.replace(
        "cal range offset mm", "")
    col = head.index("cal range offset mm") + len("cal range offset mm")
    for row in lines[2:4]:  # right-aligned under the header
        assert row[col - 1] != " " and row[col] == " "
    title = grid.plot().axes[0].get_title()
    assert METRICS["sigma_calibrated_mm"][1] in title, title


@pytest.mark.parametrize("arg", ["2:1:3", "1:2", "1:2:x", "0:2:3", "1:2:1"])
def test_cli_rejects_bad_grids(arg, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["design", str(DEFAULT_SCENE), "--radius-m", arg, "--quiet"])
    assert exc.value.code == 2
    assert "--radius-m" in capsys.readouterr().err


def test_design_grid_in_processes_is_the_same_grid(scene, grid):
    """``workers=2`` spreads the designs over two processes: the same designs, in the same
    order, bit for bit, and the progress still counts every design once, in order."""
    seen = []
    par = design_grid(scene, (0, 1), [0.5, 1.0, 2.0], [8.8, 19.0],
                      DesignSpec(draws=200, seed=1, points=11),
                      progress=lambda done, total: seen.append((done, total)), workers=2)
    assert json.dumps(par.to_dict()) == json.dumps(grid.to_dict())
    assert seen == [(k, 6) for k in range(1, 7)]


SPHERE_SCENE = DEFAULT_SCENE.parent / "sphere4.toml"


@pytest.mark.parametrize("extra", [[], ["--coverage-deg", "0:10"], ["--json", "--pair", "0", "1"]])
def test_cli_refuses_a_scene_of_2d_cells(extra, capsys):
    """A sphere of front ends (azimuth and elevation): the arc design has no design for a
    cell; it refuses (exit 2) naming the cell's commands instead of designing one plane."""
    rc = main(["design", str(SPHERE_SCENE), "--radius-m", "1:1:1", "--spacing-deg", "8:8:1",
               "--draws", "10", "--quiet", *extra])
    cap = capsys.readouterr()
    assert rc == 2 and cap.out == ""
    assert "2-D cells" in cap.err and "tolerance SCENE --cell all" in cap.err
    assert "Traceback" not in cap.err


@pytest.mark.parametrize("where", ["front end", "target"])
@pytest.mark.parametrize("elevation_deg", [-3.0, 0.5, 5.0])
def test_design_grid_refuses_elevation(scene, where, elevation_deg):
    """Any front end or target off elevation 0 makes the scene a cell (``uses_cells``), at any
    elevation; the API raises ParameterError before any design is built."""
    import dataclasses

    from rtsgeom.scene import TargetConfig
    el = math.radians(elevation_deg)
    if where == "front end":
        fes = list(scene.rts.front_ends)
        fes[1] = dataclasses.replace(fes[1], elevation_rad=el)
        cell = dataclasses.replace(scene, rts=dataclasses.replace(scene.rts, front_ends=tuple(fes)))
    else:
        cell = dataclasses.replace(scene, targets=(TargetConfig(5.0, elevation_rad=el),))
    with pytest.raises(ParameterError, match="tolerance SCENE --cell all"):
        design_grid(cell, (0, 1), [1.0], [8.0], DesignSpec(draws=10, points=5))


@pytest.mark.parametrize("scene_file", ["diewald2022.toml", "custom-array.toml"])
@pytest.mark.parametrize("section, key, value", SETUP_ERRORS)
def test_the_scenes_own_errors_do_not_enter_the_design(scene_file, section, key, value):
    """A design is made on the nominal setup (its variant drops every mounting, channel and
    RuT pose error, ``nominal_scene``): every metric is the same with or without one, on two
    scenes. (The RuT's yaw had entered the near-field bias's geometric reference: +0.5 deg
    of 'bias' from 0.5 deg of yaw.)"""
    from rtsgeom.analysis.design import evaluate_design
    clean, moved = scenes_with_and_without_error(ROOT / "scenes" / scene_file, section, key,
                                                 value)
    a, b = (evaluate_design(s, (0, 1), 1.0, math.radians(8), DesignSpec(draws=40, points=3))
            for s in (clean, moved))
    assert a == b


@pytest.mark.parametrize("section, key, value", SETUP_ERRORS)
def test_the_scenes_own_errors_do_not_enter_a_coverage_design(section, key, value):
    """``design --coverage-deg``'s arcs are built on the nominal setup too: the same arc scene
    (and so the same bias, spacing and tolerance) with or without any one setup error."""
    from rtsgeom.analysis.coverage import arc_scene
    clean, moved = scenes_with_and_without_error(DEFAULT_SCENE, section, key, value)
    angles = np.radians([-8.0, 0.0, 8.0])
    assert arc_scene(moved, 1.2, angles) == arc_scene(clean, 1.2, angles)


def test_a_valid_scene_whose_nominal_would_break_a_target_rule_is_still_designed():
    """Zeroing a scene's negative radial offsets lengthens the air path, which lowers the
    farthest target range the rules allow: a valid scene with a target just inside its limit
    has an invalid nominal scene. The studies drop the targets; they must not refuse it
    (design, coverage and nearfield had, after their variants were made nominal)."""
    import re

    from rtsgeom.analysis.coverage import arc_scene
    from rtsgeom.analysis.nearfield import nearfield
    from rtsgeom.errors import SceneError
    from rtsgeom.geometry.setup import nominal_scene

    def moved(range_m):
        def mutate(d):
            d["rts"].update(arc_center_m=[0.0, 0.1, 0.0])
            for fe in d["rts"]["front_ends"]:
                fe["radial_offset_mm"] = -5.0
            d["targets"] = [dict(d["targets"][0], range_m=range_m)]
        return make_scene(mutate)
    with pytest.raises(SceneError) as far:
        moved(1000.0)
    limit = float(re.search(r"must be < ([0-9.]+) m", str(far.value)).group(1))
    scene = moved(limit - 0.004)  # valid as built ...
    with pytest.raises(SceneError, match="targets"):
        nominal_scene(scene)  # ... not as designed
    d = evaluate_design(scene, (0, 1), 1.0, math.radians(8), DesignSpec(draws=40, points=3))
    assert d["problem"] is None and math.isfinite(d["sigma_calibrated_mm"])
    arc_scene(scene, 1.0, np.radians([-8.0, 0.0, 8.0]))
    from rtsgeom.errors import NominalSetupWarning
    with pytest.warns(NominalSetupWarning, match=r"radial_offset_mm\) play no part"):
        assert nearfield(scene, [1.0], points=3).radius_m.size == 1



def test_design_grid_flags_spacings_beyond_the_resolution_and_reports_progress():
    """Each design says whether its spacing (seen from the RuT) exceeds 1.22 lambda / d_A, and
    ``progress(done, total)`` follows the grid."""
    from rtsgeom.analysis.design import design_grid
    from rtsgeom.geometry.farfield import angular_resolution_rad
    s = small_quiet([], samples_per_chirp=512)
    seen = []
    grid = design_grid(s, (0, 1), [1.0], [8.0, 20.0], DesignSpec(draws=20, points=5),
                       progress=lambda done, total: seen.append((done, total)))
    res = np.degrees(angular_resolution_rad(build_setup(s).rut))
    flags = {round(d["spacing_deg"]): d["exceeds_resolution"] for d in grid.designs}
    assert flags == {8: 8.0 > res, 20: 20.0 > res} == {8: False, 20: True}
    assert seen == [(1, 2), (2, 2)]



def test_the_design_study_draws_with_its_seed_and_announces_its_count(default_scene):
    """``DesignStudy(mc=MonteCarlo(seed=s))`` is ``design_grid(..., DesignSpec(seed=s))`` (not the
    default seed's), and its progress opens with the number of designs to come."""
    calls = []
    radii, spacings = (1.0,), (8.0, 12.0)
    study = DesignStudy(radius_m=radii, spacing_deg=spacings, points=3,
                        mc=MonteCarlo(draws=30, seed=7,
                                      progress=lambda *a: calls.append(a)))
    got = study(default_scene).to_dataframe()
    want = design_grid(default_scene, (0, 1), list(radii), list(spacings),
                       DesignSpec(0.1, 0.95, 30, 7, points=3)).to_dataframe()
    other = design_grid(default_scene, (0, 1), list(radii), list(spacings),
                        DesignSpec(0.1, 0.95, 30, 0, points=3)).to_dataframe()
    assert got.equals(want)
    assert not got.equals(other)  # the seed matters at 30 draws
    assert calls[0] == ("designs", 0, len(radii) * len(spacings))


def test_a_scene_with_its_own_errors_gets_the_whole_warning(default_scene):
    from conftest import DRAWS_REPLACE_TEXT, moved_front_end, the_warnings
    from rtsgeom.errors import NominalSetupWarning
    study = DesignStudy(radius_m=(1.0,), spacing_deg=(8.0,), mc=MonteCarlo(20), points=5)
    assert the_warnings(lambda: study(moved_front_end(default_scene)), NominalSetupWarning) == [
        "design " + DRAWS_REPLACE_TEXT]


def test_design_refuses_unknown_options_and_cells_in_full_words(default_scene, sphere_scene):
    from conftest import assert_refused
    from rtsgeom.analysis.design import check_azimuth_arc, design_grid
    assert_refused(lambda: design_grid(default_scene, (0, 1), [1.0], [8.0], foo=1, bar=2),
                   "design_grid: no option foo, bar (progress, workers; the rest is the "
                   "DesignSpec)")
    for name in ("design", "design scenes/sphere4.toml"):
        assert_refused(lambda: check_azimuth_arc(sphere_scene, name), (
            f"{name}: this scene's front ends form 2-D cells (azimuth and elevation); the arc "
            "design varies the azimuth spacing of front ends on an arc and synthesizes in "
            "azimuth only, it has no design for a cell: use `tolerance SCENE --cell all` (the "
            "cell's mounting tolerance), `linearity SCENE --grid N` and `nearfield SCENE` for "
            "the cell"))
    check_azimuth_arc(default_scene)


# -- DesignGrid as a result: summary, table, each map's title notes and data, the folder -------

def _grid(radii, spacings, metric_scale=1.0, mask=None, scene_name="bench"):
    from rtsgeom.analysis.design import METRICS, DesignGrid
    r, s = np.asarray(radii, float), np.asarray(spacings, float)
    z = np.outer(s, 1 / r) * metric_scale
    mask = np.zeros((s.size, r.size), bool) if mask is None else np.asarray(mask)
    return DesignGrid((0, 1), 7.8, r, s, 17.5, 0.1, 0.95, 200, 3,
                      {name: z * (k + 1) for k, name in enumerate(METRICS)}, mask, (),
                      scene_name)


def test_the_design_grids_summary_and_table_in_full():
    from rtsgeom.analysis.design import METRICS
    grid = _grid([0.5, 2.0], [4.0, 10.0, 20.0], mask=[[0, 0], [0, 0], [1, 1]])
    title, rows = grid._summary()
    assert title == "arc design of pair (0, 1) (centre 7.80 deg): 3 spacings x 2 radii"
    assert [k for k, _ in rows] == ["radius_m", "spacing_deg", "tolerance", "exceeds_resolution",
                                    *METRICS, "widest tolerance"]
    d = dict(rows)
    assert d["tolerance"] == "95 % within 0.1 deg, 200 draws, seed 3"
    assert d["exceeds_resolution"] == "2 of 6 designs (spacing > 17.50 deg, eq. 24)"
    # sigma_calibrated_mm is the 4th metric: 4 s / r, widest at s = 20, r = 0.5
    assert d["widest tolerance"] == "160 mm calibrated at R_c 0.5 m, spacing 20 deg"
    none = dataclasses.replace(grid, metrics={**grid.metrics, "sigma_calibrated_mm":
                                              np.full((3, 2), np.nan)})
    assert [k for k, _ in none._summary()[1]][-1] == "sigma_uncalibrated_mm"
    df = grid.to_dataframe()
    assert list(df.columns) == ["radius_m", "spacing_deg", *METRICS, "exceeds_resolution"]
    assert df["radius_m"].tolist() == [0.5, 2.0] * 3
    assert df["spacing_deg"].tolist() == [4.0, 4.0, 10.0, 10.0, 20.0, 20.0]
    assert df["worst_error_deg"].tolist() == [8.0, 2.0, 20.0, 5.0, 40.0, 10.0]
    assert df["exceeds_resolution"].tolist() == [False] * 4 + [True] * 2


@pytest.mark.parametrize("radii, spacings, scale, mask, lines, notes", [
    ([0.5, 2.0], [4.0, 10.0], 1.0, [[0, 0], [0, 0]], False, ""),
    ([0.5, 2.0], [4.0, 20.0], 1.0, [[0, 0], [1, 1]], False,
     "\nhatched: spacing > 17.5 deg (eq. 24)"),
    ([1.0], [4.0, 20.0], 1.0, [[0], [1]], True, "\nhollow: spacing > 17.5 deg (eq. 24)"),
    ([0.5, 2.0], [4.0], 1.0, [[0, 0]], True, ""),
    # every value below the floor (0.01 x spec for the worst error): said, with the mask's note
    ([0.5, 2.0], [4.0, 20.0], 1e-5, [[0, 0], [1, 1]], False,
     "\nevery value below 0.001 (colours 0..0.001); hatched: spacing > 17.5 deg (eq. 24)"),
])
def test_the_design_maps_title_notes_and_data(monkeypatch, radii, spacings, scale, mask, lines,
                                              notes):
    import rtsgeom.viz.figures as figures
    seen = {}
    for name in ("design_heatmap_figure", "design_lines_figure"):
        monkeypatch.setattr(figures, name, lambda *a, _n=name, **kw: seen.update(
            kind=_n, args=a, kw=kw) or "fig")
    grid = _grid(radii, spacings, scale, mask)
    assert grid.plot("worst_error_deg") == "fig"
    assert seen["kind"] == ("design_lines_figure" if lines else "design_heatmap_figure")
    r, s, z, xl, yl, zl, title = seen["args"]
    assert r is grid.radius_m and s is grid.spacing_deg
    assert z is grid.metrics["worst_error_deg"]
    assert (xl, yl, zl) == ("arc radius R_c (m)", "front-end spacing (deg)",
                            "worst |angle error| (deg)")
    assert title == ("bench: Synthesized angle after calibration\npair (0, 1), spec 0.1 deg, "
                     "95 % yield, 200 draws" + notes)
    assert seen["kw"].keys() == ({"mask"} if lines else {"mask", "contour_floor"})
    np.testing.assert_array_equal(seen["kw"]["mask"], np.asarray(mask, bool))
    if not lines:
        assert seen["kw"]["contour_floor"] == pytest.approx(0.001)


@pytest.mark.parametrize("metric, label, what, floor", [
    ("near_field_bias_deg", "detected - geometric (deg)", "Near-field bias of one front end",
     0.001),
    ("range_offset_mm", "range offset (mm)", "Calibration range offset", 0.01),
    ("sigma_calibrated_mm", "mounting sigma (mm)", "Tolerance for the spec, calibrated", 0.001),
    ("sigma_uncalibrated_mm", "mounting sigma (mm)", "Tolerance for the spec, uncalibrated",
     0.001),
])
def test_each_design_map_has_its_label_title_and_floor(monkeypatch, metric, label, what, floor):
    import rtsgeom.viz.figures as figures
    seen = {}
    monkeypatch.setattr(figures, "design_heatmap_figure",
                        lambda *a, **kw: seen.update(args=a, kw=kw) or "fig")
    grid = _grid([0.5, 2.0], [4.0, 10.0], scene_name="")
    grid.plot(metric)
    assert seen["args"][5:] == (label, f"{what}\npair (0, 1), spec 0.1 deg, 95 % yield, "
                                       "200 draws")
    assert seen["kw"]["contour_floor"] == pytest.approx(floor)


def test_an_unknown_design_map_is_refused_naming_the_metrics():
    from rtsgeom.errors import ParameterError
    with pytest.raises(ParameterError) as e:
        _grid([1.0], [4.0]).plot("yield")
    assert str(e.value) == ("metric 'yield': one of worst_error_deg, near_field_bias_deg, "
                            "range_offset_mm, sigma_calibrated_mm, sigma_uncalibrated_mm")


def test_the_design_folder_is_a_map_per_metric_and_the_json(monkeypatch, tmp_path):
    import json

    import rtsgeom.viz.figures as figures
    from rtsgeom.analysis.design import METRICS
    saved = []
    monkeypatch.setattr(figures, "design_heatmap_figure", lambda *a, **kw: a[-1])
    monkeypatch.setattr(figures, "save_figure", lambda fig, path: saved.append((fig, path)))
    grid = dataclasses.replace(_grid([0.5, 2.0], [4.0, 10.0]),
                               designs=({"radius_m": 0.5, "worst_error_deg": float("nan")},))
    names = grid.write(tmp_path)
    assert names == [f"design_{m}.png" for m in METRICS] + ["design.json"]
    assert [p for _, p in saved] == [tmp_path / f"design_{m}.png" for m in METRICS]
    assert [f.split("\n")[0] for f, _ in saved] == [f"bench: {w}" for _, w in METRICS.values()]
    d = json.loads((tmp_path / "design.json").read_text())
    assert d == {"pair": [0, 1], "centre_deg": 7.8, "radius_m": [0.5, 2.0],
                 "spacing_deg": [4.0, 10.0], "angular_resolution_deg": 17.5, "spec_deg": 0.1,
                 "yield": 0.95, "draws": 200, "seed": 3,
                 "designs": [{"radius_m": 0.5, "worst_error_deg": None}]}
