"""The calibration sweep's phasor model (``calibration.phasor``): the probe models it keeps
between sweeps are those of the setup swept."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import make_scene

from rtsgeom.calibration import phasor
from rtsgeom.calibration.phasor import PairChannels, phasor_sweep
from rtsgeom.calibration.probes import probe_angles, probe_ranges
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.scene import TargetConfig

DELTAS = np.linspace(-40e-12, 40e-12, 5)


def _sweep(scene, pair=(0, 1), deltas=DELTAS, offsets=(0.0, 0.0), built=None):
    setup, paths = built or (build_setup(scene), None)
    paths = paths or exact_paths(setup)
    targets = [TargetConfig(float(r)) for r in probe_ranges(setup, 2)]
    alphas = probe_angles(*setup.fe.angle_rad[list(pair)])
    return phasor_sweep(setup, paths, (setup, paths), PairChannels(pair, offsets), targets,
                        alphas, deltas)


#: evolutions of the scene that change the probes' models: the radar's carrier, its array,
#: the arc's radius
CHANGES = [lambda s: s.evolve(radar=s.radar.evolve(f_c_hz=78e9)),
           lambda s: s.evolve(radar=s.radar.evolve(use_elevation_tx=True)),
           lambda s: s.evolve(rts=s.rts.evolve(arc_radius_m=1.3))]


@pytest.mark.parametrize("change", CHANGES, ids=["carrier", "array", "arc radius"])
def test_the_kept_probe_models_follow_an_evolved_scene(change, monkeypatch):
    """The sweep keeps its last probe models per setup and paths object (``_MODELS``); after
    ``Scene.evolve`` the sweep is the evolved scene's, as computed with nothing kept, and the
    scene before gets its own models back."""
    monkeypatch.setattr(phasor, "_MODELS", [])
    scene = make_scene()
    first = _sweep(scene)
    kept = list(phasor._MODELS)
    assert kept  # the cache is in use
    evolved = change(scene)
    after = _sweep(evolved)
    monkeypatch.setattr(phasor, "_MODELS", [])
    fresh = _sweep(evolved)
    np.testing.assert_array_equal(after.spectra, fresh.spectra)
    np.testing.assert_array_equal(after.amplitudes, fresh.amplitudes)
    assert not (after.spectra.shape == first.spectra.shape
                and np.allclose(after.spectra, first.spectra))
    monkeypatch.setattr(phasor, "_MODELS", kept)
    np.testing.assert_array_equal(_sweep(scene).spectra, first.spectra)


def test_the_kept_probe_models_are_those_of_the_pair_offsets_and_delays(monkeypatch):
    """On one setup, a sweep of another pair, other channel offsets or other delays is its
    own, as computed with nothing kept (the key holds each)."""
    monkeypatch.setattr(phasor, "_MODELS", [])
    scene = make_scene()
    setup = build_setup(scene)
    built = (setup, exact_paths(setup))
    _sweep(scene, built=built)
    for kw in ({"pair": (1, 0)}, {"offsets": (0.0, 30e-12)}, {"deltas": DELTAS + 7e-12}):
        got = _sweep(scene, built=built, **kw)
        kept = list(phasor._MODELS)
        monkeypatch.setattr(phasor, "_MODELS", [])
        np.testing.assert_array_equal(got.spectra, _sweep(scene, built=built, **kw).spectra)
        monkeypatch.setattr(phasor, "_MODELS", kept)
