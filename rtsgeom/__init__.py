"""rtsgeom: radar target simulator (RTS) setups as geometry.

Pipeline (one direction; each stage a subpackage, every import pointing down this list)::

    scene/        Scene: the setup declared in a TOML file (fields, rules, presets)
    geometry/     Setup: the RuT's MIMO array, the front ends on their arc, the sheet
    paths/        Paths per element pair: exact distances, or Sionna RT's reflections
    viz/          figures (matplotlib), the 3D view (pyvista), the HTML report
    rts/          Echoes: the RTS channels' delays, Doppler, amplitudes, FIR, cable ghosts
    radar/        AdcCube -> RangeDoppler, Detections: FMCW synthesis, FFTs, CFAR, beamformer
    synthesis/    ChannelModel: the weights that put a target between front ends
    calibration/  Calibration: probes, the delay sweep, pairs and cells of channels
    pipeline/     the programme for the scene's targets and the main job (run_scene)
    identify/     a built setup measured from probe captures
    analysis/     tolerance, arc design, near field, linearity, ghosts
    api, cli/     the jobs as functions and as commands

The public API is importable from the package itself; the names load on first use (module
``__getattr__``, PEP 562), so ``import rtsgeom`` stays fast and Sionna or pyvista load only when
ray tracing or the 3D view is used::

    import rtsgeom
    scene = rtsgeom.load_scene("scenes/diewald2022.toml")
    result = rtsgeom.run_scene(scene)
    result.detections.to_dataframe()     # pandas.DataFrame
    result.rd.to_xarray()                # xarray.DataArray (range_m, velocity_mps)
"""

from __future__ import annotations

import importlib

__version__ = "0.1.0"

# public name -> (module, attribute), in pipeline order. Only what a script needs: the scene,
# each stage's typed result, the CLI jobs as functions (api.py) and the errors a user's input
# can cause; everything else is imported from its module.
_LAZY = {
    # scene file
    "Scene": (".scene.scene", "Scene"),
    "load_scene": (".scene.scene", "load_scene"),
    "loads_scene": (".scene.scene", "loads_scene"),
    "parse_scene": (".scene.scene", "parse_scene"),
    "replace": (".api", "replace"),
    # geometry and paths
    "Setup": (".geometry", "Setup"),
    "build_setup": (".geometry", "build_setup"),
    "Paths": (".paths", "Paths"),
    "exact_paths": (".paths", "exact_paths"),
    "raytrace_paths": (".paths.raytrace", "raytrace_paths"),
    # RTS channels and the signal chain
    "RtsProgram": (".rts.channels", "RtsProgram"),
    "Echoes": (".rts.channels", "Echoes"),
    "EchoKind": (".rts.channels", "EchoKind"),
    "run_scene": (".pipeline.run", "run_scene"),
    "RunResult": (".pipeline.run", "RunResult"),
    "write_run": (".pipeline.output", "write_run"),
    "AdcCube": (".radar.fmcw", "AdcCube"),
    "RangeDoppler": (".radar.processing", "RangeDoppler"),
    "Detections": (".radar.processing", "Detections"),
    "Steering": (".radar.steering", "Steering"),
    "range_angle_map": (".radar.processing", "range_angle_map"),
    "to_dca1000": (".radar.dca1000", "to_dca1000"),
    "from_dca1000": (".radar.dca1000", "from_dca1000"),
    # AoA synthesis
    "ChannelModel": (".synthesis.model", "ChannelModel"),
    "calibrate": (".api", "calibrate"),
    "CalibrationStudy": (".analysis.calibration_study", "CalibrationStudy"),
    "CalibrationReport": (".analysis.calibration_study", "CalibrationReport"),
    "calibrate_pair": (".calibration.pair", "calibrate_pair"),
    "probe_front_ends": (".calibration.probes", "probe_front_ends"),
    "Calibration": (".calibration.sweep", "Calibration"),
    "SweepConfig": (".calibration.sweep", "SweepConfig"),
    "linearity": (".api", "linearity"),
    "Linearity": (".analysis.linearity", "Linearity"),
    "LinearityStudy": (".analysis.linearity_study", "LinearityStudy"),
    "ArcLinearity": (".analysis.linearity_study", "ArcLinearity"),
    # analyses
    "tolerance": (".api", "tolerance"),
    "MonteCarlo": (".analysis.tolerance", "MonteCarlo"),
    "ToleranceStudy": (".analysis.tolerance", "ToleranceStudy"),
    "ToleranceReport": (".analysis.tolerance", "ToleranceReport"),
    "Bounds": (".analysis.tolerance", "Bounds"),
    "monte_carlo": (".analysis.tolerance", "monte_carlo"),
    "ChannelPhasors": (".analysis.tolerance", "ChannelPhasors"),
    "ToleranceResult": (".analysis.tolerance", "ToleranceResult"),
    "design": (".api", "design"),
    "DesignStudy": (".analysis.design_study", "DesignStudy"),
    "design_grid": (".analysis.design", "design_grid"),
    "DesignSpec": (".analysis.design", "DesignSpec"),
    "DesignGrid": (".analysis.design", "DesignGrid"),
    "nearfield": (".api", "nearfield"),
    "NearField": (".analysis.nearfield", "NearField"),
    "ghosts": (".api", "ghosts"),
    "GhostReport": (".analysis.ghosts", "GhostReport"),
    "transfer": (".api", "transfer"),
    "TransferStudy": (".analysis.transfer", "TransferStudy"),
    "Transfer": (".analysis.transfer", "Transfer"),
    "resolution": (".analysis.resolution", "resolution"),
    "ResolutionStudy": (".analysis.resolution", "ResolutionStudy"),
    "Resolution": (".analysis.resolution", "Resolution"),
    "object_design": (".analysis.object_design", "object_design"),
    "ObjectDesign": (".analysis.object_design", "ObjectDesign"),
    "ObjectDesignResult": (".analysis.object_design", "ObjectDesignResult"),
    "RadarChannelsConfig": (".scene.channels", "RadarChannelsConfig"),
    "identify": (".identify", None),  # the package, callable as identify(scene, captures)
    "Identification": (".identify", "Identification"),
    "play": (".api", "play"),
    "Playback": (".analysis.playback", "Playback"),
    "PlaybackResult": (".analysis.playback", "PlaybackResult"),
    "drive_tolerance": (".analysis.playback", "drive_tolerance"),
    "kpi": (".api", "kpi"),
    "KpiStudy": (".analysis.kpi", "KpiStudy"),
    "Datasheet": (".analysis.kpi", "Datasheet"),
    "KpiSpec": (".analysis.kpi", "KpiSpec"),
    "load_spec": (".analysis.kpi", "load_spec"),
    "loads_spec": (".analysis.kpi", "loads_spec"),
    # views
    "show": (".api", "show"),
    "render_setup_png": (".viz.scene3d", "render_setup_png"),
    "export_setup": (".geometry.export", "export_setup"),
    "scene_info": (".pipeline.info", "scene_info"),
    # errors a user's input can cause (rtsgeom.errors lists them all)
    "RtsgeomError": (".errors", "RtsgeomError"),
    "SceneError": (".scene.scene", "SceneError"),
    "ParameterError": (".errors", "ParameterError"),
    "CaptureError": (".errors", "CaptureError"),
    "OutputError": ("._lib.io", "OutputError"),
    "AngleUnreachable": (".synthesis.model", "AngleUnreachable"),
    "RaytraceUnavailable": (".paths.raytrace", "RaytraceUnavailable"),
    "VizError": (".viz.render_backend", "VizError"),
    # warnings (warnings.warn; the CLI prints them as "rtsgeom: warning: ...")
    "NominalSetupWarning": (".errors", "NominalSetupWarning"),
}

__all__ = ["__version__", *_LAZY]


def __getattr__(name: str):
    try:
        module, attr = _LAZY[name]
    except KeyError:
        raise AttributeError(f"module 'rtsgeom' has no attribute {name!r}") from None
    value = importlib.import_module(module, __name__)
    if attr is not None:
        value = getattr(value, attr)
    globals()[name] = value  # later look-ups skip __getattr__
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
