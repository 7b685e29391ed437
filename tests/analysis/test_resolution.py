"""Tests of ``rtsgeom.analysis.resolution``: closed forms and invariants on grids of inputs."""

from __future__ import annotations

import numpy as np
import pytest

from rtsgeom.analysis.resolution import ResolutionStudy
from rtsgeom.errors import ParameterError


@pytest.mark.parametrize("seps", [(0.0,), (5.0, 121.0), (-1.0,)])
def test_a_bad_separation_says_the_allowed_range(seps):
    with pytest.raises(ParameterError, match=r"separations in \(0, 120\] deg"):
        ResolutionStudy(separations_deg=seps)


# -- the config: each declared range enforced exactly at its edges, in full words --

RESOLUTION_BOUNDS = [
    ("velocity_mps", [-1e3, 1e3],
     [(-1000.5, "resolution: velocity_mps = -1000.5: must be in [-1000, 1000] m/s"),
      (1000.5, "resolution: velocity_mps = 1000.5: must be in [-1000, 1000] m/s")]),
    ("rcs_dbsm", [-100.0, 100.0],
     [(-100.5, "resolution: rcs_dbsm = -100.5: must be in [-100, 100] dBsm"),
      (100.5, "resolution: rcs_dbsm = 100.5: must be in [-100, 100] dBsm")]),
    ("range_m", [None, 0.1, 1e4],
     [(0.05, "resolution: range_m = 0.05: must be in [0.1, 10000] m"),
      (10000.5, "resolution: range_m = 10000.5: must be in [0.1, 10000] m")]),
    ("centre_deg", [None, -90.0, 90.0],
     [(-90.5, "resolution: centre_deg = -90.5: must be in [-90, 90] deg"),
      (90.5, "resolution: centre_deg = 90.5: must be in [-90, 90] deg")]),
    ("amplitudes", [None, "exact", "array-factor", "paper", "nearest"],
     [("ideal", "resolution: amplitudes = 'ideal': must be one of exact, array-factor, paper, "
                "nearest")]),
    ("separations_deg", [(), (120.0,), (1e-3, 2.0)],
     [((0.0,), "resolution: separations_deg = (0.0,): must be separations in (0, 120] deg"),
      ((-1.0, 2.0), "resolution: separations_deg = (-1.0, 2.0): must be separations in "
                    "(0, 120] deg"),
      ((120.5,), "resolution: separations_deg = (120.5,): must be separations in (0, 120] deg"),
      ((float("nan"),), "resolution: separations_deg = (nan,): must be separations in "
                        "(0, 120] deg"),
      ((float("inf"),), "resolution: separations_deg = (inf,): must be separations in "
                        "(0, 120] deg"),
      (((1.0, 2.0),), "resolution: separations_deg = ((1.0, 2.0),): must be separations in "
                      "(0, 120] deg")]),
    ("phases_deg", [(-360.0, 360.0), (0.0,)],
     [((), "resolution: phases_deg = (): must be one or more phases in [-360, 360] deg"),
      ((360.5,), "resolution: phases_deg = (360.5,): must be one or more phases in "
                 "[-360, 360] deg"),
      ((0.0, -360.5), "resolution: phases_deg = (0.0, -360.5): must be one or more phases in "
                      "[-360, 360] deg"),
      (((0.0, 1.0),), "resolution: phases_deg = ((0.0, 1.0),): must be one or more phases in "
                      "[-360, 360] deg")]),
]


@pytest.mark.parametrize("name, ok, bad", RESOLUTION_BOUNDS,
                         ids=[r[0] for r in RESOLUTION_BOUNDS])
def test_resolution_study_enforces_each_range_at_its_edges(name, ok, bad):
    from conftest import assert_bounds
    assert_bounds(lambda v: ResolutionStudy(**{name: v}), ok, bad)


@pytest.mark.parametrize("seps, phases", [(10_000, 2), (5_000, 4), (20_000, 1)])
def test_resolution_cases_are_capped_at_twenty_thousand(seps, phases):
    """separations x phases <= 20 000 is taken; one more separation is refused naming both
    counts."""
    s = tuple(np.linspace(0.01, 120.0, seps))
    ResolutionStudy(separations_deg=s, phases_deg=(0.0,) * phases)
    with pytest.raises(ParameterError) as exc:
        ResolutionStudy(separations_deg=s + (1.0,), phases_deg=(0.0,) * phases)
    assert str(exc.value) == (f"resolution: {seps + 1} separations x {phases} phases: at most "
                              "20000 cases")


def test_separations_the_arc_cannot_reach_are_refused(default_scene):
    from conftest import assert_refused
    assert_refused(lambda: ResolutionStudy(centre_deg=60.0)(default_scene),
                   "resolution: the arc reaches no separation of 2 deg or more about centre_deg "
                   "60: give separations_deg")
    with pytest.raises(ParameterError) as exc:
        ResolutionStudy(separations_deg=(100.0,))(default_scene)
    assert str(exc.value).startswith("resolution: separations_deg up to 100 about centre_deg "
                                     "7.8: ")
    assert str(exc.value).endswith(": must be within the measured span of the front ends "
                                   "[3.9728, 12.7565] deg (no pair can reach it)")


# -- the result as it shows itself: headline, summary, table and CSV in full ----------------


def _result(table_rows, seps, phases, **over):
    """A Resolution of a made-up table (rows in the order separation, phase, source)."""
    from rtsgeom.analysis.resolution import Resolution, ResolutionStudy, _table
    study = ResolutionStudy(separations_deg=tuple(seps), phases_deg=tuple(phases))
    fields = dict(scene_name="bench", study=study, range_m=12.5, centre_deg=7.75,
                  table=_table(table_rows, seps, phases))
    fields.update(over)
    return Resolution(**fields)


def _rows(seps, phases, resolved):
    """Rows of a table; ``resolved(source, phase, sep)`` says which; the angles tell the row."""
    return [{"phase_deg": float(p), "source": src, "resolved": resolved(src, p, s),
             "angle_1_deg": s + p / 1000 + (src == "rts") / 10, "angle_2_deg": float("nan")}
            for s in seps for p in phases for src in ("truth", "rts")]


SEPS, PHASES = (4.0, 6.0, 8.0, 10.0), (0.0, 90.0, -45.5)


def _resolved(src, p, s):
    if src == "truth":
        return s >= 6.0 if p == 0.0 else s != 6.0  # 6 from phase 0; 8 after a gap at 90
    return p == 90.0 and s >= 10.0  # the rts: only the largest, at one phase


def test_the_resolution_table_is_the_rows_as_columns_in_order():
    from rtsgeom.analysis.resolution import _table
    rows = _rows(SEPS, PHASES, _resolved)
    t = _table(rows, SEPS, PHASES)
    assert list(t) == ["separation_deg", "phase_deg", "source", "resolved", "angle_1_deg",
                       "angle_2_deg"]
    assert t["separation_deg"].tolist() == [s for s in SEPS for _ in range(6)]
    assert t["phase_deg"].tolist() == [p for _ in SEPS for p in PHASES for _ in range(2)]
    assert t["source"].tolist() == ["truth", "rts"] * 12
    for key in ("resolved", "angle_1_deg"):
        assert t[key].tolist() == [r[key] for r in rows]
    assert np.isnan(t["angle_2_deg"]).all()
    cols = _result(rows, SEPS, PHASES)._columns()
    assert list(cols) == list(t)
    for key in ("separation_deg", "phase_deg", "source", "resolved", "angle_1_deg"):
        np.testing.assert_array_equal(cols[key], t[key])


def test_the_minimum_separation_per_source_and_phase_and_the_summary_in_full():
    """min_separation_deg: {source: {phase as %g: the start of the resolved tail or None}},
    the phases in the study's order; the summary names each source's minima and the title
    the targets' centre, range and separations."""
    res = _result(_rows(SEPS, PHASES, _resolved), SEPS, PHASES)
    assert res.min_separation_deg == {"truth": {"0": 6.0, "90": 8.0, "-45.5": 8.0},
                                      "rts": {"0": None, "90": 10.0, "-45.5": None}}
    title, rows = res._summary()
    assert title == "bench: two targets at 7.75 ± s/2 deg, 12.5 m, s 4..10 deg"
    assert rows == [("truth min separation", "6 deg at 0 deg, 8 deg at 90 deg, 8 deg at "
                                             "-45.5 deg"),
                    ("rts min separation", "- deg at 0 deg, 10 deg at 90 deg, - deg at "
                                           "-45.5 deg")]


def test_the_resolution_csv_has_six_digits_and_blank_missing_angles(tmp_path):
    seps, phases = (2.0, 12.3456789), (0.0,)
    res = _result(_rows(seps, phases, lambda *a: True), seps, phases)
    path = res.to_csv(tmp_path / "r.csv")
    assert path == tmp_path / "r.csv"
    assert path.read_text().splitlines() == [
        "separation_deg,phase_deg,source,resolved,angle_1_deg,angle_2_deg",
        "2,0,truth,True,2,", "2,0,rts,True,2.1,",
        "12.3457,0,truth,True,12.3457,", "12.3457,0,rts,True,12.4457,"]


def test_the_default_separations_are_what_the_arc_reaches_about_the_centre(default_scene):
    """2 deg up in 1-deg steps to 2 (the smaller reach about C - 1 deg), at most 30."""
    from rtsgeom.analysis.resolution import _default_separations
    from rtsgeom.geometry import build_setup
    setup = build_setup(default_scene)
    az = np.degrees(setup.fe_azimuth_rad())
    for centre in (az.min() + 3.0, 0.5 * (az.min() + az.max()), az.max() - 4.0):
        half = min(centre - az.min(), az.max() - centre) - 1.0
        want = [s for s in np.arange(2.0, 31.0) if s <= 2 * half + 1e-9]
        assert _default_separations(setup, centre).tolist() == want, centre
    wide = _Azimuths(np.radians([-40.0, 40.0]))
    assert _default_separations(wide, 0.0).tolist() == list(np.arange(2.0, 31.0))  # <= 30
    assert _default_separations(wide, 37.0).tolist() == [2.0, 3.0, 4.0]  # 2 (3 - 1)
    assert _default_separations(wide, 38.0).tolist() == [2.0]  # 2 (2 - 1), its end kept
    assert _default_separations(wide, 39.0).size == 0


class _Azimuths:
    """What _default_separations reads of a setup: the front ends' azimuths."""

    def __init__(self, az_rad):
        self.az_rad = np.asarray(az_rad)

    def fe_azimuth_rad(self):
        return self.az_rad


def test_a_pair_of_targets_sits_at_the_centre_plus_and_minus_half_the_separation():
    from rtsgeom.analysis.resolution import _pair
    a, b = _pair(15, 2, -3, 7.5, 5.0)
    for t, angle in ((a, 5.0), (b, 10.0)):
        assert (t.range_m, t.velocity_mps, t.rcs_dbsm, t.elevation_rad) == (15.0, 2.0, -3.0,
                                                                            0.0)
        assert t.angle_rad == pytest.approx(np.radians(angle), abs=1e-15)


def test_the_resolution_studys_defaults():
    from rtsgeom.analysis.resolution import SOURCES, ResolutionStudy
    st = ResolutionStudy()
    assert (st.range_m, st.velocity_mps, st.centre_deg, st.separations_deg, st.phases_deg,
            st.rcs_dbsm, st.amplitudes) == (None, 0.0, None, (), (0.0, 90.0, 180.0), 10.0,
                                            None)
    assert SOURCES == ("truth", "rts")
