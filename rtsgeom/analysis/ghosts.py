"""Cable ghosts: where and how strong the ghost targets of mismatched FE <-> back-end cables are
(paper section "Measurement": "spurious peaks ... with an additional range offset ... caused by
the mismatch of the characteristic impedance between the front ends and the coaxial cables").

The prediction is the signal chain's own model, :func:`rtsgeom.rts.channels.cable_ghosts`, applied to a
unit echo per front end: the n-th ghost has ``n`` extra round trips in the cable, an extra delay
``n 2 L / (VF c0)`` (a range offset ``n L / VF``) and the amplitude ``(n + 1) rho^n`` relative to
the target, ``rho = Gamma_fe Gamma_be a^2`` (``Gamma = 10^(-RL/20)``, ``a`` the one-way cable
loss; ``n + 1`` ways to share the round trips between the Rx and the Tx cable). Ghost orders
are listed down to a floor relative to the target.

With ``simulate``, the signal chain runs (each target on its nearest front end, the scene's
noise) and each predicted ghost is looked up in the range-Doppler map: the strongest cell within
+-1 range and Doppler bin of the predicted range and the target's Doppler, relative to the
target's own cell found the same way (the map level as a person reads it, with the scalloping
loss of each peak), and the peak of the range spectrum zoomed off the bin grid at that Doppler bin
(range and level without scalloping: what the model predicts).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.constants import c

from .._lib.results import Result
from ..geometry import build_setup
from ..radar.windows import window
from ..rts.channels import EchoKind, Echoes, cable_ghosts, program_nearest
from ..scene import Scene
from ..pipeline.run import run_scene

MAX_SUMMARY_TARGETS = 12  # targets listed in a summary
__all__ = ["DEFAULT_FLOOR_DB", "ghost_orders", "predict_ghosts", "measure_ghosts",
           "GhostReport", "ghost_analysis", "ghosts_figure"]

DEFAULT_FLOOR_DB = -80.0
ZOOM_POINTS = 401  # range zoom: +-1 bin in 1/200 bin steps (scalloping < 1e-4 dB)


def _unit_echoes(scene: Scene) -> Echoes:
    """One unit-amplitude direct echo per front end (one virtual channel, zero delay)."""
    n = len(scene.rts.front_ends)
    return Echoes.build(tau_air_s=np.zeros((n, 1)), amplitude=np.ones((n, 1), complex),
                        f_if_hz=scene.rts.f_rts_hz, target=0, front_end=np.arange(n),
                        kind=EchoKind.DIRECT)


def ghost_orders(scene: Scene, floor_db: float = DEFAULT_FLOOR_DB) -> list[dict]:
    """Per front end: its cable mismatch and the ghost orders above ``floor_db`` (delay, range
    offset, level relative to the direct echo), from ``rts.cable_ghosts``."""
    g = cable_ghosts(scene, _unit_echoes(scene), min_level_db=floor_db)
    out = []
    for q, fe in enumerate(scene.rts.front_ends):
        mismatched = fe.return_loss_fe_db is not None and fe.return_loss_be_db is not None
        sel = np.flatnonzero(g.front_end == q)
        sel = sel[np.argsort(g.order[sel])]
        out.append({
            "index": q,
            "mismatched": mismatched,
            "cable_length_m": fe.cable_length_m,
            "cable_velocity_factor": fe.cable_velocity_factor,
            "cable_loss_db": fe.cable_loss_db,
            "return_loss_fe_db": fe.return_loss_fe_db,
            "return_loss_be_db": fe.return_loss_be_db,
            "gamma_fe": None if fe.return_loss_fe_db is None else 10 ** (-fe.return_loss_fe_db / 20),
            "gamma_be": None if fe.return_loss_be_db is None else 10 ** (-fe.return_loss_be_db / 20),
            "range_offset_per_order_m": fe.cable_length_m / fe.cable_velocity_factor,
            "ghosts": [{"order": int(g.order[k]), "delay_s": float(g.tau_if_s[k]),
                        "range_offset_m": float(0.5 * c * g.tau_if_s[k]),
                        "level_db": float(20 * np.log10(np.abs(g.amplitude[k, 0])))}
                       for k in sel],
        })
    return out


def predict_ghosts(scene: Scene, floor_db: float = DEFAULT_FLOOR_DB) -> list[dict]:
    """Per target (on its nearest front end, as ``rts.program_nearest`` puts it): the ghosts'
    ranges ``R_t + n L / VF`` and levels relative to the target."""
    orders = ghost_orders(scene, floor_db)
    prog = program_nearest(scene, build_setup(scene))
    out = []
    for k, t in enumerate(scene.targets):
        q = int(prog.front_end[prog.target == k][0])
        out.append({
            "index": k, "range_m": t.range_m, "velocity_mps": t.velocity_mps,
            "angle_deg": float(np.degrees(t.angle_rad)), "front_end": q,
            "ghosts": [{**g, "range_m": t.range_m + g["range_offset_m"]}
                       for g in orders[q]["ghosts"]],
        })
    return out


# ------------------------------------------------------------------------------------------
# Simulated range-Doppler map
# ------------------------------------------------------------------------------------------


def _doppler_bin(rd, velocity_mps: float) -> int:
    n = rd.velocity_mps.size
    dv = rd.velocity_mps[1] - rd.velocity_mps[0]
    return int(np.round(velocity_mps / dv) + n // 2) % n


def _zoom_power(cube, doppler_bin: int, range_bins: np.ndarray) -> np.ndarray:
    """Range-Doppler power (sum over virtual channels) at fractional range bins of one Doppler
    bin: the same windowed DFTs as ``radar.processing.range_doppler``, the range one evaluated
    off the bin grid (no scalloping loss)."""
    radar = cube.radar
    n_l, _, n_s = cube.data.shape
    w_d = window(radar.doppler_window, n_l)
    k = (doppler_bin - n_l // 2) % n_l  # fftshifted bin -> DFT index
    y = np.einsum("l,lvn->vn", w_d * np.exp(-2j * np.pi * k * np.arange(n_l) / n_l), cube.data)
    n = np.arange(n_s)
    kern = window(radar.range_window, n_s) * np.exp(-2j * np.pi * np.outer(range_bins, n) / n_s)
    return np.sum(np.abs(kern @ y.T) ** 2, axis=1)


@dataclass(frozen=True)
class MapPeak:
    """A peak in a run's range-Doppler map (:func:`_peak`)."""

    range_bin: int  # the strongest map cell within +-1 bin of the looked-up point
    doppler_bin: int
    peak_db: float  # that cell's power (dB)
    range_m: float  # the peak of the range spectrum zoomed around it at that Doppler bin
    level_db: float  # the zoomed peak's power (dB, no scalloping loss)


def _peak(rd, cube, range_m: float, velocity_mps: float) -> MapPeak:
    """The strongest map cell within +-1 bin of (range, Doppler) (``peak_db``), and the peak
    of the range spectrum zoomed around it at that Doppler bin (``range_m``, ``level_db``)."""
    n_r, n_d = rd.power.shape
    dr = rd.range_m[1] - rd.range_m[0]
    r0 = int(np.round((range_m - rd.range_m[0]) / dr))
    d0 = _doppler_bin(rd, velocity_mps)
    rows = np.clip(np.arange(r0 - 1, r0 + 2), 0, n_r - 1)
    cols = np.arange(d0 - 1, d0 + 2) % n_d
    p = rd.power_db[np.ix_(rows, cols)]
    i, j = np.unravel_index(int(np.argmax(p)), p.shape)
    r, d = int(rows[i]), int(cols[j])
    fine = r + np.linspace(-1.0, 1.0, ZOOM_POINTS)
    zp = _zoom_power(cube, d, fine)
    k = int(np.argmax(zp))
    return MapPeak(r, d, float(rd.power_db[r, d]), float(rd.range_m[0] + fine[k] * dr),
                   float(10 * np.log10(max(zp[k], 1e-300))))


def measure_ghosts(result, predicted: list[dict]) -> list[dict]:
    """Look each predicted ghost up in a run's range-Doppler map (``run.RunResult``, targets on
    their nearest front ends). Levels are relative to the target's, found the same way:
    ``level_db_bin`` the strongest map cell within +-1 bin, ``level_db`` the zoomed peak."""
    rd, det = result.rd, result.detections
    cfar = result.scene.radar.cfar
    ring = cfar.guard_cells[0] + cfar.training_cells[0]
    dr = rd.range_m[1] - rd.range_m[0]
    median = float(np.median(rd.power_db))
    out = []
    for tgt in predicted:
        t = _peak(rd, result.cube, tgt["range_m"], tgt["velocity_mps"])
        entry = {"index": tgt["index"], "target_range_m": t.range_m,
                 "target_power_db": t.peak_db, "target_level_db": t.level_db,
                 "map_median_db": median - t.level_db,
                 "ghosts": []}
        for g in tgt["ghosts"]:
            if g["range_m"] > rd.range_m[-1]:
                entry["ghosts"].append({"order": g["order"], "beyond_max_range": True})
                continue
            m = _peak(rd, result.cube, g["range_m"], tgt["velocity_mps"])
            offset = m.range_m - t.range_m
            hit = (np.abs(det.range_bin - m.range_bin) <= 1) & \
                  (np.abs((det.doppler_bin - m.doppler_bin + rd.power.shape[1] // 2)
                          % rd.power.shape[1] - rd.power.shape[1] // 2) <= 1)
            entry["ghosts"].append({
                "order": g["order"],
                "predicted_range_m": g["range_m"], "predicted_level_db": g["level_db"],
                "range_m": m.range_m, "offset_from_target_m": offset,
                "offset_error_bins": (offset - g["range_offset_m"]) / dr,
                "level_db_bin": m.peak_db - t.peak_db,
                "level_db": m.level_db - t.level_db,
                "level_error_db": m.level_db - t.level_db - g["level_db"],
                "above_map_median_db": m.peak_db - median,
                "predicted_above_map_median_db": g["level_db"] + t.level_db - median,
                "within_cfar_window_of_target": bool(abs(m.range_bin - t.range_bin) <= ring),
                "cfar_detected": bool(np.any(hit)),
            })
        out.append(entry)
    return out


@dataclass(frozen=True, repr=False)
class GhostReport(Result):
    """Predicted (and simulated) cable ghosts. ``print(rep)`` is a summary;
    ``to_dataframe()`` one row per (target, ghost order); ``plot()`` the figure of
    ``rtsgeom ghosts --out``.

    Attributes
    ----------
    scene : Scene
    floor_db : float
    front_ends, targets : list of dict
        The predicted ghosts per front end and per target.
    simulated : list of dict or None
        Each ghost as read in the simulated range-Doppler map (``simulate``).
    """

    scene: Scene
    floor_db: float
    front_ends: list
    targets: list
    simulated: list | None = None
    result: object = None  # run.RunResult when simulated

    def _summary(self):
        title = (f"{self.scene.name}: cable ghosts above {self.floor_db:g} dB"
                 f"{', simulated' if self.simulated is not None else ''}")
        rows = [("mismatched front ends", str([f["index"] for f in self.front_ends
                                               if f["mismatched"]]))]
        for t in self.targets[:MAX_SUMMARY_TARGETS]:
            g = t["ghosts"]
            text = (", ".join(f"order {x['order']} at {x['range_m']:.3g} m {x['level_db']:.1f} dB"
                              for x in g[:3]) + (f" and {len(g) - 3} more" if len(g) > 3 else "")
                    if g else "none above the floor")
            rows.append((f"target {t['index']} ({t['range_m']:g} m, FE {t['front_end']})", text))
        if len(self.targets) > MAX_SUMMARY_TARGETS:
            rows.append(("...", f"{len(self.targets) - MAX_SUMMARY_TARGETS} more targets"))
        return title, rows

    def _columns(self) -> dict:
        keys = ("target", "front_end", "target_range_m", "order", "range_m", "level_db")
        rows = [(t["index"], t["front_end"], t["range_m"], g["order"], g["range_m"],
                 g["level_db"]) for t in self.targets for g in t["ghosts"]]
        cols = {k: [r[i] for r in rows] for i, k in enumerate(keys)}
        if self.simulated is not None:
            sim = {(s["index"] if "index" in s else k, m.get("order")): m.get("level_db")
                   for k, s in enumerate(self.simulated) for m in s.get("ghosts", [])}
            cols["simulated_level_db"] = [sim.get((r[0], r[3])) for r in rows]
        return cols

    def plot(self, title: str = ""):
        """Per target, its range profile with the predicted (and simulated) ghosts."""
        return ghosts_figure(self, title)

    def write(self, folder) -> list[str]:
        """``rtsgeom ghosts --out``: ghosts.json and ghosts.png into ``folder``; returns the
        names."""
        from ..viz.figures import save_figure  # matplotlib: only where a figure is written
        self.to_json(Path(folder) / "ghosts.json")
        save_figure(self.plot(), Path(folder) / "ghosts.png")
        return ["ghosts.json", "ghosts.png"]

    def to_dict(self) -> dict:
        r = self.scene.radar
        return {"scene": self.scene.name, "floor_db": self.floor_db,
                "range_resolution_m": float(r.range_resolution_m),
                "model": "rts.cable_ghosts: order n at +n L/VF, level (n+1) (Gamma_fe Gamma_be "
                         "a^2)^n, Gamma = 10^(-RL/20), a = 10^(-cable_loss_db/20)",
                "front_ends": self.front_ends, "targets": self.targets,
                "simulated": self.simulated}


def ghost_analysis(scene: Scene, floor_db: float = DEFAULT_FLOOR_DB, simulate: bool = False
                   ) -> GhostReport:
    """Predicted ghosts per front end and per target; with ``simulate`` also their levels in
    the simulated range-Doppler map (``run.run_scene(scene, aoa_mode="nearest")``)."""
    fes = ghost_orders(scene, floor_db)
    tg = predict_ghosts(scene, floor_db)
    if not simulate:
        return GhostReport(scene, floor_db, fes, tg)
    result = run_scene(scene, aoa_mode="nearest")
    return GhostReport(scene, floor_db, fes, tg, measure_ghosts(result, tg), result)


# ------------------------------------------------------------------------------------------
# Figure
# ------------------------------------------------------------------------------------------


def ghosts_figure(report: GhostReport, title: str = ""):
    """Per target, the range profile at its Doppler bin (dB relative to the target, when
    simulated) with the predicted ghost positions and levels marked (and the simulated ones)."""
    import matplotlib as mpl
    from ..viz.figures import STYLE, new_figure
    tg = report.targets
    n = max(len(tg), 1)
    ncols = 1 if n == 1 else 2
    nrows = int(np.ceil(n / ncols))
    with mpl.rc_context(STYLE):
        fig, axes = new_figure(figsize=(6.4, 1.9 * nrows + 0.6), nrows=nrows, ncols=ncols)
        axes = np.atleast_1d(axes).ravel()
        for ax in axes[len(tg):]:
            ax.set_visible(False)
        rd = report.result.rd if report.result is not None else None
        floor = report.floor_db
        for k, (ax, t) in enumerate(zip(axes, tg)):
            ghosts = t["ghosts"]
            hi = max([t["range_m"]] + [g["range_m"] for g in ghosts]) + 1.5
            lo = t["range_m"] - 1.5
            if rd is not None:
                sim = report.simulated[k]
                d = _doppler_bin(rd, t["velocity_mps"])
                prof = rd.power_db[:, d] - sim["target_level_db"]
                ax.plot(rd.range_m, prof, color="C0", linewidth=1.0,
                        label=f"map at {rd.velocity_mps[d]:+.2f} m/s")
                ax.axhline(sim["map_median_db"], color="0.6", linestyle=":", linewidth=0.9,
                           label="map median")
                meas = [m for m in sim["ghosts"] if not m.get("beyond_max_range")]
                if meas:
                    ax.plot([m["range_m"] for m in meas], [m["level_db"] for m in meas], "o",
                            mfc="none", color="C3", label="simulated ghost")
            ax.plot([t["range_m"]], [0.0], "v", color="k", label="target (0 dB)")
            for g in ghosts:
                ax.axvline(g["range_m"], color="C1", linestyle="--", linewidth=0.9)
            if ghosts:
                ax.plot([g["range_m"] for g in ghosts], [g["level_db"] for g in ghosts], "x",
                        color="C1", markersize=7, label="predicted ghost")
            ax.set_xlim(lo, hi)
            ax.set_ylim(min(floor, -60.0) - 5, 5)
            ax.set_title(f"target {k}: {t['range_m']:g} m, {t['velocity_mps']:+g} m/s, "
                         f"FE {t['front_end']}", fontsize=8)
            ax.set_xlabel("range (m)")
            ax.set_ylabel("dB re target")
        if tg:
            axes[0].legend(loc="upper right", fontsize=6)
        fig.suptitle(title or f"{report.scene.name}: cable ghosts", fontsize=10)
    return fig
