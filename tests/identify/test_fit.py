"""check_fit's limits (an estimate beyond a mounting or channel tolerance is a capture that is
not this setup's), each enforced exactly at its edge with the whole message; the residual
limit; parameters that are not identifiable are not checked."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rtsgeom.errors import CaptureError
from rtsgeom.identify.fit import RESIDUAL_LIMIT, FrontEndFit, _fmt, check_fit

CHECK = ("check that the sidecar's active_front_end, probe_range_m, probe_amplitude and scale "
         "are the capture's and that the scene's arc and radar are the setup's; a radar with "
         "its own per-antenna phase errors needs --radar-channels")
DB = 20 / math.log(10)


def _fit(estimate=(0.0,) * 7, residual=1.0, reasons=(None,) * 7, index=2):
    return FrontEndFit(index, np.array(estimate, float), np.full(7, 0.1), tuple(reasons),
                       np.eye(7), residual, 1.0, 3)


def _at(i, v):
    e = [0.0] * 7
    e[i] = v
    return e


# (parameter, the limit in SI, the value just beyond it in SI, its name, the message's value,
# range and unit)
LIMITS = [(0, 50e-3, 50.5e-3, "radial_offset_mm", "50.5", "[-50, 50] mm"),
          (1, 50e-3, 50.5e-3, "tangential_offset_mm", "50.5", "[-50, 50] mm"),
          (2, 50e-3, 50.5e-3, "height_offset_mm", "50.5", "[-50, 50] mm"),
          (3, math.radians(30.0), math.radians(30.5), "yaw_offset_deg", "30.5", "[-30, 30] deg"),
          (4, 10e-9, 10.5e-9, "delay_offset_s", "1.05e-08", "[-1e-08, 1e-08] s"),
          (5, 40.0 / DB, 40.5 / DB, "gain_db", "40.5", "[-40, 40] dB")]


@pytest.mark.parametrize("i, limit, beyond, name, shown, allowed", LIMITS,
                         ids=[x[3] for x in LIMITS])
@pytest.mark.parametrize("sign", [1, -1])
def test_each_estimate_limit_is_enforced_at_its_edge(i, limit, beyond, name, shown, allowed,
                                                     sign):
    inside = np.nextafter(limit, 0.0) * sign  # the limit, rounded towards zero
    assert check_fit(_fit(_at(i, inside))).misfit is None
    with pytest.raises(CaptureError) as exc:
        check_fit(_fit(_at(i, sign * beyond)))
    value = shown if sign > 0 else "-" + shown
    assert str(exc.value) == (f"front end 2: estimated: {name} = {value}: must be in {allowed} "
                              f"(not a tolerance of this setup: {CHECK})")
    # a parameter that is not identifiable keeps the scene's value, unchecked
    why = [None] * 7
    why[i] = "not identifiable"
    assert check_fit(_fit(_at(i, sign * beyond), reasons=why)).misfit is None


def test_the_phase_has_no_limit():
    assert check_fit(_fit(_at(6, 100.0))).misfit is None


@pytest.mark.parametrize("accept", [False, True])
def test_the_residual_limit_raises_or_flags(accept):
    assert RESIDUAL_LIMIT == 3.0
    assert check_fit(_fit(residual=3.0), accept).misfit is None  # at the limit: fits
    why = (f"front end 2: residual_rms = 3.01 x noise: must be at most 3 for the estimates to be "
           f"the setup's (the model does not explain the captures; {CHECK})")
    if accept:
        assert check_fit(_fit(residual=3.01), True).misfit == why
    else:
        with pytest.raises(CaptureError) as exc:
            check_fit(_fit(residual=3.01))
        assert str(exc.value) == why
    for r in (math.nan, math.inf):
        with pytest.raises(CaptureError) as exc:
            check_fit(_fit(residual=r), accept)
        assert str(exc.value) == (f"front end 2: the fit did not converge to a finite residual: "
                                  f"{CHECK}")


def test_free_is_the_identifiable_parameters():
    why = [None, "x", None, None, "y", None, "z"]
    assert _fit(reasons=why).free == (0, 2, 3, 5)
    assert _fit().free == tuple(range(7))


@pytest.mark.parametrize("i, x, text", [(0, 1.5e-3, "1.5 mm"), (1, -2e-4, "-0.2 mm"),
                                        (2, 1e-2, "10 mm"), (3, math.radians(2.0), "2 deg"),
                                        (6, math.radians(-45.0), "-45 deg"),
                                        (4, 3.3e-12, "3.3 ps"), (5, 0.125, "0.125")])
def test_parameter_values_are_shown_in_their_units(i, x, text):
    assert _fmt(i, x) == text
