"""The 2-D pair sweep (``ncal._pair_probes``) computes channel i's single-channel reference
power once per probe (``ChannelModel.reference_power``) instead of once per step: exact only
because that power depends on channel 0 alone. Checked on a grid of pairs (elevation,
azimuth, diagonal), probe ranges, delays of channel j and front-end offsets."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.cell_calibration import sphere4


@pytest.mark.parametrize("field,value", [(None, None), ("radial_offset_mm", 0.5),
                                         ("phase_offset_deg", 90.0)])
def test_reference_power_does_not_move_with_the_other_channels_delay(field, value):
    from rtsgeom.paths import nominal_model
    from rtsgeom.calibration.probes import probe_ranges
    from rtsgeom.radar.steering import Steering
    from rtsgeom.synthesis.model import ChannelModel
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.scene import TargetConfig
    scene = sphere4() if field is None else sphere4(field, value)
    setup = build_setup(scene)
    nom, nom_paths = nominal_model(setup, exact_paths(setup))
    for pair in [(0, 1), (0, 2), (1, 2)]:
        for r in probe_ranges(setup, 2):
            st = Steering.auto(nom.rut, nom.scene.radar)
            sets = [ChannelModel.build(nom, nom_paths, pair, TargetConfig(float(r)), (0.0, d),
                                       steering=st)
                    for d in (0.0, 37e-12, -420e-12, 1.3e-9)]
            ref = sets[0].reference_power()
            assert ref > 0
            for cs in sets:
                assert cs.reference_power() == ref
                w = cs.weights([1.0, 0.6], [0.0, 0.4])
                u = cs.fe_directions().mean(axis=0)
                np.testing.assert_array_equal(cs.amplitudes(w, u, ref), cs.amplitudes(w, u))
