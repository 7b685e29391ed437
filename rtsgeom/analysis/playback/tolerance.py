"""Mounting tolerance over a drive: the share of built setups whose worst angle error over the
whole drive stays within a spec, through the one tolerance engine
(:mod:`rtsgeom.analysis.tolerance`).

The drive's frames put each target in a pair of front ends (as the planner does: the pair
whose measured span holds its azimuth); every pair the drive visits becomes one channel set of
the engine's arc model with the drive's azimuths in that pair as its set-points (the engine's
pair model, designed and calibrated on the nominal setup as the lab does), at the mean range
of those frames. One draw of mounting errors (per front end, shared by every pair, as the arc
study draws them) is one built setup; its worst error over every set-point of every pair is
its worst over the drive. The engine models one reference range per pair (a draw moves the
target within its range bin): the range a drive changes within a pair is taken as the mean.
"""

from __future__ import annotations

import dataclasses
from collections import defaultdict

import numpy as np

from ...calibration.probes import probe_front_ends
from ...errors import ParameterError
from ...geometry import build_setup
from ...paths import exact_paths
from ...pipeline.plan import target_pairs, uses_cells
from ...scene import Scene, check_scene_arg
from ..tolerance import ChannelPhasors, ToleranceModel, ToleranceResult, monte_carlo
from ..tolerance.config import STUDY_ARGS, check_sigma_mm, check_study_args
from .frames import frame_target_names, frame_targets

__all__ = ["drive_tolerance"]


def drive_tolerance(scene: Scene, sigma_mm=(0.1, 0.1, 0.1), draws: int = 2000,
                    seed: int | None = None, distribution: str = "normal",
                    spec_deg: float = 0.1) -> ToleranceResult:
    """Monte Carlo of mounting errors over the scene's drive (``[scenario]``).

    Parameters
    ----------
    scene : Scene
        With a ``[scenario]``; its front ends on an arc (pairs).
    sigma_mm : sequence of 3 float
        Radial, tangential and height mounting error per front end (mm): the standard
        deviation (``normal``) or the bound (``uniform``).
    draws, seed, distribution, spec_deg
        As for :func:`rtsgeom.tolerance` (``seed`` default: the scene's), with its ranges
        (``analysis.tolerance.config.check_study_args``: draws in [1, 1e7], sigma 0 to 10 mm).

    Returns
    -------
    ToleranceResult
        The engine's arc result over the drive's pairs: ``yield_(case)`` is the share of
        setups whose every frame stays within ``spec_deg``, ``arc_worst(case)`` (draws,) the
        worst signed error over the drive; ``model.sets[p].set_rad`` the set-points of pair
        ``model.sets[p].front_ends``.
    """
    check_scene_arg(scene, "drive_tolerance")
    STUDY_ARGS["draws"].check(draws, "draws", "drive_tolerance")  # None is no default here
    draws, seed, distribution, spec_deg = check_study_args(
        "drive_tolerance", draws=draws, seed=seed, distribution=distribution,
        spec_deg=spec_deg)
    sigma = check_sigma_mm("drive_tolerance", sigma_mm)
    if scene.scenario is None:
        raise ParameterError(f"{scene.source}: has no [scenario] (docs/scenario.md)")
    if uses_cells(scene):
        raise ParameterError("drive tolerance: front ends off the arc form cells; a drive's "
                             "tolerance is modelled on pairs of an arc only")
    _, frames = frame_targets(scene)
    if any(t.elevation_rad for tg in frames for t in tg):
        raise ParameterError("drive tolerance: targets in elevation need cells; a drive's "
                             "tolerance is modelled on pairs of an arc only")
    setup = build_setup(dataclasses.replace(scene, scenario=None))  # the bench, not the drive
    probe = probe_front_ends(setup, exact_paths(setup), scene.seed)
    visits: dict = defaultdict(list)
    for f, targets in enumerate(frames):
        pairs, _ = target_pairs(setup, probe, targets,
                                where=frame_target_names(scene, f, targets=targets))
        for pair, t in zip(pairs, targets):
            visits[pair].append((t.angle_rad, t.range_m))
    models = []
    for pair in sorted(visits):
        v = np.array(visits[pair])
        models.append(ChannelPhasors.build(setup, pair, set_rad=np.unique(v[:, 0]),
                                           range_m=float(v[:, 1].mean())))
    model = ToleranceModel.arc(models, setup.fe.count)
    return monte_carlo(model, np.asarray(sigma), draws, scene.seed if seed is None else seed,
                       distribution, spec_deg)
