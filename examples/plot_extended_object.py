"""
An extended object: a car is many scatterers
============================================

A car of twelve scatterers crosses 14 m ahead of the radar (``scenes/car-crossing.toml``),
played on seven front ends that synthesize at most three targets each. Each frame the planner
merges the scatterers the radar cannot resolve into one target at the truth twin's detection
of their cell and drops the weakest beyond the budget; the radar's detections of the RTS are
compared with its detections of the real car (the truth twin): ``clouds.csv`` and the figure.
"""

# %%
import os
from pathlib import Path

import rtsgeom
from rtsgeom.analysis.objects import objects_figure, play_objects
from rtsgeom.viz.figures import save_figure

QUICK = os.environ.get("RTSGEOM_EXAMPLES_QUICK") == "1"
OUT = Path(os.environ.get("RTSGEOM_EXAMPLES_OUT", "example_output"))
OUT.mkdir(parents=True, exist_ok=True)
HERE = Path(globals().get("__file__", "plot.py")).resolve().parent
scene = rtsgeom.load_scene(HERE.parent / "scenes" / "car-crossing.toml")
if QUICK:  # three frames instead of eleven
    scene = rtsgeom.replace(scene, scenario=rtsgeom.replace(scene.scenario, frame_period_s=1.0))
print(scene.objects)

# %%
# Play the drive (no switched baseline): the truth twin runs beside every frame.
result = rtsgeom.play(scene, baseline=False)
rows, section = play_objects(result)
for f in section["frames"]:
    print(f"frame {f['frame']}: kept {f['kept']}, merged {f['merged']}, dropped "
          f"{f['dropped']}; truth {f['truth_detections']} / RTS {f['rts_detections']} "
          f"detections, {100 * f['reproduced_share']:.0f} % reproduced")

# %%
# The car from above with the truth twin's and the RTS's detections, and the drive.
fig = objects_figure(scene, rows, section)
save_figure(fig, OUT / "extended_object.png")
