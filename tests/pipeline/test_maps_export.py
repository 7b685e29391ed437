"""``rtsgeom run --out DIR --maps npz,mat,nc`` saves the maps as arrays: maps.npz, maps.mat,
maps.nc (only maps.npz without ``--maps``).

The files are read back with the readers a user would use (numpy, scipy.io.loadmat, xarray's
scipy engine) and compared with maps computed here from the in-memory run result, independently
of the writer (``power_db`` and :func:`range_angle_map` directly)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rtsgeom.cli import main

from conftest import DEFAULT_SCENE


@pytest.fixture(scope="module")
def run_out(tmp_path_factory):
    """One ``rtsgeom run`` of the default scene (nearest amplitudes: the fast simulation,
    injected like tests/cli/test_reliability.py's ``fast_run``) and its in-memory result."""
    import rtsgeom.cli.run as run
    from rtsgeom.pipeline.run import run_scene
    from rtsgeom.scene import load_scene
    result = run_scene(load_scene(DEFAULT_SCENE), "exact", "nearest")
    out = tmp_path_factory.mktemp("maps") / "out"
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(run, "run_scene", lambda *a, **k: result)
        assert main(["run", str(DEFAULT_SCENE), "--out", str(out), "--quiet",
                     "--no-report", "--maps", "npz,mat,nc"]) == 0
    return out, result


def expected(result):
    """The maps straight from the processing stage, in dB, on the documented axes."""
    from rtsgeom.radar.processing import range_angle_map
    rd = result.rd
    angle_deg = np.arange(-60.0, 60.0 + 1e-9, 0.25)
    ra = range_angle_map(rd, result.cube, np.radians(angle_deg))
    return {"range_m": rd.range_m, "velocity_mps": rd.velocity_mps, "doppler_hz": rd.doppler_hz,
            "angle_deg": angle_deg, "range_doppler_db": rd.power_db,
            "range_angle_db": 10 * np.log10(np.maximum(ra, 1e-30))}


UNITS = {"range_m": "m", "velocity_mps": "m/s", "doppler_hz": "Hz", "angle_deg": "deg",
         "range_doppler_db": "dB", "range_angle_db": "dB"}


def check(arrays, result):
    exp = expected(result)
    nr, nd = result.rd.power.shape
    assert exp["range_doppler_db"].shape == (nr, nd)
    assert arrays["range_doppler_db"].shape == (nr, nd)
    assert arrays["range_angle_db"].shape == (nr, exp["angle_deg"].size)
    for name, want in exp.items():
        got = np.asarray(arrays[name])
        assert got.shape == want.shape, name
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-9, err_msg=name)
    # the maps are not blank: the strongest range-Doppler cell is a target's
    i, _ = np.unravel_index(np.argmax(arrays["range_doppler_db"]), (nr, nd))
    assert min(abs(arrays["range_m"][i] - t.range_m) for t in result.scene.targets) < 0.5


def test_npz(run_out):
    out, result = run_out
    with np.load(out / "maps.npz", allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    check(arrays, result)
    assert json.loads(str(arrays["units"])) == UNITS


def test_mat(run_out):
    import scipy.io
    out, result = run_out
    m = scipy.io.loadmat(out / "maps.mat", squeeze_me=True, struct_as_record=False)
    for name in UNITS:  # MATLAB-safe names: a letter first, then letters, digits, underscores
        assert name[0].isalpha() and name.replace("_", "").isalnum() and len(name) <= 63
    raw = scipy.io.loadmat(out / "maps.mat")
    for axis in ("range_m", "velocity_mps", "doppler_hz", "angle_deg"):
        assert raw[axis].shape == (raw[axis].size, 1), axis  # a column vector
    check(m, result)
    assert {k: getattr(m["units"], k) for k in UNITS} == UNITS


def test_netcdf(run_out):
    import xarray as xr
    out, result = run_out
    with xr.open_dataset(out / "maps.nc", engine="scipy") as ds:
        ds = ds.load()
    assert ds.range_doppler_db.dims == ("range_m", "velocity_mps")
    assert ds.range_angle_db.dims == ("range_m", "angle_deg")
    assert ds.doppler_hz.dims == ("velocity_mps",)
    check({k: ds[k].values for k in UNITS}, result)
    assert {k: ds[k].attrs["units"] for k in UNITS} == UNITS


def test_other_outputs_unchanged(run_out):
    """detections.csv / summary.json keep their contract; the PNGs are still written."""
    from rtsgeom.pipeline.output import detections_csv
    from rtsgeom.pipeline.run import summary
    out, result = run_out
    assert (out / "detections.csv").read_text() == detections_csv(result)
    assert json.loads((out / "summary.json").read_text()) == json.loads(
        json.dumps(summary(result, "exact")))
    for name in ("range_doppler.png", "range_angle.png"):
        assert (out / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_the_map_files_do_not_depend_on_when_they_were_written(run_out, monkeypatch):
    """Two writes of one result are byte-identical in every map file: the MAT-file's header
    text carries no creation time (scipy writes ``time.asctime()`` there)."""
    import time
    from rtsgeom.pipeline.output import map_dataset, maps_arrays
    _, result = run_out
    ds = map_dataset(result)
    first = maps_arrays(ds)
    monkeypatch.setattr(time, "asctime", lambda *a: "Thu Jan  1 00:00:00 2099")
    assert maps_arrays(ds) == first
    assert first["maps.mat"].startswith(b"MATLAB 5.0 MAT-file")


def test_run_writes_only_the_maps_formats_asked_for(tmp_path):
    """npz alone by default (each format costs its writing time), ``--maps`` chooses; an
    unknown format is refused naming the allowed ones."""
    import rtsgeom.cli.run as run
    from rtsgeom.pipeline.run import run_scene
    from rtsgeom.scene import load_scene
    result = run_scene(load_scene(DEFAULT_SCENE), "exact", "nearest")
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(run, "run_scene", lambda *a, **k: result)
        for args, want in (([], {"maps.npz"}), (["--maps", "mat"], {"maps.mat"}),
                           (["--maps", "nc,npz"], {"maps.nc", "maps.npz"})):
            out = tmp_path / "-".join(args or ["default"])
            assert main(["run", str(DEFAULT_SCENE), "--out", str(out), "--quiet",
                         "--no-report", *args]) == 0
            assert {p.name for p in out.glob("maps.*")} == want, args
    with pytest.raises(SystemExit) as exc:
        main(["run", str(DEFAULT_SCENE), "--out", str(tmp_path / "x"), "--maps", "csv"])
    assert exc.value.code == 2
