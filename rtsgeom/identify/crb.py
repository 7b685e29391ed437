"""What a lab can measure: the Cramer-Rao bound of one probe capture's mounting parameters
versus SNR and arc radius (:func:`crb_grid`, :func:`crb_figure`)."""

from __future__ import annotations

import numpy as np

from ..geometry.setup import build_setup
from .capture import Capture, capture_probe
from ..scene import Scene
from .fit import cramer_rao
from .model import ProbeModel

__all__ = ["crb_grid", "crb_figure"]


def crb_grid(scene: Scene, snr_db, radii_m, active: int = 0) -> np.ndarray:
    """Cramer-Rao std of radial, tangential, height offset (m) and yaw (rad), (R, S, 4), for
    one capture of front end ``active`` at each arc radius ``radii_m`` (R,) and per-sample SNR
    ``snr_db`` (S,). Each parameter is estimated together with what a capture always fits
    (tangential and height offsets, the channel's gain and phase); the channel delay is known
    (it is inseparable otherwise). inf where the parameter does not act."""
    snr = np.atleast_1d(np.asarray(snr_db, float))
    out = np.empty((np.size(radii_m), snr.size, 4))
    for k, r in enumerate(np.atleast_1d(radii_m)):
        sc = scene.evolve(rts=scene.rts.evolve(arc_radius_m=float(r)))
        setup = build_setup(sc)
        rng, amp = capture_probe(setup)
        m = ProbeModel.of(setup, Capture(np.zeros((0, 0, 0), complex), active, rng, 0.0, amp))
        th = m.nominal()
        s2 = m.noise_variance(th, 0.0)  # SNR 0 dB; the bound scales with 10^(-SNR / 20)
        std = np.array([cramer_rao([m], th, s2, sorted({1, 2, 5, 6, p}))[p] for p in range(4)])
        out[k] = std[None, :] * 10 ** (-snr[:, None] / 20)
    return out


def crb_figure(scene: Scene, snr_db, radii_m, active: int = 0):
    """Figure: the Cramer-Rao std of each mounting parameter versus SNR, one line per arc
    radius (:func:`crb_grid`), with the +-0.5 mm / 1 deg of a careful build for scale."""
    import matplotlib.pyplot as plt
    std = crb_grid(scene, snr_db, radii_m, active)
    fig, axes = plt.subplots(1, 4, figsize=(13, 3.6), sharex=True)
    names = ("radial offset (mm)", "tangential offset (mm)", "height offset (mm)", "yaw (deg)")
    units = (1e3, 1e3, 1e3, 180 / np.pi)
    ref = (0.5, 0.5, 0.5, 1.0)
    for p, ax in enumerate(axes):
        for k, r in enumerate(np.atleast_1d(radii_m)):
            y = std[k, :, p] * units[p]
            ax.semilogy(snr_db, np.where(np.isfinite(y), y, np.nan), label=f"R_c = {r:g} m")
        ax.axhline(ref[p], color="0.5", ls="--", lw=0.8)
        ax.set_title(names[p], fontsize=9)
        ax.set_xlabel("per-sample SNR (dB)")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("Cramer-Rao std (one capture)")
    axes[0].legend(fontsize=7)
    el = "with" if scene.radar.use_elevation_tx else "without"
    fig.suptitle(f"{scene.name}: what one probe capture of front end {active} measures "
                 f"({el} elevation Tx; dashed: a careful build's tolerance)", fontsize=10)
    fig.tight_layout()
    return fig
