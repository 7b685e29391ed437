"""Scene-level conveniences for notebooks and scripts: each wraps one CLI job.

The functions here take a :class:`~rtsgeom.scene.scene.Scene` (and a front-end pair) and return the
library's own result objects; they add no physics. Import them from the package::

    import rtsgeom
    scene = rtsgeom.load_scene("scenes/diewald2022.toml")
    cal = rtsgeom.calibrate(scene, pair=(0, 1))
"""

from __future__ import annotations

import dataclasses
import difflib
from pathlib import Path

import numpy as np

from .analysis.calibration_study import CalibrationStudy
from .analysis.design_study import DesignStudy
from .analysis.ghosts import ghost_analysis
from .analysis.linearity import linearity as _linearity
from .analysis.linearity_study import LinearityStudy
from .analysis.nearfield import nearfield as _nearfield
from .analysis.playback import play as _play
from .analysis.tolerance import Bounds, MonteCarlo, ToleranceStudy
from .analysis.tolerance.config import check_sigma_mm, check_study_args
from .analysis.transfer import TransferStudy
from .calibration.probes import probe_front_ends
from .errors import ParameterError, SceneError
from .geometry import Setup, build_setup
from .paths import compute_paths, exact_paths
from .pipeline.plan import check_pair
from .scene import Scene, check_scene_arg
from .scene.registry import SYNTHESIS_MODES
from .scene.schema import check_arg, fmt, specs

__all__ = ["replace", "calibrate", "linearity", "tolerance", "design", "nearfield", "ghosts",
           "transfer", "show", "play", "kpi"]


def replace(obj, **changes):
    """A copy of a scene (or of one of its sections) with ``changes`` applied.

    A field is named as in Python, in SI units (``radial_offset_m=5e-4``, ``angle_rad``), or
    as in the scene file, in the file's units (``radial_offset_mm=0.5``, ``angle_deg``): the
    file's key converts by its declared unit (``scene.schema``), so both set the same field.
    Uses ``obj.evolve(**changes)`` where the object has it (validated again), else
    :func:`dataclasses.replace`. Errors name the key as written.

    Parameters
    ----------
    obj : Scene, RadarConfig, RtsConfig, FrontEndConfig, SheetConfig or TargetConfig
    **changes
        Fields to change: SI attribute names or the scene file's keys.

    Returns
    -------
    object
        A new object of ``obj``'s type (``obj`` itself is frozen and unchanged).

    Raises
    ------
    ParameterError
        An unknown key (with the nearest names), or one field given twice (by both names).
    SceneError
        A value outside its allowed range; the message starts with the key as written.

    Examples
    --------
    >>> fes = tuple(replace(f, radial_offset_mm=0.2) for f in scene.rts.front_ends)
    >>> scene = replace(scene, rts=replace(scene.rts, front_ends=fes))  # doctest: +SKIP
    """
    if not dataclasses.is_dataclass(obj) or isinstance(obj, type):
        raise ParameterError(f"replace: {type(obj).__name__} is not a scene or a scene section")
    names = {f.name for f in dataclasses.fields(obj) if f.init}
    by_key = {s.key: (name, s) for name, s in specs(type(obj))}
    fields, written = {}, {}  # attribute -> SI value, attribute -> (key, value) as written
    for key, value in changes.items():
        value = _tuples(value)
        if key in names:
            name, si = key, value
        elif key in by_key:
            name, s = by_key[key]
            si = s.to_si(value) if _is_number(value) else value
        else:
            near = difflib.get_close_matches(key, sorted(names | set(by_key)), n=3)
            hint = f"; did you mean {', '.join(near)}?" if near else ""
            raise ParameterError(
                f"replace: {type(obj).__name__} has no field {key!r}{hint} (Python's SI names "
                "such as radial_offset_m or the scene file's keys such as radial_offset_mm)")
        if name in fields:
            raise ParameterError(f"replace: {key} and {written[name][0]} set the same field "
                                 f"({name}); give one")
        fields[name], written[name] = si, (key, value)
    evolve = getattr(obj, "evolve", None)
    if not callable(evolve):
        return dataclasses.replace(obj, **fields)
    try:
        return evolve(**fields)
    except SceneError as exc:
        message = str(exc)
        if message.startswith("<evolve>: "):
            message = "replace: " + message[len("<evolve>: "):]
        for name, (key, value) in written.items():
            s = dict(specs(type(obj))).get(name)
            if s is not None and key != s.key and message.startswith(f"replace: {s.key} = "):
                # the check speaks the file's key and units: say which key was written
                head, tail = message[len("replace: "):].split(": ", 1)
                message = f"replace: {key} = {fmt(value)} (the scene file's {head}): {tail}"
        raise SceneError(message, exc.problems) from None


def _tuples(value):
    """A list (or a 1-D/2-D array) of numbers as the tuple a scene field holds: the reader
    turns the file's lists into tuples, and the re-check of a value set in code takes the
    same."""
    if isinstance(value, np.ndarray) and value.ndim in (1, 2) and value.dtype.kind in "iuf":
        value = value.tolist()
    if isinstance(value, list) and all(_is_number(v) or isinstance(v, (list, tuple))
                                       for v in value):
        out = tuple(_tuples(v) if isinstance(v, list) else v for v in value)
        return out if _is_number(out) else value
    return value


def _is_number(value) -> bool:
    """A number or a tuple of them (what a unit converts)."""
    if isinstance(value, bool):
        return False
    if isinstance(value, (int, float, np.number)):
        return True
    return isinstance(value, tuple) and all(_is_number(v) for v in value)


def _setup_paths(scene: Scene, fn: str):
    check_scene_arg(scene, fn)
    setup = build_setup(scene)
    return setup, exact_paths(setup)


def _check_pair(setup, pair) -> tuple[int, int]:
    if (not isinstance(pair, (tuple, list, np.ndarray)) or len(pair) != 2
            or not all(isinstance(p, (int, np.integer)) and not isinstance(p, bool)
                       for p in pair)):
        raise ParameterError(f"pair = {fmt(pair)}: must be two front-end indices (i, j)")
    i, j = (int(p) for p in pair)
    return check_pair(setup, i, j, f"pair {(i, j)}")


def calibrate(scene: Scene, pair=(0, 1)):
    """Calibrate a front-end pair by the paper's delay sweep on the simulated radar.

    Parameters
    ----------
    scene : Scene
        The setup; its seed drives the noise.
    pair : tuple of int
        Two adjacent front-end indices (0-based), channel J's delay is swept.

    Returns
    -------
    Calibration
        ``delta_tau_s``, ``residual_error_deg``, ``range_offset_m``, ``period_s`` (eq. 27) and
        the sweep (``sweep_delta_tau_s``, ``sweep_error_deg``); ``to_dict()`` gives the JSON of
        ``rtsgeom calibrate``.
    """
    check_scene_arg(scene, "calibrate")
    pair = _check_pair(_setup_paths(scene, "calibrate")[0], pair)
    return CalibrationStudy(pair)(scene).calibration


def _pair_setup(scene: Scene, pair, fn: str):
    """Setup, exact paths, the checked pair and each front end alone as the RuT detects it."""
    setup, paths = _setup_paths(scene, fn)
    pair = _check_pair(setup, pair)
    return setup, paths, pair, probe_front_ends(setup, paths, scene.seed)


def linearity(scene: Scene, pair=(0, 1), amplitudes: str = "exact", calibration=True,
              points: int = 21):
    """Synthesized-angle linearity across a pair's span on the simulated radar.

    Parameters
    ----------
    scene : Scene
    pair : tuple of int
        Two adjacent front-end indices (0-based).
    amplitudes : {'exact', 'array-factor', 'paper'}
        How the amplitude ratio of the two channels is designed (eqs. 21-23, or the exact model).
    calibration : bool or Calibration
        ``True``: run the phase calibration first (:func:`calibrate`); a
        :class:`~rtsgeom.calibration.sweep.Calibration` of this pair: use it (one calibration
        for several modes); ``False``: uncalibrated, delay offset 0.
    points : int
        Set-points across the span (its ends excluded).

    Returns
    -------
    Linearity
        ``set_deg``, ``detected_deg``, ``error_deg``, ``amplitude_db`` (2, points) and
        ``max_abs_error_deg``.
    """
    check_arg(amplitudes, "amplitudes", "str", "linearity", ParameterError,
              choices=SYNTHESIS_MODES)
    check_arg(points, "points", "int", "linearity", ParameterError, lo=3, hi=1001)
    if calibration is True or calibration is False or calibration is None:
        check_scene_arg(scene, "linearity")
        pair = _check_pair(build_setup(scene), pair)
        return LinearityStudy(pair, amplitudes, bool(calibration), points)(scene)
    setup, paths, pair, probe = _pair_setup(scene, pair, "linearity")
    cal = calibration
    if tuple(cal.pair) != pair:
        raise ParameterError(f"calibration is for pair {tuple(cal.pair)}, not {pair}")
    return _linearity(setup, paths, pair, amplitudes, probe, cal, points, scene.seed)


def tolerance(scene: Scene, pair=(0, 1), sigma_mm=(0.1, 0.1, 0.1), draws: int = 10_000,
              seed: int | None = None, distribution: str = "normal", spec_deg: float = 0.1,
              points: int = 21):
    """Mounting-tolerance Monte Carlo of a front-end pair (phasor level).

    Parameters
    ----------
    scene : Scene
    pair : tuple of int
        Two adjacent front-end indices (0-based).
    sigma_mm : sequence of 3 float
        Radial, tangential and height mounting error per front end in mm: the standard
        deviation (``normal``) or the bound (``uniform``).
    draws : int
        Number of drawn setups.
    seed : int, optional
        Random seed (default: the scene's seed); the same seed gives the same draws.
    distribution : {'normal', 'uniform'}
    spec_deg : float
        Angle-error spec for the yield.
    points : int
        Set-points across the span.

    Returns
    -------
    ToleranceResult
        ``worst_error_deg[case]`` per draw for ``'uncalibrated'`` and ``'calibrated'``,
        ``yield_(case)``, ``stats(case)`` and ``to_dict()``.

    Warns
    -----
    NominalSetupWarning
        The scene carries mounting, channel or RuT pose errors of its own: the draws start
        from the nominal setup, not from them.
    """
    check_scene_arg(scene, "tolerance")
    check_study_args("tolerance", draws=draws, seed=seed, distribution=distribution,
                     spec_deg=spec_deg, points=points)
    sigma = check_sigma_mm("tolerance", sigma_mm)
    _check_pair(build_setup(scene), pair)
    study = ToleranceStudy(Bounds(sigma), tuple(pair),
                           mc=MonteCarlo(draws, seed, distribution), spec_deg=spec_deg,
                           points=points)
    return study(scene).run


def design(scene: Scene, radius_m, spacing_deg, pair=(0, 1), *, spec_deg: float = 0.1,
           target_yield: float = 0.95, draws: int = 2000, seed: int | None = None,
           points: int = 21):
    """Arc design map: every (front-end spacing, arc radius) as a two-front-end variant.

    Parameters
    ----------
    scene : Scene
        The template (radar, sheet, RTS); the pair's centre angle is kept.
    radius_m : array_like
        Arc radii (m).
    spacing_deg : array_like
        Front-end spacings (deg).
    pair : tuple of int
        The front-end pair whose centre angle the designs keep.
    spec_deg, target_yield, draws, seed, points
        As for :func:`tolerance`; the tolerance per design is the sigma that keeps
        ``target_yield`` of the setups within ``spec_deg``.

    Returns
    -------
    DesignGrid
        ``metrics[name]`` (spacings, radii) arrays for each name in
        :data:`rtsgeom.analysis.design.METRICS`, ``exceeds_resolution`` and ``to_dict()``.
    """
    check_scene_arg(scene, "design")
    check_study_args("design", draws=draws, seed=seed, spec_deg=spec_deg, points=points)
    check_arg(target_yield, "target_yield", "float", "design", ParameterError, lo=0.0, hi=1.0,
              lo_open=True, hi_open=True)
    return DesignStudy(tuple(np.atleast_1d(radius_m)), tuple(np.atleast_1d(spacing_deg)), pair,
                       None, spec_deg, target_yield, MonteCarlo(draws, seed), points)(scene)


def nearfield(scene: Scene, radius_m=None, points: int = 11):
    """Near-field analysis versus arc radius (single-front-end bias, phase error, synthesis).

    Parameters
    ----------
    scene : Scene
    radius_m : array_like, optional
        Arc radii (m); default 13 radii over two decades around the scene's radius.
    points : int
        Synthesized set-points per pair.

    Returns
    -------
    NearField
    """
    check_scene_arg(scene, "nearfield")
    check_arg(points, "points", "int", "nearfield", ParameterError, lo=1, hi=201)
    return _nearfield(scene, radius_m, points)


def transfer(scene: Scene, radars: int = 100, sigma_phase_deg: float = 5.0,
             sigma_gain_db: float = 0.0, points: int = 11, spec_deg: float | None = None,
             seed: int | None = None):
    """Calibration transfer: every adjacent pair calibrated with the scene's radar (its
    ``[radar.channels]``), its synthesized targets measured by ``radars`` radars drawn with
    the stated per-antenna spreads (``analysis.transfer``).

    Parameters
    ----------
    scene : Scene
    radars : int
        Radars drawn.
    sigma_phase_deg, sigma_gain_db : float
        Spread of each Tx and Rx antenna's phase (deg) and gain (dB) error.
    points : int
        Set-points across each pair's span (its ends excluded).
    spec_deg : float, optional
        Angle spec (p95) for :meth:`Transfer.verdict`.
    seed : int, optional
        The draws' seed (default: the scene's).

    Returns
    -------
    Transfer
        ``error_deg`` (radars, points), ``compensated_error_deg``, ``own_error_deg``,
        ``golden_error_deg``, ``absorbed_deg``; ``to_dict()``, ``to_dataframe()``, ``plot()``.
    """
    setup, paths = _setup_paths(scene, "transfer")
    return TransferStudy(radars=radars, sigma_phase_deg=sigma_phase_deg,
                         sigma_gain_db=sigma_gain_db, points=points, spec_deg=spec_deg,
                         seed=scene.seed if seed is None else seed)(setup, paths)


def ghosts(scene: Scene, floor_db: float = -80.0, simulate: bool = False):
    """Predicted (and, with ``simulate``, simulated) cable-ghost ranges and levels.

    Parameters
    ----------
    scene : Scene
    floor_db : float
        Lowest ghost level relative to its target that is listed.
    simulate : bool
        Also run the signal chain and read each ghost in the range-Doppler map.

    Returns
    -------
    GhostReport
    """
    check_scene_arg(scene, "ghosts")
    check_arg(floor_db, "floor_db", "float", "ghosts", ParameterError, lo=-300.0, hi=-1.0,
              unit="dB")
    return ghost_analysis(scene, floor_db, simulate)


def show(scene_or_setup, paths=None, png: str | Path | None = None,
         window_size=(1600, 1000)):
    """Draw the setup in 3D (pyvista): to a PNG file, or as an image array.

    Parameters
    ----------
    scene_or_setup : Scene or Setup
    paths : Paths, {'exact', 'raytrace'} or None
        Propagation paths to draw (line of sight, and the reflections of ray tracing).
    png : path, optional
        Write an off-screen rendering there and return its path.
    window_size : (int, int)
        Image size in pixels.

    Returns
    -------
    pathlib.Path or numpy.ndarray
        The PNG's path, or the image (H, W, 3) uint8 when ``png`` is None.
    """
    from .viz.scene3d import render_setup_png, show_setup
    setup = scene_or_setup if isinstance(scene_or_setup, Setup) else build_setup(scene_or_setup)
    if isinstance(paths, str):
        paths = compute_paths(setup, paths, for_drawing=True)  # reflections with hit points
    if png is not None:
        return render_setup_png(setup, png, paths=paths, window_size=window_size)
    return show_setup(setup, paths=paths, interactive=False, window_size=window_size)


def play(scene: Scene, amplitudes: str | None = None, paths: str = "exact",
         baseline: bool = True, workers: int = 1, chain: str = "fast"):
    """Play the scene's ``[scenario]`` frame by frame (``rtsgeom play``).

    Parameters
    ----------
    scene : Scene
        With a ``[scenario]`` (moving targets; its ``[[targets]]`` stay static beside them).
    amplitudes : str, optional
        AoA mode (default: ``rts.aoa_mode``); ``'nearest'``: the switched baseline.
    paths : {'exact', 'raytrace'}
    baseline : bool
        Also play the switched baseline on the same drive (``result.baseline``).
    workers : int
        Forked processes for the frames (the same result for any number).
    chain : {'fast', 'full'}
        ``fast``: each frame's detections near its targets from the echoes' closed-form
        spectrum, the full chain for the frames outside it (``summary()['chain']`` counts
        them); ``full``: every frame through the ADC cube, FFTs and CFAR.

    Returns
    -------
    PlaybackResult
        ``summary()``, ``to_dataframe()`` (tracks), ``programme_dataframe()``, ``plot()``.
    """
    check_scene_arg(scene, "play")
    return _play(scene, amplitudes, paths, baseline, workers, chain=chain)


def kpi(scene: Scene, spec=None, sigma_mm=None, sigma_phase_deg: float | None = None,
        points: int = 11, draws: int = 2000, seed: int | None = None, progress=None):
    """The setup's datasheet (``rtsgeom kpi``): field of view, angle accuracy with its GUM
    budget validated by a Monte Carlo, range and velocity, targets, ghosts, near field,
    checked against ``spec`` (``analysis.kpi``).

    Parameters
    ----------
    scene : Scene
    spec : KpiSpec, str or Path, optional
        The spec (:func:`~rtsgeom.analysis.kpi.load_spec` reads a file).
    sigma_mm : float or sequence of 3 float, optional
        Mounting offsets' sigma (radial, tangential, height), mm; default 0.1.
    sigma_phase_deg : float, optional
        Each RuT antenna's phase spread, deg; default the RMS of ``[radar.channels]``' phases.
    points, draws, seed
        Set angles per pair, Monte Carlo draws per set angle, their seed (default the scene's).
    progress : callable, optional
        ``progress(label, done, total)``.

    Returns
    -------
    Datasheet
        ``to_dict()`` (the JSON of ``rtsgeom kpi``), ``checks``, ``passed``, ``plot()``,
        ``figures()``.
    """
    from .analysis.kpi import KpiStudy, load_spec
    if isinstance(spec, (str, Path)):
        spec = load_spec(spec)
    study = KpiStudy(sigma_mm=sigma_mm, sigma_phase_deg=sigma_phase_deg, points=points,
                     draws=draws, seed=seed, spec=spec)
    return study(scene, progress=progress)
