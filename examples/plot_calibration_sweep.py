"""
Phase-coherency calibration sweep
=================================

The paper's calibration: both front ends synthesize probe targets while the RTS delay of one
channel is swept; the angle error is smallest where the two channels are phase coherent. The
minima repeat every 1/(f_rts + B/2) (eq. 27).
"""

# %%
import os
from pathlib import Path

import rtsgeom
from rtsgeom.viz.figures import calibration_sweep_figure, save_figure

QUICK = os.environ.get("RTSGEOM_EXAMPLES_QUICK") == "1"
OUT = Path(os.environ.get("RTSGEOM_EXAMPLES_OUT", "example_output"))
OUT.mkdir(parents=True, exist_ok=True)
# the repository's scenes/ (sphinx-gallery runs a script in examples/, without a __file__)
HERE = Path(globals().get("__file__", "plot.py")).resolve().parent
SCENE = HERE.parent / "scenes" / "diewald2022.toml"

scene = rtsgeom.load_scene(SCENE)
if QUICK:  # fewer chirp loops and a coarser sweep, for the test suite
    scene = rtsgeom.replace(scene, radar=rtsgeom.replace(scene.radar, chirps_per_tx=16),
                            rts=rtsgeom.replace(scene.rts, calibration_step_s=250e-12))

# %%
# Calibrate pair (0, 1): front-end indices are 0-based, as in ``rtsgeom calibrate --pair 0 1``.
cal = rtsgeom.calibrate(scene, pair=(0, 1))
print(f"delta tau {cal.delta_tau_s * 1e12:.1f} ps, residual {cal.residual_error_deg:.4f} deg, "
      f"range offset {cal.range_offset_m * 1e3:.2f} mm, period {cal.period_s * 1e9:.4f} ns")

# %%
# The sweep with its refinement around the chosen delay.
fig = calibration_sweep_figure(cal.sweep_delta_tau_s, cal.sweep_error_deg, cal.delta_tau_s,
                               cal.period_s, residual_error_deg=cal.residual_error_deg,
                               refine_delta_tau_s=cal.refine_delta_tau_s,
                               refine_error_deg=cal.refine_error_deg)
save_figure(fig, OUT / "calibration_sweep.png")
