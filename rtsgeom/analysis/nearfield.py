"""Near-field violation: how far the arc radius R_c is from the far field the paper's signal
model assumes (section "Disadvantages": "the far-field condition is not met, and the virtual
array assumption is not fully accurate").

For a sweep of arc radii (front-end angles kept) and per front end:

(a) **Single front-end bias.** The angle the RuT detects one front end alone at, minus its
    geometric angle (module centre seen from the RuT phase centre), at phasor level with the
    exact geometry (``radar.phasors.bin_response`` through :class:`~rtsgeom.synthesis.model.ChannelModel`,
    TDM compensation, ``estimate_angles``). It is split into closed-form parts:

    * ``separation``: the front end's own Rx/Tx split, far-field closed form
      ``geometry.farfield.apparent_azimuth_rad`` minus geometric (~ 0.52 s / (2 R));
    * ``near_field`` = detected - that closed form, itself split into
      ``parallax``: the RuT's Tx group and Rx group sit 9.5 d apart (AWR1843BOOST), so the Tx
      see the front end's Rx antenna, and the Rx its Tx antenna, from their own centroids, not
      from the virtual phase centre (the "virtual array assumption" of eq. 13 breaks down);
      closed form :func:`group_azimuth_rad`, ~ 2.5 d cos^2(theta) / R;
      ``beat_frequency``: an echo of total delay tau reaches the ADC window at
      ``f_c + B/2 - S tau`` while the beamformer steers at ``f_c + B/2``, so sin(alpha) reads
      ``1 - S tau / (f_c + B/2)`` too small (range-angle coupling; depends on the target's range,
      not on R_c; ~1e-4 deg here);
      ``curvature``: the rest, phase-front curvature within each group and the beamformer's
      response to it; it falls about like 1/R^3 (a symmetric phase error does not move the
      beam peak to first order): 5e-4 deg at 1 m.

    Separation and parallax are both first order in 1/R: the bias falls like 1/R, and the
    phase-centre far-field closed form explains only about half of it at *any* radius.

(b) **Phase error across the virtual array**: the exact two-way phase minus its best-fit plane
    wave over the azimuth virtual array (what beamforming cannot absorb as a steering angle),
    peak to peak and RMS; mostly the non-planar virtual phase of (a) (Rx/Tx separation and
    parallax, ~ 1/R), with the pure curvature part reported on its own.

(c) **Synthesized angle.** For each adjacent pair, the worst |detected - set| over the pair's
    span when the amplitude ratio comes from the ``array-factor`` closed form (far field,
    geometric angles) versus ``exact`` (solved on the modelled RuT output of the nominal setup),
    phasor level, phase-coherent channels (what the calibration establishes).

**2-D cells** (a RuT that beamforms in azimuth and elevation, ``Steering.auto`` with D = 2,
e.g. ``scenes/sphere4.toml``): (a) each front end alone is detected by the 2-D beamformer, and
its bias is reported in both angles (the azimuth part split into the same closed forms as in
1-D, which are those of the azimuth row; the elevation bias as detected, no closed form);
(b) the phase error is the residual after the best-fit *plane* over the 2-D virtual positions
(x, z); (c) the synthesized angle is checked over a grid of set directions inside each cell
of front ends (the one cell of 3 or 4 front ends, else the Delaunay triangles of their
direction cosines) with the ``array-factor`` closed form in 2-D and ``exact`` peak matching
(``synthesis.model.ChannelModel``), errors in both angles. The 1-D analysis is the D = 1 case: the
cells are the adjacent pairs and the fit a line.

The Fraunhofer distance ``2 d_A^2 / lambda`` of the virtual aperture is reported alongside: at
0.12 m it is far below R_c = 1 m, yet the bias is 0.57 deg, because the bias is a first-order
(1/R) angle effect of the antenna *offsets* (Rx/Tx split, Tx/Rx groups), not the second-order
phase-front curvature the Fraunhofer criterion bounds.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..calibration.probes import probe_ranges
from ..errors import ParameterError
from .._lib.results import Result
from ..geometry import build_setup
from ..geometry.farfield import aperture_m, apparent_azimuth_rad, fraunhofer_distance_m
from ..geometry.setup import nominal_scene, warn_setup_errors
from ..paths import exact_paths
from ..radar.steering import Steering, smoothed_estimator
from ..scene import Scene
from .nearfield_terms import (beat_frequency_azimuth_rad, echo_delay_s, group_azimuth_rad,
                              phase_error_deg, single_front_end_angles_rad, synthesis_errors)

__all__ = ["DEFAULT_DECADES", "DEFAULT_POINTS", "MIN_RADIUS_M", "max_radius_m", "default_radii",
           "with_arc_radius", "NearField", "nearfield", "nearfield_figure"]

DEFAULT_DECADES = (-0.5, 1.5)  # default sweep: R_c * 10^-0.5 ... R_c * 10^1.5 (0.32 m to 32 m)
DEFAULT_POINTS = 13  # 6 per decade, so R_c itself is one of them


MIN_RADIUS_M = 0.05  # the smallest arc radius analysed


def max_radius_m(scene: Scene) -> float:
    """The largest arc radius analysed: the probe target (``calibration.probe_ranges``, at
    least R_c + 2 m) must stay within 80 % of the radar's maximum range."""
    return 0.8 * scene.radar.max_range_m - 2.0


def default_radii(scene: Scene, points: int = DEFAULT_POINTS) -> np.ndarray:
    """Log-spaced arc radii around the scene's, the scene's radius included (odd ``points``
    centred on it in log scale for the default decades), clipped to
    [:data:`MIN_RADIUS_M`, :func:`max_radius_m`] (the clipped end itself kept as the last or
    first radius: a short-range radar's sweep stops at its own limit instead of failing)."""
    r = scene.rts.arc_radius_m * np.logspace(*DEFAULT_DECADES, points)
    lo, hi = MIN_RADIUS_M, max_radius_m(scene)
    inside = r[(r >= lo) & (r <= hi)]
    return np.unique(np.concatenate([[lo] if r[0] < lo else [], inside,
                                     [hi] if r[-1] > hi else []]))


def with_arc_radius(scene: Scene, radius_m: float) -> Scene:
    """The scene with another arc radius (front-end angles, offsets and cables kept)."""
    return dataclasses.replace(scene, rts=dataclasses.replace(scene.rts,
                                                              arc_radius_m=float(radius_m)))


# ------------------------------------------------------------------------------------------
# The sweep
# ------------------------------------------------------------------------------------------


@dataclass(frozen=True, repr=False)
class NearField(Result):
    """Near-field figures of merit over arc radius (arrays (R, F) unless noted, degrees).
    ``print(nf)`` is a summary; ``to_dataframe()`` one row per (radius, front end);
    ``plot()`` the figure of ``rtsgeom nearfield --out``.

    Attributes
    ----------
    radius_m : (R,) float
    geometric_deg, detected_deg : (R, F) float
        Each front end's geometric and detected azimuth per radius.
    synthesis : list
        The synthesized-angle errors per radius.
    fraunhofer_m : float
    """

    scene: Scene
    radius_m: np.ndarray  # (R,)
    range_m: np.ndarray  # (R,) target range of the phasor-level detection
    geometric_deg: np.ndarray
    detected_deg: np.ndarray
    separation_deg: np.ndarray  # apparent_azimuth_rad - geometric
    parallax_deg: np.ndarray  # group_azimuth_rad - apparent_azimuth_rad
    beat_frequency_deg: np.ndarray  # range-dependent carrier of the echo
    phase_pp_deg: np.ndarray
    phase_rms_deg: np.ndarray
    curvature_pp_deg: np.ndarray
    synthesis: list  # per radius: list of per-pair (1-D) or per-cell (2-D) dicts
    fraunhofer_m: float
    aperture_m: float
    wavelength_m: float
    # 2-D beamformer (D = 2): each front end's geometric and detected elevation (R, F)
    geometric_el_deg: np.ndarray | None = None
    detected_el_deg: np.ndarray | None = None

    @property
    def elevation_bias_deg(self) -> np.ndarray | None:
        """Detected minus geometric elevation (R, F); None for an azimuth-only RuT."""
        if self.detected_el_deg is None:
            return None
        return self.detected_el_deg - self.geometric_el_deg

    @property
    def bias_deg(self) -> np.ndarray:
        return self.detected_deg - self.geometric_deg

    @property
    def near_field_deg(self) -> np.ndarray:
        """Detected minus the far-field closed form (everything but the Rx/Tx separation)."""
        return self.bias_deg - self.separation_deg

    @property
    def curvature_deg(self) -> np.ndarray:
        """What the closed forms leave: phase-front curvature (and beamformer nonlinearity)."""
        return self.near_field_deg - self.parallax_deg - self.beat_frequency_deg

    def scene_index(self) -> int | None:
        """Index of the scene's own radius in the sweep, if it is one of the radii."""
        k = np.flatnonzero(np.isclose(self.radius_m, self.scene.rts.arc_radius_m, rtol=1e-9))
        return int(k[0]) if k.size else None

    def _smoothed(self) -> bool:
        radar = self.scene.radar
        return smoothed_estimator(radar.angle_estimator, radar.angle_subarray)

    def bias_times_radius_deg_m(self) -> np.ndarray:
        """(F,) the 1/R coefficient of the bias: (separation + parallax) x R at the largest
        radius (the closed forms of the beamformer's peak; the detected bias x R agrees to
        ~1 % over the sweep); for a smoothed Capon or MUSIC, which peaks elsewhere (twice
        the beamformer's bias on the default scene), the median over the sweep of the
        detected bias x R (at the largest radius alone, where the bias is smallest, it read
        2-7 % low)."""
        if self._smoothed():
            return np.median(self.bias_deg * self.radius_m[:, None], axis=0)
        return (self.separation_deg[-1] + self.parallax_deg[-1]) * self.radius_m[-1]

    def _summary(self):
        title = (f"{self.scene.name}: near field over {self.radius_m.size} arc radii "
                 f"({self.radius_m.min():g} to {self.radius_m.max():g} m), "
                 f"{self.geometric_deg.shape[1]} front ends")
        coef = self.bias_times_radius_deg_m()
        rows = [("radius_m", self.radius_m), ("bias_deg", self.bias_deg),
                ("separation_deg", self.separation_deg), ("parallax_deg", self.parallax_deg),
                ("curvature_deg", self.curvature_deg), ("phase_pp_deg", self.phase_pp_deg),
                ("bias x R", f"{np.max(np.abs(coef)):.3g} deg m (largest |.| over the front "
                             f"ends): below 0.01 deg from R_c "
                             f"{np.max(np.abs(coef)) / 0.01:.3g} m"),
                ("fraunhofer_m", self.fraunhofer_m), ("aperture_m", self.aperture_m)]
        k = self.scene_index()
        if k is not None:
            rows.append((f"at R_c {self.radius_m[k]:g} m",
                         f"|bias| up to {np.max(np.abs(self.bias_deg[k])):.4g} deg"))
        return title, rows

    def _columns(self) -> dict:
        r, f = self.geometric_deg.shape
        cols = {"radius_m": np.repeat(self.radius_m, f), "front_end": np.tile(np.arange(f), r)}
        for name in ("geometric_deg", "detected_deg", "bias_deg", "separation_deg",
                     "parallax_deg", "beat_frequency_deg", "curvature_deg", "phase_pp_deg",
                     "phase_rms_deg", "curvature_pp_deg"):
            cols[name] = np.ravel(getattr(self, name))
        if self.detected_el_deg is not None:
            cols["elevation_bias_deg"] = np.ravel(self.elevation_bias_deg)
        return cols

    def plot(self, title: str = ""):
        """The bias and its parts over arc radius, the phase errors and the synthesis."""
        return nearfield_figure(self, title)

    def write(self, folder) -> list[str]:
        """``rtsgeom nearfield --out``: nearfield.json and nearfield.png into ``folder``; returns the
        names."""
        from ..viz.figures import save_figure  # matplotlib: only where a figure is written
        self.to_json(Path(folder) / "nearfield.json")
        save_figure(self.plot(), Path(folder) / "nearfield.png")
        return ["nearfield.json", "nearfield.png"]

    def to_dict(self) -> dict:
        fl = lambda a: [float(x) for x in a]  # noqa: E731
        k = self.scene_index()
        coef = self.bias_times_radius_deg_m()
        return {
            "scene": self.scene.name,
            "scene_arc_radius_m": self.scene.rts.arc_radius_m,
            "wavelength_m": self.wavelength_m,
            "aperture_m": self.aperture_m,
            "fraunhofer_distance_m": self.fraunhofer_m,
            "fraunhofer_note": "2 d_A^2 / lambda of the azimuth virtual aperture; it bounds the "
                               "phase-front curvature, not the first-order (1/R) bias from the "
                               "Rx/Tx separation and the RuT's Tx/Rx group parallax",
            "bias_1_over_r_coefficient_deg_m": fl(coef),
            "bias_1_over_r_coefficient_from": (
                "the detected bias x R, median over the radii (a smoothed estimator)"
                if self._smoothed() else "the closed forms (separation + parallax)"),
            "radius_for_bias_below_deg": {
                str(lim): fl(np.abs(coef) / lim) for lim in (0.1, 0.01)},
            "at_scene_radius": None if k is None else self._row(k),
            "radii": [self._row(i) for i in range(self.radius_m.size)],
        }

    def _row(self, i: int) -> dict:
        fes = []
        for q in range(self.geometric_deg.shape[1]):
            fes.append({
                "index": q,
                "geometric_deg": float(self.geometric_deg[i, q]),
                "detected_deg": float(self.detected_deg[i, q]),
                "bias_deg": float(self.bias_deg[i, q]),
                "separation_part_deg": float(self.separation_deg[i, q]),
                "near_field_part_deg": float(self.near_field_deg[i, q]),
                "parallax_part_deg": float(self.parallax_deg[i, q]),
                "beat_frequency_part_deg": float(self.beat_frequency_deg[i, q]),
                "curvature_part_deg": float(self.curvature_deg[i, q]),
                "phase_error_pp_deg": float(self.phase_pp_deg[i, q]),
                "phase_error_rms_deg": float(self.phase_rms_deg[i, q]),
                "curvature_phase_error_pp_deg": float(self.curvature_pp_deg[i, q]),
            })
            if self.detected_el_deg is not None:
                fes[-1].update({
                    "geometric_elevation_deg": float(self.geometric_el_deg[i, q]),
                    "detected_elevation_deg": float(self.detected_el_deg[i, q]),
                    "elevation_bias_deg": float(self.elevation_bias_deg[i, q])})
        return {"radius_m": float(self.radius_m[i]), "target_range_m": float(self.range_m[i]),
                "front_ends": fes, "synthesis": self.synthesis[i]}


def _check_radii(scene: Scene, radii: np.ndarray) -> None:
    r = np.asarray(radii, float)
    limit = max_radius_m(scene)
    bad = r[~(np.isfinite(r) & (r >= MIN_RADIUS_M) & (r <= limit))] if r.ndim == 1 else r
    if r.ndim != 1 or r.size == 0 or bad.size:
        got = ", ".join(f"{x:.4g}" for x in np.ravel(bad)[:4]) if np.size(bad) else "none"
        raise ParameterError(f"arc radii must lie in [{MIN_RADIUS_M:g}, {limit:.4g}] m (the probe "
                             f"target must stay within the radar's range), got {got} m")


def nearfield(scene: Scene, radii=None, points: int = 11) -> NearField:
    """Run the near-field analysis over ``radii`` (default :func:`default_radii`).

    ``points``: synthesized set-points per pair for (c).
    """
    warn_setup_errors(scene, "nearfield", "analyses the arc's near field on the nominal "
                      "setup: the scene's own errors ({}) play no part")
    radii = default_radii(scene) if radii is None else np.asarray(radii, float)
    _check_radii(scene, radii)
    cols = {k: [] for k in ("rng", "geo", "det", "sep", "par", "beat", "pp", "rms", "curv",
                            "geo_el", "det_el")}
    synth = []
    rut = None
    two_d = False
    # The analysis places its own probe target (``probe_ranges``) and uses exact free-space
    # paths: the scene's targets and sheet play no part. Dropped, so that a radius where the
    # targets would lie inside the arc, or the cutouts would overlap, is still analysed. It
    # is the arc's near field, on the nominal setup (``nominal_scene``): a scene's own
    # mounting, channel or RuT pose errors had entered the detected angles but not the
    # synthesis's set-points (0.5 deg of RuT yaw read as 0.5 deg of "exact" synthesis error).
    probe_scene = nominal_scene(scene, validate=False).derive(
        targets=(), sheet=scene.sheet.derive(enabled=False))
    for r in radii:
        setup = build_setup(with_arc_radius(probe_scene, r))
        paths = exact_paths(setup)
        rut, fe, radar = setup.rut, setup.fe, scene.radar
        rng = float(probe_ranges(setup, 1)[0])
        st = Steering.auto(rut, radar)  # the beamformer the RuT runs
        two_d = st.dims == 2
        geo = setup.fe_azimuth_rad()
        if two_d:  # (azimuth, elevation) of each front end alone, by the 2-D beamformer
            both = single_front_end_angles_rad(setup, paths, rng, st)
            det = both[:, 0]
            geo_both = st.angles(setup.fe_direction_cosines())
            geo = geo_both[:, 0]
            cols["geo_el"].append(geo_both[:, 1])
            cols["det_el"].append(both[:, 1])
        else:
            det = single_front_end_angles_rad(setup, paths, rng)
        app = apparent_azimuth_rad(rut, fe.rx, fe.tx)
        grp = group_azimuth_rad(rut, fe.rx, fe.tx, st.mask if two_d else None)
        beat = beat_frequency_azimuth_rad(grp, radar, echo_delay_s(setup, rng))
        ph = phase_error_deg(setup, st if two_d else None)
        for key, val in (("rng", rng), ("geo", geo), ("det", det), ("sep", app - geo),
                         ("par", grp - app), ("beat", beat - grp), ("pp", ph["pp"]),
                         ("rms", ph["rms"]), ("curv", ph["curvature_pp"])):
            cols[key].append(val)
        synth.append(synthesis_errors(setup, paths, st, rng, det, points))
    deg = {k: np.degrees(np.array(cols[k])) for k in ("geo", "det", "sep", "par", "beat")}
    el = ({"geometric_el_deg": np.degrees(np.array(cols["geo_el"])),
           "detected_el_deg": np.degrees(np.array(cols["det_el"]))} if two_d else {})
    return NearField(
        scene=scene, radius_m=radii, range_m=np.array(cols["rng"]),
        geometric_deg=deg["geo"], detected_deg=deg["det"], separation_deg=deg["sep"],
        parallax_deg=deg["par"], beat_frequency_deg=deg["beat"],
        phase_pp_deg=np.array(cols["pp"]), phase_rms_deg=np.array(cols["rms"]),
        curvature_pp_deg=np.array(cols["curv"]), synthesis=synth,
        fraunhofer_m=fraunhofer_distance_m(rut), aperture_m=aperture_m(rut),
        wavelength_m=rut.wavelength_m, **el)


# ------------------------------------------------------------------------------------------
# Figure
# ------------------------------------------------------------------------------------------


def nearfield_figure(nf: NearField, title: str = ""):
    """Three panels over arc radius (log x): the bias of each front end alone (log y when all
    positive) with the far-field closed form (Rx/Tx separation only) and the closed form with
    the RuT's Tx/Rx group parallax; the worst synthesized-angle error per pair (array-factor;
    exact in the legend); the phase error across the virtual array (p-p, RMS, curvature only).
    The scene's radius and the Fraunhofer distance are marked."""
    import matplotlib as mpl
    from ..viz.figures import STYLE, new_figure
    r = nf.radius_m
    with mpl.rc_context(STYLE):
        fig, (ax, ax2, ax3) = new_figure(figsize=(6.4, 7.2), nrows=3, sharex=True)
        for q in range(nf.geometric_deg.shape[1]):
            col = f"C{q % 10}"
            lab = f"FE {q} ({nf.geometric_deg[0, q]:.1f} deg)"
            ax.plot(r, nf.bias_deg[:, q], "o", color=col, label=f"{lab}: detected - geometric")
            if nf.elevation_bias_deg is not None:
                ax.plot(r, np.abs(nf.elevation_bias_deg[:, q]), "x", color=col,
                        label=f"{lab}: |elevation bias|")
            ax.plot(r, nf.separation_deg[:, q], "-", color=col,
                    label=f"{lab}: far-field closed form (Rx/Tx separation)")
            ax.plot(r, (nf.separation_deg + nf.parallax_deg)[:, q], "--", color=col,
                    label=f"{lab}: + RuT Tx/Rx group parallax")
            ax3.plot(r, nf.phase_pp_deg[:, q], "-", color=col, label=f"{lab}: p-p")
            ax3.plot(r, nf.phase_rms_deg[:, q], "--", color=col, label=f"{lab}: RMS")
            ax3.plot(r, nf.curvature_pp_deg[:, q], ":", color=col,
                     label=f"{lab}: curvature only, p-p")
        for k in range(len(nf.synthesis[0]) if nf.synthesis else 0):
            pick = lambda key: np.array([np.nan if row[k][key] is None else row[k][key]  # noqa: E731
                                         for row in nf.synthesis])
            af, ex = pick("array_factor_max_abs_error_deg"), pick("exact_max_abs_error_deg")
            ex_max = np.nanmax(ex) if np.any(np.isfinite(ex)) else np.nan
            first = nf.synthesis[0][k]
            name = ("cell " + "-".join(str(q) for q in first["cell"]) if "cell" in first
                    else f"pair {k}-{k + 1}")
            ax2.plot(r, af, "s-", color=f"C{k % 10}", label=f"{name}: array-factor "
                     f"(exact: <= {ex_max:.1g} deg)")
        for a in (ax, ax2, ax3):
            a.set_xscale("log")
            a.axvline(nf.scene.rts.arc_radius_m, color="C3", linewidth=0.9, linestyle="-.")
            a.axvline(nf.fraunhofer_m, color="0.4", linewidth=0.9, linestyle="-.")
        if np.all(nf.bias_deg > 0) and np.all(nf.separation_deg > 0):
            ax.set_yscale("log")
        ax2.set_yscale("log")
        ax3.set_yscale("log")
        ax.text(nf.scene.rts.arc_radius_m, 0.97, " scene R_c", color="C3", fontsize=7,
                transform=ax.get_xaxis_transform(), va="top")
        ax.text(nf.fraunhofer_m, 0.97, r" $2 d_A^2/\lambda$", color="0.3", fontsize=7,
                transform=ax.get_xaxis_transform(), va="top")
        ax.set_ylabel("single-FE bias (deg)")
        ax.set_title(title or f"{nf.scene.name}: near-field bias vs arc radius")
        ax2.set_ylabel("synthesized |error| (deg)")
        ax3.set_ylabel("phase error (deg)")
        ax3.set_xlabel("arc radius R_c (m)")
        for a in (ax, ax2, ax3):
            if a.get_legend_handles_labels()[0]:
                # the single-FE bias may be negative (Rx at the smaller azimuth): let
                # matplotlib place that legend clear of its curves
                a.legend(loc="best" if a is ax else "lower left", fontsize=6,
                         ncols=2 if a is ax3 else 1)
    return fig
