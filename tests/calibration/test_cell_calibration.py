"""The 2-D cell's channel calibration (``aoa.ncal``) on sphere4 with a front end off: the
pair fit's columns, the solver's start with calibrated phases, the loop-closure and failure
warnings, and (slow) the elevation pair against its continuous coherence point.
The grid of whole runs (radial 0 / 0.2 / 0.5 / 1.0 mm, phase 90 / 180 deg) is
``python -m benchmarks.cell_calibration``."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.cell_calibration import sphere4

PERIOD = 1.0e-9


def _wrap(x, per=PERIOD):
    return (x + per / 2) % per - per / 2


# -- the fit's columns: the zero crossings across the pair's line -----------------------------

@pytest.mark.parametrize("true_ps", [-230.0, 29.0, 280.0])
@pytest.mark.parametrize("bias_deg", [0.0, 0.02, 0.04])
def test_fit_on_the_crossing_columns_finds_the_coherence_point_despite_biased_vertices(
        true_ps, bias_deg):
    """Signed errors as a 2-D pair gives them: along its line even about the coherence point
    (1 - cos), its vertex past zero by the estimator's bias, across it odd (sin) with an even
    part: only the across columns cross zero between the window's ends, and their fit as
    crossing columns (zero at the point, any shape) lands on the point within 0.01 ps."""
    from rtsgeom.calibration.fit import CentreFit, crossing_columns, fit_centre
    near = true_ps * 1e-12 + 40e-12  # the coarse minimum, a step and a half off
    d = near + np.arange(-25, 26) * 10e-12
    th = 2 * np.pi * (d - true_ps * 1e-12) / PERIOD
    even = np.radians(1.2) * (1 - np.cos(th)) - np.radians(bias_deg)
    odd = np.radians(0.03) * np.sin(th) + np.radians(0.01) * (1 - np.cos(th))
    e = np.stack([odd, -even, 0.8 * odd, 0.9 * even], axis=1)
    cross = crossing_columns(e)
    assert cross.tolist() == [True, False, True, False]
    got = fit_centre(d, e[:, cross], PERIOD, near, CentreFit(2, 125e-12, odd=[True, True]))
    assert abs(got - true_ps * 1e-12) < 0.01e-12
    # fitted as symmetric (no zero at the point), the odd columns' even part moves it
    assert abs(fit_centre(d, e[:, cross], PERIOD, near, CentreFit(2, 125e-12))
               - true_ps * 1e-12) > 5e-12


def test_crossing_columns_none_where_every_error_is_even():
    """A pair on an arc: every probe's error even about the point, none crosses over a
    window centred near it (a column never detected does not either)."""
    from rtsgeom.calibration.fit import crossing_columns
    th = np.linspace(-np.pi / 2, np.pi / 2, 31)
    e = np.stack([1 - np.cos(th), 0.5 * (1 - np.cos(th)), np.full(th.size, np.nan)], 1)
    assert crossing_columns(e).tolist() == [False, False, False]


# -- a 2-D pair's coherence point: the array's phase centre -----------------------------------

@pytest.mark.heavy
def test_elevation_pairs_coherence_point_is_the_phase_centres_closed_form():
    """sphere4's pairs stacked in elevation are coherent at +29 ps on the perfect setup: the
    four elevated virtual elements (lambda/2 up, 4 of 12) put the array's phase centre
    lambda/6 above the RuT's reference, and a channel from direction u sees its phase k0 u .
    p_c: (u_J - u_I) . p_c / lambda of a period. The model's point within 0.3 ps of that, and
    the calibration (noiseless, full chain, the errors along the pair's line) within 2 ps of
    it (1.8 ps: where the fit's window sits about the point moves it that much)."""
    from rtsgeom.calibration.pair import calibrate_pair, pair_coherence
    from rtsgeom.calibration.probes import probe_front_ends
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    scene = sphere4()
    scene = scene.evolve(radar=scene.radar.evolve(snr_db=None))
    setup = build_setup(scene)
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, 0)
    rut = setup.rut
    centre = rut.virtual_local.mean(axis=0)  # (x lateral, y, z up), radar frame
    assert centre[2] == pytest.approx(rut.wavelength_m / 6, rel=1e-9)
    u = setup.fe_direction_cosines(2)
    for pair in ((0, 1), (2, 3)):
        du = u[pair[1]] - u[pair[0]]
        cal = calibrate_pair(setup, paths, pair, probe, seed=0)
        closed = (du[0] * centre[0] + du[1] * centre[2]) / rut.wavelength_m * cal.period_s
        assert closed == pytest.approx(29.2e-12, abs=0.1e-12)
        point = pair_coherence(setup, paths, pair, probe, near_s=cal.delta_tau_s).continuous_s
        assert abs(point - closed) < 0.3e-12
        assert abs(cal.fit_s - point) < 2e-12
        assert cal.fit_columns == (0, 2) and cal.odd_columns == ()  # along the line, even


# -- the solver's start with calibrated phases ------------------------------------------------

@pytest.fixture(scope="module")
def nominal_sphere4():
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    setup = build_setup(sphere4())
    return setup, exact_paths(setup)


@pytest.mark.parametrize("offset_ps", [0.0, 120.0, 250.0, -250.0, 750.0])
@pytest.mark.parametrize("u_set", [(0.121869, 0.0), "centre", (0.17, 0.05)])
def test_calibrated_cell_reaches_its_directions_whatever_its_channel_offsets(
        nominal_sphere4, offset_ps, u_set):
    """Calibration offsets rotate a channel's phase on the model (250 ps: ~90 deg at the
    1 ns period) and ``tree_phases`` rotates it back: the calibrated channels are coherent
    pairwise whatever the offset, so every direction inside the cell is reached. The
    closed-form start once took the tree phases as deviations from coherence, and from
    90 deg on the Gauss-Newton did not recover (sphere4 + 0.5 mm: 'outside what this cell
    can synthesize' at the cell's centre). Not at half a period (500 ps, 7.5 cm: half a
    range bin between the rows): there the elevation of (7, 0) deg and the centre are not
    reached (the detected elevation jumps across 0 as the rows' ratio grows; open)."""
    from rtsgeom.calibration.channels import tree_phases
    from rtsgeom.radar.steering import Steering
    from rtsgeom.synthesis.model import ChannelModel
    from rtsgeom.scene import TargetConfig
    setup, paths = nominal_sphere4
    offs = np.array([0.0, offset_ps, 2.0, offset_ps + 35.0]) * 1e-12
    cs = ChannelModel.build(setup, paths, (0, 1, 2, 3), TargetConfig(20.0), offs,
                            steering=Steering.auto(setup.rut, setup.scene.radar))
    u = cs.fe_directions().mean(axis=0) if u_set == "centre" else np.array(u_set)
    w = cs.solve(u, tree_phases(cs, [(0, 1), (0, 2), (1, 3)]))
    assert np.allclose(cs.direction_cosines(w, u), u, atol=1e-8)
    assert np.all(np.abs(w) > 0)


# -- failures and loop closures are said, naming the pair --------------------------------------

def _fake_pairs(monkeypatch, delays_ps, fail=()):
    import rtsgeom.calibration.channels as ncal
    from rtsgeom.calibration.sweep import Calibration

    def fake(setup, paths, pair, probe, base_offsets=(0.0, 0.0), *, config=None):
        if tuple(pair) in fail:
            raise ncal.CalibrationFailed(f"pair {tuple(pair)}: no probe detected")
        none = np.zeros(0)
        return Calibration(tuple(pair), delays_ps[tuple(pair)] * 1e-12, 0.0, 0.0, none, none,
                           none, none, (), PERIOD)
    monkeypatch.setattr(ncal, "calibrate_pair", fake)


CONSISTENT = {(0, 1): 29.0, (0, 2): 2.0, (0, 3): 31.0, (1, 3): 2.0, (2, 3): 29.0}


@pytest.mark.parametrize("closure_ps", [0.0, 20.0, 40.0, -120.0])
def test_loop_closure_beyond_tolerance_is_a_warning_naming_the_pair(
        nominal_sphere4, monkeypatch, closure_ps):
    from rtsgeom.calibration.probes import probe_front_ends
    from rtsgeom.calibration.channels import LOOP_CLOSURE_TOL_S, calibrate_channels
    setup, paths = nominal_sphere4
    delays = dict(CONSISTENT)
    delays[(0, 3)] += closure_ps  # off the tree (0,1), (0,2), (1,3)
    _fake_pairs(monkeypatch, delays)
    probe = probe_front_ends(setup, paths, 1)
    cal = calibrate_channels(setup, paths, [0, 1, 2, 3], probe)
    closures = dict(zip([e for e in sorted(delays) if e not in cal.tree], cal.loop_closure_s))
    assert closures[(0, 3)] == pytest.approx(closure_ps * 1e-12, abs=1e-13)
    flagged = [w for w in cal.warnings if "loop" in w]
    assert bool(flagged) == (abs(closure_ps) * 1e-12 > LOOP_CLOSURE_TOL_S)
    assert all("(0, 3)" in w for w in flagged)
    assert cal.to_dict()["warnings"] == list(cal.warnings)


def test_a_pair_that_fails_is_named_and_a_cell_it_disconnects_stops_the_run(
        nominal_sphere4, monkeypatch):
    from rtsgeom.calibration.probes import probe_front_ends
    from rtsgeom.errors import CalibrationFailed
    from rtsgeom.calibration.channels import calibrate_channels
    from rtsgeom.pipeline.plan import plan_targets
    from rtsgeom.errors import SceneError
    setup, paths = nominal_sphere4
    probe = probe_front_ends(setup, paths, 1)
    _fake_pairs(monkeypatch, CONSISTENT, fail={(0, 3)})  # a Delaunay edge off the tree
    cal = calibrate_channels(setup, paths, [0, 1, 2, 3], probe)
    assert any("(0, 3)" in w for w in cal.warnings) and cal.failed
    _fake_pairs(monkeypatch, CONSISTENT, fail={(0, 1), (0, 2), (0, 3)})  # 0 cut off
    why = ("channel calibration: pair (0, 1): no probe detected; channel calibration: pair "
           "(0, 2): no probe detected; channel calibration: pair (0, 3): no probe detected; "
           "channels [1, 2, 3] are not connected to the reference 0 by calibrated pairs")
    with pytest.raises(CalibrationFailed) as exc:
        calibrate_channels(setup, paths, [0, 1, 2, 3], probe)
    assert str(exc.value) == why
    with pytest.raises(SceneError) as exc:
        plan_targets(setup, paths, "exact")
    assert str(exc.value) == f"{setup.scene.source}: the channel calibration failed: {why}"
    _fake_pairs(monkeypatch, CONSISTENT, fail={(0, 3), (1, 3), (2, 3)})  # 3 alone cut off
    with pytest.raises(CalibrationFailed) as exc:
        calibrate_channels(setup, paths, [0, 1, 2, 3], probe)
    assert str(exc.value) == (
        "channel calibration: pair (0, 3): no probe detected; channel calibration: pair "
        "(1, 3): no probe detected; channel calibration: pair (2, 3): no probe detected; "
        "channels [3] are not connected to the reference 0 by calibrated pairs")


def test_run_says_the_calibration_failed_when_it_is_why_a_target_is_unreachable(
        nominal_sphere4, monkeypatch):
    """A target inside its cell that the calibrated channels cannot reach, after a
    calibration with warnings: the message says the calibration failed and why."""
    import rtsgeom.calibration.channels as ncal
    import rtsgeom.pipeline.plan as plan
    from rtsgeom.errors import AngleUnreachable
    from rtsgeom.synthesis.model import ChannelModel
    from rtsgeom.errors import SceneError
    setup, paths = nominal_sphere4
    bad = ncal.ChannelCalibration(np.zeros(4), 0, [], [(0, 1), (0, 2), (1, 3)], [40e-12],
                                  warnings=("channel calibration: the loop through pair "
                                            "(0, 3) closes to 40.0 ps",))
    monkeypatch.setattr(plan, "calibrate_channels", lambda *a, **k: bad)

    def unreachable(self, *a, **k):
        raise AngleUnreachable("outside what this cell can synthesize")
    monkeypatch.setattr(ChannelModel, "solve", unreachable)
    with pytest.raises(SceneError, match=r"calibration failed .*\(0, 3\)"):
        plan.plan_targets(setup, paths, "exact")


# -- the elevation pair against its coherence point (full chain at every step) -----------------

@pytest.mark.slow
@pytest.mark.heavy
@pytest.mark.parametrize("field, value", [("radial_offset_mm", 0.5), ("radial_offset_mm", 1.0),
                                          ("phase_offset_deg", 90.0),
                                          ("phase_offset_deg", 180.0)])
def test_elevation_pair_calibrates_to_its_coherence_point_with_a_front_end_off(field, value):
    """Pair (0, 1) of sphere4 (stacked in elevation) with front end 1 moved radially or
    given a hardware phase: the calibrated delay within 5 ps of the continuous coherence
    point on the setup as built (12 ps with one frame a step, before the frames per step
    were sized; 16 and 32 ps off at 0.5 mm and 90 deg, 71 ps with the joint fit over all
    columns, before that); the radial offset moves the point by
    -air/IF phase slope x 2 dr / c0 (~-258 ps per 0.5 mm), the phase by phi / (2 pi f_IF)."""
    from scipy.constants import c

    from rtsgeom.calibration.probes import (air_phase_slope_hz, if_phase_slope_hz, probe_front_ends,
                                            probe_ranges, probe_total_delay)
    from rtsgeom.calibration.pair import calibrate_pair, pair_coherence
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    scene = sphere4(field, value)
    setup = build_setup(scene)
    paths = exact_paths(setup)
    probe = probe_front_ends(setup, paths, scene.seed)
    got = calibrate_pair(setup, paths, (0, 1), probe, seed=scene.seed).to_dict()
    per = got["period_s"]
    point = pair_coherence(setup, paths, (0, 1), probe, near_s=got["delta_tau_s"]).continuous_s
    assert abs(_wrap(got["delta_tau_s"] - point, per)) < 5e-12
    # the point itself moves as the closed form says (nominal point from the nominal scene)
    nom = build_setup(sphere4())
    p0 = pair_coherence(nom, exact_paths(nom), (0, 1), probe, near_s=0.0).continuous_s
    tau = probe_total_delay(setup, probe_ranges(setup, 2))
    f_if = float(if_phase_slope_hz(scene, tau))
    if field == "radial_offset_mm":
        shift = -float(air_phase_slope_hz(scene, tau)) / f_if * 2 * value * 1e-3 / c
    else:
        shift = np.radians(value) / (2 * np.pi * f_if)
    assert abs(_wrap(point - p0 - shift, per)) < 6e-12


@pytest.mark.parametrize("d01_ps, d13_ps", [(-484.0, -500.0), (480.0, 470.0), (-250.0, -260.0)])
def test_channel_offsets_are_taken_to_the_period_nearest_zero(nominal_sphere4, monkeypatch,
                                                               d01_ps, d13_ps):
    """Pair delays add up along the tree to beyond half a period (180 deg on front end 1:
    channel 3 at -984 ps, its echo a whole range bin from the others); each channel's
    offset is wrapped to (-period/2, period/2], and the loop closures do not change."""
    from rtsgeom.calibration.probes import probe_front_ends
    from rtsgeom.calibration.channels import calibrate_channels
    setup, paths = nominal_sphere4
    delays = {(0, 1): d01_ps, (0, 2): 2.0, (0, 3): d01_ps + d13_ps, (1, 3): d13_ps,
              (2, 3): d01_ps + d13_ps - 2.0}
    _fake_pairs(monkeypatch, delays)
    cal = calibrate_channels(setup, paths, [0, 1, 2, 3], probe_front_ends(setup, paths, 1))
    assert np.all(np.abs(cal.offsets_s) <= PERIOD / 2 + 1e-15)
    want = np.array([0.0, d01_ps, 2.0, d01_ps + d13_ps]) * 1e-12
    assert np.allclose(_wrap(cal.offsets_s - want), 0.0, atol=1e-15)
    assert np.allclose(cal.loop_closure_s, 0.0, atol=1e-15)
