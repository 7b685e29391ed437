"""Targets that share a range-Doppler cell: said before the run, with what the radar will see.

A radar separates targets in range, Doppler and angle. Two targets within one range bin and one
velocity bin of each other are one range-Doppler cell; there the radar can tell them apart only
by angle, which needs them at least its two-target resolution apart
(:func:`rtsgeom.radar.peaks.two_target_resolution`) and reported as several angle peaks of the
cell (``[radar] angle_peaks_max``). On an RTS a second hazard adds to it: targets of one cell
synthesized on *different* front-end pairs each carry their pair's near-field phase pattern
across the RuT's aperture, so their superposition is not what two real targets give (compare
with the truth twin: ``rtsgeom resolution``).
"""

from __future__ import annotations

import numpy as np

from ..geometry import Setup
from ..radar.peaks import two_target_resolution
from ..radar.steering import Steering
from .plan import bracketing_pair

__all__ = ["shared_cell_warnings"]


def shared_cell_warnings(setup: Setup, targets, where: str = "targets") -> list[str]:
    """One line per pair of targets in one range-Doppler cell that the radar cannot resolve in
    angle, or that sit on different front-end pairs (see the module's docstring).

    Parameters
    ----------
    setup : Setup
        The bench (its radar's bins, its beamformer, its front ends' angles).
    targets : sequence of TargetConfig
        The targets of one frame.
    where : str
        How the lines name the targets (``targets``, ``frame 12: targets``). Pairs of
        scatterers of one extended object are not named: they share cells by design.

    Returns
    -------
    list of str
    """
    t = list(targets)
    if len(t) < 2:
        return []
    radar = setup.scene.radar
    st = Steering.auto(setup.rut, radar)
    res_u = float(two_target_resolution(st)[0])
    r = np.array([x.range_m for x in t])
    v = np.array([x.velocity_mps for x in t])
    u = np.sin([x.angle_rad for x in t])
    same = ((np.abs(r[:, None] - r[None]) < radar.range_resolution_m)
            & (np.abs(v[:, None] - v[None]) < radar.velocity_resolution_mps))
    fe = setup.fe_azimuth_rad()
    pair = [bracketing_pair(x.angle_rad, fe) for x in t]
    out = []
    obj = np.array([getattr(x, "object_index", -1) for x in t])  # duck-typed targets too
    # an extended object's scatterers share cells by design: its own summary (clouds.csv,
    # objects.json) says what the radar sees of it
    same &= ~((obj[:, None] == obj[None]) & (obj[:, None] >= 0))
    for i, j in zip(*np.nonzero(np.triu(same, 1))):
        sep = abs(u[i] - u[j])
        name = f"{_name(where, i, obj[i])} and {_name(where, j, obj[j])}"
        if sep < res_u:
            out.append(f"{name} share a range-Doppler cell and lie {sep:.3f} apart in sin(az), "
                       f"within the radar's two-target resolution {res_u:.3f}: it will see "
                       "one target between them (status 'merged')")
        elif pair[i] != pair[j] and setup.scene.rts.aoa_mode != "nearest":
            out.append(f"{name} share a range-Doppler cell on different front-end pairs "
                       f"{pair[i]} and {pair[j]}: each carries its pair's near-field phase "
                       "pattern, so the radar may see one broad peak where real targets give "
                       "two (the truth twin shows what it would see; rtsgeom resolution)")
    return out


def _name(where: str, k: int, obj: int) -> str:
    """Target ``k`` as the lines name it; a scatterer with its object's index."""
    return f"{where}[{k}]" + (f" (a scatterer of object {obj})" if obj >= 0 else "")
