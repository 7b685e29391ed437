"""
Near field versus arc radius
============================

At R_c = 1 m a single front end is detected about half a degree off its geometric angle. This
sweeps the arc radius and splits the bias into its closed-form parts (the front end's Rx/Tx
separation, the parallax of the RuT's Tx and Rx groups, the beat frequency, curvature).
"""

# %%
import os
from pathlib import Path

import numpy as np

import rtsgeom
from rtsgeom.analysis.nearfield import nearfield_figure
from rtsgeom.viz.figures import save_figure

QUICK = os.environ.get("RTSGEOM_EXAMPLES_QUICK") == "1"
OUT = Path(os.environ.get("RTSGEOM_EXAMPLES_OUT", "example_output"))
OUT.mkdir(parents=True, exist_ok=True)
# the repository's scenes/ (sphinx-gallery runs a script in examples/, without a __file__)
HERE = Path(globals().get("__file__", "plot.py")).resolve().parent
SCENE = HERE.parent / "scenes" / "diewald2022.toml"

scene = rtsgeom.load_scene(SCENE)
radii = np.geomspace(0.5, 8.0, 3 if QUICK else 9)
nf = rtsgeom.nearfield(scene, radii, points=3 if QUICK else 11)

# %%
d = nf.to_dict()
print("bias x R (deg m) per front end:",
      ", ".join(f"{x:.3f}" for x in d["bias_1_over_r_coefficient_deg_m"]))

# %%
save_figure(nearfield_figure(nf), OUT / "nearfield.png")
