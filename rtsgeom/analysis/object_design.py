"""The design question for an extended object: how many front ends, how far apart, and how
many targets per channel does an RTS need so that the radar sees what it would see from the
object?

``ObjectDesign(ranges_m=..., spacings_deg=..., budgets=...)(scene)`` places the scene's first
object on the RuT's boresight at each range (turned by its fixed heading; an object that turns
with its motion is turned across the line of sight, a crossing car), and for every front-end
spacing and per-channel budget builds an arc of front ends that covers the object's azimuth
extent at the nearest range, runs the scene (``run_scene``: calibration, synthesis, the truth
twin) and compares what the radar sees (:mod:`rtsgeom.analysis.objects`): the share of the
truth twin's detections the RTS reproduces within one resolution cell and the difference of
the clouds' centroid azimuths. A design *reproduces the object* where at every range the share
is at least ``min_share`` and the centroid difference at most ``max_centroid_deg``; the answer
is the smallest number of front ends (then the smallest budget) that does.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from .._lib.results import Result
from ..errors import ParameterError
from ..scene import Scene
from ..scene.objects import place
from ..scene.schema import check_arg

__all__ = ["ObjectDesign", "ObjectDesignResult", "object_design", "MAX_RUNS"]

MAX_RUNS = 200  # ranges x spacings x budgets of one study (each a full run)
_MARGIN_DEG = 1.0  # the arc extends this beyond the object's azimuth extent


@dataclass(frozen=True)
class ObjectDesign:
    """A configured object design study (module docstring).

    Parameters
    ----------
    ranges_m : tuple of float
        The object's ranges (its origin's, on boresight).
    spacings_deg : tuple of float
        Front-end spacings along the arc.
    budgets : tuple of int or None
        ``[rts] max_targets_per_channel`` values; None: no limit.
    min_share : float
        Share of the truth twin's detections the RTS must reproduce within one resolution
        cell, at every range.
    max_centroid_deg : float
        Largest difference of the clouds' centroid azimuths (RTS minus truth) at any range.
    """

    ranges_m: tuple = (5.0, 10.0, 15.0, 20.0, 25.0, 30.0)
    spacings_deg: tuple = (8.0, 16.0)
    budgets: tuple = (None, 2)
    min_share: float = 0.9
    max_centroid_deg: float = 0.5

    def __post_init__(self):
        src = "ObjectDesign"
        for name, lo, hi in (("ranges_m", 0.5, 1e4), ("spacings_deg", 0.5, 60.0)):
            v = getattr(self, name)
            check_arg(list(v), name, "floats", src, ParameterError, lo=lo, hi=hi, min_items=1,
                      max_items=64)
        if not self.budgets or any(b is not None and not (isinstance(b, int) and not isinstance(
                b, bool) and b >= 1) for b in self.budgets):
            raise ParameterError(f"{src}: budgets = {self.budgets!r}: must be a non-empty "
                                 "tuple of integers >= 1 or None (no limit)")
        check_arg(self.min_share, "min_share", "float", src, ParameterError, lo=0.0, hi=1.0)
        check_arg(self.max_centroid_deg, "max_centroid_deg", "float", src, ParameterError,
                  lo=0.0, hi=90.0)
        n = len(self.ranges_m) * len(self.spacings_deg) * len(self.budgets)
        if n > MAX_RUNS:
            raise ParameterError(f"{src}: ranges_m x spacings_deg x budgets = {n} runs: must "
                                 f"be at most {MAX_RUNS} (each is a full run)")

    def __repr__(self) -> str:
        return (f"ObjectDesign({len(self.ranges_m)} ranges {min(self.ranges_m):g}.."
                f"{max(self.ranges_m):g} m, spacings {list(self.spacings_deg)} deg, budgets "
                f"{list(self.budgets)})")

    def __call__(self, scene: Scene, progress=None) -> "ObjectDesignResult":
        if not scene.objects:
            raise ParameterError(f"{scene.source}: has no extended object (a [[targets]] or "
                                 "[[scenario.targets]] entry with scatterers or mesh)")
        from ..pipeline.run import run_scene
        from .objects import run_objects
        model = scene.objects[0]
        heading = (math.pi / 2 if model.along_velocity else model.heading_rad)
        model = dataclasses.replace(model, heading_rad=heading, along_velocity=False,
                                    moving=False)
        shape = (len(self.spacings_deg), len(self.budgets), len(self.ranges_m))
        out = {k: np.full(shape, np.nan) for k in ("share", "centroid_deg", "kept", "truth",
                                                   "rts")}
        n_fe = np.zeros(len(self.spacings_deg), int)
        placed = {r: place(model, (0.0, r, 0.0), None, scene.radar, 0) for r in self.ranges_m}
        span = max(max(abs(math.degrees(t.angle_rad)) for t in pts) for pts in placed.values())
        for i, s in enumerate(self.spacings_deg):
            half = math.ceil((span + _MARGIN_DEG) / s)
            n_fe[i] = 2 * half + 1
            arc = _arc(scene, s, half)
            for j, b in enumerate(self.budgets):
                for k, r in enumerate(self.ranges_m):
                    variant = _variant(arc, placed[r], b, model, r)
                    if progress:
                        progress(f"spacing {s:g} deg ({n_fe[i]} front ends), budget "
                                 f"{b or 'none'}, {r:g} m")
                    res = run_scene(variant)
                    frame = run_objects(res)[1]["frames"][0]
                    budget = res.calibration.get("budget")
                    out["share"][i, j, k] = _nan(frame["reproduced_share"])
                    out["centroid_deg"][i, j, k] = _nan(frame["centroid_azimuth_diff_deg"])
                    out["kept"][i, j, k] = (budget["kept"] if budget else len(placed[r]))
                    out["truth"][i, j, k] = frame["truth_detections"]
                    out["rts"][i, j, k] = frame["rts_detections"]
        return ObjectDesignResult(self, scene.name, model.where, n_fe, **out)


def object_design(scene: Scene, **kwargs) -> "ObjectDesignResult":
    """Run :class:`ObjectDesign` (``kwargs`` its parameters) on ``scene``, the function of
    ``rtsgeom objects``.

    Parameters
    ----------
    scene : Scene
        A scene with an extended object.
    **kwargs
        :class:`ObjectDesign`'s fields.

    Returns
    -------
    ObjectDesignResult

    Raises
    ------
    ParameterError
        A field outside its range, naming it.
    """
    return ObjectDesign(**kwargs)(scene)


def _nan(x):
    return np.nan if x is None else x


def _arc(scene: Scene, spacing_deg: float, half: int) -> Scene:
    """The scene with ``2 half + 1`` front ends ``spacing_deg`` apart about boresight (the
    first front end's settings for all) and the sheet spanning them."""
    fe0 = scene.rts.front_ends[0]
    angles = np.radians(spacing_deg * np.arange(-half, half + 1))
    if np.degrees(angles[-1]) > 80.0:
        raise ParameterError(f"spacings_deg: {spacing_deg:g} deg x {half} front ends each side "
                             "reaches beyond 80 deg: the object is too wide for this spacing "
                             "at the nearest range")
    fes = tuple(dataclasses.replace(fe0, angle_rad=float(a)) for a in angles)
    edge = float(angles[-1] + np.radians(spacing_deg))
    return dataclasses.replace(
        scene, scenario=None, targets=(), objects=(),
        rts=dataclasses.replace(scene.rts, front_ends=fes, allow_wide_spacing=True),
        sheet=dataclasses.replace(scene.sheet, angle_min_rad=-edge, angle_max_rad=edge))


def _variant(arc: Scene, targets, budget, model, range_m: float) -> Scene:
    """The arc with the object's scatterers at ``range_m`` and the budget (validated)."""
    s = arc.evolve(targets=tuple(targets),
                   rts=arc.rts.evolve(max_targets_per_channel=budget))
    return dataclasses.replace(s, objects=(dataclasses.replace(model, origin=(0.0, range_m,
                                                                              0.0)),))


@dataclass(frozen=True, repr=False)
class ObjectDesignResult(Result):
    """The object design study's result; :meth:`best` the smallest design that reproduces
    the object.

    Attributes
    ----------
    study : ObjectDesign
        The study that made it.
    scene_name, object_where : str
        The scene's name and the object's place in it.
    front_ends : ndarray, (S,)
        The arc's front ends per spacing.
    share : ndarray, (S, B, R)
        Per spacing, budget and range the share of the truth twin's detections the RTS
        reproduces.
    centroid_deg : ndarray, (S, B, R)
        The centroid azimuth difference, RTS against truth.
    kept : ndarray, (S, B, R)
        The targets the RTS kept.
    truth, rts : ndarray, (S, B, R)
        The detections of the truth twin and of the RTS.
    """

    study: ObjectDesign
    scene_name: str
    object_where: str
    front_ends: np.ndarray
    share: np.ndarray
    centroid_deg: np.ndarray
    kept: np.ndarray
    truth: np.ndarray
    rts: np.ndarray

    @property
    def reproduces(self) -> np.ndarray:
        """(S, B) whether the design meets the tolerance at every range."""
        ok = ((self.share >= self.study.min_share)
              & (np.abs(self.centroid_deg) <= self.study.max_centroid_deg))
        return ok.all(axis=-1)

    def best(self) -> dict | None:
        """The smallest number of front ends (then the smallest budget, no limit last) that
        reproduces the object, or None."""
        cands = [(int(self.front_ends[i]), math.inf if b is None else b, i, j)
                 for i in range(len(self.study.spacings_deg))
                 for j, b in enumerate(self.study.budgets) if self.reproduces[i, j]]
        if not cands:
            return None
        n, _, i, j = min(cands)
        return {"front_ends": n, "spacing_deg": float(self.study.spacings_deg[i]),
                "max_targets_per_channel": self.study.budgets[j]}

    def _summary(self):
        best = self.best()
        rows = [("ranges", f"{min(self.study.ranges_m):g} .. {max(self.study.ranges_m):g} m"),
                ("tolerance", f"share >= {self.study.min_share:g}, |centroid| <= "
                              f"{self.study.max_centroid_deg:g} deg at every range"),
                ("smallest design", "none reproduces the object" if best is None else
                 f"{best['front_ends']} front ends {best['spacing_deg']:g} deg apart, budget "
                 f"{best['max_targets_per_channel'] or 'none'}")]
        for i, s in enumerate(self.study.spacings_deg):
            for j, b in enumerate(self.study.budgets):
                rows.append((f"{self.front_ends[i]} x {s:g} deg, budget {b or 'none'}",
                             f"min share {np.nanmin(self.share[i, j]):.2f}, max |centroid| "
                             f"{np.nanmax(np.abs(self.centroid_deg[i, j])):.2f} deg"
                             + (" (reproduces)" if self.reproduces[i, j] else "")))
        return f"{self.scene_name}: object design ({self.object_where})", rows

    def _columns(self) -> dict:
        st = self.study
        S, B, R = self.share.shape
        idx = np.indices((S, B, R)).reshape(3, -1)
        return {"spacing_deg": np.asarray(st.spacings_deg, float)[idx[0]],
                "front_ends": self.front_ends[idx[0]],
                "max_targets_per_channel": [st.budgets[j] or 0 for j in idx[1]],
                "range_m": np.asarray(st.ranges_m, float)[idx[2]],
                "reproduced_share": self.share.ravel(), "centroid_diff_deg":
                self.centroid_deg.ravel(), "kept": self.kept.ravel(),
                "truth_detections": self.truth.ravel(), "rts_detections": self.rts.ravel()}

    def to_dict(self) -> dict:
        df = self.to_dataframe()
        return {"scene": self.scene_name, "object": self.object_where,
                "min_share": self.study.min_share,
                "max_centroid_deg": self.study.max_centroid_deg, "best": self.best(),
                "rows": [{k: (None if isinstance(v, float) and math.isnan(v) else v)
                          for k, v in r.items()} for r in df.to_dict("records")]}

    def plot(self):
        """Share reproduced, centroid azimuth difference and targets kept over range, one line
        per design (both criteria of :attr:`reproduces` with their tolerance)."""
        from ..viz.figures import new_figure
        fig, (ax, cx, bx) = new_figure(figsize=(14.0, 4.2), ncols=3)
        r = np.asarray(self.study.ranges_m, float)
        for i, s in enumerate(self.study.spacings_deg):
            for j, b in enumerate(self.study.budgets):
                lab = f"{self.front_ends[i]} FE x {s:g} deg, budget {b or 'none'}"
                style = dict(ls=("-", "--", "-.", ":")[i % 4], marker="osd^v"[j % 5],
                             ms=5 - i % 3, color=f"C{j}", lw=2.2 - 0.6 * (i % 3))
                ax.plot(r, self.share[i, j], label=lab, **style)
                cx.plot(r, np.abs(self.centroid_deg[i, j]), label=lab, **style)
                bx.plot(r, self.kept[i, j], label=lab, **style)
        cx.axhline(self.study.max_centroid_deg, color="0.4", ls="--", lw=1, label="tolerance")
        cx.set_xlabel("object range (m)")
        cx.set_ylabel("|centroid azimuth, RTS - truth| (deg)")
        top = np.nanmax(np.r_[np.abs(self.centroid_deg).ravel(), self.study.max_centroid_deg])
        cx.set_ylim(0, 1.6 * top)  # room above the lines for the legend
        cx.legend(fontsize=7)
        cx.set_title("where the RTS puts the object")
        ax.axhline(self.study.min_share, color="0.4", ls="--", lw=1, label="tolerance")
        ax.set_xlabel("object range (m)")
        ax.set_ylabel("truth detections reproduced (share)")
        ax.set_ylim(-0.05, 1.05)
        ax.legend(fontsize=7)
        ax.set_title(f"{self.scene_name}: what the RTS reproduces", parse_math=False)
        bx.plot(r, self.truth[0, 0], color="k", lw=1, label="truth twin's detections")
        bx.set_xlabel("object range (m)")
        bx.set_ylabel("targets the RTS synthesizes")
        bx.legend(fontsize=7)
        bx.set_title("dynamic resolution")
        return fig
