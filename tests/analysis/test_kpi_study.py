"""KpiStudy's config: each declared range enforced exactly at its edges, the error naming the
field, the value and the allowed range in full; the mounting sigma it uses."""

from __future__ import annotations

import pytest

from conftest import assert_bounds
from rtsgeom.analysis.kpi.study import DEFAULT_SIGMA_MM, KpiStudy

_SIGMA = "must be one number or three (radial, tangential, height) in [0, 10] mm"
BOUNDS = [
    ("sigma_mm", [None, 0.0, 10.0, 0, (0.0, 10.0, 5.0), [1, 2, 3]],
     [(-0.5, f"sigma_mm = -0.5: {_SIGMA}"), (10.5, f"sigma_mm = 10.5: {_SIGMA}"),
      ((1.0, 1.0), f"sigma_mm = (1.0, 1.0): {_SIGMA}"),
      ((1.0, 1.0, 1.0, 1.0), f"sigma_mm = (1.0, 1.0, 1.0, 1.0): {_SIGMA}"),
      ((1.0, 1.0, 10.5), f"sigma_mm = (1.0, 1.0, 10.5): {_SIGMA}"),
      ((-1.0, 1.0, 1.0), f"sigma_mm = (-1.0, 1.0, 1.0): {_SIGMA}"),
      ((1.0, "2", 1.0), f"sigma_mm = (1.0, '2', 1.0): {_SIGMA}"),
      ("1", f"sigma_mm = 1: {_SIGMA}")]),
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
                       "spec: must be a KpiSpec (rtsgeom.analysis.kpi.load_spec)")]),
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
