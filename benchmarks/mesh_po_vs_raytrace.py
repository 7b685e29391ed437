"""A mesh object's returns to the RuT: physical optics (rtsgeom.scene.mesh, the default) against
Sionna RT's monostatic geometrical optics (rtsgeom.paths.raytrace_monostatic), time and returns.

    PYTHONPATH=. python -m benchmarks.mesh_po_vs_raytrace        # writes mesh_po_vs_raytrace.json

* ``plate``: square plates 15 m ahead at normal incidence, 0.05 to 2 m: PO, Sionna RT and the
  closed forms (far field 4 pi A^2 / lambda^2, Fresnel, the mirror pi R^2).
* ``tilt``: the 0.2 m plate turned about a side: PO, its far-field sinc^2 closed form, Sionna.
* ``car``: the bundled scenes/car.ply 15 m ahead at several headings, the RuT 0.5 m above the
  ground (a bumper radar, the mesh's z = 0, as a scene places it) and on the ground
  (``rut_height_m`` is the height above the ground): each PO scatterer (one
  per resolution cell of the car-crossing radar) and each Sionna path (one and two bounces),
  every Sionna path matched to the PO scatterer of its cell.
* ``sweep``: the car's total return over headings 0-90 deg, both models; docs/mesh_po.png
  draws it with the plates.

Times are wall seconds on this (shared) machine, with the process's CPU seconds beside them;
Sionna's first solve includes its kernel compilation and is reported apart.
"""

from __future__ import annotations

from benchmarks.make_car_mesh import MOUNT_M

import argparse
import math
import os
import time
from pathlib import Path

import numpy as np

from benchmarks._io import write_json

ROOT = Path(__file__).resolve().parents[1]
LAM = 299792458.0 / 77e9
K = 2 * math.pi / LAM
CELL_M, CELL_U = 0.15, 0.25  # scenes/car-crossing.toml: 1 GHz, 8 virtual elements


def _plate(a: float, b: float):
    import trimesh
    v = [[-a / 2, 0, -b / 2], [a / 2, 0, -b / 2], [a / 2, 0, b / 2], [-a / 2, 0, b / 2]]
    return trimesh.Trimesh(v, [[0, 1, 2], [0, 2, 3]], process=False)  # normal -y


def _fresnel_db(a: float, b: float, r: float) -> float:
    from scipy.special import fresnel

    def f(w):
        s, c = fresnel(w / 2 * math.sqrt(2 * K / (math.pi * r)))
        return math.sqrt(math.pi * r / (2 * K)) * 2 * (c - 1j * s)
    return 10 * math.log10(4 * math.pi / LAM ** 2 * abs(f(a) * f(b)) ** 2)


def _timed(fn, *args, **kw):
    t0, c0 = time.perf_counter(), time.process_time()
    out = fn(*args, **kw)
    return out, round(time.perf_counter() - t0, 4), round(time.process_time() - c0, 4)


def _db(x):
    return None if x is None or not np.isfinite(x) else round(float(x), 2)


def _total_db(rcs_dbsm) -> float | None:
    return _db(10 * np.log10((10 ** (np.asarray(rcs_dbsm) / 10)).sum())) if len(rcs_dbsm) else None


def plates(mono, po) -> list[dict]:
    rows, r = [], 15.0
    for a in (0.05, 0.1, 0.2, 0.5, 1.0, 2.0):
        m = _plate(a, a)
        radar = np.array([0.0, -r, 0.0])
        (_, s_po), t_po, _ = _timed(po, m.vertices, m.faces, radar, LAM, CELL_M, CELL_U)
        go, t_go, _ = _timed(mono, m.vertices, m.faces, radar, LAM, samples_per_src=100_000)
        rows.append({"side_m": a, "range_m": r,
                     "far_field_dbsm": _db(10 * math.log10(4 * math.pi * a ** 4 / LAM ** 2)),
                     "fresnel_dbsm": _db(_fresnel_db(a, a, r)),
                     "mirror_dbsm": _db(10 * math.log10(math.pi * r ** 2)),
                     "po_dbsm": _total_db(s_po), "sionna_dbsm": _total_db(go.rcs_dbsm),
                     "sionna_paths": int(len(go.rcs_dbsm)), "po_s": t_po,
                     "sionna_solve_s": round(go.timings_s["solve_s"], 4)})
    return rows


def tilts(mono, po) -> list[dict]:
    rows, r, a = [], 15.0, 0.2
    m = _plate(a, a)
    for th_deg in (0.0, 0.5, 1.0, 2.0, 5.0, 10.0, 30.0):
        th = math.radians(th_deg)
        radar = r * np.array([math.sin(th), -math.cos(th), 0.0])
        _, s_po = po(m.vertices, m.faces, radar, LAM, CELL_M, CELL_U)
        x = K * a * math.sin(th)
        ff = 4 * math.pi * a ** 4 / LAM ** 2 * math.cos(th) ** 2 * (np.sinc(x / math.pi)) ** 2
        go = mono(m.vertices, m.faces, radar, LAM, samples_per_src=100_000)
        rows.append({"tilt_deg": th_deg, "far_field_sinc2_dbsm": _db(10 * np.log10(ff)),
                     "po_dbsm": _total_db(s_po), "sionna_dbsm": _total_db(go.rcs_dbsm),
                     "sionna_paths": int(len(go.rcs_dbsm))})
    return rows


def _match(po_pts, po_rcs, go_pts, radar):
    """Each Sionna path's PO scatterer: the nearest in range within a cell, the same lateral
    cell (|u difference| < CELL_U / 2); None where there is none."""
    out = []
    r_po = np.linalg.norm(po_pts - radar, axis=1)
    axis = np.cross(-radar, [0.0, 0.0, 1.0])
    axis /= np.linalg.norm(axis)
    u_po = (po_pts - radar) @ axis / r_po
    for p in go_pts:
        r = np.linalg.norm(p - radar)
        u = (p - radar) @ axis / r
        ok = (np.abs(r_po - r) <= CELL_M) & (np.abs(u_po - u) < CELL_U / 2)
        out.append(int(np.flatnonzero(ok)[np.argmin(np.abs(r_po - r)[ok])]) if ok.any() else None)
    return out


def car(mono, po) -> list[dict]:
    from rtsgeom.scene.mesh import load_mesh
    v, f = load_mesh(str(ROOT / "scenes" / "car.ply"), "car", "benchmark")
    rows, r = [], 15.0
    for height in (0.0, 0.5):
        for h_deg in (0.0, 30.0, 60.0, 90.0):
            h = math.radians(h_deg)
            # the RuT in the car's frame: the car turned by h, the RuT at -y of the radar frame
            radar = np.array([r * math.sin(h), -r * math.cos(h), height - MOUNT_M])
            (pts, rcs), t_po, c_po = _timed(po, v, f, radar, LAM, CELL_M, CELL_U)
            rays = {}
            for depth in (1, 2):
                go = mono(v, f, radar, LAM, max_depth=depth)
                match = _match(pts, rcs, go.points, radar)
                rays[depth] = {
                    "paths": [{"range_m": _db(np.linalg.norm(p - radar)), "point_m":
                               [round(float(x), 3) for x in p], "sionna_dbsm": _db(s),
                               "interactions": i, "po_match_dbsm":
                               None if j is None else _db(rcs[j])}
                              for p, s, i, j in zip(go.points, go.rcs_dbsm, go.interactions,
                                                    match)],
                    "total_dbsm": _total_db(go.rcs_dbsm),
                    "solve_s": round(go.timings_s["solve_s"], 3)}
            rows.append({"heading_deg": h_deg, "rut_height_m": height, "range_m": r,
                         "po": {"scatterers": int(len(rcs)), "total_dbsm": _total_db(rcs),
                                "strongest_dbsm": [_db(x) for x in rcs[:6]],
                                "strongest_range_m": [_db(np.linalg.norm(p - radar))
                                                      for p in pts[:6]],
                                "wall_s": t_po, "cpu_s": c_po},
                         "sionna_1_bounce": rays[1], "sionna_2_bounces": rays[2]})
    return rows


def sweep(mono, po) -> list[dict]:
    """The car's total return over headings 0-90 deg (nose to flank) 15 m ahead: PO (coherent
    cells, summed in power) and Sionna RT (one bounce), the RuT 0.5 and 0 m above the ground."""
    from rtsgeom.scene.mesh import load_mesh
    v, f = load_mesh(str(ROOT / "scenes" / "car.ply"), "car", "benchmark")
    rows, r = [], 15.0
    for height in (0.0, 0.5):
        for h_deg in range(0, 91, 5):
            h = math.radians(h_deg)
            radar = np.array([r * math.sin(h), -r * math.cos(h), height - MOUNT_M])
            _, rcs = po(v, f, radar, LAM, CELL_M, CELL_U)
            go = mono(v, f, radar, LAM)
            rows.append({"heading_deg": h_deg, "rut_height_m": height,
                         "po_dbsm": _total_db(rcs), "sionna_dbsm": _total_db(go.rcs_dbsm)})
    return rows


def figure(out: dict, path: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2))
    p = out["plate"]
    side = np.array([row["side_m"] for row in p])
    fine = np.geomspace(side.min(), side.max(), 200)
    a1.plot(fine, 10 * np.log10(4 * math.pi * fine ** 4 / LAM ** 2), "k:",
            label="far field $4\\pi A^2/\\lambda^2$")
    a1.plot(fine, [_fresnel_db(a, a, 15.0) for a in fine], "k-", lw=1,
            label="Fresnel closed form")
    a1.axhline(10 * math.log10(math.pi * 15.0 ** 2), color="0.5", ls="--",
               label="mirror $\\pi R^2$")
    a1.plot(side, [row["po_dbsm"] for row in p], "o", ms=7, mfc="none", label="PO (rtsgeom)")
    got = [(row["side_m"], row["sionna_dbsm"]) for row in p if row["sionna_dbsm"] is not None]
    a1.plot(*zip(*got), "x", ms=8, mew=2, label="Sionna RT (GO)")
    a1.set(xscale="log", xlabel="square plate's side (m)", ylabel="RCS (dBsm)",
           title="Plate 15 m ahead, normal incidence, 77 GHz", ylim=(0, 60))
    a1.legend(fontsize=8, loc="upper left")
    for height, style in ((0.5, "-"), (0.0, "--")):
        rows = [row for row in out["sweep"] if row["rut_height_m"] == height]
        h = [row["heading_deg"] for row in rows]
        a2.plot(h, [np.nan if row["po_dbsm"] is None else row["po_dbsm"] for row in rows],
                "C0" + style, label=f"PO, RuT {height} m above the ground")
        sio = [(row["heading_deg"], row["sionna_dbsm"]) for row in rows
               if row["sionna_dbsm"] is not None]
        if sio:
            a2.plot(*zip(*sio), "C1x", ms=8, mew=2,
                    label=f"Sionna RT, RuT {height} m above the ground" if height else None)
    a2.set(xlabel="heading (deg): 0 nose on, 90 flank", ylabel="total RCS (dBsm)",
           title="scenes/car.ply 15 m ahead (Sionna: no path from the ground)", ylim=(-30, 35))
    a2.legend(fontsize=8)
    for ax in (a1, a2):
        ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", default=str(Path(__file__).with_suffix(".json")))
    ap.add_argument("--figure", default=str(ROOT / "docs" / "mesh_po.png"))
    ap.add_argument("--from-json", action="store_true", help="only redraw the figure")
    args = ap.parse_args(argv)
    if args.from_json:
        import json
        figure(json.loads(Path(args.json).read_text()), args.figure)
        return 0
    os.environ.setdefault("RTSGEOM_RAYTRACE_BACKEND", "llvm")
    from rtsgeom.paths.raytrace_monostatic import monostatic
    from rtsgeom.paths.raytrace_backend import backend_info
    from rtsgeom.scene.mesh import mesh_scatterers
    m = _plate(0.2, 0.2)
    first, t_first, _ = _timed(monostatic, m.vertices, m.faces, np.array([0.0, -15.0, 0.0]), LAM,
                               samples_per_src=100_000)
    out = {"load_avg": os.getloadavg(), "backend": backend_info(),
           "sionna_import_s": round(first.timings_s["import_s"], 2),
           "sionna_first_call_s": t_first, "cell_m": CELL_M, "cell_u": CELL_U,
           "plate": plates(monostatic, mesh_scatterers), "tilt": tilts(monostatic, mesh_scatterers),
           "car": car(monostatic, mesh_scatterers), "sweep": sweep(monostatic, mesh_scatterers)}
    write_json(args.json, out, newline=True)
    figure(out, args.figure)
    for key in ("plate", "tilt"):
        for row in out[key]:
            print(key, row)
    for row in out["car"]:
        print("car", row["heading_deg"], row["rut_height_m"], row["po"],
              {d: (len(row[k]["paths"]), row[k]["total_dbsm"], row[k]["solve_s"])
               for d, k in ((1, "sionna_1_bounce"), (2, "sionna_2_bounces"))})
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
