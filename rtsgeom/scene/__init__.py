"""The scene: a setup declared in a TOML file, read into typed, frozen, SI objects.

Every field is declared once (:mod:`.schema`), the rules between fields live in :mod:`.rules`,
the named choices in :mod:`.registry`, the radar presets in :mod:`.presets`, and
``docs/scene-format.md`` is generated from the declarations (``python -m rtsgeom.scene.docs``).
"""

from .hardware import ArrayConfig, PatternConfig
from .scene import Scene, check_scene_arg, load_scene, loads_scene, parse_scene
from ..errors import SceneError
from .sections import (CfarConfig, FrontEndConfig, RadarConfig, RaytraceConfig, RtsConfig,
                       SheetConfig, StructureConfig, TargetConfig)

__all__ = ["Scene", "SceneError", "check_scene_arg", "RadarConfig", "CfarConfig", "FrontEndConfig", "RtsConfig",
           "SheetConfig", "TargetConfig", "RaytraceConfig", "PatternConfig", "ArrayConfig",
           "StructureConfig", "load_scene", "loads_scene", "parse_scene"]
