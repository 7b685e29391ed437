"""Tests of ``rtsgeom.analysis.resolution``: closed forms and invariants on grids of inputs."""

from __future__ import annotations

import pytest

from rtsgeom.analysis.resolution import ResolutionStudy
from rtsgeom.errors import ParameterError


@pytest.mark.parametrize("seps", [(0.0,), (5.0, 121.0), (-1.0,)])
def test_a_bad_separation_says_the_allowed_range(seps):
    with pytest.raises(ParameterError, match=r"separations in \(0, 120\] deg"):
        ResolutionStudy(separations_deg=seps)
