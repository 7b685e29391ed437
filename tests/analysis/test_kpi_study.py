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
