"""The Sphinx site builds without a single warning (``-W``): API reference from the docstrings,
the examples as a gallery (not executed here; tests/test_examples.py runs them), the scene
format and the physics notes."""

from __future__ import annotations

import os
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
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH",
                                                                                 "")]))
    run = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b",
                          "html", "-d", str(tmp_path / "doctrees"), str(ROOT / "docs"),
                          str(tmp_path / "html")], capture_output=True, text=True, env=env,
                         timeout=600)
    assert run.returncode == 0, run.stderr[-5000:]
    html = tmp_path / "html"
    gallery = sorted(p.stem for p in (html / "auto_examples").glob("plot_*.html"))
    assert gallery == sorted(p.stem for p in (ROOT / "examples").glob("plot_*.py"))
    api = (html / "api.html").read_text()
    for name in ("run_scene", "load_scene", "calibrate", "tolerance", "design", "show"):
        assert f"rtsgeom.{name}" in api, name
    assert (html / "generated" / "rtsgeom.RangeDoppler.html").is_file()
    assert "to_xarray" in (html / "generated" / "rtsgeom.RangeDoppler.html").read_text()
    assert "Near-field violation" in (html / "physics.html").read_text()
    assert "Scene format" in (html / "scene.html").read_text()
