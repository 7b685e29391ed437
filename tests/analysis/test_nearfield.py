"""Near-field violation: single front-end bias, phase error, synthesized angle
over arc radius, against closed forms."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from conftest import (
    DEFAULT_SCENE,
    SETUP_ERRORS,
    make_scene,
    scenes_with_and_without_error,
    small_quiet,
)

from rtsgeom.analysis.nearfield import default_radii, nearfield, with_arc_radius
from rtsgeom.analysis.nearfield_terms import phase_error_deg
from rtsgeom.cli import main
from rtsgeom.errors import NominalSetupWarning, ParameterError
from rtsgeom.geometry import build_setup
from rtsgeom.geometry.farfield import curvature_phase_error_rad, fraunhofer_distance_m

RADII = np.array([0.5, 1.0, 3.0, 10.0, 30.0])
SCENE_K = 1  # index of R_c = 1 m in RADII


def no_separation(doc):
    for fe in doc["rts"]["front_ends"]:
        fe["rx_tx_separation_m"] = 0.0


@pytest.fixture(scope="module")
def sweep():
    return nearfield(make_scene(), RADII, points=5)


@pytest.fixture(scope="module")
def sweep_no_sep():
    return nearfield(make_scene(no_separation), RADII, points=5)


def geometric_part(nf):
    """The bias without the (range-dependent, R_c-independent) beat-frequency term."""
    return nf.bias_deg - nf.beat_frequency_deg


def test_default_sweep_and_fraunhofer_distance():
    scene = make_scene()
    r = default_radii(scene)
    assert r.size == 13 and r[0] == pytest.approx(0.316, abs=1e-3) and r[-1] == pytest.approx(31.6, abs=0.1)
    assert np.any(np.isclose(r, scene.rts.arc_radius_m))
    rut = build_setup(scene).rut
    # 8 elements at lambda/2: d_A = 4 lambda, 2 d_A^2 / lambda = 32 lambda = 0.124 m << R_c
    assert fraunhofer_distance_m(rut) == pytest.approx(32 * rut.wavelength_m)
    scaled = build_setup(with_arc_radius(scene, 3.0))
    assert np.linalg.norm(scaled.fe.module[0] - scaled.rut.position) == pytest.approx(3.0)
    assert np.allclose(scaled.fe_azimuth_rad(), build_setup(scene).fe_azimuth_rad())


def test_bias_shrinks_like_one_over_r(sweep):
    b = sweep.bias_deg
    assert np.all(b > 0) and np.all(np.diff(b, axis=0) < 0)
    # at the paper's 1 m: ~0.57 deg, of which 0.30 deg from the 20 mm Rx/Tx separation
    assert b[SCENE_K] == pytest.approx([0.574, 0.565], abs=0.005)
    assert sweep.separation_deg[SCENE_K] == pytest.approx([0.300, 0.300], abs=0.002)
    # 1/R law: bias x R constant to 2 % from 0.5 m to 30 m (0.3 % from 3 m on)
    k = geometric_part(sweep) * RADII[:, None]
    assert np.max(np.abs(k / k[-1] - 1)) < 0.02
    assert np.max(np.abs(k[2:] / k[-1] - 1)) < 0.003


def test_separation_closed_form_is_s_over_r(sweep):
    # far-field closed form from the phase centre: the Tx carry 0.76 and the Rx 0.24 of the
    # beamformer slope, so alpha - theta = (0.76 - 0.24) (s / 2) / R  (0.300 deg at s = 20 mm)
    sep = sweep.separation_deg * RADII[:, None]
    assert np.allclose(sep, np.degrees((4 / 5.25 - 1.25 / 5.25) * 0.01), rtol=0.005)


def test_detected_approaches_closed_forms_faster_than_the_bias(sweep):
    """Quantitatively: the phase-centre closed form (Rx/Tx separation only) leaves about half
    of the bias at *every* radius -- the RuT's own Tx/Rx group parallax is also a 1/R term --
    while separation + group parallax (+ the beat-frequency term) leave a residual that falls
    faster than the bias: below 1e-3 of it at 1 m and shrinking about like 1/R^2 relative."""
    left = sweep.near_field_deg / sweep.bias_deg  # detected - phase-centre closed form
    assert np.all((left > 0.44) & (left < 0.50))
    assert np.max(np.abs(left - left[-1])) < 0.03  # does NOT go to zero
    rel = np.abs(sweep.curvature_deg / sweep.bias_deg)
    assert np.all(rel[SCENE_K] < 2e-3) and np.all(rel[SCENE_K + 1] < 3e-4)  # 1 m, 3 m
    assert np.all(rel[1] < rel[0] / 3) and np.all(rel[2] < rel[1] / 5)  # 0.5 -> 1 -> 3 m
    assert np.all(np.abs(sweep.curvature_deg[SCENE_K:]) < 1e-3)


def test_zero_separation_bias_falls_like_one_over_r(sweep_no_sep):
    nf = sweep_no_sep
    assert np.allclose(nf.separation_deg, 0.0, atol=1e-9)
    b = geometric_part(nf)
    k = b * RADII[:, None]
    assert np.max(np.abs(k / k[-1] - 1)) < 0.02
    assert np.max(np.abs(k[2:] / k[-1] - 1)) < 0.003
    # the RuT's Tx/Rx group parallax alone: 2.5 d cos^2(theta) / R ~ 0.27 deg at 1 m
    assert b[SCENE_K] == pytest.approx([0.275, 0.268], abs=0.003)
    assert np.all(np.abs(nf.bias_deg[-1]) < 0.01)


def test_phase_error_falls_like_one_over_r(sweep):
    pp = sweep.phase_pp_deg
    assert np.all(np.diff(pp, axis=0) < 0)
    k = pp * RADII[:, None]
    assert np.max(np.abs(k / k[-1] - 1)) < 0.005
    assert np.all(sweep.phase_rms_deg < pp / 2)
    # the same residual as `rtsgeom info` reports at R_c
    setup = build_setup(make_scene())
    assert pp[SCENE_K] == pytest.approx(np.degrees(curvature_phase_error_rad(setup)), rel=1e-9)
    # it is the broken virtual array (Rx/Tx split, Tx/Rx groups), not phase-front curvature:
    # 22 deg p-p at 1 m, of which the pure curvature is ~0.35 deg (also ~1/R)
    assert pp[SCENE_K] == pytest.approx([22.3, 21.6], abs=0.2)
    assert np.all(sweep.curvature_pp_deg[SCENE_K] < 0.5)
    c = sweep.curvature_pp_deg * RADII[:, None]
    assert np.max(np.abs(c / c[-1] - 1)) < 0.03


def test_phase_error_vanishes_without_separation_and_groups():
    # zero separation: the residual is the group parallax, still ~1/R and non-zero
    s = build_setup(make_scene(no_separation))
    pe = phase_error_deg(s)
    assert np.all(pe["pp"] > 5) and np.all(pe["curvature_pp"] < 0.5)


def test_synthesized_error_array_factor_vs_exact(sweep):
    af = np.array([row[0]["array_factor_max_abs_error_deg"] for row in sweep.synthesis])
    ex = np.array([row[0]["exact_max_abs_error_deg"] for row in sweep.synthesis])
    assert af[SCENE_K] == pytest.approx(0.65, abs=0.05)  # README: 0.67 deg through the chain
    assert np.all(np.diff(af) < 0)
    k = af * RADII
    assert np.max(np.abs(k / k[-1] - 1)) < 0.05  # ~1/R, like the bias it cannot see
    assert np.all(ex < 1e-6)  # exact model = the RuT's phasor model here (no mounting errors)
    lo, hi = sweep.synthesis[SCENE_K][0]["span_deg"]
    # the span starts at the detected angle of FE 0, ends at the geometric angle of FE 1
    assert lo == pytest.approx(sweep.detected_deg[SCENE_K, 0]) and hi == pytest.approx(12.2)


def test_nearfield_cli(tmp_path):
    out = tmp_path / "nf"
    assert main(["nearfield", str(DEFAULT_SCENE), "--radius-m", "0.5:2:3", "--points", "3",
                 "--out", str(out)]) == 0
    d = json.loads((out / "nearfield.json").read_text())
    assert [r["radius_m"] for r in d["radii"]] == pytest.approx([0.5, 1.0, 2.0])
    assert d["at_scene_radius"]["radius_m"] == 1.0
    fe = d["at_scene_radius"]["front_ends"][0]
    parts = (fe["separation_part_deg"] + fe["parallax_part_deg"] + fe["beat_frequency_part_deg"]
             + fe["curvature_part_deg"])
    assert parts == pytest.approx(fe["bias_deg"], abs=1e-12)
    assert d["fraunhofer_distance_m"] == pytest.approx(0.1238, abs=1e-3)
    assert (out / "nearfield.png").stat().st_size > 0
    with pytest.raises(SystemExit) as exc:
        main(["nearfield", str(DEFAULT_SCENE), "--radius-m", "2:1:3"])
    assert exc.value.code == 2
    assert main(["nearfield", str(DEFAULT_SCENE), "--radius-m", "1:500:3"]) == 2


def test_default_sweep_stops_at_the_radar_limit_and_ignores_targets_and_sheet():
    """A short-range radar's default sweep ends at its own limit (0.8 R_max - 2 m, where the
    probe target still fits) instead of failing; the scene's targets (inside the arc at large
    radii) and cutouts (overlapping at small radii) do not stop the free-space analysis."""
    from rtsgeom.analysis.nearfield import max_radius_m
    from rtsgeom.scene import load_scene
    scene = load_scene(DEFAULT_SCENE.parent / "custom-array.toml")
    r = default_radii(scene)
    full = scene.rts.arc_radius_m * np.logspace(-0.5, 1.5, 13)
    assert full[-1] > max_radius_m(scene)  # the unclipped sweep would leave the radar's range
    assert r[-1] == max_radius_m(scene) and np.all(np.diff(r) > 0)
    assert np.array_equal(r[:-1], full[full < max_radius_m(scene)])
    with pytest.warns(NominalSetupWarning, match=r"own errors \(rts.front_ends\[1\]"):
        nf = nearfield(scene, r[[0, -1]], points=3)  # the scene's own yaw, left out
    assert np.all(np.isfinite(nf.bias_deg))
    assert abs(nf.bias_deg[-1]).max() < abs(nf.bias_deg[0]).max()  # ~1/R
    with pytest.raises(Exception, match=r"must lie in \[0.05, 28.98\] m .*got 40 m"), \
            pytest.warns(NominalSetupWarning):
        nearfield(scene, np.array([1.0, 40.0]), points=3)


def test_radius_sweep_keeps_its_ends_exactly(capsys):
    """``--radius-m A:B:N`` is log-spaced with A and B exactly (logspace gave 0.04999..., which
    the radius check then refused at its own minimum 0.05 m)."""
    assert main(["nearfield", str(DEFAULT_SCENE), "--radius-m", "0.05:0.2:3", "--points", "3",
                 "--json", "--quiet"]) == 0
    radii = [r["radius_m"] for r in json.loads(capsys.readouterr().out)["radii"]]
    assert radii[0] == 0.05 and radii[-1] == 0.2 and radii[1] == pytest.approx(0.1)


@pytest.mark.parametrize("section, key, value", SETUP_ERRORS)
def test_the_scenes_own_errors_do_not_enter_the_near_field(section, key, value):
    """The near field of the arc is analysed on the nominal setup: the same report with or
    without any one of the scene's own errors (a RuT yaw had turned the detected angles but
    not the synthesis's set-points: 0.5 deg of yaw read as 0.5 deg of "exact" synthesis
    error), and the CLI names the errors it leaves out."""
    clean, moved = scenes_with_and_without_error(DEFAULT_SCENE, section, key, value)
    a = nearfield(clean, [0.7, 2.0], points=3).to_dict()
    with pytest.warns(NominalSetupWarning, match=re.escape(key)) as caught:
        b = nearfield(moved, [0.7, 2.0], points=3).to_dict()
    assert a == b
    assert [w.filename for w in caught] == [__file__]  # at this line, not in the package


def test_nearfield_cli_names_the_errors_it_leaves_out(tmp_path, capsys):
    text = DEFAULT_SCENE.read_text()
    moved = tmp_path / "moved.toml"
    moved.write_text(text.replace("[radar]\n", "[radar]\nyaw_offset_deg = 0.5\n", 1))
    args = ["--radius-m", "0.7:2:2", "--points", "3", "--json", "--quiet"]
    outs = []
    for path in (DEFAULT_SCENE, moved):
        assert main(["nearfield", str(path), *args]) == 0
        cap = capsys.readouterr()
        outs.append(json.loads(cap.out)["radii"])
        assert ("radar.yaw_offset_deg" in cap.err) is (path == moved), cap.err
    assert outs[0] == outs[1]


@pytest.mark.parametrize("estimator", ["bartlett", "capon"])
def test_the_bias_coefficient_follows_the_estimator(estimator):
    """bias x R is the 1/R law of the bias the RuT's own estimator shows: for Bartlett the
    closed forms, for a smoothed Capon (twice the beamformer's bias here) the detected bias;
    either way it predicts the detected bias at every radius within 3 %."""
    kw = dict(angle_estimator="capon", angle_subarray=5) if estimator == "capon" else {}
    scene = make_scene(**kw)
    nf = nearfield(scene, [1.0, 2.0, 4.0], points=3)
    coef = nf.bias_times_radius_deg_m()
    got = nf.bias_deg * nf.radius_m[:, None]
    np.testing.assert_allclose(got, np.broadcast_to(coef, got.shape), rtol=0.03)
    assert ("detected" in nf.to_dict()["bias_1_over_r_coefficient_from"]) is (estimator == "capon")



@pytest.mark.parametrize("separation_m", [0.0, 0.02])
def test_nearfield_rows_and_exact_synthesis_on_the_nominal_setup(separation_m):
    """Each row's bias is detected - geometric and the sum of its parts; on a setup without
    mounting errors the exact amplitudes put every set-point on its angle (the design model
    is the RuT's), the array-factor closed form is off by a finite amount."""
    from rtsgeom.analysis.nearfield import nearfield

    def mutate(doc):
        for fe in doc["rts"]["front_ends"]:
            fe["rx_tx_separation_m"] = separation_m
    radii = np.array([0.5, 2.0])
    nf = nearfield(make_scene(mutate), radii, points=3)
    d = nf.to_dict()
    for i, row in enumerate(d["radii"]):
        assert row["radius_m"] == pytest.approx(radii[i])
        for fe in row["front_ends"]:
            assert fe["bias_deg"] == pytest.approx(fe["detected_deg"] - fe["geometric_deg"],
                                                   abs=1e-12)
            parts = (fe["separation_part_deg"] + fe["parallax_part_deg"]
                     + fe["beat_frequency_part_deg"] + fe["curvature_part_deg"])
            assert parts == pytest.approx(fe["bias_deg"], abs=1e-9)
        syn = row["synthesis"][0]
        assert syn["exact_max_abs_error_deg"] is not None
        assert syn["exact_max_abs_error_deg"] < 1e-6
        assert 1e-3 < syn["array_factor_max_abs_error_deg"] < 2.0


def test_nearfield_refuses_empty_or_non_finite_radii():
    from rtsgeom.analysis.nearfield import nearfield
    s = make_scene()
    for bad in ([], [1.0, float("nan")], [0.01]):
        with pytest.raises(ValueError, match="arc radii"):
            nearfield(s, bad)


def test_nearfield_rows_carry_the_curvature_part_of_the_phase_error():
    """The pure phase-front curvature (what the Fraunhofer criterion bounds) is reported per
    radius and falls like 1/R (second order in the aperture over R)."""
    from rtsgeom.analysis.nearfield import nearfield
    nf = nearfield(small_quiet([], samples_per_chirp=512), [1.0, 4.0], points=3).to_dict()
    rows = nf["radii"]
    curv = [[fe["curvature_phase_error_pp_deg"] for fe in r["front_ends"]] for r in rows]
    np.testing.assert_allclose(np.array(curv[0]) / np.array(curv[1]), 4.0, rtol=0.05)



@pytest.mark.parametrize("n_bad", [1, 4, 5, 9])
def test_bad_arc_radii_are_listed_four_at_most(default_scene, n_bad):
    """The error names the first bad radii, four at most (a long list stays one line)."""
    from rtsgeom.analysis.nearfield import nearfield
    bad = [-1.0 - k for k in range(n_bad)]
    with pytest.raises(ParameterError, match="arc radii") as err:
        nearfield(default_scene, [1.0] + bad, points=3)
    listed = str(err.value).split("got ")[1].removesuffix(" m").split(", ")
    assert [float(x) for x in listed] == bad[:4]


def test_a_scene_with_its_own_errors_gets_the_whole_warning(default_scene):
    from conftest import moved_front_end, the_warnings
    assert the_warnings(lambda: nearfield(moved_front_end(default_scene), [1.0], points=3),
                        NominalSetupWarning) == [
        "nearfield analyses the arc's near field on the nominal setup: the scene's own errors "
        "(rts.front_ends[1].radial_offset_mm) play no part"]


@pytest.mark.parametrize("radii, got", [
    ([0.01, 0.02, 0.03, 0.04, 0.05], "0.01, 0.02, 0.03, 0.04"), ([1.0, -2.0], "-2"),
    ([float("nan"), 1.0], "nan"), ([1e6], "1e+06"), ([], "none")])
def test_bad_radii_are_named_the_first_four(default_scene, radii, got):
    from rtsgeom.analysis.nearfield import MIN_RADIUS_M, max_radius_m
    assert MIN_RADIUS_M == 0.05
    with pytest.raises(ParameterError) as exc:
        nearfield(default_scene, radii, points=3)
    assert str(exc.value) == (f"arc radii must lie in [0.05, {max_radius_m(default_scene):.4g}] "
                              f"m (the probe target must stay within the radar's range), got "
                              f"{got} m")


# -- the result as it shows itself: summary, table and the 1/R coefficient, in full --------


def _near_field(scene, radii, **over):
    """A NearField of made-up numbers (R radii x 2 front ends), each array distinct, so that
    every row of the summary and every column of the table reads a field of its own."""
    from rtsgeom.analysis.nearfield import NearField
    r = np.asarray(radii, float)
    n = r.size
    base = np.arange(1.0, 2 * n + 1).reshape(n, 2)
    fields = dict(scene=scene, radius_m=r, range_m=10.0 + r, geometric_deg=5.0 + base,
                  detected_deg=5.0 + 1.25 * base, separation_deg=0.1 * base,
                  parallax_deg=0.05 * base ** 2, beat_frequency_deg=-0.01 * base,
                  phase_pp_deg=2.0 * base, phase_rms_deg=0.5 * base,
                  curvature_pp_deg=0.02 * base, synthesis=[[] for _ in r],
                  fraunhofer_m=0.1238, aperture_m=0.0175, wavelength_m=0.0039)
    fields.update(over)
    return NearField(**fields)


@pytest.mark.parametrize("radii, k", [([0.5, 1.0, 3.0], 1), ([0.5, 2.0], None),
                                      ([1.0 + 1e-12, 4.0], 0)])
def test_the_near_fields_summary_in_full(radii, k):
    """The title (radii, their range, front ends), each array's row, bias x R as the largest
    |coefficient| over the front ends with the radius where it falls below 0.01 deg, and the
    scene radius's worst |bias| only where the scene's radius is one of the sweep's (to 1e-9
    relative)."""
    from rtsgeom._lib.results import brief
    scene = make_scene()
    nf = _near_field(scene, radii)
    r = np.asarray(radii)
    bias = nf.detected_deg - nf.geometric_deg
    coef = (nf.separation_deg[-1] + nf.parallax_deg[-1]) * r[-1]
    assert nf.bias_times_radius_deg_m() == pytest.approx(coef, rel=1e-15)
    worst = np.max(np.abs(coef))
    title, rows = nf._summary()
    assert title == (f"diewald2022: near field over {r.size} arc radii ({r.min():g} to "
                     f"{r.max():g} m), 2 front ends")
    curvature = bias - nf.separation_deg - nf.parallax_deg - nf.beat_frequency_deg
    expected = [("radius_m", r), ("bias_deg", bias), ("separation_deg", nf.separation_deg),
                ("parallax_deg", nf.parallax_deg), ("curvature_deg", curvature),
                ("phase_pp_deg", nf.phase_pp_deg),
                ("bias x R", f"{worst:.3g} deg m (largest |.| over the front ends): below "
                             f"0.01 deg from R_c {worst / 0.01:.3g} m"),
                ("fraunhofer_m", 0.1238), ("aperture_m", 0.0175)]
    if k is not None:
        expected.append((f"at R_c {r[k]:g} m",
                         f"|bias| up to {np.max(np.abs(bias[k])):.4g} deg"))
    assert [name for name, _ in rows] == [name for name, _ in expected]
    for (_, got), (_, want) in zip(rows, expected):
        assert (brief(got) if not isinstance(got, str) else got) == (
            brief(want) if not isinstance(want, str) else want)
        if isinstance(want, np.ndarray):
            np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-15)
    assert nf.scene_index() == k


def test_the_near_fields_bias_coefficient_of_a_smoothed_estimator_is_the_median():
    """A smoothed Capon's coefficient: the median over the radii of the detected bias x R,
    per front end (not the closed forms' value at the largest radius)."""
    scene = make_scene(angle_estimator="capon", angle_subarray=5)
    nf = _near_field(scene, [0.5, 1.0, 3.0, 9.0])
    bias_r = (nf.detected_deg - nf.geometric_deg) * nf.radius_m[:, None]
    np.testing.assert_array_equal(nf.bias_times_radius_deg_m(), np.median(bias_r, axis=0))
    plain = _near_field(make_scene(angle_estimator="capon", angle_subarray=0), [0.5, 1.0])
    np.testing.assert_array_equal(plain.bias_times_radius_deg_m(),
                                  (plain.separation_deg[-1] + plain.parallax_deg[-1]) * 1.0)


@pytest.mark.parametrize("two_d", [False, True])
def test_the_near_fields_table_in_full(two_d):
    """One row per (radius, front end), radius-major; every column the ravelled field (the
    derived ones from their definitions), the elevation bias only for a 2-D beamformer."""
    r = [0.5, 1.0, 3.0]
    el = (dict(geometric_el_deg=np.full((3, 2), 1.0), detected_el_deg=np.arange(6.0).reshape(3, 2))
          if two_d else {})
    nf = _near_field(make_scene(), r, **el)
    cols = nf._columns()
    names = ["radius_m", "front_end", "geometric_deg", "detected_deg", "bias_deg",
             "separation_deg", "parallax_deg", "beat_frequency_deg", "curvature_deg",
             "phase_pp_deg", "phase_rms_deg", "curvature_pp_deg"]
    assert list(cols) == names + (["elevation_bias_deg"] if two_d else [])
    assert cols["radius_m"].tolist() == [0.5, 0.5, 1.0, 1.0, 3.0, 3.0]
    assert cols["front_end"].tolist() == [0, 1, 0, 1, 0, 1]
    bias = nf.detected_deg - nf.geometric_deg
    want = {"geometric_deg": nf.geometric_deg, "detected_deg": nf.detected_deg,
            "bias_deg": bias, "separation_deg": nf.separation_deg,
            "parallax_deg": nf.parallax_deg, "beat_frequency_deg": nf.beat_frequency_deg,
            "curvature_deg": bias - nf.separation_deg - nf.parallax_deg - nf.beat_frequency_deg,
            "phase_pp_deg": nf.phase_pp_deg, "phase_rms_deg": nf.phase_rms_deg,
            "curvature_pp_deg": nf.curvature_pp_deg}
    for name, a in want.items():
        np.testing.assert_allclose(cols[name], a.ravel(), rtol=1e-12, atol=1e-15, err_msg=name)
    assert nf.near_field_deg == pytest.approx(bias - nf.separation_deg)
    if two_d:
        np.testing.assert_array_equal(cols["elevation_bias_deg"], np.arange(6.0) - 1.0)
    else:
        assert nf.elevation_bias_deg is None


def test_the_radius_check_takes_its_bounds_and_refuses_beyond_them():
    """[MIN_RADIUS_M, max_radius_m] both ends accepted, a hair beyond refused; a 2-D array of
    radii is refused, naming its values."""
    from rtsgeom.analysis.nearfield import _check_radii, max_radius_m
    scene = make_scene()
    hi = max_radius_m(scene)
    assert hi == 0.8 * scene.radar.max_range_m - 2.0
    _check_radii(scene, np.array([0.05, 1.0, hi]))
    msg = ("arc radii must lie in [0.05, {:.4g}] m (the probe target must stay within the "
           "radar's range), got {} m").format(hi, "{}")
    for bad, got in (([0.05 * (1 - 1e-12)], "0.05"), ([hi * (1 + 1e-12)], f"{hi:.4g}"),
                     ([[1.0, 2.0]], "1, 2"), ([float("inf")], "inf")):
        with pytest.raises(ParameterError) as exc:
            _check_radii(scene, np.array(bad))
        assert str(exc.value) == msg.format(got)


def test_default_radii_clip_to_the_limits_and_keep_them():
    """Below MIN_RADIUS_M the sweep starts at 0.05 m exactly; radii inside are the log sweep
    of R_c x 10^(-0.5..1.5); a sweep exactly at its ends keeps them without adding."""
    from rtsgeom.analysis.nearfield import DEFAULT_DECADES, DEFAULT_POINTS, default_radii
    assert (DEFAULT_DECADES, DEFAULT_POINTS) == ((-0.5, 1.5), 13)
    small = with_arc_radius(make_scene(), 0.1)  # unchecked: only the radius is read
    got = default_radii(small, 5)
    full = 0.1 * np.logspace(-0.5, 1.5, 5)
    assert got[0] == 0.05 and np.array_equal(got[1:], full[full >= 0.05])
    scene = make_scene()
    np.testing.assert_array_equal(default_radii(scene, 3), np.logspace(-0.5, 1.5, 3))
