"""
Range-Doppler map of the paper's Table I
========================================

The bundled scene is the paper's measurement setup: an AWR1843BOOST in front of two RTS front
ends at 3.4 and 12.2 deg on a 1 m arc, four targets synthesized at 7, 4, 10 and 11 deg. This
runs the whole pipeline (paths, calibration, ADC cube, FFTs, CFAR, beamforming) and compares
the detections with the set-points.
"""

# %%
import os
from pathlib import Path

import numpy as np

import rtsgeom
from rtsgeom.viz.figures import range_angle_figure, range_doppler_figure, save_figure

QUICK = os.environ.get("RTSGEOM_EXAMPLES_QUICK") == "1"
OUT = Path(os.environ.get("RTSGEOM_EXAMPLES_OUT", "example_output"))
OUT.mkdir(parents=True, exist_ok=True)
# the repository's scenes/ (sphinx-gallery runs a script in examples/, without a __file__)
HERE = Path(globals().get("__file__", "plot.py")).resolve().parent
SCENE = HERE.parent / "scenes" / "diewald2022.toml"

scene = rtsgeom.load_scene(SCENE)
if QUICK:  # 16 instead of 120 chirp loops (a 7x smaller cube), a coarser calibration sweep
    scene = rtsgeom.replace(scene, radar=rtsgeom.replace(scene.radar, chirps_per_tx=16),
                            rts=rtsgeom.replace(scene.rts, calibration_step_s=250e-12))

# %%
# Run the pipeline. ``result.rd`` is the range-Doppler map, ``result.detections`` the CFAR
# detections with their angles.
result = rtsgeom.run_scene(scene)
print(result.detections.to_dataframe().round(3))

# %%
# Set-points against detections (Table I).
for m in result.matches:
    e = m["error"]
    print(f"target {m['index']}: set {m['set']['range_m']} m, {m['set']['velocity_mps']:+} m/s, "
          f"{m['set']['angle_deg']} deg -> errors "
          + ("not detected" if e is None else
             f"{e['range_m']:+.3f} m, {e['velocity_mps']:+.3f} m/s, {e['angle_deg']:+.3f} deg"))

# %%
# The map as a labelled xarray: select by range and velocity instead of bin indices.
rd = result.rd.to_xarray()
db = 10 * np.log10(rd)
peak = db.sel(range_m=33.5, velocity_mps=0.0, method="nearest").item()
print(f"target 0 stands {peak - float(db.median()):.1f} dB above the map's median")

det = result.detections
fig = range_doppler_figure(db.values, rd["range_m"].values, rd["velocity_mps"].values,
                           detections=np.c_[det.range_m, det.velocity_mps],
                           title=f"{scene.name}: range-Doppler map")
save_figure(fig, OUT / "table1_range_doppler.png")

# %%
# The range-angle map (each range bin at its strongest Doppler bin).
ra = result.rd.range_angle_to_xarray(result.cube, np.arange(-30.0, 30.01, 0.25))
sets = np.array([[t.range_m, np.degrees(t.angle_rad)] for t in scene.targets])
fig = range_angle_figure(10 * np.log10(ra.values), ra["range_m"].values, ra["angle_deg"].values,
                         detections=np.c_[det.range_m, det.angle_deg], set_points=sets)
save_figure(fig, OUT / "table1_range_angle.png")
