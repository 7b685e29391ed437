"""Tests of ``rtsgeom.calibration.paper``: closed forms and invariants on grids of inputs."""

from __future__ import annotations

import pytest
from conftest import small_noiseless


def test_paper_procedure_reports_the_exact_period_at_its_target():
    """``calibrate_pair_paper`` (one target at one set angle) reports the period
    1/(f_rts + S t_mid - S tau) at its target's delay, as the pair calibration does at its
    probes' (not eq. 27's 1/(f_rts + B/2))."""
    from scipy.constants import c

    from rtsgeom.calibration.paper import calibrate_pair_paper
    from rtsgeom.calibration.probes import probe_front_ends, probe_ranges
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    for f_rts in (500e6, 300e6):
        setup = build_setup(small_noiseless(lambda d, f=f_rts: d["rts"].update(f_rts_hz=f)))
        paths = exact_paths(setup)
        probe = probe_front_ends(setup, paths, 1)
        cal = calibrate_pair_paper(setup, paths, (0, 1), probe, 1, span_s=(0.0, 50e-12),
                                   step_s=25e-12)
        r = setup.scene.radar
        t_mid = r.adc_start_s + 0.5 * (r.samples_per_chirp - 1) / r.adc_rate_hz
        s = r.bandwidth_hz / r.chirp_duration_s
        tau = 2 * float(probe_ranges(setup, 1)[0]) / c
        assert cal.period_s == pytest.approx(1 / (f_rts + s * t_mid - s * tau), rel=1e-4)
