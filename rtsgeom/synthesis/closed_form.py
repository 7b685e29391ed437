"""The closed forms of the arbitrary-angle synthesis (paper section "Arbitrary Angle of Arrival",
eqs. 17-23) for a pair, and the far-field closed form for any set of channels in D dimensions
(:func:`closed_form_amplitudes`).

Two adjacent channels I, J generate the same range and Doppler; their amplitude ratio
``rho = A_J / A_I`` steers the beamformer peak between the two front ends. Three modes:

``paper``
    eq. (22)/(23) as printed: g_q is the derivative of sinc((sin theta_q - sin alpha)/2), and
    the ratio follows from A_I g_I + A_J g_J = 0, i.e. ``A_I / A_J = -g_J / g_I`` (the printed
    eq. 23 drops the minus sign; between the beams the ratio is positive only with it). The
    sinc is not the beam of an N_A-element array, which costs ~0.3 deg mid-span.
``array-factor``
    the same condition with the true array factor ``sin(N_A pi u / 2) / sin(pi u / 2)``,
    ``u = sin theta_q - sin alpha`` (lambda/2 spacing): exact in the ideal far field.
``exact``
    ``rho`` solved numerically so that the RuT's own beamformer output -- from the per-element
    geometry through the windowed range/Doppler DFTs (``radar.phasors``) -- peaks at the set
    angle: near field, Rx/Tx separation, real element positions, windowing, calibration delay
    (:class:`~rtsgeom.synthesis.model.ChannelModel`).

With more channels, or in azimuth and elevation, the ``array-factor`` closed form is
:func:`closed_form_amplitudes`: channel q's beam is the array factor
AF_q(u) = sum_v t_v e^{j k p_v . (u - u_q)} / sum_v t_v (u_q: the front end's direction
cosines seen from the RuT); the peak condition ``d|B|^2/du = 0`` at u* with B real there is
linear in the amplitudes a: ``G a = 0``, ``G_dq = Re(e^{j phi_q} dAF_q/du_d (u*))``,
phi_q = -arg AF_q(u*) (coherent at u*). Of the solutions the one with the largest peak power
per unit norm, ``a = P_null(G) f``, f_q = |AF_q(u*)| (for a triangle the null space is one
line; for the pair it is eq. 22/23 with the true array factor, :func:`ratio_array_factor`).
"""

from __future__ import annotations

import itertools

import numpy as np

from ..errors import AngleUnreachable
from ..radar.steering import Steering

__all__ = ["g_paper", "ratio_paper", "array_factor", "ratio_array_factor", "array_factor_args",
           "closed_form_amplitudes"]


def g_paper(theta, alpha):
    """Paper eq. (22): derivative substitute of sinc((sin theta - sin alpha) / 2).

    Near u = sin theta - sin alpha = 0 the two terms cancel catastrophically; there its series
    -u/6 + u^3/240 is used."""
    u = np.asarray(np.sin(theta) - np.sin(alpha), float)
    small = np.abs(u) < 1e-3
    us = np.where(small, 1.0, u)
    exact = 2 * np.cos(us / 2) / us - 4 * np.sin(us / 2) / us ** 2
    return np.where(small, -u / 6 + u ** 3 / 240, exact)


def ratio_paper(theta_i, theta_j, alpha):
    """A_J / A_I from eq. (23) with the sign fixed: A_I g_I + A_J g_J = 0."""
    return -g_paper(theta_i, alpha) / g_paper(theta_j, alpha)


def array_factor(u, n: int = 0, positions_wl=None, weights=None):
    """Normalised array factor: of ``n`` elements at lambda/2, sin(n pi u/2) / (n sin(pi u/2));
    or, with ``positions_wl`` (element positions in wavelengths, any spacing, sparse,
    non-uniform or repeated) and optional ``weights`` (the beamformer's taper per element),
    the real part of sum_k w_k exp(j 2 pi x_k u) / sum_k w_k about the weighted centroid (the
    same Dirichlet kernel for a filled untapered lambda/2 array; exact for a symmetric array
    and taper). This is the beamformer output of eq. (14) for one plane wave, u = sin theta -
    sin alpha."""
    u = np.asarray(u, float)
    if positions_wl is not None:
        x = np.asarray(positions_wl, float)
        w = np.ones_like(x) if weights is None else np.asarray(weights, float)
        x = x - np.sum(w * x) / np.sum(w)
        return np.cos(2 * np.pi * u[..., None] * x) @ w / np.sum(w)
    den = n * np.sin(np.pi * u / 2)
    small = np.abs(den) < 1e-12
    return np.where(small, 1.0, np.sin(n * np.pi * u / 2) / np.where(small, 1.0, den))


def ratio_array_factor(theta_i, theta_j, alpha, n: int = 0, h: float = 1e-6,
                       positions_wl=None, weights=None):
    """A_J / A_I with the true array factor: A_I AF_I'(alpha) + A_J AF_J'(alpha) = 0
    (``n`` lambda/2 elements, or the positions ``positions_wl`` and taper ``weights`` of
    :func:`array_factor`)."""
    def d_af(theta):
        return (array_factor(np.sin(theta) - np.sin(alpha + h), n, positions_wl, weights)
                - array_factor(np.sin(theta) - np.sin(alpha - h), n, positions_wl,
                               weights)) / (2 * h)
    return -d_af(theta_i) / d_af(theta_j)


def array_factor_args(steering) -> dict:
    """The keyword arguments of :func:`ratio_array_factor` that make its array factor the RuT's
    own azimuth beamformer (:class:`~rtsgeom.radar.steering.Steering`, D = 1): a filled,
    untapered lambda/2 row without repeated elements is the closed form in ``n``; anything
    else (a taper, repeated virtual elements such as the cascade's 144 on 86 positions, gaps,
    another spacing) its element positions and taper weights."""
    x = np.asarray(steering.positions_m)[:, 0] / steering.wavelength_m
    w = np.asarray(steering.taper, float)
    xs = np.sort(x)
    if (x.size > 1 and np.all(w == w[0])
            and np.allclose(np.diff(xs), 0.5, rtol=1e-9, atol=1e-12)):
        return {"n": int(x.size)}
    return {"positions_wl": x, "weights": w}


def closed_form_amplitudes(steering: Steering, u_fe, u_set, phases=None) -> np.ndarray:
    """The ``array-factor`` amplitudes a (Q,) (the largest 1) of channels at direction cosines
    ``u_fe`` (Q, D) synthesizing ``u_set`` (D,) (module docstring); ``phases`` (Q,): the
    channels' programmed phases, default coherent at ``u_set`` (given ones are taken as making
    the channels coherent there: B(u*) is rotated real by channel 0's phase)."""
    u_fe = np.asarray(u_fe, float)
    du = np.asarray(u_set, float)[None, :] - u_fe  # (Q, D)
    t = steering.taper
    e = t * steering.steer(du)  # (Q, V_s)
    af = e.sum(-1) / t.sum()
    d_af = 1j * (e @ steering.wavevector) / t.sum()  # (Q, D)
    phi = -np.angle(af) if phases is None else np.asarray(phases, float)
    rot = np.exp(1j * (phi - np.angle(np.exp(1j * phi[0]) * af[0])))  # B(u*) real, channel 0
    g = np.real(rot[:, None] * d_af).T  # (D, Q)
    f = np.real(rot * af)
    a = f - g.T @ np.linalg.lstsq(g @ g.T, g @ f, rcond=None)[0]  # P_null(G) f
    if np.any(a < -1e-12 * np.abs(a).max()) and a.size > g.shape[0] + 1:
        # more channels than conditions and P_null f not all positive (near a corner of a
        # quadrilateral): of the sub-cells of D + 1 channels (its triangles) whose one
        # solution is non-negative, the one with the largest peak power per unit norm
        best, score = None, -np.inf
        for sub in itertools.combinations(range(a.size), g.shape[0] + 1):
            null = np.linalg.svd(g[:, sub])[2][-1]
            null = null * np.sign(null @ f[list(sub)] or 1.0)
            if np.all(null >= -1e-12) and null @ f[list(sub)] / np.linalg.norm(null) > score:
                best, score = (sub, null), null @ f[list(sub)] / np.linalg.norm(null)
        if best is not None:
            a = np.zeros(a.size)
            a[list(best[0])] = best[1]
    if np.max(a) <= 0:
        raise AngleUnreachable("the array-factor closed form gives no channel a weight here")
    a = a / np.max(a)
    if np.any(a < -1e-9):
        raise AngleUnreachable(f"the array-factor closed form needs a negative amplitude "
                               f"{a.min():.3g} here: the direction is outside the cell")
    return np.clip(a, 0.0, None)
