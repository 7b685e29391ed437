"""The RTS's delay hardware: a sample buffer at ``f_s`` plus a fractional-delay FIR (a
windowed sinc, Kaiser window), which realises a requested delay only to its step
(:func:`realised_delay`) and whose response ripples along the chirp's IF sweep
(:func:`fir_if_gain`); its whole-sample taps (:func:`fir_taps`) let the tolerance tables sum a
few tones per geometry instead of every echo's samples."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._lib.util import frozen, tones
from ..scene import Scene

__all__ = ["FIR_KAISER_BETA", "realised_delay", "fractional_delay_fir", "fir_error_response",
           "fir_if_gain", "fir_modelled", "FirTaps", "fir_taps"]

FIR_KAISER_BETA = 4.0  # [assumed] fractional-delay FIR window (about 40 dB stop band)


def realised_delay(delay_s, f_s_hz: float, fractional: bool, step_s: float) -> np.ndarray:
    """The delay the back end actually applies: an integer buffer of ``1/f_s`` steps plus a
    fractional-delay FIR whose setting is quantised to ``step_s`` (or nothing without one)."""
    d = np.asarray(delay_s, float)
    ts = 1.0 / f_s_hz
    if not fractional:
        return np.round(d / ts) * ts
    n = np.floor(d / ts)
    frac = np.round((d - n * ts) / step_s) * step_s
    return n * ts + frac


def fractional_delay_fir(mu, taps: int, beta: float = FIR_KAISER_BETA) -> np.ndarray:
    """Coefficients (M, taps) of a Kaiser-windowed-sinc fractional-delay FIR for fractional
    delays ``mu`` (M,) in samples, [0, 1): ``h[n] = sinc(n - D) w(n - D)``, D = (taps - 1)/2
    + mu, with the Kaiser window centred on D (the standard shifted-window design, Laakso et
    al. 1996), normalised to unit gain at DC. The bulk (taps - 1)/2 samples are part of the
    delay buffer. Hand-written: scipy's ``firwin`` only delays by whole or half samples."""
    from scipy.special import i0
    mu = np.atleast_1d(np.asarray(mu, float))
    n = np.arange(taps)
    x = n[None, :] - (taps - 1) / 2 - mu[:, None]
    arg = np.clip(1.0 - (2.0 * x / (taps - 1)) ** 2, 0.0, None)
    h = np.sinc(x) * i0(beta * np.sqrt(arg)) / i0(beta)
    return h / h.sum(axis=1, keepdims=True)


def fir_error_response(mu, taps: int, f_s_hz: float, f_hz, shift_hz=0.0) -> np.ndarray:
    """The FIR's response relative to the ideal delay it is set to, ``H(f) exp(j 2 pi f D /
    f_s)`` (magnitude and phase ripple), for settings ``mu`` (M,) at frequencies
    ``f_hz[n] + shift_hz[m]`` -> (M, N): ``f_hz`` a grid (N,) common to all settings (or
    (M, N) rows that are shifted copies of one grid; ValueError otherwise), ``shift_hz`` (M,)
    or a scalar.

    Evaluated as ``sum_k h_k exp(-j w (k - D))`` with ``w = 2 pi f / f_s`` split into the
    grid's and the shift's part: one matrix product (M, taps) x (taps, N) (BLAS) and the
    settings' distinct ``mu`` (a delay table has ~250 per sample period) for the window's
    ``exp(j w mu)``, instead of a Horner pass over (M, N) per tap (the tolerance model's
    delay tables spent half of their construction there). Agrees with the direct sum to
    ~1e-15."""
    mu = np.atleast_1d(np.asarray(mu, float))
    f = np.asarray(f_hz, float)
    grid = f.reshape(-1, f.shape[-1])[0]  # (N,)
    off = 0.0
    if f.ndim > 1:  # rows: the grid shifted per setting
        off = f[..., 0] - grid[0]
        if not np.allclose(f - off[..., None], grid, rtol=1e-12, atol=1e-9):
            raise ValueError("f_hz: each row must be the same frequency grid, shifted")
    shift = np.broadcast_to(np.asarray(shift_hz, float) + off, mu.shape)
    uniq, inv = np.unique(mu, return_inverse=True)
    inv = np.ravel(inv)
    h, phase, kern = _fir_rows(uniq, int(taps), float(f_s_hz), grid)
    k = np.arange(taps) - (taps - 1) / 2  # centred: small phases
    v = 2 * np.pi * shift / f_s_hz  # (M,)
    # exp(-j (w_n + v_m)(k - D_m)), D_m = (taps - 1)/2 + mu_m, as exp(-j v_m (k - mu_m))
    # exp(-j w_n k) exp(j w_n mu_m)
    coef = h[inv] * np.exp(-1j * v[:, None] * (k[None, :] - mu[:, None]))  # (M, taps)
    resp = coef @ kern  # (M, N)
    resp *= phase[inv]
    return resp


#: per (taps, f_s, frequency grid): the settings met so far (sorted) and their slots in
#: buffers of ``_FIR_ROWS_MAX`` rows of taps and of the window's ``exp(j w mu)``, and
#: ``exp(-j w k)`` (see :func:`_fir_rows`)
_FIR_ROWS: dict = {}
_FIR_ROWS_MAX = 2048  # settings kept per key (~17 MiB at N = 512); beyond: start afresh
_FIR_KEYS_MAX = 2  # frequency grids kept (a process meets one per scene)


def _fir_rows(uniq: np.ndarray, taps: int, f_s_hz: float, grid: np.ndarray):
    """:func:`fir_error_response`'s per-setting factors for the sorted distinct settings
    ``uniq``: the FIR's taps (U, taps), ``exp(j w mu)`` (U, N) and the common ``exp(-j w k)``
    (taps, N), w = 2 pi grid / f_s. A delay table meets the same few hundred settings (one
    per delay step in a sample period) in every block of echoes and in every design of a
    grid; their taps and phase rows (U N complex exponentials per call: over half of the
    response's time) are computed once per process and looked up. New rows are written into
    preallocated buffers (a drive meets new settings every frame: copying the whole memo per
    call to insert them was 3.5 ms a call, most of a frame's planning). Each row is computed
    by the same elementwise arithmetic as before, so the bits do not depend on the memo."""
    key = (taps, f_s_hz, grid.tobytes())
    w = 2 * np.pi * grid / f_s_hz  # (N,)
    entry = _FIR_ROWS.get(key)
    if entry is None:
        k = np.arange(taps) - (taps - 1) / 2
        entry = {"mus": np.zeros(0), "slots": np.zeros(0, int),
                 "h": np.empty((_FIR_ROWS_MAX, taps)),
                 "phase": np.empty((_FIR_ROWS_MAX, grid.size), complex),
                 "kern": np.exp(-1j * np.outer(k, w))}
        if len(_FIR_ROWS) >= _FIR_KEYS_MAX:
            _FIR_ROWS.clear()
        _FIR_ROWS[key] = entry
    mus, slots = entry["mus"], entry["slots"]
    cap = min(_FIR_ROWS_MAX, entry["h"].shape[0])  # (the buffers' rows)
    pos = np.minimum(np.searchsorted(mus, uniq), max(mus.size - 1, 0))
    hit = (mus[pos] == uniq) if mus.size else np.zeros(uniq.size, bool)
    if not hit.all():
        new = uniq[~hit]
        if mus.size + new.size > cap:  # start afresh with these settings
            if uniq.size > cap:  # more than the memo holds: computed, not kept
                return (fractional_delay_fir(uniq, taps), np.exp(1j * np.outer(uniq, w)),
                        entry["kern"])
            mus, slots, new = np.zeros(0), np.zeros(0, int), uniq
        free = np.arange(mus.size, mus.size + new.size)  # slots are filled in order
        entry["h"][free] = fractional_delay_fir(new, taps)
        entry["phase"][free] = np.exp(1j * np.outer(new, w))
        order = np.argsort(np.concatenate([mus, new]), kind="stable")
        mus = np.concatenate([mus, new])[order]
        slots = np.concatenate([slots, free])[order]
        entry["mus"], entry["slots"] = mus, slots
        pos = np.searchsorted(mus, uniq)
    rows = slots[pos]
    return entry["h"][rows], entry["phase"][rows], entry["kern"]


def fir_if_gain(scene: Scene, delay_s, tau_total_s) -> np.ndarray | None:
    """Fast-time gain (E, N) of the fractional-delay FIR on each echo's beat signal.

    The RTS processes the RuT's chirp at the IF ``f_rts + S (t - tau)`` (t: the RuT's fast
    time, tau the echo's total delay), so the FIR's magnitude and phase ripple at its
    setting becomes a gain/phase that changes along the chirp. The beat signal carries the
    conjugate of the RTS's complex gain (eq. 8: tx * conj(rx)). None for an ideal delay
    (``fractional_delay_filter = "ideal"`` or no fractional delay)."""
    rts, radar = scene.rts, scene.radar
    if not fir_modelled(scene):
        return None
    t_n = radar.adc_start_s + np.arange(radar.samples_per_chirp) / radar.adc_rate_hz
    # every echo at its setting; the IF f_rts + S t_n shifted by -S tau per echo
    out = fir_error_response(_fir_setting(delay_s, rts.f_s_hz), rts.fractional_delay_taps,
                             rts.f_s_hz, rts.f_rts_hz + radar.slope_hz_per_s * t_n,
                             -radar.slope_hz_per_s * np.asarray(tau_total_s, float))
    return np.conj(out)


def fir_modelled(scene: Scene) -> bool:
    """Whether the scene's RTS realises its delays with a modelled fractional-delay FIR (whose
    response :func:`fir_if_gain` and :func:`fir_taps` give); else an ideal delay."""
    return bool(scene.rts.fractional_delay and scene.rts.fractional_delay_filter != "ideal")


def _fir_setting(delay_s, f_s_hz: float) -> np.ndarray:
    """The FIR's fractional delay mu in samples, [0, 1), for realised delays ``delay_s``:
    rounded to 1e-9 samples (a setting within 1e-9 of a whole sample is 0)."""
    ts = 1.0 / f_s_hz
    d = np.asarray(delay_s, float)
    mu = (d - np.floor(d / ts) * ts) / ts
    return np.round(np.where(mu >= 1.0 - 1e-9, 0.0, mu), 9)


@dataclass(frozen=True)
class FirTaps:
    """The fractional-delay FIR's action on echoes as whole-sample-delayed copies: with
    ``t_s = 1 / f_s`` and the taps centred (k_c = k - (T - 1) / 2), echo e's fast-time
    signal ``exp(j 2 pi S tau_if t) fir_if_gain(t)`` equals::

        exp(j 2 pi S residual_s[e] t) sum_k weights[e, k] exp(j 2 pi S t_s (samples[e] + k_c) t)

    (the FIR's output is the sum of its taps' copies of the input, each delayed by whole
    samples: ``weights = h_k(mu) exp(j 2 pi (f_rts - S tau) (k_c - mu) t_s)``, the taps h_k
    real; ``samples`` the buffer's whole samples n with tau_if = (n + mu) t_s + residual, the
    residual from mu's rounding to 1e-9 samples, its phase 2 pi S residual t below 1e-8 rad
    (B <= f_s)). A delay table's thousands of settings then share a few dozen tones
    (:func:`rtsgeom.radar.phasors.bin_response`, ``taps``). Direct echoes only: a cable
    ghost carries its direct echo's FIR, not one set to its own delay."""

    samples: np.ndarray  # (E,) int
    weights: np.ndarray  # (E, T) complex
    residual_s: np.ndarray  # (E,)
    sample_period_s: float

    def select(self, rows) -> "FirTaps":
        return FirTaps(self.samples[rows], self.weights[rows], self.residual_s[rows],
                       self.sample_period_s)


def fir_taps(scene: Scene, delay_s, tau_total_s) -> FirTaps | None:
    """:func:`fir_if_gain` of the same echoes (realised RTS delays ``delay_s`` (E,), total
    delays ``tau_total_s`` (E,)) in its whole-sample form, :class:`FirTaps` (None for an ideal
    delay). The same model: ``exp(j 2 pi S delay t) fir_if_gain(t)`` of each echo is its
    ``FirTaps`` sum to rounding, with the residual's phase, below 1e-8 rad, to first order
    (tested)."""
    rts, radar = scene.rts, scene.radar
    if not fir_modelled(scene):
        return None
    ts = 1.0 / rts.f_s_hz
    d = np.asarray(delay_s, float)
    taps = rts.fractional_delay_taps
    if d.size == 0:
        return FirTaps(frozen(np.zeros(0, np.int64)), frozen(np.zeros((0, taps), complex)),
                       frozen(np.zeros(0)), ts)
    mu = _fir_setting(d, rts.f_s_hz)
    uniq, inv = np.unique(mu, return_inverse=True)
    t_n = radar.adc_start_s + np.arange(radar.samples_per_chirp) / radar.adc_rate_hz
    # the taps of the settings met so far (fir_error_response's memo, the same grid)
    h = _fir_rows(uniq, taps, float(rts.f_s_hz), rts.f_rts_hz + radar.slope_hz_per_s * t_n)[0]
    n = np.round(d / ts - mu)
    f = rts.f_rts_hz - radar.slope_hz_per_s * np.asarray(tau_total_s, float)  # (E,)
    # exp(j 2 pi f (k_c - mu) t_s) as exp(j 2 pi f k_c t_s) exp(-j 2 pi f mu t_s), the
    # first factor by tones (2 sqrt(T) exponentials a row instead of T)
    w = (h[np.ravel(inv)] * tones(f, -0.5 * (taps - 1) * ts, ts, taps)
         * np.exp(-2j * np.pi * f * mu * ts)[:, None])
    return FirTaps(frozen(n.astype(np.int64)), frozen(w), frozen(d - (n + mu) * ts), ts)
