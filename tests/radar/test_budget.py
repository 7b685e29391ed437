"""The static budget's option gates read in full: with ``[radar.link]`` the budget carries the
sheet's physical-optics estimate (rows equal to ``setup_echoes`` of ``sheet_paths`` through the
link), without the link or without a sheet it carries none; cable ghosts stay out of a target's
row (only its direct echoes count)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy.constants import c

from conftest import make_scene
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.radar import budget
from rtsgeom.radar.budget import link_budget, static_budget
from rtsgeom.radar.link import apply_radar_link, beat_hz, dbm, if_response
from rtsgeom.rts.channels import (KIND_DIRECT, KIND_GHOST, build_echoes, program_nearest,
                                  setup_echoes)


def _doc(linked: bool, sheet: bool, ghosts: bool = False):
    def mut(doc):
        doc["radar"].pop("snr_db", None)
        doc["radar"].update(samples_per_chirp=128, chirps_per_tx=32, adc_rate_hz=12.5e6)
        if linked:
            doc["radar"]["link"] = {}
        else:
            doc["radar"]["snr_db"] = 30.0
        doc["rts"]["front_ends"] = doc["rts"]["front_ends"][:1]
        fe = doc["rts"]["front_ends"][0]
        fe["angle_deg"] = 0.0
        if ghosts:
            fe["return_loss_fe_db"] = fe["return_loss_be_db"] = 10.0
        else:
            fe.pop("return_loss_fe_db", None)
            fe.pop("return_loss_be_db", None)
        doc["rts"]["fractional_delay_filter"] = "ideal"
        doc["rts"]["aoa_mode"] = "nearest"
        doc["sheet"]["enabled"] = sheet
        doc["sheet"]["angle_min_deg"], doc["sheet"]["angle_max_deg"] = -15.0, 15.0
        doc["targets"] = [{"range_m": 20.0, "rcs_dbsm": 10.0, "angle_deg": 0.0}]
    return make_scene(mut)


@pytest.fixture(scope="module")
def linked_sheet():
    setup = build_setup(_doc(True, True))
    # the sheet's PO estimate with a coarse grid (lambda): the gate is under test, not PO
    lam = c / setup.scene.radar.f_center_hz
    return setup, budget.sheet_paths(setup, step_m=lam)


def test_a_linked_budget_carries_the_sheets_estimate_row_for_row(linked_sheet, monkeypatch):
    """``static_budget`` on a linked scene with a sheet: after the in-signal setup rows, one
    row per ``setup_echoes(setup, sheet_paths(setup))`` echo, its levels that echo's through
    the link (power over the virtual channels, IF response, range and beat), marked not in the
    signal and sourced to physical optics; the rest of the budget is ``link_budget``'s."""
    setup, sp = linked_sheet
    calls = []
    monkeypatch.setattr(budget, "sheet_paths", lambda s: calls.append(s) or sp)
    got = static_budget(setup)
    assert calls == [setup]
    scene = setup.scene
    est = setup_echoes(setup, sp)
    assert len(est) > 0  # one echo over the virtual channels per reflection
    program = program_nearest(scene, setup)
    raw = build_echoes(setup, exact_paths(setup), program)
    want = link_budget(scene, raw, program, False, None, est, predict=True, setup=setup)
    assert got.to_dict() == want.to_dict()
    # the estimate's rows from the primitives
    n_sig = sum(r["in_signal"] for r in got.setup_echoes)
    rows = got.setup_echoes[n_sig:]
    assert len(rows) == len(est) and not any(r["in_signal"] for r in rows)
    e = apply_radar_link(est, scene)
    f_b = beat_hz(est, scene.radar)
    from rtsgeom.radar.link import radar_link
    h2 = np.mean(np.abs(if_response(radar_link(scene.radar), f_b)) ** 2, axis=1)
    noise = got.noise_w * h2 + got.quantisation_noise_w
    for j, r in enumerate(rows):
        p_adc = float(np.mean(np.abs(e.amplitude[j]) ** 2))
        assert set(r) == {"index", "range_m", "beat_hz", "in_signal", "source", "adc_power_dbm",
                          "if_response_db", "snr_after_fft_db", "clip_margin_db"}
        assert r["index"] == n_sig + j
        assert r["source"] == "sheet, physical-optics estimate"
        assert r["range_m"] == pytest.approx(np.mean(est.tau_s[j]) * c / 2, rel=1e-12)
        assert r["beat_hz"] == pytest.approx(np.mean(f_b[j]), rel=1e-12)
        assert r["adc_power_dbm"] == pytest.approx(float(dbm(p_adc)), abs=1e-9)
        assert r["if_response_db"] == pytest.approx(10 * np.log10(h2[j]), abs=1e-9)
        assert r["snr_after_fft_db"] == pytest.approx(
            10 * np.log10(p_adc / noise[j]) + got.fft_gain_db, abs=1e-9)
        assert r["clip_margin_db"] == pytest.approx(
            float(dbm(budget.radar_link(scene.radar).adc_full_scale_w) - dbm(p_adc)), abs=1e-9)


@pytest.mark.parametrize("linked,sheet", [(False, True), (True, False), (False, False)])
def test_without_the_link_or_the_sheet_no_estimate_is_made(linked, sheet, monkeypatch):
    """No ``[radar.link]``: the ~1 s PO estimate is skipped (``sheet_paths`` not called); no
    sheet: ``sheet_paths`` gives None. Either way every setup row is one in the signal, and
    the budget is ``link_budget``'s without an estimate."""
    setup = build_setup(_doc(linked, sheet))
    calls = []
    real = budget.sheet_paths
    monkeypatch.setattr(budget, "sheet_paths", lambda s: calls.append(s) or real(s))
    got = static_budget(setup)
    assert calls == ([setup] if linked else [])
    assert all(r["in_signal"] for r in got.setup_echoes)
    scene = setup.scene
    program = program_nearest(scene, setup)
    raw = build_echoes(setup, exact_paths(setup), program)
    assert got.to_dict() == link_budget(scene, raw, program, False, None, None, predict=True,
                                        setup=setup).to_dict()
    assert got.modelled is linked


def _subset(e, keep):
    n = len(e)
    return dataclasses.replace(e, **{
        f.name: getattr(e, f.name)[keep] for f in dataclasses.fields(e)
        if isinstance(getattr(e, f.name), np.ndarray) and getattr(e, f.name).shape[:1] == (n,)})


def test_cable_ghosts_stay_out_of_a_targets_row():
    """A scene with cable ghosts (return losses): the target's row sums its direct echoes
    only, so dropping the ghosts from the echoes leaves every target row unchanged; the
    ghosts are there (else the test would not test)."""
    setup = build_setup(_doc(False, False, ghosts=True))
    scene = setup.scene
    program = program_nearest(scene, setup)
    raw = build_echoes(setup, exact_paths(setup), program)
    ghost = raw.kind == KIND_GHOST
    assert ghost.any() and (raw.kind == KIND_DIRECT).any()
    full = link_budget(scene, raw, program, False, predict=True, setup=setup)
    direct = link_budget(scene, _subset(raw, ~ghost), program, False, predict=True, setup=setup)
    assert full.targets == direct.targets
    assert full.targets[0]["adc_power_dbm"] is not None
    assert static_budget(setup).targets == full.targets
