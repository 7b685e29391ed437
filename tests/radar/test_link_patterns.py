"""Antenna gains from the patterns toward each front end.

Without a pattern the link's antenna gains are scalars (the preset's RuT gain, 10 dBi front
ends). With ``[radar.pattern]`` / ``[rts.pattern]`` the paths carry each antenna's field gain
toward the other, its dB read as dBi, and the scalar on top defaults to 0 dBi: a cos pattern
of peak gain G gives ``G + 10 log10(cos^q theta_q)`` toward front end q, in the budget, in the
echo's power at the ADC (the radar equation with G_t(theta) G_r(theta)), in the back end's
input level and in the channels' re-radiated noise.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.constants import c

from conftest import make_scene
from rtsgeom.radar import budget, link as lk
from rtsgeom.geometry import build_setup
from rtsgeom.geometry.patterns import cos_power_exponent
from rtsgeom.paths import exact_paths
from rtsgeom.rts.channels import build_echoes, program_nearest


def _scene(fe_deg, target_deg=None, radar_pattern=None, fe_pattern=None, link=None,
           rts_link=None, rcs_dbsm=10.0):
    def mut(d):
        d["radar"].pop("snr_db", None)
        d["radar"].update(samples_per_chirp=128, chirps_per_tx=32, adc_rate_hz=12.5e6)
        d["radar"]["link"] = dict(link or {})
        fes = d["rts"]["front_ends"]
        d["rts"]["front_ends"] = [dict(fes[0], angle_deg=a) for a in fe_deg]
        for fe in d["rts"]["front_ends"]:
            fe.pop("return_loss_fe_db", None)
            fe.pop("return_loss_be_db", None)
        d["rts"]["fractional_delay_filter"] = "ideal"
        d["rts"]["aoa_mode"] = "nearest"
        if radar_pattern:
            d["radar"]["pattern"] = dict(radar_pattern)
        if fe_pattern:
            d["rts"]["pattern"] = dict(fe_pattern)
        if rts_link:
            d["rts"]["link"] = dict(rts_link)
        d["sheet"]["enabled"] = False
        ang = fe_deg if target_deg is None else target_deg
        d["targets"] = [{"range_m": 20.0, "rcs_dbsm": rcs_dbsm, "angle_deg": a} for a in ang]
    return make_scene(mut)


def _budget(scene):
    setup = build_setup(scene)
    program = program_nearest(scene, setup)
    echoes = lk.apply_radar_link(build_echoes(setup, exact_paths(setup), program), scene)
    return budget.link_budget(scene, echoes, program, linked=True, setup=setup), setup


@pytest.mark.parametrize("hpbw_deg", [30.0, 60.0, 120.0])
@pytest.mark.parametrize("peak_db", [0.0, 12.0])
def test_rut_pattern_gives_the_gain_toward_each_front_end(hpbw_deg, peak_db):
    """[radar.pattern] cos (HPBW, peak G), front ends at 0/10/25 deg: the budget's RuT gains
    toward front end q are G + 10 log10(cos^q theta_q) (theta_q: the angle of its Rx / Tx
    antenna off the RuT's boresight, power-averaged over the RuT's elements) within 0.05 dB, and each target's power at the ADC is the radar equation with those
    two gains (P_t G_t G_r lambda^2 sigma / ((4 pi)^3 R^4) |H|^2) within 0.05 dB."""
    fe_deg = [0.0, 10.0, 25.0]
    scene = _scene(fe_deg, radar_pattern={"kind": "cos", "hpbw_deg": hpbw_deg,
                                          "peak_gain_db": peak_db})
    b, setup = _budget(scene)
    q = cos_power_exponent(np.radians(hpbw_deg))

    def off_boresight_db(points, elements):  # mean over the elements of cos^q(theta)
        v = (points[:, None, :] - elements[None, :, :]) @ setup.rut.rotation  # radar frame
        cos_t = v[..., 1] / np.linalg.norm(v, axis=-1)
        return peak_db + 10 * np.log10(np.mean(cos_t ** q, axis=1))
    expect_tx = off_boresight_db(setup.fe.rx, setup.rut.tx_world)
    expect_rx = off_boresight_db(setup.fe.tx, setup.rut.rx_world)
    assert np.ptp(np.degrees(setup.fe_azimuth_rad())) > 20  # the grid spans the beam
    for fe, e_t, e_r in zip(b.front_ends, expect_tx, expect_rx):
        assert fe["rut_tx_gain_dbi"] == pytest.approx(e_t, abs=0.05)
        assert fe["rut_rx_gain_dbi"] == pytest.approx(e_r, abs=0.05)
        assert fe["fe_rx_gain_dbi"] == pytest.approx(10.0, abs=1e-9)  # no FE pattern: scalar
    assert b.radar["tx_antenna_gain_dbi"] == 0.0  # nothing on top of the pattern
    rl = lk.radar_link(scene.radar)
    lam = c / scene.radar.f_center_hz
    for t, e_t, e_r in zip(b.targets, expect_tx, expect_rx):
        p_r = (rl.tx_power_w * 10 ** ((e_t + e_r) / 10) * lam ** 2 * 10 ** (t["rcs_dbsm"] / 10)
               / ((4 * np.pi) ** 3 * t["range_m"] ** 4))
        assert t["adc_power_dbm"] - t["if_response_db"] == pytest.approx(float(lk.dbm(p_r)),
                                                                          abs=0.05)


def test_explicit_scalar_adds_to_the_pattern_and_no_pattern_keeps_the_scalar():
    """An explicit [radar.link] tx_antenna_gain_dbi with a pattern adds on top of it; without a
    pattern the preset's scalar (10.5 dBi, AWR1843BOOST) is the gain toward every front end."""
    pat = {"kind": "cos", "hpbw_deg": 60.0, "peak_gain_db": 6.0}
    b_pat, _ = _budget(_scene([0.0, 20.0], radar_pattern=pat))
    b_both, _ = _budget(_scene([0.0, 20.0], radar_pattern=pat,
                               link={"tx_antenna_gain_dbi": 4.0}))
    b_none, _ = _budget(_scene([0.0, 20.0]))
    for a, ab, n in zip(b_pat.front_ends, b_both.front_ends, b_none.front_ends):
        assert ab["rut_tx_gain_dbi"] - a["rut_tx_gain_dbi"] == pytest.approx(4.0, abs=1e-9)
        assert ab["rut_rx_gain_dbi"] == pytest.approx(a["rut_rx_gain_dbi"], abs=1e-9)
        assert n["rut_tx_gain_dbi"] == pytest.approx(10.5, abs=1e-9)
    d = b_both.targets[1]["adc_power_dbm"] - b_pat.targets[1]["adc_power_dbm"]
    assert d == pytest.approx(4.0, abs=1e-9)


@pytest.mark.parametrize("peak_db,scalar_db", [(8.0, None), (15.0, None), (8.0, 3.0)])
def test_front_end_pattern_sets_the_back_end_level_and_channel_noise(peak_db, scalar_db):
    """[rts.pattern] cos of peak G (the front ends face the RuT): their gain toward it is G (+ an
    explicit [rts.link] scalar s, else 0), so the RuT's chirp at each back end's ADC is
    (G + s) - 10 dB against the 10 dBi scalar-only front end, and the channels' re-radiated
    noise (electronic gain^2 x FE Tx antenna toward the RuT = |A|^2 / s_rx x pattern) by
    G - s + 10 dB."""
    pat = {"kind": "cos", "hpbw_deg": 40.0, "peak_gain_db": peak_db}
    rts_link = {} if scalar_db is None else {"fe_rx_antenna_gain_dbi": scalar_db,
                                             "fe_tx_antenna_gain_dbi": scalar_db}
    s = 0.0 if scalar_db is None else scalar_db
    ref = _scene([0.0, 12.0])
    got = _scene([0.0, 12.0], fe_pattern=pat, rts_link=rts_link)
    b_ref, setup_ref = _budget(ref)
    b_got, setup = _budget(got)
    for r, g in zip(b_ref.front_ends, b_got.front_ends):
        assert g["fe_rx_gain_dbi"] == pytest.approx(peak_db + s, abs=0.02)
        assert g["fe_tx_gain_dbi"] == pytest.approx(peak_db + s, abs=0.02)
        assert g["rut_chirp_at_adc_dbm"] - r["rut_chirp_at_adc_dbm"] == pytest.approx(
            peak_db + s - 10.0, abs=0.02)
    p_ref, p_got = program_nearest(ref, setup_ref), program_nearest(got, setup)
    n_ref = lk.channel_noise_w(ref, p_ref, setup=setup_ref)
    n_got = lk.channel_noise_w(got, p_got, setup=setup)
    # |E|^2 G_fe_tx = |A|^2 / s_rx x pattern(FE Tx -> RuT): (peak - s) against (0 - 10); the
    # program A is the same (a pattern is not compensated by program_nearest)
    assert 10 * np.log10(n_got / n_ref) == pytest.approx(peak_db - s + 10.0, abs=0.02)
