"""The setup as built, from an :class:`~rtsgeom.identify.Identification`: the scene with the
estimates written in (:func:`identified_scene`, and into the scene file keeping its comments,
:func:`identified_scene_toml`), and a pair's calibration delay predicted without a sweep
(:func:`predicted_calibration`)."""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from .._lib.util import frozen
from ..geometry import Setup
from ..geometry.setup import build_setup
from ..paths import exact_paths
from .capture import capture_probe
from ..scene import FrontEndConfig, Scene
from ..scene.channels import RadarChannelsConfig
from .identification import Identification
from ..calibration.pair import pair_coherence
from ..calibration.probes import probe_angles
from ..geometry.frontends import front_ends
from ..scene import TargetConfig
from ..synthesis.model import ChannelModel

__all__ = ["identified_scene", "identified_scene_toml", "setup_of", "detected_angles",
           "PredictedCalibration", "predicted_calibration", "calibrate_from_identified"]


@dataclass(frozen=True)
class PredictedCalibration:
    """A pair's calibration delay predicted from an identified setup (no sweep);
    :meth:`to_dict` is ``rtsgeom calibrate --from-identified`` (JSON and calibration.json)."""

    pair: tuple[int, int]
    delta_tau_s: float  # the coherence point of the pair (s)
    probe_angles_rad: np.ndarray  # (P,) the probe angles the sweep would use

    def to_dict(self) -> dict:
        return {"pair": [int(q) for q in self.pair], "delta_tau_s": float(self.delta_tau_s),
                "probe_angles_deg": [float(a) for a in np.degrees(self.probe_angles_rad)],
                "method": "identified"}


def _has_field(name: str) -> bool:
    return name in {f.name for f in fields(FrontEndConfig)}


def identified_scene(ident: Identification) -> Scene:
    """The scene with its mounting fields (and channel gain/phase errors) set to the
    estimates, and with a joint fit the radar's ``[radar.channels]`` antenna gains and phases;
    parameters not identified keep the scene's values. Yaw only where the schema
    has a per-front-end ``yaw_offset_rad``."""
    scene = ident.scene
    fes = list(scene.rts.front_ends)
    for f in ident.fits:
        e, ok = f.estimate, [r is None for r in f.reasons]
        kw = {}
        for i, name in ((0, "radial_offset_m"), (1, "tangential_offset_m"),
                        (2, "height_offset_m")):
            if ok[i]:
                kw[name] = float(e[i])
        if ok[3] and _has_field("yaw_offset_rad"):
            kw["yaw_offset_rad"] = float(e[3])
        kw["gain_offset_db"] = float(e[5] * 20 / np.log(10))
        kw["phase_offset_rad"] = float(np.angle(np.exp(1j * e[6])))
        fes[f.index] = fes[f.index].evolve(**kw)
    scene = scene.evolve(rts=scene.rts.evolve(front_ends=tuple(fes)))
    if ident.radar is None:
        return scene
    return scene.evolve(radar=scene.radar.evolve(channels=_radar_channels(scene, ident.radar)))


def _radar_channels(scene: Scene, r) -> RadarChannelsConfig:
    """The scene's ``[radar.channels]`` with every antenna's gain and phase set to the joint
    fit's estimates (the references and the antennas that do not act keep the scene's: the
    fit holds them there)."""
    k = 20 / np.log(10)
    tx_lg, tx_ph, *_ = r.side("tx")
    rx_lg, rx_ph, *_ = r.side("rx")
    ch = scene.radar.channels or RadarChannelsConfig()
    return ch.evolve(tx_gain_db=tuple(float(x) for x in tx_lg * k),
                     tx_phase_rad=tuple(float(x) for x in tx_ph),
                     rx_gain_db=tuple(float(x) for x in rx_lg * k),
                     rx_phase_rad=tuple(float(x) for x in rx_ph))


def identified_scene_toml(scene_text: str, ident: Identification) -> str:
    """The scene file ``scene_text`` with each identified front end's fields replaced (the
    comments and everything else kept; tomlkit edits TOML in place, a hand-written writer would
    lose the file's comments)."""
    import tomlkit
    doc = tomlkit.parse(scene_text)
    new = identified_scene(ident)
    keys = [("radial_offset_m", "radial_offset_mm", 1e3),
            ("tangential_offset_m", "tangential_offset_mm", 1e3),
            ("height_offset_m", "height_offset_mm", 1e3),
            ("gain_offset_db", "gain_offset_db", 1.0),
            ("phase_offset_rad", "phase_offset_deg", 180 / np.pi)]
    if _has_field("yaw_offset_rad"):
        keys.append(("yaw_offset_rad", "yaw_offset_deg", 180 / np.pi))
    tables = doc["rts"]["front_ends"]
    owner = {"radial_offset_m": 0, "tangential_offset_m": 1, "height_offset_m": 2,
             "yaw_offset_rad": 3, "gain_offset_db": 5, "phase_offset_rad": 6}
    for f in ident.fits:
        cfg = new.rts.front_ends[f.index]
        for attr, key, unit in keys:
            if f.reasons[owner[attr]] is None:  # not identified: the scene's value stays
                tables[f.index][key] = round(float(getattr(cfg, attr)) * unit, 6)
    if ident.radar is not None:
        ch = new.radar.channels
        created = "channels" not in doc["radar"]
        if created:
            doc["radar"]["channels"] = tomlkit.table()
        table = doc["radar"]["channels"]
        for key, vals, unit in (("tx_gain_db", ch.tx_gain_db, 1.0),
                                ("tx_phase_deg", ch.tx_phase_rad, 180 / np.pi),
                                ("rx_gain_db", ch.rx_gain_db, 1.0),
                                ("rx_phase_deg", ch.rx_phase_rad, 180 / np.pi)):
            table[key] = [round(float(v) * unit, 6) for v in vals]
        if created:
            table.add(tomlkit.nl())
    doc["name"] = f"{new.name}-identified"
    return tomlkit.dumps(doc)


def setup_of(scene: Scene, yaw_rad=None) -> Setup:
    """``build_setup`` with per-front-end yaws ``yaw_rad`` (F,) where the scene has none."""
    setup = build_setup(scene)
    if yaw_rad is None:
        return setup
    return Setup(scene, setup.rut, front_ends(scene, setup.fe.arc_centre, yaw_rad=yaw_rad))


def detected_angles(setup: Setup, paths=None) -> np.ndarray:
    """Each front end alone as the RuT's beamformer sees it (noise-free phasor model at the
    calibration's probe range): what ``calibrate``'s amplitude step measures."""
    paths = exact_paths(setup) if paths is None else paths
    r, _ = capture_probe(setup)
    return np.array([float(ChannelModel.build(setup, paths, [q], TargetConfig(r))
                           .direction(np.ones(1))) for q in range(setup.fe.count)])


def predicted_calibration(setup: Setup, pair: tuple[int, int], alphas=None
                          ) -> PredictedCalibration:
    """The pair's calibration delay predicted from a setup *as identified* (no sweep): the
    coherence point (``calibration.pair.pair_coherence``) of the identified geometry and channel
    gains at the probes the sweep would use (``alphas``, default from :func:`detected_angles`)."""
    paths = exact_paths(setup)
    i, j = pair
    if alphas is None:
        ang = detected_angles(setup, paths)
        alphas = probe_angles(ang[i], ang[j])
    d = pair_coherence(setup, paths, (i, j), alphas=np.asarray(alphas)).continuous_s
    return PredictedCalibration((int(i), int(j)), float(d),
                                frozen(np.asarray(alphas, float)))


def calibrate_from_identified(scene: Scene, pair: tuple[int, int]) -> PredictedCalibration:
    """``rtsgeom calibrate --from-identified FILE``: the pair's calibration delay of a scene
    written by ``rtsgeom identify --out`` (its mounting fields and channel gain/phase errors
    hold the estimates), predicted without a sweep (:func:`predicted_calibration`)."""
    return predicted_calibration(setup_of(scene), tuple(pair))
