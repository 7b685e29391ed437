"""measure's checks of a capture against the scene, each refusal in full words: its shape,
active front end, TDM order, probe inside the radar's range and velocity, a real-only
capture's range, and the front end its probe's direction shows."""

from __future__ import annotations

import dataclasses

import pytest

from conftest import assert_refused, make_scene
from rtsgeom.errors import CaptureError
from rtsgeom.geometry import build_setup
from rtsgeom.identify.capture import simulate_capture
from rtsgeom.identify.model import measure


def _small(doc):
    doc["radar"].update(chirps_per_tx=32, samples_per_chirp=128, adc_rate_hz=12.5e6)


@pytest.fixture(scope="module")
def bench():
    setup = build_setup(make_scene(_small))
    return setup, simulate_capture(setup, 0, seed=1), simulate_capture(setup, 1, seed=2)


def _refused(setup, cap, message):
    assert_refused(lambda: measure(setup, cap), message, CaptureError)


def test_a_capture_of_another_shape_order_or_front_end_is_refused(bench):
    setup, cap, _ = bench
    y, sigma2, model = measure(setup, cap)
    assert y.shape == (setup.rut.num_virtual,) and sigma2 > 0 and model.active == 0
    _refused(setup, dataclasses.replace(cap, data=cap.data[:, :, :64]),
             "capture of front end 0: shape [32, 8, 64] does not match the scene's radar "
             "[32, 8, 128] [loop, virtual, sample]")
    for q in (2, -1):
        _refused(setup, dataclasses.replace(cap, active=q, source="a.npy"),
                 f"a.npy: active_front_end = {q}: must be a front end of the scene (0..1)")
    _refused(setup, dataclasses.replace(cap, tx_order=(2, 0), source="b.bin"),
             "b.bin: tx_order = [2, 0]: must be the scene's radar's [0, 2] (another TDM order "
             "puts other antennas in each virtual channel)")
    assert measure(setup, dataclasses.replace(cap, tx_order=(0, 2)))[0].shape == y.shape


def test_the_probe_must_be_inside_the_radars_range_and_velocity(bench):
    setup, cap, _ = bench
    radar = setup.scene.radar
    r, v = radar.max_range_m, radar.max_velocity_mps
    _refused(setup, dataclasses.replace(cap, range_m=r),
             f"capture: probe_range_m = {r:g}: must be below the scene's radar range {r:g} m")
    for s in (1, -1):
        _refused(setup, dataclasses.replace(cap, velocity_mps=s * v),
                 f"capture: probe_velocity_mps = {s * v:g}: must be within the scene's "
                 f"unambiguous +-{v:g} m/s")
    _refused(setup, dataclasses.replace(cap, adc="real", range_m=0.9 * r),
             f"capture: probe_range_m = {0.9 * r:g}: must be within a real-only capture's "
             f"unambiguous range, below {r / 2:.4g} m (beat frequencies up to half the ADC "
             "rate; above it the echo folds onto its mirror)")


def test_a_capture_showing_another_front_end_is_refused(bench):
    setup, _, cap1 = bench
    with pytest.raises(CaptureError) as exc:
        measure(setup, dataclasses.replace(cap1, active=0))
    got = str(exc.value)
    head = ("capture: active_front_end = 0: must be the front end the capture shows: its "
            "probe's direction matches front end 1 (|cos| 1.000), not 0 (|cos| ")
    assert got.startswith(head) and got.endswith(")")
    assert 0.0 <= float(got[len(head):-1]) < 0.98
    # without the direction check (the joint fit's), it is measured
    assert measure(setup, dataclasses.replace(cap1, active=0), False)[2].active == 0


def test_a_sidecar_putting_the_probe_elsewhere_names_where_the_echo_is(bench):
    """The strongest echo of the map, in metres and m/s (its bins times the range bin and
    the velocity bin), against the sidecar's bins."""
    import re
    setup, cap, _ = bench
    radar = setup.scene.radar
    wrong = dataclasses.replace(cap, range_m=2 * cap.range_m)
    with pytest.raises(CaptureError) as exc:
        measure(setup, wrong)
    msg = str(exc.value)
    m = re.fullmatch(
        rf"capture: probe_range_m = {2 * cap.range_m:g}, probe_velocity_mps = 0: must be where "
        r"the capture's strongest echo is, (\S+) m and (\S+) m/s \(range bin (\d+), Doppler bin "
        r"(\d+); the sidecar's probe is at bins (\d+), (\d+)\): the sidecar does not describe "
        r"this capture", msg)
    assert m, msg
    r, v, ri, di, rs, ds = float(m[1]), float(m[2]), int(m[3]), int(m[4]), int(m[5]), int(m[6])
    assert abs(r - cap.range_m) <= 1.5 * radar.range_resolution_m  # where the echo is
    assert r == pytest.approx(ri * radar.range_resolution_m, rel=1e-3)
    assert v == pytest.approx(0.0, abs=1e-9) and di == ds  # at rest: the probe's Doppler bin
    assert abs(rs * radar.range_resolution_m - 2 * cap.range_m) <= 1.5 * radar.range_resolution_m
