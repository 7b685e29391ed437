"""The calibration's bits do not depend on how many threads BLAS may use (``calibrate_pair``
and ``probe_front_ends`` run BLAS on one thread: its small products are faster so, and a
multi-threaded BLAS splits products differently, which moved the sweep's errors in their
15th digit), on the default scene and on one with mounting, gain and phase errors."""

from __future__ import annotations

import pytest
from threadpoolctl import threadpool_limits

from rtsgeom.calibration.pair import calibrate_pair
from rtsgeom.calibration.probes import probe_front_ends
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.scene import load_scene

OFFSETS = dict(radial_offset_m=0.8e-3, tangential_offset_m=-0.5e-3, height_offset_m=0.3e-3,
               gain_offset_db=0.6)


@pytest.mark.parametrize("offsets", [False, True])
def test_calibration_is_the_same_whatever_the_blas_threads(offsets):
    scene = load_scene("scenes/diewald2022.toml")
    if offsets:
        fes = list(scene.rts.front_ends)
        fes[1] = fes[1].evolve(**OFFSETS)
        scene = scene.evolve(rts=scene.rts.evolve(front_ends=tuple(fes)))
    setup = build_setup(scene)
    paths = exact_paths(setup)
    runs = []
    for threads in (1, 2):
        with threadpool_limits(threads, user_api="blas"):
            probe = probe_front_ends(setup, paths, scene.seed)
            runs.append(calibrate_pair(setup, paths, (0, 1), probe, seed=scene.seed).to_dict())
    assert runs[0] == runs[1]
