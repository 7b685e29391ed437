"""
Measuring a built setup from radar captures
===========================================

A lab has built the arc; where are its front ends really? With one front end active and a
probe target programmed, the radar under test sees it: the phase across its virtual array
carries the front end's direction (tangential offset) and, with the elevated Tx, its height.
``rtsgeom identify`` inverts the exact forward model of that response by nonlinear least
squares, reports each estimate with its standard deviation, and says which parameters one
capture cannot separate (radial offset and channel delay look like the channel's phase).
The identified setup predicts the pair's calibration delay without a sweep. Last, the
Cramer-Rao bound versus SNR and arc radius: what a lab can measure with its radar.
"""

# %%
import os
from pathlib import Path

import numpy as np

import rtsgeom
from rtsgeom.identify import (crb_figure, identified_scene, identify, predicted_calibration,
                              setup_of, simulate_capture)
from rtsgeom.viz.figures import save_figure

QUICK = os.environ.get("RTSGEOM_EXAMPLES_QUICK") == "1"
OUT = Path(os.environ.get("RTSGEOM_EXAMPLES_OUT", "example_output"))
OUT.mkdir(parents=True, exist_ok=True)
# the repository's scenes/ (sphinx-gallery runs a script in examples/, without a __file__)
HERE = Path(globals().get("__file__", "plot.py")).resolve().parent
SCENE = HERE.parent / "scenes" / "diewald2022.toml"

nominal = rtsgeom.load_scene(SCENE)
nominal = rtsgeom.replace(nominal, radar=rtsgeom.replace(nominal.radar, use_elevation_tx=True))

# %%
# The setup as built: mounting errors within +-0.5 mm and channel gain/phase errors the lab
# does not know.
rng = np.random.default_rng(19)
offsets_m = rng.uniform(-0.5e-3, 0.5e-3, (2, 3))
fes = tuple(rtsgeom.replace(f, radial_offset_m=float(o[0]), tangential_offset_m=float(o[1]),
                            height_offset_m=float(o[2]), gain_offset_db=0.5 * k,
                            phase_offset_rad=1.0 + k)
            for k, (f, o) in enumerate(zip(nominal.rts.front_ends, offsets_m)))
built = rtsgeom.replace(nominal, rts=rtsgeom.replace(nominal.rts, front_ends=fes))
built_setup = setup_of(built)

# %%
# One capture per front end (what ``rtsgeom adc SCENE --active I`` writes), then the fit on the
# nominal scene (what ``rtsgeom identify SCENE cap0.bin cap1.bin`` prints).
captures = [simulate_capture(built_setup, q, seed=q) for q in range(2)]
result = identify(nominal, captures).to_dict()
for q, fe in enumerate(result["front_ends"]):
    for key, truth in (("tangential_offset_mm", offsets_m[q, 1]),
                       ("height_offset_mm", offsets_m[q, 2])):
        est = fe[key]
        print(f"front end {q} {key}: true {truth * 1e3:+.3f}, "
              + ("not identifiable" if est is None else
                 f"estimated {est['value']:+.3f} +- {est['std']:.3f}"))
    print(f"  radial: {fe['not_identifiable'].get('radial_offset_mm', 'identified')[:60]}...")

# %%
# The corrected scene (``identify --out DIR`` writes it as DIR/identified.toml) predicts the
# calibration delay without a sweep; the coherence point of the setup as built is the truth.
ident = identify(nominal, captures)
pred = predicted_calibration(setup_of(identified_scene(ident)), (0, 1))
true = predicted_calibration(built_setup, (0, 1))
print(f"calibration delay: predicted {pred.delta_tau_s * 1e12:.1f} ps, "
      f"setup as built {true.delta_tau_s * 1e12:.1f} ps")

# %%
# Cramer-Rao bound of one capture versus SNR and arc radius.
snr_db = np.linspace(-10.0, 30.0, 3 if QUICK else 21)
radii = [0.5, 1.0, 2.0] if QUICK else [0.5, 1.0, 2.0, 4.0]
save_figure(crb_figure(nominal, snr_db, radii), OUT / "identify_crb.png")
