"""Many channel models at once: :func:`build_models`, what ``ChannelModel.build`` gives for each
of a batch of (channels, target, delays) from one programme of all their echoes. A drive's
planning builds two models per target and frame; built together they cost a fraction."""

from __future__ import annotations

import numpy as np
from scipy.constants import c

from ..geometry import Setup
from ..paths import Paths
from ..radar.phasors import bin_response_rows
from ..radar.steering import Steering
from ..rts.channels import (KIND_DIRECT, RtsProgram, channel_echoes, nominal_link_gain,
                            requested_delay, target_amplitude)
from .model import ChannelModel, require_air_path_compensation

__all__ = ["build_models"]


def build_models(setup: Setup, paths: Paths, channels, targets, delta_tau_s,
                 half_bins: int = 1, steering: Steering | None = None) -> list[ChannelModel]:
    """``ChannelModel.build`` for many (channels, target, delays) at once: ``channels`` (M, Q),
    ``targets`` (M,) ``TargetConfig``, ``delta_tau_s`` (M, Q). The echoes of all M models
    in one programme and one pass of ``radar.phasors.bin_response_rows`` (each echo at
    its model's bins), each model's responses summed per channel as ``build`` does:
    the same models (to the BLAS products' rounding) at a fraction of the per-model cost
    (a drive's planning builds two per target and frame)."""
    scene, radar = setup.scene, setup.scene.radar
    require_air_path_compensation(scene)
    if len(targets) == 0:
        return []
    ch = np.asarray(channels, int).reshape(len(targets), -1)
    n_m, n_q = ch.shape
    dtau = np.asarray(delta_tau_s, float).reshape(n_m, n_q)
    lam = setup.rut.wavelength_m
    f_d = np.array([2 * radar.f_c_hz * t.velocity_mps / c for t in targets])
    tau = np.array([float(requested_delay(scene, t.range_m)) for t in targets])
    prog = RtsProgram.build(np.arange(n_m * n_q), ch.ravel(), (tau[:, None] + dtau).ravel(),
                            np.repeat(f_d, n_q), np.ones(n_m * n_q))
    ech = channel_echoes(setup, paths, prog)
    ech = ech.select(ech.kind == KIND_DIRECT)  # ghosts land bins away
    rng = np.array([t.range_m for t in targets])
    rbin = rng * 2 * radar.slope_hz_per_s / c * radar.samples_per_chirp / radar.adc_rate_hz
    h = int(half_bins)
    rbins = ((np.round(rbin).astype(int)[:, None] + np.arange(-h, h + 1))
             % radar.samples_per_chirp)  # (M, K)
    dbins = ((np.round(f_d * radar.tdm_cycle_s * radar.chirps_per_tx).astype(int)
              + radar.chirps_per_tx // 2) % radar.chirps_per_tx)  # (M,)
    model = ech.target // n_q
    resp = bin_response_rows(ech, radar, setup.rut, rbins[model],
                             np.repeat(dbins[model][:, None], rbins.shape[1], 1))
    counts = np.bincount(ech.target, minlength=n_m * n_q)
    if np.all(counts == 1):  # one echo per channel (line of sight): no sums
        per_q = resp[:, np.argsort(ech.target)].reshape(resp.shape[0], n_m, n_q, -1)
    else:  # each channel's echoes summed in echo order, as build does
        per_q = np.stack([np.stack([resp[:, ech.target == m * n_q + q].sum(1)
                                    for q in range(n_q)], 1) for m in range(n_m)], 1)
    st = Steering.build(setup.rut, radar) if steering is None else steering
    gain = nominal_link_gain(scene, lam)
    out = []
    for m, t in enumerate(targets):
        amp = target_amplitude(t.range_m, t.rcs_m2, lam) / gain
        out.append(ChannelModel(setup, tuple(int(q) for q in ch[m]), per_q[:, m], float(f_d[m]),
                       float(amp), float(t.range_m), st))
    return out
