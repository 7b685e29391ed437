"""The radar under test's own channels ([radar.channels]): the section's checks, an ideal radar's
bit-identical outputs, the one place the gains act (ADC cube and phasor model alike), the
single-source angle error against its first-order closed form on a grid of error vectors,
and the radar's boresight compensation."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.constants import c

from conftest import far_field, make_scene, quiet
from rtsgeom.errors import SceneError
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths, nominal_model
from rtsgeom.radar.channels import (antenna_gains, boresight_reference, channel_gain,
                                    virtual_gain)
from rtsgeom.radar.fmcw import synthesize
from rtsgeom.radar.phasors import bin_response
from rtsgeom.radar.steering import Steering
from rtsgeom.rts.channels import build_echoes, program_nearest
from rtsgeom.scene import TargetConfig
from rtsgeom.synthesis.model import ChannelModel


def with_channels(channels=None, small=True, angles=None, far=False, separation=None,
                  **radar):
    """The default scene, quiet (small cube), with ``[radar.channels]`` = ``channels``
    (None: no section) and front ends at ``angles`` (deg); ``far``: in the far field."""
    def mutate(doc):
        quiet(doc, small=small, **radar)
        if far:
            far_field(doc)
            doc["targets"] = []
        if channels is not None:
            doc["radar"]["channels"] = channels
        if angles is not None:
            for fe, a in zip(doc["rts"]["front_ends"], angles):
                fe["angle_deg"] = a
        if separation is not None:
            for fe in doc["rts"]["front_ends"]:
                fe["rx_tx_separation_m"] = separation
    return make_scene(mutate)


# -- the section -------------------------------------------------------------------------------

@pytest.mark.parametrize("channels, words", [
    ({"rx_phase_deg": [0.0, 10.0, 0.0]}, ["radar.channels.rx_phase_deg", "4 values",
                                          "Rx antenna", "awr1843boost", "it has 3"]),
    ({"tx_gain_db": [0.0, 1.0]}, ["radar.channels.tx_gain_db", "3 values", "Tx antenna"]),
    ({"rx_phase_deg": [0.0, 200.0, 0.0, 0.0]}, ["radar.channels.rx_phase_deg[1]", "200",
                                                "[-180, 180] deg"]),
    ({"rx_gain_db": [0.0, float("nan"), 0.0, 0.0]}, ["radar.channels.rx_gain_db[1]", "finite"]),
    ({"rx_gain_db": [0.0, 25.0, 0.0, 0.0]}, ["rx_gain_db[1]", "[-20, 20] dB"]),
    ({"compensation": "factory"}, ["radar.channels.compensation", "none, boresight"]),
    ({"compensation_range_m": 0.0}, ["radar.channels.compensation_range_m", "[0.1, 10000]"]),
    ({"compensation_range_m": 1.0}, ["radar.channels.compensation_range_m", "left out",
                                     'compensation = "none"']),
    ({"rx_coupling_db": 0.0}, ["radar.channels.rx_coupling_db", "[-80, -3] dB"]),
    ({"rx_phase": [1.0]}, ["radar.channels.rx_phase", "not a known field", "rx_phase_deg"]),
])
def test_section_errors_name_the_field_and_the_range(channels, words):
    with pytest.raises(SceneError) as exc:
        with_channels(channels)
    msg = str(exc.value)
    for w in words:
        assert w in msg, (w, msg)


def test_custom_array_counts_its_own_antennas():
    arr = {"tx_mm": [[0.0, 0.0], [7.8, 0.0]], "rx_mm": [[20.0, 0.0], [22.0, 0.0]],
           "tx_order": [0, 1]}
    with pytest.raises(SceneError, match=r"2 values, one per Rx antenna of \[radar.array\]"):
        with_channels({"rx_phase_deg": [1.0, 2.0, 3.0, 4.0]}, array=arr)
    s = with_channels({"rx_phase_deg": [1.0, 2.0]}, array=arr)
    assert np.allclose(s.radar.channels.rx_phase_rad, np.radians([1.0, 2.0]))


def test_values_are_si_and_evolve_is_checked():
    s = with_channels({"tx_phase_deg": [0.0, 30.0, 0.0], "rx_gain_db": [0, 0, -1.5, 0]})
    ch = s.radar.channels
    assert ch.tx_phase_rad[1] == pytest.approx(np.pi / 6)
    assert ch.rx_gain_db[2] == -1.5 and ch.compensation == "none" and not ch.ideal
    with pytest.raises(SceneError, match="rx_phase_deg"):
        ch.evolve(rx_phase_rad=(0.0, 4.0, 0.0, 0.0))  # 229 deg


# -- an ideal radar: nothing changes -------------------------------------------------------------

@pytest.mark.parametrize("channels", [
    {}, {"tx_gain_db": [0, 0, 0], "tx_phase_deg": [0, 0, 0], "rx_gain_db": [0, 0, 0, 0],
         "rx_phase_deg": [0, 0, 0, 0]}, {"compensation": "boresight"}])
def test_ideal_section_gives_bit_identical_outputs(channels):
    plain, zero = with_channels(None), with_channels(channels)
    assert zero.radar.channels.ideal
    outs = []
    for scene in (plain, zero):
        setup = build_setup(scene)
        paths = exact_paths(setup)
        ech = build_echoes(setup, paths, program_nearest(scene, setup))
        assert channel_gain(scene.radar, setup.rut) is None
        outs.append((synthesize(ech, scene.radar, setup.rut).data,
                     bin_response(ech, scene.radar, setup.rut, [10, 20], [16, 16])))
    assert np.array_equal(outs[0][0], outs[1][0])
    assert np.array_equal(outs[0][1], outs[1][1])


# -- one place, every engine ----------------------------------------------------------------------

ERR = {"tx_gain_db": [0.5, -0.8, 0.3], "tx_phase_deg": [0.0, 12.0, -5.0],
       "rx_gain_db": [0.0, 1.0, -0.5, 0.2], "rx_phase_deg": [3.0, -10.0, 4.0, 8.0]}


def expected_gain(setup, ch=ERR):
    return virtual_gain(setup.rut,
                        antenna_gains(ch["tx_gain_db"], np.radians(ch["tx_phase_deg"]), 3),
                        antenna_gains(ch["rx_gain_db"], np.radians(ch["rx_phase_deg"]), 4))


def test_cube_and_phasors_carry_the_virtual_gains():
    ideal, bad = with_channels(None), with_channels(ERR)
    s0, s1 = build_setup(ideal), build_setup(bad)
    g = expected_gain(s1)
    assert np.allclose(channel_gain(bad.radar, s1.rut), g, rtol=1e-14)
    p0, p1 = exact_paths(s0), exact_paths(s1)
    e0 = build_echoes(s0, p0, program_nearest(ideal, s0))
    e1 = build_echoes(s1, p1, program_nearest(bad, s1))
    c0, c1 = synthesize(e0, ideal.radar, s0.rut).data, synthesize(e1, bad.radar, s1.rut).data
    top = np.abs(c0).max()
    assert np.abs(c1 - c0 * g[None, :, None].astype(np.complex64)).max() < 1e-5 * top
    r0 = bin_response(e0, ideal.radar, s0.rut, [10, 20], [16, 16])
    r1 = bin_response(e1, bad.radar, s1.rut, [10, 20], [16, 16])
    assert np.allclose(r1, r0 * g, rtol=1e-12, atol=1e-12 * np.abs(r0).max())
    # the lab's design model does not know the radar's errors; the paths are the same
    nom, nom_paths = nominal_model(s1, p1)
    assert nom.scene.radar.channels is None and nom_paths is p1


def test_a_calibration_is_a_measurement_of_its_radar():
    from rtsgeom.calibration.file import setup_fingerprint
    plain = with_channels(None)
    assert setup_fingerprint(plain) == setup_fingerprint(with_channels({"rx_phase_deg": [0] * 4}))
    assert setup_fingerprint(with_channels(ERR)) != setup_fingerprint(plain)


# -- the closed form: a single front end's angle error ------------------------------------------

def closed_form_shift(st: Steering, phase_v, theta):
    """First-order Bartlett peak shift (rad) of a source at ``theta`` for per-virtual phase
    errors ``phase_v`` (..., V): P'(u0) = -2 k W sum w p_c phi, P''(u0) = -2 k^2 W sum w p_c^2
    (w the taper, p_c the positions about their weighted centre), so
    d theta = -sum w p_c phi / (k cos(theta) sum w p_c^2)."""
    k = 2 * np.pi / st.wavelength_m
    w = st.taper
    p = st.positions_m[:, 0]
    pc = p - np.sum(w * p) / np.sum(w)
    phi = np.asarray(phase_v)[..., st.mask]
    return -np.sum(w * pc * phi, -1) / (k * np.cos(theta) * np.sum(w * pc ** 2))


def single_fe_angles(setup, paths, gains, q=0):
    """Detected azimuth of front end ``q`` alone on the phasor model, for virtual gains
    (B, V) (the ideal radar's snapshot times each)."""
    from rtsgeom.analysis.transfer import snapshot_angles
    scene = setup.scene
    fe_az = float(setup.fe_azimuth_rad()[q])
    t = TargetConfig(2 * scene.rts.arc_radius_m + 30.0, 0.0, 10.0, fe_az)
    model = ChannelModel.build(setup, paths, (q,), t)
    return snapshot_angles(model, np.ones(1), gains)


def test_single_front_end_angle_error_matches_the_closed_form_on_a_grid():
    scene = with_channels(None, small=False)
    setup = build_setup(scene)
    paths = exact_paths(setup)
    st = Steering.build(setup.rut, scene.radar)
    rng = np.random.default_rng(7)
    # random vectors, a linear ramp over the Rx, one Rx alone, one Tx alone: 1 deg scale
    phases = [rng.normal(0, np.radians(1.0), 7) for _ in range(12)]
    phases += [np.radians([0, 0, 0, -1.5, -0.5, 0.5, 1.5]), np.radians([0, 0, 0, 0, 2, 0, 0]),
               np.radians([0, 1.0, 0, 0, 0, 0, 0])]
    ph = np.array(phases)
    g = virtual_gain(setup.rut, np.exp(1j * ph[:, :3]), np.exp(1j * ph[:, 3:]))
    phase_v = np.angle(g)
    for q in (0, 1):
        theta = float(setup.fe_azimuth_rad()[q])
        got = single_fe_angles(setup, paths, np.vstack([np.ones(st.mask.size), g]), q)
        shift = got[1:] - got[0]
        pred = closed_form_shift(st, phase_v, theta)
        assert np.max(np.abs(pred)) > np.radians(0.05)  # the errors move the angle measurably
        # first order: the rest is second order in the ~1 deg phases (a few % of the shift)
        assert np.allclose(shift, pred, rtol=0.03, atol=np.radians(2e-4)), \
            np.degrees(np.c_[shift, pred])
    # gain errors alone move a plane wave's peak only at second order (near the arc the
    # wavefront's curvature, weighted by them, moves it at first order: 0.013 deg at 1 m)
    far = build_setup(with_channels(None, small=False, far=True))
    gain_only = virtual_gain(setup.rut, antenna_gains([0.5, -0.5, 0.2], [], 3),
                             antenna_gains([1.0, -1.0, 0.5, 0.0], [], 4))
    got = single_fe_angles(far, exact_paths(far), np.vstack([np.ones(st.mask.size), gain_only]))
    assert abs(got[1] - got[0]) < np.radians(2e-4)


def test_the_chain_detects_the_same_angle_error():
    """The ADC-cube chain with CFAR detection agrees with the phasor model's shift."""
    from rtsgeom.calibration.probes import simulate_detect
    from rtsgeom.radar.processing import nearest_detection
    ch = {"rx_phase_deg": [0.0, 4.0, -3.0, 6.0], "tx_phase_deg": [0.0, 5.0, 0.0]}
    det = []
    for scene in (with_channels(None, small=False), with_channels(ch, small=False)):
        setup = build_setup(scene)
        paths = exact_paths(setup)
        prog = program_nearest(scene, setup).__class__.build(
            [0], [0], [2 * 40.0 / c - 2 * scene.rts.arc_radius_m / c], [0.0], [1e-3])
        rd, d = simulate_detect(setup, paths, prog, 0)
        n = nearest_detection(d, rd, 40.0)
        det.append(d.angle_rad[n])
    setup = build_setup(with_channels(ch, small=False))
    st = Steering.build(setup.rut, setup.scene.radar)
    pred = closed_form_shift(st, np.angle(channel_gain(setup.scene.radar, setup.rut)),
                             float(setup.fe_azimuth_rad()[0]))
    assert det[1] - det[0] == pytest.approx(pred, rel=0.05)


# -- the radar's own boresight compensation -------------------------------------------------------

def test_boresight_compensation_removes_the_error():
    """Far field: the compensation is 1 / g, every angle is as the ideal radar's. Measured on
    a reflector at the arc's radius: exact for a front end at boresight (Rx and Tx together: a
    point at the reflector's place), the reflector's wavefront curvature left as an error
    elsewhere."""
    big = {k: [5 * x for x in v] for k, v in ERR.items() if "phase" in k}
    for rng_m, angles in ((None, (0.0, 12.2)), (1.0, (0.0, 12.2))):
        extra = {} if rng_m is None else {"compensation_range_m": rng_m}
        kw = dict(small=False, angles=angles, separation=0.0)
        ideal = build_setup(with_channels(None, **kw))
        raw = build_setup(with_channels(big, **kw))
        comp = build_setup(with_channels({**big, "compensation": "boresight", **extra}, **kw))
        paths = exact_paths(ideal)
        g_raw = channel_gain(raw.scene.radar, raw.rut)
        g_comp = channel_gain(comp.scene.radar, comp.rut)
        for q in (0, 1):
            a0, a_raw, a_comp = single_fe_angles(ideal, paths, np.vstack([
                np.ones(g_raw.size), g_raw, g_comp]), q)
            assert abs(a_raw - a0) > np.radians(0.1)  # 15-60 deg errors: a large error
            if rng_m is None:
                assert abs(a_comp - a0) < np.radians(1e-6)
            elif q == 0:  # the front end at boresight, at the compensation's own range
                assert abs(a_comp) < np.radians(1e-4), np.degrees([a0, a_raw, a_comp])
            else:  # the curvature measured at boresight, taken for an error, moves it
                assert abs(a_comp - a0) > np.radians(0.1)
    # the near reflector's curvature: the reference is the two-way path difference
    rut = ideal.rut
    h = boresight_reference(rut, 1.0)
    d = (np.linalg.norm(rut.tx_local - [0, 1.0, 0], axis=1)[rut.virtual_tx]
         + np.linalg.norm(rut.rx_local - [0, 1.0, 0], axis=1)[rut.virtual_rx] - 2.0)
    assert np.allclose(np.angle(h), np.angle(np.exp(2j * np.pi * d / rut.wavelength_m)))


# -- the calibration transfer study ---------------------------------------------------------------

GOLDEN = {"tx_phase_deg": [0.0, 0.0, 3.0], "rx_phase_deg": [0.0, 2.0, -2.5, 3.5],
          "rx_gain_db": [0.0, 0.3, -0.2, 0.1]}


def test_the_draws_multiply_like_a_scene_with_those_channels():
    """The study's shortcut (the ideal radar's snapshot times each draw's gains) is the phasor
    model of a scene that carries the draw's channels."""
    from rtsgeom.analysis.transfer import draw_channel_gains, snapshot_angles
    ideal = build_setup(with_channels(None, small=False))
    paths = exact_paths(ideal)
    g, ph, gd = draw_channel_gains(ideal.rut, 3, np.radians(4.0), 0.5, 11)
    assert g.shape == (3, ideal.rut.num_virtual) and ph.shape == gd.shape == (3, 7)
    assert np.std(ph) > np.radians(1.5) and np.std(gd) > 0.15  # drawn with the spreads
    t = TargetConfig(33.5, 0.0, 10.0, np.radians(7.0))
    w = np.array([1.0, 0.8])
    got = snapshot_angles(ChannelModel.build(ideal, paths, (0, 1), t), w, g)
    for b in range(3):
        ch = {"tx_phase_deg": list(np.degrees(ph[b, :3])), "rx_phase_deg":
              list(np.degrees(ph[b, 3:])), "tx_gain_db": list(gd[b, :3]),
              "rx_gain_db": list(gd[b, 3:])}
        s = build_setup(with_channels(ch, small=False))
        model = ChannelModel.build(s, exact_paths(s), (0, 1), t)
        assert model.direction(w) == pytest.approx(got[b], abs=1e-9)


@pytest.mark.slow
def test_transfer_study_matches_the_chain_for_a_few_draws():
    """Calibrated with a golden radar (the scene's channels), the study's error per drawn radar
    is what the ADC-cube chain detects with that radar's channels and the same programme; a
    radar's own boresight compensation leaves the ideal radar's error."""
    from rtsgeom.analysis.transfer import TransferStudy
    from rtsgeom.calibration.probes import simulate_detect
    from rtsgeom.radar.processing import nearest_detection
    from rtsgeom.rts.channels import RtsProgram, requested_delay
    scene = with_channels(GOLDEN, small=False)
    setup = build_setup(scene)
    paths = exact_paths(setup)
    res = TransferStudy(radars=40, sigma_phase_deg=3.0, sigma_gain_db=0.3, points=3,
                        spec_deg=0.1, seed=3)(setup, paths)
    assert res.error_deg.shape == (40, 3) and "40 radars x 3 set-points" in repr(res)
    out = res.to_dict()
    assert set(out["angle_error_deg"]) == {"p50", "p95", "max"}
    assert out["angle_error_deg"]["p95"] > 0.1 and out["verdict"] in ("boresight", "radar")
    df = res.to_dataframe()
    assert len(df) == 41 * 3 and set(df.radar) == set(range(-1, 40))
    # the compensated radars are ideal radars: one curve, the ideal radar's on A's calibration
    assert np.ptp(res.compensated_error_deg, axis=0).max() < 1e-6
    tau = float(requested_delay(scene, res.range_m))
    for b in (0, 1, 2):
        ch = {"tx_phase_deg": list(np.degrees(res.draw_phase_rad[b, :3])),
              "rx_phase_deg": list(np.degrees(res.draw_phase_rad[b, 3:])),
              "tx_gain_db": list(res.draw_gain_db[b, :3]),
              "rx_gain_db": list(res.draw_gain_db[b, 3:])}
        s = build_setup(with_channels(ch, small=False))
        for p in (0, 2):
            a_i, a_j, o_i, o_j = res.programs[p]
            prog = RtsProgram.build([0, 0], [0, 1], [tau + o_i, tau + o_j], [0.0, 0.0],
                                    [a_i, a_j])
            rd, det = simulate_detect(s, paths, prog, 0)
            n = nearest_detection(det, rd, res.range_m)
            err = np.degrees(det.angle_rad[n]) - res.set_deg[p]
            assert err == pytest.approx(res.error_deg[b, p], abs=2e-3)


@pytest.mark.slow
def test_transfer_command_reports_the_distribution(tmp_path, capsys):
    """``rtsgeom transfer``: the JSON's percentiles and verdict, the output folder whole, and a
    bad spread refused with the option's range (exit 2)."""
    import json
    from conftest import DEFAULT_SCENE
    from rtsgeom.cli import main
    out = tmp_path / "tr"
    assert main(["transfer", str(DEFAULT_SCENE), "--radars", "30", "--sigma-phase-deg", "2",
                 "--points", "3", "--spec-deg", "0.05", "--json", "--out", str(out)]) == 0
    doc = json.loads(capsys.readouterr().out)
    for key in ("angle_error_deg", "compensated_angle_error_deg", "own_angle_error_deg"):
        e = doc[key]
        assert 0 <= e["p50"] <= e["p95"] <= e["max"]
    assert doc["radars"] == 30 and doc["set_points"] == 3 and doc["pairs"] == [[0, 1]]
    # the scene's radar is ideal: its calibration absorbed nothing
    assert doc["absorbed_offset_ps"] == [0.0] and doc["absorbed_deg"]["max"] == 0.0
    assert doc["verdict"] in ("transfers", "boresight", "recalibrate", "radar")
    assert {"transfer.json", "transfer.png"} <= {p.name for p in out.iterdir()}
    with pytest.raises(SystemExit) as exc:
        main(["transfer", str(DEFAULT_SCENE), "--sigma-phase-deg", "-1"])
    assert exc.value.code == 2
    assert "--sigma-phase-deg" in capsys.readouterr().err


def test_drawn_radars_angle_bias_has_the_closed_form_spread():
    """Each antenna's phase ~ N(0, s): the first-order bias is a sum of them, normal with
    sigma = s sqrt(sum_t c_t^2 + sum_r c_r^2) / (k cos(theta) sum p_c^2), c_t (c_r) the centred
    positions summed over the virtual elements of Tx t (Rx r): 3000 radars' own errors on a
    real target have that spread (5 %: the sampling error is 1.3 %)."""
    from rtsgeom.analysis.transfer import draw_channel_gains, own_angle_errors
    setup = build_setup(with_channels(None, small=False))
    st = Steering.build(setup.rut, setup.scene.radar)
    s = np.radians(1.0)
    g, _, _ = draw_channel_gains(setup.rut, 3000, s, 0.0, 5)
    k = 2 * np.pi / st.wavelength_m
    p = st.positions_m[:, 0]
    pc = p - p.mean()
    vt, vr = setup.rut.virtual_tx[st.mask], setup.rut.virtual_rx[st.mask]
    c_t = np.array([pc[vt == t].sum() for t in range(3)])
    c_r = np.array([pc[vr == r].sum() for r in range(4)])
    for theta in np.radians([0.0, 7.0, 30.0]):
        sigma = s * np.sqrt(np.sum(c_t ** 2) + np.sum(c_r ** 2)) / (k * np.cos(theta)
                                                                    * np.sum(pc ** 2))
        e = own_angle_errors(st, g, np.array([theta]))[:, 0]
        assert abs(np.mean(e)) < 4 * sigma / np.sqrt(e.size)
        assert np.std(e) == pytest.approx(sigma, rel=0.05)


# -- mutual coupling between neighbouring Rx -----------------------------------------------------

def test_coupling_mixes_the_neighbouring_rx_of_one_chirp():
    from rtsgeom.radar.channels import channel_coupling
    ideal, coupled = with_channels(None), with_channels({"rx_coupling_db": -20.0,
                                                         "rx_coupling_phase_deg": 45.0})
    s0, s1 = build_setup(ideal), build_setup(coupled)
    m = channel_coupling(coupled.radar, s1.rut)
    c = 0.1 * np.exp(1j * np.pi / 4)
    vt, vr = s1.rut.virtual_slot, s1.rut.virtual_rx
    want = np.where((vt[:, None] == vt[None]) & (np.abs(vr[:, None] - vr[None]) == 1), c, 0.0)
    assert np.allclose(m, np.eye(vt.size) + want)  # the AWR1843's Rx in a row at lambda / 2
    p0 = exact_paths(s0)
    e0 = build_echoes(s0, p0, program_nearest(ideal, s0))
    c0 = synthesize(e0, ideal.radar, s0.rut).data
    c1 = synthesize(e0, coupled.radar, s1.rut).data
    # the cube mixed by M; to the neighbours' beat-frequency difference, which the model
    # takes as the element's own (S x picoseconds: 2e-4 of the signal here)
    assert np.abs(c1 - np.einsum("vw,lwn->lvn", m, c0)).max() < 1e-3 * np.abs(c0).max()


def test_coupling_angle_error_and_what_a_boresight_compensation_leaves():
    """Coupling is an angle-dependent channel error: on a plane wave the virtual channels see
    phases phi_v(u) = arg((M s(u))_v / s_v(u)), and the first-order closed form of those
    phases gives the angle error at every angle; a compensation measured at boresight removes
    phi_v(0) (the error there, to 1e-6 deg), and leaves phi_v(u) - phi_v(0) elsewhere."""
    from rtsgeom.analysis.transfer import own_angle_errors
    from rtsgeom.radar.channels import channel_coupling
    for comp in ("none", "boresight"):
        scene = with_channels({"rx_coupling_db": -30.0, "rx_coupling_phase_deg": 60.0,
                               "compensation": comp}, small=False)
        setup = build_setup(scene)
        st = Steering.build(setup.rut, scene.radar)
        m = channel_coupling(scene.radar, setup.rut)
        g = channel_gain(scene.radar, setup.rut)
        theta = np.radians(np.arange(-40.0, 41.0, 10.0))
        got = own_angle_errors(st, g[None], theta, m)[0]
        s = np.conj(st.steer(st.directions(theta)))  # (P, V): the plane waves
        phi = np.angle((s @ m.T) * g / s)
        pred = closed_form_shift(st, phi, theta)
        assert np.max(np.abs(pred)) > np.radians(0.01)
        assert np.allclose(got, pred, rtol=0.05, atol=np.radians(2e-4)), \
            np.degrees(np.c_[got, pred])
        if comp == "boresight":
            assert abs(got[theta.size // 2]) < np.radians(1e-6)
            assert np.max(np.abs(got)) > np.radians(0.01)


def test_the_study_couples_like_a_scene_with_coupling():
    """With the type's Rx coupling the study's shortcut (the ideal radar's spectra coupled,
    then times each radar's gains) is the phasor model of the scene that carries both."""
    from rtsgeom.analysis.transfer import snapshot_angles
    from rtsgeom.radar.channels import channel_coupling
    ch = {"rx_coupling_db": -20.0, "rx_coupling_phase_deg": 30.0, "rx_phase_deg": [0, 5, 0, 2]}
    ideal = build_setup(with_channels(None, small=False))
    s = build_setup(with_channels(ch, small=False))
    t = TargetConfig(33.5, 0.0, 10.0, np.radians(7.0))
    w = np.array([1.0, 0.8])
    m = channel_coupling(s.scene.radar, s.rut)
    g = channel_gain(s.scene.radar, s.rut)
    got = snapshot_angles(ChannelModel.build(ideal, exact_paths(ideal), (0, 1), t), w, g[None],
                          m)[0]
    want = ChannelModel.build(s, exact_paths(s), (0, 1), t).direction(w)
    # the scene couples the echoes taking a neighbour's beat frequency as the element's own,
    # the study couples the spectra: 9e-4 deg apart here
    assert got == pytest.approx(want, abs=np.radians(2e-3))
    plain = snapshot_angles(ChannelModel.build(ideal, exact_paths(ideal), (0, 1), t), w,
                            g[None])[0]
    assert abs(plain - want) > np.radians(0.01)  # the coupling matters here


def test_info_states_the_radars_own_bias():
    """``rtsgeom info``: the radar's own angle error at each front end's azimuth (the closed
    form's, to first order); nothing for an ideal radar."""
    from rtsgeom.pipeline.info import format_info, scene_info
    ch = {"rx_phase_deg": [0.0, 2.0, -1.0, 1.5]}
    setup = build_setup(with_channels(ch))
    info = scene_info(setup)
    st = Steering.build(setup.rut, setup.scene.radar)
    phi = np.angle(channel_gain(setup.scene.radar, setup.rut))
    for q, fe in enumerate(info["front_ends"]):
        pred = closed_form_shift(st, phi, setup.fe_azimuth_rad()[q])
        assert fe["radar_channel_bias_deg"] == pytest.approx(np.degrees(pred), rel=0.03)
    assert "no RTS calibration removes it" in format_info(info)
    plain = scene_info(build_setup(with_channels(None)))
    assert all("radar_channel_bias_deg" not in fe for fe in plain["front_ends"])
