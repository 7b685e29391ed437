"""Shared fixtures: the bundled default scene and scene variants built from it."""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path

import pytest

from rtsgeom.scene import parse_scene

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_SCENE = ROOT / "scenes" / "diewald2022.toml"


def default_doc() -> dict:
    return tomllib.loads(DEFAULT_SCENE.read_text())


def make_scene(mutate=None, **radar_overrides):
    """The default scene, optionally changed by ``mutate(doc)`` (a dict edited in place)."""
    doc = copy.deepcopy(default_doc())
    doc["radar"].update(radar_overrides)
    if mutate is not None:
        mutate(doc)
    return parse_scene(doc, "test.toml")


@pytest.fixture(scope="session")
def default_scene():
    from rtsgeom.scene import load_scene
    return load_scene(DEFAULT_SCENE)


@pytest.fixture(scope="session")
def rt():
    """The Sionna RT adapter, or a skip naming why it cannot run here (the ray-tracing tests)."""
    from rtsgeom.paths import raytrace
    ok, msg = raytrace.preflight()
    if not ok:
        pytest.skip(f"Sionna RT unavailable: {msg}")
    return raytrace
