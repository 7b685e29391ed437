"""The public Python API: lazy names, __all__, result conversion to pandas/xarray."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import rtsgeom

SCENE = "scenes/diewald2022.toml"


def test_all_names_resolve():
    for name in rtsgeom.__all__:
        assert getattr(rtsgeom, name) is not None, name
    with pytest.raises(AttributeError):
        rtsgeom.no_such_name  # noqa: B018


@pytest.mark.subprocess
def test_import_is_lazy():
    """``import rtsgeom`` loads neither Sionna, pyvista, matplotlib nor the pipeline."""
    code = ("import sys, rtsgeom; heavy = [m for m in ('sionna', 'pyvista', 'matplotlib', "
            "'mitsuba', 'drjit', 'pandas', 'xarray', 'rtsgeom.pipeline.run') if m in sys.modules]; "
            "print(heavy)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.strip()
    assert out == "[]"


@pytest.fixture(scope="module")
def result():
    return rtsgeom.run_scene(rtsgeom.load_scene(SCENE))


def test_detections_dataframe(result):
    import pandas as pd
    df = result.detections.to_dataframe()
    assert isinstance(df, pd.DataFrame)
    assert len(df) == len(result.detections)
    np.testing.assert_array_equal(df["range_m"].to_numpy(), result.detections.range_m)
    np.testing.assert_array_equal(df["angle_deg"].to_numpy(), result.detections.angle_deg)


def test_range_doppler_xarray(result):
    import xarray as xr
    rd = result.rd
    da = rd.to_xarray()
    assert isinstance(da, xr.DataArray)
    assert da.dims == ("range_m", "velocity_mps")
    np.testing.assert_array_equal(da["range_m"].to_numpy(), rd.range_m)
    np.testing.assert_array_equal(da["velocity_mps"].to_numpy(), rd.velocity_mps)
    # every target's set-point lies at the map's peak near it (labelled selection works)
    for t in result.scene.targets:
        near = da.sel(range_m=slice(t.range_m - 0.5, t.range_m + 0.5),
                      velocity_mps=slice(t.velocity_mps - 0.5, t.velocity_mps + 0.5))
        peak = near.where(near == near.max(), drop=True)
        assert abs(float(peak["range_m"][0]) - t.range_m) <= 1.01 * (rd.range_m[1] - rd.range_m[0])
        assert abs(float(peak["velocity_mps"][0]) - t.velocity_mps) <= 1.01 * (
            rd.velocity_mps[1] - rd.velocity_mps[0])


def test_cube_and_range_angle_xarray(result):
    cube = result.cube.to_xarray()
    assert cube.dims == ("chirp_loop", "virtual_channel", "sample")
    assert cube.shape == result.cube.shape
    n_rx = result.setup.rut.num_rx
    np.testing.assert_array_equal(cube["tx_slot"] * n_rx + cube["rx"], cube["virtual_channel"])
    ra = result.rd.range_angle_to_xarray(result.cube, np.arange(-20, 20.01, 0.5))
    assert ra.dims == ("range_m", "angle_deg")
    # each target's range bin peaks near its set angle (within 2 grid steps)
    for m in result.matches:
        if m["detection"] is None:
            continue
        row = ra.sel(range_m=m["detection"]["range_m"], method="nearest")
        assert abs(float(row.idxmax()) - m["set"]["angle_deg"]) <= 1.0


def test_bad_pair_names_field():
    s = rtsgeom.load_scene(SCENE)
    with pytest.raises(ValueError, match="pair"):
        rtsgeom.calibrate(s, pair=(0, 5))


def test_raytrace_kernel_cache_is_outside_the_checkout(monkeypatch, tmp_path):
    """Dr.Jit's kernel cache lies outside the checkout (it used to be <repo>/.drjit_cache)."""
    from pathlib import Path

    from rtsgeom.paths import raytrace
    repo = Path(rtsgeom.__file__).resolve().parents[1]
    monkeypatch.delenv("RTSGEOM_CACHE_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert raytrace._default_cache_dir() == tmp_path / "xdg" / "rtsgeom" / "drjit"
    monkeypatch.delenv("XDG_CACHE_HOME")
    default = raytrace._default_cache_dir()
    assert default == Path.home() / ".cache" / "rtsgeom" / "drjit"
    assert repo not in default.parents
    monkeypatch.setenv("RTSGEOM_CACHE_DIR", str(tmp_path / "mine"))
    assert raytrace._default_cache_dir() == tmp_path / "mine" / "drjit"


# -- the functions that call into the physics packages forward every argument unchanged ------

def test_the_api_forwards_its_arguments_to_the_studies(monkeypatch, default_scene):
    """A spy in place of each study: what it is built and called with, argument by argument."""
    import rtsgeom.api as api
    from rtsgeom.analysis.tolerance import Bounds, MonteCarlo
    seen = {}

    class Spy:
        def __init__(self, *args, **kw):
            seen["init"] = (args, kw)

        def __call__(self, *args):
            seen["call"] = args
            return type("R", (), {"run": "ran"})()

    monkeypatch.setattr(api, "ToleranceStudy", Spy)
    assert api.tolerance(default_scene, [1, 0], (0.2, 0.3, 0.4), 17, 9, "uniform", 0.25,
                         5) == "ran"
    assert seen["init"] == ((Bounds((0.2e-3, 0.3e-3, 0.4e-3)), (1, 0)), {
        "mc": MonteCarlo(17, 9, "uniform"), "spec_deg": 0.25, "points": 5})
    assert seen["call"] == (default_scene,)
    monkeypatch.setattr(api, "TransferStudy", Spy)
    api.transfer(default_scene, 3, 2.5, 0.5, 4, 0.3, 11)
    assert seen["init"] == ((), {"radars": 3, "sigma_phase_deg": 2.5, "sigma_gain_db": 0.5,
                                 "points": 4, "spec_deg": 0.3, "seed": 11})
    api.transfer(default_scene)
    assert seen["init"][1] == {"radars": 100, "sigma_phase_deg": 5.0, "sigma_gain_db": 0.0,
                               "points": 11, "spec_deg": None, "seed": default_scene.seed}
    monkeypatch.setattr(api, "_nearfield", lambda *a: seen.setdefault("nf", a))
    api.nearfield(default_scene, (1.0, 2.0), 7)
    assert seen["nf"] == (default_scene, (1.0, 2.0), 7)
    monkeypatch.setattr(api, "ghost_analysis", lambda *a: seen.setdefault("gh", a))
    api.ghosts(default_scene, -60.0, True)
    assert seen["gh"] == (default_scene, -60.0, True)
