"""The fast numerical paths compute what the plain formulas compute: windows bit for bit
with scipy, the factored fast-time tones to rounding, the range-Doppler map to a plain
double-precision FFT chain, on grids of sizes."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from rtsgeom._lib.util import tones
from rtsgeom.radar.processing import range_doppler
from rtsgeom.radar.windows import window
from rtsgeom.scene.registry import WINDOWS


@pytest.mark.parametrize("name", [w for w in WINDOWS if w != "none"])
def test_windows_are_scipys_bit_for_bit(name):
    for n in (1, 2, 3, 4, 5, 8, 31, 64, 120, 256, 512, 1001, 4096):
        ours, ref = window(name, n), signal.get_window(name, n, fftbins=False)
        assert ours.dtype == ref.dtype and np.array_equal(ours, ref), (name, n)


def test_tones_match_the_direct_exponential():
    rng = np.random.default_rng(3)
    for n in (1, 2, 3, 16, 17, 100, 256, 512, 1000):
        for t0, dt in ((0.0, 1e-7), (4.1e-6, 1 / 12.5e6), (2e-5, 1 / 5e6)):
            f = rng.uniform(-3e7, 3e7, (6, 5))
            direct = np.exp(2j * np.pi * f[..., None] * (t0 + np.arange(n) * dt))
            phase_scale = 2 * np.pi * np.max(np.abs(f)) * (t0 + n * dt)  # rad
            got = tones(f, t0, dt, n)
            assert got.shape == (6, 5, n)
            # both forms round the phase argument; they agree to that rounding
            assert np.max(np.abs(got - direct)) <= 8 * np.finfo(float).eps * max(phase_scale, 1)


class _Cube:
    def __init__(self, data, radar):
        self.data, self.radar = data, radar


@pytest.mark.parametrize("shape", [(120, 8, 512), (16, 4, 64), (15, 3, 33), (1, 2, 8)])
@pytest.mark.parametrize("windows", [("hann", "hann"), ("none", "blackman"), ("hamming", "none")])
def test_range_doppler_matches_a_plain_fft_chain(default_scene, shape, windows):
    import dataclasses
    radar = dataclasses.replace(default_scene.radar, chirps_per_tx=shape[0],
                                samples_per_chirp=shape[2], range_window=windows[0],
                                doppler_window=windows[1])
    rng = np.random.default_rng(sum(shape))
    data = (rng.standard_normal(shape) + 1j * rng.standard_normal(shape)).astype(np.complex64)
    rd = range_doppler(_Cube(data, radar))
    x = np.fft.fft(data.astype(np.complex128) * window(windows[0], shape[2]), axis=2)
    x = np.fft.fftshift(np.fft.fft(x * window(windows[1], shape[0])[:, None, None], axis=0),
                        axes=0)
    ref = x.transpose(2, 0, 1)
    assert rd.spectrum.shape == ref.shape and rd.spectrum.dtype == np.complex64
    scale = np.max(np.abs(ref))
    assert np.max(np.abs(rd.spectrum - ref)) <= 1e-6 * scale
    p_ref = np.sum(np.abs(ref) ** 2, axis=2)
    assert np.allclose(rd.power, p_ref, rtol=1e-6, atol=1e-12 * p_ref.max())
