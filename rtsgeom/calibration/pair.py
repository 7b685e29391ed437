"""Calibration of a front-end pair on the simulated RuT output (paper section "Calibration").

1. Amplitude: each front end alone, its power at the RuT is measured (detections of the
   simulated radar) and compared with the model; the ratio corrects its programmed gain
   (``probes.probe_front_ends``).
2. Phase: channel J's RTS delay swept against channel I's while two probe targets synthesized
   by the pair are detected (``sweep.run_sweep``). The probes sit off mid-span on purpose: a
   target exactly between two symmetric beams keeps its angle over about half a period of
   phase error (flat-bottomed error curve), a quarter-span target gives a sharp V.

A pair on an arc (the RuT beamforms in azimuth) is measured on the phasor model
(``phasor.PhasorProbes``; the full chain on request); a pair in a 2-D beamformer, side by side
or stacked in elevation, through the full chain in both axes (``beam.BeamProbes``). The delay
offset also moves channel J's echo in range ("Disadvantages"): the reported ``range_offset_m``
is ``c0 / 2`` times the total delay mismatch of the two channels.
"""

from __future__ import annotations

import numpy as np

from .._lib.util import one_blas_thread
from ..geometry import Setup
from ..paths import Paths, nominal_model
from ..radar.steering import Steering
from .beam import BeamProbes
from .phasor import PhasorProbes
from .probes import FrontEndProbe, probe_front_ends
from .sweep import Calibration, CoherencePoint, Probes, SweepConfig, coherence_point, run_sweep

__all__ = ["pair_probes", "calibrate_pair", "pair_coherence"]


def pair_probes(setup: Setup, paths: Paths, pair, probe: FrontEndProbe | None = None,
                base_offsets=(0.0, 0.0), config: SweepConfig = SweepConfig(),
                alphas=None) -> Probes:
    """The probes that calibrate ``pair``: on the phasor model where the RuT beamforms in
    azimuth alone (``config.full_chain``: detected through the chain), through the full chain
    in its 2-D beamformer otherwise. ``probe``: the front ends' amplitude calibration (default:
    measured, ``probes.probe_front_ends``; with ``alphas``, the probe angles of a pair on an
    arc, none is needed)."""
    if probe is None:
        probe = (FrontEndProbe(np.full(setup.fe.count, np.nan), np.full(setup.fe.count, np.nan),
                               np.ones(setup.fe.count)) if alphas is not None
                 else probe_front_ends(setup, paths, config.seed))
    if Steering.auto(nominal_model(setup, paths)[0].rut, setup.scene.radar).dims == 1:
        return PhasorProbes(setup, paths, pair, probe, base_offsets, config.seed,
                            config.full_chain, alphas)
    return BeamProbes(setup, paths, pair, probe, base_offsets, config.seed)


@one_blas_thread
def calibrate_pair(setup: Setup, paths: Paths, pair: tuple[int, int],
                   probe: FrontEndProbe | None = None, base_offsets=(0.0, 0.0), *,
                   config: SweepConfig | None = None, **settings) -> Calibration:
    """Channel J's delay offset relative to channel I that makes the pair (I, J) coherent at
    the RuT (module doc; the sweep: ``sweep.run_sweep``).

    Parameters
    ----------
    setup, paths : the setup as built and its paths.
    pair : (I, J) front-end indices; J's delay is swept.
    probe : the front ends' amplitude calibration (default: measured).
    base_offsets : both channels' delay offsets before the sweep (s), e.g. from the pair
        before it on an arc.
    config : :class:`SweepConfig`; ``settings`` (its field names: ``seed``, ``span_s``,
        ``step_s``, ``frames``, ``full_chain``) change single settings.

    Returns
    -------
    Calibration
        J's delay offset (``delta_tau_s``), the sweep it was fitted on and its scatter.

    Raises
    ------
    CalibrationFailed
        No probe detected at any step of the sweep, or at too few steps for the fit.
    ParameterError
        A setting outside its range (:class:`SweepConfig`), naming it.

    BLAS runs on one thread throughout: the phasor model's products are small, and handing
    them to threads cost more than their arithmetic (the whole calibration 1.4-1.7 s CPU ->
    0.3 s on a busy 2-core machine); one thread also makes the bits independent of the
    machine's core count."""
    config = (config or SweepConfig()).evolve(**settings)
    pair = (int(pair[0]), int(pair[1]))
    return run_sweep(pair_probes(setup, paths, pair, probe, base_offsets, config), config)


def pair_coherence(setup: Setup, paths: Paths, pair, probe: FrontEndProbe | None = None,
                   near_s: float = 0.0, base_offsets=(0.0, 0.0), alphas=None) -> CoherencePoint:
    """The coherence point of ``pair`` on the setup as built nearest ``near_s``
    (``sweep.coherence_point`` with the pair's probes, :func:`pair_probes`)."""
    return coherence_point(pair_probes(setup, paths, pair, probe, base_offsets, alphas=alphas),
                           near_s)
