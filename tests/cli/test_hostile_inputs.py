"""Hostile inputs end in one clean line naming the field, or in a finite answer: never a
traceback, a NaN in an output or a silent estimate. One table per input kind: scene files the
commands could not compute, probe captures and their sidecars, calibration files, command-line
paths and Python arguments."""

from __future__ import annotations

import json
import math
import re
import shutil

import numpy as np
import pytest

import rtsgeom
from conftest import DEFAULT_SCENE, ROOT
from rtsgeom.cli import main
from rtsgeom.errors import CaptureError, ParameterError, SceneError
from rtsgeom.identify import read_capture, simulate_capture, write_capture
from rtsgeom.identify.capture import MAX_CAPTURE_BYTES
from rtsgeom.geometry import build_setup


def _finite_json(text: str):
    """The JSON of an output, refusing NaN/Infinity (json.loads would accept them)."""
    def refuse(name):
        raise AssertionError(f"{name} in an output")
    return json.loads(text, parse_constant=refuse)


def _clean_error(err: str, *words: str) -> None:
    assert "Traceback" not in err and "RuntimeWarning" not in err
    line = [x for x in err.splitlines() if x.startswith("rtsgeom: error:")]
    assert line, err
    for w in words:
        assert w in line[0], line[0]


# -- scene files: refused at load naming the rule, or computed with no NaN ------------------

def _with(text: str, tmp_path, name="s.toml", add="", drop=None):
    if drop:
        text = re.sub(drop, "", text, flags=re.M)
    p = tmp_path / name
    p.write_text(text + "\n" + add)
    return p


@pytest.mark.parametrize("key, value", [("adc_full_scale_dbm", -1), ("adc_full_scale_dbm", 50),
                                        ("adc_bits", 2), ("if_lowpass_hz", 1000),
                                        ("if_highpass_hz", 1e9), ("noise_figure_db", 50)])
def test_info_json_with_extreme_link_values_is_finite(key, value, tmp_path, capsys):
    """Link values that hide the front ends from the RuT (ADC clipped or below the noise):
    info says why the reachable spans are not computed instead of writing [nan, nan]."""
    drop = r"^snr_db.*$" if key == "noise_figure_db" else None
    p = _with(DEFAULT_SCENE.read_text(), tmp_path, add=f"[radar.link]\n{key} = {value}\n",
              drop=drop)
    assert main(["info", str(p), "--json"]) == 0
    cap = capsys.readouterr()
    info = _finite_json(cap.out)
    assert "Traceback" not in cap.err and "RuntimeWarning" not in cap.err
    if "reachable" not in info:
        assert "not detected" in info["reachable_unavailable"]
    assert main(["info", str(p)]) == 0
    text = capsys.readouterr()
    assert not re.search(r"\bnan\b|\binf\b", (text.out + text.err).lower())


_ARRAYS = {"diagonal": ("[[0,0],[1.9,1.9],[3.8,3.8]]",
                        "[[10,10],[11.9,11.9],[13.8,13.8],[15.7,15.7]]", "[0, 1, 2]"),
           "single": ("[[0,0]]", "[[10,0]]", "[0]"),
           "vertical": ("[[0,0],[0,1.9],[0,3.8]]", "[[10,0],[10,1.9],[10,3.8],[10,5.7]]",
                        "[0, 1, 2]")}


def _custom_array_scene(kind, tmp_path):
    """custom-array.toml with the Tx, Rx and Tx order of ``_ARRAYS[kind]``, written beside it."""
    tx, rx, order = _ARRAYS[kind]
    text = (ROOT / "scenes" / "custom-array.toml").read_text()
    text = re.sub(r"^tx_mm = .*$", f"tx_mm = {tx}", text, flags=re.M)
    text = re.sub(r"^rx_mm = .*$", f"rx_mm = {rx}", text, flags=re.M)
    text = re.sub(r"^tx_order = .*$", f"tx_order = {order}", text, flags=re.M)
    return _with(text, tmp_path)


@pytest.mark.parametrize("kind", list(_ARRAYS))
def test_info_json_of_degenerate_custom_arrays_is_finite(kind, tmp_path, capsys):
    """A custom array without azimuth aperture: the undefined quantities are null with the
    reason, the rest as for any array."""
    p = _custom_array_scene(kind, tmp_path)
    assert main(["info", str(p), "--json"]) == 0
    info = _finite_json(capsys.readouterr().out)
    one_position = kind != "diagonal"
    assert (info["virtual_array"]["smallest_spacing_m"] is None) == (
        info["virtual_array"]["num_azimuth_unique"] < 2)
    if one_position:
        assert all(fe["apparent_azimuth_deg"] is None for fe in info["front_ends"])
        assert "fewer than two" in info["apparent_azimuth_unavailable"]


@pytest.mark.parametrize("kind", list(_ARRAYS))
def test_run_refuses_an_array_without_azimuth_aperture_naming_it(kind, tmp_path, capsys):
    """run on the diagonal array ended in a traceback (CalibrationFailed after an All-NaN
    RuntimeWarning); single and vertical arrays in a span of [-90, -90] deg."""
    p = _custom_array_scene(kind, tmp_path)
    assert main(["run", str(p), "--out", str(tmp_path / "out"), "--no-report"]) == 2
    _clean_error(capsys.readouterr().err, "radar.array", "at least 2")
    assert not (tmp_path / "out").exists()


def _pattern(tmp_path, gain):
    rows = ["azimuth_deg,elevation_deg,gain_db,phase_deg"]
    rows += [f"{a},{e},{gain if a == 0 else 0},0" for a in range(-90, 91, 10) for e in (-10, 0, 10)]
    (tmp_path / "pat.csv").write_text("\n".join(rows) + "\n")
    return _with(DEFAULT_SCENE.read_text(), tmp_path,
                 add='[radar.pattern]\nkind = "table"\ntable = "pat.csv"\n')


def test_pattern_table_gain_beyond_its_range_is_refused(tmp_path, capsys):
    """gain_db = 1e5 overflowed the amplitudes (paths wrote nan on 14 rows, exit 0)."""
    p = _pattern(tmp_path, 1e5)
    assert main(["paths", str(p), "--out", str(tmp_path / "p.csv")]) == 2
    _clean_error(capsys.readouterr().err, "gain_db = 100000", "[-300, 100] dB")
    assert not (tmp_path / "p.csv").exists()


def test_pattern_table_gain_at_its_bound_is_finite(tmp_path, capsys):
    p = _pattern(tmp_path, 100.0)
    assert main(["paths", str(p), "--out", str(tmp_path / "p.csv")]) == 0
    assert "nan" not in (tmp_path / "p.csv").read_text()


def test_pattern_csv_with_an_over_long_field_is_refused(tmp_path, capsys):
    (tmp_path / "pat.csv").write_text("azimuth_deg,elevation_deg,gain_db,phase_deg\n"
                                      + "1" * 140_000 + ",0,0,0\n")
    p = _with(DEFAULT_SCENE.read_text(), tmp_path,
              add='[radar.pattern]\nkind = "table"\ntable = "pat.csv"\n')
    assert main(["info", str(p)]) == 2
    _clean_error(capsys.readouterr().err, "not a CSV table")


# -- command-line paths ---------------------------------------------------------------------

@pytest.mark.parametrize("command", ["paths", "adc"])
def test_out_naming_a_folder_is_refused_not_written_as_a_file(command, tmp_path, capsys):
    """``--out newdir/`` of a one-file command wrote a file named newdir."""
    out = str(tmp_path / "newdir") + "/"
    with pytest.raises(SystemExit) as exc:
        main([command, str(DEFAULT_SCENE), "--out", out])
    assert exc.value.code == 2
    assert "names a folder" in capsys.readouterr().err
    assert not (tmp_path / "newdir").exists()


# -- probe captures and their sidecars -------------------------------------------------------

@pytest.fixture(scope="module")
def captures(tmp_path_factory):
    """A .npy and a DCA1000 capture of front end 0 of the bundled scene, with sidecars."""
    d = tmp_path_factory.mktemp("caps")
    scene = rtsgeom.load_scene(DEFAULT_SCENE)
    setup = build_setup(scene)
    cap = simulate_capture(setup, 0, seed=3)
    write_capture(cap, setup.rut, d / "cap.npy", "npy")
    write_capture(cap, setup.rut, d / "cap.bin", "dca1000")
    return d


def _variant(captures, tmp_path, name, meta=None, data=None, binary=False, raw_side=None,
             header=None):
    src = captures / ("cap.bin" if binary else "cap.npy")
    p = tmp_path / (name + src.suffix)
    if header is not None:
        p.write_bytes(header)
    elif data is not None:
        np.save(p, data)
    else:
        shutil.copy(src, p)
    side = json.loads((captures / (src.name + ".json")).read_text())
    text = raw_side(json.dumps(side)) if raw_side else json.dumps({**side, **(meta or {})})
    (tmp_path / (p.name + ".json")).write_text(text)
    return p


def _npy_header(shape):
    h = f"{{'descr': '<c8', 'fortran_order': False, 'shape': {shape}, }}"
    h = h + " " * (118 - len(h)) + "\n"
    return b"\x93NUMPY\x01\x00" + len(h).to_bytes(2, "little") + h.encode()


_SIDECARS = [  # name, variant keywords, the words the one-line error must hold
    ("tx_order empty", dict(meta={"tx_order": []}, binary=True), ["tx_order = []"]),
    ("scale 0", dict(meta={"scale": 0}, binary=True), ["scale = 0", "[1e-30, 1e+30]"]),
    ("scale nan", dict(meta={"scale": math.nan}, binary=True), ["scale = nan", "finite"]),
    ("scale inf", dict(meta={"scale": math.inf}, binary=True), ["scale = inf"]),
    ("scale -1", dict(meta={"scale": -1}, binary=True), ["scale = -1"]),
    ("amplitude 0", dict(meta={"probe_amplitude": 0}), ["probe_amplitude = 0"]),
    ("amplitude nan", dict(meta={"probe_amplitude": math.nan}), ["probe_amplitude = nan"]),
    ("range nan", dict(meta={"probe_range_m": math.nan}), ["probe_range_m = nan"]),
    ("range inf", dict(meta={"probe_range_m": math.inf}), ["probe_range_m = inf"]),
    ("range 1e308", dict(meta={"probe_range_m": 1e308}), ["probe_range_m = 1e+308"]),
    ("range 30 m", dict(meta={"probe_range_m": 30.0}), ["probe_range_m = 30",
                                                        "strongest echo"]),
    ("5000 digits", dict(raw_side=lambda s: s.replace('"active_front_end": 0',
                                                      '"active_front_end": ' + "9" * 5000)),
     ["not JSON"]),
    ("deep nesting", dict(raw_side=lambda s: "[" * 100_000 + "]" * 100_000),
     ["nested too deeply"]),
    ("wrong front end", dict(meta={"active_front_end": 1}), ["active_front_end = 1",
                                                             "front end 0"]),
    ("front end 7", dict(meta={"active_front_end": 7}), ["active_front_end = 7"]),
    ("200 m/s", dict(meta={"probe_velocity_mps": 200.0}), ["probe_velocity_mps = 200"]),
    ("other f_c", dict(meta={"radar": {"f_c_hz": 76.5e9}}), ["radar.f_c_hz = 7.65e+10",
                                                             "scene's 7.7e+10"]),
    ("huge header", dict(header=_npy_header((100000, 100000, 1000))),
     ["[100000, 100000, 1000]", "[120, 8, 512]"]),
    ("short .bin", dict(meta={"chirps": 120}, binary=True), ["must be the scene's radar"]),
    # within one bin of the echo: passed the strongest-cell check and fitted a wrong phase
    ("range +0.11 m", dict(meta={"probe_range_m": 15.6}), ["probe_range_m = 15.6",
                                                          "-0.74 bins", "15.488 m"]),
    ("range -0.09 m", dict(meta={"probe_range_m": 15.4}), ["probe_range_m = 15.4", "bins"]),
    ("velocity 0.2", dict(meta={"probe_velocity_mps": 0.2}), ["probe_velocity_mps = 0.2",
                                                             "at most 0.05 bin"]),
    ("velocity 0.05", dict(meta={"probe_velocity_mps": 0.05}), ["probe_velocity_mps = 0.05"]),
    ("no radar record", dict(raw_side=lambda t: json.dumps(
        {k: v for k, v in json.loads(t).items() if k != "radar"})),
     ["radar is missing (required)", "carrier"]),
    ("radar without f_c", dict(raw_side=lambda t: json.dumps(
        {**json.loads(t), "radar": {k: v for k, v in json.loads(t)["radar"].items()
                                    if k != "f_c_hz"}})), ["radar.f_c_hz is missing"]),
    ("other tx_order", dict(meta={"tx_order": [2, 0]}, binary=True),
     ["tx_order = [2, 0]", "the scene's radar's [0, 2]"]),
    ("other shape", dict(meta={"shape": [120, 8, 256]}), ["shape = [120, 8, 256]",
                                                          "[120, 8, 512]"]),
    ("other kind", dict(meta={"kind": "my-capture"}), ["kind = 'my-capture'",
                                                       "rtsgeom-probe-capture"]),
]


@pytest.mark.parametrize("name, kw, words", _SIDECARS, ids=[c[0] for c in _SIDECARS])
def test_identify_refuses_a_capture_its_sidecar_does_not_describe(name, kw, words, captures,
                                                                   tmp_path, capsys):
    p = _variant(captures, tmp_path, name.replace(" ", "_").replace("/", ""), **kw)
    assert main(["identify", str(DEFAULT_SCENE), str(p), "--json"]) == 2
    cap = capsys.readouterr()
    assert cap.out == ""
    _clean_error(cap.err, "CAPTURE:", *words)


@pytest.mark.parametrize("name, change, words", [
    ("one NaN sample", lambda d: d.__setitem__((0, 0, 0), np.nan), ["1 sample(s) not finite"]),
    ("all zero", lambda d: d.__imul__(0), ["every sample is 0"]),
])
def test_identify_refuses_captures_without_a_finite_signal(name, change, words, captures,
                                                           tmp_path, capsys):
    d = np.load(captures / "cap.npy")
    change(d)
    p = _variant(captures, tmp_path, "bad", data=d)
    assert main(["identify", str(DEFAULT_SCENE), str(p)]) == 2
    _clean_error(capsys.readouterr().err, *words)


def test_a_capture_larger_than_the_cap_is_refused_before_it_is_read(tmp_path):
    """Without a scene to size it by, a .npy header promising more than the cap is refused
    (the header of 72.8 TiB was an allocation attempt)."""
    p = tmp_path / "big.npy"
    p.write_bytes(_npy_header((100000, 100000, 1000)))
    (tmp_path / "big.npy.json").write_text(json.dumps(
        {"active_front_end": 0, "probe_range_m": 15.0, "probe_velocity_mps": 0.0,
         "probe_amplitude": 1.0, "format": "npy"}))
    with pytest.raises(CaptureError, match="must be at most 4 GiB"):
        read_capture(p)
    assert MAX_CAPTURE_BYTES == 4 << 30


@pytest.mark.slow
def test_absurd_estimates_and_misfits_are_refused_or_flagged(captures, tmp_path, capsys):
    """A capture times 1e30 fits a gain of +600 dB: refused as not this setup's. A capture of
    a 1.2 m arc fitted on the 1 m scene (residual ~9 x noise): refused, and with
    --accept-misfit written with its flag."""
    p = _variant(captures, tmp_path, "big", data=np.load(captures / "cap.npy") * 1e30)
    assert main(["identify", str(DEFAULT_SCENE), str(p), "--quiet"]) == 2
    _clean_error(capsys.readouterr().err, "gain_db = 599.", "[-40, 40] dB")
    scene = rtsgeom.load_scene(DEFAULT_SCENE)
    wide = scene.evolve(rts=scene.rts.evolve(arc_radius_m=1.2))
    setup = build_setup(wide)
    write_capture(simulate_capture(setup, 0, seed=5), setup.rut, tmp_path / "arc.npy", "npy")
    # a sidecar without the RTS delay (the scene's is taken): the arc shows only in the fit
    side = tmp_path / "arc.npy.json"
    side.write_text(json.dumps({k: v for k, v in json.loads(side.read_text()).items()
                                if k != "rts_delay_s"}))
    assert main(["identify", str(DEFAULT_SCENE), str(tmp_path / "arc.npy"), "--quiet"]) == 2
    _clean_error(capsys.readouterr().err, "residual_rms", "must be at most 3")
    assert main(["identify", str(DEFAULT_SCENE), str(tmp_path / "arc.npy"), "--json",
                 "--accept-misfit"]) == 0
    cap = capsys.readouterr()
    d = _finite_json(cap.out)
    assert d["model_fits"] is False and "residual_rms" in d["front_ends"][0]["misfit"]
    assert "rtsgeom: warning:" in cap.err


# -- calibration files ------------------------------------------------------------------------

def test_from_identified_refuses_a_file_of_another_setup(tmp_path, capsys):
    """--from-identified FILE used to ignore SCENE: a FILE that is not SCENE as identified
    (here another arc radius) is refused."""
    text = DEFAULT_SCENE.read_text()
    other = _with(re.sub(r"^arc_radius_m = .*$", "arc_radius_m = 1.3", text, flags=re.M),
                  tmp_path, "other.toml")
    assert main(["calibrate", str(DEFAULT_SCENE), "--from-identified", str(other)]) == 2
    _clean_error(capsys.readouterr().err, "--from-identified", "not SCENE")


@pytest.mark.slow
def test_from_identified_writes_a_calibration_file_run_reads(tmp_path, capsys):
    """calibration.json of --from-identified is a calibration file: load_calibration (what
    run --calibration uses) accepts it, with the detected angles of the front ends."""
    from rtsgeom.calibration.file import load_calibration
    out = tmp_path / "cal"
    assert main(["calibrate", str(DEFAULT_SCENE), "--from-identified", str(DEFAULT_SCENE),
                 "--out", str(out), "--quiet"]) == 0
    doc = json.loads((out / "calibration.json").read_text())
    probe, cals = load_calibration(doc, build_setup(rtsgeom.load_scene(DEFAULT_SCENE)))
    assert list(cals) == [(0, 1)] and np.all(np.isfinite(probe.angle_rad))
    assert np.allclose(probe.gain_correction, 1.0)  # the bundled scene has no gain errors
    capsys.readouterr()
    assert main(["run", str(DEFAULT_SCENE), "--calibration", str(out / "calibration.json"),
                 "--out", str(tmp_path / "run"), "--no-report"]) == 0
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert all(t["detection"] is not None and abs(t["error"]["angle_deg"]) < 0.05
               for t in summary["targets"])


# -- Python arguments -------------------------------------------------------------------------

@pytest.fixture(scope="module")
def scene():
    return rtsgeom.load_scene(DEFAULT_SCENE)


_API = [  # call, exception, words of the message
    (lambda s: rtsgeom.load_scene(123), ParameterError, "path = 123"),
    (lambda s: rtsgeom.replace(s, targets=[{"range_m": 5.0}]), SceneError,
     "a tuple of TargetConfig"),
    (lambda s: rtsgeom.replace(s, radar={"f_c_hz": 77e9}), SceneError, "a RadarConfig"),
    (lambda s: rtsgeom.tolerance(s, sigma_mm=math.nan), ParameterError, "sigma_mm = nan"),
    (lambda s: rtsgeom.tolerance(s, sigma_mm=(0.1, math.nan, 0.1)), ParameterError,
     "finite numbers in [0, 10] mm"),
    (lambda s: rtsgeom.tolerance(s, sigma_mm=0.1), ParameterError, "a list of 3 numbers"),
    (lambda s: rtsgeom.tolerance(s, draws=0), ParameterError, "draws = 0: must be in [1, 1e+07]"),
    (lambda s: rtsgeom.tolerance(s, draws=-5), ParameterError, "draws = -5"),
    (lambda s: rtsgeom.tolerance(s, draws=10 ** 12), ParameterError, "draws = 1000000000000"),
    (lambda s: rtsgeom.tolerance(s, draws=2.5), ParameterError, "an integer"),
    (lambda s: rtsgeom.tolerance(s, distribution="cauchy"), ParameterError, "normal, uniform"),
    (lambda s: rtsgeom.calibrate("scenes/diewald2022.toml"), ParameterError,
     "rtsgeom.load_scene(path)"),
    (lambda s: rtsgeom.calibrate(s, pair="01"), ParameterError, "pair = '01'"),
    (lambda s: rtsgeom.calibrate(s, pair=(0, 1, 2)), ParameterError, "two front-end indices"),
    (lambda s: rtsgeom.run_scene(None), ParameterError, "scene = None: must be a Scene"),
    (lambda s: rtsgeom.run_scene(s, "bogus"), ParameterError, "paths_method = 'bogus'"),
    (lambda s: rtsgeom.run_scene(s, aoa_mode="magic"), ParameterError, "aoa_mode = 'magic'"),
    (lambda s: rtsgeom.linearity(s, amplitudes="x"), ParameterError, "amplitudes = 'x'"),
    (lambda s: rtsgeom.ghosts(s, floor_db=math.inf), ParameterError, "floor_db = inf"),
    (lambda s: rtsgeom.design(s, [1.0], [8.0], target_yield=1.5), ParameterError,
     "target_yield = 1.5"),
]


@pytest.mark.parametrize("call, exc, words", _API, ids=[c[2] for c in _API])
def test_python_arguments_raise_the_named_error(call, exc, words, scene):
    with pytest.raises(exc) as info:
        call(scene)
    assert words in str(info.value)


def test_fuzzed_sidecars_and_calibration_files_keep_the_contract(capsys):
    """Mutated sidecars and calibration files (the scene fuzzer's mutators) end in a finite
    result or the input's own error (a pair of one index was an IndexError, a 400-digit gain
    an OverflowError, a sidecar scale of 5e-324 a division by zero)."""
    from benchmarks.fuzz_inputs import main as fuzz
    assert fuzz(["--inputs", "40", "--seed", "7"]) == 0, capsys.readouterr().out


# -- identify: the captures as a whole, and Python's arguments ----------------------------------

def test_identify_refuses_one_recording_given_twice(captures, tmp_path, capsys):
    """cap.bin twice, or one recording as .bin and .npy, counted as independent evidence
    (1024 links to one file read +-0.0023 mm, 10 sigma from the truth)."""
    for pair in (("cap.npy", "cap.npy"), ("cap.npy", "cap.bin")):
        assert main(["identify", str(DEFAULT_SCENE), *(str(captures / p) for p in pair)]) == 2
        _clean_error(capsys.readouterr().err, "the same recording as", "independent")


def test_identify_refuses_a_folder_or_fifo_as_capture(tmp_path, capsys):
    import os
    (tmp_path / "d.npy").mkdir()
    assert main(["identify", str(DEFAULT_SCENE), str(tmp_path / "d.npy")]) == 2
    _clean_error(capsys.readouterr().err, "a folder", "must be a capture file")
    os.mkfifo(tmp_path / "f.npy")
    assert main(["identify", str(DEFAULT_SCENE), str(tmp_path / "f.npy")]) == 2
    _clean_error(capsys.readouterr().err, "not a regular file")


def test_capture_repr_is_one_line(captures):
    text = repr(read_capture(captures / "cap.npy"))
    assert "\n" not in text and len(text) < 200 and "120x8x512" in text


def test_identify_python_counts_and_kinds(captures, scene):
    from rtsgeom.identify import identify
    cap = read_capture(captures / "cap.npy")
    for caps, words in (([], "captures = []"), (None, "captures = None"),
                        ("cap.npy", "captures = 'cap.npy'"), (["cap.npy"], "captures[0]"),
                        ([cap] * 1025, "must be at most 1024")):
        with pytest.raises(ParameterError, match=re.escape(words)):
            identify(scene, caps)
    for bad in (None, "scenes/diewald2022.toml"):
        with pytest.raises(ParameterError, match="must be a Scene"):
            identify(bad, [cap])
    with pytest.raises(CaptureError, match="the same recording"):
        identify(scene, [cap, cap])


# -- the newer entry points: Python arguments ------------------------------------------------

_X = ROOT / "scenes" / "crossing.toml"
_NEW_API = [  # (entry, keywords), words of the ParameterError
    ("transfer", dict(radars=5.5), "radars = 5.5: must be an integer in [1, 100000]"),
    ("transfer", dict(radars=True), "radars = True"),
    ("transfer", dict(radars="5"), "radars = '5'"),
    ("transfer", dict(radars=None), "radars = None"),
    ("transfer", dict(radars=10 ** 6), "radars = 1000000: must be in [1, 100000]"),
    ("transfer", dict(radars=100_000, points=201, sigma_phase_deg=1.0), None),  # (see below)
    ("transfer", dict(sigma_phase_deg="5"), "sigma_phase_deg = '5': must be a number"),
    ("transfer", dict(sigma_phase_deg=None), "sigma_phase_deg = None"),
    ("transfer", dict(sigma_phase_deg=1j), "sigma_phase_deg = 1j"),
    ("transfer", dict(sigma_phase_deg=np.array([1.0, 2.0])), "sigma_phase_deg = array"),
    ("transfer", dict(sigma_phase_deg=math.nan), "sigma_phase_deg = nan"),
    ("transfer", dict(sigma_gain_db=7.0), "sigma_gain_db = 7: must be in [0, 6] dB"),
    ("transfer", dict(spec_deg="0.1"), "spec_deg = '0.1'"),
    ("transfer", dict(seed=-1), "seed = -1"),
    ("transfer", dict(seed="x"), "seed = 'x'"),
    ("transfer", dict(seed=1.5), "seed = 1.5"),
    ("drive_tolerance", dict(draws=None), "draws = None: must be an integer in [1, 1e+07]"),
    ("drive_tolerance", dict(draws=0), "draws = 0: must be in [1, 1e+07]"),
    ("drive_tolerance", dict(draws=-5), "draws = -5"),
    ("drive_tolerance", dict(draws=10 ** 12), "draws = 1000000000000"),
    ("drive_tolerance", dict(spec_deg=math.nan), "spec_deg = nan"),
    ("drive_tolerance", dict(spec_deg=-1), "spec_deg = -1: must be in [1e-06, 90] deg"),
    ("drive_tolerance", dict(sigma_mm=(1e6, 0.1, 0.1)), "finite numbers in [0, 10] mm"),
    ("drive_tolerance", dict(sigma_mm=0.1), "sigma_mm = 0.1: must be a list of 3 numbers"),
    ("drive_tolerance", dict(sigma_mm=(0.1, 0.1)), "sigma_mm = (0.1, 0.1)"),
    ("drive_tolerance", dict(sigma_mm="abc"), "sigma_mm = 'abc'"),
    ("drive_tolerance", dict(seed=-1), "seed = -1"),
    ("drive_tolerance", dict(seed="x"), "seed = 'x'"),
    ("drive_tolerance", dict(distribution="cauchy"), "normal, uniform"),
    ("drive_tolerance", dict(scene=None), "drive_tolerance: scene = None: must be a Scene"),
    ("Playback", dict(scene=None), "Playback: scene = None: must be a Scene"),
    ("Playback", dict(workers=0), "workers = 0"),
    ("Playback", dict(bins=True), "bins = True"),
    ("Playback", dict(amplitudes=3), "amplitudes = 3"),
]
_NEW_API = [c for c in _NEW_API if c[2] is not None]


@pytest.mark.parametrize("entry, kw, words", _NEW_API, ids=[c[2][:40] for c in _NEW_API])
def test_new_entry_points_raise_the_named_error(entry, kw, words, scene):
    """37 such calls raised a TypeError, ValueError, AttributeError or IndexError (or
    returned a NaN yield); each now names the argument and its range, before any work."""
    kw = dict(kw)
    if entry == "transfer":
        call = lambda: rtsgeom.transfer(scene, **kw)  # noqa: E731
    elif entry == "drive_tolerance":
        target = kw.pop("scene", rtsgeom.load_scene(_X))
        call = lambda: rtsgeom.drive_tolerance(target, **kw)  # noqa: E731
    else:
        target = kw.pop("scene", rtsgeom.load_scene(_X))
        call = lambda: rtsgeom.Playback(**kw)(target)  # noqa: E731
    with pytest.raises(ParameterError) as info:
        call()
    assert words in str(info.value)


def test_transfer_caps_radars_times_set_points(scene):
    """The (B, P) results are held whole: radars x set-points beyond 2.01e7 are refused
    before any work (10**6 radars tried 21.5 GiB)."""
    from rtsgeom.analysis.transfer import MAX_RADAR_POINTS, TransferStudy
    study = TransferStudy(radars=100_000, points=201)
    assert study.set_points(1) == 201
    with pytest.raises(ParameterError, match="radar set-points"):
        study.set_points(2)
    assert MAX_RADAR_POINTS == 100_000 * 201


def test_minus_zero_spreads_read_as_zero(tmp_path, capsys):
    """--sigma-phase-deg -0 ended in numpy's "ValueError: scale < 0"."""
    assert main(["transfer", str(DEFAULT_SCENE), "--radars", "3", "--points", "3",
                 "--sigma-phase-deg", "-0", "--sigma-gain-db", "-0", "--json"]) == 0
    out = _finite_json(capsys.readouterr().out)
    assert out["sigma_phase_deg"] == 0.0 and math.copysign(1, out["sigma_phase_deg"]) == 1


def test_replace_takes_a_list_for_a_tuple_field():
    from rtsgeom.scene.channels import RadarChannelsConfig
    ch = rtsgeom.replace(RadarChannelsConfig(), rx_phase_deg=[0, 10, 0, 0])
    assert np.allclose(np.degrees(ch.rx_phase_rad), [0, 10, 0, 0])


def _channels_scene(tmp_path, text):
    return _with(DEFAULT_SCENE.read_text(), tmp_path, add="[radar.channels]\n" + text)


def test_transfer_names_the_channels_when_no_front_end_is_seen(tmp_path, capsys):
    """Every antenna at -20 dB: raw 'All-NaN slice' warnings, then an error naming no field."""
    p = _channels_scene(tmp_path, "tx_gain_db = [-20, -20, -20]\nrx_gain_db = [-20, -20, -20, -20]\n")
    assert main(["transfer", str(p), "--radars", "3", "--points", "3"]) == 2
    _clean_error(capsys.readouterr().err, "not detected", "radar.channels.tx_gain_db")


def test_reference_phase_of_a_radar_with_half_turn_antennas_is_wrapped():
    """rx_phase_deg = [0, 180, -180, 0] failed naming '<evolve>: front_ends[1].
    phase_offset_deg = 447.803', a field nobody wrote: the sweep's reference phase wraps."""
    from rtsgeom.calibration.steps import reference_setup
    setup = build_setup(rtsgeom.load_scene(DEFAULT_SCENE))
    for phase in (np.radians(447.803), -7.0, 100.0):
        ref = reference_setup(setup, 1, phase)
        got = ref.scene.rts.front_ends[1].phase_offset_rad
        assert -np.pi < got <= np.pi and np.isclose(np.exp(1j * got), np.exp(1j * phase))


def test_coupling_phase_without_coupling_is_refused(tmp_path, capsys):
    p = _channels_scene(tmp_path, "rx_coupling_phase_deg = 30\n")
    assert main(["info", str(p)]) == 2
    _clean_error(capsys.readouterr().err, "rx_coupling_phase_deg = 30", "rx_coupling_db")


def test_a_large_scene_file_is_named_by_its_own_size(tmp_path, capsys):
    p = tmp_path / "big.toml"
    p.write_bytes(b"# " + b"x" * (20 << 20))
    assert main(["info", str(p)]) == 2
    _clean_error(capsys.readouterr().err, f"({(20 << 20) + 2} bytes")


@pytest.mark.parametrize("kind", ["single", "vertical"])
def test_info_json_reachable_spans_null_without_azimuth_aperture(kind, tmp_path, capsys):
    """measured_angle_deg -90 and pair spans [-90, -90] were written instead of null."""
    p = _custom_array_scene(kind, tmp_path)
    assert main(["info", str(p), "--json"]) == 0
    info = _finite_json(capsys.readouterr().out)
    assert "reachable" not in info and "fewer than two" in info["reachable_unavailable"]


def test_nearest_without_air_path_compensation_finds_its_targets(tmp_path, capsys):
    """compensate_air_path = false with run --amplitudes nearest: every target 'lost', exit 0,
    the echoes R_c further out labelled unmatched with a wrong reason."""
    text = re.sub(r"^compensate_air_path = .*$", "compensate_air_path = false",
                  DEFAULT_SCENE.read_text(), flags=re.M)
    p = _with(text, tmp_path)
    assert main(["run", str(p), "--amplitudes", "nearest", "--out", str(tmp_path / "o"),
                 "--no-report"]) == 0
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert all(t["detection"] is not None and abs(t["error"]["range_m"]) < 0.05
               for t in summary["targets"])


def test_play_refuses_tolerance_flags_without_draws(tmp_path, capsys):
    for flags in (["--sigma-mm", "1", "1", "1"], ["--spec-deg", "0.2"]):
        assert main(["play", str(_X), "--out", str(tmp_path / "o"), *flags]) == 2
        _clean_error(capsys.readouterr().err, flags[0], "--tolerance-draws")
        assert not (tmp_path / "o").exists()


def test_a_drive_target_is_named_as_the_file_names_it(tmp_path):
    """A scenario azimuth outside every pair was reported as targets[N] with N shifted by the
    static [[targets]] (one static target: targets[1], not in the file)."""
    from rtsgeom.analysis.playback.frames import frame_target_names
    scene = rtsgeom.load_scene(_X)
    names = frame_target_names(scene, 3, static=1)
    assert names(0) == "frame 3: targets[0]" and names(1) == "frame 3: scenario.targets[0]"


def test_a_drive_beyond_the_target_frames_cap_is_refused(monkeypatch, capsys):
    """(Here with the cap lowered to 10: crossing.toml's 21 frames of one target.)"""
    import rtsgeom.scene.scenario as scenario
    monkeypatch.setattr(scenario, "MAX_TARGET_FRAMES", 10)
    assert main(["info", str(_X)]) == 2
    _clean_error(capsys.readouterr().err, "scenario.frame_period_s", "21 target-frames",
                 "at most 10")


def test_play_figure_of_many_targets_keeps_a_short_legend():
    """64 targets: a legend of 192 entries covering the figure, and matplotlib's warning."""
    import warnings
    from rtsgeom.viz.playback import LEGEND_TARGETS, playback_figure
    t = np.arange(5.0)
    s = np.tile(np.linspace(-5, 5, 64), (5, 1))
    d = s.copy()
    d[2, 3] = np.nan
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fig = playback_figure(t, s, {"exact": d}, {"exact": [1.0]})
    labels = [x.get_text() for x in fig.legends[0].get_texts()]
    assert len(labels) <= LEGEND_TARGETS and len(set(labels)) == len(labels)


def test_fuzzed_entry_points_keep_the_contract(capsys):
    """transfer, drive_tolerance, Playback and identify(radar_channels=True) with one hostile
    argument (or a mutated sidecar): a finite result or an RtsgeomError."""
    from benchmarks.fuzz_inputs import main as fuzz
    assert fuzz(["--inputs", "12", "--seed", "3", "--kind", "entry"]) == 0, \
        capsys.readouterr().out


@pytest.mark.parametrize("make, field", [
    (lambda: rtsgeom.CalibrationStudy(procedure="paper", full_chain=True), "full_chain"),
    (lambda: rtsgeom.LinearityStudy(pair="all", grid=3), "grid")])
def test_study_options_that_would_be_ignored_are_refused(make, field):
    """A combination a study would silently ignore is refused, naming the field."""
    with pytest.raises(ParameterError, match=field):
        make()


def test_an_arcs_inversion_refuses_one_axis(scene):
    study = rtsgeom.ToleranceStudy(rtsgeom.Bounds((1e-4,) * 3), pair="all", invert_yield=0.9,
                                   invert_axis="tangential", mc=rtsgeom.MonteCarlo(50, 1))
    with pytest.raises(ParameterError, match="invert_axis"):
        study(scene)


def test_radar_channels_refuse_captures_of_a_wider_arc_on_the_cli(tmp_path, capsys):
    """`rtsgeom adc` on a copy of the bundled scene with arc_radius_m = 1.2, identified
    against the 1 m scene with --radar-channels: accepted at residual 0.86 before (the antenna
    phases took the curvature); now exit 2 with one line naming the arc and the air path."""
    text = DEFAULT_SCENE.read_text()
    assert "arc_radius_m = 1.0 " in text
    wide = tmp_path / "wide.toml"
    wide.write_text(text.replace("arc_radius_m = 1.0 ", "arc_radius_m = 1.2 "))
    caps = []
    for q in (0, 1):
        caps.append(str(tmp_path / f"cap{q}.bin"))
        assert main(["adc", str(wide), "--active", str(q), "--out", caps[-1], "--quiet"]) == 0
    assert main(["identify", str(DEFAULT_SCENE), *caps, "--radar-channels", "--quiet"]) == 2
    _clean_error(capsys.readouterr().err, "rts.arc_radius_m = 1 m", "another arc",
                 "rts_delay_s")
