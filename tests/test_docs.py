"""The Sphinx site builds without a single warning (``-W``): API reference from the docstrings,
the examples as a gallery that runs them and shows their figures (with their small settings
here, RTSGEOM_EXAMPLES_QUICK=1), the scene format and one page per physics topic."""

from __future__ import annotations

import os
import re
import subprocess
import sys

import pytest

from conftest import ROOT

pytest.importorskip("sphinx", reason="the docs extra is not installed (pip install -e '.[docs]')")
pytest.importorskip("sphinx_gallery")
pytest.importorskip("myst_parser")
pytest.importorskip("pydata_sphinx_theme")


@pytest.mark.slow
def test_docs_build_without_warnings(tmp_path):
    env = dict(os.environ, RTSGEOM_EXAMPLES_QUICK="1", MPLBACKEND="Agg",
               PYVISTA_OFF_SCREEN="true",
               PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    run = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b",
                          "html", "-d", str(tmp_path / "doctrees"), str(ROOT / "docs"),
                          str(tmp_path / "html")], capture_output=True, text=True, env=env,
                         timeout=600)
    assert run.returncode == 0, run.stderr[-5000:]
    html = tmp_path / "html"
    gallery = sorted(p.stem for p in (html / "auto_examples").glob("plot_*.html"))
    assert gallery == sorted(p.stem for p in (ROOT / "examples").glob("plot_*.py"))
    # every example shows at least one rendered figure (the images its run wrote), at least 8
    # in all; a thumbnail alone does not count
    figures = {}
    for page in (html / "auto_examples").glob("plot_*.html"):
        srcs = set(re.findall(r'<img[^>]*src="\.\./_images/(sphx_glr_%s_\d+\.png)"'
                              % page.stem, page.read_text()))
        figures[page.stem] = [s for s in srcs if (html / "_images" / s).stat().st_size > 1000]
    assert all(figures.values()), {k: v for k, v in figures.items() if not v}
    # and wrote every file it promises (the gallery is where the examples run:
    # tests/test_examples.py runs them only where this build cannot)
    from test_examples import OUTPUTS
    out = tmp_path / "doctrees" / "example_output"
    written = {p.name: p.stat().st_size for d in (out, out / "written") for p in d.glob("*")
               if p.is_file()}
    missing = [n for names in OUTPUTS.values() for n in names if written.get(n, 0) <= 100]
    assert not missing, missing
    assert sum(len(v) for v in figures.values()) >= 8, figures
    api = (html / "api.html").read_text()
    for name in ("run_scene", "load_scene", "calibrate", "tolerance", "design", "show"):
        assert f"rtsgeom.{name}" in api, name
    assert (html / "generated" / "rtsgeom.RangeDoppler.html").is_file()
    assert "to_xarray" in (html / "generated" / "rtsgeom.RangeDoppler.html").read_text()
    assert "Near-field violation" in (html / "nearfield.html").read_text()
    for page in ("signal-model", "calibration", "link-budget", "ghosts", "tolerance", "design",
                 "identify", "raytrace", "nchannel", "estimators", "performance", "outputs",
                 "testing"):
        assert (html / f"{page}.html").is_file(), page
    assert "Scene format" in (html / "scene.html").read_text()
