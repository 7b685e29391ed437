"""Which carrier turns velocity into Doppler, on a grid of velocities and bandwidths.

The model's choice (README "Velocity and the carrier frequency"): the RTS is told
f_D = 2 f_c v / c0 (``rts.program_nearest``) and the processing reports v = nu c0 / (2 f_c)
(``radar.processing.range_doppler``), both with f_c the chirp's START frequency. The RTS's
Doppler is a frequency shift, so the slow-time frequency at the detected range bin is f_D
itself whatever the carrier: programmed and reported velocity agree exactly.

A real moving target instead changes its delay at 2 v / c0; its echo at fast time t_n
carries f_c + S (t_n - tau), so the phase progression across chirps at the range bin
(symmetric range window) follows the carrier at the middle of the ADC window,
f_mid = f_c + S (t_adc + (N - 1) / (2 f_adc) - tau). Both closed forms are checked here.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.constants import c

from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.radar import process, synthesize
from rtsgeom.radar.fmcw import synthesize_exact
from rtsgeom.radar.windows import window
from rtsgeom.rts.channels import Echoes, build_echoes, program_nearest

from conftest import make_scene

RANGE_M = 21.3
VELOCITIES = (-7.1, -2.2, 3.1, 6.6)  # m/s, inside the scene rule's velocity range
BANDWIDTHS = (0.5e9, 1e9, 2e9)  # Hz


def _scene(bandwidth_hz, velocity):
    def mutate(doc):
        doc["radar"].pop("snr_db", None)
        doc["radar"]["bandwidth_hz"] = bandwidth_hz
        doc["radar"]["chirps_per_tx"] = 32
        for fe in doc["rts"]["front_ends"]:
            fe.pop("return_loss_fe_db", None)
            fe.pop("return_loss_be_db", None)
        doc["targets"] = [{"range_m": RANGE_M, "velocity_mps": velocity, "angle_deg": 3.4}]
    return make_scene(mutate)


def _slow_time_hz(cube, range_bin):
    """Slow-time frequency at one range bin: mean phase step between chirp loops of each
    virtual channel (loops of one channel are one TDM cycle apart)."""
    r = cube.radar
    x = np.fft.fft(cube.data.astype(np.complex128) * window(r.range_window, r.samples_per_chirp),
                   axis=2)[:, :, range_bin]  # (L, V)
    step = np.angle(np.sum(x[1:] * np.conj(x[:-1])))
    return step / (2 * np.pi * r.tdm_cycle_s)


def _f_mid(radar, tau_s):
    t_mid = radar.adc_start_s + (radar.samples_per_chirp - 1) / (2 * radar.adc_rate_hz)
    return radar.f_c_hz + radar.slope_hz_per_s * (t_mid - tau_s)


@pytest.mark.parametrize("bandwidth_hz", BANDWIDTHS)
@pytest.mark.parametrize("velocity", VELOCITIES)
def test_rts_velocity_round_trip_uses_the_start_frequency(bandwidth_hz, velocity):
    scene = _scene(bandwidth_hz, velocity)
    setup = build_setup(scene)
    program = program_nearest(scene, setup)
    r = scene.radar
    assert program.doppler_hz[0] == pytest.approx(2 * r.f_c_hz * velocity / c, rel=1e-12)
    cube = synthesize(build_echoes(setup, exact_paths(setup), program), r, setup.rut)
    rd, det = process(cube)
    k = int(np.argmin(np.abs(det.range_m - RANGE_M)))
    nu = _slow_time_hz(cube, det.range_bin[k])
    # the slow-time frequency is the programmed shift; the processing's conversion undoes it
    assert nu == pytest.approx(program.doppler_hz[0], rel=1e-5)
    assert nu * c / (2 * r.f_c_hz) == pytest.approx(velocity, rel=1e-5)
    assert det.velocity_mps[k] == pytest.approx(velocity, abs=0.5 * r.velocity_resolution_mps)


@pytest.mark.parametrize("bandwidth_hz", BANDWIDTHS)
@pytest.mark.parametrize("velocity", VELOCITIES)
def test_real_target_phase_follows_the_carrier_mid_adc_window(bandwidth_hz, velocity):
    scene = _scene(bandwidth_hz, velocity)
    setup = build_setup(scene)
    r = scene.radar
    tau = 2 * RANGE_M / c
    n_v = setup.rut.num_virtual
    z = np.zeros(1)
    # the delay acts at RF (f_if = f_c, no air path) and drifts at 2 v / c0: a real target
    echo = Echoes(np.zeros((1, n_v)), np.full(1, tau), np.full(1, r.f_c_hz), z,
                  np.ones((1, n_v), complex), *(np.zeros(1, int),) * 4)
    cube = synthesize_exact(echo, r, setup.rut, delay_rate=np.full(1, 2 * velocity / c))
    bin_ = int(round(r.slope_hz_per_s * tau * r.samples_per_chirp / r.adc_rate_hz))
    nu = _slow_time_hz(cube, bin_)
    f_mid = _f_mid(r, tau)
    assert nu == pytest.approx(2 * velocity * f_mid / c, rel=2e-5)
    # ... which the start frequency misses by S (t_mid - tau) / f_c (0.65 % at 77 GHz, 1 GHz)
    off = f_mid / r.f_c_hz - 1
    assert abs(nu * c / (2 * r.f_c_hz) / velocity - 1 - off) < 2e-5 < 0.1 * off
