"""Data contracts across the package: the Echoes table's constructor and shape checks, the echo
kinds, the curated top level, and that every ``__all__`` lists only names that exist."""

from __future__ import annotations

import ast
import importlib
import pkgutil
import re
from pathlib import Path

import numpy as np
import pytest

import rtsgeom
from rtsgeom.rts.channels import KIND_DIRECT, KIND_GHOST, KIND_SETUP, EchoKind, Echoes

ROOT = Path(__file__).resolve().parents[1]
PER_ECHO = ("tau_if_s", "f_if_hz", "doppler_hz", "target", "front_end", "kind", "order")


def _full(e, v, n=None, seed=0):
    rng = np.random.default_rng(seed)
    kw = dict(tau_air_s=rng.uniform(1e-9, 1e-8, (e, v)), tau_if_s=rng.uniform(0, 1e-6, e),
              f_if_hz=np.full(e, 1e9), doppler_hz=rng.normal(0, 100, e),
              amplitude=rng.normal(size=(e, v)) + 1j * rng.normal(size=(e, v)),
              target=rng.integers(0, 4, e), front_end=rng.integers(0, 3, e),
              kind=rng.integers(0, 3, e), order=rng.integers(0, 3, e))
    if n is not None:
        kw["fast_gain"] = np.exp(1j * rng.normal(size=(e, n)))
    return kw


@pytest.mark.parametrize("e, v, n", [(1, 1, None), (3, 8, None), (5, 12, 64), (0, 4, None),
                                     (2, 86, 16)])
def test_echoes_keywords_equal_positional_and_are_read_only(e, v, n):
    kw = _full(e, v, n)
    a = Echoes(**kw)
    b = Echoes(*(kw[k] for k in ("tau_air_s", "tau_if_s", "f_if_hz", "doppler_hz", "amplitude",
                                 "target", "front_end", "kind", "order")),
               kw.get("fast_gain"))
    for name in kw:
        assert np.array_equal(getattr(a, name), kw[name])
        assert np.array_equal(getattr(b, name), kw[name])
        assert not getattr(a, name).flags.writeable
    assert len(a) == e and a.tau_s.shape == (e, v)


@pytest.mark.parametrize("e, v", [(1, 1), (3, 8), (4, 12)])
@pytest.mark.parametrize("field", ["tau_air_s", "amplitude", *PER_ECHO, "fast_gain"])
def test_echoes_wrong_shape_names_the_field_and_its_shape(e, v, field):
    kw = _full(e, v, 16)
    bad = np.asarray(kw[field])
    bad = np.concatenate([bad, bad[:1]]) if bad.shape[0] else np.zeros((1,) + bad.shape[1:])
    if field == "tau_air_s":  # E follows tau_air_s: break V instead
        bad = kw[field][:, :-1] if v > 1 else np.zeros((e, 2))
    kw[field] = bad
    # tau_air_s sets E and V: a tau_air_s of the wrong V is reported at the amplitude
    named = "(tau_air_s|amplitude)" if field == "tau_air_s" else field
    with pytest.raises(ValueError, match=rf"Echoes\.{named}: got shape .* must be \("):
        Echoes(**kw)


@pytest.mark.parametrize("field", ["target", "front_end", "kind", "order"])
def test_echoes_index_fields_must_be_integers(field):
    kw = _full(3, 4)
    kw[field] = np.asarray(kw[field], float) + 0.5
    with pytest.raises(ValueError, match=rf"Echoes\.{field}: .* integers"):
        Echoes(**kw)


def test_echoes_tau_air_must_be_two_dimensional():
    kw = _full(3, 4)
    kw["tau_air_s"] = np.zeros(3)
    with pytest.raises(ValueError, match=r"Echoes\.tau_air_s: shape \(3,\) must be \(E, V\)"):
        Echoes(**kw)


@pytest.mark.parametrize("e, v", [(1, 1), (4, 8), (0, 3)])
def test_echoes_build_broadcasts_per_echo_scalars(e, v):
    tau = np.full((e, v), 2e-9)
    ech = Echoes.build(tau_air_s=tau, amplitude=np.ones((e, v)), tau_if_s=1e-7, f_if_hz=2e9,
                       doppler_hz=-50.0, front_end=2, kind=EchoKind.GHOST, order=1)
    for name, want in (("tau_if_s", 1e-7), ("f_if_hz", 2e9), ("doppler_hz", -50.0),
                       ("target", -1), ("front_end", 2), ("kind", 1), ("order", 1)):
        assert getattr(ech, name).shape == (e,) and np.all(getattr(ech, name) == want)
    assert np.all(ech.kind == EchoKind.GHOST) and ech.fast_gain is None
    assert np.allclose(ech.tau_s, 2e-9 + 1e-7)
    sel = ech.select(np.arange(e) % 2 == 0)
    assert len(sel) == (e + 1) // 2 and sel.amplitude.shape == ((e + 1) // 2, v)


def test_echo_kinds_keep_their_old_names_and_values():
    assert [int(k) for k in EchoKind] == [0, 1, 2]
    assert (KIND_DIRECT, KIND_GHOST, KIND_SETUP) == (EchoKind.DIRECT, EchoKind.GHOST,
                                                     EchoKind.SETUP)
    kinds = np.array([2, 0, 1, 0])
    assert np.array_equal(kinds == EchoKind.DIRECT, kinds == 0)


def _modules():
    for info in pkgutil.walk_packages(rtsgeom.__path__, "rtsgeom."):
        name = info.name
        if name.endswith("__main__") or ".viz.scene3d" in name or name.startswith(
                "rtsgeom.viz.meshes") or "raytrace" in name:
            continue  # pyvista / Sionna load on use only
        yield name


@pytest.mark.parametrize("name", sorted(_modules()))
def test_every_all_lists_existing_public_names(name):
    mod = importlib.import_module(name)
    names = getattr(mod, "__all__", None)
    if names is None:
        return
    assert len(set(names)) == len(names), f"{name}.__all__ repeats a name"
    for n in names:
        assert hasattr(mod, n), f"{name}.__all__ lists {n!r}, which it does not define"
        assert not n.startswith("_") or n == "__version__", f"{name}.__all__ lists private {n!r}"


def test_top_level_lists_each_name_once_and_only_public_ones():
    assert len(set(rtsgeom.__all__)) == len(rtsgeom.__all__)
    assert all(not n.startswith("_") for n in rtsgeom.__all__ if n != "__version__")
    assert set(rtsgeom.__all__) == {"__version__", *rtsgeom._LAZY}
    # the API reference documents exactly the top level
    text = (ROOT / "docs" / "api.rst").read_text(encoding="utf-8").split("Figures (")[0]
    assert set(re.findall(r"^   ([A-Za-z_0-9]+)$", text, re.M)) == set(rtsgeom._LAZY)


def test_no_private_name_is_imported_from_another_package():
    """``from ..x import _y`` across packages: a private helper crossing a package boundary."""
    bad = []
    for path in (ROOT / "rtsgeom").rglob("*.py"):
        pkg = path.parent.relative_to(ROOT).parts
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not isinstance(node, ast.ImportFrom) or node.level == 0:
                continue
            target = list(pkg[:len(pkg) - node.level + 1]) + (node.module or "").split(".")
            target = [t for t in target if t]
            target_pkg = tuple(target[:-1]) if (ROOT.joinpath(*target).with_suffix(".py")
                                                .exists()) else tuple(target)
            for a in node.names:
                if re.match(r"_[a-zA-Z]", a.name) and target_pkg != pkg:
                    bad.append(f"{path.relative_to(ROOT)}: {a.name} from {'.'.join(target)}")
    assert not bad, bad


# ------------------------------------------------------------------------------------------
# Specific exceptions: a user's bad input is a named error (exit 2), never a masked bug
# ------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def capture_files(tmp_path_factory):
    from rtsgeom.cli import main
    from conftest import DEFAULT_SCENE
    d = tmp_path_factory.mktemp("caps")
    for name in ("c.bin", "c.npy"):
        assert main(["adc", str(DEFAULT_SCENE), "--active", "0", "--out", str(d / name),
                     "--quiet"]) == 0
    return d


def _corrupt(kind, path):
    side = path.with_name(path.name + ".json")
    if kind == "truncated":
        path.write_bytes(path.read_bytes()[:1001])
    elif kind == "not-json":
        side.write_text("{not json")
    elif kind == "not-object":
        side.write_text("[1, 2]")
    elif kind == "missing-key":
        import json
        meta = json.loads(side.read_text())
        del meta["probe_range_m" if path.suffix == ".npy" else "num_rx"]
        side.write_text(json.dumps(meta))
    elif kind == "bad-value":
        import json
        meta = json.loads(side.read_text())
        meta["active_front_end"] = "first"
        side.write_text(json.dumps(meta))
    elif kind == "no-sidecar":
        side.unlink()
    elif kind == "missing":  # the capture itself gone: say so, not "no sidecar"
        path.unlink()


@pytest.mark.parametrize("name", ["c.bin", "c.npy"])
@pytest.mark.parametrize("kind", ["truncated", "not-json", "not-object", "missing-key",
                                  "bad-value", "no-sidecar", "missing"])
def test_a_broken_capture_is_a_capture_error_and_exit_2(capture_files, tmp_path, name, kind,
                                                        capsys):
    import shutil

    from rtsgeom.cli import main
    from rtsgeom.errors import CaptureError
    from rtsgeom.identify import read_capture
    from conftest import DEFAULT_SCENE
    path = tmp_path / name
    shutil.copy(capture_files / name, path)
    shutil.copy(capture_files / (name + ".json"), tmp_path / (name + ".json"))
    assert read_capture(path).data.ndim == 3  # intact: reads
    _corrupt(kind, path)
    with pytest.raises(CaptureError, match=re.escape(str(tmp_path))) as exc:
        read_capture(path)
    assert ("no such file" in str(exc.value)) == (kind == "missing")
    assert main(["identify", str(DEFAULT_SCENE), str(path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("rtsgeom: error: CAPTURE: ") and "Traceback" not in err


def test_odd_samples_cannot_be_dca1000(tmp_path, capsys):
    from rtsgeom.errors import ParameterError
    from rtsgeom.geometry import build_setup
    from rtsgeom.radar.dca1000 import to_dca1000
    from rtsgeom.radar.fmcw import AdcCube
    from conftest import make_scene
    scene = make_scene(samples_per_chirp=63)
    setup = build_setup(scene)
    cube = AdcCube(np.zeros((2, setup.rut.num_virtual, 63), np.complex64), scene.radar, setup.rut)
    with pytest.raises(ParameterError, match="samples_per_chirp = 63: must be even"):
        to_dca1000(cube)


@pytest.mark.parametrize("suffix", [".xyz", ".png", ".glb2"])
def test_unknown_mesh_format_is_an_output_error(tmp_path, suffix, capsys):
    from rtsgeom.cli import main
    from conftest import DEFAULT_SCENE
    assert main(["export-mesh", str(DEFAULT_SCENE), "--out", str(tmp_path / f"m{suffix}")]) == 2
    err = capsys.readouterr().err
    assert "unsupported mesh format" in err and "Traceback" not in err
