"""Each radar preset's raw capture in its board's own DCA1000 layout (TI SWRA581): real or
complex ADC, 2 or 4 LVDS lanes, stated in the sidecar and read back from it by `identify`."""

from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest

from conftest import DEFAULT_SCENE
from rtsgeom import identify as ident_mod
from rtsgeom.cli import main
from rtsgeom.errors import CaptureError
from rtsgeom.radar.dca1000 import capture_layout, dca1000_bytes, from_dca1000, to_dca1000
from rtsgeom.radar.fmcw import AdcCube
from rtsgeom.scene import load_scene
from rtsgeom.scene.presets import PRESETS

BASE = load_scene(DEFAULT_SCENE)
#: what each board's datasheet says of its receiver and LVDS lanes (see the presets' sources)
BOARD = {"awr1843boost": ("complex", 2), "iwr6843isk": ("complex", 2),
         "awr2944": ("real", 2), "awr2243-cascade": ("complex", 4)}


def test_every_preset_declares_its_boards_layout():
    assert set(BOARD) == set(PRESETS)
    for name, p in PRESETS.items():
        lay = p.capture
        assert (lay.adc, lay.lanes) == BOARD[name], name
        assert lay.name == f"dca1000-{lay.family}-{lay.adc}-{lay.lanes}lane"
        assert "SWRA581" in lay.source
        assert lay.name in p.doc  # listed where the presets are listed


def _swra581_reader(raw: bytes, chirps: int, num_rx: int, samples: int, adc: str,
                    lanes: int) -> np.ndarray:
    """TI SWRA581 sec. 9's readDCA1000, transcribed literally (one chirp at a time, as the
    MATLAB loops read it): an independent decoder to check the writer against."""
    a = np.frombuffer(raw, "<i2").astype(float)
    out = np.zeros((chirps, num_rx, samples), complex)
    if lanes == 2:
        per = num_rx * samples * (2 if adc == "complex" else 1)
        for ch in range(chirps):
            block = a[ch * per:(ch + 1) * per]
            if adc == "complex":  # for i = 1:4:end: LVDS(c) = a(i) + j a(i+2); c+1: a(i+1), a(i+3)
                lv = np.empty(per // 2, complex)
                lv[0::2] = block[0::4] + 1j * block[2::4]
                lv[1::2] = block[1::4] + 1j * block[3::4]
            else:
                lv = block
            out[ch] = lv.reshape(num_rx, samples)
        return out
    n_dev = -(-num_rx // 4)
    rows = 8 if adc == "complex" else 4  # reshape(adcData, numLanes*2, []) / (numLanes, [])
    per = n_dev * samples * rows
    for ch in range(chirps):
        for dev in range(n_dev):
            block = a[ch * per + dev * samples * rows:ch * per + (dev + 1) * samples * rows]
            m = block.reshape(samples, rows).T  # column-major reshape of MATLAB
            lanes_x = m[0:4] + 1j * m[4:8] if adc == "complex" else m[0:4]
            for lane in range(4):
                if dev * 4 + lane < num_rx:
                    out[ch, dev * 4 + lane] = lanes_x[lane]
    return out


@pytest.mark.parametrize("name", sorted(PRESETS))
def test_each_layout_is_what_tis_reader_reads(name):
    """A random cube in each preset's layout, read by the transcribed SWRA581 reader: the
    real part (and the imaginary part for a complex ADC) to one LSB, the file size as
    declared, full scale reached; the package's decoder agrees."""
    lay = PRESETS[name].capture
    rng = np.random.default_rng(1)
    n_rx, n_tx, n_l, n_s = PRESETS[name].num_rx, 2, 3, 16
    data = (rng.normal(size=(n_l, n_tx * n_rx, n_s))
            + 1j * rng.normal(size=(n_l, n_tx * n_rx, n_s))).astype(np.complex64)
    rut = SimpleNamespace(num_rx=n_rx, tx_order=(0, 1))
    raw, scale = to_dca1000(AdcCube(data, None, rut), lay)
    chirps = n_l * n_tx
    assert len(raw) == dca1000_bytes(chirps, n_rx, n_s, lay)
    expect = data.reshape(chirps, n_rx, n_s) * scale
    if lay.adc == "real":
        expect = expect.real.astype(complex)
        assert len(raw) == chirps * n_rx * n_s * 2  # one int16 per sample
    ti = _swra581_reader(raw, chirps, n_rx, n_s, lay.adc, lay.lanes)
    assert np.max(np.abs(ti - expect)) <= 0.71
    assert np.max(np.abs(np.frombuffer(raw, "<i2"))) == 32767
    ours = from_dca1000(raw, chirps, n_rx, n_s, lay)
    assert np.array_equal(ours, ti.astype(np.complex64))


def _scene(preset: str):
    return BASE.evolve(targets=(), radar=BASE.radar.evolve(antenna_preset=preset,
                                                           use_elevation_tx=False))


@pytest.mark.parametrize("name", sorted(PRESETS))
def test_adc_writes_and_states_each_presets_layout(name, tmp_path):
    """`rtsgeom adc --active` on a scene of each preset: the sidecar states the board's
    layout; the file has its size; read_capture reads the layout from the sidecar."""
    scene = _scene(name)
    setup = ident_mod.setup_of(scene)
    cap = ident_mod.simulate_capture(setup, 0, seed=2)
    meta = ident_mod.write_capture(cap, setup.rut, tmp_path / "c.bin", "dca1000",
                                   capture_layout(scene.radar))
    lay = PRESETS[name].capture
    side = json.loads((tmp_path / "c.bin.json").read_text())
    assert side == json.loads(json.dumps(meta))
    assert (side["format"], side["adc"], side["lvds_lanes"]) == (lay.name, lay.adc, lay.lanes)
    n_l, n_v, n_s = cap.data.shape
    assert (tmp_path / "c.bin").stat().st_size == dca1000_bytes(side["chirps"], side["num_rx"],
                                                               n_s, lay)
    back = ident_mod.read_capture(tmp_path / "c.bin")
    assert back.adc == lay.adc
    want = cap.data if lay.complex else cap.data.real
    assert np.max(np.abs(back.data - want)) <= 0.71 / side["scale"]


def test_cli_adc_on_an_awr2944_scene_writes_real_2lane(tmp_path):
    """The reproducer: `rtsgeom adc` on an AWR2944 scene wrote dca1000-xwr18xx-complex-2lane
    for a real-only receiver."""
    src = DEFAULT_SCENE.read_text().replace('antenna_preset = "awr1843boost"',
                                            'antenna_preset = "awr2944"')
    scene = tmp_path / "s.toml"
    scene.write_text(src)
    out = tmp_path / "cap0.bin"
    assert main(["adc", str(scene), "--active", "0", "--out", str(out), "--quiet"]) == 0
    side = json.loads((tmp_path / "cap0.bin.json").read_text())
    assert (side["format"], side["adc"], side["lvds_lanes"]) == (
        "dca1000-awr2944-real-2lane", "real", 2)


def _awr2944_truth(tangential_mm, gain_db=0.5, phase_rad=-0.3):
    scene = _scene("awr2944")
    fes = list(scene.rts.front_ends)
    fes[0] = fes[0].evolve(tangential_offset_m=tangential_mm * 1e-3, gain_offset_db=gain_db,
                           phase_offset_rad=phase_rad)
    return scene, scene.evolve(rts=scene.rts.evolve(front_ends=tuple(fes)))


def test_real_only_capture_spectrum_is_conjugate_symmetric(tmp_path):
    """A real-only capture's range-Doppler spectrum: X[k, d] = conj(X[-k, -d]) (Doppler
    unshifted), so the echo appears at +f_b and at its mirror with equal power."""
    scene, truth = _awr2944_truth(0.3)
    setup = ident_mod.setup_of(truth)
    cap = ident_mod.simulate_capture(setup, 0, seed=3)
    ident_mod.write_capture(cap, setup.rut, tmp_path / "c.bin", "dca1000")
    x = ident_mod.read_capture(tmp_path / "c.bin").data[:, 0, :].astype(complex)  # (L, N)
    assert not np.any(x.imag)
    X = np.fft.fft2(x)
    mirror = np.conj(np.roll(np.flip(X, (0, 1)), 1, (0, 1)))
    assert np.max(np.abs(X - mirror)) <= 1e-9 * np.max(np.abs(X))
    # the echo at the probe's positive range bin and its mirror, the same power
    n_s = x.shape[1]
    p = np.sum(np.abs(X) ** 2, axis=0)
    k = int(np.argmax(p[1:n_s // 2])) + 1
    assert np.isclose(p[k], p[n_s - k], rtol=1e-9)


@pytest.mark.parametrize("tangential_mm", [-0.4, 0.3, 1.0])
def test_real_only_capture_round_trip_identifies_the_offset(tangential_mm, tmp_path):
    """adc -> identify on an AWR2944 scene: the real-only capture (read as such from its
    sidecar, estimator on the positive half at twice the value) gives the mounting offset,
    gain and phase of the bench as built within 3 sigma (and 0.1 dB, 1 deg); the noise
    model holds (residual about 1). Reading it as complex halves the echo: -6 dB."""
    scene, truth = _awr2944_truth(tangential_mm)
    setup = ident_mod.setup_of(truth)
    cap = ident_mod.simulate_capture(setup, 0, seed=11)
    ident_mod.write_capture(cap, setup.rut, tmp_path / "c.bin", "dca1000")
    back = ident_mod.read_capture(tmp_path / "c.bin")
    d = ident_mod.identify(scene, [back]).to_dict()
    fe, ch = d["front_ends"][0], d["channels"][0]
    t = fe["tangential_offset_mm"]
    assert abs(t["value"] - tangential_mm) <= 3 * t["std"] + 0.02
    assert abs(ch["gain_db"]["value"] - 0.5) <= max(3 * ch["gain_db"]["std"], 0.1)
    assert abs(ch["phase_deg"]["value"] - np.degrees(-0.3)) <= max(
        3 * ch["phase_deg"]["std"], 1.0)
    assert d["model_fits"]
    assert 0.7 <= fe["residual_rms"] <= 1.3
    import dataclasses
    as_complex = dataclasses.replace(back, adc="complex")
    g = ident_mod.identify(scene, [as_complex]).to_dict()["channels"][0]["gain_db"]["value"]
    assert g < 0.5 - 5.0


def test_real_only_probe_beyond_half_the_adc_range_is_refused():
    scene, truth = _awr2944_truth(0.0)
    setup = ident_mod.setup_of(truth)
    r = 0.6 * scene.radar.max_range_m
    cap = ident_mod.simulate_capture(setup, 0, r, seed=1)
    import dataclasses
    cap = dataclasses.replace(cap, data=cap.data.real.astype(np.complex64), adc="real")
    with pytest.raises(CaptureError, match="real-only capture's unambiguous range"):
        ident_mod.identify(scene, [cap])


@pytest.mark.parametrize("edit,match", [
    ({"format": "dca1000-awr2944-real-3lane"}, "format"),
    ({"format": "dca1000-awr2944-complex-2lane", "adc": "real"}, "must agree"),
    ({"adc": "imaginary"}, "adc"),
    ({"lvds_lanes": 3}, "lvds_lanes"),
])
def test_a_sidecar_stating_no_known_layout_is_refused(edit, match, tmp_path):
    scene, truth = _awr2944_truth(0.0)
    setup = ident_mod.setup_of(truth)
    cap = ident_mod.simulate_capture(setup, 0, seed=1)
    meta = ident_mod.write_capture(cap, setup.rut, tmp_path / "c.bin", "dca1000")
    meta.update(edit)
    (tmp_path / "c.bin.json").write_text(json.dumps(meta))
    with pytest.raises(CaptureError, match=match):
        ident_mod.read_capture(tmp_path / "c.bin")


def test_an_old_sidecar_without_layout_fields_reads_as_xwr18xx_complex(tmp_path):
    setup = ident_mod.setup_of(BASE)
    cap = ident_mod.simulate_capture(setup, 0, seed=1)
    meta = ident_mod.write_capture(cap, setup.rut, tmp_path / "c.bin", "dca1000")
    assert meta["format"] == "dca1000-xwr18xx-complex-2lane"
    for k in ("adc", "lvds_lanes", "format"):
        meta.pop(k)
    (tmp_path / "c.bin.json").write_text(json.dumps(meta))
    assert ident_mod.read_capture(tmp_path / "c.bin").adc == "complex"
