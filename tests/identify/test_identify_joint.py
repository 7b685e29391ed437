"""The radar's own channels identified together with the front ends' mounting errors
(rtsgeom.identify.identify_joint, rtsgeom identify --radar-channels)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from conftest import DEFAULT_SCENE, ROOT
from scipy.optimize import least_squares
from scipy.stats import chi2

from rtsgeom import identify as ident_mod
from rtsgeom.cli import main
from rtsgeom.geometry import build_setup
from rtsgeom.identify import PARAMS, fisher, joint_cramer_rao, measure
from rtsgeom.identify.joint import joint_model
from rtsgeom.paths import exact_paths
from rtsgeom.scene import load_scene
from rtsgeom.scene.channels import RadarChannelsConfig

N = len(PARAMS)
LG, PH, TANG = (PARAMS.index(p) for p in ("log_gain", "phase", "tangential_offset"))


def _nominal(path, radius_m=None, elevation=None):
    scene = load_scene(path)
    radar = scene.radar.evolve(snr_db=10.0)
    if elevation is not None:
        radar = radar.evolve(use_elevation_tx=elevation)
    rts = scene.rts if radius_m is None else scene.rts.evolve(arc_radius_m=radius_m)
    return scene.evolve(radar=radar, rts=rts)


def _built(scene, seed, mm=0.5, phase_deg=20.0, gain_db=1.0):
    """The scene as built: every antenna of the radar with a gain and phase error within
    +-``gain_db`` / +-``phase_deg`` (the references' too), every front end (the reference
    too) with mounting offsets within +-mm and a channel gain and phase. Returns the built
    scene and the truth: front-end params (F, 7) and the antennas' complex log-gains
    (N_tx + N_rx,)."""
    rng = np.random.default_rng(seed)
    rut = build_setup(scene).rut
    n_tx, n_rx, n = rut.tx_local.shape[0], rut.rx_local.shape[0], len(scene.rts.front_ends)
    a_db = rng.uniform(-gain_db, gain_db, n_tx + n_rx)
    a_ph = np.radians(rng.uniform(-phase_deg, phase_deg, n_tx + n_rx))
    off = rng.uniform(-mm, mm, (n, 3)) * 1e-3
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


def _in_gauge(model, truth_fe, ant, free, sigma2):
    """The truth as the fit's conventions express it: every parameter the fit holds (the
    references, the radial offsets, delays and yaws, an antenna no capture sees) at the
    nominal scene's value, the ``free`` ones the closest to the truth's response (noiseless
    least squares on the joint model, whitened by the captures' noise ``sigma2``). The
    conventions' null directions (Tx/Rx factor, common factor) are exact; the reference
    front end's tangential offset and a radial offset are moved into the others' (a common
    turn; the channel's phase) up to the near field's trace."""
    raw = np.r_[truth_fe[list(model.fronts)].ravel(), ant.real, ant.imag]
    start = raw.copy()
    held = np.setdiff1d(np.arange(model.size), free)
    nominal = np.r_[np.concatenate([next(m for m in model.models if m.active == q).nominal()
                                    for q in model.fronts]), np.zeros(2 * model.n_ant)]
    start[held] = nominal[held]
    w = np.repeat(1 / np.sqrt(sigma2), model.virtual_tx.size)
    target = model.respond(raw).ravel()

    def fun(x):
        t = start.copy()
        t[free] = x
        r = (model.respond(t).ravel() - target) * w
        return np.r_[r.real, r.imag]

    def jac(x):
        t = start.copy()
        t[free] = x
        j = model.jacobian(t, free)[1] * w[:, None]
        return np.r_[j.real, j.imag]

    scale = np.where(np.asarray(free) < N * len(model.fronts), 1e-3, 0.1)
    sol = least_squares(fun, start[free], jac=jac, x_scale=scale, xtol=1e-14, ftol=1e-14,
                        gtol=1e-14)
    out = start.copy()
    out[free] = sol.x
    assert np.sqrt(np.mean(sol.fun ** 2)) < 0.05  # the conventions cost < 0.05 noise std
    return out


GRID = [  # (scene, arc radius, elevated Tx, antenna phase errors within +- deg)
    (DEFAULT_SCENE, 0.8, False, 20.0), (DEFAULT_SCENE, 1.6, False, 20.0),
    (DEFAULT_SCENE, 0.8, True, 20.0), (DEFAULT_SCENE, 1.6, True, 20.0),
    (DEFAULT_SCENE, 1.0, False, 180.0),
    (ROOT / "scenes" / "custom-array.toml", None, None, 20.0),
    (ROOT / "scenes" / "template.toml", None, None, 20.0),
    (ROOT / "scenes" / "template.toml", None, None, 180.0)]


@pytest.mark.slow
@pytest.mark.parametrize("path, radius_m, elevation, phase_deg", GRID,
                         ids=[f"{p.stem}-{r}-{e}-{d:g}" for p, r, e, d in GRID])
def test_joint_fit_recovers_radar_and_mounting_within_the_crb(path, radius_m, elevation,
                                                               phase_deg):
    """On a grid of setups (the paper's radar at two arc radii with and without its elevated
    Tx, the custom non-uniform array with 3 front ends, the template's 5): antenna phase
    errors of +-20 deg (and of any phase, +-180 deg: an uncalibrated radar) and gains of +-1
    dB on every antenna, offsets within +-0.5 mm on every front end (the reference's too),
    one capture per front end at SNR 10 dB. Every front end's channel gain and phase, every
    seen antenna but the references and every tangential offset but the reference's are
    estimated; the error over all of them, against the truth as the conventions express it,
    is chi-square distributed with the Fisher information there (below its 99.9 % point),
    each within 4 std, and the std of the antennas' and the mounting estimates is the
    Cramer-Rao bound there (within 5 %)."""
    scene = _nominal(path, radius_m, elevation)
    for seed in (1,):  # one draw per setup (two took 50 s of the suite)
        built, truth, ant = _built(scene, seed + int(10 * (radius_m or 0)), phase_deg=phase_deg)
        setup = ident_mod.setup_of(built)
        paths = exact_paths(setup)
        caps = [ident_mod.simulate_capture(setup, q, seed=[seed, q], paths=paths)
                for q in range(setup.fe.count)]
        ident = ident_mod.identify(scene, caps, radar_channels=True)
        nominal = build_setup(scene)
        model = joint_model(nominal, [measure(nominal, cap, False) for cap in caps])
        r = ident.radar
        n_fe = N * len(model.fronts)
        est = np.r_[np.concatenate([f.estimate for f in ident.fits]), r.log_gain, r.phase]
        free = [N * k + i for k, f in enumerate(ident.fits) for i in f.free]
        free += [n_fe + a for a in range(model.n_ant) if r.reasons[a][0] is None]
        free += [n_fe + model.n_ant + a for a in range(model.n_ant) if r.reasons[a][1] is None]
        seen = set(np.unique(model.virtual_tx)) | set(model.n_tx + np.unique(model.virtual_rx))
        refs = {int(np.min(model.virtual_tx)), model.n_tx}
        assert {n_fe + model.n_ant + a for a in seen - refs} <= set(free)
        assert not {n_fe + model.n_ant + a for a in refs} & set(free)
        assert all({LG, PH} <= set(f.free) for f in ident.fits), [f.free for f in ident.fits]
        assert all(TANG in f.free for f in ident.fits[1:]) and TANG not in ident.fits[0].free
        sigma2 = [m.noise_variance(truth[m.active], scene.radar.snr_db) for m in model.models]
        want = _in_gauge(model, truth, ant, free, sigma2)
        err = (est - want)[free]
        phases = np.array([(i < n_fe and i % N == PH) or i >= n_fe + model.n_ant for i in free])
        err[phases] = np.angle(np.exp(1j * err[phases]))
        crb = joint_cramer_rao(model, want, sigma2, free)[free]
        std = np.r_[np.concatenate([f.std for f in ident.fits]), r.log_gain_std,
                    r.phase_std][free]
        assert np.all(np.abs(err) < 4 * std), (seed, np.abs(err) / std)
        # the std at the estimate is the bound at the truth for the antennas and the mounting;
        # a front end's channel phase shares a height's common phase, which grows with the
        # height itself: its std moves with the height's estimate (by up to 20 % here)
        asked = np.asarray([i >= n_fe or i % N not in (LG, PH) for i in free])
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
    built, _, ant = _built(scene, 5, mm=0.0)  # no common turn: the phases are the truth's
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
    with pytest.raises(SceneError) as exc:
        ident_mod.identify(comp, caps, radar_channels=True)
    assert str(exc.value) == (
        "radar.channels.compensation = 'boresight': must be \"none\" to identify the radar's "
        "channels (the radar's compensation divides its own channel errors out of every "
        "capture)")
    # a reference front end that was not captured
    from conftest import assert_refused
    from rtsgeom.identify.joint import identify_joint
    from rtsgeom.identify.model import measure
    ms = [measure(setup, caps[0], False)]
    for ref in (1, -1):
        assert_refused(lambda: identify_joint(scene, ms, reference=ref),
                       f"reference front end {ref}: must be one of the captured front ends [0]")


def test_an_antenna_gain_beyond_the_schema_is_refused_naming_it():
    """An estimated antenna gain beyond [radar.channels]' +-20 dB (a broken chain, or captures
    that are not this radar's) is refused naming the antenna, not written into an
    identified.toml that would not load; within it the fit passes unchanged."""
    from rtsgeom.errors import CaptureError
    from rtsgeom.identify import RadarChannelsFit
    from rtsgeom.identify.joint import check_radar_fit
    n = 7
    ok = ((None, None),) * n
    lg = np.zeros(n)
    lg[5] = 19.0 * np.log(10) / 20
    fit = RadarChannelsFit(lg, np.zeros(n), np.ones(n), np.ones(n), ok, 3, 0, 0, 0)
    assert check_radar_fit(fit) is fit
    lg[5] = 25.0 * np.log(10) / 20
    with pytest.raises(CaptureError, match=r"rx_gain_db\[2\] = 25"):
        check_radar_fit(RadarChannelsFit(lg, np.zeros(n), np.ones(n), np.ones(n), ok, 3, 0,
                                         0, 0))



@pytest.mark.parametrize("radius_m, seed", [(None, 3), (1.6, 4)])
def test_identifying_a_nominal_radar_finds_no_antenna_errors(radius_m, seed):
    """The joint fit (``identify(..., radar_channels=True)``) of captures simulated on the
    nominal scene itself at 30 dB SNR: an identification of that scene, one fit per front
    end, every antenna's estimated gain and phase zero to within noise (1e-2)."""
    from conftest import DEFAULT_SCENE

    from rtsgeom import identify as ident_mod
    from rtsgeom.paths import exact_paths
    from rtsgeom.scene import load_scene
    scene = load_scene(DEFAULT_SCENE)
    rts = scene.rts if radius_m is None else scene.rts.evolve(arc_radius_m=radius_m)
    scene = scene.evolve(radar=scene.radar.evolve(snr_db=30.0), rts=rts)
    setup = ident_mod.setup_of(scene)
    paths = exact_paths(setup)
    caps = [ident_mod.simulate_capture(setup, q, seed=[seed, q], paths=paths)
            for q in range(setup.fe.count)]
    ident = ident_mod.identify(scene, caps, radar_channels=True)
    assert ident.scene is scene
    assert len(ident.fits) == setup.fe.count
    np.testing.assert_allclose(ident.radar.phase, 0.0, atol=1e-2)
    np.testing.assert_allclose(ident.radar.log_gain, 0.0, atol=1e-2)
