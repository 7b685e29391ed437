"""
A car crossing the arc: scenario playback
=========================================

A target 20 m ahead drives from 3 m left to 3 m right of the radar's boresight in 2 s, played
on five front ends 8 deg apart on a 0.8 m arc (``scenes/crossing.toml``). The setup is
calibrated once; then every frame gets its set-points from the straight line, its RTS
programme (which two channels carry the target, their delays, Doppler and amplitudes) and the
RuT's detection through the full chain. The switched baseline (each target on its nearest
front end) plays the same drive beside it: its staircase is what arbitrary angles remove.
"""

# %%
import os
from pathlib import Path

import rtsgeom
from rtsgeom.viz.figures import save_figure

QUICK = os.environ.get("RTSGEOM_EXAMPLES_QUICK") == "1"
OUT = Path(os.environ.get("RTSGEOM_EXAMPLES_OUT", "example_output"))
OUT.mkdir(parents=True, exist_ok=True)
# the repository's scenes/ (sphinx-gallery runs a script in examples/, without a __file__)
HERE = Path(globals().get("__file__", "plot.py")).resolve().parent
scene = rtsgeom.load_scene(HERE.parent / "scenes" / "crossing.toml")
if QUICK:  # five frames instead of 21
    scene = rtsgeom.replace(scene, scenario=rtsgeom.replace(scene.scenario, frame_period_s=0.5))

# %%
# Play the drive (the synthesis and, beside it, the switched baseline).
result = rtsgeom.play(scene)
print(result)
summary = result.summary()
print(f"synthesis: max |angle error| {summary['angle_error_deg']['max']:.4f} deg, "
      f"baseline: {summary['baseline']['angle_error_deg']['max']:.2f} deg")

# %%
# What the RTS is told each frame: per target and channel the delay, Doppler, amplitude and
# phase (``programme.csv`` of ``rtsgeom play``), and what the RuT tracked.
print(result.programme_dataframe().head(6).to_string(index=False))
print(result.to_dataframe()[["time_s", "set_azimuth_deg", "azimuth_deg", "channels"]]
      .to_string(index=False))

# %%
fig = result.plot()
save_figure(fig, OUT / "scenario_crossing.png")
