"""The link budget (``radar.budget``) of a target on two RTS channels (a synthesized one): its
power is the coherent sum the RuT's range-Doppler cell sees, each channel's echo with its own
beat phase (the two front ends reach the RuT over different air paths)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import make_scene
from scipy.constants import c

from rtsgeom.calibration.probes import probe_ranges
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.radar.budget import link_budget
from rtsgeom.radar.link import relative_noise_power
from rtsgeom.radar.phasors import bin_response
from rtsgeom.radar.windows import window
from rtsgeom.rts.channels import KIND_DIRECT, RtsProgram, build_echoes, requested_delay


def linked_scene(nf_db=12.0, fs_dbm=-25.0, target_m=None, **radar):
    """The paper's bench with a physical link and no snr_db; ``target_m``: one target of 10
    dBsm at that range in front end 0's direction (what ``rtsgeom info`` budgets)."""
    def mut(d):
        d["radar"].pop("snr_db", None)
        d["radar"].update(radar)
        d["radar"]["link"] = {"noise_figure_db": nf_db, "adc_full_scale_dbm": fs_dbm}
        if target_m is not None:
            d["targets"] = [{"range_m": target_m, "velocity_mps": 0.0, "angle_deg": 3.4,
                             "rcs_dbsm": 10.0}]
    return make_scene(mut)


def scalloping_db(radar, range_m: float) -> float:
    """The range window's gain (dB) at the target's fractional bin against the bin centre
    (``|sum w_n e^{j 2 pi d n / N}| / sum w_n``, d the offset from the nearest bin)."""
    n = radar.samples_per_chirp
    frac = range_m * 2 * radar.slope_hz_per_s / c * n / radar.adc_rate_hz
    d = frac - round(frac)
    w = window(radar.range_window, n)
    return 20 * math.log10(abs(np.sum(w * np.exp(2j * np.pi * d * np.arange(n) / n)))
                           / np.sum(w))


@pytest.mark.parametrize("ratio", [0.3, 1.0, 3.0])
@pytest.mark.parametrize("off_j_ps", [0.0, 5.0, -10.0])
def test_a_synthesized_targets_budget_snr_is_its_cells(ratio, off_j_ps):
    """Front ends 0 and 1 (8.8 deg apart) programmed with amplitudes (1, ratio) and J's delay
    moved by ``off_j_ps``: the budget's post-FFT SNR is the cell's (the windowed DFTs of every
    echo with its phase, ``radar.phasors.bin_response``, at the strongest range bin) over the
    link's noise through the same windows, within 0.05 dB once the range window's scalloping
    is counted (the budget counts the bin centre; J's delay offsets of tens of ps, which move
    its tone by a tenth of a bin and turn its windowed DFT's phase, leave 0.1-0.2 dB). Before,
    the budget summed the channels' echo amplitudes without their beat phases: 0.85 to 1.25
    dB high."""
    rng_m = float(probe_ranges(build_setup(linked_scene()), 1)[0])
    scene = linked_scene(target_m=rng_m)
    radar = scene.radar
    setup = build_setup(scene)
    tau = float(requested_delay(scene, rng_m))
    amps = 10.0 * np.array([1.0, ratio])  # about the paper target's programme (50 dB)
    prog = RtsProgram.build([0, 0], [0, 1], [tau, tau + off_j_ps * 1e-12], [0.0, 0.0],
                            list(amps))
    echoes = build_echoes(setup, exact_paths(setup), prog)
    b = link_budget(scene, echoes, prog, linked=False, predict=True, setup=setup)
    direct = echoes.select(echoes.kind == KIND_DIRECT)
    r0 = round(rng_m * 2 * radar.slope_hz_per_s / c * radar.samples_per_chirp
               / radar.adc_rate_hz)
    rbins = np.arange(r0 - 1, r0 + 2)
    cell = bin_response(direct, radar, setup.rut, rbins,
                        np.full(3, radar.chirps_per_tx // 2)).sum(axis=1)  # (K, V)
    p_cell = float(np.max(np.mean(np.abs(cell) ** 2, axis=-1)))
    n_rel = float(relative_noise_power(scene, float(np.sum(amps ** 2)),
                                       radar.slope_hz_per_s * 2 * rng_m / c))
    g = (np.sum(window(radar.range_window, radar.samples_per_chirp) ** 2)
         * np.sum(window(radar.doppler_window, radar.chirps_per_tx) ** 2))
    cell_db = 10 * math.log10(p_cell / (n_rel * g))
    assert b.targets[0]["snr_after_fft_db"] + scalloping_db(radar, rng_m) == \
        pytest.approx(cell_db, abs=0.05)
