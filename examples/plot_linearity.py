"""
Amplitude attenuation, angle linearity and error
================================================

The paper's figure: the attenuation of the two channels, the detected against the set angle
and the error across the pair's span, for the three ways of choosing the amplitude ratio:
``exact`` (the modelled RuT output), ``array-factor`` (eq. 22 with the 8-element beam) and
``paper`` (eq. 23's sinc).
"""

# %%
import os
from pathlib import Path

import rtsgeom
from rtsgeom.viz.figures import linearity_figure, save_figure

QUICK = os.environ.get("RTSGEOM_EXAMPLES_QUICK") == "1"
OUT = Path(os.environ.get("RTSGEOM_EXAMPLES_OUT", "example_output"))
OUT.mkdir(parents=True, exist_ok=True)
# the repository's scenes/ (sphinx-gallery runs a script in examples/, without a __file__)
HERE = Path(globals().get("__file__", "plot.py")).resolve().parent
SCENE = HERE.parent / "scenes" / "diewald2022.toml"

scene = rtsgeom.load_scene(SCENE)
points = 11
if QUICK:
    scene = rtsgeom.replace(scene, radar=rtsgeom.replace(scene.radar, chirps_per_tx=16))
    points = 3

# %%
# Calibrate the pair once (the paper's delay sweep), then sweep the set angle for each mode.
if QUICK:
    scene = rtsgeom.replace(scene, rts=rtsgeom.replace(scene.rts, calibration_step_s=250e-12))
cal = rtsgeom.calibrate(scene, (0, 1))
modes = ("exact", "paper") if QUICK else ("exact", "array-factor", "paper")
results = {m: rtsgeom.linearity(scene, (0, 1), amplitudes=m, calibration=cal, points=points)
           for m in modes}
for m, lin in results.items():
    print(f"{m:>12}: max |error| {lin.max_abs_error_deg:.3f} deg")

# %%
lin = results["exact"]
fig = linearity_figure(lin.set_deg, {m: r.detected_deg for m, r in results.items()},
                       {m: r.amplitude_db for m, r in results.items()}, pair=(0, 1))
save_figure(fig, OUT / "linearity.png")
