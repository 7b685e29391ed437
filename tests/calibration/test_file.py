"""A calibration file read back for a scene (load_calibration): each field checked against
the setup, every refusal in full words; the delay's range is the scene's calibration span and
a period either side, exactly at its edges."""

from __future__ import annotations

import math

import numpy as np
import pytest

from conftest import assert_refused
from rtsgeom.calibration.file import calibration_mismatch, load_calibration, setup_fingerprint
from rtsgeom.errors import SceneError
from rtsgeom.geometry import build_setup

W = "calibration file"


@pytest.fixture(scope="module")
def setup(default_scene):
    s = build_setup(default_scene)
    assert s.scene.rts.calibration_span_s == (-5e-10, 1e-9) and s.scene.rts.f_rts_hz == 5e8
    return s


def _doc(**changes):
    doc = {"pair": [0, 1], "delta_tau_s": 2e-12, "front_end_angles_deg": [4.0, 12.8],
           "gain_correction": [1.0, 1.0]}
    doc.update(changes)
    return {k: v for k, v in doc.items() if v is not None}


def test_a_file_that_fits_is_read_as_the_probe_and_the_pairs(setup):
    probe, cals = load_calibration(_doc(gain_correction=[0.1, 10.0]), setup)
    assert list(cals) == [(0, 1)] and cals[(0, 1)].delta_tau_s == 2e-12
    assert np.allclose(probe.angle_rad, np.radians([4.0, 12.8]), rtol=0, atol=1e-15)
    assert np.array_equal(probe.gain_correction, [0.1, 10.0])
    assert np.all(np.isnan(probe.power_db))  # not measured: read from a file
    two = _doc(pairs=[{"pair": [0, 1], "delta_tau_s": 1e-12}, {"pair": [1, 0],
                                                                "delta_tau_s": -1e-12}])
    assert sorted(load_calibration(two, setup)[1]) == [(0, 1), (1, 0)]
    assert np.array_equal(load_calibration(_doc(gain_correction=None), setup)[0]
                          .gain_correction, [1.0, 1.0])


@pytest.mark.parametrize("changes, message", [
    ({"pairs": []}, f"{W}: pairs = []: must be a list of pair calibrations"),
    ({"pairs": "x"}, f"{W}: pairs = 'x': must be a list of pair calibrations"),
    ({"front_end_angles_deg": None}, f"{W}: not an rtsgeom calibration ('front_end_angles_deg'): "
                                     "write one with `rtsgeom calibrate SCENE --out DIR`"),
    ({"front_end_angles_deg": "abc"}, f"{W}: not an rtsgeom calibration (could not convert "
                                      "string to float: 'abc'): write one with `rtsgeom "
                                      "calibrate SCENE --out DIR`"),
    ({"front_end_angles_deg": [1.0]}, f"{W}: front_end_angles_deg has 1 entries, "
                                      "gain_correction 2: the scene has 2 front ends (calibrated "
                                      "on another setup?)"),
    ({"gain_correction": [1.0, 1.0, 1.0]}, f"{W}: front_end_angles_deg has 2 entries, "
                                           "gain_correction 3: the scene has 2 front ends "
                                           "(calibrated on another setup?)"),
    ({"gain_correction": [1.0, 10.5]}, f"{W}: gain_correction[1] = 10.5: must be in [0.1, 10] "
                                       "(a front end's measured over modelled amplitude, +-20 "
                                       "dB)"),
    ({"gain_correction": [0.09, 1.0]}, f"{W}: gain_correction[0] = 0.09: must be in [0.1, 10] "
                                       "(a front end's measured over modelled amplitude, +-20 "
                                       "dB)"),
    ({"gain_correction": [1.0, math.nan]}, f"{W}: gain_correction[1] = nan: must be in [0.1, "
                                           "10] (a front end's measured over modelled "
                                           "amplitude, +-20 dB)"),
    ({"front_end_angles_deg": [1.0, math.inf]}, f"{W}: front_end_angles_deg: must be finite"),
    ({"pair": [0, 2]}, f"{W}: pair (0, 2): must be front-end indices in [0, 1]"),
    ({"pairs": [{"pair": [0, 1], "delta_tau_s": 1e-12}, {"pair": [0, 1, 2],
                                                         "delta_tau_s": 0.0}]},
     f"{W}: pairs[1].pair = [0, 1, 2]: must be a list (at least 2 and at most 2 entries) of "
     "integers in [0, 10000]")])
def test_a_file_that_does_not_fit_is_refused_naming_the_field(setup, changes, message):
    assert_refused(lambda: load_calibration(_doc(**changes), setup), message, SceneError)


@pytest.mark.parametrize("period, lo, hi", [(None, -2.5e-9, 3e-9), (1e-9, -1.5e-9, 2e-9),
                                            (0.25e-9, -0.75e-9, 1.25e-9)])
def test_the_delay_is_within_the_span_and_a_period_either_side(setup, period, lo, hi):
    """[span low - period, span high + period] (the period: the file's, else 1 / f_rts)."""
    extra = {} if period is None else {"period_s": period}
    for d in (lo, hi):
        assert load_calibration(_doc(delta_tau_s=d * (1 - 1e-12), **extra), setup)[1]
    for d in (lo - 0.05e-9, hi + 0.05e-9):
        assert_refused(lambda: load_calibration(_doc(delta_tau_s=d, **extra), setup),
                       f"{W}: pairs[0].delta_tau_s = {d:g} s: must be in [{lo * 1e9:.3f}, "
                       f"{hi * 1e9:.3f}] ns (the scene's calibration span, "
                       "rts.calibration_span_ns, and a period either side: what a sweep can "
                       "find)", SceneError)


def test_a_file_of_another_setup_is_said_to_be(default_scene):
    fp = setup_fingerprint(default_scene)
    assert calibration_mismatch({"setup_sha256": fp}, default_scene) is None
    assert calibration_mismatch({}, default_scene) is None
    assert calibration_mismatch({"setup_sha256": "0" * 64}, default_scene) == (
        "--calibration: the file was made on another setup (the arc, a front end's mounting or "
        "channel, the RuT or the RTS's delays differ from this scene's): applied as it is; run "
        "`rtsgeom calibrate` on this scene if the setup changed")
    # the scenario, seed and name are not the setup
    import dataclasses
    assert setup_fingerprint(dataclasses.replace(default_scene, seed=99, name="x",
                                                 targets=())) == fp
