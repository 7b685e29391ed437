"""Property-based tests of the signal chain and the AoA synthesis (hypothesis)."""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from hypothesis import given, settings, strategies as st
from scipy.constants import c

from rtsgeom.synthesis.model import ChannelModel
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.radar import synthesize
from rtsgeom.rts.channels import build_echoes, program_nearest
from rtsgeom.scene import TargetConfig

from conftest import make_scene


@lru_cache(maxsize=None)
def _chain():
    setup = build_setup(make_scene())
    paths = exact_paths(setup)
    return setup, paths, build_echoes(setup, paths, program_nearest(setup.scene, setup))


@lru_cache(maxsize=None)
def _pair_model(delta_ps: int = 0):
    setup, paths, _ = _chain()
    return ChannelModel.build(setup, paths, (0, 1), TargetConfig(20.0), (0.0, delta_ps * 1e-12))


@settings(max_examples=20, deadline=None)
@given(k=st.floats(1e-3, 1e3), phase=st.floats(-np.pi, np.pi))
def test_adc_cube_is_linear_in_echo_amplitude(k, phase):
    setup, _, ech = _chain()
    radar = setup.scene.radar
    base = synthesize(ech, radar, setup.rut).data
    g = k * np.exp(1j * phase)
    scaled = synthesize(ech.scaled(g), radar, setup.rut).data
    assert np.allclose(scaled, g * base, rtol=1e-4, atol=1e-5 * abs(g) * np.abs(base).max())
    energy = np.sum(np.abs(scaled.astype(complex)) ** 2) / np.sum(np.abs(base.astype(complex)) ** 2)
    assert abs(energy / k ** 2 - 1) < 1e-4  # energy scales with |g|^2


@settings(max_examples=15, deadline=None)
@given(st.lists(st.integers(-600, 600), min_size=3, max_size=8, unique=True))
def test_synthesized_angle_is_monotone_in_the_amplitude_ratio(log_rhos_centi):
    m = _pair_model()
    rho = np.exp(np.sort(np.asarray(log_rhos_centi)) / 100.0)  # ratios 0.0025 .. 400
    angles = m.direction(m.pair_weights(rho, (0.0, float(m.pair_phase(np.radians([6.0, 10.0]))))))
    assert np.all(np.diff(angles) > 0)  # more of front end J (at 12.2 deg) -> larger angle


@settings(max_examples=10, deadline=None)
@given(delta_ps=st.integers(-400, 400), k=st.sampled_from([-1, 1]))
def test_calibration_phase_repeats_every_period(delta_ps, k):
    # eq. (27), exact form: d phi / d tau_rts = 2 pi (f_rts + S t_mid - S tau), t_mid the ADC
    # window's centre (B/2 in the paper) and S tau the target's beat frequency
    setup = _chain()[0]
    r = setup.scene.radar
    t_mid = r.adc_start_s + 0.5 * (r.samples_per_chirp - 1) / r.adc_rate_hz
    period = 1 / (setup.scene.rts.f_rts_hz + r.slope_hz_per_s * (t_mid - 2 * 20.0 / c))
    probes = np.radians([6.0, 10.0])
    a = _pair_model(delta_ps).pair_phase(probes)
    shifted = ChannelModel.build(setup, _chain()[1], (0, 1), TargetConfig(20.0),
                              (0.0, delta_ps * 1e-12 + k * period))
    b = shifted.pair_phase(probes)
    assert abs(np.degrees(np.angle(np.exp(1j * (b - a))))) < 0.5
