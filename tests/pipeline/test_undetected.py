"""Why a target has no detection (`run` prints it; summary.json's ``undetected``): its SNR at
its cell against the CFAR threshold, on synthetic range-Doppler maps of known noise."""

import numpy as np
import pytest

from conftest import make_scene
from rtsgeom.radar.processing import Detections, RangeDoppler
from rtsgeom.pipeline.matching import undetected_reason
from rtsgeom.scene import TargetConfig


def _map(snr_db, v, rng, r0=40, d0=16):
    """A (128, 32) map of V complex Gaussian channels, unit noise power each, plus a tone of
    ``snr_db`` over the channel-summed noise mean (V) at (r0, d0)."""
    x = (rng.standard_normal((128, 32, v)) + 1j * rng.standard_normal((128, 32, v))) / np.sqrt(2)
    x[r0, d0] += np.sqrt(10 ** (snr_db / 10))  # |.|^2 summed over V: V * 10^(snr/10)
    power = np.sum(np.abs(x) ** 2, -1)
    rng_m = np.arange(128) * 0.05
    vel = (np.arange(32) - 16) * 0.16
    return RangeDoppler(x.astype(np.complex64), power, rng_m, vel, vel * 1.0), rng_m[r0], vel[d0]


def _dets(ranges=(), vels=()):
    n = len(ranges)
    z = np.zeros(n)
    return Detections(np.asarray(ranges, float), np.asarray(vels, float), z, z, z,
                      np.zeros(n, int), np.zeros(n, int))


@pytest.mark.parametrize("v", [4, 8, 12])
@pytest.mark.parametrize("snr_db", [3.0, 8.0, 12.0])
def test_reason_reports_the_cell_snr_under_the_threshold(v, snr_db):
    scene = make_scene()
    rd, r, vel = _map(snr_db, v, np.random.default_rng(v))
    out = undetected_reason(scene, _dets(), rd, TargetConfig(r, vel))
    # the peak cell's power over the noise mean: the tone plus the noise in its cell
    # (within ~2 dB at these SNRs: max over 9 cells of noise, one realisation)
    assert out["snr_db"] == pytest.approx(10 * np.log10(10 ** (snr_db / 10) + 1), abs=2.0)
    assert out["threshold_db"] == scene.radar.cfar.threshold_db
    assert "under the CFAR threshold" in out["reason"]


def test_reason_names_a_shared_cell():
    rd, r, vel = _map(30.0, 8, np.random.default_rng(0))
    out = undetected_reason(make_scene(), _dets([r + 0.05], [vel]), rd, TargetConfig(r, vel))
    assert "another target" in out["reason"]


def test_noiseless_map_has_no_snr():
    rd, r, vel = _map(20.0, 8, np.random.default_rng(0))
    quiet = RangeDoppler(rd.spectrum, np.zeros_like(rd.power), rd.range_m, rd.velocity_mps,
                         rd.doppler_hz)
    out = undetected_reason(make_scene(), _dets(), quiet, TargetConfig(r, vel))
    assert out["snr_db"] is None and "CFAR did not report" in out["reason"]
