"""Absorbers per surface: ``sheet.reflection_loss_db`` and ``[[structure]] reflection_loss_db``
lower every ray-traced path by their loss once per bounce off the surface that carries them,
and leave every other path as it was.

Skipped, like ``test_raytrace.py``, where Sionna RT or a usable LLVM backend is missing.
"""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from scipy.constants import c

from conftest import default_doc
from rtsgeom.geometry import build_setup
from rtsgeom.paths.table import RUT_TO_RUT
from rtsgeom.errors import SceneError
from rtsgeom.scene import parse_scene

pytestmark = pytest.mark.raytrace


def _plate(folder, dist_m: float, az_deg: float) -> None:
    """A 0.4 m x 0.4 m plate ``dist_m`` from the RuT at azimuth ``az_deg`` (outside the sheet's
    -15..30 deg, which would shadow it), facing it."""
    plate = trimesh.creation.box(extents=[0.4, 0.01, 0.4])
    az = np.radians(az_deg)
    pose = trimesh.transformations.rotation_matrix(-az, [0, 0, 1])
    pose[:3, 3] = (dist_m + 0.005) * np.array([np.sin(az), np.cos(az), 0.0])
    plate.apply_transform(pose)
    plate.export(folder / "plate.ply")


def _trace(rt, folder, sheet_db: float, plate_db: float, material: str):
    doc = default_doc()
    doc["sheet"]["reflection_loss_db"] = sheet_db
    doc["structure"] = [{"mesh": "plate.ply", "material": material,
                         "reflection_loss_db": plate_db}]
    s = build_setup(parse_scene(doc, "absorber.toml", base_dir=folder))
    cfg = s.scene.raytrace.evolve(max_depth=2, min_gain_db=-400.0)  # nothing dropped as weak
    return rt.trace(s, cfg)


@pytest.mark.parametrize("dist_m,az_deg,material", [(2.5, -40.0, "itu_metal"),
                                                    (1.7, -60.0, "itu_concrete")])
def test_absorber_lowers_each_bounce_off_its_surface(rt, tmp_path, dist_m, az_deg, material):
    """Per row: gain(losses) = gain(no absorber) * 10^(-(n_sheet L_sheet + n_plate L_plate)/20),
    n_x the row's bounces off surface x; rows touching neither are unchanged; delays equal."""
    _plate(tmp_path, dist_m, az_deg)
    ref = _trace(rt, tmp_path, 0.0, 0.0, material)
    n_sheet = np.sum(ref.objects == "sheet", axis=1)
    n_plate = np.sum(ref.objects == "structure_0", axis=1)
    assert np.any(n_plate == 1) and np.any(n_sheet == 1) and np.any(n_sheet + n_plate == 0)
    # the plate's own echo of the RuT's chirp: a single bounce at 2 d / c
    echo = (ref.paths.direction == RUT_TO_RUT) & (n_plate == 1) & (ref.paths.bounces == 1)
    assert np.all(np.abs(ref.paths.delay_s[echo] * c - 2 * dist_m) < 0.03)
    for sheet_db, plate_db in ((0.0, 20.0), (10.0, 0.0), (6.0, 13.0)):
        got = _trace(rt, tmp_path, sheet_db, plate_db, material)
        assert np.array_equal(got.objects, ref.objects)
        np.testing.assert_array_equal(got.paths.delay_s, ref.paths.delay_s)
        expect = ref.paths.gain * 10 ** (-(n_sheet * sheet_db + n_plate * plate_db) / 20)
        # Sionna traces in float32: a re-trace may round a row differently (seen: 1e-7)
        np.testing.assert_allclose(got.paths.gain, expect, rtol=1e-6, atol=0)
        level = 20 * np.log10(np.abs(got.paths.gain[echo]) / np.abs(ref.paths.gain[echo]))
        np.testing.assert_allclose(level, -plate_db, atol=1e-9)


def test_structure_loss_out_of_range_is_a_clear_error(tmp_path):
    _plate(tmp_path, 2.0, 0.0)
    doc = default_doc()
    doc["structure"] = [{"mesh": "plate.ply", "reflection_loss_db": -3.0}]
    with pytest.raises(SceneError, match=r"reflection_loss_db.*\[0, 100\]"):
        parse_scene(doc, "absorber.toml", base_dir=tmp_path)
