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


@pytest.mark.parametrize("mode", ["paper", "array-factor"])
def test_a_closed_form_plan_is_its_inputs_field_by_field(mode):
    """``paper`` / ``array-factor``: the whole ``PairPlan`` is ``pair_amplitudes`` at the
    channels' offsets and gain correction, J's offset, the calibrated difference as both the
    realised and the planned one, no residual, no period offset, the target's IF slope."""
    import dataclasses
    from scipy.constants import c
    from rtsgeom.calibration.phasor import PairChannels
    from rtsgeom.calibration.probes import if_phase_slope_hz
    from rtsgeom.pipeline.pair import PairPlan, pair_amplitudes, plan_pair
    from rtsgeom.scene import TargetConfig
    setup = build_setup(small_quiet([]))
    paths = exact_paths(setup)
    th = setup.fe_azimuth_rad()
    t = TargetConfig(25.0, 0.0, 10.0, float(th[0] + 0.4 * (th[1] - th[0])))
    probes = th[0] + np.array([0.25, 0.75]) * (th[1] - th[0])
    ch = PairChannels((0, 1), (0.3e-9, -0.45e-9), (1.1, 0.8))
    plan = plan_pair(setup, paths, ch, t, mode, probes)
    a_i, a_j, rho = pair_amplitudes(setup, paths, (0, 1), t, mode, probes, ch.offsets,
                                    ch.gain_correction)
    d = -0.45e-9 - 0.3e-9
    want = PairPlan(a_i, a_j, rho, -0.45e-9, d, d, 0.0, 0,
                    float(if_phase_slope_hz(setup.scene, 2 * 25.0 / c)))
    assert dataclasses.astuple(plan) == pytest.approx(dataclasses.astuple(want), rel=1e-12,
                                                      abs=1e-24)
    assert [type(v) for v in dataclasses.astuple(plan)[4:]] == [float, float, float, int, float]
