"""Antenna patterns: closed forms of the cos^q model, table interpolation,
and their entry into the exact paths (isotropic unchanged)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rtsgeom.geometry import Setup, build_setup
from rtsgeom.geometry.frontends import front_ends
from rtsgeom.geometry.patterns import (
    ISOTROPIC,
    AntennaPatterns,
    CosinePattern,
    TablePattern,
    cos_power_exponent,
    direction_angles,
    pattern_from_config,
)
from rtsgeom.paths import exact_paths
from rtsgeom.paths.table import FE_TO_RX, TX_TO_FE


def _dir(az, el=0.0):
    az, el = np.broadcast_arrays(np.asarray(az, float), np.asarray(el, float))
    return np.stack([np.sin(az) * np.cos(el), np.cos(az) * np.cos(el), np.sin(el)], -1)


@pytest.mark.parametrize("hpbw_deg", [10.0, 30.0, 60.0, 90.0, 120.0, 170.0])
def test_cos_q_half_power_at_half_the_beamwidth(hpbw_deg):
    h = np.radians(hpbw_deg)
    p = CosinePattern(h)
    assert p.q == pytest.approx(np.log(0.5) / np.log(np.cos(h / 2)))
    power = np.abs(p.field(_dir([0.0, h / 2, -h / 2, 0.0], [0.0, 0.0, 0.0, h / 2]))) ** 2
    assert np.allclose(power, [1.0, 0.5, 0.5, 0.5])
    # monotonic off boresight, nothing behind the antenna
    off = np.radians(np.linspace(0, 89, 90))
    assert np.all(np.diff(np.abs(p.field(_dir(off)))) < 0)
    assert np.allclose(p.field(_dir(np.radians([95.0, 180.0, -120.0]))), 0.0)
    assert p.directivity == pytest.approx(2 * (p.q + 1))


@pytest.mark.parametrize("az_deg,el_deg", [(20.0, 60.0), (60.0, 20.0), (45.0, 45.0)])
def test_separable_cos_pattern_has_both_beamwidths(az_deg, el_deg):
    p = CosinePattern(np.radians(az_deg), np.radians(el_deg), peak_gain_db=6.0)
    peak = 10 ** (6 / 20)
    g = p.field(_dir([np.radians(az_deg) / 2, 0.0], [0.0, np.radians(el_deg) / 2]))
    assert np.allclose(np.abs(g) ** 2, 0.5 * peak ** 2)
    assert abs(p.field(_dir(0.0))) == pytest.approx(peak)


def test_bad_pattern_input_names_the_field():
    for bad in (0.0, np.pi, -1.0):
        with pytest.raises(ValueError, match="hpbw_deg"):
            cos_power_exponent(bad)
    with pytest.raises(ValueError, match="pattern.kind"):
        pattern_from_config("dipole")
    with pytest.raises(ValueError, match="hpbw_deg"):
        pattern_from_config("cos")
    with pytest.raises(ValueError, match="full regular"):
        TablePattern.from_samples([0, 10, 0], [0, 0, 5], [0, 0, 0], [0, 0, 0])
    assert pattern_from_config("isotropic") is ISOTROPIC


def _sampled_cos(hpbw_deg, step=2.0, phase_deg=None):
    az = np.arange(-90, 90.01, step)
    el = np.arange(-60, 60.01, step)
    A, E = np.meshgrid(az, el, indexing="ij")
    ref = CosinePattern(np.radians(hpbw_deg), np.radians(hpbw_deg))
    g = ref.field(_dir(np.radians(A), np.radians(E)))
    gain_db = 20 * np.log10(np.maximum(np.abs(g), 1e-6))
    ph = np.zeros_like(A) if phase_deg is None else phase_deg(A, E)
    return ref, A.ravel(), E.ravel(), gain_db.ravel(), ph.ravel()


@pytest.mark.parametrize("hpbw_deg", [40.0, 80.0])
def test_table_interpolates_a_sampled_pattern(hpbw_deg, tmp_path):
    ref, a, e, g, ph = _sampled_cos(hpbw_deg)
    tab = TablePattern.from_samples(a, e, g, ph)
    rng = np.random.default_rng(0)
    az = np.radians(rng.uniform(-70, 70, 200))
    el = np.radians(rng.uniform(-40, 40, 200))
    v = _dir(az, el)
    assert np.allclose(tab.field(v), ref.field(v), atol=3e-3)
    # CSV round trip (degrees at the edge)
    path = tmp_path / "pat.csv"
    rows = ["azimuth_deg,elevation_deg,gain_db,phase_deg"]
    rows += [f"{x},{y},{z},{w}" for x, y, z, w in zip(a, e, g, ph)]
    path.write_text("\n".join(rows))
    tab2 = pattern_from_config("table", table=path)
    assert np.allclose(tab2.field(v), tab.field(v))
    # outside the table: no radiation
    assert np.allclose(tab.field(_dir(0.0, np.radians(75.0))), 0.0)
    with pytest.raises(ValueError, match="columns"):
        bad = tmp_path / "bad.csv"
        bad.write_text("az,el\n0,0\n")
        TablePattern.from_csv(bad)


def test_table_phase_interpolates_across_the_wrap():
    # phase runs through +-180 deg: complex interpolation keeps the short way round
    ref, a, e, g, _ = _sampled_cos(80.0, step=5.0)
    ph = np.where(a >= 0, 179.0, -179.0)  # a 2 deg step across azimuth 0
    tab = TablePattern.from_samples(a, e, g, ph)
    mid = tab.field(_dir(np.radians(-2.5), 0.0))
    assert abs(np.degrees(np.angle(mid))) > 179.0 - 1e-6
    assert abs(mid) > 0.99 * abs(ref.field(_dir(np.radians(-2.5), 0.0)))


def test_direction_angles_inverse_of_the_direction():
    az = np.radians([-80.0, -10.0, 0.0, 33.0])
    el = np.radians([-30.0, 0.0, 12.0, 45.0])
    a2, e2 = direction_angles(3.0 * _dir(az, el))
    assert np.allclose(a2, az) and np.allclose(e2, el)


# ------------------------------------------------------------------------------------------
# Into the exact paths
# ------------------------------------------------------------------------------------------


def test_isotropic_patterns_leave_the_exact_paths_bit_identical(default_scene):
    setup = build_setup(default_scene)
    a, b = exact_paths(setup), exact_paths(setup, AntennaPatterns())
    assert np.array_equal(a.gain, b.gain) and np.array_equal(a.delay_s, b.delay_s)


def _angle_between(u, v):
    u = u / np.linalg.norm(u, axis=-1, keepdims=True)
    v = v / np.linalg.norm(v, axis=-1, keepdims=True)
    return np.arccos(np.clip(np.sum(u * v, -1), -1, 1))


@pytest.mark.parametrize("yaw_deg", [0.0, 3.0, -8.0])
@pytest.mark.parametrize("rut_yaw_deg", [0.0, 5.0])
def test_cos_patterns_scale_each_leg_by_both_off_boresight_angles(default_scene, yaw_deg,
                                                                  rut_yaw_deg):
    import dataclasses
    scene = dataclasses.replace(default_scene, radar=dataclasses.replace(
        default_scene.radar, yaw_rad=np.radians(rut_yaw_deg)))
    base = build_setup(scene)
    n = base.fe.count
    fe = front_ends(scene, base.fe.arc_centre, yaw_rad=np.full(n, np.radians(yaw_deg)))
    setup = Setup(scene, base.rut, fe)
    p_rut, p_fe = CosinePattern(np.radians(70.0)), CosinePattern(np.radians(25.0))
    iso = exact_paths(setup)
    pat = exact_paths(setup, AntennaPatterns(rut_tx=p_rut, rut_rx=p_rut, fe_rx=p_fe, fe_tx=p_fe))
    ratio = pat.gain / iso.gain
    rut, bore_rut = setup.rut, setup.rut.rotation[:, 1]
    _, _, bore_fe = fe.axes()
    for i in range(len(iso)):
        q = iso.front_end[i]
        if iso.direction[i] == TX_TO_FE:
            p_r, p_f = rut.tx_world[iso.rut_tx[i]], fe.rx[q]
        else:
            assert iso.direction[i] == FE_TO_RX
            p_r, p_f = rut.rx_world[iso.rut_rx[i]], fe.tx[q]
        th_r = _angle_between(p_f - p_r, bore_rut)
        th_f = _angle_between(p_r - p_f, bore_fe[q])
        want = np.cos(th_r) ** (p_rut.q / 2) * np.cos(th_f) ** (p_fe.q / 2)
        assert ratio[i] == pytest.approx(want, rel=1e-9)
    # a yawed front end looks past the RuT (which it sees within ~0.6 deg of boresight)
    if yaw_deg != 0.0:
        only_fe = AntennaPatterns(fe_rx=p_fe, fe_tx=p_fe)
        yawed = np.abs(exact_paths(setup, only_fe).gain / iso.gain)
        straight = np.abs(exact_paths(base, only_fe).gain / exact_paths(base).gain)
        assert np.all(yawed < straight)


def test_pattern_phase_enters_the_leg_gain(default_scene):
    setup = build_setup(default_scene)
    a = np.array([-90.0, 0.0, 90.0, -90.0, 0.0, 90.0])
    e = np.array([-30.0, -30.0, -30.0, 30.0, 30.0, 30.0])
    tab = TablePattern.from_samples(a, e, np.full(6, -3.0), np.full(6, 40.0))
    iso = exact_paths(setup)
    pat = exact_paths(setup, AntennaPatterns(fe_rx=tab, fe_tx=tab))
    r = pat.gain / iso.gain
    assert np.allclose(np.abs(r), 10 ** (-3 / 20)) and np.allclose(np.degrees(np.angle(r)), 40.0)
    # one pattern per front end
    per = exact_paths(setup, AntennaPatterns(fe_rx=(tab, ISOTROPIC), fe_tx=(ISOTROPIC, tab)))
    rp = per.gain / iso.gain
    rx0 = (per.front_end == 0) & (per.direction == TX_TO_FE)
    rx1 = (per.front_end == 1) & (per.direction == TX_TO_FE)
    tx1 = (per.front_end == 1) & (per.direction == FE_TO_RX)
    assert np.allclose(rp[rx0], r[rx0]) and np.allclose(rp[rx1], 1.0)
    assert np.allclose(rp[tx1], r[tx1])
    with pytest.raises(ValueError, match="front-end patterns"):
        exact_paths(setup, AntennaPatterns(fe_rx=(tab,)))



@pytest.mark.parametrize("hpbw_deg, peak_db", [(60.0, 0.0), (30.0, 6.0), (120.0, -3.0)])
def test_pattern_gain_db_is_twenty_log_of_the_field_and_finite_behind(hpbw_deg, peak_db):
    """``gain_db_towards`` is 20 log10 |field| (field gain, so the power gain in dB) on a grid
    of directions: peak_gain_db at boresight, -3 dB at half the half-power beamwidth, and a
    finite floor (not -inf) behind the antenna, where the field is 0."""
    from rtsgeom.geometry.patterns import CosinePattern
    pat = CosinePattern(math.radians(hpbw_deg), peak_gain_db=peak_db)
    th = np.radians(np.linspace(-89.0, 89.0, 37))
    v = np.stack([np.sin(th), np.cos(th), np.zeros_like(th)], -1)
    g = pat.gain_db_towards(v)
    np.testing.assert_allclose(g, 20 * np.log10(np.abs(pat.field(v))), atol=1e-9)
    half = math.radians(hpbw_deg / 2)
    edge = pat.gain_db_towards(np.array([math.sin(half), math.cos(half), 0.0]))
    assert float(edge) == pytest.approx(peak_db - 10 * math.log10(2), abs=1e-6)
    assert float(pat.gain_db_towards(np.array([0.0, 1.0, 0.0]))) == pytest.approx(peak_db)
    behind = pat.gain_db_towards(np.array([[0.0, -1.0, 0.0], [0.3, -0.9, 0.0]]))
    assert np.all(np.isfinite(behind)) and np.all(behind < -1000)


def test_pattern_tables_may_span_the_whole_circle():
    from rtsgeom.geometry.patterns import TablePattern
    az = np.radians(np.linspace(-180, 180, 9))
    el = np.radians([-90.0, 0.0, 90.0])
    p = TablePattern(az, el, np.zeros((9, 3)), np.zeros((9, 3)))
    assert p is not None
    with pytest.raises(ValueError, match="azimuth_deg"):
        TablePattern(np.radians(np.linspace(-181, 180, 9)), el, np.zeros((9, 3)), np.zeros((9, 3)))


def test_cos_pattern_from_config_without_an_elevation_beamwidth():
    from rtsgeom.geometry.patterns import CosinePattern, pattern_from_config
    p = pattern_from_config("cos", hpbw_deg=60.0)
    assert isinstance(p, CosinePattern) and p.hpbw_el_rad is None
    q = pattern_from_config("cos", hpbw_deg=60.0, hpbw_el_deg=30.0)
    assert q.hpbw_el_rad == pytest.approx(np.radians(30.0))


def test_bad_pattern_input_is_refused_word_for_word():
    from conftest import assert_refused
    for bad, shown in ((0.0, "0"), (np.pi, "180"), (-0.1, "-5.72958")):
        assert_refused(lambda: cos_power_exponent(bad),
                       f"pattern.hpbw_deg: must lie in (0, 180) deg, got {shown}", ValueError)
    # the open interval's edges: just inside is a pattern, q = ln(1/2) / ln(cos(HPBW / 2))
    for h in (np.pi - 1e-9, 1e-6):
        assert cos_power_exponent(h) == pytest.approx(np.log(0.5) / np.log(np.cos(h / 2)),
                                                      rel=1e-12)
    assert_refused(lambda: pattern_from_config("dipole"),
                   "pattern.kind: one of isotropic, cos, table; got 'dipole'", ValueError)
    assert_refused(lambda: pattern_from_config("cos"),
                   "pattern.hpbw_deg: required for a 'cos' pattern, in (0, 180) deg", ValueError)
    assert_refused(lambda: pattern_from_config("table"),
                   "pattern.table: a CSV path is required for a 'table' pattern", ValueError)
