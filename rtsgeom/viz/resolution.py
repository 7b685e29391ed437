"""The resolution test's figure: angle spectra of truth and RTS, resolved over separation x phase."""

from __future__ import annotations

import numpy as np
from matplotlib.colors import ListedColormap

from .figures import new_figure

__all__ = ["resolution_figure"]

_COLOURS = {"truth": "tab:blue", "rts": "tab:orange"}


def resolution_figure(result):
    """Upper row: per chosen separation, the RuT's angle spectrum of the targets' cell (truth
    and RTS, at the study's first phase) with the set angles marked; lower row: resolved (filled) or not over
    separation x phase, truth and RTS, the minimum resolvable separation marked."""
    sp = result.spectra
    n = max(len(sp.get("separation_deg", [])), 2)
    fig = new_figure(figsize=(3.0 * n, 6.0))[0]
    fig.clear()
    grid = fig.add_gridspec(2, n)
    for i, s in enumerate(sp.get("separation_deg", [])):
        ax = fig.add_subplot(grid[0, i])
        for src in ("truth", "rts"):
            ax.plot(sp["angle_deg"], sp[src][i], color=_COLOURS[src],
                    label="truth twin" if src == "truth" else "RTS")
        for a in (result.centre_deg - s / 2, result.centre_deg + s / 2):
            ax.axvline(a, color="0.4", lw=0.8, ls=":")
        ax.set_xlim(result.centre_deg - max(1.5 * s, 20), result.centre_deg + max(1.5 * s, 20))
        ax.set_ylim(-30, 1)
        ax.set_title(f"s = {s:g} deg, phase {sp.get('phase_deg', 0.0):g} deg", fontsize=9)
        ax.set_xlabel("angle (deg)")
        if i == 0:
            ax.set_ylabel("beamformer power (dB)")
            ax.legend(fontsize=7, loc="lower left")
    t = result.table
    phases = list(dict.fromkeys(t["phase_deg"].tolist()))
    seps = np.unique(t["separation_deg"])
    ms = result.min_separation_deg
    half = n // 2
    for k, src in enumerate(("truth", "rts")):
        ax = fig.add_subplot(grid[1, k * half:(k + 1) * half] if n > 1 else grid[1, k])
        img = np.zeros((len(phases), seps.size))
        for r, ph in enumerate(phases):
            sel = (t["source"] == src) & (t["phase_deg"] == ph)
            order = np.searchsorted(seps, t["separation_deg"][sel])
            img[r, order] = t["resolved"][sel]
        step = seps[1] - seps[0] if seps.size > 1 else 1.0
        ax.imshow(img, aspect="auto", origin="lower", cmap=ListedColormap(["0.92", _COLOURS[src]]),
                  vmin=0, vmax=1, extent=(seps[0] - step / 2, seps[-1] + step / 2, -0.5,
                                          len(phases) - 0.5), interpolation="nearest")
        for r, ph in enumerate(phases):
            m = ms[src].get(f"{ph:g}")
            if m is not None:
                ax.plot([m - step / 2] * 2, [r - 0.45, r + 0.45], color="k", lw=1.5)
        ax.set_yticks(range(len(phases)), [f"{p:g}" for p in phases])
        ax.set_xlabel("separation s (deg)")
        ax.set_ylabel("relative phase (deg)")
        ax.set_title(f"{'truth twin' if src == 'truth' else 'RTS'}: resolved (filled); "
                     "bar: minimum", fontsize=9)
    fig.suptitle(f"{result.scene_name}: two targets at {result.centre_deg:g} ± s/2 deg, "
                 f"{result.range_m:g} m", fontsize=10)
    return fig
