"""Tests of ``rtsgeom.pipeline.pair``: closed forms and invariants on grids of inputs."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import small_quiet

from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths


def test_pair_amplitudes_design_for_the_channel_delay_offsets():
    """``exact`` designs J's amplitude for its calibration delay (the range offset it causes):
    an offset of a whole period changes the ratio, by the model built with that delay."""
    from rtsgeom.pipeline.pair import pair_amplitudes
    from rtsgeom.scene import TargetConfig
    from rtsgeom.synthesis.model import ChannelModel
    setup = build_setup(small_quiet([], samples_per_chirp=512))
    paths = exact_paths(setup)
    th = setup.fe_azimuth_rad()
    t = TargetConfig(25.0, 0.0, 10.0, float(th.mean()))
    probes = th[0] + np.array([0.25, 0.75]) * (th[1] - th[0])
    off = (0.0, 0.5e-9)
    a0 = pair_amplitudes(setup, paths, (0, 1), t, "exact", probes)
    a1 = pair_amplitudes(setup, paths, (0, 1), t, "exact", probes, off)
    pm = ChannelModel.build(setup, paths, (0, 1), t, off)
    rho = pm.pair_ratio(t.angle_rad, (0.0, float(pm.pair_phase(probes))))
    assert a1[2] == pytest.approx(rho, rel=1e-6)
    assert abs(a1[2] / a0[2] - 1) > 1e-3
