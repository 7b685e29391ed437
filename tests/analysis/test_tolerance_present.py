"""A tolerance result shown: the drawn scales in words, what was studied, the summary rows and
the per-draw table of a pair, a cell and an arc, in closed form on hand-made results."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from rtsgeom.analysis.tolerance.draws import Bounds
from rtsgeom.analysis.tolerance.present import columns, scales_text, subject, summary


@pytest.mark.parametrize("bounds, distribution, text", [
    (Bounds((1e-4, 2e-4, 5e-5)), "normal", "sigma r/t/h 0.1/0.2/0.05 mm"),
    (Bounds((1e-4,) * 3), "uniform", "bound r/t/h 0.1/0.1/0.1 mm"),
    (Bounds((0.0,) * 3, math.radians(0.5)), "normal",
     "sigma r/t/h 0/0/0 mm, yaw/pitch 0.5/0 deg"),
    (Bounds((0.0,) * 3, 0.0, math.radians(2.0)), "normal",
     "sigma r/t/h 0/0/0 mm, yaw/pitch 0/2 deg"),
    (Bounds((0.0,) * 3, rut_position_m=(1e-3, 0.0, 0.0)), "normal",
     "sigma r/t/h 0/0/0 mm, RuT 1/0/0 mm, 0 deg"),
    (Bounds((1e-3,) * 3, math.radians(1.0), 0.0, (0.0, 0.0, 0.0), math.radians(0.25)), "uniform",
     "bound r/t/h 1/1/1 mm, yaw/pitch 1/0 deg, RuT 0/0/0 mm, 0.25 deg")])
def test_the_scales_in_words(bounds, distribution, text):
    assert scales_text(SimpleNamespace(bounds=bounds, distribution=distribution)) == text


def _model(kind, sets):
    return SimpleNamespace(kind=kind, count=5, sets=[SimpleNamespace(front_ends=fe,
                                                                     set_rad=np.zeros(n))
                                                     for fe, n in sets])


def test_what_was_studied():
    assert subject(SimpleNamespace(model=_model("pair", [((0, 1), 3)]))) == "pair (0, 1)"
    assert subject(SimpleNamespace(model=_model("cell", [((0, 1, 2, 3), 5)]))) == \
        "cell (0, 1, 2, 3)"
    assert subject(SimpleNamespace(model=_model("arc", [((0, 1), 3), ((1, 2), 3)]))) == \
        "arc of 5 front ends (2 pairs)"


def _pair_result():
    """Four draws of a pair with 3 set-points: worst signed errors, delays and offsets."""
    worst = np.array([0.05, -0.2, 0.01, 0.15])
    e = {"uncalibrated": np.stack([worst * 3, worst * 3], 1)[:, :1, None],
         "calibrated": worst[:, None, None]}
    return SimpleNamespace(
        model=_model("pair", [((0, 1), 3)]), errors_deg=e, draws=4, spec_deg=0.1,
        bounds=Bounds((1e-4,) * 3), distribution="normal",
        yield_=lambda case: float(np.mean(np.abs(e[case][:, 0, 0]) <= 0.1)),
        passes=lambda case: np.abs(e[case][:, 0, 0]) <= 0.1,
        off_bin_per_set={"uncalibrated": np.array([2]), "calibrated": np.array([0])},
        fallbacks_per_set={"uncalibrated": np.array([0]), "calibrated": np.array([1])},
        delay_s=np.array([1e-12, -2e-12, 3e-12, 4e-12]),
        range_offset_m=np.array([1e-4, -1e-4, 2e-4, 0.0]), seed=7, elapsed_s=1.5)


def test_a_pairs_summary_rows():
    res = _pair_result()
    title, rows = summary(res)
    assert title == ("pair (0, 1) mounting tolerance, 4 draws (sigma r/t/h 0.1/0.1/0.1 mm), "
                     "spec 0.1 deg")
    w = np.abs(np.array([0.05, -0.2, 0.01, 0.15]))
    p50, p95 = np.percentile(w, [50, 95])
    q50, q95 = np.percentile(3 * w, [50, 95])
    d95 = np.percentile([1, 2, 3, 4], 95)
    r95 = np.percentile([0.1, 0.1, 0.2, 0.0], 95)
    assert rows == [
        ("uncalibrated", f"yield 25.00 %; |worst error| p50 {q50:.3g}, p95 {q95:.3g}, max "
                         f"{0.6:.3g} deg"),
        ("calibrated", f"yield 50.00 %; |worst error| p50 {p50:.3g}, p95 {p95:.3g}, max 0.2 deg"),
        ("off_bin", "uncalibrated 2, calibrated 0 of 12 set-points (draws x set-points)"),
        ("fallbacks", "uncalibrated 0, calibrated 1 of 12 set-points (draws x set-points)"),
        ("calibration", f"|delta tau| p95 {d95:.3g} ps, |range offset| p95 {r95:.3g} mm"),
        ("seed", 7), ("elapsed_s", 1.5)]


def test_a_pairs_table_has_one_row_per_draw():
    res = _pair_result()
    cols = columns(res)
    assert list(cols) == ["draw", "uncalibrated_error_deg", "uncalibrated_passes",
                          "calibrated_error_deg", "calibrated_passes", "delay_ps",
                          "range_offset_mm"]
    assert list(cols["draw"]) == [0, 1, 2, 3]
    assert np.allclose(cols["calibrated_error_deg"], [0.05, -0.2, 0.01, 0.15])
    assert list(cols["calibrated_passes"]) == [True, False, True, False]
    assert np.allclose(cols["delay_ps"], [1, -2, 3, 4]) and np.allclose(
        cols["range_offset_mm"], [0.1, -0.1, 0.2, 0.0])


def test_a_cells_table_and_summary_read_the_angular_distance():
    e = np.zeros((2, 1, 3))
    e[:, 0] = [[0.1, -0.3, 0.35], [-0.02, 0.01, 0.03]]
    res = SimpleNamespace(
        model=_model("cell", [((0, 1, 2, 3), 5)]), errors_deg={"calibrated": e}, draws=2,
        spec_deg=0.2, bounds=Bounds((1e-4,) * 3), distribution="uniform",
        yield_=lambda case: 0.5, passes=lambda case: np.array([False, True]),
        off_bin_per_set={"calibrated": np.array([0])},
        fallbacks_per_set={"calibrated": np.array([0])},
        delay_s=np.array([[0.0, 1e-12, 2e-12, 3e-12], [0.0, -1e-12, 0.0, 1e-12]]),
        range_offset_m=np.array([1e-4, 2e-4]), seed=1, elapsed_s=0.5)
    cols = columns(res)
    assert list(cols) == ["draw", "calibrated_azimuth_error_deg", "calibrated_elevation_error_deg",
                          "calibrated_distance_error_deg", "calibrated_passes",
                          "delay_channel_1_ps", "delay_channel_2_ps", "delay_channel_3_ps",
                          "range_offset_mm"]
    assert np.allclose(cols["calibrated_elevation_error_deg"], [-0.3, 0.01])
    assert np.allclose(cols["delay_channel_3_ps"], [3, 1])
    title, rows = summary(res)
    assert title.startswith("cell (0, 1, 2, 3) mounting tolerance, 2 draws (bound r/t/h")
    # a cell's worst is the larger of |azimuth| and |elevation|; the reference's delay left out
    w = np.array([0.3, 0.02])
    assert rows[0] == ("calibrated", f"yield 50.00 %; |worst error| p50 "
                                     f"{np.percentile(w, 50):.3g}, p95 "
                                     f"{np.percentile(w, 95):.3g}, max 0.3 deg")
    d = np.abs(np.array([[1, 2, 3], [-1, 0, 1]]))
    assert rows[3][1].startswith(f"|delta tau| p95 {np.percentile(d, 95):.3g} ps")


def test_an_arcs_table_has_each_pairs_columns_and_the_arcs_worst():
    e = np.array([[[0.1], [-0.4]], [[0.05], [0.02]]])
    worst = np.array([-0.4, 0.05])
    res = SimpleNamespace(
        model=_model("arc", [((0, 1), 2), ((1, 2), 2)]), errors_deg={"calibrated": e},
        draws=2, spec_deg=0.1, bounds=Bounds((1e-4,) * 3), distribution="normal",
        arc_worst=lambda case: worst, yield_=lambda case: 0.5,
        passes=lambda case: np.abs(worst) <= 0.1,
        off_bin_per_set={"calibrated": np.array([1, 2])},
        fallbacks_per_set={"calibrated": np.array([0, 0])},
        delay_s=np.array([[1e-12, 2e-12], [3e-12, 4e-12]]),
        range_offset_m=np.array([[1e-4, 2e-4], [3e-4, 4e-4]]), seed=2, elapsed_s=0.1)
    cols = columns(res)
    assert list(cols) == ["draw", "calibrated_pair_0_1_error_deg",
                          "calibrated_pair_1_2_error_deg", "calibrated_arc_error_deg",
                          "calibrated_passes", "delay_pair_0_1_ps", "range_offset_pair_0_1_mm",
                          "delay_pair_1_2_ps", "range_offset_pair_1_2_mm"]
    assert np.allclose(cols["calibrated_pair_1_2_error_deg"], [-0.4, 0.02])
    assert np.allclose(cols["range_offset_pair_1_2_mm"], [0.2, 0.4])
    title, rows = summary(res)
    assert title.startswith("arc of 5 front ends (2 pairs) mounting tolerance, 2 draws")
    assert rows[0][1].endswith("max 0.4 deg")
    assert rows[1] == ("off_bin", "calibrated 3 of 8 set-points (draws x set-points)")
