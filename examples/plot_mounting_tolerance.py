"""
Mounting tolerance of your own arc
==================================

How precisely must the front ends of *your* arc be mounted? Start from the bundled scene,
change the arc radius, the front-end angles and a known mounting offset, then draw random
mounting errors (Monte Carlo, phasor level) and read the yield against an angle spec,
uncalibrated and after the paper's calibration.
"""

# %%
import os
from pathlib import Path

import numpy as np

import rtsgeom
from rtsgeom.viz.figures import save_figure, tolerance_cdf_figure

QUICK = os.environ.get("RTSGEOM_EXAMPLES_QUICK") == "1"
OUT = Path(os.environ.get("RTSGEOM_EXAMPLES_OUT", "example_output"))
OUT.mkdir(parents=True, exist_ok=True)
SCENE = Path(__file__).resolve().parents[1] / "scenes" / "diewald2022.toml"

# %%
# Your arc: 1.5 m radius, front ends at 5 and 12 deg. Scene fields are SI (radians, metres).
base = rtsgeom.load_scene(SCENE)
fes = tuple(rtsgeom.replace(f, angle_rad=np.radians(a))
            for f, a in zip(base.rts.front_ends, (5.0, 12.0)))
scene = rtsgeom.replace(base, rts=rtsgeom.replace(base.rts, arc_radius_m=1.5, front_ends=fes))
info = rtsgeom.scene_info(rtsgeom.build_setup(scene))
print(f"arc radius {info['far_field']['arc_radius_m']} m, front ends at "
      + ", ".join(f"{fe['azimuth_from_rut_deg']:.2f}" for fe in info["front_ends"]) + " deg")

# %%
# Draw 0.1 mm (1 sigma) radial, tangential and height errors per front end.
draws = 2_000 if QUICK else 50_000
res = rtsgeom.tolerance(scene, pair=(0, 1), sigma_mm=(0.1, 0.1, 0.1), draws=draws, seed=1,
                        spec_deg=0.1)
for case in res.worst_error_deg:
    st = res.stats(case)
    print(f"{case:>13}: |error| p95 {st['angle_error_deg']['p95']:.4f} deg, "
          f"yield {100 * st['yield']:.1f} % within {res.spec_deg} deg")

# %%
# The empirical CDF of the worst error per drawn setup: calibration buys two orders of
# magnitude.
fig = tolerance_cdf_figure(res.worst_error_deg, res.spec_deg,
                           f"Your arc (R_c = 1.5 m), {draws} setups")
save_figure(fig, OUT / "mounting_tolerance.png")

# %%
# The same errors on a smaller and a larger arc: the calibrated tolerance grows with the radius
# (a tangential error dt turns a front end by dt / R_c), the uncalibrated one does not.
for radius in (2.0,) if QUICK else (1.0, 2.0, 3.0):
    other = rtsgeom.replace(scene, rts=rtsgeom.replace(scene.rts, arc_radius_m=radius))
    r = rtsgeom.tolerance(other, (0, 1), sigma_mm=(0.1, 0.1, 0.1), draws=draws, seed=1)
    print(f"R_c = {radius} m: yield {100 * r.yield_('uncalibrated'):.1f} % uncalibrated, "
          f"{100 * r.yield_('calibrated'):.1f} % calibrated; calibrated p95 "
          f"{r.stats('calibrated')['angle_error_deg']['p95']:.4f} deg")
