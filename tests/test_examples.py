"""Every script in examples/ runs top to bottom with small settings (RTSGEOM_EXAMPLES_QUICK=1),
off screen (matplotlib Agg, pyvista off-screen), and writes the figures it promises: run by
the docs build's gallery (tests/test_docs.py, which checks the files) where Sphinx is
installed, else here, one process each."""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import ROOT

EXAMPLES = sorted((ROOT / "examples").glob("plot_*.py"))

# the figures each example writes (the test fails if one is missing or empty)
OUTPUTS = {
    "plot_range_doppler_table1.py": ["table1_range_doppler.png", "table1_range_angle.png"],
    "plot_calibration_sweep.py": ["calibration_sweep.png"],
    "plot_linearity.py": ["linearity.png"],
    "plot_mounting_tolerance.py": ["mounting_offset.png", "mounting_tolerance.png"],
    "plot_arc_design.py": ["arc_design.png"],
    "plot_setup_3d.py": ["setup_3d.png"],
    "plot_cable_ghosts.py": ["cable_ghosts.png"],
    "plot_nearfield.py": ["nearfield.png"],
    "plot_dca1000_capture.py": ["adc.bin", "adc.bin.json", "dca1000_range_profile.png"],
    "plot_identify.py": ["identify_crb.png"],
    "plot_superposition.py": ["superposition.png"],
    "plot_calibration_transfer.py": ["calibration_transfer.png"],
    "plot_scenario_crossing.py": ["scenario_crossing.png"],
    "plot_two_targets_resolution.py": ["two_targets_resolution.png"],
    "plot_extended_object.py": ["extended_object.png"],
    "plot_kpi_datasheet.py": ["kpi_angle_accuracy.png", "kpi_uncertainty_budget.png"],
}


def test_every_example_is_listed():
    assert sorted(OUTPUTS) == [p.name for p in EXAMPLES]


#: the docs build (tests/test_docs.py) runs every example in its gallery and checks the files
#: each writes (:data:`OUTPUTS`); where it can run, the examples are not run a second time here
DOCS_BUILD_RUNS_THEM = all(importlib.util.find_spec(m) is not None for m in (
    "sphinx", "sphinx_gallery", "myst_parser", "pydata_sphinx_theme"))


@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_example_layout(path: Path):
    text = path.read_text()
    assert text.startswith('"""') and "\n# %%" in text  # sphinx-gallery layout
    assert "rtsgeom._" not in text and "import _" not in text  # public API only


@pytest.mark.slow
@pytest.mark.skipif(DOCS_BUILD_RUNS_THEM, reason="the docs build runs every example "
                    "(tests/test_docs.py)")
@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_example_runs(path: Path, tmp_path):
    env = dict(os.environ, RTSGEOM_EXAMPLES_QUICK="1", RTSGEOM_EXAMPLES_OUT=str(tmp_path),
               MPLBACKEND="Agg", PYVISTA_OFF_SCREEN="true",
               PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    run = subprocess.run([sys.executable, str(path)], cwd=tmp_path, env=env,
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-3000:]
    for name in OUTPUTS[path.name]:
        out = tmp_path / name
        assert out.is_file() and out.stat().st_size > 100, (name, run.stdout[-2000:])
