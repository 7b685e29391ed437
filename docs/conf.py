"""Sphinx configuration of the rtsgeom documentation.

Build: ``python -m sphinx -W -b html docs docs/_build/html`` (warnings are errors; the test
suite does this in tests/test_docs.py). The gallery runs every script in examples/ and shows the
figures each one writes: the whole build takes about 40 s on 2 cores with the examples' full
settings, about 25 s with their small ones (``RTSGEOM_EXAMPLES_QUICK=1 python -m sphinx ...``,
what the test suite builds). Every build runs every example again (``run_stale_examples``), so
the figures never lag behind the code or the settings.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(HERE))  # _gallery.py: the gallery's order and scraper

import rtsgeom  # noqa: E402

project = "rtsgeom"
author = "rtsgeom authors"
copyright = "rtsgeom authors"
release = version = rtsgeom.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "generated_scene", "scene-format.md", "Thumbs.db", ".DS_Store"]

myst_enable_extensions = ["dollarmath"]
myst_heading_anchors = 3

autosummary_generate = True
autodoc_typehints = "none"  # the numpy docstrings carry the types
autodoc_member_order = "bysource"
autodoc_default_options = {"members": False}
napoleon_numpy_docstring = True
napoleon_google_docstring = False
napoleon_use_rtype = False

sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "plot_gallery": "True",
    "download_all_examples": False,
    "within_subsection_order": "_gallery.ExampleOrder",
    "remove_config_comments": True,
    "image_scrapers": ("_gallery.scrape_outputs",),  # the PNG files each example writes
    "reset_modules": ("matplotlib", "_gallery.reset_outputs"),
    "capture_repr": (),  # the scripts print what they want to show
    "only_warn_on_example_error": False,  # a failing example fails the build
    "run_stale_examples": True,  # no cached figures from another version or setting
}

# How the gallery runs the examples: off screen, their output files (example_output/) out of
# the source tree (see setup below); RTSGEOM_EXAMPLES_QUICK=1 from the environment for small
# settings.
os.environ.setdefault("MPLBACKEND", "Agg")
os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")

html_theme = "pydata_sphinx_theme"
html_title = f"rtsgeom {release}"
html_theme_options = {"navigation_with_keys": False, "show_toc_level": 2}
html_static_path: list[str] = []


def _escape_abs_bars(app, what, name, obj, options, lines):
    """Docstrings write absolute values as ``|x|``, which reST reads as a substitution
    reference (an error under -W); show the bars literally."""
    import re
    bars = re.compile(r"(?<![`\\\w])\|([^|`\n]+?)\|(?![`\w])")
    lines[:] = [bars.sub(r"\\|\1\\|", ln) for ln in lines]


def setup(app):
    app.connect("autodoc-process-docstring", _escape_abs_bars)
    # the files each example writes (besides the figures the gallery shows) go beside the
    # doctrees, not into examples/ where the scripts run
    os.environ.setdefault("RTSGEOM_EXAMPLES_OUT", str(Path(app.doctreedir) / "example_output"))


# The scene-format page: docs/scene-format.md is generated from the scene schema; until it
# exists, a placeholder keeps the build (and its cross-references) working.
_scene = HERE / "scene-format.md"
_page = HERE / "scene.md"
_text = ("# Scene format\n\n"
         + ("```{include} scene-format.md\n:heading-offset: 1\n```\n" if _scene.is_file() else
            "The scene file (TOML) reference is generated from the schema into "
            "`docs/scene-format.md`; it is not there in this checkout. The bundled scene "
            "`scenes/diewald2022.toml` documents every field in its comments.\n"))
if not _page.is_file() or _page.read_text() != _text:
    _page.write_text(_text)
