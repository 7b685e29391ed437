"""What keeps a calibration of many pairs cheap gives the same calibrations: the sweep's
reference built from the nominal models (channel J turned by its phase) equals the one built
on its own setup, the models reused only for the very same inputs, and the pairs of an arc
calibrated side by side (``CalibrationStudy(workers=N)``) give the report of one process."""

from __future__ import annotations

import numpy as np
import pytest
from calibration.test_dense_arc import TEMPLATE, dense_arc

import rtsgeom
from rtsgeom.calibration import phasor
from rtsgeom.calibration.pair import pair_probes
from rtsgeom.calibration.steps import reference_setup
from rtsgeom.errors import ParameterError
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.scene import load_scene


@pytest.mark.parametrize("phase_deg", [0.0, 37.0, -150.0, 180.0])
@pytest.mark.parametrize("pair", [(0, 1), (3, 4)])
def test_reference_models_turned_equal_models_built(phase_deg, pair):
    """The reference sweep (nominal setup, channel J at a hardware phase) from the nominal
    models turned by e^{-j phase} equals the sweep built on the reference setup itself: its
    spectra, designs and bins, over a grid of phases and pairs."""
    setup = build_setup(dense_arc(6, 2.0))
    paths = exact_paths(setup)
    probes = pair_probes(setup, paths, pair)
    deltas = np.arange(-20, 21) * 5e-12
    ref = probes.reference(np.radians(phase_deg))
    phasor._MODELS.clear()
    fast = ref.sweep(deltas)
    phasor._MODELS.clear()
    built = phasor.phasor_sweep(reference_setup(probes.nominal[0], pair[1],
                                                np.radians(phase_deg)),
                                probes.nominal[1], probes.nominal,
                                phasor.PairChannels(pair, probes.base_offsets,
                                                    probes.gain_correction),
                                probes.targets, probes.alphas, deltas)
    scale = np.max(np.abs(built.spectra))
    assert np.max(np.abs(fast.spectra - built.spectra)) < 1e-12 * scale
    assert np.array_equal(fast.bin_index, built.bin_index)
    assert np.allclose(fast.amplitudes, built.amplitudes, rtol=1e-12, atol=0)


def test_models_reused_only_for_the_same_inputs():
    """A second sweep of the same probes and delays reuses the models (the same objects);
    other delays, another pair or other probes build their own."""
    setup = build_setup(dense_arc(4, 2.0))
    paths = exact_paths(setup)
    probes = pair_probes(setup, paths, (0, 1))
    t = probes.targets
    d = np.arange(-3, 4) * 5e-12
    phasor._MODELS.clear()
    a = phasor._models(setup, paths, (0, 1), t, (0.0, 0.0), d)
    assert phasor._models(setup, paths, (0, 1), t, (0.0, 0.0), d.copy()) is a
    for other in [((0, 1), t, (0.0, 0.0), d + 1e-12), ((1, 2), t, (0.0, 0.0), d),
                  ((0, 1), t[::-1], (0.0, 0.0), d), ((0, 1), t, (1e-12, 0.0), d)]:
        assert phasor._models(setup, paths, *other) is not a
    assert phasor._models(build_setup(dense_arc(4, 2.0)), paths, (0, 1), t, (0.0, 0.0),
                          d) is not a


def test_pairs_side_by_side_give_the_report_of_one_process():
    """The template's four pairs (noise on) in two processes: the calibration file of one
    process, byte for byte; the count of pairs is told to a counting ``steps``."""
    scene = load_scene(TEMPLATE)
    one = rtsgeom.CalibrationStudy(pair="all", workers=1)(scene).to_dict()
    counts = []

    class Steps:
        def __call__(self, label):
            pass

        def count(self, stage, done, total):
            counts.append((stage, done, total))
    two = rtsgeom.CalibrationStudy(pair="all", workers=2, steps=Steps())(scene).to_dict()
    assert one == two
    assert counts and counts[-1] == ("pairs calibrated", 4, 4)


@pytest.mark.parametrize("bad", [0, 1025, 2.5, "2"])
def test_workers_out_of_range_refused(bad):
    with pytest.raises(ParameterError, match="workers"):
        rtsgeom.CalibrationStudy(pair="all", workers=bad)


# -- the config: each declared range and choice enforced exactly, in full words --

def test_calibration_study_enforces_its_ranges_and_choices():
    from conftest import assert_bounds
    from rtsgeom.analysis.calibration_study import CalibrationStudy
    assert_bounds(lambda v: CalibrationStudy(workers=v), [None, 1, 1024],
                  [(0, "CalibrationStudy: workers = 0: must be in [1, 1024]"),
                   (1025, "CalibrationStudy: workers = 1025: must be in [1, 1024]"),
                   (2.0, "CalibrationStudy: workers = 2.0: must be an integer in [1, 1024]")])
    assert_bounds(lambda v: CalibrationStudy(procedure=v), ["exact", "paper"],
                  [("Exact", "CalibrationStudy: procedure = 'Exact': must be one of exact, "
                             "paper")])
    assert_bounds(lambda v: CalibrationStudy(procedure="paper", full_chain=v), [False],
                  [(True, "CalibrationStudy: full_chain: must be false with procedure 'paper' "
                          "(the paper's sweep runs the full chain already)")])
    CalibrationStudy(procedure="exact", full_chain=True)
    d = CalibrationStudy()
    assert (d.pair, d.procedure, d.full_chain, d.fir, d.steps, d.workers) == (
        (0, 1), "exact", False, None, None, None)


def test_the_papers_procedure_is_refused_on_cells(sphere_scene):
    from conftest import assert_refused
    from rtsgeom.analysis.calibration_study import CalibrationStudy
    assert_refused(lambda: CalibrationStudy(procedure="paper")(sphere_scene),
                   "procedure paper: the paper's sweep is a pair on an arc (one set angle in "
                   "azimuth); this scene's front ends form 2-D cells")
