"""Work beside the process (``_lib.parallel.fork_call``): the run's 3D view rendered while the
run simulates gives the report of the view rendered after it, byte for byte; a forked call
returns its value and raises its exception as the call itself; the maps' arrays without
xarray are the dataset's."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from rtsgeom._lib.parallel import fork_call
from rtsgeom.pipeline.output import (_calibration_figures, map_arrays, map_dataset,
                                     maps_arrays, run_report_html, start_setup_view)
from rtsgeom.pipeline.run import run_scene
from rtsgeom.scene import load_scene

SCENE = Path(__file__).resolve().parents[2] / "scenes" / "diewald2022.toml"


def _fail(text):
    raise KeyError(text)


def test_fork_call_returns_and_raises_as_the_call():
    assert fork_call(pow, 3, 7).result() == 3 ** 7
    assert np.array_equal(fork_call(np.arange, 5).result(), np.arange(5))
    with pytest.raises(KeyError, match="nothing here"):
        fork_call(_fail, "nothing here").result()


def _late_bytes():
    time.sleep(0.3)
    return b"x" * (1 << 20)  # more than a pipe holds: sending waits for a reader


def test_a_forked_call_whose_parent_is_gone_ends():
    """A parent killed before collecting (SIGKILL of a run): the forked process's answer
    finds no reader and it ends, instead of waiting forever with its memory (it held the
    pipe's other end itself)."""
    forked = fork_call(_late_bytes)
    forked._conn.close()  # what the parent's death does to its end
    forked._proc.join(timeout=20)
    try:
        assert forked._proc.exitcode == 0
    finally:
        if forked._proc.exitcode is None:
            forked._proc.kill()
            forked._proc.join()


@pytest.fixture(scope="module")
def result():
    return run_scene(load_scene(SCENE), aoa_mode="nearest", truth=False)


def test_forked_view_gives_the_same_report(result):
    view = start_setup_view(result.scene)
    assert (run_report_html(result, {}, "exact", [], view)
            == run_report_html(result, {}, "exact", []))


def test_forked_calibration_figures_give_the_same_report():
    """The calibration's figures drawn in a process forked before the maps (write_run)."""
    result = run_scene(load_scene(SCENE), truth=False)  # exact amplitudes: calibrated
    here = run_report_html(result, {}, "exact", [])
    assert here.count('alt="Calibration"') == 1  # the one pair's sweep
    assert run_report_html(result, {}, "exact", [], None,
                           fork_call(_calibration_figures, result)) == here


def test_map_arrays_are_the_datasets(result):
    arrays = map_arrays(result)
    ds = map_dataset(result)
    assert list(arrays) == list(ds.coords) + list(ds.data_vars)
    for k, v in arrays.items():
        assert np.array_equal(v, ds[k].values)
    assert maps_arrays(arrays, ("npz", "mat")) == maps_arrays(ds, ("npz", "mat"))


@pytest.mark.subprocess
@pytest.mark.skipif(not Path("/proc/self/task").is_dir(), reason="needs Linux's /proc")
def test_the_range_doppler_ffts_start_no_thread_pool():
    """The commands fork (design and calibration pools, the report's 3D view); a thread pool
    of pocketfft's joins its threads in its pre-fork handler and hung a forked design in the
    test suite once. The chain's FFTs run on the calling thread: a fresh process has as many
    native threads after a frame's range-Doppler as before it."""
    code = """
import os, numpy as np
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.radar import process
from rtsgeom.radar.frame import simulate
from rtsgeom.rts.channels import program_nearest
from rtsgeom.scene import load_scene
scene = load_scene(%r)
setup = build_setup(scene)
paths = exact_paths(setup)
_, cube = simulate(setup, paths, program_nearest(scene, setup), 0)
before = len(os.listdir("/proc/self/task"))
process(cube)
print(before, len(os.listdir("/proc/self/task")))
""" % str(SCENE)
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1", OMP_NUM_THREADS="1",
               NUMBA_NUM_THREADS="1")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, env=env, cwd=SCENE.parents[1]).stdout.split()
    assert out[0] == out[1], out
