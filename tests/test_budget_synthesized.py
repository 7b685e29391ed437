"""The link budget (``radar.budget``) of a target synthesized by two RTS channels: its power is
the coherent sum the RuT's range-Doppler cell sees, each channel's echo with its own beat
phase (the two front ends reach the RuT over different air paths)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_kpi_closed_forms import _linked, _scalloping_db

from rtsgeom.analysis.kpi.accuracy import link_snr
from rtsgeom.calibration.probes import probe_ranges
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.radar.budget import link_budget
from rtsgeom.rts.channels import RtsProgram, build_echoes, requested_delay
from rtsgeom.scene import TargetConfig
from rtsgeom.synthesis.model import ChannelModel


@pytest.mark.parametrize("ratio", [0.3, 1.0, 3.0])
@pytest.mark.parametrize("off_j_ps", [0.0, 5.0, -10.0])
def test_a_synthesized_targets_budget_snr_is_its_cells(ratio, off_j_ps):
    """Front ends 0 and 1 (8.8 deg apart) programmed with amplitudes (1, ratio) x the
    target's and J's delay moved by ``off_j_ps``: the budget's post-FFT SNR is the cell's
    (``ChannelModel``'s bin responses: the windowed DFTs of each echo with its phase) over
    the link's noise, within 0.05 dB once the range window's scalloping is counted (the
    budget counts the bin centre: J's delay offsets of tens of ps, which move its tone by a
    tenth of a bin and turn its windowed DFT's phase, leave 0.1-0.2 dB). Before, the budget
    summed the channels' echo amplitudes without their beat phases: 0.9 to 1.4 dB high."""
    scene0 = _linked(12.0)
    rng_m = float(probe_ranges(build_setup(scene0), 1)[0])
    scene = _linked(12.0, target_m=rng_m)
    setup = build_setup(scene)
    paths = exact_paths(setup)
    off = off_j_ps * 1e-12
    model = ChannelModel.build(setup, paths, (0, 1),
                               TargetConfig(rng_m, 0.0, 10.0, math.radians(7.0)), (0.0, off))
    w = model.unit_gain * np.array([1.0, ratio]) / math.hypot(1.0, ratio)
    tau = float(requested_delay(scene, rng_m))
    prog = RtsProgram.build([0, 0], [0, 1], [tau, tau + off], [0.0, 0.0], list(w))
    b = link_budget(scene, build_echoes(setup, paths, prog), prog, linked=False, predict=True,
                    setup=setup)
    cell_db = 10 * math.log10(link_snr(scene, model, w))
    assert b.targets[0]["snr_after_fft_db"] + _scalloping_db(scene.radar, rng_m) == \
        pytest.approx(cell_db, abs=0.05)
