"""Tests of ``rtsgeom.calibration.probes``: closed forms and invariants on grids of inputs."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import make_scene

from rtsgeom.geometry import build_setup


def test_probe_finds_each_front_end_at_the_model_angle_with_unit_gain_correction(small_setup):
    """Each front end alone, measured in the noise-free chain: at the exact model's angle of
    that front end (the beamformer peak of its own phasors), and with a gain correction of 1
    where the setup is the nominal one (the model then is the measurement)."""
    from rtsgeom.calibration.probes import probe_front_ends, probe_ranges
    from rtsgeom.scene import TargetConfig
    from rtsgeom.synthesis.model import ChannelModel
    setup, paths = small_setup
    probe = probe_front_ends(setup, paths)
    ranges = probe_ranges(setup, setup.fe.count)
    assert np.all(np.diff(ranges) > 0)
    for q in range(setup.fe.count):
        cm = ChannelModel.build(setup, paths, (q,), TargetConfig(float(ranges[q])))
        want = cm.direction(np.array([1.0]))
        assert np.degrees(abs(probe.angle_rad[q] - want)) < 2e-3
    np.testing.assert_allclose(probe.gain_correction, 1.0, rtol=2e-3)
    assert np.all(np.isfinite(probe.power_db))


@pytest.mark.parametrize("length", [1.0, 2.1, 2.9, 4.2])
def test_probe_ranges_keep_clear_of_every_cable_ghost(length):
    """Probes m * step apart never sit within 4 range bins of a ghost k L / VF of another."""
    from rtsgeom.calibration.probes import probe_ranges
    s = make_scene(lambda d: [fe.update(cable_length_m=length) for fe in d["rts"]["front_ends"]])
    setup = build_setup(s)
    r = probe_ranges(setup, 3)
    clear = 4 * s.radar.range_resolution_m
    ghosts = [k * length / 0.7 for k in range(1, 6)]
    for a in range(3):
        for b in range(a + 1, 3):
            assert all(abs((r[b] - r[a]) - g) >= clear - 1e-12 for g in ghosts)
