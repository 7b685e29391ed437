"""Every study's result shows itself briefly: a ``repr`` of at most 20 lines and 2000
characters whatever the size of its arrays (a tolerance result printed 105 556 characters, a
calibration its arrays), an HTML table, ``to_dataframe()`` one row per item, ``plot()`` a
figure. Presentation only: the numbers behind them are tested with their studies."""

from __future__ import annotations

import importlib
import pkgutil

import numpy as np
import pytest
from matplotlib.figure import Figure

import rtsgeom
from conftest import DEFAULT_SCENE
from rtsgeom._lib.results import MAX_LINES, Result, brief

CASES = ("uncalibrated", "calibrated")


@pytest.fixture(scope="module")
def scene():
    return rtsgeom.load_scene(DEFAULT_SCENE)


@pytest.fixture(scope="module")
def tolerance_pair(scene):
    from rtsgeom.analysis.tolerance import ChannelPhasors, monte_carlo
    from rtsgeom.geometry import build_setup
    model = ChannelPhasors.build(build_setup(scene), (0, 1), 5)
    return {n: monte_carlo(model, (1e-4,) * 3, n, 1) for n in (40, 400)}


def _calibration():
    from rtsgeom.calibration.sweep import Calibration
    t = np.linspace(-200e-12, 200e-12, 41)
    sweep = [{"delta_tau_s": float(x), "angle_error_deg": float(1e10 * x)} for x in t]
    return Calibration.from_dict({"pair": [0, 1], "delta_tau_s": 10e-12, "period_s": 1.3e-9,
                                  "residual_error_deg": 0.002, "range_offset_m": 0.003,
                                  "sweep": sweep, "refinement": sweep[15:26]})


def _linearity(dims):
    from rtsgeom.analysis.linearity import Linearity
    if dims == 1:
        s = np.linspace(-3, 3, 9)
        return Linearity("exact", True, s, s + 0.01 * np.sin(s), np.zeros((2, 9)),
                         channels=(0, 1))
    a, e = np.meshgrid(np.linspace(-2, 2, 3), np.linspace(-1, 1, 3))
    s = np.column_stack([a.ravel(), e.ravel()])
    return Linearity("exact", True, s, s + 0.01, channels=(0, 1, 2, 3))


def _verify():
    from rtsgeom.analysis.tolerance import VerifyResult
    m = {c: np.linspace(-0.1, 0.1, 6) for c in CASES}
    ch = {c: v + 1e-4 for c, v in m.items()}
    return VerifyResult({c: np.zeros(6, int) for c in CASES}, m, ch, 0.5, np.zeros(6, int))


def _design():
    from rtsgeom.analysis.design import METRICS, DesignGrid
    r, s = np.linspace(0.5, 2, 4), np.linspace(4, 10, 3)
    z = np.outer(s, 1 / r)
    return DesignGrid((0, 1), 0.0, r, s, 17.5, 0.1, 0.95, 200, 1,
                      {name: z * (k + 1) for k, name in enumerate(METRICS)},
                      np.zeros((3, 4), bool), (), "unit")


def _coverage():
    from rtsgeom.analysis.coverage import ArcDesign, ArcPlan, CoverageDesign
    designs = []
    for r in (0.5, 1.0):
        for e in (0, 1):
            n = 3 + e
            plan = ArcPlan(None, r, n, tuple(np.linspace(-10, 10, n)), 20 / (n - 1), 17.5, 3.0,
                           (0.1, -0.1), "kept", "", ("resolution",), e)
            designs.append(ArcDesign(plan, 0.01 / r, 0.3, 0.2 * r, False, None, 0.02, 0.97,
                                     0.5, 0.3, 0.95))
    return CoverageDesign((-10.0, 10.0), np.array([0.5, 1.0]), 0.1, 0.95, 100, tuple(designs),
                          "unit")


def _nearfield(scene):
    from rtsgeom.analysis.nearfield import NearField
    r = np.array([0.5, 1.0, 2.0])
    g = np.tile([-4.0, 4.0], (3, 1))
    b = 0.3 / r[:, None] * np.ones((3, 2))
    return NearField(scene, r, r + 30, g, g + b, 0.5 * b, 0.5 * b, 0 * b, 10 * b, 5 * b, 0 * b,
                     [], 0.12, 0.015, 3.9e-3)


def _identification(scene):
    from rtsgeom.identify import FrontEndFit, Identification
    fits = tuple(FrontEndFit(q, np.r_[1e-4 * (q + 1), -2e-4, 0.0, 0.0, 0.0, 0.0, 0.0],
                             np.full(7, 2e-5), (None,) * 4 + ("not free",) * 3, np.eye(7), 1.1,
                             1.0, 2) for q in range(2))
    return Identification(scene, fits)


def _joint_identification(scene):
    from rtsgeom.identify import RadarChannelsFit
    ident = _identification(scene)
    n = 7  # 3 Tx, 4 Rx
    why = ((None, None),) * n
    radar = RadarChannelsFit(np.linspace(-0.1, 0.1, n), np.linspace(-0.3, 0.3, n),
                             np.full(n, 1e-3), np.full(n, 1e-3), (("reference", "reference"),)
                             + why[1:], 3, 0, 0, 0)
    return type(ident)(ident.scene, ident.fits, radar)


def _transfer():
    from rtsgeom.analysis.transfer import Transfer
    b, p = 6, 5
    rng = np.random.default_rng(0)
    e = rng.normal(0, 0.1, (b, p))
    return Transfer(((0, 1),), np.zeros(p, int), np.linspace(-4, 4, p), 0.05 * np.ones(p),
                    0.06 * np.ones(p), e, 0.01 * e, 0.9 * e, (0.0,), np.zeros((p, 4)),
                    np.zeros((b, 7)), np.zeros((b, 7)), 15.0, 3.0, 0.3, 0.1, "unit")


def _playback(scene):
    from rtsgeom.analysis.playback.result import PlaybackResult
    f, t = 4, 2
    az = np.linspace(-3, 3, f)[:, None] + np.zeros((f, t))
    track = {"range_m": np.full((f, t), 10.0), "azimuth_deg": az,
             "velocity_mps": np.zeros((f, t))}
    seen = dict(track, azimuth_deg=az + 0.01)
    channels = np.empty((f, t), object)
    for i in range(f):
        for k in range(t):
            channels[i, k] = (0, 1) if i < 2 else (1, 2)
    return PlaybackResult(scene, "exact", np.arange(f) * 0.1, track, seen, np.zeros((f, t)),
                          channels, np.zeros((0, 7)), {})


def _datasheet():
    """A datasheet of two set angles, its sections as the study writes their keys."""
    from rtsgeom.analysis.kpi import BudgetRow, Datasheet, KpiSpec, KpiStudy
    from rtsgeom.analysis.kpi.accuracy import AnglePoint
    rows = (BudgetRow("front end 0 tangential offset", 0.1, "mm", "normal", 0.02),
            BudgetRow("receiver noise", 0.002, "1", "normal", 3.0))
    pts = tuple(AnglePoint((0, 1), a, 0.001, rows, 0.006, 0.012, (-0.011, 0.013), 0.001,
                           0.006, True, 0.03) for a in (5.0, 8.0))
    fov = {"mode": "exact", "cells": False, "azimuth_deg": [4.0, 12.0], "gaps_deg": [],
           "covered_deg": [[4.0, 12.0]]}
    rv = {"min_range_m": 1.6, "max_range_m": 75.0, "max_velocity_mps": 9.0,
          "range_resolution_m": 0.15, "range_step_m": 0.0001, "velocity_resolution_mps": 0.1,
          "range_accuracy_m": 0.05, "velocity_accuracy_mps": 0.01, "accuracy_note": ""}
    return Datasheet("unit", KpiStudy(), fov, pts, "", {}, rv,
                     {"total": 8, "per_channel": 4,
                      "resolution": {"rts_deg": None, "note": "none"}},
                     {"ghost_suppression_db": 26.0}, {"fraunhofer_distance_m": 0.12},
                     spec=KpiSpec(targets=4))


def _object_design():
    from rtsgeom.analysis.object_design import ObjectDesign, ObjectDesignResult
    st = ObjectDesign(ranges_m=(5.0, 10.0, 20.0), spacings_deg=(8.0, 16.0), budgets=(None, 2))
    share = np.linspace(0.4, 1.0, 12).reshape(2, 2, 3)
    return ObjectDesignResult(st, "unit", "targets[0]", np.array([9, 5]), share,
                              0.1 * share, 4 + 0 * share, 5 + 0 * share, 4 + 0 * share)


@pytest.fixture(scope="module")
def results(scene, tolerance_pair):
    from rtsgeom.analysis.ghosts import ghost_analysis
    return {"Calibration": _calibration(), "ToleranceResult": tolerance_pair[400],
            "Linearity": _linearity(1), "Linearity 2-D": _linearity(2),
            "VerifyResult": _verify(), "DesignGrid": _design(), "CoverageDesign": _coverage(),
            "NearField": _nearfield(scene), "GhostReport": ghost_analysis(scene),
            "Identification": _identification(scene),
            "Identification with radar": _joint_identification(scene),
            "Transfer": _transfer(), "PlaybackResult": _playback(scene),
            "ObjectDesignResult": _object_design(), "Datasheet": _datasheet(),
            "RunResult": rtsgeom.run_scene(scene, aoa_mode="nearest"),
            "Resolution": _resolution(),
            "ToleranceReport": _tolerance_report(scene), "CalibrationReport": _cal_report(),
            "ArcLinearity": _arc_linearity()}


def _resolution():
    from rtsgeom.analysis.resolution import Resolution, ResolutionStudy
    seps = np.repeat(np.arange(10.0, 30.0, 0.5), 4)
    n = seps.size
    table = {"separation_deg": seps, "phase_deg": np.tile([0.0, 0.0, 180.0, 180.0], n // 4),
             "source": np.tile(["truth", "rts"], n // 2), "resolved": seps > 20,
             "angle_1_deg": np.where(seps > 20, -seps / 2, np.nan),
             "angle_2_deg": np.where(seps > 20, seps / 2, np.nan)}
    grid = np.linspace(-60, 60, 121)
    spectra = {"angle_deg": grid, "separation_deg": np.array([12.0, 24.0]),
               "truth": [-np.abs(grid) / 3] * 2, "rts": [-np.abs(grid) / 2] * 2}
    return Resolution("bench", ResolutionStudy(phases_deg=(0.0, 180.0)), 20.0, 0.0, table,
                      spectra)


def _tolerance_report(scene):
    study = rtsgeom.ToleranceStudy(rtsgeom.Bounds((1e-4,) * 3), pair=(0, 1), points=5,
                                   mc=rtsgeom.MonteCarlo(40, 1))
    return study(scene)


def _cal_report():
    from types import SimpleNamespace
    from rtsgeom.analysis.calibration_study import CalibrationReport
    probe = SimpleNamespace(angle_rad=np.radians([-4.0, 4.0, 12.0]), gain_correction=np.ones(3))
    return CalibrationReport(((0, 1), (1, 2)), (_calibration(), _calibration()), probe,
                             "exact", "unit", arc=True)


def _arc_linearity():
    from rtsgeom.analysis.linearity_study import ArcLinearity
    return ArcLinearity(((0, 1), (1, 2)), (_linearity(1), _linearity(1)), True, "exact")


def _result_classes() -> set[str]:
    """Every class deriving from Result in the package (imported module by module)."""
    for mod in pkgutil.walk_packages(rtsgeom.__path__, "rtsgeom."):
        if mod.name.startswith(("rtsgeom.cli", "rtsgeom.__main__", "rtsgeom.viz.scene3d",
                                "rtsgeom.paths.raytrace")):
            continue
        importlib.import_module(mod.name)

    def walk(cls):
        for sub in cls.__subclasses__():
            yield sub
            yield from walk(sub)
    return {c.__name__ for c in walk(Result) if c.__module__.startswith("rtsgeom.")}


def test_every_result_class_is_covered(results):
    names = {type(r).__name__ for r in results.values()}
    assert _result_classes() <= names, _result_classes() - names


def test_repr_is_short_and_says_what_was_studied(results):
    for name, res in results.items():
        text = repr(res)
        assert len(text.splitlines()) <= MAX_LINES and len(text) < 2000, (name, text)
        assert text.startswith(f"<{type(res).__name__}: "), name
        assert "[" not in text.splitlines()[0] or "array" not in text, name
        html = res._repr_html_()
        assert html.startswith("<table>") and html.count("<tr>") == len(text.splitlines()) - 1


def test_repr_does_not_grow_with_the_draws(tolerance_pair):
    """Arrays are summarised, never printed: ten times the draws, the same length."""
    small, large = (len(repr(tolerance_pair[n])) for n in (40, 400))
    assert abs(small - large) <= 20


def test_to_dataframe_one_row_per_item(results, tolerance_pair):
    import pandas as pd
    for name, res in results.items():
        df = res.to_dataframe()
        assert isinstance(df, pd.DataFrame) and len(df) > 0 and len(df.columns) >= 2, name
    tol = tolerance_pair[400]
    df = tol.to_dataframe()
    assert len(df) == 400
    assert np.array_equal(df["calibrated_error_deg"], tol.worst_error_deg["calibrated"])
    assert df["calibrated_passes"].mean() == pytest.approx(tol.yield_("calibrated"))
    cal = results["Calibration"].to_dataframe()
    assert list(cal["stage"]).count("fine") == 11 and len(cal) == 52
    design = results["DesignGrid"].to_dataframe()
    assert len(design) == 12 and design["radius_m"].nunique() == 4
    run = results["RunResult"].to_dataframe()
    assert len(run) == len(results["RunResult"].scene.targets)


def test_plot_returns_a_figure(results):
    for name, res in results.items():
        fig = res.plot()
        assert isinstance(fig, Figure) and fig.axes, name


def test_counters_are_set_points_not_draws(tolerance_pair):
    """``detected_off_bin`` counts (draw, set-point) pairs: it can exceed the draws but never
    draws x set-points, which ``stats`` reports beside it."""
    tol = tolerance_pair[400]
    for case in CASES:
        st = tol.stats(case)
        assert st["set_points_total"] == 400 * 5
        assert 0 <= st["detected_off_bin"] <= st["set_points_total"]
    assert "of 2000 set-points (draws x set-points)" in repr(tol)


def test_brief_summarises_arrays_and_numbers():
    assert brief(np.arange(100_000.0).reshape(1000, 100)) == "array (1000x100): 0 .. 1e+05"
    assert brief(np.array([1.0, np.nan])) == "array (2): 1 .. 1, 1 not finite"
    assert brief(0.123456789) == "0.1235" and brief(3) == "3" and brief(None) == "None"
    assert brief(np.zeros(3, bool)) == "array (3) bool: 0 True"
