"""Targets sharing a range-Doppler cell: each hazard said in full words, at the edges of the
range and Doppler bins, of the radar's two-target resolution and of the front-end pairs; an
extended object's own scatterers not named."""

from __future__ import annotations

import dataclasses
import math
from types import SimpleNamespace

import numpy as np
import pytest

from conftest import ROOT
from rtsgeom.geometry import build_setup
from rtsgeom.pipeline.cells import shared_cell_warnings
from rtsgeom.radar.peaks import two_target_resolution
from rtsgeom.radar.steering import Steering
from rtsgeom.scene import load_scene


@pytest.fixture(scope="module")
def setup():
    scene = load_scene(ROOT / "scenes" / "crossing.toml")  # five front ends, four pairs
    return build_setup(dataclasses.replace(scene, scenario=None))


def _t(r, v, u, obj=-1):
    return SimpleNamespace(range_m=r, velocity_mps=v, angle_rad=math.asin(u), object_index=obj)


def _res(setup):
    return float(two_target_resolution(Steering.auto(setup.rut, setup.scene.radar))[0])


def test_targets_within_the_resolution_are_said_to_merge(setup):
    res = _res(setup)
    u0 = math.sin(setup.fe_azimuth_rad()[0]) + 0.2 * res
    sep = 0.5 * res
    got = shared_cell_warnings(setup, [_t(10.0, 1.0, u0), _t(10.0, 1.0, u0 + sep)], "frame 3")
    assert got == [f"frame 3[0] and frame 3[1] share a range-Doppler cell and lie {sep:.3f} "
                   f"apart in sin(az), within the radar's two-target resolution {res:.3f}: it "
                   "will see one target between them (status 'merged')"]


@pytest.mark.parametrize("dr, dv, shared", [(0.0, 0.0, True), (0.999, 0.0, True),
                                            (1.001, 0.0, False), (0.0, 0.999, True),
                                            (0.0, -1.001, False), (-0.999, -0.999, True)])
def test_a_cell_is_one_range_and_one_doppler_bin(setup, dr, dv, shared):
    """Within a bin in range and in Doppler: one cell; a bin apart in either: two."""
    radar = setup.scene.radar
    res = _res(setup)
    u0 = math.sin(setup.fe_azimuth_rad()[0]) + 0.2 * res
    t = [_t(10.0, 1.0, u0),
         _t(10.0 + dr * radar.range_resolution_m, 1.0 + dv * radar.velocity_resolution_mps,
            u0 + 0.5 * res)]
    assert len(shared_cell_warnings(setup, t)) == (1 if shared else 0)


def test_resolved_targets_on_different_pairs_are_warned_about_their_phase_patterns(setup):
    fe = setup.fe_azimuth_rad()
    res = _res(setup)
    a = 0.5 * (fe[0] + fe[1])
    b = 0.5 * (fe[3] + fe[4])
    assert abs(math.sin(b) - math.sin(a)) >= res
    t = [_t(20.0, 0.0, math.sin(a)), _t(20.0, 0.0, math.sin(b))]
    assert shared_cell_warnings(setup, t) == [
        "targets[0] and targets[1] share a range-Doppler cell on different front-end pairs "
        "(0, 1) and (3, 4): each carries its pair's near-field phase pattern, so the radar may "
        "see one broad peak where real targets give two (the truth twin shows what it would "
        "see; rtsgeom resolution)"]
    # the switched baseline plays each target on one front end: no phase pattern to mix
    nearest = dataclasses.replace(setup, scene=setup.scene.evolve(
        rts=setup.scene.rts.evolve(aoa_mode="nearest")))
    assert shared_cell_warnings(nearest, t) == []


def test_an_objects_own_scatterers_are_not_named_but_others_are(setup):
    res = _res(setup)
    u0 = math.sin(setup.fe_azimuth_rad()[0]) + 0.2 * res
    t = [_t(10.0, 0.0, u0, obj=0), _t(10.0, 0.0, u0 + 0.1 * res, obj=0),
         _t(10.0, 0.0, u0 + 0.2 * res, obj=1), _t(10.0, 0.0, u0 + 0.3 * res)]
    got = shared_cell_warnings(setup, t)
    names = [w.split(" share ")[0] for w in got]
    assert names == [
        "targets[0] (a scatterer of object 0) and targets[2] (a scatterer of object 1)",
        "targets[0] (a scatterer of object 0) and targets[3]",
        "targets[1] (a scatterer of object 0) and targets[2] (a scatterer of object 1)",
        "targets[1] (a scatterer of object 0) and targets[3]",
        "targets[2] (a scatterer of object 1) and targets[3]"]
    assert shared_cell_warnings(setup, t[:1]) == [] and shared_cell_warnings(setup, []) == []
    # targets without object_index (duck-typed) are plain targets
    plain = [SimpleNamespace(range_m=10.0, velocity_mps=0.0, angle_rad=math.asin(u0 + k * 0.1 *
                                                                              res))
             for k in range(2)]
    assert [w.split(" share ")[0] for w in shared_cell_warnings(setup, plain)] == [
        "targets[0] and targets[1]"]
    assert np.isfinite(res)
