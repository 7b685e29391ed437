"""
Cable ghosts
============

Mismatched cables between a front end and its back end reflect part of the signal, which
returns one round trip later: ghost targets behind each target at R_t + n L / VF. This predicts
their ranges and levels from the cable parameters and reads them in the simulated
range-Doppler map.
"""

# %%
import os
from pathlib import Path

import rtsgeom
from rtsgeom.analysis.ghosts import ghosts_figure
from rtsgeom.viz.figures import save_figure

QUICK = os.environ.get("RTSGEOM_EXAMPLES_QUICK") == "1"
OUT = Path(os.environ.get("RTSGEOM_EXAMPLES_OUT", "example_output"))
OUT.mkdir(parents=True, exist_ok=True)
# the repository's scenes/ (sphinx-gallery runs a script in examples/, without a __file__)
HERE = Path(globals().get("__file__", "plot.py")).resolve().parent
SCENE = HERE.parent / "scenes" / "diewald2022.toml"

scene = rtsgeom.load_scene(SCENE)
if QUICK:
    scene = rtsgeom.replace(scene, radar=rtsgeom.replace(scene.radar, chirps_per_tx=16))

# %%
# Predicted ghosts per target (levels relative to the target) and, with ``simulate=True``, as
# found in the map.
report = rtsgeom.ghosts(scene, floor_db=-60.0, simulate=True)
d = report.to_dict()
for t in d["targets"][:2]:
    for g in t["ghosts"]:
        print(f"target {t['index']} ({t['range_m']} m): ghost {g['order']} at "
              f"{g['range_m']:.3f} m (+{g['range_offset_m']:.4f} m), {g['level_db']:.2f} dB")

# %%
save_figure(ghosts_figure(report), OUT / "cable_ghosts.png")
