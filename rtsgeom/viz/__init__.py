"""Visualisation: the setup in 3D (pyvista), result figures (matplotlib), HTML reports.

Submodules are imported on use so that ``import rtsgeom.viz`` stays cheap; pyvista/VTK load only
with :mod:`rtsgeom.viz.scene3d` (the view: plotter, PNG, HTML, window) and
:mod:`rtsgeom.viz.meshes` (what it draws); :mod:`rtsgeom.viz.render_backend` finds an
off-screen OpenGL context without importing them.
"""
