"""The RuT's 2-D CFAR on its range-Doppler power map (CA or OS), cyclic on both axes.

Training cells form a ring around each cell under test (guard cells excluded); the ring sums
and quantiles run in O(map) (CA) or O(map x :data:`OS_MAX_CELLS`) (OS) whatever the ring, with
rounding relative to the ring's own content. A detection is a cell above its threshold that is
a local maximum of its 3 x 3 neighbourhood.
"""

from __future__ import annotations

import numpy as np

from ..scene import CfarConfig

__all__ = ["OS_MAX_CELLS", "cfar_mask"]


#: OS-CFAR ranks at most this many training cells per cell under test (an evenly thinned ring
#: beyond it), so that its cost stays O(map x OS_MAX_CELLS) whatever the ring the scene asks for.
OS_MAX_CELLS = 512


def _window_sums(a: np.ndarray, lo: int, hi: int, axis: int) -> np.ndarray:
    """``out[i] = sum(a[(i + k) mod n] for k in lo..hi)`` along ``axis`` (cyclic), in O(size)
    time and memory whatever the window, with additions only: blocks of the window's length,
    each window the suffix of one block plus the prefix of the next (van Herk / Gil-Werman), so
    the rounding error is relative to the window's own content (no difference of long running
    sums, which would leave eps x the strongest peak in every quiet cell). A window longer than
    the axis counts each wrap in full, as a wrapped convolution does."""
    return np.roll(_leading_window_sums(a, hi - lo + 1, axis), -lo, axis=axis)


def _leading_window_sums(a: np.ndarray, length: int, axis: int) -> np.ndarray:
    """:func:`_window_sums` of the window ``0..length - 1``: every window of the same length is
    a cyclic shift of it (``np.roll``, a permutation: the same bits), so windows of equal
    length share one pass."""
    lo, hi = 0, length - 1
    a = np.moveaxis(a, axis, 0)
    n = a.shape[0]
    full, w = divmod(hi - lo + 1, n)
    out = full * a.sum(axis=0, keepdims=True) if full else None
    if w:
        nb = -(-(n + w - 1) // w)  # blocks covering every window start 0..n-1
        ext = np.take(a, np.arange(nb * w + w) % n, axis=0)  # cyclic extension
        blocks = ext.reshape((nb + 1, w) + a.shape[1:])
        pre = np.cumsum(blocks, axis=1).reshape(ext.shape)
        suf = np.flip(np.cumsum(np.flip(blocks, 1), axis=1), 1).reshape(ext.shape)
        s = np.arange(n)
        part = np.where(((s % w) == 0).reshape((n,) + (1,) * (a.ndim - 1)),
                        suf[s], suf[s] + pre[s + w - 1])
        out = part if out is None else out + part
    out = np.broadcast_to(out, a.shape)
    return np.moveaxis(out, 0, axis)


def _ring_sum(power: np.ndarray, gr: int, gd: int, tr: int, td: int) -> np.ndarray:
    """Sum over the CA-CFAR ring: four cyclic rectangles (the bands above and below the guard
    window, over the full Doppler width; left and right of it), each summed over range first,
    then Doppler, and added in that order. Sums only, no outer-minus-inner cancellation.

    The two bands have the same range length and the same Doppler window, the two sides the
    same range window and the same Doppler length: each pair shares its window sums and
    differs by a cyclic shift (bit-identical to summing each rectangle on its own, 4 passes
    instead of 8)."""
    hr, hd = gr + tr, gd + td
    bands = _window_sums(_leading_window_sums(power, tr, 0), -hd, hd, 1)
    above = np.roll(bands, hr, axis=0)  # range offsets -hr..-gr-1
    below = np.roll(bands, -(gr + 1), axis=0)  # gr+1..hr
    sides = _leading_window_sums(_window_sums(power, -gr, gr, 0), td, 1)
    left = np.roll(sides, hd, axis=1)  # Doppler offsets -hd..-gd-1
    right = np.roll(sides, -(gd + 1), axis=1)  # gd+1..hd
    return above + below + left + right


def _os_footprint(shape, gr: int, gd: int, tr: int, td: int) -> np.ndarray:
    """The OS-CFAR training ring, clipped to the map (no cell twice) and thinned evenly to at
    most :data:`OS_MAX_CELLS` cells."""
    hr = min(gr + tr, (shape[0] - 1) // 2)
    hd = min(gd + td, (shape[1] - 1) // 2)
    ring = np.ones((2 * hr + 1, 2 * hd + 1), bool)
    ring[max(hr - gr, 0):hr + gr + 1, max(hd - gd, 0):hd + gd + 1] = False
    if not ring.any():  # the guard cells cover the whole map: train on every other cell
        ring[:] = True
        ring[hr, hd] = False
    idx = np.flatnonzero(ring)
    if idx.size > OS_MAX_CELLS:
        keep = idx[np.linspace(0, idx.size - 1, OS_MAX_CELLS).round().astype(int)]
        ring = np.zeros_like(ring)
        ring.flat[keep] = True
    return ring


def cfar_mask(power: np.ndarray, cfg: CfarConfig, map_shape=None
              ) -> tuple[np.ndarray, np.ndarray]:
    """2D CFAR on a (range, Doppler) power map: returns (detected mask, noise estimate).

    ``power`` may carry trailing axes (R, D, ...): maps (or windows of one map,
    :mod:`rtsgeom.radar.windowed`) side by side, each on its own. ``map_shape`` (R, D): the
    map's shape where ``power`` holds windows of it (the OS ring is clipped to the map's).

    Training cells form a ring around each cell under test (guard cells excluded); the range
    axis is cyclic too: with a complex ADC the beat frequencies wrap at f_adc, so the top
    range bins neighbour the bottom ones.

    CA averages the ring, summed as four rectangles with cyclic block prefix/suffix sums
    (:func:`_window_sums`): time and memory O(map) whatever the ring size, rounding relative to
    the ring's own content (a ring larger than the map counts wrapped cells once per wrap, as a
    wrapped convolution does).
    OS takes the ring's ``os_rank`` quantile; its ring is clipped to the map and thinned evenly
    to at most :data:`OS_MAX_CELLS` cells, bounding the cost at O(map x OS_MAX_CELLS).
    """
    from scipy import ndimage  # here: 0.2 s of imports that `rtsgeom info` does not need
    gr, gd = cfg.guard_cells
    tr, td = cfg.training_cells
    power = np.asarray(power, dtype=np.float64)
    if cfg.kind == "ca":
        hr, hd = gr + tr, gd + td
        total = _ring_sum(power, gr, gd, tr, td)
        count = (2 * hr + 1) * (2 * hd + 1) - (2 * gr + 1) * (2 * gd + 1)
        noise = total / count
    else:
        ring = _os_footprint(power.shape[:2] if map_shape is None else map_shape,
                             gr, gd, tr, td)
        ring = ring.reshape(ring.shape + (1,) * (power.ndim - 2))
        noise = ndimage.percentile_filter(power, 100 * cfg.os_rank, footprint=ring,
                                          mode="wrap")
    thr = noise * 10 ** (cfg.threshold_db / 10)
    peak = power == ndimage.maximum_filter(power, size=(3, 3) + (1,) * (power.ndim - 2),
                                           mode="wrap")
    return (power > thr) & peak, noise
