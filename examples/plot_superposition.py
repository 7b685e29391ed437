"""
Two channels superposed after beamforming
=========================================

The paper's principle (its figure "Simulated signal superposition of two adjacent RTS channels
after beamforming"): the RuT beamforms the sum of two RTS channels' echoes, and where the two
are phase coherent the sum has one peak between the two front ends, placed by their amplitude
ratio. This draws each front end's beam alone and the superposition for three set angles, on
the modelled RuT output of the bundled setup (1 m arc, near field included).
"""

# %%
import os
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import rtsgeom

OUT = Path(os.environ.get("RTSGEOM_EXAMPLES_OUT", "example_output"))
OUT.mkdir(parents=True, exist_ok=True)
# the repository's scenes/ (sphinx-gallery runs a script in examples/, without a __file__)
HERE = Path(globals().get("__file__", "plot.py")).resolve().parent
SCENE = HERE.parent / "scenes" / "diewald2022.toml"

# %%
# The modelled RuT output of front ends 0 and 1 for the first target of the scene (33.5 m):
# each channel's spectrum at the target's range-Doppler bin, per virtual element.
scene = rtsgeom.load_scene(SCENE)
setup = rtsgeom.build_setup(scene)
model = rtsgeom.ChannelModel.build(setup, rtsgeom.exact_paths(setup), (0, 1), scene.targets[0])
angles_deg = np.linspace(-30.0, 45.0, 601)
u = np.sin(np.radians(angles_deg))[:, None]  # direction cosines (P, 1)
beams = model.steering.beam(model.phasors, u)  # (2, P): each channel's beamformer output

# %%
# The channel phase that makes the two coherent (what the calibration's delay sets, here at the
# probe angles 1/4 and 3/4 across the span), then the amplitude ratio for each set angle.
fe_deg = np.degrees(np.arcsin(model.fe_directions()[:, 0]))
probes = fe_deg[0] + np.array([0.25, 0.75]) * (fe_deg[1] - fe_deg[0])
phases = model.coherent_phases(np.sin(np.radians(probes))[:, None])
set_deg = (5.0, 7.8, 10.5)
weights = {s: model.solve(np.sin(np.radians([s])), phases) for s in set_deg}
for s, w in weights.items():
    print(f"set {s:4.1f} deg: channel 1 / channel 0 amplitude {abs(w[1] / w[0]):.3f} "
          f"({20 * np.log10(abs(w[1] / w[0])):+.2f} dB)")

# %%
# Each front end alone (grey) and the coherent sum for each set angle (solid): one peak,
# on the set angle (the dotted lines), between the two front ends.
ref = np.max(np.abs(beams)) ** 2
fig, ax = plt.subplots(figsize=(7.0, 4.0))
for q, style in enumerate(("--", "-.")):
    ax.plot(angles_deg, 10 * np.log10(np.abs(beams[q]) ** 2 / ref), style, color="0.55",
            label=f"front end {q} alone ({fe_deg[q]:.1f} deg)")
for n, (s, w) in enumerate(weights.items()):
    w = w / np.max(np.abs(w))
    total = np.abs(w @ beams) ** 2
    ax.plot(angles_deg, 10 * np.log10(total / ref), color=f"C{n}", label=f"sum, set {s} deg")
    ax.axvline(s, color=f"C{n}", ls=":", lw=1)
ax.set_ylim(-40, 6)
ax.set_xlabel("beamformer angle (deg)")
ax.set_ylabel("beamformer power (dB)")
ax.set_title("Two RTS channels superposed after beamforming (default scene)")
ax.grid(alpha=0.3)
ax.legend(fontsize=8, loc="lower left")
fig.tight_layout()
fig.savefig(OUT / "superposition.png", dpi=100)
