"""The setup's datasheet (``rtsgeom kpi``, ``analysis.kpi``): the GUM budget's arithmetic, its
sensitivity coefficients against finite differences of the full model, the spec's pass/fail
with margins, and the three outputs."""

from __future__ import annotations

import dataclasses
import json
import math
import re

import numpy as np
import pytest
from conftest import DEFAULT_SCENE, ROOT, CountedProgress

import rtsgeom
from rtsgeom.analysis.kpi import KpiSpec, KpiStudy, check_spec, loads_spec
from rtsgeom.analysis.kpi.budget import (
    K_COVERAGE,
    BudgetRow,
    combined,
    coverage_interval,
    validate,
)
from rtsgeom.cli import main
from rtsgeom.errors import ParameterError, SceneError

# -- the GUM arithmetic -----------------------------------------------------------------------

@pytest.mark.parametrize("c", [(0.5, -2.0, 0.0), (1e-3, 3.0, 0.7), (4.0,)])
@pytest.mark.parametrize("u", [0.1, 2.5])
def test_gum_combination_of_a_linear_model_matches_its_monte_carlo(c, u):
    """y = sum c_i x_i, x_i ~ N(0, u): u_c = u sqrt(sum c_i^2) (JCGM 100 eq. 10), and the
    Monte Carlo's 95 % interval is +-1.96 u_c (JCGM 101), which U = 2 u_c meets within 10 %."""
    rows = [BudgetRow(f"x{i}", u, "1", "normal", ci) for i, ci in enumerate(c)]
    u_c = combined(rows)
    assert u_c == pytest.approx(u * math.sqrt(sum(ci * ci for ci in c)))
    rng = np.random.default_rng(3)
    y = rng.standard_normal((200_000, len(c))) * u @ np.asarray(c)
    lo, hi = coverage_interval(y)
    assert (hi - lo) / 2 == pytest.approx(1.96 * u_c, rel=0.02)
    ok, diff = validate(0.0, K_COVERAGE * u_c, (lo, hi))
    assert ok and diff < 0.05


def test_a_nonlinear_input_fails_the_validation():
    """y = x^2 (zero derivative at the estimate: U = 0 by the GUM's first order) is not
    validated by its Monte Carlo (JCGM 101 8.2)."""
    y = np.random.default_rng(0).standard_normal(10_000) ** 2
    ok, _ = validate(0.0, K_COVERAGE * combined([BudgetRow("x", 1.0, "1", "normal", 0.0)]),
                     coverage_interval(y))
    assert not ok


def test_rectangular_and_triangular_standard_uncertainties():
    """u of a rectangular half-width a is a/sqrt3, of a triangular one a/sqrt6 (JCGM 100
    4.3.7, 4.3.9): checked against draws."""
    from rtsgeom.analysis.kpi.budget import RECTANGULAR, TRIANGULAR
    rng = np.random.default_rng(1)
    a = 0.7
    rect = rng.uniform(-a, a, 400_000)
    tri = rng.uniform(-a / 2, a / 2, 400_000) - rng.uniform(-a / 2, a / 2, 400_000)
    assert np.std(rect) == pytest.approx(a * RECTANGULAR, rel=0.01)
    assert np.std(tri) == pytest.approx(a * TRIANGULAR, rel=0.01)


# -- the spec file ----------------------------------------------------------------------------

@pytest.mark.parametrize("text, where", [
    ("angle_accuracy_deg = -1.0", "angle_accuracy_deg = -1"),
    ("targets = 2.5", "targets = 2.5"),
    ("azimuth_deg = [1.0]", "azimuth_deg"),
    ("ghost_supression_db = 3.0", "ghost_supression_db"),
    ("max_range_m = 'far'", "max_range_m"),
])
def test_a_bad_spec_names_its_key(text, where):
    with pytest.raises(SceneError, match=re.escape(where)):
        loads_spec(text, "spec.toml")


def test_every_spec_key_is_optional():
    assert loads_spec("") == KpiSpec()
    assert not check_spec(KpiSpec(), {"angle_accuracy_deg": 0.1})


# -- one datasheet of the paper's scene ---------------------------------------------------------

@pytest.fixture(scope="module")
def sheet():
    # every progress call is checked as it is told (CountedProgress): a step told without its
    # total fails every test of this sheet, whichever test built it
    told = CountedProgress()
    scene = rtsgeom.load_scene(DEFAULT_SCENE)
    sheet = KpiStudy(points=3, draws=2000, sigma_phase_deg=1.0)(scene, told)
    for step in ("field of view", "angle accuracy: pair (0, 1)",
                 "the signal chain on the scene's targets (rtsgeom run)",
                 "range, velocity, targets, ghosts, near field",
                 "resolution (two targets, truth beside RTS)"):
        assert told.finished(step), (step, told.calls)
    acc = [c for c in told.calls if c[0].startswith("angle accuracy")]
    assert [c[1:] for c in acc] == [(m, 3) for m in (1, 2, 3)], acc
    seps = [c[0] for c in told.calls if c[0].startswith("separation")]
    n = len(seps)
    assert n >= 2 and all(lab.endswith(f"({k}/{n})") for k, lab in enumerate(seps, 1)), seps
    return sheet


def test_the_gum_budget_holds_against_its_monte_carlo_on_the_paper_scene(sheet):
    """At three set angles of the paper's pair, U (k = 2) and the Monte Carlo's 95 % interval
    agree within 10 % of U; U covers every input's contribution."""
    assert len(sheet.accuracy) == 3
    for p in sheet.accuracy:
        assert p.validated, (p.set_deg, p.end_difference)
        assert p.mc_half_width_deg == pytest.approx(p.expanded_deg, rel=0.1)
        assert p.expanded_deg >= K_COVERAGE * max(r.contribution_deg for r in p.budget)
        assert p.accuracy_deg == pytest.approx(abs(p.error_deg) + p.expanded_deg)


def _values(sheet) -> dict:
    return {c.kpi: c.value for c in dataclasses.replace(sheet, spec=_met(sheet)).checks}


def _met(sheet) -> KpiSpec:
    """A spec the setup meets, every key given a limit with room."""
    v = sheet.spec_values()
    lo, hi = sheet.fov["azimuth_deg"]
    return KpiSpec(angle_accuracy_deg=2 * v["angle_accuracy_deg"],
                   azimuth_deg=(lo + 0.5, hi - 0.5), min_range_m=v["min_range_m"] + 1.0,
                   max_range_m=v["max_range_m"] - 1.0,
                   max_velocity_mps=v["max_velocity_mps"] / 2,
                   range_accuracy_m=2 * v["range_accuracy_m"],
                   velocity_accuracy_mps=2 * v["velocity_accuracy_mps"],
                   targets=1, ghost_suppression_db=v["ghost_suppression_db"] - 3.0)


#: per key: a limit the setup misses, from its value (what "tightening" means for the key)
TIGHTEN = {
    "angle_accuracy_deg": lambda v, s: v / 2,
    "azimuth_deg": lambda v, s: (s.fov["azimuth_deg"][0] - 1.0, s.fov["azimuth_deg"][1]),
    "min_range_m": lambda v, s: v / 2,
    "max_range_m": lambda v, s: v * 2,
    "max_velocity_mps": lambda v, s: v * 2,
    "range_accuracy_m": lambda v, s: v / 2,
    "velocity_accuracy_mps": lambda v, s: v / 2,
    "targets": lambda v, s: int(v) + 1,
    "ghost_suppression_db": lambda v, s: v + 3.0,
}


def test_a_met_spec_passes_and_tightening_one_kpi_fails_exactly_it(sheet):
    met = dataclasses.replace(sheet, spec=_met(sheet))
    assert met.passed and met.exit_code == 0
    assert all(c.margin >= 0 for c in met.checks)
    values = _values(sheet)
    for key, tighten in TIGHTEN.items():
        limit = tighten(values[key], sheet)
        spec = dataclasses.replace(_met(sheet), **{key: limit})
        tight = dataclasses.replace(sheet, spec=spec)
        failed = [c.kpi for c in tight.checks if not c.passed]
        assert failed == [key], (key, failed)
        assert tight.exit_code == 1
        bad = next(c for c in tight.checks if c.kpi == key)
        assert bad.margin < 0


def test_a_kpi_without_a_value_is_reported_and_not_met(sheet):
    """The paper's two front ends span 8.8 deg: two targets within it are not resolved at every
    phase (the RuT's resolution is 17.5 deg), so a resolution spec has no value to meet."""
    res = sheet.targets["resolution"]
    assert res["rts_deg"] is None and "does not resolve" in res["note"]
    asked = dataclasses.replace(sheet, spec=KpiSpec(resolution_deg=12.0))
    (check,) = asked.checks
    assert check.passed is None and check.note == res["note"] and asked.exit_code == 1


def test_the_json_contract(sheet):
    d = json.loads(json.dumps(sheet.to_dict(), allow_nan=False))
    for entry in d["angle_accuracy"]:
        for key in ("set_angle_deg", "error_deg", "expanded_uncertainty_deg",
                    "monte_carlo_half_width_deg", "budget"):
            assert key in entry
        for row in entry["budget"]:
            assert {"quantity", "standard_uncertainty", "unit", "sensitivity",
                    "contribution_deg"} <= set(row)
    for section in ("field_of_view", "range_velocity", "targets", "ghosts_leakage",
                    "near_field", "spec"):
        assert section in d
    assert {"min_range_m", "max_range_m", "max_velocity_mps", "range_resolution_m",
            "velocity_resolution_mps", "range_accuracy_m"} <= set(d["range_velocity"])
    assert "resolution" in d["targets"] and "note" in d["targets"]["resolution"]
    fes = d["near_field"]["front_ends"]
    assert all(f["distance_m"] > f["fraunhofer_distance_m"] for f in fes)
    # each adjacent pair's far-field design error, as the near-field study gives it
    from rtsgeom.analysis.nearfield import nearfield
    scene = rtsgeom.load_scene(DEFAULT_SCENE)  # the sheet's scene
    at = nearfield(scene, [scene.rts.arc_radius_m], 5).to_dict()["at_scene_radius"]
    assert d["near_field"]["pairs"] and d["near_field"]["pairs"] == json.loads(
        json.dumps(at["synthesis"], allow_nan=False))


def test_every_view_shows_the_one_headline(sheet):
    """The command's summary, the HTML's and the PDF's key figures and the repr show the rows
    one function makes (each view once formatted its own, with different names and digits),
    and the headline names the receiver noise's SNR and where it comes from."""
    import html

    from rtsgeom.analysis.kpi.headline import headline
    from rtsgeom.analysis.kpi.report import _text_page, to_html
    from rtsgeom.cli.kpi import summary
    d = sheet.to_dict()
    rows = headline(d)
    assert [n for n, _ in rows] == ["field of view", "angle accuracy", "receiver noise", "range",
                                    "velocity", "targets", "ghosts", "near field"]
    # the paper's 10 dB per sample after the FFTs: symmetric Hann windows lose 2 (N - 1) / 3 N
    snr = d["inputs"]["snr_effective_db"]
    assert snr == pytest.approx(10 + 10 * math.log10(511 * 119 * (2 / 3) ** 2), abs=1e-6)
    assert f"SNR {snr:.1f} dB at the detection cell (radar.snr_db" in dict(rows)["receiver noise"]
    cli, page, rep = summary(d), to_html(sheet, figs={}), repr(sheet)
    pdf = "".join("".join(t.get_text() for t in _text_page(sheet).texts).split())
    for name, value in rows:
        assert f"  {name:<18} {value}" in cli, name
        assert f"<td>{html.escape(name)}</td><td>{html.escape(value)}</td>" in page, name
        assert "".join(value.split()) in pdf, name
        assert f"{name} " in rep and value[:30] in rep, name


# -- the sensitivity coefficients against the full model -------------------------------------

def _chain_error_deg(scene, pair, alpha, off_j, amps) -> float:
    """The RuT's error on a programme (J's delay offset ``off_j``, amplitudes ``amps``)
    through the full ADC-cube chain (noise-free): synthesis, FFTs, CFAR, the beamformer."""
    from rtsgeom.calibration.probes import probe_ranges
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.radar import process
    from rtsgeom.radar.frame import simulate
    from rtsgeom.radar.processing import nearest_detection
    from rtsgeom.rts.channels import RtsProgram, requested_delay
    setup = build_setup(scene)
    rng_m = float(probe_ranges(setup, 1)[0])
    tau = float(requested_delay(scene, rng_m))
    prog = RtsProgram.build([0, 0], list(pair), [tau, tau + off_j], [0.0, 0.0], list(amps))
    _, cube = simulate(setup, exact_paths(setup), prog)
    rd, dets = process(cube)
    hit = nearest_detection(dets, rd, rng_m)
    return math.degrees(dets.angle_rad[hit] - alpha)


@pytest.mark.slow
def test_sensitivity_coefficients_match_finite_differences_of_the_full_model():
    """The budget's coefficients (phasor model) against central differences of the full
    chain: J's delay and an Rx antenna's phase through the ADC-cube chain (the programme
    fixed), a front end's tangential offset through the whole lab procedure (``run``:
    calibrated on the setup as built, planned, synthesized, detected)."""
    from rtsgeom.analysis.kpi.accuracy import AccuracyInputs, pair_accuracy
    from rtsgeom.analysis.transfer import set_angles
    from rtsgeom.calibration.pair import calibrate_pair
    from rtsgeom.calibration.phasor import PairChannels
    from rtsgeom.calibration.probes import probe_angles, probe_front_ends, probe_ranges
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.pipeline.pair import pair_design
    from rtsgeom.scene import TargetConfig
    scene = rtsgeom.replace(rtsgeom.load_scene(DEFAULT_SCENE), radar=rtsgeom.replace(
        rtsgeom.load_scene(DEFAULT_SCENE).radar, snr_db=None))
    setup, pair = build_setup(scene), (0, 1)
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, scene.seed)
    angles = set_angles(setup, probe, pair, 3)[1:2]  # the span's middle
    alpha = float(angles[0])
    inputs = AccuracyInputs((1e-4, 1e-4, 1e-4), math.radians(2.0), None, 100, 1)
    point = pair_accuracy(setup, setup, paths, pair, probe, angles, inputs)[0]
    coef = {r.quantity: r.sensitivity for r in point.budget}
    # the programme the budget's operating point uses
    cal = calibrate_pair(setup, paths, pair, probe, seed=scene.seed)
    t = TargetConfig(float(probe_ranges(setup, 1)[0]), 0.0, 10.0, alpha)
    channels = PairChannels(pair, (0.0, cal.delta_tau_s), probe.gain_correction[list(pair)])
    a_i, a_j, _, off_j = pair_design(setup, paths, channels, t, scene.rts.aoa_mode,
                                     probe_angles(*probe.angle_rad[list(pair)]),
                                     cal.quantisation_residual_s)
    # J's delay, deg/ps
    h = 0.5e-12
    e = [_chain_error_deg(scene, pair, alpha, off_j + s * h, (a_i, a_j)) for s in (1, -1)]
    c_tau = (e[0] - e[1]) / (2 * h * 1e12)
    assert coef["RTS delay quantisation (J against I)"] == pytest.approx(c_tau, rel=0.05,
                                                                        abs=1e-5)
    # an Rx antenna's phase, deg/deg
    n_rx = setup.rut.rx_local.shape[0]
    for k in (0, n_rx - 1):
        e = []
        for s in (1, -1):
            ph = [0.0] * n_rx
            ph[k] = s * 2.0
            radar = rtsgeom.replace(scene.radar, channels=rtsgeom.RadarChannelsConfig(
                rx_phase_rad=tuple(math.radians(p) for p in ph)))
            e.append(_chain_error_deg(rtsgeom.replace(scene, radar=radar), pair, alpha,
                                      off_j, (a_i, a_j)))
        c_ph = (e[0] - e[1]) / 4.0
        assert coef[f"RuT Rx {k} phase"] == pytest.approx(c_ph, rel=0.05, abs=1e-4)
    # front end 1's tangential offset through the lab's procedure, deg/mm
    h_mm = 0.3
    e = []
    for s in (1, -1):
        fes = list(scene.rts.front_ends)
        fes[1] = rtsgeom.replace(fes[1], tangential_offset_mm=s * h_mm)
        moved = rtsgeom.replace(scene, rts=rtsgeom.replace(scene.rts, front_ends=tuple(fes)),
                                targets=(rtsgeom.replace(scene.targets[0],
                                                         angle_deg=math.degrees(alpha)),))
        run = rtsgeom.run_scene(moved)
        e.append(run.matches[0]["error"]["angle_deg"])
    c_t = (e[0] - e[1]) / (2 * h_mm)
    assert coef["front end 1 tangential offset"] == pytest.approx(c_t, rel=0.15)


# -- the command ------------------------------------------------------------------------------

def _count_pdf_pages(data: bytes) -> int:
    return len(re.findall(rb"/Type\s*/Page[^s]", data))


@pytest.mark.slow
def test_the_command_writes_three_self_contained_outputs_and_exits_by_the_spec(tmp_path,
                                                                               capsys):
    met = tmp_path / "met.toml"
    met.write_text("angle_accuracy_deg = 0.5\nazimuth_deg = [5.0, 10.0]\nmax_range_m = 50.0\n"
                   "ghost_suppression_db = 20.0\n")
    out = tmp_path / "o"
    args = ["kpi", str(DEFAULT_SCENE), "--points", "3", "--draws", "500", "--quiet"]
    assert main(args + ["--out", str(out), "--spec", str(met)]) == 0
    d = json.loads((out / "kpi.json").read_text())
    assert d["passed"] is True and all(c["pass"] for c in d["spec"])
    page = (out / "kpi.html").read_text()
    assert page.count("src='data:image/png;base64,") >= 4
    # nothing fetched: every image inline; besides them no URL, stylesheet, script or frame
    assert all(s.startswith("data:image/png;base64,")
               for s in re.findall(r"src=['\"]([^'\"]*)", page))
    text = re.sub(r"data:image/png;base64,[A-Za-z0-9+/=]*", "", page)
    assert not re.search(r"https?:|//[a-z]|<link|<script|<iframe|<object|url\(|@import",
                         text, re.I)
    assert "PASS" in page and "Uncertainty budget" in page
    assert 1 <= _count_pdf_pages((out / "kpi.pdf").read_bytes()) <= 3
    capsys.readouterr()
    # tighten one KPI below the setup's value: exactly it fails, its margin printed
    tight = tmp_path / "tight.toml"
    tight.write_text(met.read_text().replace("ghost_suppression_db = 20.0",
                                             "ghost_suppression_db = 30.0"))
    assert main(args + ["--spec", str(tight)]) == 1
    text = capsys.readouterr().out
    assert re.search(r"ghost_suppression_db\s+FAIL .*margin -4\.0\d", text), text
    assert text.count("FAIL") == 2  # the verdict line and the KPI


def test_bad_input_exits_2_naming_the_field(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text("angle_accuracy_deg = 0.0\n")
    assert main(["kpi", str(DEFAULT_SCENE), "--spec", str(bad), "--quiet"]) == 2
    assert "angle_accuracy_deg = 0" in capsys.readouterr().err
    assert main(["kpi", str(DEFAULT_SCENE), "--sigma-mm", "0.1", "0.2", "--quiet"]) == 2
    assert "--sigma-mm" in capsys.readouterr().err


def test_every_spec_key_is_documented():
    from rtsgeom.analysis.kpi.spec import SPEC_SENSE
    from rtsgeom.scene.schema import specs
    page = (DEFAULT_SCENE.parents[1] / "docs" / "kpi.md").read_text()
    keys = [s.key for _, s in specs(KpiSpec)]
    assert keys == list(SPEC_SENSE)
    for key in keys:
        assert re.search(rf"^{key} = ", page, re.M), key


def test_the_monte_carlos_inputs_are_drawn_independently():
    """The mounting offsets and the RuT's antenna phases come from separate streams: drawn
    with one seed they are uncorrelated (the phases once repeated the offsets' normals)."""
    from rtsgeom.analysis.tolerance.draws import PHASE_STREAM, draw_offsets
    from rtsgeom.analysis.transfer import draw_channel_gains
    from rtsgeom.geometry import build_setup
    rut = build_setup(rtsgeom.load_scene(ROOT / "scenes" / "template.toml")).rut
    off = draw_offsets(5, 4000, np.ones(3), "normal", 2).reshape(4000, -1)
    ph = draw_channel_gains(rut, 4000, 1.0, 0.0, [5, PHASE_STREAM])[1]
    r = np.corrcoef(off[:, 0], ph[:, 0])[0, 1]
    assert abs(r) < 4 / np.sqrt(4000)



@pytest.mark.parametrize("sigma", [(0.1, 0.2, 0.3), [0.0, 0.05, 1.0]])
def test_kpi_study_takes_three_sigmas(sigma):
    """``sigma_mm`` is one number or three (radial, tangential, height)."""
    assert tuple(KpiStudy(sigma_mm=sigma).sigma_mm) == tuple(sigma)
    with pytest.raises(ParameterError, match="sigma_mm"):
        KpiStudy(sigma_mm=tuple(sigma)[:2])


# -- the HTML datasheet's pieces, word for word --

@pytest.mark.parametrize("v, text", [(None, "-"), (True, "yes"), (False, "no"), (3, "3"),
                                     (np.int64(7), "7"), (0.123456, "0.1235"), (12345.0, "1.234e+04"),
                                     ([1.5, None, True], "[1.5, -, yes]"), ((2, 0.5), "[2, 0.5]"),
                                     ("a<b", "a<b")])
def test_report_values_are_formatted_by_their_type(v, text):
    from rtsgeom.analysis.kpi.report import _fmt
    assert _fmt(v) == text
    assert _fmt(0.123456, 2) == "0.12"


def test_report_tables_escape_and_mark_failed_rows():
    from rtsgeom.analysis.kpi.report import _table
    assert _table(("a<", "b"), [(1, "x&y"), (0.5, None)], ["", "fail"]) == (
        "<table><tr><th>a&lt;</th><th>b</th></tr><tr><td>1</td><td>x&amp;y</td></tr>"
        "<tr class='fail'><td>0.5</td><td>-</td></tr></table>")
    assert _table(("k",), [(True,)]) == "<table><tr><th>k</th></tr><tr><td>yes</td></tr></table>"


@pytest.mark.parametrize("quantity, unit, group", [
    ("radial offset", "mm", "mounting"), ("delay quantisation", "ps", "calibration and delay"),
    ("RuT Tx phase", "deg", "RuT channels"), ("receiver noise", "deg", "noise"),
    ("RuT offset", "mm", "mounting")])
def test_budget_rows_are_grouped_by_what_they_are(quantity, unit, group):
    from types import SimpleNamespace
    from rtsgeom.analysis.kpi.report import _group
    assert _group(SimpleNamespace(quantity=quantity, unit=unit)) == group


def test_the_html_says_the_spec_verdict_and_marks_each_failed_kpi(sheet):
    from rtsgeom.analysis.kpi.report import _spec_rows, to_html
    tight = dataclasses.replace(sheet, spec=dataclasses.replace(
        _met(sheet), angle_accuracy_deg=sheet.spec_values()["angle_accuracy_deg"] / 2))
    rows, classes = _spec_rows(tight)
    verdicts = {r[0]: (r[4], cls) for r, cls in zip(rows, classes)}
    assert verdicts["angle_accuracy_deg"] == ("FAIL", "fail")
    assert all(v == ("pass", "") for k, v in verdicts.items() if k != "angle_accuracy_deg")
    page = to_html(tight, figs={})
    assert page.startswith(f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>"
                           f"{sheet.scene_name} datasheet</title><style>")
    assert f"<h1>{sheet.scene_name}: RTS setup datasheet</h1>" in page
    assert "<h2>Spec: FAIL: see below</h2><table><tr><th>KPI</th><th>value</th><th>limit</th>" \
           "<th>margin</th><th>verdict</th><th>note</th></tr>" in page
    assert "<tr class='fail'><td>angle_accuracy_deg</td>" in page
    assert page.endswith(f"Computed in {sheet.elapsed_s:.1f} s by rtsgeom kpi.</p></body></html>")
    met = to_html(dataclasses.replace(sheet, spec=_met(sheet)), figs={})
    assert "<h2>Spec: PASS: every KPI meets the spec</h2>" in met and "class='fail'" not in met
    assert "<h2>Spec" not in to_html(sheet, figs={})
    none = dataclasses.replace(sheet, spec=KpiSpec(resolution_deg=12.0))
    assert _spec_rows(none)[0][0][4] == "no value" and _spec_rows(none)[1] == ["fail"]


def test_the_html_budget_section_is_the_worst_set_angles(sheet):
    import matplotlib
    matplotlib.use("Agg")
    from matplotlib.figure import Figure
    from rtsgeom.analysis.kpi.report import to_html
    tiny = Figure(figsize=(1, 1))
    page = to_html(sheet, figs={"angle_accuracy": tiny, "uncertainty_budget": tiny,
                                "mystery": tiny})
    d = sheet.to_dict()
    assert ("<h2>Angle accuracy</h2><img alt='angle_accuracy' src='data:image/png;base64,"
            in page)
    import html
    assert f"<p>{html.escape(d['angle_accuracy_summary']['gum_validation'])}.</p>" in page
    assert "<h2>Uncertainty budget (JCGM 100, validated by JCGM 101)</h2>" in page
    assert "<h2>mystery</h2><img alt='mystery'" in page
    worst = max(sheet.accuracy, key=lambda p: p.accuracy_deg)
    assert (f"<p>The budget at the worst set angle, {worst.set_deg:.3f} deg (pair {worst.pair}): "
            f"u_c = {worst.combined_deg:.4g} deg, U = {worst.expanded_deg:.4g} deg; Monte Carlo "
            f"95 % interval [{worst.mc_interval_deg[0]:.4g}, {worst.mc_interval_deg[1]:.4g}] "
            "deg.</p><table><tr><th>quantity</th><th>u(x_i)</th><th>unit</th><th>distribution"
            "</th><th>c_i (deg/unit)</th><th>u_i(y) (deg)</th></tr>") in page
    assert page.count("<tr><td>") >= len(worst.budget)


def test_a_spec_file_too_large_or_with_a_reversed_span_is_refused(tmp_path):
    from conftest import assert_refused
    from rtsgeom.analysis.kpi.spec import MAX_SPEC_BYTES, load_spec
    big = tmp_path / "big.toml"
    big.write_text("#" * MAX_SPEC_BYTES)
    assert load_spec(big) == KpiSpec()  # at the limit: read
    big.write_text("#" * (MAX_SPEC_BYTES + 1))
    assert_refused(lambda: load_spec(big),
                   f"{big}: spec file too large (at most {MAX_SPEC_BYTES} bytes)", SceneError)
    for span in ("[5.0, 5.0]", "[6.0, -6.0]"):
        p = tmp_path / "span.toml"
        p.write_text(f"azimuth_deg = {span}\n")
        lo, hi = (float(x) for x in span.strip("[]").split(","))
        assert_refused(lambda: load_spec(p), f"{p}: azimuth_deg = {[lo, hi]}: must be [lo, hi] "
                                             "with lo < hi", SceneError)
    p.write_text("azimuth_deg = [-6.0, 6.0]\n")
    assert load_spec(p).azimuth_deg == (-6.0, 6.0)


def test_every_budget_row_names_its_input_unit_distribution_and_source(sheet):
    """The rows of each set angle's budget (rtsgeom.analysis.kpi.accuracy.pair_accuracy) in
    full but the sensitivities: six mounting offsets at the default 0.1 mm, the three delay
    inputs (the calibration's scatter, half the RTS step as a rectangular, the step as a
    triangular), each RuT antenna's phase at sigma_phase_deg, the receiver noise at the SNR of
    the detection cell; one sensitivity for the three delay inputs."""
    from rtsgeom.analysis.kpi.accuracy import effective_snr
    from rtsgeom.geometry import build_setup
    scene = rtsgeom.load_scene(DEFAULT_SCENE)
    rut = build_setup(scene).rut
    res_ps = scene.rts.delay_resolution_s * 1e12
    snr = effective_snr(scene.radar)
    n_tx, n_rx = rut.tx_local.shape[0], rut.rx_local.shape[0]
    mount = "tolerance model, calibrated on the nominal setup"
    rows = ([(f"front end {fe} {axis} offset", pytest.approx(0.1), "mm", "normal", mount)
             for fe in (0, 1) for axis in ("radial", "tangential", "height")]
            + [("calibration residual (J's fitted delay)", None, "ps", "normal",
                "the sweep's fitted delay scatter over the frames averaged"),
               ("calibration step (J's delay rounded)", pytest.approx(0.5 * res_ps / math.sqrt(3)),
                "ps", "rectangular", f"half the RTS delay step {res_ps:g} ps"),
               ("RTS delay quantisation (J against I)", pytest.approx(res_ps / math.sqrt(6)), "ps",
                "triangular", "each channel's delay realised to the step [assumed independent]")]
            + [(f"RuT {kind} {k} phase", pytest.approx(1.0), "deg", "normal",
                "radars of the type about the scene's own")
               for kind, n in (("Tx", n_tx), ("Rx", n_rx)) for k in range(n)]
            + [("receiver noise (per I/Q, relative to the echo)",
                pytest.approx(1 / math.sqrt(2 * snr)), "1", "normal",
                f"each of {rut.num_virtual} virtual channels' I and Q, SNR "
                f"{10 * math.log10(snr):.1f} dB at the detection, from radar.snr_db")])
    for p in sheet.accuracy:
        got = [(r.quantity, r.standard_uncertainty, r.unit, r.distribution, r.note)
               for r in p.budget]
        assert got[6][1] >= 0
        assert got == [w if w[1] is not None else (*w[:1], got[6][1], *w[2:]) for w in rows]
        assert len({r.sensitivity for r in p.budget[6:9]}) == 1
        assert p.pair == (0, 1) and p.snr_effective_db == pytest.approx(10 * math.log10(snr))
        assert p.expanded_deg == pytest.approx(2 * p.combined_deg)
        assert p.combined_deg == pytest.approx(math.sqrt(sum(r.contribution_deg ** 2
                                                             for r in p.budget)))
