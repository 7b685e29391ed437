"""Shared fixtures: the bundled default scene, scene variants built from it, and the small
quiet scenes and setups the unit tests of several subpackages share."""

from __future__ import annotations

import copy
import os
import tomllib
from pathlib import Path

import pytest

# One BLAS thread per test process (unless the environment asks for more): the suite's
# products are small, and with one xdist worker per core a threaded BLAS only hands work
# between threads (the 2-D cells grid of tests/synthesis/test_nchannel.py: 10.6 -> 2.4 s of CPU on a
# loaded two-core machine). The results are the same bits (tests/calibration/test_calibration_threads.py
# sets its own limits); subprocesses (the CLI, the docs build) inherit the variables.
if not any(k in os.environ for k in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
                                     "OMP_NUM_THREADS")):
    os.environ.update(OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1")
    from threadpoolctl import threadpool_limits
    _BLAS_LIMIT = threadpool_limits(limits=1, user_api="blas")  # numpy may be loaded already

from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.scene import parse_scene

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_SCENE = ROOT / "scenes" / "diewald2022.toml"


def default_doc() -> dict:
    return tomllib.loads(DEFAULT_SCENE.read_text())


def make_scene(mutate=None, **radar_overrides):
    """The default scene, optionally changed by ``mutate(doc)`` (a dict edited in place)."""
    doc = copy.deepcopy(default_doc())
    doc["radar"].update(radar_overrides)
    if mutate is not None:
        mutate(doc)
    return parse_scene(doc, "test.toml")


@pytest.fixture(scope="session")
def default_scene():
    from rtsgeom.scene import load_scene
    return load_scene(DEFAULT_SCENE)


@pytest.fixture(scope="session")
def rt():
    """The Sionna RT adapter, or a skip naming why it cannot run here (the ray-tracing tests)."""
    from rtsgeom.paths import raytrace
    ok, msg = raytrace.preflight()
    if not ok:
        pytest.skip(f"Sionna RT unavailable: {msg}")
    return raytrace


# ---------------------------------------------------------------- shared scene mutations
# (used as ``make_scene(lambda d: quiet(d, ...))`` or inside a test's own ``mutate``)

SMALL = dict(chirps_per_tx=32, samples_per_chirp=128, adc_rate_hz=12.5e6)  # a small, fast cube


def no_ghosts(doc) -> None:
    """No cable ghosts: drop every front end's return losses."""
    for fe in doc["rts"]["front_ends"]:
        fe.pop("return_loss_fe_db", None)
        fe.pop("return_loss_be_db", None)


def quiet(doc, small=False, **radar) -> None:
    """No receiver noise and no ghosts (a clean channel for closed-form checks); the small cube
    (:data:`SMALL`) when ``small``; then the ``radar`` fields given."""
    doc["radar"].pop("snr_db", None)
    if small:
        doc["radar"].update(SMALL)
    doc["radar"].update(radar)
    no_ghosts(doc)


def far_field(doc) -> None:
    """The ideal far field: a 50 m arc, no sheet, no Rx/Tx separation, no ghosts."""
    doc["rts"]["arc_radius_m"] = 50.0
    doc["sheet"]["enabled"] = False
    for fe in doc["rts"]["front_ends"]:
        fe["rx_tx_separation_m"] = 0.0
    no_ghosts(doc)


class CoherenceShift:
    """The phasor model's coherence point of a nominal pair (0, 1) setup and its closed-form
    move for a radial offset dr of one front end: -(f_c + S t_mid - S tau) /
    (f_rts + S t_mid - S tau) * 2 dr / c0 for J (front end 1), the opposite way for I."""

    def __init__(self, nom, probe):
        from rtsgeom.calibration.probes import (air_phase_slope_hz, if_phase_slope_hz, probe_angles,
                                                probe_ranges, probe_total_delay)
        from rtsgeom.calibration.pair import pair_coherence
        from rtsgeom.paths import exact_paths
        self.alphas = probe_angles(*probe.angle_rad[[0, 1]])
        self.d0 = pair_coherence(nom, exact_paths(nom), (0, 1), alphas=self.alphas).continuous_s
        tau = probe_total_delay(nom, probe_ranges(nom, 2))
        self.ratio = air_phase_slope_hz(nom.scene, tau) / if_phase_slope_hz(nom.scene, tau)
        self.period = 1 / if_phase_slope_hz(nom.scene, tau)

    def predicted(self, fe: int, dr_mm: float) -> float:
        """The closed-form coherence point with front end ``fe`` moved radially by ``dr_mm``."""
        from scipy.constants import c
        sign = 1.0 if fe == 1 else -1.0
        return self.d0 - sign * self.ratio * 2 * dr_mm * 1e-3 / c

    def wrapped(self, delay_s: float, fe: int, dr_mm: float) -> float:
        """``delay_s`` minus the predicted point, wrapped into one period around 0."""
        p = self.period
        return (delay_s - self.predicted(fe, dr_mm) + p / 2) % p - p / 2


def two_front_end_pair(radius_m: float, spacing_deg: float = 8.0):
    """The default scene as the arc design's clean two-front-end variant (pair (0, 1) at
    ``radius_m`` and ``spacing_deg``, no mounting or channel errors) and its pair-study model
    (3 candidate bins): ``(scene, ChannelPhasors)``."""
    import math

    from rtsgeom.analysis.design import two_front_end_scene
    from rtsgeom.analysis.tolerance.phasors import ChannelPhasors
    from rtsgeom.geometry import build_setup
    scene, _, problem = two_front_end_scene(make_scene(), (0, 1), radius_m,
                                            math.radians(spacing_deg))
    assert problem is None, problem
    return scene, ChannelPhasors.build(build_setup(scene), (0, 1), 3)


#: one mounting, channel or RuT pose error per file key (``geometry.setup.FRONT_END_ERRORS``,
#: ``RUT_POSE_ERRORS``): (section, key, value); "fe" is the second front end
SETUP_ERRORS = [("fe", "radial_offset_mm", 0.3), ("fe", "tangential_offset_mm", -0.2),
                ("fe", "height_offset_mm", 0.25), ("fe", "yaw_offset_deg", 1.5),
                ("fe", "pitch_offset_deg", -1.0), ("fe", "gain_offset_db", 0.7),
                ("fe", "phase_offset_deg", 40.0), ("radar", "position_offset_mm", [0.4, -0.3, 0.2]),
                ("radar", "yaw_offset_deg", 0.5)]


def _error_keys() -> dict:
    """The file keys of ``geometry.setup.FRONT_END_ERRORS`` and ``RUT_POSE_ERRORS`` (the
    schema's names for them, as ``setup_errors`` reports them)."""
    from rtsgeom.geometry.setup import FRONT_END_ERRORS, RUT_POSE_ERRORS
    from rtsgeom.scene import FrontEndConfig, RadarConfig
    from rtsgeom.scene.schema import specs
    fe, radar = dict(specs(FrontEndConfig)), dict(specs(RadarConfig))
    return {"fe": tuple(fe[n].key for n in FRONT_END_ERRORS),
            "radar": tuple(radar[n].key for n in RUT_POSE_ERRORS)}


ERROR_KEYS = _error_keys()


def scenes_with_and_without_error(path: Path, section: str, key: str, value):
    """The scene at ``path`` without any of its own setup errors, and the same with one error
    (``SETUP_ERRORS``)."""
    doc = tomllib.loads(path.read_text())
    for fe in doc["rts"]["front_ends"]:
        for k in ERROR_KEYS["fe"]:
            fe.pop(k, None)
    for k in ERROR_KEYS["radar"]:
        doc["radar"].pop(k, None)
    moved = copy.deepcopy(doc)
    (moved["rts"]["front_ends"][1] if section == "fe" else moved["radar"])[key] = value
    return (parse_scene(doc, str(path), path.parent), parse_scene(moved, str(path), path.parent))


# Small quiet scenes and module-scoped setups shared by the unit tests of several subpackages


def small_noiseless(mutate=None):
    """A small noise-free scene: 32 chirps per Tx, 128 samples at 12.5 MHz."""
    def m(doc):
        doc["radar"].pop("snr_db", None)
        doc["radar"].update(chirps_per_tx=32, samples_per_chirp=128, adc_rate_hz=12.5e6)
        if mutate:
            mutate(doc)
    return make_scene(m)


def small_quiet(targets=None, **radar):
    def mutate(doc):
        quiet(doc, small=True, **radar)
        doc["targets"] = targets if targets is not None else [
            {"range_m": 30.0, "angle_deg": 7.0}, {"range_m": 45.0, "velocity_mps": 2.0,
                                                  "angle_deg": 10.0}]
    return make_scene(mutate)


@pytest.fixture(scope="module")
def small_setup():
    # 512 samples: the probes' 3 m spacing (probe_ranges) must clear the CA-CFAR ring of
    # 2 + 8 range bins; with 128 samples (0.6 m bins) it does not and one probe is masked
    scene = small_quiet(samples_per_chirp=512)
    setup = build_setup(scene)
    return setup, exact_paths(setup)


@pytest.fixture(scope="module")
def cal_setup():
    """Small quiet scene with a 3 dB gain error on front end 0 and a 0.3 mm radial error on
    front end 1, a coarse FIR (50 ps) and a short sweep (0 .. 1.2 ns in 200 ps steps)."""
    def mutate(doc):
        doc["radar"].pop("snr_db", None)
        doc["radar"]["chirps_per_tx"] = 32
        doc["rts"].update(calibration_span_ns=[0.0, 1.2], calibration_step_ps=200.0,
                          fractional_delay_step_s=50e-12)
        for fe in doc["rts"]["front_ends"]:
            fe.pop("return_loss_fe_db", None)
            fe.pop("return_loss_be_db", None)
        doc["rts"]["front_ends"][0]["gain_offset_db"] = 3.0
        doc["rts"]["front_ends"][1]["radial_offset_mm"] = 0.3
        doc["targets"] = []
    setup = build_setup(make_scene(mutate))
    return setup, exact_paths(setup)


@pytest.fixture(scope="module")
def calibrated(cal_setup):
    from rtsgeom.calibration.pair import calibrate_pair
    from rtsgeom.calibration.probes import probe_front_ends
    setup, paths = cal_setup
    probe = probe_front_ends(setup, paths)
    return probe, calibrate_pair(setup, paths, (0, 1), probe)



def assert_bounds(make, ok, bad, error=None):
    """A config's declared range, enforced exactly at its edges: ``make(value)`` accepts every
    value of ``ok`` (the bounds themselves) and refuses each ``(value, message)`` of ``bad``
    (just outside them) with ``error`` (default ``ParameterError``) whose text is ``message``,
    the whole of it (the field, the value and the allowed range)."""
    from rtsgeom.errors import ParameterError
    for v in ok:
        make(v)
    for v, message in bad:
        with pytest.raises(error or ParameterError) as exc:
            make(v)
        assert str(exc.value) == message, (v, str(exc.value))


#: the whole warning a Monte-Carlo study gives on a scene with front end 1 moved radially
#: (:func:`moved_front_end`): ``<study> `` and this
DRAWS_REPLACE_TEXT = (
    "draws mounting errors about the nominal setup; the scene's own errors "
    "(rts.front_ends[1].radial_offset_mm) are not its starting point: each draw replaces them. "
    "Their effect on the synthesized angle: `rtsgeom linearity SCENE --uncalibrated` (and "
    "without the flag, calibrated), in Python rtsgeom.linearity(scene, calibration=False)")


def moved_front_end(scene):
    """``scene`` with front end 1 moved 0.3 mm radially (an error of the scene's own)."""
    import rtsgeom
    fes = list(scene.rts.front_ends)
    fes[1] = rtsgeom.replace(fes[1], radial_offset_mm=0.3)
    return rtsgeom.replace(scene, rts=rtsgeom.replace(scene.rts, front_ends=tuple(fes)))


def the_warnings(call, category) -> list[str]:
    """The texts of the ``category`` warnings ``call()`` gives (each once)."""
    import warnings
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        call()
    return [str(w.message) for w in caught if issubclass(w.category, category)]


def assert_refused(call, message, error=None):
    """``call()`` raises ``error`` (default ``ParameterError``) whose whole text is
    ``message``."""
    from rtsgeom.errors import ParameterError
    with pytest.raises(error or ParameterError) as exc:
        call()
    assert str(exc.value) == message


@pytest.fixture(scope="session")
def sphere_scene():
    """scenes/sphere4.toml: four front ends on a sphere (a 2-D cell), an RuT with elevation."""
    from rtsgeom.scene import load_scene
    return load_scene(ROOT / "scenes" / "sphere4.toml")


@pytest.fixture(scope="session")
def crossing_bench():
    """scenes/crossing.toml's bench without its drive: five front ends on an arc."""
    import dataclasses
    from rtsgeom.scene import load_scene
    return dataclasses.replace(load_scene(ROOT / "scenes" / "crossing.toml"), scenario=None)


class CountedProgress:
    """A ``progress(label, done, total)`` callback that holds the study to its contract on
    every call: exactly three arguments (a missing total is a TypeError where it is told), a
    non-empty text label, integer counts with 0 <= done <= total and total >= 1, and, per
    label, counts that never go back. ``calls`` keeps what it was told."""

    def __init__(self):
        self.calls: list[tuple[str, int, int]] = []

    def __call__(self, label, done, total):
        assert isinstance(label, str) and label, label
        assert int(done) == done and int(total) == total, (label, done, total)
        assert 0 <= done <= total and total >= 1, (label, done, total)
        last = [c for c in self.calls if c[0] == label]
        assert not last or (done >= last[-1][1] or done == 0), (label, done, last[-1])
        self.calls.append((label, int(done), int(total)))

    def finished(self, label) -> bool:
        """Whether ``label`` was told its end (done == total)."""
        return any(c[0] == label and c[1] == c[2] for c in self.calls)
