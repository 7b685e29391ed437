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


# ---- every refusal of rtsgeom.identify.capture, its whole text, both sides of each bound ----

def _copy(written, tmp_path, fmt, meta_edit=None, data=None):
    """A copy of the written ``fmt`` capture in ``tmp_path`` (its sidecar edited by
    ``meta_edit(meta)``, its .npy data replaced by ``data``): (path, sidecar path, meta)."""
    import json
    import shutil
    path, side = tmp_path / f"c.{fmt}", tmp_path / f"c.{fmt}.json"
    shutil.copy(written / f"cap.{fmt}", path)
    meta = json.loads((written / f"cap.{fmt}.json").read_text())
    if meta_edit is not None:
        meta_edit(meta)
    side.write_text(json.dumps(meta))
    if data is not None:
        np.save(path, data)
    return path, side, meta


def _refused(call, message):
    from conftest import assert_refused
    from rtsgeom.errors import CaptureError
    assert_refused(call, message, CaptureError)


def test_a_npy_capture_s_every_refusal_is_said_whole(written, tmp_path):
    """``read_capture`` of a ``.npy``: the header's shape and size against ``shape`` and
    ``max_bytes`` (the size itself accepted, one byte less refused), the sidecar's shape,
    non-finite and all-zero samples, a file that is no .npy and one cut short."""
    from rtsgeom.identify.capture import read_capture
    path, side, meta = _copy(written, tmp_path, "npy")
    good = np.load(path)
    shape = list(good.shape)
    nbytes = good.nbytes
    assert read_capture(path, tuple(shape), max_bytes=nbytes).data.shape == good.shape
    _refused(lambda: read_capture(path, (1, 8, 128)),
             f"{path}: shape {shape}: must be the scene's radar [1, 8, 128] "
             "[loop, virtual, sample]")
    _refused(lambda: read_capture(path, max_bytes=nbytes - 1),
             f"{path}: shape {shape} ({nbytes / 2**30:.3g} GiB): must be at most "
             f"{(nbytes - 1) / 2**30:.3g} GiB")
    np.save(path, good[0])
    _refused(lambda: read_capture(path),
             f"{path}: expected a complex [loop, virtual, sample] cube, got complex64 "
             f"{shape[1:]}")
    np.save(path, good.real)
    _refused(lambda: read_capture(path),
             f"{path}: expected a complex [loop, virtual, sample] cube, got float32 {shape}")
    for n_bad in (1, 3):
        bad = good.copy()
        bad.flat[:n_bad] = [np.nan, np.inf, -np.inf][:n_bad]
        np.save(path, bad)
        _refused(lambda: read_capture(path),
                 f"{path}: {n_bad} sample(s) not finite (NaN or inf): must be finite")
    np.save(path, np.zeros_like(good))
    _refused(lambda: read_capture(path), f"{path}: every sample is 0: must hold the probe's echo")
    np.save(path, good)
    side.write_text(side.read_text().replace(f'"shape": {shape}'.replace("'", ""),
                                             '"shape": [1, 2, 3]'))
    _refused(lambda: read_capture(path),
             f"{side}: shape = [1, 2, 3]: must be the capture's {shape} [loop, virtual, sample]")
    path, side, meta = _copy(written, tmp_path, "npy")
    path.write_bytes(b"not an array")
    with open(path, "rb") as fh, pytest.raises(ValueError) as exc:
        np.lib.format.read_magic(fh)
    _refused(lambda: read_capture(path), f"{path}: not a .npy array ({str(exc.value)[:120]})")
    path, side, meta = _copy(written, tmp_path, "npy")
    path.write_bytes(path.read_bytes()[:-16])
    with pytest.raises(ValueError) as exc:
        np.load(path, allow_pickle=False)
    _refused(lambda: read_capture(path),
             f"{path}: cannot read the capture its sidecar describes ({exc.value})")


def test_a_dca1000_capture_s_every_refusal_is_said_whole(written, tmp_path):
    """``read_capture`` of a ``.bin``: chirps against the TDM slots, the described cube
    against ``shape`` and ``max_bytes`` (the cube's size accepted, one byte less refused), the
    file's size, and the layout (``format``, ``adc``, ``lvds_lanes``)."""
    from rtsgeom.identify.capture import read_capture
    from rtsgeom.scene.presets import LAYOUT_DEFAULT
    path, side, meta = _copy(written, tmp_path, "bin")
    n_tx, n_rx, n_s, chirps = (len(meta["tx_order"]), meta["num_rx"],
                               meta["samples_per_chirp"], meta["chirps"])
    got = [chirps // n_tx, n_tx * n_rx, n_s]
    cube = chirps * n_rx * n_s * 8
    assert read_capture(path, tuple(got), max_bytes=cube).data.shape == tuple(got)
    _refused(lambda: read_capture(path, (1, 8, 128)),
             f"{side}: chirps, tx_order, num_rx, samples_per_chirp describe {got}: must be "
             "the scene's radar [1, 8, 128] [loop, virtual, sample]")
    _refused(lambda: read_capture(path, max_bytes=cube - 1),
             f"{side}: {got} ({cube / 2**30:.3g} GiB): must be at most "
             f"{(cube - 1) / 2**30:.3g} GiB")
    size = path.stat().st_size
    path.write_bytes(path.read_bytes() + b"\0\0")
    _refused(lambda: read_capture(path),
             f"{path}: {size + 2} bytes: must be the {size} bytes its sidecar describes "
             f"({meta['format']})")
    path, side, _ = _copy(written, tmp_path, "bin",
                          lambda m: m.update(chirps=chirps + 1, shape=None))
    _refused(lambda: read_capture(path),
             f"{side}: chirps = {chirps + 1}: must be a multiple of the {n_tx} TDM slots of "
             "tx_order")
    cases = [
        ({"format": "dca1000-xwr18xx-complex-3lane"},
         "format = 'dca1000-xwr18xx-complex-3lane': must be a DCA1000 layout "
         f"dca1000-FAMILY-complex|real-2lane|4lane (e.g. {LAYOUT_DEFAULT.name}) for a .bin "
         "capture"),
        ({"lvds_lanes": 3}, "lvds_lanes = 3: must be 2 or 4 (the DCA1000's layouts)"),
        ({"format": None, "lvds_lanes": 3},
         "lvds_lanes = 3: must be 2 or 4 (the DCA1000's layouts)"),
        ({"adc": "real"}, "format = 'dca1000-xwr18xx-complex-2lane': must agree with "
                          "adc = 'real' and lvds_lanes = 2"),
        ({"lvds_lanes": 4}, "format = 'dca1000-xwr18xx-complex-2lane': must agree with "
                            "adc = 'complex' and lvds_lanes = 4"),
    ]
    for edit, tail in cases:
        path, side, _ = _copy(written, tmp_path, "bin", lambda m: m.update(edit))
        _refused(lambda: read_capture(path), f"{side}: {tail}")


def test_a_sidecar_too_large_or_too_deep_is_refused_whole(written, tmp_path):
    """A sidecar of exactly ``MAX_SIDECAR_BYTES`` reads; one byte more is refused by its size;
    a deeply nested one by its nesting; a FIFO is no capture file."""
    import os
    from rtsgeom.identify.capture import MAX_SIDECAR_BYTES, read_capture
    assert MAX_SIDECAR_BYTES == 1 << 20
    path, side, _ = _copy(written, tmp_path, "npy")
    text = side.read_text()
    side.write_text(text + " " * (MAX_SIDECAR_BYTES - len(text)))
    assert side.stat().st_size == MAX_SIDECAR_BYTES and read_capture(path).active == 0
    side.write_text(text + " " * (MAX_SIDECAR_BYTES + 1 - len(text)))
    _refused(lambda: read_capture(path), f"{side}: {MAX_SIDECAR_BYTES + 1} bytes: must be a "
                                         f"sidecar of at most {MAX_SIDECAR_BYTES} bytes")
    side.write_text("[" * 100_000 + "]" * 100_000)
    _refused(lambda: read_capture(path),
             f"{side}: not a probe capture's sidecar (JSON nested too deeply)")
    side.write_text("{nope")
    with pytest.raises(ValueError) as exc:
        import json
        json.loads("{nope")
    _refused(lambda: read_capture(path), f"{side}: not JSON ({str(exc.value)[:120]})")
    fifo = tmp_path / "fifo.npy"
    os.mkfifo(fifo)
    _refused(lambda: read_capture(fifo), f"{fifo}: not a regular file (a FIFO, socket or "
                                         "device): must be a capture file (.bin or .npy with "
                                         "its sidecar FILE.json)")


def test_a_capture_s_radar_record_against_the_scene_s_is_refused_whole():
    """``check_capture_radar``: no record, a missing field, a field off by 2e-6 relative (each
    field in turn) refused naming it; 0.5e-6 off accepted."""
    import dataclasses
    from rtsgeom.geometry import build_setup
    from rtsgeom.identify.capture import (
        RADAR_KEYS,
        Capture,
        check_capture_radar,
        radar_record,
    )
    scene = build_setup(small_noiseless()).scene
    radar = scene.radar
    rec = radar_record(radar)
    assert list(rec) == list(RADAR_KEYS) == [
        "f_c_hz", "bandwidth_hz", "chirp_duration_s", "chirp_repetition_s",
        "samples_per_chirp", "adc_rate_hz", "adc_start_s", "chirps_per_tx"]
    assert rec == {k: getattr(radar, k) for k in RADAR_KEYS}
    cap = Capture(np.ones((1, 1, 1), complex), 0, 1.0, 0.0, 1.0, radar=rec, source="src")
    check_capture_radar(cap, radar)
    _refused(lambda: check_capture_radar(dataclasses.replace(cap, radar=None), radar),
             "src: radar is missing (required): the sidecar must record the radar that made "
             "the capture (f_c_hz, bandwidth_hz, chirp_duration_s, chirp_repetition_s, "
             "samples_per_chirp, adc_rate_hz, adc_start_s, chirps_per_tx; rtsgeom adc "
             "--active writes it): the carrier does not show in a static probe's capture, "
             "only in its channel phase; for a capture made with the scene's radar, copy the "
             "scene's [radar] values")
    for k in RADAR_KEYS:
        want = getattr(radar, k)
        less = dataclasses.replace(cap, radar={j: v for j, v in rec.items() if j != k})
        _refused(lambda: check_capture_radar(less, radar),
                 f"src: radar.{k} is missing (required): must be the radar's that made the "
                 f"capture (the scene's is {want:g})")
        for rel, ok in ((0.5e-6, True), (-0.5e-6, True), (2e-6, False), (-2e-6, False)):
            have = want * (1 + rel)
            off = dataclasses.replace(cap, radar={**rec, k: have})
            if ok:
                check_capture_radar(off, radar)
            else:
                _refused(lambda: check_capture_radar(off, radar),
                         f"src: radar.{k} = {have:g}: must be the scene's {want:g} (the "
                         "capture was recorded with another radar configuration; identify "
                         "it against a scene with that radar)")


@pytest.mark.filterwarnings("error::RuntimeWarning")  # refused before any arithmetic on r
def test_simulate_capture_refuses_a_front_end_or_probe_range_out_of_range():
    from rtsgeom.geometry import build_setup
    from rtsgeom.identify.capture import simulate_capture
    setup = build_setup(small_noiseless())
    n, r_max = setup.fe.count, setup.scene.radar.max_range_m
    for active in (-1, n):
        _refused(lambda: simulate_capture(setup, active),
                 f"active front end {active}: must be in 0..{n - 1}")
    for r in (r_max, -1.0, 0.0):
        _refused(lambda: simulate_capture(setup, 0, r),
                 f"probe range {r:g} m: must be in (0, {r_max:g}) m")
