"""Tests of ``rtsgeom.rts.channels``: closed forms and invariants on grids of inputs."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import make_scene, small_noiseless, small_quiet

from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.paths.table import RUT_TO_RUT, Paths
from rtsgeom.rts.channels import KIND_SETUP, setup_echoes


@pytest.mark.parametrize("extra_tx, extra_rx", [(1, 0), (0, 2), (2, 1)])
def test_channel_echoes_pair_every_path_of_one_leg_with_every_path_of_the_other(extra_tx,
                                                                              extra_rx):
    """A leg with Pa paths (Tx -> front end) and one with Pb (front end -> Rx) give Pa x Pb
    direct echoes per channel and virtual element, with delays tau_a + tau_b (+ the RTS's)
    and amplitudes conj(g_a g_b G): here the line-of-sight legs plus copies 0.1 ns later each
    and half as strong, so the echoes' delays are the LoS one plus 0.1 ns x (m + n)."""
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    from rtsgeom.paths.table import FE_TO_RX, TX_TO_FE, Paths
    from rtsgeom.rts.channels import KIND_DIRECT, RtsProgram, channel_echoes
    setup = build_setup(small_noiseless())
    los = exact_paths(setup)
    extra = []
    for direction, count in ((TX_TO_FE, extra_tx), (FE_TO_RX, extra_rx)):
        leg = los.select(los.direction == direction)
        for m in range(1, count + 1):
            extra.append(Paths.build(leg.front_end, leg.direction, leg.rut_tx, leg.rut_rx,
                                     leg.delay_s + m * 0.1e-9, leg.gain * 0.5 ** m,
                                     np.ones(len(leg), int)))
    paths = Paths.concat([los, *extra])
    prog = RtsProgram.build([0, 1], [0, 1], [1e-7, 1.2e-7], [0.0, 0.0], [1.0, 0.5])
    ref = channel_echoes(setup, los, prog)
    ref = ref.select(ref.kind == KIND_DIRECT)
    got = channel_echoes(setup, paths, prog)
    got = got.select(got.kind == KIND_DIRECT)
    pa, pb = 1 + extra_tx, 1 + extra_rx
    assert len(got) == len(ref) * pa * pb
    for k in range(len(prog)):
        r = np.flatnonzero(ref.target == k)[0]
        rows = np.flatnonzero(got.target == k)
        assert rows.size == pa * pb
        lag = got.tau_air_s[rows] - ref.tau_air_s[r]  # (Pa Pb, V): 0.1 ns x (m + n)
        steps = np.round(lag / 0.1e-9)
        np.testing.assert_allclose(lag, steps * 0.1e-9, atol=1e-15)
        expect = sorted(m + n for m in range(pa) for n in range(pb))
        assert sorted(steps[:, 0].astype(int).tolist()) == expect
        np.testing.assert_allclose(got.amplitude[rows], ref.amplitude[r] * 0.5 ** steps,
                                   rtol=1e-12)


def test_setup_echoes_are_the_rut_to_rut_rows_conjugated():
    """Static reflections of the RuT's own chirp: per virtual element each RUT_TO_RUT row of
    its (Tx, Rx) pair becomes an echo with that delay and the conjugate gain; other rows and
    other pairs add nothing."""
    scene = small_quiet([])
    setup = build_setup(scene)
    rut = setup.rut
    rows = []
    rng = np.random.default_rng(4)
    for m in range(rut.tx_world.shape[0]):
        for k in range(rut.rx_world.shape[0]):
            for _ in range(1 + (m + k) % 2):
                rows.append((m, k, rng.uniform(5e-9, 9e-9), rng.normal() + 1j * rng.normal()))
    m_, k_, d_, g_ = map(np.array, zip(*rows))
    paths = Paths.build(np.full(len(rows), -1), np.full(len(rows), RUT_TO_RUT), m_, k_, d_, g_,
                        bounces=np.ones(len(rows), int))
    ech = setup_echoes(setup, paths)
    assert np.all(ech.kind == KIND_SETUP) and np.all(ech.tau_if_s == 0)
    assert ech.amplitude.dtype.kind == "c"
    for v in range(rut.num_virtual):
        sel = (m_ == rut.virtual_tx[v]) & (k_ == rut.virtual_rx[v])
        got = sorted(zip(ech.tau_air_s[:, v][ech.amplitude[:, v] != 0],
                         ech.amplitude[:, v][ech.amplitude[:, v] != 0]), key=lambda x: x[0])
        want = sorted(zip(d_[sel], np.conj(g_[sel])), key=lambda x: x[0])
        assert len(got) == len(want)
        for (a, b), (x, y) in zip(got, want):
            assert a == x and b == y
    # no RUT_TO_RUT rows: no echoes
    assert len(setup_echoes(setup, exact_paths(setup))) == 0


def test_ghosts_of_a_later_front_end_when_an_earlier_one_is_idle():
    """Cable ghosts are added per front end with echoes; a front end without any programmed
    channel does not end the loop, and the ghost order is an integer."""
    from rtsgeom.rts.channels import RtsProgram, channel_echoes
    s = make_scene(lambda d: d["radar"].pop("snr_db", None))
    setup = build_setup(s)
    prog = RtsProgram.build([0], [1], [1e-7], [0.0], [1.0])  # only front end 1
    ech = channel_echoes(setup, exact_paths(setup), prog)
    ghosts = ech.kind == 1
    assert ghosts.any() and np.all(ech.front_end[ghosts] == 1)
    assert ech.order.dtype.kind == "i"


def _echo_fields(e=3, v=4, n=None):
    f = dict(tau_air_s=np.zeros((e, v)), tau_if_s=np.zeros(e), f_if_hz=np.zeros(e),
             doppler_hz=np.zeros(e), amplitude=np.ones((e, v), complex),
             target=np.zeros(e, int), front_end=np.zeros(e, int), kind=np.zeros(e, int),
             order=np.zeros(e, int))
    if n is not None:
        f["fast_gain"] = np.ones((e, n), complex)
    return f


@pytest.mark.parametrize("name, bad, message", [
    ("tau_air_s", np.zeros(3), "Echoes.tau_air_s: shape (3,) must be (E, V) (echoes, virtual "
                               "channels)"),
    ("amplitude", np.ones((3, 5)), "Echoes.amplitude: got shape (3, 5) of float64, must be "
                                   "(E, V) = (3, 4) numbers (E echoes and V virtual channels as "
                                   "in tau_air_s, N fast-time samples)"),
    ("tau_if_s", np.zeros(2), "Echoes.tau_if_s: got shape (2,) of float64, must be (E,) = (3,) "
                              "numbers (E echoes and V virtual channels as in tau_air_s, N "
                              "fast-time samples)"),
    ("target", np.zeros(3), "Echoes.target: got shape (3,) of float64, must be (E,) = (3,) "
                            "integers (E echoes and V virtual channels as in tau_air_s, N "
                            "fast-time samples)"),
    ("kind", np.array(["a", "b", "c"]), "Echoes.kind: got shape (3,) of <U1, must be (E,) = "
                                        "(3,) integers (E echoes and V virtual channels as in "
                                        "tau_air_s, N fast-time samples)"),
    ("doppler_hz", np.array(["a", "b", "c"]), "Echoes.doppler_hz: got shape (3,) of <U1, must "
                                              "be (E,) = (3,) numbers (E echoes and V virtual "
                                              "channels as in tau_air_s, N fast-time samples)")])
def test_echoes_name_the_field_and_the_shape_it_must_have(name, bad, message):
    from conftest import assert_refused
    from rtsgeom.rts.channels import Echoes
    fields = _echo_fields()
    fields[name] = bad
    assert_refused(lambda: Echoes(**fields), message, ValueError)


def test_echoes_are_stored_read_only_with_an_optional_fast_gain():
    from conftest import assert_refused
    from rtsgeom.rts.channels import Echoes
    e = Echoes(**_echo_fields(n=6))
    assert e.fast_gain.shape == (3, 6) and not e.fast_gain.flags.writeable
    assert not e.amplitude.flags.writeable and not e.target.flags.writeable
    assert Echoes(**_echo_fields()).fast_gain is None
    bad = _echo_fields(n=6)
    bad["fast_gain"] = np.ones((2, 6))
    assert_refused(lambda: Echoes(**bad), (
        "Echoes.fast_gain: got shape (2, 6) of float64, must be (E, N) = (3, 6) numbers (E "
        "echoes and V virtual channels as in tau_air_s, N fast-time samples)"), ValueError)


@pytest.mark.parametrize("compensate", [True, False])
def test_the_nearest_programme_is_each_targets_radar_equation_on_its_nearest_front_end(
        compensate):
    """``program_nearest`` field by field from the closed forms: target k on the nearest
    front end, delay 2 R / c0 (minus 2 R_c / c0 where the RTS compensates the air path),
    Doppler 2 f_c v / c0, amplitude sqrt(sigma) lambda / ((4 pi)^1.5 R^2) over the nominal
    link gain (lambda / (4 pi R_c))^2; the apparent range R (or R + R_c); no target, no row."""
    from scipy.constants import c

    from conftest import make_scene
    from rtsgeom.geometry import build_setup
    from rtsgeom.rts.channels import apparent_range, program_nearest

    def mutate(doc):
        doc["rts"]["compensate_air_path"] = compensate
        doc["targets"] = [{"range_m": 12.5, "angle_deg": -3.0, "velocity_mps": 1.5,
                           "rcs_dbsm": 10.0},
                          {"range_m": 40.0, "angle_deg": 4.1, "velocity_mps": -7.0,
                           "rcs_dbsm": -5.0}]
    scene = make_scene(mutate)
    setup = build_setup(scene)
    prog = program_nearest(scene, setup)
    az = setup.fe_azimuth_rad()
    r_c, lam, f_c = scene.rts.arc_radius_m, setup.rut.wavelength_m, scene.radar.f_c_hz
    rng = np.array([12.5, 40.0])
    rcs = 10 ** (np.array([10.0, -5.0]) / 10)
    angle = np.radians([-3.0, 4.1])
    np.testing.assert_array_equal(prog.target, [0, 1])
    np.testing.assert_array_equal(prog.front_end,
                                  [int(np.argmin(np.abs(az - a))) for a in angle])
    np.testing.assert_allclose(prog.delay_s, 2 * rng / c - (2 * r_c / c if compensate else 0),
                               rtol=1e-12, atol=0)
    np.testing.assert_allclose(prog.doppler_hz, 2 * f_c * np.array([1.5, -7.0]) / c,
                               rtol=1e-12)
    link = (lam / (4 * np.pi * r_c)) ** 2
    np.testing.assert_allclose(prog.amplitude,
                               np.sqrt(rcs) * lam / ((4 * np.pi) ** 1.5 * rng ** 2) / link,
                               rtol=1e-12)
    np.testing.assert_array_equal(apparent_range(scene, rng), rng if compensate else rng + r_c)
    assert len(program_nearest(scene.evolve(targets=()), setup)) == 0


def test_a_target_midway_between_two_front_ends_stays_on_the_lower_index():
    """``nearest_front_ends``: distances within ``NEAREST_TIE_RAD`` of the smallest tie and the
    lowest index wins; beyond it the nearer one."""
    from rtsgeom.rts.channels import NEAREST_TIE_RAD, nearest_front_ends
    assert NEAREST_TIE_RAD == 1e-9
    fe = np.array([0.25, -0.25, 0.0])
    e = 2.0 ** -31  # below the tie (4.7e-10): exact binary offsets
    far = 2.0 ** -28  # beyond it (3.7e-9)
    got = nearest_front_ends(fe, [0.125, 0.125 - e, 0.125 + e, 0.125 - far, 0.125 + far,
                                  -0.125, -0.125 + far, -0.2, 0.3])
    np.testing.assert_array_equal(got, [0, 0, 0, 2, 0, 1, 2, 1, 0])
