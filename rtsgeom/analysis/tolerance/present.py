"""How a tolerance study's result shows itself: its short summary, its per-draw table and its
figure (the CDF of each draw's worst error; an arc's histogram). The functions take a
:class:`~.montecarlo.ToleranceResult`; its methods call them."""

from __future__ import annotations

import numpy as np

__all__ = ["scales_text", "subject", "summary", "columns", "figure"]


def scales_text(res) -> str:
    """The drawn errors' scales in words: ``sigma r/t/h 0.1/0.1/0.1 mm`` (``bound`` for
    uniform draws) and the rotations and RuT pose where drawn."""
    b = res.bounds
    word = "sigma" if res.distribution == "normal" else "bound"
    parts = [f"{word} r/t/h " + "/".join(f"{1e3 * s:g}" for s in b.offsets_m) + " mm"]
    if b.yaw_rad or b.pitch_rad:
        parts.append(f"yaw/pitch {np.degrees(b.yaw_rad):g}/{np.degrees(b.pitch_rad):g} deg")
    if any(b.rut_position_m) or b.rut_yaw_rad:
        parts.append("RuT " + "/".join(f"{1e3 * s:g}" for s in b.rut_position_m)
                     + f" mm, {np.degrees(b.rut_yaw_rad):g} deg")
    return ", ".join(parts)


def subject(res) -> str:
    """What was studied: ``pair (0, 1)``, ``cell (0, 1, 2, 3)``, ``arc of 5 front ends``."""
    sets = res.model.sets
    if res.model.kind == "arc":
        return f"arc of {res.model.count} front ends ({len(sets)} pairs)"
    return f"{res.model.kind} {tuple(sets[0].front_ends)}"


def _points(res) -> int:
    """Set-points per draw over every set."""
    return int(sum(np.asarray(m.set_rad).shape[0] for m in res.model.sets))


def _worst(res, case) -> np.ndarray:
    """|worst angle error| per draw (deg): a pair's, a cell's worst angle, an arc's worst."""
    if res.model.kind == "arc":
        return np.abs(res.arc_worst(case))
    e = np.abs(res.errors_deg[case][:, 0])
    return e[:, 0] if res.model.kind == "pair" else np.max(e[:, :2], axis=-1)


def summary(res) -> tuple[str, list]:
    title = (f"{subject(res)} mounting tolerance, {res.draws} draws ({scales_text(res)}), "
             f"spec {res.spec_deg:g} deg")
    rows = []
    for case in res.errors_deg:
        w = _worst(res, case)
        p = np.percentile(w, [50, 95]) if w.size else (np.nan, np.nan)
        rows.append((case, f"yield {100 * res.yield_(case):.2f} %; |worst error| p50 "
                           f"{p[0]:.3g}, p95 {p[1]:.3g}, max {np.max(w, initial=0):.3g} deg"))
    total = res.draws * _points(res)
    for name, counts in (("off_bin", res.off_bin_per_set),
                         ("fallbacks", res.fallbacks_per_set)):
        text = ", ".join(f"{case} {int(np.sum(v))}" for case, v in counts.items())
        rows.append((name, f"{text} of {total} set-points (draws x set-points)"))
    delay = np.abs(np.asarray(res.delay_s, float))
    if res.model.kind == "cell":
        delay = delay[:, 1:]
    if delay.size:
        rows.append(("calibration", f"|delta tau| p95 {1e12 * np.percentile(delay, 95):.3g} ps, "
                                    f"|range offset| p95 "
                                    f"{1e3 * np.percentile(np.abs(res.range_offset_m), 95):.3g} mm"))
    rows += [("seed", res.seed), ("elapsed_s", res.elapsed_s)]
    return title, rows


def columns(res) -> dict:
    """One row per draw: ``draw``, per case its worst signed error (deg; a cell's azimuth,
    elevation and angular distance, an arc's per pair and the arc's worst) and ``<case>_passes``,
    then the calibration delay (ps) and the range offset (mm) (an arc's per pair)."""
    cols = {"draw": np.arange(res.draws)}
    kind = res.model.kind
    pairs = ["_".join(str(q) for q in m.front_ends) for m in res.model.sets]
    for case, e in res.errors_deg.items():
        if kind == "pair":
            cols[f"{case}_error_deg"] = e[:, 0, 0]
        elif kind == "cell":
            for k, name in enumerate(("azimuth", "elevation", "distance")):
                cols[f"{case}_{name}_error_deg"] = e[:, 0, k]
        else:
            for p, name in enumerate(pairs):
                cols[f"{case}_pair_{name}_error_deg"] = e[:, p, 0]
            cols[f"{case}_arc_error_deg"] = res.arc_worst(case)
        cols[f"{case}_passes"] = res.passes(case)
    delay, rng = np.asarray(res.delay_s), np.asarray(res.range_offset_m)
    if kind == "arc":
        for p, name in enumerate(pairs):
            cols[f"delay_pair_{name}_ps"] = 1e12 * delay[:, p]
            cols[f"range_offset_pair_{name}_mm"] = 1e3 * rng[:, p]
    else:
        if kind == "cell":
            for q in range(1, delay.shape[1]):
                cols[f"delay_channel_{q}_ps"] = 1e12 * delay[:, q]
        else:
            cols["delay_ps"] = 1e12 * delay
        cols["range_offset_mm"] = 1e3 * rng
    return cols


def figure(res, title: str = ""):
    """A pair's and a cell's empirical CDF of each draw's worst |error| (a cell's angular
    distance), an arc's histogram of each arc's worst error; the title says the study, the
    drawn scales and the spec."""
    from ...viz.figures import tolerance_cdf_figure, tolerance_histogram_figure
    head = title or f"{subject(res)}, {res.draws} draws, {scales_text(res)}"
    cases = list(res.errors_deg)
    if res.model.kind == "arc":
        p95 = max(float(np.percentile(np.abs(res.arc_worst(c)), 95)) for c in cases)
        lim = max(5 * res.spec_deg, 1.2 * p95)
        return tolerance_histogram_figure(
            {c: np.clip(res.arc_worst(c), -lim, lim) for c in cases}, res.spec_deg,
            f"Worst error per arc (clipped at ±{lim:.2g} deg)\n{head}")
    if res.model.kind == "cell":
        return tolerance_cdf_figure({c: res.worst_error_deg[c][:, 2] for c in cases},
                                    res.spec_deg, f"Worst angular distance per setup\n{head}")
    return tolerance_cdf_figure({c: res.worst_error_deg[c] for c in cases}, res.spec_deg,
                                f"Worst |error| per setup\n{head}")
