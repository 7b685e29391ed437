"""The datasheet's sections (rtsgeom.analysis.kpi.sections), each compared WHOLE (every key
and value) with what is built here from the inputs and the analyses they summarise: the field
of view's covered intervals and gaps, the range and velocity accuracy over the run's matches,
the target budget's notes, the ghosts' and the near field's sections, the resolution's
fallback note."""

from __future__ import annotations

import math
from types import SimpleNamespace

from scipy.constants import c

import numpy as np
import pytest
from conftest import make_scene, quiet

from rtsgeom.analysis.ghosts import ghost_analysis
from rtsgeom.analysis.kpi.sections import (RESOLUTION_PHASES_DEG, RESOLUTION_STEP_DEG, _merge,
                                           field_of_view, ghosts_section, nearfield_section,
                                           range_velocity, resolution_section, targets_section,
                                           uncovered_deg)
from rtsgeom.analysis.nearfield import nearfield
from rtsgeom.geometry import build_setup
from rtsgeom.geometry.farfield import angular_resolution_rad
from rtsgeom.paths import exact_paths
from rtsgeom.pipeline.info import reachable_spans
from rtsgeom.scene.rules import resolvable_limits
from rtsgeom.scene.sections import MAX_TARGETS


def _three(doc, mode="exact", wide=False):
    """Three front ends at -20, 3.4 and 12.2 deg: the first pair wider than the RuT's angular
    resolution (17.5 deg), the second within it."""
    quiet(doc)
    doc["sheet"]["angle_min_deg"] = -30.0
    fe = dict(doc["rts"]["front_ends"][0])
    fe["angle_deg"] = -20.0
    doc["rts"]["front_ends"].insert(0, fe)
    doc["rts"]["aoa_mode"] = mode
    doc["rts"]["allow_wide_spacing"] = wide
    doc["targets"] = []


@pytest.fixture(scope="module")
def three():
    """{(mode, wide): (setup, paths)} of the three-front-end arc."""
    out = {}
    for key in (("exact", False), ("exact", True), ("nearest", False)):
        setup = build_setup(make_scene(lambda d: _three(d, *key)))
        out[key] = (setup, exact_paths(setup))
    return out


def _expected_fov(setup, paths, covered, gaps, ok):
    spans = reachable_spans(setup, None, paths)
    m = spans["measured_angle_deg"]
    geo = np.degrees(setup.fe_azimuth_rad())
    return {"mode": spans["mode"], "cells": False,
            "front_ends": [{"index": q, "geometric_azimuth_deg": float(geo[q]),
                            "measured_azimuth_deg": float(m[q]), "elevation_deg": 0.0}
                           for q in range(3)],
            "pairs": [{"pair": [q, q + 1], "lo_deg": spans["pairs"][q]["lo_deg"],
                       "hi_deg": spans["pairs"][q]["hi_deg"],
                       "spacing_deg": abs(float(geo[q + 1] - geo[q])), "synthesizable": ok[q]}
                      for q in range(2)],
            "azimuth_deg": [m[0], m[2]], "elevation_deg": [0.0, 0.0],
            "covered_deg": covered(m), "gaps_deg": gaps(m),
            "angular_resolution_deg": math.degrees(angular_resolution_rad(setup.rut))}


@pytest.mark.parametrize("key, covered, gaps, ok", [
    # the wide pair is not synthesized: its front ends' points alone, a gap between them
    (("exact", False), lambda m: [[m[0], m[0]], [m[1], m[2]]], lambda m: [[m[0], m[1]]],
     [False, True]),
    # allow_wide_spacing forces it: one interval
    (("exact", True), lambda m: [[m[0], m[2]]], lambda m: [], [True, True]),
    # nearest synthesizes nothing: three points, two gaps
    (("nearest", False), lambda m: [[x, x] for x in m], lambda m: [[m[0], m[1]], [m[1], m[2]]],
     [False, False]),
])
def test_the_field_of_view_covers_the_synthesizable_pairs_and_names_the_gaps(three, key,
                                                                             covered, gaps, ok):
    setup, paths = three[key]
    res = math.degrees(angular_resolution_rad(setup.rut))
    geo = np.degrees(setup.fe_azimuth_rad())
    assert geo[1] - geo[0] > res > geo[2] - geo[1]  # the scene is what the cases assume
    fov = field_of_view(setup, paths)
    assert fov == _expected_fov(setup, paths, covered, gaps, ok)
    lo, hi = fov["azimuth_deg"]
    assert uncovered_deg(fov, [lo, hi]) == pytest.approx(
        sum(b - a for a, b in fov["gaps_deg"]), abs=1e-12)


def test_a_scene_of_cells_has_its_front_ends_azimuths_and_elevations(sphere_scene):
    setup = build_setup(sphere_scene)
    geo = np.degrees(setup.fe_azimuth_rad())
    elev = [math.degrees(f.elevation_rad) for f in sphere_scene.rts.front_ends]
    assert field_of_view(setup, None) == {
        "mode": sphere_scene.rts.aoa_mode, "cells": True,
        "front_ends": [{"index": q, "geometric_azimuth_deg": float(geo[q]),
                        "elevation_deg": elev[q]} for q in range(len(geo))],
        "azimuth_deg": [float(geo.min()), float(geo.max())],
        "elevation_deg": [min(elev), max(elev)], "pairs": [], "covered_deg": [],
        "gaps_deg": [], "angular_resolution_deg": math.degrees(angular_resolution_rad(
            setup.rut))}


@pytest.mark.parametrize("intervals, merged", [
    ([], []),
    ([(2.0, 3.0), (0.0, 1.0)], [[0.0, 1.0], [2.0, 3.0]]),  # sorted, apart
    ([(0.0, 1.0), (1.0, 2.0)], [[0.0, 2.0]]),  # touching: one
    ([(0.0, 1.0), (1.0 + 0.5e-9, 2.0)], [[0.0, 2.0]]),  # within the 1e-9 slack: one
    ([(0.0, 1.0), (1.0 + 2e-9, 2.0)], [[0.0, 1.0], [1.0 + 2e-9, 2.0]]),  # beyond it: two
    ([(0.0, 5.0), (1.0, 2.0)], [[0.0, 5.0]]),  # inside: the longer end kept
    ([(0.0, 1.0), (0.5, 3.0), (2.0, 4.0)], [[0.0, 4.0]]),  # a chain
])
def test_merge_joins_overlapping_and_touching_intervals(intervals, merged):
    assert _merge(intervals) == merged


@pytest.mark.parametrize("covered, span, missed", [
    ([], [0.0, 4.0], 4.0),
    ([[1.0, 2.0]], [0.0, 4.0], 3.0),
    ([[-5.0, 1.0], [3.0, 9.0]], [0.0, 4.0], 2.0),  # clipped at both ends
    ([[-5.0, 9.0]], [0.0, 4.0], 0.0),
    ([[5.0, 9.0]], [0.0, 4.0], 4.0),  # outside: nothing inside
    ([[1.0, 2.0]], [3.0, 3.0], 0.0),
])
def test_uncovered_is_the_span_less_its_covered_parts(covered, span, missed):
    assert uncovered_deg({"covered_deg": covered}, span) == pytest.approx(missed, abs=1e-12)


@pytest.mark.parametrize("compensate, fir", [(True, True), (False, False)])
def test_the_range_and_velocity_section_without_targets_in_full(compensate, fir):
    """Every key of the section of a scene without targets: the limits from the air path, the
    FIR's bulk delay and the processing (``scene.rules.resolvable_limits``)."""
    def mutate(doc):
        quiet(doc)
        doc["rts"].update(compensate_air_path=compensate, fractional_delay=fir)
        if not fir:
            doc["rts"]["calibration_step_ps"] = 250.0
    setup = build_setup(make_scene(mutate))
    radar, rts = setup.scene.radar, setup.scene.rts
    r_lim, v_lim, why_r, why_v = resolvable_limits(radar)
    air = rts.arc_radius_m  # the RuT at the arc's centre
    fir_m = 0.5 * c * (rts.fractional_delay_taps - 1) / 2 / rts.f_s_hz if fir else 0.0
    unsub = 0.0 if compensate else air
    assert range_velocity(setup, None) == {
        "min_range_m": pytest.approx(air + fir_m), "max_range_m": pytest.approx(r_lim - unsub),
        "limits": {"air_path_m": pytest.approx(air), "fir_latency_m": pytest.approx(fir_m),
                   "fir_latency_note": "[assumed] the fractional-delay FIR's bulk (taps - 1)/2 "
                                       "samples are part of the delay buffer (rts.fir), the "
                                       "least delay the back end realises",
                   "buffer_note": "the scene declares no buffer depth: no limit from it",
                   "processing_max_range_m": r_lim, "processing_note": why_r,
                   "unsubtracted_air_path_m": pytest.approx(unsub, abs=1e-12)},
        "max_velocity_mps": v_lim, "velocity_note": why_v,
        "range_resolution_m": radar.range_resolution_m,
        "velocity_resolution_mps": radar.velocity_resolution_mps,
        "range_step_m": 0.5 * c * rts.delay_resolution_s,
        "range_accuracy_m": None, "velocity_accuracy_mps": None, "targets": [],
        "accuracy_note": "the scene has no [[targets]] to measure"}


def _match(k, r, v, err):
    return {"index": k, "set": {"range_m": r, "velocity_mps": v},
            "error": None if err is None else {"range_m": err[0], "velocity_mps": err[1]}}


@pytest.mark.parametrize("matches, rows, acc_r, acc_v", [
    ([_match(0, 10.0, 1.0, (0.02, -0.3)), _match(3, 20.0, -2.0, None),
      _match(5, 30.0, 0.0, (-0.05, 0.1))],
     [(0, 10.0, 1.0, 0.02, -0.3, True), (3, 20.0, -2.0, None, None, False),
      (5, 30.0, 0.0, -0.05, 0.1, True)], 0.05, 0.3),
    ([_match(1, 10.0, 1.0, None)], [(1, 10.0, 1.0, None, None, False)], None, None),
])
def test_the_range_and_velocity_accuracy_is_the_largest_error_of_the_detected_targets(
        matches, rows, acc_r, acc_v):
    setup = build_setup(make_scene(quiet))
    without = range_velocity(setup, None)
    assert without["accuracy_note"] == "the scene has no [[targets]] to measure"
    assert (without["targets"], without["range_accuracy_m"], without["velocity_accuracy_mps"]) \
        == ([], None, None)
    got = range_velocity(setup, SimpleNamespace(matches=matches))
    keys = ("index", "set_range_m", "set_velocity_mps", "range_error_m", "velocity_error_mps",
            "detected")
    assert got == {**without, "targets": [dict(zip(keys, r)) for r in rows],
                   "range_accuracy_m": acc_r, "velocity_accuracy_mps": acc_v,
                   "accuracy_note": "largest |detected - set| over the scene's targets through "
                                    "the full chain (rtsgeom run), at the scene's SNR"}


def _budget_run(margins):
    lb = SimpleNamespace(to_dict=lambda: {"targets": [{"clip_margin_db": m} for m in margins]})
    return SimpleNamespace(link_budget=lb)


CLIP = "the RuT's ADC clips {:.1f} dB above the strongest target's echo: that many equal " \
       "echoes adding in phase"
BACK = "the back end synthesizes {} per channel (rts.max_targets_per_channel)"
NONE = ("no clip margin known (no targets to budget) and no rts.max_targets_per_channel: the "
        "scene's limit")


@pytest.mark.parametrize("mode, fov_cells, per_target", [
    ("exact", False, 2), ("nearest", False, 1), ("exact", True, 1)])
@pytest.mark.parametrize("run, budget, margin, per_channel, notes", [
    (None, None, None, MAX_TARGETS, [NONE]),
    (SimpleNamespace(link_budget=None), None, None, MAX_TARGETS, [NONE]),
    (_budget_run([None]), None, None, MAX_TARGETS, [NONE]),
    # 10^(12/20) = 3.98 equal echoes: 3; the least margin counts
    (_budget_run([20.0, None, 12.0]), None, 12.0, 3, [CLIP.format(12.0)]),
    (_budget_run([40.0]), None, 40.0, 100, [CLIP.format(40.0)]),  # 10^2 exactly: 100
    (_budget_run([80.0]), None, 80.0, MAX_TARGETS, [CLIP.format(80.0)]),  # the limit
    (None, 7, None, 7, [BACK.format(7)]),
    (_budget_run([40.0]), 7, 40.0, 7, [CLIP.format(40.0), BACK.format(7)]),
    (_budget_run([12.0]), 7, 12.0, 3, [CLIP.format(12.0), BACK.format(7)]),
])
def test_the_target_budget_is_the_least_of_the_clip_margin_the_back_end_and_the_limit(
        mode, fov_cells, per_target, run, budget, margin, per_channel, notes):
    def mutate(doc):
        quiet(doc)
        if budget is not None:
            doc["rts"]["max_targets_per_channel"] = budget
    setup = build_setup(make_scene(mutate))
    got = targets_section(setup, run, {"mode": mode, "cells": fov_cells})
    assert got == {"per_channel": per_channel,
                   "total": min(MAX_TARGETS, per_channel * 2 // per_target), "channels": 2,
                   "channels_per_target": per_target, "clip_margin_db": margin,
                   "max_targets_per_channel": budget, "scene_limit": MAX_TARGETS,
                   "note": "; ".join(notes)}


SETUP_NOTE = ("the setup's own reflections (the sheet) in the run's link budget; exact paths "
              "carry none: rtsgeom info with [radar.link] estimates the sheet by physical optics")


@pytest.mark.parametrize("ghosts", [True, False])
def test_the_ghosts_section_is_the_ghost_analysis_and_the_runs_setup_echoes(ghosts):
    scene = make_scene(None if ghosts else quiet)
    d = ghost_analysis(scene).to_dict()
    levels = [g["level_db"] for fe in d["front_ends"] for g in fe["ghosts"]]
    assert bool(levels) == ghosts
    echoes = [{"name": "sheet", "level_db": -31.0}]
    lb = SimpleNamespace(to_dict=lambda: {"setup_echoes": echoes})
    for run, want in ((None, []), (SimpleNamespace(link_budget=None), []),
                      (SimpleNamespace(link_budget=SimpleNamespace(to_dict=dict)), []),
                      (SimpleNamespace(link_budget=lb), echoes)):
        strongest = max(levels) if levels else None
        assert ghosts_section(scene, run) == {
            "floor_db": d["floor_db"], "cable_ghosts": d["front_ends"], "model": d["model"],
            "strongest_ghost_db": strongest,
            "ghost_suppression_db": -strongest if ghosts else -d["floor_db"],
            "ghost_suppression_note": "the strongest cable ghost below its target" if ghosts
            else f"no cable ghost above the floor {d['floor_db']:g} dB: at least that",
            "setup_echoes": want, "setup_echoes_note": SETUP_NOTE}


@pytest.mark.parametrize("radius_m", [1.0, 2.5])
def test_the_nearfield_section_is_the_nearfield_analysis_at_the_scenes_radius(radius_m):
    setup = build_setup(make_scene(lambda d: d["rts"].update(arc_radius_m=radius_m)))
    got, nf = nearfield_section(setup)
    d = nearfield(setup.scene, [radius_m], 5).to_dict()
    assert nf.to_dict() == d
    at = d["at_scene_radius"]
    dist = np.linalg.norm(setup.fe.module - np.asarray(setup.scene.radar.position_m), axis=-1)
    assert dist == pytest.approx(radius_m)
    f_d = d["fraunhofer_distance_m"]
    assert got == {
        "fraunhofer_distance_m": f_d, "fraunhofer_note": d["fraunhofer_note"],
        "front_ends": [{"index": q, "distance_m": float(dist[q]), "fraunhofer_distance_m": f_d,
                        "distance_over_fraunhofer": float(dist[q]) / f_d,
                        "bias_deg": f["bias_deg"], "phase_error_pp_deg": f["phase_error_pp_deg"]}
                       for q, f in enumerate(at["front_ends"])],
        "pairs": at["synthesis"],
        "bias_1_over_r_coefficient_deg_m": d["bias_1_over_r_coefficient_deg_m"]}
    assert [p["pair"] for p in got["pairs"]] == [[0, 1]]


@pytest.mark.parametrize("spacing_deg", [2.9, 2.99])
def test_an_arc_too_narrow_for_two_targets_has_no_resolution_and_says_its_span(spacing_deg):
    """The separations run every 2 deg up to twice the arc's half-span less 1 deg: a span of
    2.9 or 2.99 deg reaches 1.9 or 1.99 deg, none."""
    def mutate(doc):
        quiet(doc)
        doc["rts"]["front_ends"][1]["angle_deg"] = 3.4 + spacing_deg
    setup = build_setup(make_scene(mutate))
    assert resolution_section(setup, progress=lambda *a: pytest.fail("no study runs")) == {
        "min_separation_deg": None, "rts_deg": None, "truth_deg": None,
        "note": f"the arc spans {spacing_deg:.2f} deg: no two targets "
                f"{RESOLUTION_STEP_DEG:g} deg apart fit between its front ends"}


@pytest.mark.parametrize("rts, truth, worst_rts, worst_truth", [
    ({"0": 4.0, "90": 6.0, "180": 2.0}, {"0": 2.0, "90": 2.0, "180": 4.0}, 6.0, 4.0),
    ({"0": None, "90": 6.0, "180": 2.0}, {"0": 2.0, "90": 2.0, "180": 2.0}, None, 2.0),
    ({"0": 4.0, "90": 4.0, "180": 4.0}, {"0": None, "90": None, "180": None}, 4.0, None),
    ({}, {}, None, None),
])
def test_the_resolution_section_runs_the_study_on_the_arcs_middle(monkeypatch, rts, truth,
                                                                  worst_rts, worst_truth):
    """An arc of 3.4 .. 12.2 deg: separations 2, 4, 6 deg (up to 8.8 - 1) about 7.8 deg at
    the three phases; every progress call a (label, 0, 1); the worst over the phases, None
    where one is not resolved."""
    import rtsgeom.analysis.kpi.sections as sections
    seen = {}

    class Study:
        def __init__(self, **kw):
            seen["config"] = kw

        def __call__(self, scene, say):
            seen["scene"] = scene
            if say is None:
                return SimpleNamespace(min_separation_deg={"rts": rts, "truth": truth},
                                       range_m=12.5)
            say("a step", 3, 7)
            say("another")
            return SimpleNamespace(min_separation_deg={"rts": rts, "truth": truth}, range_m=12.5)
    monkeypatch.setattr(sections, "ResolutionStudy", Study)
    setup = build_setup(make_scene(quiet))
    calls = []
    got = resolution_section(setup, progress=lambda *a: calls.append(a))
    assert calls == [("a step", 0, 1), ("another", 0, 1)]
    assert seen["scene"] is setup.scene
    assert seen["config"] == {"centre_deg": pytest.approx(7.8),
                              "separations_deg": (2.0, 4.0, 6.0),
                              "phases_deg": (0.0, 90.0, 180.0)}
    note = ("the RTS's worst over the phases" if worst_rts is not None else
            "the RTS does not resolve two targets at every phase up to 6 deg (the largest "
            "separation the arc reaches)")
    assert got == {"min_separation_deg": {"rts": rts, "truth": truth}, "rts_deg": worst_rts,
                   "truth_deg": worst_truth, "centre_deg": pytest.approx(7.8), "range_m": 12.5,
                   "separations_deg": [2.0, 4.0, 6.0], "phases_deg": [0.0, 90.0, 180.0],
                   "note": note}
    seen.clear()
    resolution_section(setup)  # no progress: the study is told None
    assert seen["scene"] is setup.scene
