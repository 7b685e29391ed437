"""The 2-D cell tolerance study with the target's sub-bin position drawn and the RuT's bin
choice (``analysis/tolerance_cell.py``): the positions are the pair study's, the bin-centre
special case is the old model, the detected bin follows the echo, and the model agrees with
the full ADC-cube chain at positions across the bin, on a grid of cells."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from conftest import ROOT
from scipy.constants import c

from rtsgeom.analysis.tolerance.draws import subbin_draws, subbin_positions
from rtsgeom.analysis.tolerance.montecarlo import monte_carlo
from rtsgeom.analysis.tolerance.phasors import CASES, ChannelPhasors
from rtsgeom.analysis.tolerance.config import MonteCarlo
from rtsgeom.analysis.tolerance.verify import verify_draws
from rtsgeom.geometry import build_setup
from rtsgeom.scene import load_scene

from .test_tolerance_cell import CELLS, cell_scene


@pytest.fixture(scope="module", params=[1, 2], ids=lambda k: f"cell{k}")
def model(request):
    return ChannelPhasors.build(build_setup(cell_scene(*CELLS[request.param])), points=4)


@pytest.mark.parametrize("resolution_s", [1e-12, 7e-12])
@pytest.mark.parametrize("bandwidth_hz", [1e9, 3e9])
def test_positions_are_the_pair_studys(resolution_s, bandwidth_hz):
    """One definition of where a target can sit in its bin: the pair model's positions are
    subbin_positions' for other delay resolutions and range bins too."""
    scene = load_scene(ROOT / "scenes" / "diewald2022.toml")
    base = scene.radar.range_resolution_m
    scene = dataclasses.replace(
        scene, rts=dataclasses.replace(scene.rts, fractional_delay_step_s=resolution_s),
        radar=dataclasses.replace(scene.radar, bandwidth_hz=bandwidth_hz))
    assert scene.rts.delay_resolution_s == resolution_s
    assert (scene.radar.range_resolution_m == base) == (bandwidth_hz == 1e9)
    pair = ChannelPhasors.build(build_setup(scene), (0, 1), 3)
    want = subbin_positions(scene.radar.range_resolution_m, resolution_s)
    assert np.array_equal(pair.subbin_steps, want)
    # one range bin: 2 dR / c0 in steps (to half a step), centred on 0
    span = want.size * resolution_s * c / 2
    assert abs(span - scene.radar.range_resolution_m) <= 0.5 * resolution_s * c / 2
    assert want[0] == -(want.size // 2) and np.all(np.diff(want) == 1)


def test_cell_positions_and_stream(model):
    """The cell draws the pair study's positions from its stream, uniform over the bin."""
    rs = model.setup.scene.radar.range_resolution_m
    assert np.array_equal(model.subbin_steps,
                          subbin_positions(rs, model.delay_resolution_s))
    res = monte_carlo(model, [1e-4] * 3, 400, seed=3, chunk=150)
    idx = next(subbin_draws(3, 400, model.subbin_steps.size, 400))
    assert np.array_equal(res.subbin_steps, model.subbin_steps[idx])
    assert res.to_dict()["subbin"]["positions"] == model.subbin_steps.size
    # uniform: each quarter of the bin gets about a quarter of the draws
    q = np.histogram(res.subbin_steps, 4, (model.subbin_steps[0], model.subbin_steps[-1]))[0]
    assert np.all(np.abs(q - 100) < 35)


def test_bin_centre_is_the_special_case(model):
    """subbin=None is the centre position, bit for bit, and reads the table row the
    bin-centre model read (x_nominal to rounding)."""
    rng = np.random.default_rng(1)
    off = rng.standard_normal((6, len(model.front_ends), 3)) * 1e-4
    a = model.draw(off, None, CASES)
    b = model.draw(off, np.full(6, model.subbin_zero), CASES)
    for case in CASES:
        assert np.array_equal(a[case]["error_rad"], b[case]["error_rad"])
        assert np.all(a[case]["bin"] == 0)
    row = model.table[:, model.table_zero, model.table.shape[2] // 2]
    assert np.allclose(row, model.x_nominal, rtol=1e-12, atol=0)


def test_detected_bin_follows_the_echo(model):
    """No errors, uncalibrated (every channel at the target's delay): the echoes slide with
    the target, so the RuT detects the set range's bin for a target within 0.45 bins of its
    centre; a target moved by whole bins (the table's own rows) is detected that many bins
    off. The direction barely depends on the position (the channels slide alike: < 0.02
    deg across the bin)."""
    n_u = model.subbin_steps.size
    u = np.arange(0, n_u, 37)
    d = model.draw(np.zeros((u.size, len(model.front_ends), 3)), u, ("uncalibrated",))
    frac = model.subbin_steps[u] / n_u
    inner = np.abs(frac) <= 0.45
    assert np.all(d["uncalibrated"]["bin"][inner] == 0)
    e = np.degrees(d["uncalibrated"]["error_rad"])
    assert np.max(np.abs(e - e[np.argmin(np.abs(frac))])) < 0.02


def test_calibrated_nominal_error_grows_towards_the_bin_edge(model):
    """No mounting errors: after calibration the channels sit at different delays (the
    nominal calibration's), so the design made at the bin centre holds there best; its error
    grows towards either edge (the bin-centre model could not see this)."""
    n_u = model.subbin_steps.size
    u = np.array([model.subbin_zero, int(0.1 * n_u), int(0.9 * n_u)])
    d = model.draw(np.zeros((3, len(model.front_ends), 3)), u, ("calibrated",))
    e = np.degrees(np.abs(d["calibrated"]["error_rad"])).max(axis=(1, 2))
    assert e[0] < e[1] and e[0] < e[2]


def test_model_matches_the_chain_across_the_bin(model):
    """Draws at sub-bin positions across the bin (centre, both quarters, near both edges)
    through the full ADC-cube chain at every set-point: the fast model within 1e-4 deg."""
    n_u = model.subbin_steps.size
    pos = [0, n_u // 4, model.subbin_zero, 3 * n_u // 4, n_u - 1]
    v = verify_draws(model, [1e-4] * 3, MonteCarlo(draws=len(pos), seed=2), all_points=True,
                          positions=pos)
    assert v.max_difference_deg < 1e-4
    assert all(c["missed"] == 0 for c in v.to_dict()["cases"].values())
    assert v.subbin_steps.tolist() == model.subbin_steps[pos].tolist()


@pytest.mark.slow
def test_bin_edge_draws_match_the_chain():
    """The draws the sub-bin positions make worst (the calibrated case detected off the set
    range's bin on sphere4 at 0.3 mm): the chain agrees there too (1e-4 deg)."""
    m = ChannelPhasors.build(build_setup(load_scene(ROOT / "scenes" / "sphere4.toml")), points=9)
    res = monte_carlo(m, [3e-4] * 3, 60, seed=4, cases=("calibrated",))
    worst = np.argsort(-res.worst_error_deg["calibrated"][:, 2])[:4]
    n = int(worst.max()) + 1
    v = verify_draws(m, [3e-4] * 3, MonteCarlo(draws=n, seed=4), cases=("calibrated",))
    diff = np.abs(v.chain_deg["calibrated"] - v.model_deg["calibrated"])
    assert np.max(diff[worst]) < 1e-4
    assert math.isfinite(v.max_difference_deg)
