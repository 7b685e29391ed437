"""How the gallery runs the examples (docs/conf.py names these): their order (the paper's
figures first, then the user's jobs, then the rest; an example not listed goes last, by file
name) and the scraper that shows the figures they write."""

from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

ORDER = (
    # the paper's figures
    "plot_range_doppler_table1.py",
    "plot_superposition.py",
    "plot_calibration_sweep.py",
    "plot_linearity.py",
    # the user's jobs
    "plot_mounting_tolerance.py",
    "plot_arc_design.py",
    "plot_setup_3d.py",
    # the analyses behind them
    "plot_nearfield.py",
    "plot_cable_ghosts.py",
    "plot_identify.py",
    "plot_dca1000_capture.py",
)


class ExampleOrder:
    """Sort key: the position in :data:`ORDER`, then the file name."""

    def __init__(self, src_dir):
        self.src_dir = src_dir

    def __call__(self, filename: str):
        return (ORDER.index(filename) if filename in ORDER else len(ORDER), filename)

    def __repr__(self) -> str:  # sphinx compares config values between builds by repr
        return f"ExampleOrder({len(ORDER)} examples)"


class OutputScraper:
    """Image scraper: the PNG files an example wrote (or rewrote) into its output folder
    (``RTSGEOM_EXAMPLES_OUT``) during a code block, in the order written.

    The examples save their figures as files, mostly through ``rtsgeom.viz.figures`` (no
    pyplot, so sphinx-gallery's matplotlib scraper would not see them) and the 3D view through
    pyvista off screen; the gallery shows exactly those files.
    """

    def __init__(self):
        self.seen: dict[str, tuple[int, int]] = {}

    def __repr__(self) -> str:
        return "OutputScraper()"

    @staticmethod
    def folder() -> Path:
        return Path(os.environ["RTSGEOM_EXAMPLES_OUT"])

    def reset(self, gallery_conf, fname) -> None:
        """Before each example: an empty output folder (the previous example's files moved
        into its ``written/``, where the docs test checks them), no figure open in pyplot."""
        out = self.folder()
        if out.is_dir():
            (out / "written").mkdir(exist_ok=True)
            for p in out.iterdir():
                if p.is_file():
                    p.replace(out / "written" / p.name)
        self.seen.clear()
        if "matplotlib.pyplot" in sys.modules:
            sys.modules["matplotlib.pyplot"].close("all")

    def __call__(self, block, block_vars, gallery_conf, **kwargs) -> str:
        from sphinx_gallery.scrapers import figure_rst
        out = self.folder()
        if not out.is_dir():
            return ""
        stamps = {p: (p.stat().st_mtime_ns, p.stat().st_size) for p in out.glob("*.png")}
        new = [p for p in sorted(stamps, key=lambda p: (stamps[p], p.name))
               if self.seen.get(p.name) != stamps[p]]
        images = []
        for src, dest in zip(new, block_vars["image_path_iterator"]):
            self.seen[src.name] = stamps[src]
            shutil.copyfile(src, dest)
            images.append(dest)
        return figure_rst(images, gallery_conf["src_dir"]) if images else ""


scrape_outputs = OutputScraper()


def reset_outputs(gallery_conf, fname) -> None:
    scrape_outputs.reset(gallery_conf, fname)
