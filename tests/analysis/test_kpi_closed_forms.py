"""The datasheet's (``analysis.kpi``) noise and range rows against their closed forms: the
receiver noise's angle uncertainty (the beamformer peak's first-order noise), the SNR it is
taken at (``radar.snr_db``, or the link budget under ``[radar.link]``) and the range span the
setup emulates (the RTS's air path and FIR latency, the radar's range axis less its window's
main lobe and the CFAR ring)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import ROOT, make_scene
from radar.test_budget_synthesized import linked_scene as _linked
from radar.test_budget_synthesized import scalloping_db as _scalloping_db
from scipy.constants import c

import rtsgeom
from rtsgeom.analysis.kpi import accuracy as acc
from rtsgeom.analysis.kpi.accuracy import (AccuracyInputs, _noise_row, _Point, effective_snr,
                                           link_snr, pair_accuracy)
from rtsgeom.analysis.kpi.sections import range_velocity
from rtsgeom.analysis.transfer import ideal_radar, set_angles
from rtsgeom.calibration.probes import probe_front_ends, probe_ranges
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.radar.budget import link_budget, static_budget
from rtsgeom.radar.channels import channel_coupling
from rtsgeom.radar.steering import Steering
from rtsgeom.radar.windows import window
from rtsgeom.rts.channels import RtsProgram, build_echoes, requested_delay
from rtsgeom.scene import TargetConfig
from rtsgeom.synthesis.model import ChannelModel

NOISE_ROW = "receiver noise"


def _noise(point):
    return next(r for r in point.budget if r.quantity.startswith(NOISE_ROW))


# -- the noise row: the beamformer peak's angle noise -----------------------------------------

def _peak_noise_deg(st: Steering, theta: float, u: float) -> float:
    """Standard deviation (deg) of the tapered beamformer's peak for a plane wave at ``theta``
    with I and Q noise of standard deviation ``u`` (relative to the element amplitude) on each
    element: to first order ``d sin(theta) = sum t x Im(n) / (k sum t x^2)`` about the taper's
    centroid, so ``sigma = u sqrt(sum t^2 x^2) / (k cos(theta) sum t x^2)``; untapered
    ``1 / (k cos(theta) sqrt(2 SNR sum x^2))`` (the single-source Cramer-Rao bound)."""
    x, t = st.positions_m[:, 0], st.taper
    x = x - np.sum(t * x) / np.sum(t)
    k = 2 * math.pi / st.wavelength_m
    return math.degrees(u * math.sqrt(np.sum(t * t * x * x))
                        / (k * math.cos(theta) * np.sum(t * x * x)))


@pytest.mark.parametrize("scene", [
    pytest.param(lambda: make_scene(), id="awr1843-none"),
    pytest.param(lambda: make_scene(angle_window="hann"), id="awr1843-hann"),
    pytest.param(lambda: make_scene(angle_window="blackman", use_elevation_tx=True),
                 id="awr1843-12ch-blackman"),
    pytest.param(lambda: rtsgeom.load_scene(ROOT / "scenes" / "custom-array.toml"),
                 id="custom-nonuniform")])
def test_the_noise_row_is_the_beamformer_peaks_angle_noise(scene):
    """One front end alone (a plane wave up to the near field) at 15, 30 and 50 dB SNR: the
    noise row's contribution, from the coefficients of every channel's I and Q, is the closed
    form's standard deviation within 1.5 %, on uniform and non-uniform arrays, with and
    without an angle taper."""
    scene = scene()
    setup = build_setup(scene)
    paths, ideal, rut = exact_paths(setup), ideal_radar(setup), setup.rut
    st = Steering.build(rut, scene.radar)
    rng_m = float(probe_ranges(setup, 1)[0])
    for q in (0, 1):
        alpha = float(setup.fe_azimuth_rad()[q])
        pt = _Point(ideal, paths, (0, 1), TargetConfig(rng_m, 0.0, 10.0, alpha), 0.0,
                    np.eye(2)[q], st, channel_coupling(scene.radar, rut),
                    np.ones(rut.num_virtual, complex))
        theta = alpha + math.radians(float(pt.error_deg()[0]))  # where the RuT sees it
        for snr_db in (15.0, 30.0, 50.0):
            snr = 10 ** (snr_db / 10)
            u = 1 / math.sqrt(2 * snr)
            row = _noise_row(pt, rut, u, snr, "test")
            assert row.standard_uncertainty == u
            assert row.contribution_deg == pytest.approx(_peak_noise_deg(st, theta, u),
                                                         rel=0.015), (q, snr_db)


@pytest.mark.parametrize("snr_db, n_s, n_c, win", [
    (10.0, 512, 120, ("hann", "hann")), (-5.0, 256, 64, ("none", "blackman")),
    (25.0, 128, 32, ("hamming", "none"))])
def test_the_snr_of_snr_db_is_the_ffts_coherent_gain_with_the_window_losses(snr_db, n_s, n_c,
                                                                           win):
    """``radar.snr_db`` per sample times N_s N_c and each window's loss (sum w)^2 / (N sum
    w^2): the processing gain of two coherent sums of white noise."""
    scene = make_scene(snr_db=snr_db, samples_per_chirp=n_s, chirps_per_tx=n_c,
                       range_window=win[0], doppler_window=win[1])
    w_r, w_d = window(win[0], n_s), window(win[1], n_c)
    gain = np.sum(w_r) ** 2 / np.sum(w_r ** 2) * np.sum(w_d) ** 2 / np.sum(w_d ** 2)
    assert effective_snr(scene.radar) == pytest.approx(10 ** (snr_db / 10) * gain, rel=1e-12)


# -- the SNR under [radar.link] ----------------------------------------------------------------

@pytest.mark.parametrize("nf_db, fs_dbm, radar", [
    (12.0, -25.0, {}), (40.0, -25.0, {}), (15.0, -60.0, {}),  # thermal, thermal, quantisation
    (20.0, -25.0, {"range_window": "none"}), (20.0, -25.0, {"samples_per_chirp": 256})])
def test_the_link_snr_at_the_cell_is_the_link_budgets(nf_db, fs_dbm, radar):
    """The datasheet's target (its range, 10 dBsm) on front end 0 alone: the SNR at the
    detection cell is the link budget's post-FFT SNR that ``rtsgeom info`` prints for that
    target (thermal, RTS channel and quantisation noise), less the range window's
    scalloping at the target's fractional bin (the budget counts the bin centre)."""
    rng_m = float(probe_ranges(build_setup(_linked(nf_db, fs_dbm, **radar)), 1)[0])
    scene = _linked(nf_db, fs_dbm, rng_m, **radar)
    setup = build_setup(scene)
    budget_db = static_budget(setup).targets[0]["snr_after_fft_db"]
    model = ChannelModel.build(setup, exact_paths(setup), (0, 1),
                               TargetConfig(rng_m, 0.0, 10.0, math.radians(3.4)))
    got_db = 10 * math.log10(link_snr(scene, model, np.array([model.unit_gain, 0.0])))
    assert got_db == pytest.approx(budget_db + _scalloping_db(scene.radar, rng_m), abs=0.05)


@pytest.fixture(scope="module")
def linked_points():
    """The paper's pair's accuracy at three set angles under the link at NF 12 and 40 dB, and
    each set angle's planned programme (the point the noise row was taken on)."""
    out = {}
    for nf in (12.0, 40.0):
        scene = _linked(nf)
        setup = build_setup(scene)
        paths = exact_paths(setup)
        probe = probe_front_ends(setup, paths, scene.seed)
        angles = set_angles(setup, probe, (0, 1), 3)
        inputs = AccuracyInputs((1e-4,) * 3, 0.0, effective_snr(scene.radar), 2000, 1)
        seen = []

        def spy(pt, *args, _row=acc._noise_row):
            seen.append(pt)
            return _row(pt, *args)
        with pytest.MonkeyPatch.context() as mp:
            mp.setattr(acc, "_noise_row", spy)
            points = pair_accuracy(setup, ideal_radar(setup), paths, (0, 1), probe, angles,
                                   inputs)
        out[nf] = (scene, points, seen)
    return out


def _programme_budget_snr_db(scene, pt) -> float:
    """The link budget's post-FFT SNR (``run``'s ``summary.json``) of the set angle's
    programme: the target (its range, 10 dBsm) on both channels with the planned amplitudes
    and J's delay offset, the window's scalloping at its fractional bin added."""
    t = pt.target
    scene_t = _linked(scene.radar.link.noise_figure_db, scene.radar.link.adc_full_scale_dbm,
                      t.range_m)
    setup = build_setup(scene_t)
    tau = float(requested_delay(scene_t, t.range_m))
    prog = RtsProgram.build([0, 0], list(pt.pair), [tau, tau + pt.off_j], [0.0, 0.0],
                            [float(a) for a in np.abs(pt.w)])
    echoes = build_echoes(setup, exact_paths(setup), prog)
    b = link_budget(scene_t, echoes, prog, linked=False, predict=True, setup=setup)
    return b.targets[0]["snr_after_fft_db"] + _scalloping_db(scene.radar, t.range_m)


def test_a_linked_scene_without_snr_db_has_the_link_budgets_receiver_noise(linked_points):
    """``[radar.link]`` and no ``snr_db``: the chain adds thermal + RTS channel noise
    (``radar.frame``), so the budget's noise row is not zero: its SNR at each set angle is the
    link budget's for that set angle's programme (within 0.05 dB), its u = 1 / sqrt(2 SNR),
    and the Monte Carlo widens with it (its interval still U's). Before, the datasheet saw
    such a scene as noiseless: the row 0, U 0.010 deg at NF 40 dB where it is 0.56-0.61 deg."""
    for nf, (scene, points, seen) in linked_points.items():
        assert len(seen) == len(points)
        for p, pt in zip(points, seen):
            row = _noise(p)
            want_db = _programme_budget_snr_db(scene, pt)
            assert p.snr_effective_db == pytest.approx(want_db, abs=0.05), (nf, p.set_deg)
            assert row.standard_uncertainty == pytest.approx(
                1 / math.sqrt(2 * 10 ** (want_db / 10)), rel=0.01)
            assert row.contribution_deg > 0 and "link budget" in row.note
    hi, lo = linked_points[40.0][1], linked_points[12.0][1]
    # 28 dB more noise figure, thermal-dominated: the angle noise about 10^(28/20) = 25 x
    for a, b in zip(hi, lo):
        assert 15 < _noise(a).contribution_deg / _noise(b).contribution_deg < 26
        assert a.expanded_deg > 0.3 and a.validated
        assert a.mc_half_width_deg == pytest.approx(a.expanded_deg, rel=0.1)


# -- the range span -----------------------------------------------------------------------------

MAINLOBE_BINS = {"none": 1, "hann": 2, "hamming": 2, "blackman": 3}  # first nulls, in bins


@pytest.mark.parametrize("radar, rts, cfar", [
    ({}, {}, {}),
    ({"range_window": "none", "bandwidth_hz": 2e9}, {"fractional_delay_taps": 17},
     {"guard_cells": [1, 1], "training_cells": [4, 2]}),
    ({"range_window": "blackman", "adc_rate_hz": 6.25e6, "samples_per_chirp": 256,
      "position_m": [0.05, -0.2, 0.0]}, {"arc_radius_m": 2.5, "arc_center_m": [0.0, 0.0, 0.0]},
     {}),
    ({"position_m": [0.0, -0.3, 0.0]},
     {"compensate_air_path": False, "fractional_delay": False, "arc_center_m": [0.0, 0.0, 0.0]},
     {}),
])
def test_the_range_span_is_the_air_path_fir_and_the_range_axis(radar, rts, cfar):
    """Minimum: the arc radius the RTS subtracts (or, without the subtraction, the RuT's
    farthest air path to a front end) plus the FIR's (taps - 1)/2 samples at f_s; maximum:
    the complex ADC's f_adc c / (2 S) less (main lobe + CFAR guard + training) range bins, less
    the air path the RTS does not subtract; over windows, CFAR rings, chirps, arc radii and
    the RuT off the arc's centre."""
    def mut(d):
        d["radar"].update(radar)
        d["radar"].setdefault("cfar", {}).update(cfar)
        d["rts"].update(rts)
        d["targets"] = []  # (the paper's targets lie beyond some of these range axes)
        if not d["rts"].get("fractional_delay", True):  # whole samples: a coarser sweep
            d["rts"]["calibration_step_ps"] = 250.0
    scene = make_scene(mut)
    setup = build_setup(scene)
    r, s = scene.radar, scene.rts
    slope = r.bandwidth_hz / r.chirp_duration_s
    axis = r.adc_rate_hz * c / (2 * slope)
    bins = MAINLOBE_BINS[r.range_window] + r.cfar.guard_cells[0] + r.cfar.training_cells[0]
    # the arc's centre: the RuT's phase centre unless given
    centre = np.asarray(r.position_m if s.arc_center_m is None else s.arc_center_m, float)
    az = np.asarray([fe.angle_rad for fe in s.front_ends])
    modules = centre + s.arc_radius_m * np.stack([np.sin(az), np.cos(az), 0 * az], axis=1)
    air = float(np.max(np.linalg.norm(modules - np.asarray(r.position_m), axis=1)))
    fir = (s.fractional_delay_taps - 1) / 2 / s.f_s_hz * c / 2 if s.fractional_delay else 0.0
    unsubtracted = max(0.0, air - s.arc_radius_m) if s.compensate_air_path else air
    rv = range_velocity(setup, None)
    assert rv["min_range_m"] == pytest.approx(
        (s.arc_radius_m if s.compensate_air_path else air) + fir, rel=1e-9)
    assert rv["max_range_m"] == pytest.approx(axis - bins * axis / r.samples_per_chirp
                                              - unsubtracted, rel=1e-9)
    assert rv["range_resolution_m"] == pytest.approx(c / (2 * slope * r.samples_per_chirp
                                                          / r.adc_rate_hz), rel=1e-9)
