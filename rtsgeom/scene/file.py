"""The scene file as bytes and text: size and key limits, UTF-8 and TOML decoding, reading
from disk and resolving mesh paths -- everything :mod:`rtsgeom.scene.scene` does before and around
building the :class:`~rtsgeom.scene.scene.Scene` from the parsed document. Every failure is a
:class:`~rtsgeom.scene.schema.SceneError` naming the file.

Resource limits: a scene file is a few kB; these stop a hostile or mistyped file from asking
for gigabytes of memory or hours of work before anything is computed.
"""

from __future__ import annotations

import hashlib
import re
import os
import stat
import tomllib
from pathlib import Path

from ..errors import ParameterError, SceneError
from .schema import fmt as _fmt

__all__ = ["MAX_SCENE_BYTES", "MAX_KEY_PARTS", "MAX_KEY_CHARS", "decode_toml", "read_scene_bytes",
           "resolve_meshes", "resolve_mesh"]

MAX_SCENE_BYTES = 4 << 20  # size of a scene file
MAX_KEY_PARTS = 16  # dotted parts of one TOML key (tomllib is quadratic in them)
MAX_KEY_CHARS = 1000  # characters of one bare key

# A dotted key of many parts (``a.a.a. ... = 1``, also in table headers and inline tables):
# tomllib takes time quadratic in the parts, minutes for a 400 kB line, so they are counted
# first. The lookbehind anchors the search at the start of a key and the possessive
# quantifiers keep the scan linear.
_DOTTED = re.compile(r"""(?<![\w"'-])(?:(?:[\w-]++|"[^"\\\n]*+"|'[^'\n]*+')[ \t]*+\.[ \t]*+)"""
                     + "{%d}" % MAX_KEY_PARTS)
_LONG_KEY = re.compile(r"^[ \t]*+\[*+[ \t]*+[\w-]{%d}" % (MAX_KEY_CHARS + 1), re.MULTILINE)


def _prescan(text: str, source: str) -> None:
    """Refuse keys TOML would take minutes to parse: too many dotted parts, too long."""
    m = _DOTTED.search(text)
    if m:
        line = text.count("\n", 0, m.start()) + 1
        raise SceneError(f"{source}: line {line}: a key of more than {MAX_KEY_PARTS} dotted "
                         f"parts ({_fmt(m.group(0))}...): scene keys are at most "
                         f"{MAX_KEY_PARTS} deep")
    m = _LONG_KEY.search(text)
    if m:
        line = text.count("\n", 0, m.start()) + 1
        raise SceneError(f"{source}: line {line}: a key of more than {MAX_KEY_CHARS} "
                         f"characters ({_fmt(m.group(0).strip())}...): no scene key is that long")


def decode_toml(raw: bytes | str, source: str) -> tuple[dict, str]:
    """Scene text (bytes or str; a UTF-8 byte-order mark accepted) -> (parsed TOML document,
    SHA-256 of the bytes)."""
    if isinstance(raw, str):
        raw = raw.encode("utf-8", "surrogatepass")
    if len(raw) > MAX_SCENE_BYTES:
        raise SceneError(f"{source}: scene file too large ({len(raw)} bytes; at most "
                         f"{MAX_SCENE_BYTES})")
    try:
        text = raw.decode("utf-8-sig")
        _prescan(text, source)
        data = tomllib.loads(text)
    except UnicodeDecodeError as exc:
        raise SceneError(f"{source}: not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    except SceneError:
        raise
    except ValueError as exc:  # TOMLDecodeError, or an integer of more than 4300 digits
        raise SceneError(f"{source}: not valid TOML ({str(exc)[:200]})") from None
    except RecursionError:
        raise SceneError(f"{source}: not valid TOML (arrays or tables nested too deeply)") from None
    return data, hashlib.sha256(raw).hexdigest()


def read_scene_bytes(path: str | Path) -> tuple[bytes, Path]:
    """A scene file's bytes (at most one more than the limit, so the size check sees it) and
    its folder."""
    if not isinstance(path, (str, os.PathLike)):
        raise ParameterError(f"load_scene: path = {_fmt(path)}: must be a scene file's path "
                             "(str or os.PathLike)")
    p = Path(path)
    try:
        st = p.stat()
        if stat.S_ISDIR(st.st_mode):
            raise SceneError(f"{p}: cannot read scene file (it is a directory)")
        if not stat.S_ISREG(st.st_mode):
            raise SceneError(f"{p}: cannot read scene file (not a regular file)")
        with p.open("rb") as fh:
            raw = fh.read(MAX_SCENE_BYTES + 1)
        return raw, p.resolve().parent
    except SceneError:
        raise
    except OSError as exc:
        raise SceneError(f"{p}: cannot read scene file ({exc.strerror or exc})") from None
    except (ValueError, RuntimeError) as exc:  # embedded NUL byte; symlink loop
        raise SceneError(f"{_fmt(str(p))}: cannot read scene file ({exc})") from None


def resolve_meshes(structures, source: str, base_dir: Path | None,
                   allow_external_meshes: bool) -> tuple[tuple[str, str, float], ...]:
    """Mesh paths, resolved against the scene's folder and (unless allowed) kept inside it.

    A path outside the folder is refused before the file system is asked anything, so the
    error cannot reveal whether some file elsewhere exists."""
    out = []
    for i, st in enumerate(structures):
        p = resolve_mesh(st.mesh, f"structure[{i}].mesh", source, base_dir,
                         allow_external_meshes)
        out.append((p, st.material, float(st.reflection_loss_db)))
    return tuple(out)


def resolve_mesh(rel: str, where: str, source: str, base_dir: Path | None,
                 allow_external_meshes: bool) -> str:
    """One mesh path (the field ``where``), resolved against the scene's folder and (unless
    allowed) kept inside it."""
    base = (base_dir or Path.cwd())
    p = Path(rel)
    if not allow_external_meshes:
        if p.is_absolute() or ".." in p.parts or "\0" in rel:
            raise SceneError(f"{source}: {where} = {_fmt(rel)}: must be a relative path "
                             "inside the scene's folder (no absolute path, no '..'; "
                             "pass allow_external_meshes to load one from elsewhere)")
    if not p.is_absolute():
        p = base / p
    try:
        exists = p.is_file()
        inside = allow_external_meshes or p.resolve().is_relative_to(base.resolve())
    except (OSError, ValueError, RuntimeError):  # a name too long, a symlink loop
        exists = inside = False
    if not inside:
        raise SceneError(f"{source}: {where} = {_fmt(rel)}: must be a file inside the "
                         "scene's folder (a link leads out of it)")
    if not exists:
        raise SceneError(f"{source}: {where} = {_fmt(rel)}: must be an existing mesh file "
                         f"in the scene's folder (resolved to {_fmt(str(p))})")
    return str(p)
