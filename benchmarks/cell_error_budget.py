"""``python -m benchmarks.cell_error_budget``: where a 2-D cell's synthesis error comes from.

On ``scenes/sphere4.toml`` and variants of it (a hardware phase offset on front end 1, other
radii, other elevation spacings of the front ends, targets on a grid inside the cell), each
target's detected (azimuth, elevation) error is taken apart by switching one cause off at a
time:

* ``run``: the run as ``rtsgeom run`` does it (measured channel calibration, the planner's cell branch,
  one noisy frame through the ADC-cube chain);
* ``noiseless``: the same programme, a frame without noise (``snr_db`` None): run - this is
  the receiver noise's share;
* ``ideal_cal``: noiseless, the calibration's per-channel offsets replaced by the continuous
  coherence points of its tree pairs on the setup as built (``ncal.coherence_point_nd``,
  added along the same tree, wrapped like ``calibrate_channels``): noiseless - this is the
  calibration residual's share;
* ``ideal_cal_model``: the same programme read by the phasor model of the setup as built
  (``ChannelModel`` on the true setup, the RuT's own beamformer, the strongest of the
  candidate bins), instead of the chain: the chain's own difference (should be ~0);
* ``no_quant``: ideal calibration unrounded on a scene whose RTS realises any delay (1 fs
  steps, ideal FIR): ideal_cal - this is the delay quantisation's share (the RTS has no
  amplitude quantisation to switch off);
* ``bin_centre``: ``ideal_cal`` with each target moved to the centre of its range bin;
* ``bins``: per target the design's strongest candidate bin and its power over the next
  (``margin``: near 1 is a bin edge where two bins carry nearly equal power);
* ``array_factor``: the far-field closed form's error through the true model (what the near
  field would cost if the design ignored it).

Writes ``benchmarks/cell_error_budget.json``; prints one line per target and case.
``--quick``: the bundled scene and the 180 deg case only. ``--part noise``
(``cell_error_budget_noise.json``): the run's frame noise over 40 frames against the array's
Cramer-Rao bound, and each channel's delay sensitivity (:func:`noise_study`). ``--part
frames`` (``cell_error_budget_frames.json``): the proposed fix, the calibration's sweeps
averaging 16 frames a step (:func:`frames_study`). The findings: README, "Where a cell's
angle error comes from".
"""

from __future__ import annotations

import argparse
import copy
import time
import tomllib
from pathlib import Path

import numpy as np

from benchmarks._io import write_json

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "scenes" / "sphere4.toml"
SPEC_DEG = 0.03


def scene_doc(phase_deg: float = 0.0, radius_m: float = 1.0, el_deg: float = 5.0,
              targets=None, step_s: float | None = None, ideal_fir: bool = False) -> dict:
    """sphere4's TOML document with front end 1's hardware phase ``phase_deg``, arc radius
    ``radius_m`` (the sheet's cap scaled with it), front ends at elevation +-``el_deg`` and
    ``targets`` [(range, az, el)]."""
    doc = copy.deepcopy(tomllib.loads(SCENE.read_text()))
    doc["rts"]["arc_radius_m"] = radius_m
    doc["sheet"]["height_m"] = 0.3 * radius_m
    for fe in doc["rts"]["front_ends"]:
        fe["elevation_deg"] = float(np.sign(fe["elevation_deg"]) * el_deg)
    if phase_deg:
        doc["rts"]["front_ends"][1]["phase_offset_deg"] = phase_deg
    if targets is not None:
        doc["targets"] = [{"range_m": float(r), "angle_deg": float(a), "elevation_deg": float(e)}
                          for r, a, e in targets]
    if step_s is not None:
        doc["rts"]["fractional_delay_step_s"] = step_s
    if ideal_fir:
        doc["rts"]["fractional_delay_filter"] = "ideal"
    return doc


def parse(doc):
    from rtsgeom.scene import parse_scene
    return parse_scene(doc, str(SCENE))


class Bench:
    """One scene: setup, paths, probe, the measured and the ideal calibration."""

    def __init__(self, scene):
        from rtsgeom.calibration.probes import probe_front_ends
        from rtsgeom.geometry import build_setup
        from rtsgeom.paths import compute_paths
        self.scene = scene
        self.setup = build_setup(scene)
        self.paths = compute_paths(self.setup, "exact")
        self.probe = probe_front_ends(self.setup, self.paths, scene.seed)
        self.cal = None
        self.ideal = None

    def used(self):
        from rtsgeom.paths import nominal_model
        from rtsgeom.pipeline.plan import target_cells
        nom, _ = nominal_model(self.setup, self.paths)
        _, _, found = target_cells(nom)
        return sorted({q for cell, _ in found for q in cell})

    def calibrate(self):
        from rtsgeom.calibration.channels import calibrate_channels
        self.cal = calibrate_channels(self.setup, self.paths, self.used(), self.probe)
        return self.cal

    def ideal_calibration(self, cal, rounded: bool = True):
        """``cal`` with its tree pairs at their continuous coherence points."""
        import dataclasses

        from rtsgeom.calibration.steps import realisable
        from rtsgeom.calibration.pair import pair_coherence
        meas = {tuple(p["pair"]): p for p in cal.pairs}
        off = np.zeros(self.setup.fe.count)
        per = float(np.median([p["period_s"] for p in cal.pairs]))
        cps = {}
        for p, q in cal.tree:
            i, j = min(p, q), max(p, q)
            d = pair_coherence(self.setup, self.paths, (i, j), self.probe, near_s=meas[(i,
                               j)]["delta_tau_s"]).continuous_s
            cps[(i, j)] = d
            off[q] = off[p] + (d if q == j else -d)
        off = off - per * np.round(off / per)
        if rounded:
            off = realisable(off, self.scene.rts.delay_resolution_s)
        return dataclasses.replace(cal, offsets_s=np.asarray(off, float)), cps

    def program(self, cal, mode="exact", scene=None):
        """The planner with ``cal`` as the channel calibration (its measurement skipped)."""
        from rtsgeom.pipeline import plan
        from rtsgeom.geometry import build_setup
        from rtsgeom.paths import compute_paths
        setup, paths = self.setup, self.paths
        if scene is not None:
            setup = build_setup(scene)
            paths = compute_paths(setup, "exact")
        orig = plan.calibrate_channels
        plan.calibrate_channels = lambda *a, **k: cal
        try:
            prog, _, _ = plan.plan_targets(setup, paths, mode, True)
        finally:
            plan.calibrate_channels = orig
        return prog, setup, paths

    @staticmethod
    def chain(setup, paths, prog, snr_db, seed):
        """(az, el) errors (deg) (T, 2) of one frame through the ADC-cube chain."""
        from rtsgeom.radar import process
        from rtsgeom.radar.frame import simulate
        from rtsgeom.pipeline.run import match_targets
        _, cube = simulate(setup, paths, prog, seed, snr_db)
        rd, det = process(cube)
        out = []
        for m in match_targets(setup.scene, det, rd):
            e = m.get("error")
            out.append((np.nan, np.nan) if not e else (e["angle_deg"], e["elevation_deg"]))
        return np.array(out)

    @staticmethod
    def model(setup, paths, prog):
        """(az, el) errors (deg) (T, 2) of the programme read by the phasor model of the setup
        as built (no noise), and per target the strongest candidate bin's power over the
        next."""
        import dataclasses

        from rtsgeom.synthesis.model import ChannelModel
        from rtsgeom.radar.steering import Steering
        from rtsgeom.rts.channels import requested_delay
        scene = setup.scene
        st = Steering.auto(setup.rut, scene.radar)
        errs, margins = [], []
        for k, t in enumerate(scene.targets):
            rows = np.flatnonzero(prog.target == k)
            ch = prog.front_end[rows]
            tau = float(requested_delay(scene, t.range_m))
            m = ChannelModel.build(setup, paths, ch, t, prog.delay_s[rows] - tau, 2)
            m = dataclasses.replace(m, steering=st)
            w = prog.amplitude[rows].astype(complex)
            x = np.einsum("q,kqv->kv", w, m.responses)
            p = np.sort(np.sum(np.abs(x) ** 2, -1))
            margins.append(float(p[-1] / p[-2]))
            got = st.search(m.snapshot(w))
            errs.append(np.degrees(np.asarray(got) - [t.angle_rad, t.elevation_rad]))
        return np.array(errs), np.array(margins)


def edge_range(range_m: float, sub_bin: float) -> float:
    """A range near ``range_m`` at ``sub_bin`` bins from its bin's centre (sphere4's bin)."""
    w = parse(scene_doc()).radar.range_resolution_m
    return float((np.round(range_m / w) + sub_bin) * w)


def set_targets(doc, targets):
    doc = copy.deepcopy(doc)
    doc["targets"] = [{"range_m": float(r), "angle_deg": float(a), "elevation_deg": float(e)}
                      for r, a, e in targets]
    return doc


def case(name: str, doc: dict, seed_frames: int = 8) -> dict:
    """Every switch of the module doc on one scene document."""
    t0 = time.process_time()
    scene = parse(doc)
    b = Bench(scene)
    cal = b.calibrate()
    ideal, cps = b.ideal_calibration(cal)
    ideal_cont, _ = b.ideal_calibration(cal, rounded=False)
    out = {"case": name, "targets": [[t.range_m, float(np.degrees(t.angle_rad)),
                                       float(np.degrees(t.elevation_rad))]
                                      for t in scene.targets],
           "offsets_ps": (cal.offsets_s * 1e12).tolist(),
           "ideal_offsets_ps": (ideal_cont.offsets_s * 1e12).tolist(),
           "tree": [list(e) for e in cal.tree],
           "pair_error_ps": {f"{i}-{j}": (next(p["delta_tau_s"] for p in cal.pairs
                                              if tuple(p["pair"]) == (i, j)) - d) * 1e12
                             for (i, j), d in cps.items()}}
    prog, setup, paths = b.program(cal)
    snr = scene.radar.snr_db
    out["run"] = b.chain(setup, paths, prog, snr, scene.seed)
    out["noise_seeds"] = np.array([b.chain(setup, paths, prog, snr, s)
                                   for s in range(1, seed_frames + 1)])
    out["noiseless"] = b.chain(setup, paths, prog, None, scene.seed)
    out["measured_cal_model"], out["margin"] = b.model(setup, paths, prog)
    prog_i, setup, paths = b.program(ideal)
    out["ideal_cal"] = b.chain(setup, paths, prog_i, None, scene.seed)
    out["ideal_cal_model"], _ = b.model(setup, paths, prog_i)
    # quantisation off: any delay realisable, ideal FIR, the continuous offsets
    doc_q = copy.deepcopy(doc)
    doc_q["rts"]["fractional_delay_step_s"] = 1e-15
    doc_q["rts"]["fractional_delay_filter"] = "ideal"
    sc_q = parse(doc_q)
    prog_q, setup_q, paths_q = b.program(ideal_cont, scene=sc_q)
    out["no_quant"] = b.chain(setup_q, paths_q, prog_q, None, scene.seed)
    # each target at the centre of its range bin
    w = scene.radar.range_resolution_m
    centred = [(np.round(t.range_m / w) * w, np.degrees(t.angle_rad), np.degrees(t.elevation_rad))
               for t in scene.targets]
    sc_c = parse(set_targets(doc, centred))
    prog_c, setup_c, paths_c = b.program(ideal, scene=sc_c)
    out["bin_centre"] = b.chain(setup_c, paths_c, prog_c, None, scene.seed)
    out["sub_bin"] = [float(t.range_m / w - np.round(t.range_m / w)) for t in scene.targets]
    try:
        prog_a, setup, paths = b.program(ideal, mode="array-factor")
        out["array_factor"], _ = b.model(setup, paths, prog_a)
    except Exception as exc:  # noqa: BLE001  (a mode the cell cannot reach: say so)
        out["array_factor"] = str(exc)
    out["cpu_s"] = time.process_time() - t0
    return out


def show(o: dict) -> None:
    print(f"== {o['case']}  pair errors (ps) "
          + ", ".join(f"{k} {v:+.1f}" for k, v in o["pair_error_ps"].items())
          + f"  ({o['cpu_s']:.0f} s CPU)", flush=True)
    keys = ["run", "noiseless", "measured_cal_model", "ideal_cal", "ideal_cal_model",
            "no_quant", "bin_centre", "array_factor"]
    for k, t in enumerate(o["targets"]):
        line = f"  t{k} {t[0]:.2f} m ({t[1]:.2f}, {t[2]:.2f}) sub-bin {o['sub_bin'][k]:+.2f} " \
               f"margin {o['margin'][k]:.2f} |"
        for key in keys:
            v = o[key]
            if isinstance(v, str):
                continue
            line += f" {key} {v[k][0]:+.4f}/{v[k][1]:+.4f}"
        ns = o["noise_seeds"][:, k]
        line += f" | noise sd {np.nanstd(ns[:, 0]):.4f}/{np.nanstd(ns[:, 1]):.4f}"
        print(line, flush=True)


def cases(quick: bool):
    base = scene_doc()
    grid = [(21.0 + 2.3 * n, a, e) for n, (a, e) in enumerate(
        [(a, e) for e in (-3.5, 0.0, 3.5) for a in (4.5, 7.8, 11.0)])]
    out = [("sphere4", base), ("phase180", scene_doc(180.0))]
    if quick:
        return out
    out += [("phase90", scene_doc(90.0)),
            ("grid", scene_doc(targets=grid)),
            ("grid_phase180", scene_doc(180.0, targets=grid)),
            ("grid_edge", scene_doc(targets=[(edge_range(r, 0.45 * (-1) ** n), a, e)
                                             for n, (r, a, e) in enumerate(grid)])),
            ("el3", scene_doc(el_deg=3.0, targets=[(r, a, e * 0.6) for r, a, e in grid])),
            ("el7", scene_doc(el_deg=7.0, targets=[(r, a, e * 1.4) for r, a, e in grid])),
            ("R2", scene_doc(radius_m=2.0, targets=grid)),
            ("R0.7", scene_doc(radius_m=0.7, targets=grid))]
    return out


def ideal_tree_calibration(b: Bench, tree=((0, 1), (0, 2), (1, 3))):
    """A calibration whose tree pairs sit at their continuous coherence points nearest zero
    (rounded to 1 ps), without measuring: the reference the noise study designs on."""
    from rtsgeom.calibration.channels import ChannelCalibration
    from rtsgeom.calibration.pair import pair_coherence
    off = np.zeros(b.setup.fe.count)
    for p, q in tree:
        off[q] = off[p] + pair_coherence(b.setup, b.paths, (p, q), b.probe, near_s=0.0).continuous_s
    return ChannelCalibration(np.round(off * 1e12) * 1e-12, 0, [], list(tree))


def noise_study(doc: dict, frames: int = 40) -> dict:
    """Receiver noise alone: the ideal calibration's programme, ``frames`` noisy frames
    (seeds 100..), per target the detected errors' spread against the Cramer-Rao bound of
    the RuT's 2-D array at the detection's SNR (deterministic signal, one snapshot:
    Fisher matrix ``2 SNR sum_v (k_v - k_mean)(k_v - k_mean)^T`` over the steering's
    wavevectors k_v, mapped from direction cosines to (azimuth, elevation)); and the
    sensitivity of the noiseless phasor model's (az, el) to one channel's delay (deg/ps,
    +-5 ps): what a calibration error of a pair costs."""
    import dataclasses

    from rtsgeom.radar.steering import Steering
    b = Bench(parse(doc))
    prog, setup, paths = b.program(ideal_tree_calibration(b))
    st = Steering.auto(setup.rut, setup.scene.radar)
    d = st.wavevector - st.wavevector.mean(0)
    fisher = 2 * d.T @ d
    errs, snrs = [], []
    from rtsgeom.radar import process
    from rtsgeom.radar.frame import simulate
    from rtsgeom.pipeline.run import match_targets
    for s in range(frames):
        _, cube = simulate(setup, paths, prog, 100 + s, setup.scene.radar.snr_db)
        rd, det = process(cube)
        m = match_targets(setup.scene, det, rd)
        errs.append([(x["error"]["angle_deg"], x["error"]["elevation_deg"]) if x.get("error")
                     else (np.nan, np.nan) for x in m])
        snrs.append([x["detection"]["snr_db"] if x.get("detection") else np.nan for x in m])
    errs, snrs = np.array(errs), np.array(snrs)
    e0, _ = b.model(setup, paths, prog)
    rows = []
    for k, t in enumerate(setup.scene.targets):
        g = 10 ** (np.nanmean(snrs[:, k]) / 10)
        az, el = t.angle_rad, t.elevation_rad
        jac = np.linalg.inv(np.array([[np.cos(az) * np.cos(el), -np.sin(az) * np.sin(el)],
                                      [0.0, np.cos(el)]]))  # d(az, el) / d(u_az, u_el)
        cov = jac @ np.linalg.inv(g * fisher) @ jac.T
        rows.append({"range_m": t.range_m, "snr_db": float(np.nanmean(snrs[:, k])),
                     "sd_deg": np.nanstd(errs[:, k], 0).tolist(),
                     "crb_deg": np.degrees(np.sqrt(np.diag(cov))).tolist(),
                     "p_el_beyond_spec": float(np.mean(np.abs(errs[:, k, 1]) > SPEC_DEG)),
                     "max_abs_el_deg": float(np.nanmax(np.abs(errs[:, k, 1])))})
    sens = {}
    for q in range(1, setup.fe.count):
        per = []
        for dd in (5e-12, -5e-12):
            p2 = dataclasses.replace(prog, delay_s=prog.delay_s + dd * (prog.front_end == q))
            per.append((b.model(setup, paths, p2)[0] - e0) / (dd * 1e12))
        sens[str(q)] = np.mean(per, 0).tolist()  # (T, 2) deg/ps
    return {"targets": rows, "sensitivity_deg_per_ps": sens}


def frames_study(doc: dict, runs) -> list[dict]:
    """The proposed fix measured: the channel calibration with ``k`` coherently averaged
    frames per sweep step (its SNR raised by 10 log10 k, as ``calibration.simulate_detect``
    averages) for each ``(k, seed)`` of ``runs``; each tree pair's distance from its
    continuous coherence point and the targets' noiseless and one-frame (the scene's
    ``snr_db``) errors with that calibration."""
    from rtsgeom.calibration.channels import calibrate_channels
    from rtsgeom.calibration.pair import pair_coherence
    b0 = Bench(parse(doc))
    cps, out = {}, []
    for k, seed in runs:
        d = copy.deepcopy(doc)
        d["radar"]["snr_db"] = float(doc["radar"]["snr_db"]) + 10 * np.log10(k)
        b = Bench(parse(d))
        cal = calibrate_channels(b.setup, b.paths, b.used(), b.probe, seed=seed)
        errs = {}
        for p in cal.pairs:
            pr = tuple(p["pair"])
            if pr not in cps:
                cps[pr] = pair_coherence(b0.setup, b0.paths, pr, b0.probe,
                                         near_s=p["delta_tau_s"]).continuous_s
            errs[f"{pr[0]}-{pr[1]}"] = (p["delta_tau_s"] - cps[pr]) * 1e12
        prog, setup, paths = b0.program(cal)
        out.append({"frames": k, "seed": seed, "pair_error_ps": errs,
                    "noiseless_deg": b0.chain(setup, paths, prog, None, 2023).tolist(),
                    "one_frame_deg": b0.chain(setup, paths, prog, b0.scene.radar.snr_db,
                                              2023).tolist()})
        o = out[-1]
        print(f"frames {k} seed {seed}: pair errors (ps) "
              + ", ".join(f"{a} {v:+.1f}" for a, v in errs.items())
              + f"; noiseless max |el| {np.nanmax(np.abs(np.array(o['noiseless_deg'])[:, 1])):.4f}"
              f" deg", flush=True)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--only", nargs="*")
    ap.add_argument("--part", choices=("budget", "noise", "frames"), default="budget")
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "cell_error_budget"))
    a = ap.parse_args(argv)
    if a.part == "noise":
        res = noise_study(scene_doc())
        for r in res["targets"]:
            print(r, flush=True)
        print(res["sensitivity_deg_per_ps"])
        write_json(a.out + "_noise.json", res, default=float)
        return 0
    if a.part == "frames":
        runs = [(k, s) for k in (1, 16) for s in (2023, 1, 2)]
        write_json(a.out + "_frames.json", frames_study(scene_doc(), runs), default=float)
        return 0
    res = []
    for name, doc in cases(a.quick):
        if a.only and name not in a.only:
            continue
        o = case(name, doc)
        show(o)
        res.append(o)
        write_json(a.out + ".json", res, default=lambda x: np.asarray(x).tolist())
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
