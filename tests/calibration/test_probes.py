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


@pytest.mark.parametrize("r0, step1, step, limit", [
    (8.0, 3.0, 4.0, 32.0),  # the 7th probe ends exactly on the limit
    (8.0, 3.0, 4.0, 31.75),  # just below: 6
    (8.0, 4.0, 4.0, 32.0), (2.0, 1.5, 6.0, 32.0), (8.0, 3.0, 32.0, 32.0), (40.0, 3.0, 4.0, 32.0)])
def test_probes_per_frame_is_the_most_probes_up_to_the_limit_the_limit_included(
        monkeypatch, r0, step1, step, limit):
    """``probes_per_frame``: the largest k <= n whose k probes (the first at r0, the others a
    spacing step(k) apart) end at or below ``PROBE_RANGE_LIMIT`` of the range axis, at least
    1; probes ending exactly on the limit fit (exact binary fractions)."""
    from types import SimpleNamespace

    import rtsgeom.calibration.probes as pr
    assert pr.PROBE_RANGE_LIMIT == 0.85
    monkeypatch.setattr(pr, "PROBE_RANGE_LIMIT", 0.5)
    monkeypatch.setattr(pr, "probe_ranges", lambda setup, n: r0 + step1 * np.arange(n))
    monkeypatch.setattr(pr, "_probe_step", lambda setup, k: step1 if k == 1 else step)
    setup = SimpleNamespace(scene=SimpleNamespace(radar=SimpleNamespace(max_range_m=2 * limit)))
    for n in (1, 2, 5, 7, 10, 40):
        fits = [k for k in range(1, n + 1)
                if r0 + (step1 if k == 1 else step) * (k - 1) <= limit]
        assert pr.probes_per_frame(setup, n) == max(fits + [1]), n
