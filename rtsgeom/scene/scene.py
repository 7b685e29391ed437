"""The scene: TOML -> validated, frozen :class:`Scene`.

The sections' fields are declared in :mod:`.sections`, read by the one generic reader of
:mod:`.schema`; the rules between fields live in :mod:`.rules` (:func:`~.rules.problems`), the
file's bytes and limits in :mod:`.file`; ``docs/scene-format.md`` is generated from the
declarations (``python -m rtsgeom.scene.docs``). Every error names the file, the field (dotted
path), the value and what is allowed; unknown keys are rejected so a typo never silently falls
back to a default.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

from .objects import expand_objects, object_paths
from .file import decode_toml, read_scene_bytes, resolve_meshes
from .hardware import check_layout_keys, resolve_pattern_tables
from .rules import problems
from .scenario import ScenarioConfig
from .evolve import Evolvable, check_fields
from .schema import Derived, fmt, read, spec
from ..errors import ParameterError, SceneError
from .sections import (MAX_NAME_CHARS, MAX_TARGETS, RadarConfig, RaytraceConfig, RtsConfig,
                       SheetConfig, StructureConfig, TargetConfig)

__all__ = ["Scene", "SceneError", "load_scene", "loads_scene", "parse_scene", "check_scene_arg"]


@dataclass(frozen=True)
class Scene(Evolvable):
    """A validated scene. ``evolve(**changes)`` builds a variant and checks it again.

    Attributes
    ----------
    name : str
    radar : RadarConfig
        The radar under test ([radar]).
    rts : RtsConfig
        The RTS: its arc, front ends and channels ([rts]).
    sheet : SheetConfig
    targets : tuple of TargetConfig
    raytrace : RaytraceConfig
    seed : int
        The noise and Monte-Carlo seed.
    source : str
        Where the scene was read from.
    sha256 : str
        The file's hash (calibration files record it).
    scenario : ScenarioConfig or None
        A drive ([scenario]), if any.
    """

    name: str = spec("name", "str", "scene name (printed, used in titles)",
                     Derived("the file name without .toml", lambda v: v["_stem"]),
                     max_chars=MAX_NAME_CHARS, printable=True)
    radar: RadarConfig = spec("radar", "table", "[radar] the radar under test", cls=RadarConfig)
    rts: RtsConfig = spec("rts", "table", "[rts] the radar target simulator", cls=RtsConfig)
    sheet: SheetConfig = spec("sheet", "table", "[sheet] the metal sheet", {}, cls=SheetConfig)
    targets: tuple[TargetConfig, ...] = spec("targets", "tables", "[[targets]] virtual targets",
                                             [], cls=TargetConfig, max_items=MAX_TARGETS,
                                             item="target")
    raytrace: RaytraceConfig = spec("raytrace", "table", "[raytrace] Sionna RT settings", {},
                                    cls=RaytraceConfig)
    seed: int = spec("seed", "int", "random seed (noise)", 0, lo=0, hi=2**63 - 1)
    source: str | None = None
    sha256: str = ""
    description: str = spec("description", "str", "free text", "")
    extra_meshes: tuple[tuple[str, str, float], ...] = spec(  # (absolute path, material, loss dB)
        "structure", "tables", "[[structure]] extra meshes for ray tracing", [],
        cls=StructureConfig, max_items=MAX_TARGETS, item="structure")
    scenario: ScenarioConfig | None = spec(
        "scenario", "table", "[scenario] moving targets played frame by frame (`rtsgeom play`)",
        None, cls=ScenarioConfig)
    #: the extended objects (``scatterers`` or ``mesh`` entries; :mod:`.objects`), their
    #: static ones expanded into ``targets`` on load
    objects: tuple = ()

    def evolve(self, **changes) -> "Scene":
        """``dataclasses.replace`` that validates the variant again (fields and rules)."""
        new = dataclasses.replace(self, **changes)
        src = self.source or "<scene>"
        check_fields(dataclasses.replace(new, extra_meshes=()), src)
        found = problems(new)
        if found:
            raise SceneError(found[0], found)
        return new


# --------------------------------------------------------------------------------------------
# Loading
# --------------------------------------------------------------------------------------------


def parse_scene(data: dict, source: str = "<scene>", base_dir: Path | None = None,
                sha256: str = "", allow_external_meshes: bool = False) -> Scene:
    """Build a validated :class:`Scene` from a parsed TOML document.

    Raises :class:`SceneError` naming the first problem; its ``problems`` lists all the
    violated cross-field rules (:func:`problems`).

    Parameters
    ----------
    data : dict
        The scene as a parsed TOML document.
    source : str
        Where it came from (named in errors).
    base_dir : Path, optional
        The folder relative paths (meshes, pattern tables) are read from.
    sha256 : str
        The file's hash, recorded with the scene.
    allow_external_meshes : bool
        Accept mesh files outside ``base_dir``.

    Returns
    -------
    Scene

    Raises
    ------
    SceneError
        A field outside its range or a violated rule; the message names the field.
    """
    stem = Path(source).stem if source != "<scene>" else "scene"
    scene = read(Scene, data, source, "", {"_stem": stem, "source": source, "sha256": sha256})
    check_layout_keys(data, source)  # the file's keys (a read scene cannot tell them apart)
    meshes = resolve_meshes(scene.extra_meshes, source, base_dir, allow_external_meshes)
    scene = dataclasses.replace(scene, extra_meshes=meshes)
    scene = resolve_pattern_tables(scene, source, base_dir)
    scene = expand_objects(scene, object_paths(scene, source, base_dir, allow_external_meshes))
    found = problems(scene)
    if found:
        raise SceneError(found[0], found)
    return scene


def loads_scene(raw: bytes | str, source: str = "<scene>", base_dir: Path | None = None,
                allow_external_meshes: bool = False) -> Scene:
    """Parse and validate scene text (TOML). Every failure is a :class:`SceneError`.

    ``base_dir`` is the folder relative mesh paths are resolved against (default: the current
    directory); meshes must lie inside it unless ``allow_external_meshes``. A UTF-8 byte-order
    mark is accepted.

    Parameters
    ----------
    raw : bytes or str
        The TOML text.
    source, base_dir, allow_external_meshes
        As :func:`parse_scene`.

    Returns
    -------
    Scene

    Raises
    ------
    SceneError
        Not TOML, or an invalid field (named).
    """
    data, sha256 = decode_toml(raw, source)
    return parse_scene(data, source, base_dir, sha256, allow_external_meshes)


def load_scene(path: str | Path, allow_external_meshes: bool = False) -> Scene:
    """Load and validate a scene file (TOML, parsed with the standard library's safe loader).

    Parameters
    ----------
    path : str or Path
        The scene file (TOML).
    allow_external_meshes : bool
        Accept mesh files outside the scene's folder.

    Returns
    -------
    Scene

    Raises
    ------
    SceneError
        A missing or unreadable file, not TOML, or an invalid field (named).

    Examples
    --------
    >>> scene = rtsgeom.load_scene("scenes/diewald2022.toml")
    """
    raw, base = read_scene_bytes(path)
    return loads_scene(raw, str(Path(path)), base, allow_external_meshes)


def check_scene_arg(scene, source: str) -> Scene:
    """A function's ``scene`` argument: a :class:`Scene`, else ``ParameterError`` saying how
    to make one (a path is the common mistake)."""
    if not isinstance(scene, Scene):
        hint = (": load it with rtsgeom.load_scene(path)" if isinstance(scene, (str, Path))
                else "")
        raise ParameterError(f"{source}: scene = {fmt(scene)}: must be a Scene{hint}")
    return scene
