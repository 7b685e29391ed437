"""The joint model's bookkeeping in closed form on a hand-made model (a 3-Tx, 4-Rx radar whose
Tx 0 never transmits, two front ends): the parameter vector's layout, names, kinds, references,
the unseen antennas, the nominal values from ``[radar.channels]``, the virtual gains; the
radar's fit as shown and its gain limit."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from rtsgeom.errors import CaptureError
from rtsgeom.identify.joint import (GAUGES, JointModel, RadarChannelsFit, _gauges,
                                    check_radar_fit)
from rtsgeom.identify.model import PARAMS

N = len(PARAMS)  # 7
VTX = np.array([1, 1, 1, 1, 2, 2, 2, 2])
VRX = np.array([0, 1, 2, 3, 0, 1, 2, 3])


def _front(q, seed):
    values = np.random.default_rng(seed).normal(size=N)
    return SimpleNamespace(active=q, nominal=lambda: values, values=values)


@pytest.fixture
def model():
    return JointModel((_front(2, 1), _front(5, 2), _front(2, 3)), np.array([0, 1, 0]), (2, 5),
                      3, 4, VTX, VRX)


def test_the_parameter_vector_layout(model):
    assert (model.n_ant, model.size) == (7, 2 * N + 2 * 7)
    # front ends' blocks, then every antenna's ln-gain (Tx then Rx), then their phases
    assert model.antenna_index("tx", 0, PARAMS.index("log_gain")) == 14
    assert model.antenna_index("tx", 2, PARAMS.index("log_gain")) == 16
    assert model.antenna_index("rx", 0, PARAMS.index("log_gain")) == 17
    assert model.antenna_index("rx", 3, PARAMS.index("phase")) == 14 + 7 + 3 + 3
    assert model.antenna_index("tx", 1, PARAMS.index("phase")) == 14 + 7 + 1
    assert list(model.kinds()) == list(range(N)) * 2 + [5] * 7 + [6] * 7
    names = model.names()
    assert names[:N] == [f"front end 2 {p}" for p in PARAMS]
    assert names[N:2 * N] == [f"front end 5 {p}" for p in PARAMS]
    assert names[14:] == ([f"{a} ln-gain" for a in ("tx0", "tx1", "tx2", "rx0", "rx1", "rx2",
                                                    "rx3")]
                          + [f"{a} phase" for a in ("tx0", "tx1", "tx2", "rx0", "rx1", "rx2",
                                                    "rx3")])
    assert len(names) == model.size


def test_references_and_unseen_antennas(model):
    assert model.reference_tx == 1  # the first Tx that transmits
    assert list(model.unseen()) == [0]
    other = JointModel((), np.zeros(0, int), (0,), 2, 3, np.array([0, 1]), np.array([0, 2]))
    assert other.reference_tx == 0 and list(other.unseen()) == [2 + 1]  # Rx 1, Tx-then-Rx


@pytest.mark.parametrize("channels", [None, "set"])
def test_nominal_values_are_each_front_ends_then_the_scenes_antennas(model, channels):
    """Each front end's values (its first capture's model), then ln|g| = G_dB ln(10) / 20 and
    the phases of ``[radar.channels]`` (0 without it)."""
    tx_db, rx_db = (1.0, -2.0, 0.5), (0.0, 3.0, -1.0, 2.0)
    tx_ph, rx_ph = (0.1, -0.2, 0.3), (0.0, 0.4, -0.5, 1.0)
    ch = None if channels is None else SimpleNamespace(
        tx_gain_db=tx_db, rx_gain_db=rx_db, tx_phase_rad=tx_ph, rx_phase_rad=rx_ph)
    got = model.nominal(SimpleNamespace(radar=SimpleNamespace(channels=ch)))
    fe = model.models
    assert np.array_equal(got[:N], fe[0].values) and np.array_equal(got[N:2 * N], fe[1].values)
    if ch is None:
        assert np.array_equal(got[14:], np.zeros(14))
    else:
        assert np.allclose(got[14:21], np.r_[tx_db, rx_db] * math.log(10) / 20, atol=1e-15)
        assert np.allclose(got[21:], np.r_[tx_ph, rx_ph], atol=1e-15)


def test_virtual_gain_is_tx_times_rx(model):
    rng = np.random.default_rng(4)
    theta = rng.normal(size=model.size)
    lg, ph = theta[14:21], theta[21:]
    want = np.exp(lg[VTX] + lg[3 + VRX] + 1j * (ph[VTX] + ph[3 + VRX]))
    assert np.allclose(model.virtual_gain(theta), want, rtol=1e-13, atol=0)


def test_the_gauges_fix_the_references_the_unseen_and_the_ramp(model):
    setup = SimpleNamespace(rut=SimpleNamespace(
        tx_local=np.zeros((3, 3)), rx_local=np.zeros((4, 3)), virtual_tx=VTX, virtual_rx=VRX))
    g = _gauges(model, setup, 5)
    lg, ph = PARAMS.index("log_gain"), PARAMS.index("phase")
    ref_tx = f"the reference Tx: keeps the scene's {{}} ({GAUGES[0][1]})"
    ref_rx = f"the reference Rx: keeps the scene's {{}} ({GAUGES[1][1]})"
    unseen = ("in no virtual element of this radar's configuration (e.g. the elevated Tx "
              "without radar.use_elevation_tx): no capture sees it; keeps the scene's value")
    ramp = f"the reference front end: keeps the scene's value ({GAUGES[2][1]}; {GAUGES[2][2]})"
    assert g == {15: ref_tx.format("gain"), 22: ref_tx.format("phase"),
                 17: ref_rx.format("gain"), 24: ref_rx.format("phase"),
                 14: unseen, 21: unseen, N + PARAMS.index("tangential_offset"): ramp}
    assert (lg, ph) == (5, 6)
    # an array spanning heights: the height ramp is fixed too
    tall = SimpleNamespace(rut=SimpleNamespace(
        tx_local=np.array([[0, 0, 0], [0, 0, 0], [0, 0, 1e-3]]), rx_local=np.zeros((4, 3)),
        virtual_tx=VTX, virtual_rx=VRX))
    g = _gauges(model, tall, 2)
    assert g[PARAMS.index("tangential_offset")] == ramp == g[PARAMS.index("height_offset")]


def _radar(lg_db=(0.0, 1.0, -2.0, 0.5, 0.0), reasons=None):
    k = 20 / math.log(10)
    lg = np.array(lg_db) / k
    ph = np.radians([0.0, 10.0, -5.0, 0.0, 3.0])
    why = reasons or (("ref", "ref"), (None, None), (None, None), ("ref", "ref"), (None, None))
    return RadarChannelsFit(lg, ph, np.full(5, 0.1 / k), np.radians(np.full(5, 0.5)), why, 2,
                            0, 0, 3)


def test_the_radar_fit_is_shown_in_db_and_deg_with_its_references():
    """Tx 0 and Rx 1 fixed (None, with their reasons), the others in dB and deg."""
    r = _radar()
    lg, ph, _, _, why = r.side("tx")
    assert lg.size == 2 and len(why) == 2 and r.side("rx")[0].size == 3
    assert np.array_equal(r.side("rx")[1], np.radians([-5.0, 0.0, 3.0]))
    d = r.to_dict()
    assert d["tx_gain_db"][0] is None and d["tx_phase_deg"][0] is None
    assert d["tx_gain_db"][1] == pytest.approx({"value": 1.0, "std": 0.1})
    assert d["tx_phase_deg"][1] == pytest.approx({"value": 10.0, "std": 0.5})
    assert d["rx_gain_db"][1] is None and d["rx_phase_deg"][1] is None
    assert d["rx_gain_db"][0] == pytest.approx({"value": -2.0, "std": 0.1})
    assert d["rx_gain_db"][2] == pytest.approx({"value": 0.0, "std": 0.1})
    assert d["rx_phase_deg"][0] == pytest.approx({"value": -5.0, "std": 0.5})
    assert d["rx_phase_deg"][2] == pytest.approx({"value": 3.0, "std": 0.5})
    assert d["not_identifiable"] == {"tx_gain_db[0]": "ref", "tx_phase_deg[0]": "ref",
                                     "rx_gain_db[1]": "ref", "rx_phase_deg[1]": "ref"}
    assert d["references"] == {"tx": 0, "rx": 0, "front_end": 3}
    assert [g["name"] for g in d["fixed_by_convention"]] == ["tx_rx_factor", "common_factor",
                                                              "array_ramp"]
    assert [(g["what"], g["separate_by"]) for g in d["fixed_by_convention"]] == [
        (w, b) for _, w, b in GAUGES]


def test_the_radar_fit_refuses_a_gain_beyond_the_scenes_limit():
    from rtsgeom.scene.channels import MAX_GAIN_ERROR_DB
    lim = MAX_GAIN_ERROR_DB
    assert lim == 20.0
    check_radar_fit(_radar((0.0, lim - 1e-9, -lim + 1e-9, 0.0, 0.0)))
    for lg, message in (((0.0, 0.0, 0.0, 0.0, -20.5), "rx_gain_db[2] = -20.5"),
                        ((0.0, 20.5, 0.0, 0.0, 0.0), "tx_gain_db[1] = 20.5"),
                        ((0.0, 0.0, 20.5, 0.0, 0.0), "rx_gain_db[0] = 20.5")):
        with pytest.raises(CaptureError) as exc:
            check_radar_fit(_radar(lg))
        assert str(exc.value) == (f"radar channels: estimated: {message}: must be in [-20, 20] "
                                  "dB")
    # a reference keeps the scene's value, unchecked
    check_radar_fit(_radar((lim + 5.0, 0.0, 0.0, lim + 5.0, 0.0)))


def _linear_front(q, seed, v):
    """A front end whose capture is linear in its PARAMS: h = A theta_b + h0 (V,)."""
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(v, N)) + 1j * rng.normal(size=(v, N))
    h0 = rng.normal(size=v) + 1j * rng.normal(size=v)
    return SimpleNamespace(active=q, jacobian=lambda th, cols: (a @ th + h0, a[:, cols]))


@pytest.mark.parametrize("sigma2", [0.3, (0.5, 2.0, 0.05)])
def test_joint_cramer_rao_is_the_weighted_fisher_inverse(sigma2):
    """rtsgeom.identify.joint.joint_cramer_rao = sqrt(diag(F^-1)) on the free parameters,
    F = sum_c 2 Re(J_c^H J_c) / sigma2_c over the captures' rows of the model's Jacobian
    (a scalar sigma2 for every capture, or one per capture), NaN elsewhere."""
    from rtsgeom.identify.joint import joint_cramer_rao
    fronts = (_linear_front(2, 11, VTX.size), _linear_front(5, 12, VTX.size))
    model = JointModel(fronts + (fronts[0],), np.array([0, 1, 0]), (2, 5), 3, 4, VTX, VRX)
    theta = np.random.default_rng(3).normal(0, 0.3, model.size)
    free = list(range(2 * N)) + [model.antenna_index("tx", 2, PARAMS.index("log_gain")),
                                 model.antenna_index("rx", 1, PARAMS.index("phase"))]
    _, jac = model.jacobian(theta, free)
    s2 = np.broadcast_to(np.asarray(sigma2, float), (3,))
    fim = sum(2 * np.real(j.conj().T @ j) / s for j, s in
              zip(np.split(jac, 3), s2))
    want = np.full(model.size, np.nan)
    want[free] = np.sqrt(np.diag(np.linalg.inv(fim)))
    got = joint_cramer_rao(model, theta, sigma2, free)
    np.testing.assert_allclose(got, want, rtol=1e-10, atol=0)
    assert np.isnan(got).sum() == model.size - len(free)
