"""Delay tables through ``bin_response`` and the FIR's response (for the speed of
``design``): the shortcuts for echoes that share their geometry agree with the direct sums."""

from __future__ import annotations

import numpy as np
import pytest

from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.radar.phasors import bin_response
from rtsgeom.rts.channels import KIND_DIRECT, RtsProgram, channel_echoes
from rtsgeom.rts.fir import fir_error_response, fractional_delay_fir

from conftest import make_scene


def _horner(mu, taps, f_s, f):
    """The FIR's error response by Horner on every (setting, frequency): the reference."""
    h = fractional_delay_fir(mu, taps)
    w = 2 * np.pi * f / f_s
    z = np.exp(-1j * w)
    resp = np.zeros(w.shape, complex)
    for k in range(taps - 1, -1, -1):
        resp = resp * z + h[:, k:k + 1]
    return resp * np.exp(1j * w * ((taps - 1) / 2 + mu)[:, None])


@pytest.mark.parametrize("taps", [3, 8, 33, 129])
@pytest.mark.parametrize("f_s", [1e9, 4e9])
def test_fir_response_on_shifted_grids_is_the_direct_sum(taps, f_s):
    rng = np.random.default_rng(taps)
    mu = np.round(rng.random(300), 9)
    mu[::5] = mu[0]  # repeated settings (a delay table's)
    grid = 0.5e9 + np.linspace(0.0, 0.35 * f_s, 257)
    shift = rng.uniform(-2e6, 2e6, mu.size)
    ref = _horner(mu, taps, f_s, grid[None] + shift[:, None])
    assert np.abs(fir_error_response(mu, taps, f_s, grid, shift) - ref).max() < 1e-13 * taps
    # (M, N) rows that are shifted copies of one grid: the same response
    rows = fir_error_response(mu, taps, f_s, grid[None] + shift[:, None])
    assert np.abs(rows - ref).max() < 1e-13 * taps
    with pytest.raises(ValueError, match="f_hz"):
        fir_error_response(mu[:2], taps, f_s, np.stack([grid, grid[::-1]]))


@pytest.mark.parametrize("radius_m", [0.5, 1.0, 2.5])
@pytest.mark.parametrize("filt", ["windowed-sinc", "ideal"])
@pytest.mark.parametrize("doppler_hz", [0.0, 1.7e3])
def test_delay_table_through_bin_response_is_echo_by_echo(radius_m, filt, doppler_hz):
    """Many echoes of one channel at different RTS delays (a delay table: shared air delays)
    take the grouped path; one echo at a time takes the direct one: the same spectra."""
    def mutate(doc):
        doc["rts"]["arc_radius_m"] = radius_m
        doc["rts"]["fractional_delay_filter"] = filt
    scene = make_scene(mutate)
    setup = build_setup(scene)
    paths = exact_paths(setup)
    k = np.arange(-40, 41, 3)
    prog = RtsProgram.build(np.arange(k.size), np.full(k.size, 1), 3e-8 + k * 1e-12,
                            np.full(k.size, doppler_hz), np.ones(k.size))
    ech = channel_echoes(setup, paths, prog)
    ech = ech.select(ech.kind == KIND_DIRECT)
    assert len(ech) == k.size
    radar, rut = scene.radar, setup.rut
    r0 = int(round(radar.slope_hz_per_s * ech.tau_s.mean() * radar.samples_per_chirp
                   / radar.adc_rate_hz))
    bins = r0 + np.arange(-2, 3)  # the echoes' bin and two either side
    dop = np.full(bins.size, radar.chirps_per_tx // 2 + 1)
    table = bin_response(ech, radar, rut, bins, dop)
    one = np.concatenate([bin_response(ech.select(np.arange(len(ech)) == e), radar, rut, bins,
                                       dop) for e in range(len(ech))], axis=1)
    assert table.shape == one.shape == (bins.size, len(ech), rut.num_virtual)
    assert np.abs(table - one).max() < 1e-12 * np.abs(one).max()


@pytest.mark.parametrize("taps", [5, 33])
@pytest.mark.parametrize("step_ps", [1.0, 3.7])
def test_fir_response_does_not_depend_on_its_memo(taps, step_ps, monkeypatch):
    """The per-setting rows are memoised per process (``rts._FIR_ROWS``): a delay table's
    blocks give the same bits with the memo cleared before each block (every row computed
    for that block alone), warm, or overflowing (a memo that keeps restarting)."""
    import rtsgeom.rts.fir as rts
    f_s = 4e9
    grid = 77e6 + 29.98e12 * (1e-6 + np.arange(300) / 20e6)
    d = rts.realised_delay(7.3e-8 + np.arange(-700, 700) * step_ps * 1e-12, f_s, True, 1e-12)
    ts = 1.0 / f_s
    mu = np.round((d - np.floor(d / ts) * ts) / ts, 9)
    shift = -29.98e12 * (d + 3e-9)

    def table(clear: bool):
        out = []
        for b in range(0, mu.size, 97):
            if clear:
                rts._FIR_ROWS.clear()
            out.append(fir_error_response(mu[b:b + 97], taps, f_s, grid, shift[b:b + 97]))
        return np.concatenate(out).view(np.uint64)

    monkeypatch.setattr(rts, "_FIR_ROWS", {})
    cold = table(True)
    assert np.array_equal(table(False), cold)
    monkeypatch.setattr(rts, "_FIR_ROWS_MAX", 40)
    assert np.array_equal(table(False), cold)
    assert len(rts._FIR_ROWS) == 1


@pytest.mark.parametrize("taps", [5, 8, 33])
@pytest.mark.parametrize("f_s, step_ps", [(4e9, 1.0), (1e9, 3.7), (3.76543e9, 1.234567),
                                        (2.5e9, 25.0)])
@pytest.mark.parametrize("radius_m, doppler_hz", [(0.5, 0.0), (2.5, 1.7e3)])
def test_fir_taps_through_bin_response_are_the_fir_gain(taps, f_s, step_ps, radius_m,
                                                         doppler_hz):
    """The FIR as whole-sample copies (``rts.fir_taps``, what the delay tables use) gives the
    spectra of the FIR's gain along the chirp (``rts.fir_if_gain``, what the ADC chain
    synthesizes) to rounding: odd and even tap counts, settings on whole samples and next
    to them, delays over many buffer samples, two front ends' geometries in one call (the
    grouped path), a Doppler shift."""
    from rtsgeom.rts.fir import fir_taps

    def mutate(doc, filt="windowed-sinc"):
        doc["rts"].update(arc_radius_m=radius_m, fractional_delay_filter=filt,
                          fractional_delay_taps=taps, f_s_hz=f_s,
                          fractional_delay_step_s=step_ps * 1e-12)
    scene = make_scene(mutate)
    ideal = make_scene(lambda d: mutate(d, "ideal"))
    setup, setup_ideal = build_setup(scene), build_setup(ideal)
    paths = exact_paths(setup)
    ts_ps = 1e12 / f_s
    k = np.concatenate([np.arange(-300, 301, 7) * step_ps,  # settings over many samples
                        np.arange(-3, 4) * ts_ps,  # whole samples ...
                        np.arange(-3, 4) * ts_ps + step_ps,  # ... and one step beside them
                        np.arange(-3, 4) * ts_ps - step_ps])
    n = k.size
    prog = RtsProgram.build(np.arange(2 * n), np.repeat([0, 1], n),
                            np.tile(3e-8 + k * 1e-12, 2), np.full(2 * n, doppler_hz),
                            np.ones(2 * n))
    fir = channel_echoes(setup, paths, prog)
    plain = channel_echoes(setup_ideal, paths, prog)
    fir, plain = (e.select(e.kind == KIND_DIRECT) for e in (fir, plain))
    assert fir.fast_gain is not None and plain.fast_gain is None
    assert np.array_equal(fir.tau_if_s, plain.tau_if_s)
    t = fir_taps(scene, plain.tau_if_s, plain.tau_if_s + plain.tau_air_s.mean(axis=1))
    # (the setting rounded to 1e-9 samples: a residual where step x f_s has more decimals)
    assert np.abs(t.residual_s).max() < 1e-9 / f_s
    radar, rut = scene.radar, setup.rut
    r0 = int(round(radar.slope_hz_per_s * fir.tau_s.mean() * radar.samples_per_chirp
                   / radar.adc_rate_hz))
    bins = r0 + np.arange(-2, 3)
    dop = np.full(bins.size, radar.chirps_per_tx // 2 + 1)
    ref = bin_response(fir, radar, rut, bins, dop)
    got = bin_response(plain, radar, rut, bins, dop, t)
    assert np.abs(got - ref).max() < 1e-12 * np.abs(ref).max()
    assert fir_taps(ideal, plain.tau_if_s, plain.tau_if_s) is None
    with pytest.raises(ValueError, match="taps"):
        bin_response(fir, radar, rut, bins, dop, t)


def test_fir_taps_need_one_doppler():
    from rtsgeom.rts.fir import fir_taps
    scene = make_scene()
    setup = build_setup(scene)
    prog = RtsProgram.build(np.arange(2), np.zeros(2, int), np.full(2, 3e-8), np.array([0.0, 1e3]),
                            np.ones(2))
    ideal = build_setup(make_scene(lambda d: d["rts"].update(fractional_delay_filter="ideal")))
    ech = channel_echoes(ideal, exact_paths(setup), prog)
    t = fir_taps(scene, ech.tau_if_s, ech.tau_if_s)
    with pytest.raises(ValueError, match="one Doppler"):
        bin_response(ech, scene.radar, setup.rut, [3], [4], t)


def test_fir_taps_refuse_what_they_do_not_model():
    """Taps for other echoes than these (a row count that differs) or for cable ghosts (a
    ghost carries its direct echo's FIR, not one set to its own delay) are an error; no
    echoes give an empty table."""
    from rtsgeom.rts.channels import Echoes
    from rtsgeom.rts.fir import fir_taps
    scene = make_scene(lambda d: d["rts"].update(fractional_delay_filter="ideal"))
    fir_scene = make_scene()
    setup = build_setup(scene)
    prog = RtsProgram.build(np.arange(3), np.zeros(3, int), 3e-8 + np.arange(3) * 1e-12,
                            np.zeros(3), np.ones(3))
    ech = channel_echoes(setup, exact_paths(setup), prog)
    assert np.any(ech.kind != KIND_DIRECT)  # the default scene's cables ring
    radar, rut = scene.radar, setup.rut
    with pytest.raises(ValueError, match="direct echoes"):
        bin_response(ech, radar, rut, [3], [4], fir_taps(fir_scene, ech.tau_if_s, ech.tau_if_s))
    direct = ech.select(ech.kind == KIND_DIRECT)
    t = fir_taps(fir_scene, direct.tau_if_s, direct.tau_if_s)
    with pytest.raises(ValueError, match="one row per echo"):
        bin_response(direct, radar, rut, [3], [4], t.select(slice(0, 1)))
    none = direct.select(np.zeros(len(direct), bool))
    empty = fir_taps(fir_scene, none.tau_if_s, none.tau_if_s)
    assert empty.weights.shape == (0, fir_scene.rts.fractional_delay_taps)
    out = bin_response(none, radar, rut, [3, 4], [4, 4], empty)
    assert out.shape == (2, 0, rut.num_virtual)
    assert isinstance(none, Echoes)
