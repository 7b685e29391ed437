"""The paths method is chosen in one place: ``registry.PATH_METHODS`` via ``compute_paths``."""

from __future__ import annotations

import numpy as np
import pytest

from rtsgeom.scene import registry
from rtsgeom.geometry import build_setup
from rtsgeom.paths import compute_paths, exact_paths


def test_unknown_method_names_the_registered_ones(default_scene):
    with pytest.raises(ValueError, match="exact, raytrace"):
        compute_paths(build_setup(default_scene), "nope")


def test_a_new_registry_entry_is_all_a_method_needs(default_scene, monkeypatch):
    """Adding a method is one entry: run_scene and the CLI's paths command dispatch through it."""
    monkeypatch.setitem(registry.PATH_METHODS, "exact-copy", registry.PathMethod(
        "a copy of exact", "rtsgeom.paths.exact:exact_paths", "rtsgeom.paths.exact:exact_paths"))
    setup = build_setup(default_scene)
    got, ref = compute_paths(setup, "exact-copy"), exact_paths(setup)
    np.testing.assert_array_equal(got.delay_s, ref.delay_s)
    from rtsgeom.cli import build_parser
    args = build_parser().parse_args(["paths", "scenes/diewald2022.toml", "--out", "x.csv",
                                      "--method", "exact-copy"])
    assert args.method == "exact-copy"
