"""The worked example of docs/contributing.md, run: a study added in four places (its module,
its API entry, one COMMANDS line, its docs page) is callable from Python and gets its command
made from its config (``cli/study.py``): options from its fields and declared arguments, the
run, ``--json`` and ``--out``.

The study here is the one the guide writes: each front end alone as the RuT detects it, its
detected angle against its geometric one, flagged beyond a spec."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest

import rtsgeom
from conftest import DEFAULT_SCENE
from rtsgeom._lib.results import Result
from rtsgeom.analysis.tolerance.config import STUDY_ARGS
from rtsgeom.calibration.probes import probe_front_ends
from rtsgeom.cli import COMMANDS, build_parser, main
from rtsgeom.geometry import build_setup
from rtsgeom.paths import exact_paths
from rtsgeom.scene import Scene


# -- 1. the study's module (rtsgeom/analysis/probes_study.py in the guide) --------------------

@dataclass(frozen=True)
class ProbeStudy:
    """Each front end alone as the RuT detects it.

    Parameters
    ----------
    spec_deg : float
        A front end whose detected angle is further than this from its geometric one is
        flagged
    relative : bool
        Report the gain corrections in dB instead of as factors
    """

    ARGS: ClassVar[dict] = {"spec_deg": STUDY_ARGS["spec_deg"]}

    spec_deg: float = 0.1
    relative: bool = False

    def __post_init__(self):
        self.ARGS["spec_deg"].check(self.spec_deg, "spec_deg", "ProbeStudy")

    def __call__(self, scene: Scene) -> "Probes":
        setup = build_setup(scene)
        probe = probe_front_ends(setup, exact_paths(setup), scene.seed)
        gain = probe.gain_correction
        return Probes(np.degrees(setup.fe_azimuth_rad()), np.degrees(probe.angle_rad),
                      20 * np.log10(gain) if self.relative else gain, self.spec_deg)


@dataclass(frozen=True, repr=False)
class Probes(Result):
    """Per front end: geometric and detected azimuth (deg) and its gain correction."""

    geometric_deg: np.ndarray
    detected_deg: np.ndarray
    gain_correction: np.ndarray
    spec_deg: float

    @property
    def bias_deg(self) -> np.ndarray:
        return self.detected_deg - self.geometric_deg

    def _summary(self):
        return (f"{self.bias_deg.size} front ends alone",
                [("bias_deg", self.bias_deg),
                 ("beyond spec", int(np.sum(np.abs(self.bias_deg) > self.spec_deg)))])

    def _columns(self) -> dict:
        return {"geometric_deg": self.geometric_deg, "detected_deg": self.detected_deg,
                "bias_deg": self.bias_deg}

    def to_dict(self) -> dict:
        return {"bias_deg": self.bias_deg.tolist(), "spec_deg": self.spec_deg,
                "gain_correction": np.asarray(self.gain_correction).tolist()}

    def plot(self):
        from rtsgeom.viz.figures import Figure  # matplotlib's, as every figure of the package
        fig = Figure()
        fig.add_subplot().plot(self.geometric_deg, self.bias_deg, "o")
        return fig

    def write(self, folder) -> list[str]:
        self.to_json(Path(folder) / "probes.json")
        self.to_csv(Path(folder) / "probes.csv")
        return ["probes.json", "probes.csv"]


# -- 2. and 3. its API entry and its COMMANDS line (here patched in) ---------------------------

@pytest.fixture
def registered(monkeypatch):
    monkeypatch.setitem(COMMANDS, "probes",
                        ("study", "each front end alone as the RuT detects it",
                         "test_add_a_study:ProbeStudy"))
    monkeypatch.setitem(rtsgeom._LAZY, "ProbeStudy", ("test_add_a_study", "ProbeStudy"))


def test_the_study_is_callable_from_python():
    res = ProbeStudy()(rtsgeom.load_scene(DEFAULT_SCENE))
    assert res.bias_deg.shape == (2,) and np.all(np.isfinite(res.bias_deg))
    assert "front ends alone" in repr(res) and len(res.to_dataframe()) == 2


def test_its_command_is_made_from_its_config(registered, tmp_path, capsys):
    sub = next(a for a in build_parser()._actions if a.__class__.__name__ == "_SubParsersAction")
    opts = {o for a in sub.choices["probes"]._actions for o in a.option_strings}
    assert {"--spec-deg", "--relative", "--json", "--out"} <= opts
    assert "in [1e-06, 90]" in sub.choices["probes"].format_help()
    assert main(["probes", str(DEFAULT_SCENE), "--relative", "--json", "--spec-deg", "0.5",
                 "--out", str(tmp_path / "o")]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["spec_deg"] == 0.5 and len(out["bias_deg"]) == 2
    assert out["gain_correction"][0] == pytest.approx(0.0, abs=3.0)  # dB, not a factor
    assert {"probes.csv", "probes.json"} <= {p.name for p in (tmp_path / "o").iterdir()}


def test_its_command_refuses_what_the_declaration_refuses(registered, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["probes", str(DEFAULT_SCENE), "--spec-deg", "100"])
    assert exc.value.code == 2 and "--spec-deg: 100 is outside" in capsys.readouterr().err
