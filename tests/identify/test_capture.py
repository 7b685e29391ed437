"""Tests of ``rtsgeom.identify.capture``: closed forms and invariants on grids of inputs."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import small_noiseless


@pytest.mark.parametrize("fmt", ["npy", "bin"])
@pytest.mark.parametrize("active", [0, 1])
def test_probe_capture_round_trip(tmp_path, fmt, active):
    """A probe capture written (``.npy`` or DCA1000 ``.bin`` + sidecar) reads back with its
    active front end, probe range, velocity and amplitude, and the same samples (DCA1000:
    within int16 quantisation). The default probe is the calibration's first probe range."""
    from rtsgeom.calibration.probes import probe_ranges
    from rtsgeom.geometry import build_setup
    from rtsgeom.identify.capture import (
        capture_probe,
        read_capture,
        simulate_capture,
        write_capture,
    )
    setup = build_setup(small_noiseless())
    r0, amp0 = capture_probe(setup)
    assert r0 == pytest.approx(float(probe_ranges(setup, 1)[0]))
    r1, amp1 = capture_probe(setup, 2 * r0)
    assert r1 == 2 * r0 and amp1 == pytest.approx(amp0 / 4, rel=1e-9)  # amplitude ~ 1/R^2
    cap = simulate_capture(setup, active, velocity_mps=-1.5, seed=3)
    out = tmp_path / f"cap.{fmt}"
    write_capture(cap, setup.rut, out, fmt)
    back = read_capture(out)
    assert (back.active, back.range_m, back.velocity_mps, back.amplitude) == (
        active, cap.range_m, -1.5, cap.amplitude)
    assert back.data.shape == cap.data.shape
    tol = 1e-6 if fmt == "npy" else 2.0 / 32767
    assert np.max(np.abs(back.data - cap.data)) <= tol * np.max(np.abs(cap.data))


@pytest.mark.parametrize("bad", ["real", "2d"])
def test_a_capture_that_is_not_a_complex_3d_cube_is_refused(tmp_path, bad):
    """``read_capture`` refuses a ``.npy`` whose data is real (a 3-D cube of floats) or complex
    but not 3-D, naming the file."""
    from rtsgeom.geometry import build_setup
    from rtsgeom.identify.capture import read_capture, simulate_capture, write_capture
    setup = build_setup(small_noiseless())
    cap = simulate_capture(setup, 0, seed=1)
    out = tmp_path / "cap.npy"
    write_capture(cap, setup.rut, out, "npy")
    data = np.real(cap.data) if bad == "real" else cap.data[0]
    np.save(out, data)
    with pytest.raises(ValueError, match="cap.npy: expected a complex"):
        read_capture(out)
