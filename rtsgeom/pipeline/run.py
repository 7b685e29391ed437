"""The main job: a scene through the whole pipeline, and its matched results.

Scene -> Setup -> Paths -> RTS program (AoA synthesis + calibration) -> Echoes -> ADC cube
(+ noise) -> range-Doppler -> detections -> per-target match against the set-points.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import __version__
from .._lib.results import Result
from .._lib.util import one_blas_thread
from ..geometry import Setup, build_setup
from ..paths import Paths, compute_paths
from ..radar import AdcCube, Detections, RangeDoppler, process
from ..radar.frame import noise_power, simulate
from ..rts.channels import Echoes, RtsProgram, program_nearest
from ..errors import ParameterError
from ..scene import Scene, check_scene_arg
from ..scene.registry import AOA_MODES, PATH_METHODS
from ..scene.schema import check_arg
from ..radar.budget import link_budget, link_warnings, sheet_paths
from ..radar.link import radar_link
from ..rts.channels import EchoKind, setup_echoes
from .cells import shared_cell_warnings
from .info import scene_info
from .matching import associate_targets, match_targets, truth_twin
from .plan import plan_targets

MAX_SUMMARY_TARGETS = 12  # targets listed in a summary

__all__ = ["RunResult", "simulate", "run_scene", "match_targets", "associate_targets",
           "label_detections", "noise_power"]


@dataclass(frozen=True, repr=False)
class RunResult(Result):
    """One simulated frame of a scene and what the RuT detected (:func:`run_scene`).
    ``print(result)`` is a summary; ``to_dataframe()`` one row per target (set, detected,
    error); ``detections.to_dataframe()`` every detection; ``plot()`` the range-Doppler map.

    Attributes
    ----------
    scene : Scene
        The scene as run (with the ``aoa_mode`` override applied).
    setup : Setup
        Its built geometry.
    paths : Paths
        The propagation paths.
    program : RtsProgram
        The RTS programme: per channel the delay, Doppler shift and amplitude.
    echoes : Echoes
        The echoes the RuT receives.
    cube : AdcCube
        The frame's ADC samples.
    rd : RangeDoppler
        The range-Doppler maps.
    detections : Detections
        What the RuT detected.
    matches : list of dict
        Per target its set values, the matched detection and the error.
    calibration : dict
        The calibration record (front-end angles, gain corrections, pair calibrations).
    warnings : tuple of str
        The run's warnings.
    aoa_mode : str
        The amplitude mode used.
    link_budget : LinkBudget or None
        The frame's link budget (:mod:`rtsgeom.radar.budget`).
    truth_detections : Detections or None
        The truth twin's detections (None: not run).
    """

    scene: Scene
    setup: Setup
    paths: Paths
    program: RtsProgram
    echoes: Echoes
    cube: AdcCube
    rd: RangeDoppler
    detections: Detections
    matches: list[dict]
    calibration: dict = field(default_factory=dict)
    warnings: tuple[str, ...] = ()
    aoa_mode: str = "exact"  # the amplitude mode actually used
    link_budget: object = None  # rtsgeom.radar.budget.LinkBudget
    truth_detections: Detections | None = None  # the truth twin's (None: not run)

    def _summary(self):
        title = (f"{self.scene.name}: one frame, {len(self.scene.targets)} targets, "
                 f"{self.aoa_mode} amplitudes")
        rows = [("cube", f"{'x'.join(str(n) for n in self.cube.data.shape)} ADC samples"
                         + (f", {self.cube.clipped} CLIPPED" if self.cube.clipped else "")),
                ("detections", len(self.detections.range_m))]
        for m in self.matches[:MAX_SUMMARY_TARGETS]:
            e = m.get("error")
            rows.append((f"target {m['index']}", "not detected" if e is None else
                         f"error {e['range_m'] * 1e3:+.1f} mm, {e['velocity_mps']:+.3g} m/s, "
                         f"{e['angle_deg']:+.4f} deg"))
        if len(self.matches) > MAX_SUMMARY_TARGETS:
            rows.append(("...", f"{len(self.matches) - MAX_SUMMARY_TARGETS} more targets"))
        rows += [("warnings", f"{len(self.warnings)}: {self.warnings[0]}" if self.warnings
                  else "none")]
        return title, rows

    def _columns(self) -> dict:
        cols: dict = {"target": [m["index"] for m in self.matches]}
        for key in ("range_m", "velocity_mps", "angle_deg"):
            cols[f"set_{key}"] = [m["set"][key] for m in self.matches]
            cols[f"detected_{key}"] = [np.nan if m["detection"] is None
                                       else m["detection"][key] for m in self.matches]
            cols[f"error_{key}"] = [np.nan if m["error"] is None else m["error"][key]
                                    for m in self.matches]
        cols["snr_db"] = [np.nan if m["detection"] is None else m["detection"]["snr_db"]
                          for m in self.matches]
        return cols

    def plot(self, title: str = ""):
        """The range-Doppler map with the detections circled (as ``run`` writes it)."""
        from ..viz.figures import range_doppler_figure  # matplotlib: only for the figure
        det = self.detections
        return range_doppler_figure(self.rd.power_db, self.rd.range_m, self.rd.velocity_mps,
                                    detections=np.c_[det.range_m, det.velocity_mps],
                                    title=title or f"{self.scene.name}: range-Doppler map")


def label_detections(result: "RunResult", bins: float = 2.0) -> list[str]:
    """What each detection is, from what the simulation knows about its echoes: ``target N``
    (the detection matched to target N), ``cable ghost of target N`` (order k of its cable
    reflections), ``setup reflection`` (the sheet, the board), or ``unmatched``.

    Each echo's apparent position follows from the beat model (eq. 8): beat frequency
    ``S tau + f_D`` (range, wrapped at the unambiguous range) and Doppler ``f_D`` (velocity,
    wrapped at the unambiguous velocity). A detection takes the kind of the strongest echo
    within ``bins`` range and Doppler bins of it (cyclic distances).
    """
    from scipy.constants import c

    det, rd, echoes, radar = result.detections, result.rd, result.echoes, result.scene.radar
    labels = ["unmatched"] * len(det)
    if len(det) and len(echoes):
        dr = rd.range_m[1] - rd.range_m[0]
        dv = rd.velocity_mps[1] - rd.velocity_mps[0]
        span_r, span_v = dr * rd.range_m.size, dv * rd.velocity_mps.size
        beat = radar.slope_hz_per_s * echoes.tau_s.mean(axis=1) + echoes.doppler_hz
        e_r = beat * c / (2 * radar.slope_hz_per_s)
        e_v = echoes.doppler_hz * c / (2 * radar.f_c_hz)
        power = np.mean(np.abs(echoes.amplitude) ** 2, axis=1)

        def cyc(a, span):
            return np.abs((a + span / 2) % span - span / 2)
        near = ((cyc(det.range_m[:, None] - e_r[None, :], span_r) <= bins * dr)
                & (cyc(det.velocity_mps[:, None] - e_v[None, :], span_v) <= bins * dv))
        for j in range(len(det)):
            cand = np.flatnonzero(near[j])
            if cand.size == 0:
                continue
            e = cand[np.argmax(power[cand])]
            if echoes.kind[e] == EchoKind.SETUP:
                labels[j] = "setup reflection"
            elif echoes.kind[e] == EchoKind.GHOST:
                labels[j] = f"cable ghost of target {int(echoes.target[e])}"
            else:
                labels[j] = f"target {int(echoes.target[e])}"
    served: dict[int, list[int]] = {}
    for m in result.matches:  # the association decides which detection is the target itself
        j = m.get("detection_index")
        if j is not None:
            served.setdefault(j, []).append(m["index"])
    for j, ts in served.items():
        labels[j] = "target " + "+".join(map(str, sorted(ts)))
    for j, lab in enumerate(labels):  # a target's second detection is not the target
        if lab.startswith("target ") and not any(m.get("detection_index") == j
                                                 for m in result.matches):
            labels[j] = "unmatched"
    return labels


@one_blas_thread  # small products (the planner's models): BLAS threads cost more than they give
def run_scene(scene: Scene, paths_method: str = "exact", aoa_mode: str | None = None,
              progress=None, calibration: dict | None = None, truth: bool = True) -> RunResult:
    """Run the whole pipeline on ``scene``: geometry, paths, the RTS programme (calibrated
    where the mode synthesizes), one simulated frame, the RuT's processing and detections.

    Parameters
    ----------
    scene : Scene
        The scene (:func:`rtsgeom.load_scene`).
    paths_method : str
        The path solver (``rtsgeom.paths.PATH_METHODS``: ``exact`` by default).
    aoa_mode : str, optional
        Overrides the scene's ``rts.aoa_mode``: ``nearest`` puts each target on its nearest
        front end; the synthesis modes calibrate the front-end pairs first, or take them
        from ``calibration``. The override is validated like the scene's own mode
        (``Scene.evolve``: e.g. paper eq. 24's spacing rule for the synthesis modes), so it
        cannot bypass a rule the scene file must meet.
    progress : callable, optional
        Told each calibrated pair: ``progress(message)`` (a list's ``append`` keeps the
        messages), or ``progress.count(stage, done, total)`` where it has one
        (``rtsgeom._lib.util.tell``).
    calibration : dict, optional
        A calibration file's content (``json.load`` of ``calibration.json``,
        :func:`rtsgeom.calibration.file.load_calibration`) used instead of calibrating.
    truth : bool
        Also run the truth twin (:func:`truth_twin`: the same radar on the real targets)
        and add ``truth``, ``truth_status`` and ``vs_truth`` to every match.

    Returns
    -------
    RunResult
        The frame, its detections and each target's match.

    Raises
    ------
    ParameterError
        An argument outside its allowed values, naming it.
    SceneError
        A scene the mode cannot program (a set angle no pair reaches, a calibration file
        that does not fit the scene's front ends).
    CalibrationFailed
        A pair whose probes the calibration sweep never detects.
    """
    check_scene_arg(scene, "run_scene")
    check_arg(paths_method, "paths_method", "str", "run_scene", ParameterError,
              choices=tuple(PATH_METHODS))
    if aoa_mode is not None:
        check_arg(aoa_mode, "aoa_mode", "str", "run_scene", ParameterError,
                  choices=tuple(AOA_MODES))
    if calibration is not None and not isinstance(calibration, dict):
        raise ParameterError(f"run_scene: calibration = {type(calibration).__name__}: must be "
                             "a calibration file's content (a dict, json.load of "
                             "calibration.json)")
    if aoa_mode is not None and aoa_mode != scene.rts.aoa_mode:
        scene = scene.evolve(rts=scene.rts.evolve(aoa_mode=aoa_mode))
    setup = build_setup(scene)
    paths = compute_paths(setup, paths_method)
    mode = aoa_mode or scene.rts.aoa_mode
    cal_file, calibration = calibration, {}
    warnings: list[str] = []
    if mode == "nearest" or not scene.targets:
        program = program_nearest(scene, setup)
    else:
        program, calibration, warnings = plan_targets(setup, paths, mode, progress=progress,
                                                       calibration=cal_file)
    warnings = list(warnings) + shared_cell_warnings(setup, scene.targets)
    echoes, cube = simulate(setup, paths, program, scene.seed, scene.radar.snr_db)
    rd, det = process(cube)
    matches = match_targets(scene, det, rd, steering=cube.steering)
    truth_det = None
    if truth and scene.targets:
        truth_det, matches, _ = truth_twin(setup, scene.targets, echoes, matches)
    budget = _budget(scene, setup, echoes, program)
    if scene.radar.link is not None:
        warnings = list(warnings) + link_warnings(budget, scene.radar.cfar.threshold_db)
        if cube.clipped:
            warnings.append(f"link: the ADC clipped {cube.clipped} of {cube.data.size} samples "
                            "of this frame")
    return RunResult(scene, setup, paths, program, echoes, cube, rd, det, matches,
                     calibration, tuple(warnings), mode, budget, truth_det)


def _budget(scene: Scene, setup: Setup, echoes: Echoes, program: RtsProgram):
    """The run's link budget (rtsgeom.radar.link); the snr_db override's noise where it is set; with
    ``[radar.link]``, the sheet's echo estimated by physical optics where the paths carry no
    setup reflection."""
    est = None
    # the physical-optics sheet estimate costs ~1 s: only for a physical budget ([radar.link])
    if scene.radar.link is not None and not np.any(echoes.kind == EchoKind.SETUP):
        sp = sheet_paths(setup)
        est = setup_echoes(setup, sp) if sp is not None else None
    override = None
    if scene.radar.snr_db is not None:
        override = noise_power(echoes, scene.radar.snr_db)
        if scene.radar.link is None:  # relative echoes: scale the override like the link would
            rl = radar_link(scene.radar)
            override *= rl.tx_power_w * rl.tx_gain * rl.rx_gain
    return link_budget(scene, echoes, program, scene.radar.link is not None, override, est)


def summary(result: RunResult, paths_method: str) -> dict:
    """The content of ``summary.json`` (no timestamps: same seed -> same bytes)."""
    s, r, rut = result.scene, result.scene.radar, result.setup.rut
    info = scene_info(result.setup)
    return {
        "rtsgeom_version": __version__,
        "scene": s.name,
        "scene_sha256": s.sha256,
        "seed": s.seed,
        "paths": paths_method,
        "aoa_mode": result.aoa_mode,
        "radar": {
            "f_c_hz": r.f_c_hz, "bandwidth_hz": r.bandwidth_hz,
            "slope_hz_per_s": r.slope_hz_per_s, "adc_rate_hz": r.adc_rate_hz,
            "adc_start_s": r.adc_start_s, "samples_per_chirp": r.samples_per_chirp,
            "chirps_per_tx": r.chirps_per_tx, "chirp_repetition_s": r.chirp_repetition_s,
            "tx_order": list(rut.tx_order), "num_rx": rut.num_rx,
            "cube_layout": "[chirp_loop, virtual_channel (tx_slot * num_rx + rx), sample]",
            "range_resolution_m": r.range_resolution_m,
            "velocity_resolution_mps": r.velocity_resolution_mps,
            "snr_db": r.snr_db,
        },
        "far_field": info["far_field"],
        "front_ends": info["front_ends"],
        "calibration": result.calibration,
        "targets": [{k: v for k, v in m.items() if k != "detection_index"}
                    for m in result.matches],
        "link_budget": (result.link_budget.to_dict() if result.link_budget is not None
                        else None),
        "adc_clipped_samples": result.cube.clipped,
        "num_detections": len(result.detections),
        "num_echoes": len(result.echoes),
        "warnings": list(result.warnings),
    }
