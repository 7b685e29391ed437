"""The radar's taper windows: over the ADC samples (range), the chirps (Doppler) and the virtual
elements (the beamformer's taper, separable over its axes)."""

from __future__ import annotations

import numpy as np

__all__ = ["window", "taper"]


#: The cosine-sum coefficients of the registry's windows (``registry.WINDOWS``), as in
#: ``scipy.signal.windows``.
_COSINE_SUMS = {"hann": (0.5, 1.0 - 0.5), "hamming": (0.54, 1.0 - 0.54),  # scipy: (a, 1 - a)
                "blackman": (0.42, 0.50, 0.08)}


def window(name: str, n: int) -> np.ndarray:
    """Symmetric window ``name`` (scipy.signal names, or ``none``) of n points.

    The registry's cosine-sum windows are formed here with scipy's own arithmetic
    (``scipy.signal.windows.general_cosine``: ``sum_k a_k cos(k x)``, x = linspace(-pi, pi, n)),
    bit for bit (tested), because importing ``scipy.signal`` costs about half a second (it
    loads ``scipy.stats``), more than the rest of ``rtsgeom info``; other names go to
    ``scipy.signal.get_window``."""
    if name == "none" or n <= 1:
        return np.ones(n)
    coeffs = _COSINE_SUMS.get(name)
    if coeffs is None:
        from scipy import signal
        return signal.get_window(name, n, fftbins=False)
    x = np.linspace(-np.pi, np.pi, n, dtype=np.float64)
    w = np.zeros(n, dtype=np.float64)
    for k, a in enumerate(coeffs):
        w += a * np.cos(k * x)
    return w


def taper(name: str, positions: np.ndarray) -> np.ndarray:
    """Window over the elements in position order, separable over the D axes (D = 1: the
    window over the elements sorted by x)."""
    w = np.ones(positions.shape[0])
    for d in range(positions.shape[1]):
        x = positions[:, d]
        if positions.shape[1] == 1:
            wd = np.empty_like(x)
            wd[np.argsort(x)] = window(name, x.size)
        else:  # one window value per distinct coordinate (a row or a column of a 2-D array)
            vals, inv = np.unique(np.round(x, 12), return_inverse=True)
            wv = window(name, vals.size)
            if not np.all(wv > 0):  # e.g. hann over 2 rows is (0, 0): drop the zero ends
                wv = window(name, vals.size + 2)[1:-1]
            wd = wv[inv]
        w = w * wd
    return w
