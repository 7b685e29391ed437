"""The ``[raytrace]`` and ``sheet.material`` fields change what Sionna RT returns.

Skipped, like ``test_raytrace.py``, where Sionna RT or a usable LLVM backend is missing. One
solve of the default scene takes ~0.1 s once the kernels are compiled.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from conftest import make_scene
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.paths.table import RUT_TO_RUT

pytestmark = [pytest.mark.raytrace, pytest.mark.slow]  # ~20 s idle (Sionna solves)


@pytest.fixture(scope="module")
def setup():
    return build_setup(make_scene())


@pytest.fixture(scope="module")
def base(rt, setup):
    return rt.trace(setup)


def _trace(rt, setup, **changes):
    return rt.trace(setup, dataclasses.replace(setup.scene.raytrace, **changes))


def test_los_switch(rt, setup, base):
    """raytrace.los: without it no row has zero bounces; with it every element pair has one."""
    assert np.sum(base.paths.bounces == 0) == len(exact_paths(setup))
    off = _trace(rt, setup, los=False)
    assert len(off.paths) and not np.any(off.paths.bounces == 0)


@pytest.mark.parametrize("depth", [0, 1])
def test_max_depth_bounds_the_bounces(rt, setup, base, depth):
    """raytrace.max_depth: no path has more reflections than allowed (the default, 2, has
    double bounces between the sheet and the RuT board)."""
    assert base.paths.bounces.max() == 2
    res = _trace(rt, setup, max_depth=depth)
    assert res.paths.bounces.max() == depth


def test_specular_switch(rt, setup, base):
    """raytrace.specular_reflection: off (and no diffuse) leaves line of sight only."""
    assert np.any(base.paths.bounces > 0)
    res = _trace(rt, setup, specular_reflection=False)
    assert np.all(res.paths.bounces == 0)


def test_min_gain_drops_the_weaker_paths(rt, setup, base):
    """raytrace.min_gain_db: every reflected row is at least that strong, and the weaker
    rows of the default run are gone (line-of-sight rows are always kept)."""
    g_db = 20 * np.log10(np.abs(base.paths.gain))
    refl = base.paths.bounces > 0
    floor = float(np.median(g_db[refl]))
    res = _trace(rt, setup, min_gain_db=floor)
    r_refl = res.paths.bounces > 0
    assert np.all(20 * np.log10(np.abs(res.paths.gain[r_refl])) >= floor - 1e-9)
    assert 0 < r_refl.sum() < refl.sum()


def test_solver_receives_the_sampling_and_interaction_fields(rt, setup, monkeypatch):
    """raytrace.samples_per_src, diffuse_reflection, refraction: passed to the path solver as
    set (no closed form for a ray count or a diffuse field: the call is what is checked)."""
    mi, sionna_rt = rt.ensure_available()
    seen = {}
    real = sionna_rt.PathSolver

    class Spy(real):
        def __call__(self, *a, **kw):
            seen.update(kw)
            return super().__call__(*a, **kw)
    monkeypatch.setattr(sionna_rt, "PathSolver", Spy)
    _trace(rt, setup, samples_per_src=2000, diffuse_reflection=True, refraction=True,
           max_depth=1)
    assert seen["samples_per_src"] == 2000
    assert seen["diffuse_reflection"] is True and seen["refraction"] is True
    assert seen["max_depth"] == 1


def test_sheet_material_sets_the_reflection_loss(rt):
    """sheet.material: the sheet's single bounces of the RuT's own chirp are weaker off ITU
    concrete than off metal. The half-space closed form |(1 - sqrt(eps))/(1 + sqrt(eps))|^2 is
    -8.1 dB (eps_r = 5.24); Sionna's slab model of the material gives -5.2 dB here (measured,
    not derived), so the check is a band around it that excludes 0 dB (material ignored)."""
    out = {}
    for mat in ("itu_metal", "itu_concrete"):
        s = build_setup(make_scene(lambda d, m=mat: d["sheet"].update(material=m)))
        res = rt.trace(s, dataclasses.replace(s.scene.raytrace, max_depth=1))
        p = res.paths
        sel = (p.direction == RUT_TO_RUT) & (p.bounces == 1) & (res.objects[:, 0] == "sheet")
        out[mat] = np.median(np.abs(p.gain[sel]))
    ratio_db = 20 * np.log10(out["itu_concrete"] / out["itu_metal"])
    eps = 5.24
    half_space_db = 20 * np.log10(abs((1 - np.sqrt(eps)) / (1 + np.sqrt(eps))))
    assert half_space_db - 1.0 < ratio_db < -3.0
