"""measure's checks of a capture against the scene, each refusal in full words: its shape,
active front end, TDM order, probe inside the radar's range and velocity, a real-only
capture's range, and the front end its probe's direction shows."""

from __future__ import annotations

import dataclasses

import pytest

import numpy as np
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


def _bins(radar):
    """The range bin (m) and velocity bin (m/s) of the scene's radar, from its chirp."""
    from scipy.constants import c
    r_bin = c * radar.adc_rate_hz / (2 * radar.slope_hz_per_s * radar.samples_per_chirp)
    v_bin = c / (2 * radar.f_c_hz * radar.tdm_cycle_s * radar.chirps_per_tx)
    return r_bin, v_bin


def _offsets(setup, cap, recorded_delay=False):
    """(range, Doppler) offset in bins of the capture's echo from the sidecar's probe, read
    on the capture's own range-Doppler map as ``measure`` reads it (its primitives)."""
    from rtsgeom.identify.model import ProbeModel, probe_offset_bins
    from rtsgeom.radar.fmcw import AdcCube
    from rtsgeom.radar.processing import range_doppler
    scale = float(np.max(np.abs(cap.data)))
    rd = range_doppler(AdcCube((cap.data / scale).astype(np.complex64), setup.scene.radar,
                               setup.rut))
    model = ProbeModel.of(setup, cap)
    if not recorded_delay:
        model = dataclasses.replace(model, rts_delay_s=None)
    return probe_offset_bins(rd.power, model)


_RANGE_TAIL = (", or a radial or channel delay offset larger than that moves the echo")


@pytest.mark.parametrize("field, axis, shift, inside", [
    ("range_m", 0, 0.5, 0.1), ("range_m", 0, -0.4, 0.1),
    ("velocity_mps", 1, 0.3, 0.01), ("velocity_mps", 1, -0.3, 0.01)])
def test_a_sidecar_probe_off_by_part_of_a_bin_is_refused_whole(bench, field, axis, shift,
                                                               inside):
    """The sidecar's probe range (velocity) ``shift`` range (Doppler) bins off the echo:
    refused with the echo's position (the sidecar's plus the offset it read, which is about
    -shift) in the whole message (the Doppler's without the range's 'or ...' tail); an
    offset of ``inside`` bin (inside ``SUBBIN_LIMIT``) is measured."""
    from rtsgeom.identify.model import SUBBIN_LIMIT
    assert SUBBIN_LIMIT == {"range": 0.25, "doppler": 0.05}
    setup, cap, _ = bench
    size = _bins(setup.scene.radar)[axis]
    base = cap.range_m if axis == 0 else 0.0
    measure(setup, dataclasses.replace(cap, **{field: base + inside * size}))
    have = base + shift * size
    moved = dataclasses.replace(cap, **{field: have})
    with pytest.raises(CaptureError) as exc:
        measure(setup, moved)
    off = _offsets(setup, moved)[axis]
    assert off == pytest.approx(-shift, abs=0.06)
    unit, limit, name = (("m", 0.25, "probe_range_m") if axis == 0 else
                         ("m/s", 0.05, "probe_velocity_mps"))
    assert str(exc.value) == (
        f"capture: {name} = {have:g}: must be where the capture's echo is, "
        f"{have + off * size:.5g} {unit} ({off:+.2f} bins of {size:.4g} {unit} away, at most "
        f"{limit:g} bin on the nominal setup): the sidecar does not describe this capture"
        + (_RANGE_TAIL if axis == 0 else ""))


def test_a_recorded_rts_delay_that_the_scene_s_air_path_misses_is_refused_whole(bench):
    """The sidecar's programmed RTS delay half a range bin (two-way) longer than the
    capture's: the echo against that delay plus the scene's air path is refused, the message
    built from the model's air path and the RTS's realised delay."""
    from scipy.constants import c
    from rtsgeom.identify.model import ProbeModel
    from rtsgeom.rts.channels import requested_delay
    from rtsgeom.rts.fir import realised_delay
    setup, cap, _ = bench
    scene, rts = setup.scene, setup.scene.rts
    r_bin, _ = _bins(scene.radar)
    wrong = dataclasses.replace(cap, rts_delay_s=cap.rts_delay_s + 2 * 0.5 * r_bin / c)
    with pytest.raises(CaptureError) as exc:
        measure(setup, wrong)
    msg = str(exc.value)
    dr = _offsets(setup, wrong, recorded_delay=True)[0]
    assert dr == pytest.approx(-0.5, abs=0.06)
    model = ProbeModel.of(setup, wrong)
    air = float(model.echoes(model.nominal()[None]).tau_air_s.mean()) * c
    tau0 = float(realised_delay(wrong.rts_delay_s, rts.f_s_hz, rts.fractional_delay,
                                rts.fractional_delay_step_s))
    want = c / 2 * (tau0 + air / c)
    own = float(requested_delay(scene, cap.range_m)) * 1e9
    assert own == pytest.approx(cap.rts_delay_s * 1e9, rel=1e-12)
    assert msg == (
        f"capture: the capture's echo is at {want + dr * r_bin:.4g} m, where the scene puts it "
        f"{want:.4g} m ({dr:+.2f} bins of {r_bin:.3g} m, at most 0.25): front end 0's two-way "
        f"air path on the scene's arc (rts.arc_radius_m = {rts.arc_radius_m:g} m, {air:.4g} m)"
        f" misses the capture's by about {2 * dr * r_bin:+.2g} m, with the RTS delay its "
        f"sidecar records (rts_delay_s = {wrong.rts_delay_s * 1e9:.4f} ns; the scene programs "
        f"{own:.4f} ns for probe_range_m = {cap.range_m:g}): the capture was made on another "
        "arc or front-end position; identify it against the bench's scene")
