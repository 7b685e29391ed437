"""A synthesized target whose echo sits near a range-bin edge reads its set range.

Near a bin edge two bins carry nearly equal power, and their pair designs are the same
programme (ratios within 1 %). The planner's bin choice used to prefer the other bin at a
power margin of 1.1 and move channel J by an IF period: J's echo one range bin away from
I's, and the combined peak half a bin short (template-derived arcs: the zero-Doppler targets
at 27.0 and 62.7 m, 0.51 and 0.55 bins past a bin centre, read 71 and 98 mm short). The
margin now counts only bins whose design differs (``synthesis.kernels``). With the receiver's
noise on a 1-deg arc the planner still takes J an IF period earlier for some of them (the
strict xfail below: it fails once that is fixed, and the mark comes off)."""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path

import numpy as np
import pytest

from rtsgeom.pipeline.run import run_scene
from rtsgeom.scene import parse_scene

TEMPLATE = Path(__file__).resolve().parents[2] / "scenes" / "template.toml"
FRACTIONS = (0.40, 0.45, 0.50, 0.51, 0.545, 0.55, 0.60, 0.65)  # of a bin past its centre


def test_targets_at_bin_edges_read_their_range():
    """The template's bench, noiseless, a grid of zero-Doppler targets from 0.40 to 0.65 of
    a bin past a bin centre spread over its four pairs: every one detected within 15 mm of
    its set range and within 10 mm of the truth twin's (the point target's own reading)."""
    doc = copy.deepcopy(tomllib.loads(TEMPLATE.read_text()))
    doc["radar"].pop("snr_db", None)
    scene = parse_scene(doc, "template.toml")
    bin_m = scene.radar.range_resolution_m
    doc["targets"] = [{"range_m": float((90 + 30 * k + f) * bin_m), "velocity_mps": 0.0,
                       "angle_deg": -8.0 + 4.0 * k} for k, f in enumerate(FRACTIONS)]
    result = run_scene(parse_scene(doc, "edges.toml"))
    errors = [m["error"]["range_m"] for m in result.matches if m["detection"] is not None]
    assert len(errors) == len(FRACTIONS)
    assert np.max(np.abs(errors)) < 0.015, np.round(errors, 4)
    vs_truth = [m["vs_truth"]["range_m"] for m in result.matches]
    assert np.max(np.abs(vs_truth)) < 0.010, np.round(vs_truth, 4)


@pytest.mark.xfail(strict=True, reason="not fixed: with the receiver's noise the pair's "
                   "calibration moves and plan_pair (pipeline/pair.py) takes channel J one IF "
                   "period (1.006 ns, one range bin) earlier: period_offset -1, I and J a bin "
                   "apart, the target 150 mm short")
@pytest.mark.parametrize("index", [10, 25])
def test_dense_arc_targets_at_bin_edges_with_noise(index):
    """The dense-arc benchmark's bench with 16 front ends 1 deg apart and its target 10 (27.0
    m, 0 m/s, 0.51 bin past a bin centre) or 25 (52.5 m, +1.1 m/s) alone, at the template's
    10 dB SNR: within 15 mm of its set range (noiseless it is: 0.2 and 5 mm)."""
    from benchmarks.dense_arc import arc_scene
    doc = tomllib.loads(arc_scene(16, 1.0, 32))
    doc["targets"] = [doc["targets"][index]]
    result = run_scene(parse_scene(doc, "dense16.toml"), truth=False)
    assert abs(result.matches[0]["error"]["range_m"]) < 0.015
