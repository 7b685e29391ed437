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


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """A probe capture written as .npy and as DCA1000 .bin, each with its sidecar."""
    from rtsgeom.geometry import build_setup
    from rtsgeom.identify.capture import simulate_capture, write_capture
    setup = build_setup(small_noiseless())
    cap = simulate_capture(setup, 0, seed=1)
    out = tmp_path_factory.mktemp("caps")
    for fmt in ("npy", "bin"):
        write_capture(cap, setup.rut, out / f"cap.{fmt}", fmt)
    return out


@pytest.mark.parametrize("fmt", ["npy", "bin"])
def test_a_sidecar_without_a_required_key_is_refused_naming_it(written, tmp_path, fmt):
    """Every required key of the sidecar, and of a DCA1000 file's (only for .bin), named when
    it is missing; the others may be left out."""
    import json
    import shutil
    from conftest import assert_refused
    from rtsgeom.errors import CaptureError
    from rtsgeom.identify.capture import REQUIRED, SIDECAR, SIDECAR_DCA1000, read_capture
    src = written / f"cap.{fmt}"
    meta = json.loads((written / f"cap.{fmt}.json").read_text())
    need = [k for k, d in {**SIDECAR, **(SIDECAR_DCA1000 if fmt == "bin" else {})}.items()
            if d.default is REQUIRED]
    assert {"active_front_end", "probe_range_m", "probe_velocity_mps", "probe_amplitude"} <= \
        set(need)
    assert ({"num_rx", "samples_per_chirp", "chirps", "scale"} <= set(need)) == (fmt == "bin")
    path = tmp_path / f"c.{fmt}"
    shutil.copy(src, path)
    side = tmp_path / f"c.{fmt}.json"
    for key in need:
        side.write_text(json.dumps({k: v for k, v in meta.items() if k != key}))
        assert_refused(lambda: read_capture(path),
                       f"{side}: no {key!r}: not a probe capture (rtsgeom adc --active I)",
                       CaptureError)
    optional = [k for k in meta if k not in need and k != "format"]
    side.write_text(json.dumps({k: v for k, v in meta.items() if k not in optional}))
    assert read_capture(path).active == 0


def test_a_capture_path_that_is_not_a_capture_is_named(tmp_path):
    from conftest import assert_refused
    from rtsgeom.errors import CaptureError
    from rtsgeom.identify.capture import read_capture
    tail = ": must be a capture file (.bin or .npy with its sidecar FILE.json)"
    assert_refused(lambda: read_capture(tmp_path / "none.bin"),
                   f"{tmp_path / 'none.bin'}: no such file{tail}", CaptureError)
    assert_refused(lambda: read_capture(tmp_path), f"{tmp_path}: a folder{tail}", CaptureError)
    lone = tmp_path / "lone.npy"
    lone.write_bytes(b"x")
    assert_refused(lambda: read_capture(lone), f"{lone}: no sidecar lone.npy.json (write "
                                               "captures with rtsgeom adc --active I)",
                   CaptureError)
    side = tmp_path / "lone.npy.json"
    side.write_text("[1, 2]")
    assert_refused(lambda: read_capture(lone),
                   f"{side}: not a probe capture's sidecar (a JSON object)", CaptureError)
    side.write_text("{nope")
    with pytest.raises(CaptureError) as exc:
        read_capture(lone)
    assert str(exc.value).startswith(f"{side}: not JSON (")
