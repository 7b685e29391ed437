"""Work beside the process (``_lib.parallel.fork_call``): the run's 3D view rendered while the
run simulates gives the report of the view rendered after it, byte for byte; a forked call
returns its value and raises its exception as the call itself; the maps' arrays without
xarray are the dataset's."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rtsgeom._lib.parallel import fork_call
from rtsgeom.pipeline.output import (map_arrays, map_dataset, maps_arrays, run_report_html,
                                     start_setup_view)
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


@pytest.fixture(scope="module")
def result():
    return run_scene(load_scene(SCENE), aoa_mode="nearest", truth=False)


def test_forked_view_gives_the_same_report(result):
    view = start_setup_view(result.scene)
    assert (run_report_html(result, {}, "exact", [], view)
            == run_report_html(result, {}, "exact", []))


def test_map_arrays_are_the_datasets(result):
    arrays = map_arrays(result)
    ds = map_dataset(result)
    assert list(arrays) == list(ds.coords) + list(ds.data_vars)
    for k, v in arrays.items():
        assert np.array_equal(v, ds[k].values)
    assert maps_arrays(arrays, ("npz", "mat")) == maps_arrays(ds, ("npz", "mat"))
