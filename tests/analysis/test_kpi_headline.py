"""The datasheet's headline rows (rtsgeom.analysis.kpi.headline) as literal text, over both
sides of each of its choices: gaps or none, cells or an arc, an accuracy or its note, receiver
noise or none, targets' accuracies or none, the resolution or why not, a clip margin or
none."""

from __future__ import annotations

import copy

import pytest

from rtsgeom.analysis.kpi.headline import headline

SHEET = {
    "field_of_view": {"azimuth_deg": [3.97, 12.756], "mode": "exact", "cells": False,
                      "gaps_deg": [], "elevation_deg": [0.0, 0.0]},
    "range_velocity": {"min_range_m": 1.5996, "max_range_m": 75.625, "range_resolution_m": 0.15126,
                       "range_step_m": 0.00014989, "range_accuracy_m": 0.012346,
                       "max_velocity_mps": 9.2468, "velocity_resolution_mps": 0.16222,
                       "velocity_accuracy_mps": 0.054321},
    "targets": {"per_channel": 12, "total": 12, "clip_margin_db": 21.58,
                "resolution": {"rts_deg": 6.0, "truth_deg": 4.0, "note": "n"}},
    "ghosts_leakage": {"ghost_suppression_db": 25.979},
    "angle_accuracy_summary": {"worst_accuracy_deg": 0.123456, "note": "no pair",
                               "gum_validation": "GUM validated at 3 of 3"},
    "inputs": {"snr_effective_db": 44.56, "snr_from": "radar.snr_db"},
    "near_field": {"fraunhofer_distance_m": 0.12379},
}

ROWS = [
    ("field of view", "3.97 .. 12.76 deg (exact), gaps: none"),
    ("angle accuracy", "|error| + U (k = 2) worst 0.1235 deg; GUM validated at 3 of 3"),
    ("receiver noise", "SNR 44.6 dB at the detection cell (radar.snr_db)"),
    ("range", "1.600 .. 75.62 m, resolution 0.1513 m, RTS step 0.150 mm, accuracy 0.01235 m on "
              "the scene's targets"),
    ("velocity", "+-9.247 m/s, resolution 0.1622 m/s, accuracy 0.05432 m/s"),
    ("targets", "12 per channel, 12 in total; minimum separation 6 deg on the RTS, 4 deg on "
                "real targets"),
    ("ghosts", "strongest 26.0 dB below its target; RuT ADC clip margin 21.6 dB"),
    ("near field", "Fraunhofer distance 0.124 m"),
]


def _with(changes):
    d = copy.deepcopy(SHEET)
    for (section, key), v in changes.items():
        if v is KeyError:
            del d[section][key]
        else:
            d[section][key] = v
    return d


@pytest.mark.parametrize("changes, rows", [
    ({}, {}),
    ({("field_of_view", "gaps_deg"): [[4.0, 5.5], [7.125, 8.0]]},
     {"field of view": "3.97 .. 12.76 deg (exact), gaps: 4.00 .. 5.50, 7.12 .. 8.00"}),
    ({("field_of_view", "cells"): True, ("field_of_view", "mode"): "nearest",
      ("field_of_view", "elevation_deg"): [-3.0, 4.25]},
     {"field of view": "3.97 .. 12.76 deg (nearest), gaps: none, elevation -3.00 .. 4.25 deg"}),
    ({("angle_accuracy_summary", "worst_accuracy_deg"): None},
     {"angle accuracy": "no pair"}),
    ({("inputs", "snr_effective_db"): None, ("inputs", "snr_from"): "no radar.snr_db"},
     {"receiver noise": "none: no radar.snr_db"}),
    ({("inputs", "snr_effective_db"): None, ("inputs", "snr_from"): KeyError},
     {"receiver noise": "none: radar.snr_db"}),
    ({("inputs", "snr_from"): KeyError},  # a kpi.json written before snr_from
     {"receiver noise": "SNR 44.6 dB at the detection cell (radar.snr_db)"}),
    ({("range_velocity", "range_accuracy_m"): None,
      ("range_velocity", "velocity_accuracy_mps"): None},
     {"range": "1.600 .. 75.62 m, resolution 0.1513 m, RTS step 0.150 mm, accuracy - (no "
               "targets)", "velocity": "+-9.247 m/s, resolution 0.1622 m/s, accuracy -"}),
    ({("targets", "resolution"): {"rts_deg": None, "truth_deg": 4.0, "note": "arc too short"}},
     {"targets": "12 per channel, 12 in total; minimum separation: - (arc too short)"}),
    ({("targets", "resolution"): {"rts_deg": 2.5, "truth_deg": None, "note": "n"}},
     {"targets": "12 per channel, 12 in total; minimum separation 2.5 deg on the RTS, - deg on "
                 "real targets"}),
    ({("targets", "resolution"): {"rts_deg": 2.5, "note": "n"}},
     {"targets": "12 per channel, 12 in total; minimum separation 2.5 deg on the RTS, - deg on "
                 "real targets"}),
    ({("targets", "clip_margin_db"): None},
     {"ghosts": "strongest 26.0 dB below its target; RuT ADC clip margin -"}),
    ({("targets", "clip_margin_db"): KeyError},
     {"ghosts": "strongest 26.0 dB below its target; RuT ADC clip margin -"}),
])
def test_the_headline_rows_are_literal_text(changes, rows):
    assert headline(_with(changes)) == [(n, rows.get(n, v)) for n, v in ROWS]
