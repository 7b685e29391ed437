"""Measure a built setup from radar captures: each front end's mounting errors and each RTS
channel's gain, phase and delay, by nonlinear least squares on the RuT's own output.

With one front end active and a probe target programmed, the RuT's spectrum at the probe's
range-Doppler bin, per virtual element ``v``, is (paper eqs. 8, 15/16 with the exact legs)::

    y_v = conj(G_q A g_a,v g_b,v) exp(j 2 pi [f_c tau_air,v + f_rts tau_if - S tau_v^2/2])
          * R_r(S tau_v + f_D) D_d(f_D)                                            (+ noise)

``tau_air,v = |RuT Tx_m - FE Rx| / c0 + |FE Tx - RuT Rx_k| / c0`` moves with the front end's
radial, tangential and height offsets and its yaw (``arcmath.antenna_positions``), ``tau_if``
with the channel's delay offset, ``G_q`` is the channel's complex gain. :class:`ProbeModel`
evaluates this for a batch of parameter vectors at once (``radar.phasors.bin_response``, the
same kernels the simulator is tested against); :func:`identify` fits it with
``scipy.optimize.least_squares``, the Jacobian by batched central differences (one model call
for all columns), the residuals whitened by the noise measured in the capture's own
range-Doppler map. The covariance is the inverse Fisher information ``F = 2 Re(J^H J)`` of the
whitened Jacobian: at the truth and with the true noise it is the Cramer-Rao bound
(:func:`cramer_rao`).

Not every parameter is visible in one capture: a channel delay offset turns the response's phase
(at f_rts) like the channel's phase, and a radial offset does the same (at f_c) except for a
near-field curvature far below the noise. :func:`free_parameters` finds such directions from the
Fisher information's eigenvalues (normalised to unit diagonal, a correlation-like matrix) and
fixes the parameter least worth keeping at its nominal value; the output then says why and which
extra capture separates it. Fixed or not, the fitted response is the measured one, so the
*combination* that coherence between two channels depends on (channel phase + radial offset +
delay offset) is measured: :func:`predicted_calibration` gives the pair's calibration delay
without a sweep.

The package, by concept: :mod:`.model` (the forward model and the measurement),
:mod:`.fit` (identifiability, the fit, the Cramer-Rao bound), :mod:`.joint` (the radar's
own antenna gains and phases fitted with every front end), :mod:`.identification` (the
entry point and its result), :mod:`.built` (the setup as
built: corrected scene, calibration without a sweep), :mod:`.crb` (the bound versus SNR and
arc radius). Everything is importable from ``rtsgeom.identify``.

Calling the package, ``rtsgeom.identify(scene, captures, ...)``, is
:func:`~rtsgeom.identify.identification.identify`.

Parameters
----------
scene, captures, accept_misfit, radar_channels, reference
    As :func:`~rtsgeom.identify.identification.identify`: the nominal scene, its probe
    captures, whether a misfit is kept (flagged), whether the radar's channels are fitted,
    the reference front end.

Returns
-------
Identification
    Each front end's fit and, with ``radar_channels``, the radar's channels.

Raises
------
ParameterError, CaptureError
    As :func:`~rtsgeom.identify.identification.identify`.
"""

from __future__ import annotations

import sys
import types

from .capture import Capture, capture_probe, read_capture, simulate_capture, write_capture
from .built import (PredictedCalibration, calibrate_from_identified, detected_angles,
                    identified_scene, identified_scene_toml, predicted_calibration, setup_of)
from .crb import crb_figure, crb_grid
from .fit import (ESTIMATE_LIMITS, MIN_EIGENVALUE, RESIDUAL_LIMIT, SEPARATE_BY, STD_LIMIT,
                  FrontEndFit, check_fit, cramer_rao, fisher, fit_front_end, free_parameters)
from .identification import Identification, identify
from .joint import GAUGES, JointModel, RadarChannelsFit, identify_joint, joint_cramer_rao
from .model import PARAMS, ProbeModel, measure


class _Package(types.ModuleType):
    """This package, callable as its entry point: ``rtsgeom.identify(scene, captures)`` is
    :func:`identify` (the name of the command and of the function), while
    ``rtsgeom.identify.read_capture`` and ``from rtsgeom.identify import ...`` stay the
    package's. (A plain function of that name at the top level would be shadowed by the
    package as soon as it is imported.)"""

    def __call__(self, *args, **kwargs):
        return identify(*args, **kwargs)


sys.modules[__name__].__class__ = _Package

__all__ = ["PARAMS", "Capture", "ProbeModel", "FrontEndFit", "Identification", "capture_probe",
           "simulate_capture", "write_capture", "read_capture", "measure", "fisher",
           "free_parameters", "fit_front_end", "identify", "cramer_rao", "STD_LIMIT",
           "MIN_EIGENVALUE", "SEPARATE_BY", "identified_scene", "identified_scene_toml",
           "setup_of", "detected_angles", "PredictedCalibration", "predicted_calibration",
           "calibrate_from_identified", "crb_grid", "crb_figure", "RESIDUAL_LIMIT",
           "ESTIMATE_LIMITS", "check_fit", "GAUGES", "JointModel", "RadarChannelsFit",
           "identify_joint", "joint_cramer_rao"]
