"""KpiStudy's config: each declared range enforced exactly at its edges, the error naming the
field, the value and the allowed range in full; the mounting sigma it uses."""

from __future__ import annotations

import pytest

from conftest import assert_bounds
from rtsgeom.analysis.kpi.study import DEFAULT_SIGMA_MM, KpiStudy

_SIGMA = "must be one number or three (radial, tangential, height) in [0, 10] mm"
BOUNDS = [
    ("sigma_mm", [None, 0.0, 10.0, 0, (0.0, 10.0, 5.0), [1, 2, 3]],
     [(-0.5, f"KpiStudy: sigma_mm = -0.5: {_SIGMA}"), (10.5, f"KpiStudy: sigma_mm = 10.5: {_SIGMA}"),
      ((1.0, 1.0), f"KpiStudy: sigma_mm = (1.0, 1.0): {_SIGMA}"),
      ((1.0, 1.0, 1.0, 1.0), f"KpiStudy: sigma_mm = (1.0, 1.0, 1.0, 1.0): {_SIGMA}"),
      ((1.0, 1.0, 10.5), f"KpiStudy: sigma_mm = (1.0, 1.0, 10.5): {_SIGMA}"),
      ((-1.0, 1.0, 1.0), f"KpiStudy: sigma_mm = (-1.0, 1.0, 1.0): {_SIGMA}"),
      ((1.0, "2", 1.0), f"KpiStudy: sigma_mm = (1.0, '2', 1.0): {_SIGMA}"),
      ("1", f"KpiStudy: sigma_mm = 1: {_SIGMA}"),
      (True, f"KpiStudy: sigma_mm = True: {_SIGMA}"),
      ((1.0, False, 1.0), f"KpiStudy: sigma_mm = (1.0, False, 1.0): {_SIGMA}")]),
    ("sigma_phase_deg", [None, 0.0, 90.0],
     [(-0.5, "KpiStudy: sigma_phase_deg = -0.5: must be in [0, 90] deg"),
      (90.5, "KpiStudy: sigma_phase_deg = 90.5: must be in [0, 90] deg")]),
    ("points", [1, 201], [(0, "KpiStudy: points = 0: must be in [1, 201]"),
                          (202, "KpiStudy: points = 202: must be in [1, 201]")]),
    ("draws", [100, 1_000_000], [(99, "KpiStudy: draws = 99: must be in [100, 1e+06]"),
                                 (1_000_001, "KpiStudy: draws = 1000001: must be in [100, 1e+06]")]),
    ("seed", [None, 0, 2 ** 63 - 1],
     [(-1, "KpiStudy: seed = -1: must be in [0, 9.22337e+18]"),
      (2 ** 63, "KpiStudy: seed = 9223372036854775808: must be in [0, 9.22337e+18]")]),
    ("spec", [None], [({"angle_accuracy_deg": 0.1},
                       "KpiStudy: spec = {'angle_accuracy_deg': 0.1}: must be a KpiSpec "
                       "(rtsgeom.analysis.kpi.load_spec)")]),
]


@pytest.mark.parametrize("name, ok, bad", BOUNDS, ids=[b[0] for b in BOUNDS])
def test_kpi_study_enforces_each_range_at_its_edges(name, ok, bad):
    assert_bounds(lambda v: KpiStudy(**{name: v}), ok, bad)


@pytest.mark.parametrize("sigma, want", [(None, (0.1, 0.1, 0.1)), (0.5, (0.5, 0.5, 0.5)),
                                         (2, (2.0, 2.0, 2.0)), ((0.1, 0.2, 0.3), (0.1, 0.2, 0.3))])
def test_kpi_mounting_sigma_is_per_axis_with_the_documented_default(sigma, want):
    assert DEFAULT_SIGMA_MM == 0.1
    got = KpiStudy(sigma_mm=sigma).mounting_sigma_mm()
    assert got == want and all(type(v) is float for v in got)


def test_kpi_study_repr_and_defaults():
    assert repr(KpiStudy()) == ("KpiStudy(sigma_mm=None, sigma_phase_deg=None, points=11, "
                                "draws=2000, spec=none)")
    assert repr(KpiStudy(sigma_mm=0.2, sigma_phase_deg=3.0, points=5, draws=500)) == (
        "KpiStudy(sigma_mm=0.2, sigma_phase_deg=3.0, points=5, draws=500, spec=none)")


def test_the_phase_spread_and_where_it_comes_from():
    """sigma_phase_deg where given; else the RMS of [radar.channels]' antenna phases; else an
    ideal radar's 0."""
    import math
    from types import SimpleNamespace

    def scene(ch):
        return SimpleNamespace(radar=SimpleNamespace(channels=ch))
    ch = SimpleNamespace(tx_phase_rad=(0.1, -0.2), rx_phase_rad=(0.0, 0.3, 0.0, 0.0))
    rms = math.degrees(math.sqrt((0.01 + 0.04 + 0.09) / 6))
    got, why = KpiStudy().phase_sigma_deg(scene(ch))
    assert got == pytest.approx(rms, rel=1e-12)
    assert why == "the RMS of [radar.channels]' antenna phases"
    assert KpiStudy(sigma_phase_deg=2).phase_sigma_deg(scene(ch)) == (2.0, "sigma_phase_deg")
    ideal = (0.0, "an ideal radar (no [radar.channels], no sigma_phase_deg)")
    assert KpiStudy().phase_sigma_deg(scene(None)) == ideal
    zero = SimpleNamespace(tx_phase_rad=(0.0,), rx_phase_rad=())
    assert KpiStudy().phase_sigma_deg(scene(zero)) == ideal


def test_the_studys_steps_open_and_close_in_order():
    from rtsgeom.analysis.kpi.study import _Steps
    told = []
    step = _Steps(lambda *a: told.append(a))
    step("a")
    step(None)
    step("b")
    step("c")
    step(None)
    assert told == [("a", 0, 1), ("a", 1, 1), ("b", 0, 1), ("b", 1, 1), ("c", 0, 1),
                    ("c", 1, 1)]
    quiet = _Steps(None)
    quiet("a")
    quiet(None)  # nothing to tell, nothing raised


def test_the_snr_the_budget_uses_and_where_it_comes_from():
    import math
    from types import SimpleNamespace
    from rtsgeom.analysis.kpi.study import _snr_inputs
    scene = SimpleNamespace(radar=SimpleNamespace(link=None))
    assert _snr_inputs(scene, SimpleNamespace(snr_effective=1000.0), []) == {
        "snr_effective_db": pytest.approx(30.0),
        "snr_from": "radar.snr_db per sample, after the FFTs' coherent gain"}
    assert _snr_inputs(scene, SimpleNamespace(snr_effective=None), []) == {
        "snr_effective_db": None, "snr_from": "noiseless (no radar.snr_db, no [radar.link])"}
    linked = SimpleNamespace(radar=SimpleNamespace(link=object()))
    pts = [SimpleNamespace(snr_effective_db=v) for v in (25.0, None, 21.5, 30.0)]
    assert _snr_inputs(linked, SimpleNamespace(snr_effective=None), pts) == {
        "snr_effective_db": 21.5,
        "snr_from": "the link budget ([radar.link]) per set angle, the lowest"}
    assert _snr_inputs(linked, SimpleNamespace(snr_effective=None), [])[
        "snr_effective_db"] is None
    assert math.isclose(_snr_inputs(linked, SimpleNamespace(snr_effective=10.0), pts)[
        "snr_effective_db"], 10.0)


# -- the study on scenes without a synthesizable pair, and the Datasheet's views -----------

def _no_resolution(monkeypatch):
    import rtsgeom.analysis.kpi.study as study
    called = []
    monkeypatch.setattr(study, "resolution_section",
                        lambda setup, progress: called.append(setup) or {"rts_deg": None,
                                                                         "note": "stub"})
    return called


def test_a_nearest_mode_sheet_names_its_inputs_and_why_it_has_no_accuracy(monkeypatch):
    """Every input of the budget named with where it comes from; no synthesizable pair in the
    nearest mode: no accuracy, that note; the steps told in order."""
    from conftest import CountedProgress, make_scene, quiet

    from rtsgeom.analysis.kpi.study import Datasheet

    def mutate(doc):
        quiet(doc)
        doc["radar"]["snr_db"] = 10.0
        doc["rts"]["aoa_mode"] = "nearest"
        doc["targets"] = []
    scene = make_scene(mutate)
    called = _no_resolution(monkeypatch)
    told = CountedProgress()
    sheet = KpiStudy(sigma_mm=(0.1, 0.2, 0.3), sigma_phase_deg=2.0, points=4, draws=300,
                     seed=7)(scene, told)
    assert isinstance(sheet, Datasheet) and len(called) == 1
    r = scene.radar
    from rtsgeom.analysis.kpi.accuracy import effective_snr
    import math
    assert sheet.inputs == {
        "sigma_mm": {"radial": 0.1, "tangential": 0.2, "height": 0.3}, "sigma_mm_from": "sigma_mm",
        "sigma_phase_deg": 2.0, "sigma_phase_from": "sigma_phase_deg", "snr_db": 10.0,
        "snr_effective_db": pytest.approx(10 * math.log10(effective_snr(r))),
        "snr_from": "radar.snr_db per sample, after the FFTs' coherent gain", "draws": 300,
        "seed": 7, "points_per_pair": 4,
        "delay_resolution_ps": pytest.approx(scene.rts.delay_resolution_s * 1e12)}
    assert sheet.accuracy == () and sheet.accuracy_note == "no synthesizable pair in the " \
                                                           "nearest mode"
    assert sheet.targets["resolution"] == {"rts_deg": None, "note": "stub"}
    assert sheet.scene_name == scene.name and sheet.study.points == 4 and sheet.spec is None
    steps = [c[0] for c in told.calls if c[1:] == (0, 1)]
    assert steps == ["field of view", "the signal chain on the scene's targets (rtsgeom run)",
                     "range, velocity, targets, ghosts, near field",
                     "resolution (two targets, truth beside RTS)"]
    for s in steps:
        assert told.finished(s), s
    # the defaults: the scene's seed and the documented sigma
    d = KpiStudy(draws=100)(scene)
    assert d.inputs["seed"] == scene.seed
    assert d.inputs["sigma_mm"] == {"radial": 0.1, "tangential": 0.1, "height": 0.1}
    assert d.inputs["sigma_mm_from"] == ("the default 0.1 mm (the scene declares no "
                                         "tolerance)")


def test_a_sheet_of_cells_has_no_pair_budget_and_no_resolution(monkeypatch, sphere_scene):
    import dataclasses
    called = _no_resolution(monkeypatch)
    sheet = KpiStudy(points=1, draws=100)(dataclasses.replace(sphere_scene, targets=()))
    assert called == []
    assert sheet.accuracy == () and sheet.accuracy_note == (
        "a scene of 2-D cells: the budget covers pairs on an arc (azimuth); rtsgeom tolerance "
        "--cell gives a cell's Monte Carlo")
    assert sheet.targets["resolution"] == {
        "min_separation_deg": None, "rts_deg": None, "truth_deg": None,
        "note": "a scene of 2-D cells: the resolution test covers an arc"}


def _point(pair, set_deg, err, u, validated=True, lo=-1.0, hi=1.0):
    from rtsgeom.analysis.kpi.accuracy import AnglePoint
    return AnglePoint(pair=pair, set_deg=set_deg, error_deg=err, budget=(), combined_deg=u / 2,
                      expanded_deg=u, mc_interval_deg=(lo, hi), mc_mean_deg=0.0, mc_std_deg=0.1,
                      validated=validated, end_difference=0.0)


def _datasheet(points, spec=None, resolution=None, accuracy_m=0.01):
    """A datasheet of ``points``, its other sections the headline test's."""
    import copy

    from analysis.test_kpi_headline import SHEET

    from rtsgeom.analysis.kpi.study import Datasheet
    d = copy.deepcopy(SHEET)
    rv = {**d["range_velocity"], "min_range_m": 1.6, "max_range_m": 75.0,
          "max_velocity_mps": 9.2, "range_accuracy_m": accuracy_m,
          "velocity_accuracy_mps": None if accuracy_m is None else 0.05,
          "accuracy_note": "no targets here"}
    return Datasheet(scene_name="s", study=KpiStudy(),
                     fov={**d["field_of_view"], "covered_deg": [[0.0, 10.0]]},
                     accuracy=tuple(points), accuracy_note="acc note", inputs=d["inputs"],
                     range_velocity=rv,
                     targets={**d["targets"], "total": 12,
                              "resolution": resolution or {"rts_deg": 4.0}},
                     ghosts={"ghost_suppression_db": 26.0}, nearfield=d["near_field"],
                     spec=spec)


POINTS = [_point((0, 1), 2.0, 0.1, 0.2), _point((0, 1), 5.0, -0.3, 0.1),
          _point((1, 2), 9.0, 0.0, 0.2, validated=False, lo=-0.7, hi=0.25)]


@pytest.mark.parametrize("span, worst", [
    (None, 0.7), ((2.0, 5.0), 0.4), ((2.0, 4.99), 0.3), ((2.01, 5.0), 0.4), ((5.0, 9.0), 0.7),
    ((5.01, 8.99), None)])
def test_the_worst_accuracy_over_a_span_includes_its_ends(span, worst):
    got = _datasheet(POINTS).worst_accuracy_deg(span)
    assert got == (None if worst is None else pytest.approx(worst))


def test_the_sheets_values_for_the_spec_and_their_notes():
    from rtsgeom.analysis.kpi.spec import KpiSpec
    base = {"min_range_m": 1.6, "max_range_m": 75.0, "max_velocity_mps": 9.2, "targets": 12,
            "ghost_suppression_db": 26.0}
    assert _datasheet(POINTS).spec_values() == {
        **base, "angle_accuracy_deg": pytest.approx(0.7), "azimuth_deg": None,
        "range_accuracy_m": 0.01, "velocity_accuracy_mps": 0.05, "resolution_deg": 4.0}
    got = _datasheet(POINTS, spec=KpiSpec(azimuth_deg=(-4.0, 1.5)),
                     resolution={"rts_deg": None, "note": "res note"},
                     accuracy_m=None).spec_values()
    assert got == {**base, "angle_accuracy_deg": None, "azimuth_deg": pytest.approx(4.0),
                   "range_accuracy_m": None, "velocity_accuracy_mps": None,
                   "resolution_deg": None,
                   "angle_accuracy_deg_note": "no set angle within azimuth_deg",
                   "resolution_deg_note": "res note", "range_accuracy_m_note": "no targets here",
                   "velocity_accuracy_mps_note": "no targets here"}
    assert _datasheet([]).spec_values()["angle_accuracy_deg_note"] == "acc note"


def test_the_sheets_table_summary_and_verdict():
    from rtsgeom.analysis.kpi.spec import KpiSpec
    sheet = _datasheet(POINTS)
    assert (sheet.passed, sheet.exit_code, sheet.checks) == (None, 0, ())
    df = sheet.to_dataframe()
    assert list(df.columns) == ["pair", "set_angle_deg", "error_deg", "expanded_uncertainty_deg",
                                "monte_carlo_half_width_deg", "gum_validated", "accuracy_deg"]
    assert df["pair"].tolist() == ["0-1", "0-1", "1-2"]
    assert df["set_angle_deg"].tolist() == [2.0, 5.0, 9.0]
    assert df["error_deg"].tolist() == [0.1, -0.3, 0.0]
    assert df["expanded_uncertainty_deg"].tolist() == [0.2, 0.1, 0.2]
    assert df["monte_carlo_half_width_deg"].tolist() == pytest.approx([1.0, 1.0, 0.475])
    assert df["gum_validated"].tolist() == [True, True, False]
    assert df["accuracy_deg"].tolist() == pytest.approx([0.3, 0.4, 0.7])
    met = _datasheet(POINTS, spec=KpiSpec(targets=12, max_range_m=70.0))
    assert (met.passed, met.exit_code) == (True, 0)
    title, rows = met._summary()
    assert title == "s: datasheet"
    from rtsgeom.analysis.kpi.headline import headline
    assert rows[:-2] == headline(met.to_dict())
    missed = _datasheet(POINTS, spec=KpiSpec(targets=13, resolution_deg=3.0))
    assert (missed.passed, missed.exit_code) == (False, 1)
    _, rows = missed._summary()
    assert rows[-2:] == [("spec targets", "FAIL (margin -1)"),
                         ("spec resolution_deg", "FAIL (margin -1)")]
    _, rows = met._summary()
    assert rows[-2:] == [("spec max_range_m", "pass (margin 5)"), ("spec targets",
                                                                    "pass (margin 0)")]
    none = _datasheet(POINTS, spec=KpiSpec(resolution_deg=3.0),
                      resolution={"rts_deg": None, "note": "n"})
    assert none._summary()[1][-1] == ("spec resolution_deg", "no value")
    assert (none.passed, none.exit_code) == (False, 1)
