"""``info`` reports each pair's reachable angles -- the same numbers that
``run`` then enforces -- and warns about a target outside them."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from conftest import make_scene
from rtsgeom.cli import main
from rtsgeom.geometry import build_setup
from rtsgeom.pipeline.info import reachable_spans, scene_info, unreachable_warnings
from rtsgeom.pipeline.plan import plan_targets
from rtsgeom.paths import exact_paths
from rtsgeom.pipeline.run import run_scene
from rtsgeom.errors import SceneError


def _variant(radius_m, mode, angle_deg, separation_m=0.02):
    def mutate(doc):
        doc["rts"]["arc_radius_m"] = radius_m
        doc["rts"]["aoa_mode"] = mode
        for fe in doc["rts"]["front_ends"]:
            fe["rx_tx_separation_m"] = separation_m
        doc["targets"] = doc["targets"][:1]
        doc["targets"][0]["angle_deg"] = angle_deg
    return make_scene(mutate)


def _bracket(text: str) -> tuple[str, str]:
    m = re.search(r"\[(-?[\d.]+), (-?[\d.]+)\] deg", text)
    assert m, text
    return m.group(1), m.group(2)


@pytest.mark.parametrize("radius_m,separation_m", [(1.0, 0.02), (2.0, 0.0), (0.7, 0.03)])
@pytest.mark.parametrize("mode", ["exact", "array-factor", "paper"])
def test_info_span_is_the_span_run_enforces(radius_m, separation_m, mode):
    """Across radii, Rx/Tx separations and amplitude modes: a target just outside the span that
    ``info`` reports is refused by ``run`` quoting the same span end; one just inside it is
    accepted by both."""
    probe = reachable_spans(build_setup(_variant(radius_m, mode, 7.0, separation_m)))
    (span,) = probe["pairs"]
    lo, hi = span["lo_deg"], span["hi_deg"]
    geo = np.degrees(build_setup(_variant(radius_m, mode, 7.0, separation_m)).fe_azimuth_rad())
    if separation_m > 0 and radius_m <= 1.0:
        assert lo > geo.min() + 0.1  # the measured span is not the geometric one
    for angle, end in ((lo - 0.05, lo), (hi + 0.05, hi)):
        scene = _variant(radius_m, mode, angle, separation_m)
        info = scene_info(build_setup(scene), reachable=True)
        assert info["reachable"]["pairs"] == probe["pairs"]  # deterministic (seeded)
        assert [t["reachable"] for t in info["reachable"]["targets"]] == [False]
        (warning,) = unreachable_warnings(info)
        with pytest.raises(SceneError) as exc:
            if mode == "exact":
                run_scene(scene)
            else:  # run's planning step without the (slow) calibration sweep before it
                setup = build_setup(scene)
                plan_targets(setup, exact_paths(setup), mode, calibrate=False)
        quoted = _bracket(str(exc.value))
        assert f"{end:.4f}" in quoted, (str(exc.value), warning)
        assert f"{end:.4f}" in warning
    inside = _variant(radius_m, mode, lo + 0.05, separation_m)
    info = scene_info(build_setup(inside), reachable=True)
    assert info["reachable"]["targets"][0]["reachable"]


def test_info_cli_reports_spans_and_warns(tmp_path, capsys):
    """A target at 3.6 deg lies between the front ends' geometric angles
    (3.4, 12.2) but outside the measured span; ``info`` says so, ``run`` refuses it, both with
    the same numbers."""
    from conftest import DEFAULT_SCENE
    text = DEFAULT_SCENE.read_text()
    assert text.count("angle_deg = 7.0") == 1
    path = tmp_path / "s.toml"
    path.write_text(text.replace("angle_deg = 7.0", "angle_deg = 3.6"))
    assert main(["info", str(path), "--json"]) == 0
    cap = capsys.readouterr()
    info = json.loads(cap.out)
    (span,) = info["reachable"]["pairs"]
    assert not info["reachable"]["targets"][0]["reachable"]
    assert "targets[0].angle_deg = 3.6: outside the reachable angles" in cap.err
    lo = f"{span['lo_deg']:.4f}"
    assert lo in cap.err
    assert main(["info", str(path)]) == 0
    cap = capsys.readouterr()
    assert f"pair 0-1: [{lo}, {span['hi_deg']:.4f}] deg" in cap.out
    assert "OUTSIDE the reachable angles" in cap.out
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert _bracket(err) == (lo, f"{span['hi_deg']:.4f}")
