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

QUICK = os.environ.get("RTSGEOM_EXAMPLES_QUICK") == "1"
OUT = Path(os.environ.get("RTSGEOM_EXAMPLES_OUT", "example_output"))
OUT.mkdir(parents=True, exist_ok=True)
SCENE = Path(__file__).resolve().parents[1] / "scenes" / "diewald2022.toml"

setup = rtsgeom.build_setup(rtsgeom.load_scene(SCENE))
size = (800, 500) if QUICK else (1600, 1000)

# %%
# Ray tracing needs Sionna RT and Dr.Jit's LLVM backend; ``RaytraceUnavailable`` says what to
# install.
try:
    from rtsgeom.paths.raytrace import trace

    traced = trace(setup)
    n_refl = int((traced.paths.bounces > 0).sum())
    print(f"{len(traced.paths)} paths, {n_refl} reflected (hit points drawn)")
    paths = traced
except rtsgeom.RaytraceUnavailable as exc:
    print(f"ray tracing unavailable here ({exc}); drawing line of sight only")
    paths = rtsgeom.exact_paths(setup)

# %%
png = rtsgeom.show(setup, paths=paths, png=OUT / "setup_3d.png", window_size=size)
print(f"wrote {png}")
