"""
Designing an arc
================

Which arc radius and front-end spacing should an RTS use? ``rtsgeom.design`` evaluates each
(radius, spacing) as a two-front-end variant of the scene: the worst synthesized-angle error
after calibration, the near-field bias of one front end, the calibration's range offset and the
mounting tolerance for a yield (a small Monte Carlo per design).
"""

# %%
import os
from pathlib import Path

import numpy as np

import rtsgeom
from rtsgeom.viz.figures import design_heatmap_figure, design_lines_figure, save_figure

QUICK = os.environ.get("RTSGEOM_EXAMPLES_QUICK") == "1"
OUT = Path(os.environ.get("RTSGEOM_EXAMPLES_OUT", "example_output"))
OUT.mkdir(parents=True, exist_ok=True)
# the repository's scenes/ (sphinx-gallery runs a script in examples/, without a __file__)
HERE = Path(globals().get("__file__", "plot.py")).resolve().parent
SCENE = HERE.parent / "scenes" / "diewald2022.toml"

scene = rtsgeom.load_scene(SCENE)
radii = np.array([0.5, 1.0]) if QUICK else np.array([0.5, 1.0, 1.5, 2.0])
spacings = np.array([8.0]) if QUICK else np.array([4.0, 8.0, 12.0])
grid = rtsgeom.design(scene, radii, spacings, pair=(0, 1), draws=100 if QUICK else 1000)

# %%
# One row per design; the sheet is kept, widened, or disabled where its cutouts do not fit.
import pandas as pd  # noqa: E402

df = pd.DataFrame(grid.to_dict()["designs"])
print(df[["radius_m", "spacing_deg", "sheet", "worst_error_deg", "near_field_bias_deg",
          "sigma_calibrated_mm", "sigma_uncalibrated_mm"]].round(4).to_string(index=False))

# %%
# The calibrated tolerance grows with the radius (a tangential error dt turns a front end by
# dt / R_c). A single spacing is a 1-D sweep: lines; a grid: a heat map.
draw = design_lines_figure if min(radii.size, spacings.size) == 1 else design_heatmap_figure
fig = draw(grid.radius_m, grid.spacing_deg, grid.metrics["sigma_calibrated_mm"],
           "arc radius R_c (m)", "front-end spacing (deg)", "mounting sigma (mm)",
           "Tolerance for 95 % within 0.1 deg, calibrated", mask=grid.exceeds_resolution)
save_figure(fig, OUT / "arc_design.png")
