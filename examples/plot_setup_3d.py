"""
The setup in 3D with ray-traced reflections
===========================================

The RuT, the front-end arc with its antennas, the metal sheet with its cutouts and the virtual
targets, drawn off screen with pyvista. With Sionna RT (and a recent LLVM for its CPU backend)
the reflections off the sheet and the RuT's board are traced and drawn through their hit
points; without it the line-of-sight paths are drawn and the reason is printed.
"""

# %%
import os
from pathlib import Path

import rtsgeom

OUT = Path(os.environ.get("RTSGEOM_EXAMPLES_OUT", "example_output"))
OUT.mkdir(parents=True, exist_ok=True)
# the repository's scenes/ (sphinx-gallery runs a script in examples/, without a __file__)
HERE = Path(globals().get("__file__", "plot.py")).resolve().parent
SCENE = HERE.parent / "scenes" / "diewald2022.toml"

setup = rtsgeom.build_setup(rtsgeom.load_scene(SCENE))
size = (1600, 1000)  # the labels need the room; smaller windows overlap them

# %%
# Ray tracing needs Sionna RT and Dr.Jit's LLVM backend; ``RaytraceUnavailable`` says what to
# install. This is what ``rtsgeom show SCENE --paths raytrace --png setup_3d.png`` writes: left
# the perspective view (the RuT drawn five times its size, the targets at 1.5 R_c), top right
# the RuT's board at true scale, bottom right the plan view.
try:
    png = rtsgeom.show(setup, paths="raytrace", png=OUT / "setup_3d.png", window_size=size)
except rtsgeom.RaytraceUnavailable as exc:
    print(f"ray tracing unavailable here ({exc}); drawing line of sight only")
    png = rtsgeom.show(setup, paths="exact", png=OUT / "setup_3d.png", window_size=size)
print(f"wrote {png}")
