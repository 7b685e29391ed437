"""``python -m benchmarks.calibration_noise``: the calibration under the link budget's thermal
noise (``[radar.link]``, no ``snr_db``) over noise figures and seeds.

For each noise figure (default 12, 30, 40, 45, 50 dB: 50 is the field's maximum) and seed,
the default scene's pair (0, 1) is calibrated (``aoa.calibration.calibrate_pair``, phasor
sweep + full-chain confirmation) with the probe of the noiseless scene (at NF >= 45 dB the
front ends alone fall below the CFAR threshold), and compared with the noiseless scene's
calibration:

* ``pull_ps``: chosen delay minus the noiseless one (the RTS's 1 ps steps);
* ``frames_per_step`` / ``coarse_frames_per_step``: frames averaged per fine / coarse step;
* ``one_frame_scatter_ps``: the predicted 1-sigma of the fitted delay with one frame per step;
* ``frame_noise_deg``: the predicted 1-sigma probe-angle noise of one frame;
* ``cpu_s``: CPU time of the calibration (``time.process_time``).

Writes ``benchmarks/calibration_noise.json`` and ``.csv`` (``--out PREFIX``: elsewhere) and
prints one line per case.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

from benchmarks._io import write_json_csv

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_SCENE = ROOT / "scenes" / "diewald2022.toml"
PAIR = (0, 1)


def linked(nf_db: float | None):
    """The default scene without ``snr_db``; with ``[radar.link] noise_figure_db = nf_db``
    (None: no link, noiseless), parsed as a scene file would be."""
    import tomllib

    from rtsgeom.scene import parse_scene
    doc = tomllib.loads(DEFAULT_SCENE.read_text())
    doc["radar"].pop("snr_db", None)
    if nf_db is not None:
        doc["radar"]["link"] = {"noise_figure_db": float(nf_db)}
    return parse_scene(doc, str(DEFAULT_SCENE))


def run(nf_db=(12.0, 30.0, 40.0, 45.0, 50.0), seeds=range(5)) -> dict:
    from rtsgeom.calibration.pair import calibrate_pair
    from rtsgeom.calibration.probes import probe_front_ends
    from rtsgeom.geometry import build_setup
    from rtsgeom.paths import exact_paths
    quiet = build_setup(linked(None))
    qp = exact_paths(quiet)
    probe = probe_front_ends(quiet, qp, 1)
    ref = calibrate_pair(quiet, qp, PAIR, probe, seed=1)
    rows = []
    for nf in nf_db:
        setup = build_setup(linked(nf))
        paths = exact_paths(setup)
        for seed in seeds:
            t0 = time.process_time()
            cal = calibrate_pair(setup, paths, PAIR, probe, seed=int(seed))
            cpu = time.process_time() - t0
            row = {"noise_figure_db": float(nf), "seed": int(seed),
                   "pull_ps": (cal.delta_tau_s - ref.delta_tau_s) * 1e12,
                   "frames_per_step": int(cal.frames_per_step),
                   "coarse_frames_per_step": int(getattr(cal, "coarse_frames_per_step", 1)),
                   "one_frame_scatter_ps": float(cal.one_frame_scatter_ps),
                   "frame_noise_deg": float(cal.frame_noise_deg),
                   "residual_deg": float(cal.residual_error_deg), "cpu_s": cpu}
            rows.append(row)
            print(f"NF {nf:4.1f} dB seed {seed}: pull {row['pull_ps']:+8.2f} ps, frames "
                  f"{row['frames_per_step']:6d} (coarse {row['coarse_frames_per_step']:3d}), "
                  f"one-frame scatter {row['one_frame_scatter_ps']:6.2f} ps, angle noise "
                  f"{row['frame_noise_deg']:.3f} deg, {cpu:.2f} s CPU", flush=True)
    return {"reference_delta_tau_s": ref.delta_tau_s, "load": os.getloadavg(), "rows": rows}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nf", type=float, nargs="+", default=[12.0, 30.0, 40.0, 45.0, 50.0])
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "calibration_noise"))
    a = ap.parse_args(argv)
    out = run(a.nf, range(a.seeds))
    write_json_csv(a.out, out, out["rows"])
    pulls = np.array([abs(r["pull_ps"]) for r in out["rows"]])
    print(f"max |pull| {pulls.max():.2f} ps over {pulls.size} cases; wrote {a.out}.json/.csv")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
