"""The radar's own channels identified together with the front ends' mounting errors
(rtsgeom.identify.identify_joint, rtsgeom identify --radar-channels)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.stats import chi2

from conftest import DEFAULT_SCENE, ROOT
from rtsgeom import identify as ident_mod
from rtsgeom.cli import main
from rtsgeom.geometry import build_setup
from rtsgeom.identify import PARAMS, fisher, joint_cramer_rao, measure
from rtsgeom.identify.joint import joint_model
from rtsgeom.paths import exact_paths
from rtsgeom.scene import load_scene
from rtsgeom.scene.channels import RadarChannelsConfig

N = len(PARAMS)
LG, PH, TANG, RADIAL = (PARAMS.index(p) for p in ("log_gain", "phase", "tangential_offset",
                                                   "radial_offset"))


def _nominal(path, radius_m=None, elevation=None):
    scene = load_scene(path)
    radar = scene.radar.evolve(snr_db=10.0)
    if elevation is not None:
        radar = radar.evolve(use_elevation_tx=elevation)
    rts = scene.rts if radius_m is None else scene.rts.evolve(arc_radius_m=radius_m)
    return scene.evolve(radar=radar, rts=rts)


def _built(scene, seed, reference=0, mm=0.5, phase_deg=20.0, gain_db=1.0):
    """The scene as built: every antenna of the radar with a gain and phase error (the
    references' too), every front end with mounting offsets within +-mm and a channel gain and
    phase, the reference front end's tangential offset and height kept (the array-ramp gauge).
    Returns the built scene and the truth: front-end params (F, 7) and the antennas' complex
    log-gains (N_tx + N_rx,)."""
    rng = np.random.default_rng(seed)
    rut = build_setup(scene).rut
    n_tx, n_rx, n = rut.tx_local.shape[0], rut.rx_local.shape[0], len(scene.rts.front_ends)
    a_db = rng.uniform(-gain_db, gain_db, n_tx + n_rx)
    a_ph = np.radians(rng.uniform(-phase_deg, phase_deg, n_tx + n_rx))
    off = rng.uniform(-mm, mm, (n, 3)) * 1e-3
    off[reference, 1:3] = 0.0
    g_db, g_ph = rng.uniform(-1, 1, n), rng.uniform(-np.pi, np.pi, n)
    fes = tuple(f.evolve(radial_offset_m=float(o[0]), tangential_offset_m=float(o[1]),
                         height_offset_m=float(o[2]), gain_offset_db=float(g),
                         phase_offset_rad=float(p))
                for f, o, g, p in zip(scene.rts.front_ends, off, g_db, g_ph))
    ch = RadarChannelsConfig(tx_gain_db=tuple(a_db[:n_tx]), tx_phase_rad=tuple(a_ph[:n_tx]),
                             rx_gain_db=tuple(a_db[n_tx:]), rx_phase_rad=tuple(a_ph[n_tx:]))
    built = scene.evolve(radar=scene.radar.evolve(channels=ch),
                         rts=scene.rts.evolve(front_ends=fes))
    truth = np.c_[off, np.zeros(n), np.zeros(n), g_db * np.log(10) / 20, g_ph]
    return built, truth, a_db * np.log(10) / 20 + 1j * a_ph


def _in_gauge(model, truth_fe, ant):
    """The truth moved to the fit's conventions: the reference Tx and Rx at the nominal
    scene's values (0), the difference carried by every front end's channel gain (the beat
    carries conj(G) g_tx g_rx); the parameter vector of ``model``."""
    ref_tx, ref_rx = int(np.min(model.virtual_tx)), model.n_tx
    d = ant[ref_tx] + ant[ref_rx]
    a = ant.copy()
    a[:model.n_tx] -= ant[ref_tx]
    a[model.n_tx:] -= ant[ref_rx]
    fe = truth_fe.copy()
    fe[:, LG] += d.real
    fe[:, PH] -= d.imag
    want = np.r_[fe[list(model.fronts)].ravel(), a.real, a.imag]
    # a radial offset is not identifiable (it turns the response like the channel's phase,
    # but for a curvature far below the noise): the fit holds it at the scene's value and the
    # channel's gain and phase carry it, the complex factor between the two responses
    fixed = want.copy()
    for k, q in enumerate(model.fronts):
        fixed[N * k + RADIAL] = model.models[0].setup.scene.rts.front_ends[q].radial_offset_m
    y_true, y_fixed = model.respond(want), model.respond(fixed)
    for k in range(len(model.fronts)):
        mine = model.block == k
        f = np.vdot(y_fixed[mine], y_true[mine]) / np.vdot(y_fixed[mine], y_fixed[mine])
        fixed[N * k + LG] += np.log(abs(f))
        fixed[N * k + PH] -= np.angle(f)  # the beat carries conj(G)
    return fixed


GRID = [(DEFAULT_SCENE, 0.8, False), (DEFAULT_SCENE, 1.6, False), (DEFAULT_SCENE, 0.8, True),
        (DEFAULT_SCENE, 1.6, True), (ROOT / "scenes" / "custom-array.toml", None, None),
        (ROOT / "scenes" / "template.toml", None, None)]


@pytest.mark.parametrize("path, radius_m, elevation", GRID,
                         ids=[f"{p.stem}-{r}-{e}" for p, r, e in GRID])
def test_joint_fit_recovers_radar_and_mounting_within_the_crb(path, radius_m, elevation):
    """On a grid of setups (the paper's radar at two arc radii with and without its elevated
    Tx, the custom non-uniform array with 3 front ends, the template's 5): antenna phase
    errors of +-20 deg and gains of +-1 dB on every antenna, offsets within +-0.5 mm, one
    capture per front end at SNR 10 dB. The estimate's error over all free parameters is
    chi-square distributed with the Fisher information at the truth (below its 99.9 %
    point), each within 4 std, and the std of the antennas' and the mounting estimates is the
    Cramer-Rao bound at the truth (within 5 %)."""
    scene = _nominal(path, radius_m, elevation)
    for seed in (1, 2):
        built, truth, ant = _built(scene, seed + int(10 * (radius_m or 0)))
        setup = ident_mod.setup_of(built)
        paths = exact_paths(setup)
        caps = [ident_mod.simulate_capture(setup, q, seed=[seed, q], paths=paths)
                for q in range(setup.fe.count)]
        ident = ident_mod.identify(scene, caps, radar_channels=True)
        nominal = build_setup(scene)
        meas = [measure(nominal, cap) for cap in caps]
        model = joint_model(nominal, meas)
        want = _in_gauge(model, truth, ant)
        r = ident.radar
        est = np.r_[np.concatenate([f.estimate for f in ident.fits]), r.log_gain, r.phase]
        free = [N * k + i for k, f in enumerate(ident.fits) for i in f.free]
        free += [N * len(model.fronts) + a for a in range(model.n_ant) if r.reasons[a][0] is None]
        free += [N * len(model.fronts) + model.n_ant + a for a in range(model.n_ant)
                 if r.reasons[a][1] is None]
        # the captures see every antenna's pattern and every front end's tangential offset
        # but the reference's (and height with elevation elements)
        acting = set(np.unique(model.virtual_tx)) | set(model.n_tx + np.arange(model.n_rx))
        assert {N * len(model.fronts) + model.n_ant + a for a in acting} - set(free) == {
            N * len(model.fronts) + model.n_ant + int(np.min(model.virtual_tx)),
            N * len(model.fronts) + model.n_ant + model.n_tx}
        assert all(TANG in f.free for f in ident.fits[1:]) and TANG not in ident.fits[0].free
        err = (est - want)[free]
        phases = np.isin(np.asarray(free) % N, [PH]) | (np.asarray(free) >= N * len(model.fronts)
                                                         + model.n_ant)
        err[phases] = np.angle(np.exp(1j * err[phases]))
        sigma2 = [m.noise_variance(truth[m.active], scene.radar.snr_db) for m in model.models]
        crb = joint_cramer_rao(model, want, sigma2, free)[free]
        std = np.r_[np.concatenate([f.std for f in ident.fits]), r.log_gain_std,
                    r.phase_std][free]
        assert np.all(np.abs(err) < 4 * std), (seed, np.abs(err) / std)
        # the std at the estimate is the bound at the truth for the antennas and the mounting;
        # a front end's channel phase shares a height's common phase, which grows with the
        # height itself: its std moves with the height's estimate (by up to 20 % here)
        asked = np.asarray([i % N not in (LG, PH) or i >= N * len(model.fronts) for i in free])
        assert np.allclose(std[asked], crb[asked], rtol=0.05), (seed, std / crb)
        _, jac = model.jacobian(want, free)
        w = np.repeat(1 / np.sqrt(sigma2), model.virtual_tx.size)[:, None]
        q = float(err @ fisher(jac * w) @ err)
        assert q < chi2.ppf(0.999, len(free)), (seed, q, len(free))
        assert all(0.5 < f.residual_rms < 1.6 for f in ident.fits)
    fig = ident.plot()  # the mounting offsets and the antennas' phases
    assert len(fig.axes) == 2 and "radar channels" in fig._suptitle.get_text()


def test_the_gauges_change_no_capture_and_the_ramp_is_a_common_turn():
    """What no capture separates, on the joint model's own Jacobian (both front ends of the
    paper's scene, every antenna): a phase moved from every Rx to every Tx, and a phase on
    every virtual channel against each front end's channel phase, change nothing (to 1e-9); a
    phase ramp ``-k x du`` across the array is undone by the front ends' parameters to 0.4 %
    (the near field's trace), with tangential offsets ``-R_c du / cos(theta)`` (within 1 %)."""
    scene = _nominal(DEFAULT_SCENE)
    setup = build_setup(scene)
    caps = [ident_mod.simulate_capture(setup, q, seed=q) for q in range(2)]
    model = joint_model(setup, [measure(setup, cap) for cap in caps])
    theta = np.r_[np.concatenate([m.nominal() for m in model.models]), np.zeros(2 * model.n_ant)]
    _, j = model.jacobian(theta, range(model.size))
    n_fe = N * 2
    ph = n_fe + model.n_ant  # the antennas' phases
    scale = np.linalg.norm(j[:, ph:])

    def change(v):
        return np.linalg.norm(j @ v) / scale

    v = np.zeros(model.size)
    v[ph:ph + model.n_tx], v[ph + model.n_tx:] = 1.0, -1.0
    assert change(v) < 1e-9
    v = np.zeros(model.size)
    v[ph + model.n_tx:] = 1.0
    v[[PH, N + PH]] = 1.0  # the beat carries conj(G)
    assert change(v) < 1e-9
    du = 1e-3
    k = 2 * np.pi / setup.rut.wavelength_m
    ramp = np.zeros(model.size)
    ramp[ph:ph + model.n_tx] = -k * setup.rut.tx_local[:, 0] * du
    ramp[ph + model.n_tx:] = -k * setup.rut.rx_local[:, 0] * du
    turned = ramp.copy()
    for q in (0, 1):
        turned[N * q + TANG] = -scene.rts.arc_radius_m * du / np.cos(setup.fe_azimuth_rad()[q])
    assert change(turned) < 0.03 * change(ramp)  # the closed-form turn: 1.4 %
    # the best the front ends' (real) parameters can do against the ramp: least squares
    a = np.concatenate([j[:, :n_fe].real, j[:, :n_fe].imag])
    r = j @ ramp
    x, *_ = np.linalg.lstsq(a, -np.concatenate([r.real, r.imag]), rcond=None)
    best = ramp.copy()
    best[:n_fe] = x
    assert change(best) < 1e-2 * change(ramp)  # 0.4 %: the near field
    assert np.allclose(x[[TANG, N + TANG]], turned[[TANG, N + TANG]], rtol=0.01)


def test_cli_radar_channels_json_and_identified_scene(tmp_path, capsys):
    """``identify --radar-channels``: the JSON's radar_channels names the references and the
    conventions (what no capture separates, and what would), identified.toml carries the
    estimates in [radar.channels] and loads; bad combinations exit 2 with the field named."""
    scene = _nominal(DEFAULT_SCENE)
    built, _, ant = _built(scene, 5)
    setup = ident_mod.setup_of(built)
    files = []
    for q in range(2):
        cap = ident_mod.simulate_capture(setup, q, seed=q)
        f = tmp_path / f"cap{q}.npy"
        ident_mod.write_capture(cap, setup.rut, f, "npy")
        files.append(str(f))
    out = tmp_path / "id"
    assert main(["identify", str(DEFAULT_SCENE), *files, "--radar-channels", "--json",
                 "--out", str(out), "--quiet"]) == 0
    d = json.loads(capsys.readouterr().out)
    r = d["radar_channels"]
    assert r["references"] == {"tx": 0, "rx": 0, "front_end": 0}
    assert {g["name"] for g in r["fixed_by_convention"]} == {"tx_rx_factor", "common_factor",
                                                             "array_ramp"}
    assert "surveyed" in next(g["separate_by"] for g in r["fixed_by_convention"]
                              if g["name"] == "array_ramp")
    assert r["rx_phase_deg"][0] is None and "reference Rx" in r["not_identifiable"][
        "rx_phase_deg[0]"]
    assert r["tx_phase_deg"][1] is None  # the elevated Tx does not transmit here
    got = [p["value"] for p in r["rx_phase_deg"][1:]]
    truth = np.degrees(ant.imag[4:] - ant.imag[3])
    assert np.allclose(got, truth, atol=0.5)
    back = load_scene(out / "identified.toml")
    assert np.allclose(np.degrees(back.radar.channels.rx_phase_rad[1:]), got, atol=1e-5)
    assert main(["identify", str(DEFAULT_SCENE), *files, "--reference-front-end", "1"]) == 2
    assert "--radar-channels" in capsys.readouterr().err
    assert main(["identify", str(DEFAULT_SCENE), *files, "--radar-channels",
                 "--reference-front-end", "4"]) == 2
    assert "reference front end 4" in capsys.readouterr().err


def test_a_compensated_radar_is_refused_with_the_field_named():
    """A radar with its boresight compensation on divides its channel errors out of every
    capture: the joint fit refuses the scene, naming the field, instead of estimating ~0."""
    from rtsgeom.errors import SceneError
    scene = _nominal(DEFAULT_SCENE)
    setup = build_setup(scene)
    caps = [ident_mod.simulate_capture(setup, 0, seed=0)]
    comp = scene.evolve(radar=scene.radar.evolve(channels=RadarChannelsConfig(
        compensation="boresight")))
    with pytest.raises(SceneError, match="radar.channels.compensation"):
        ident_mod.identify(comp, caps, radar_channels=True)
