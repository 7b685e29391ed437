"""The link budget of a run or a scene (``summary.json``'s ``link_budget``, ``rtsgeom info``).

Split from :mod:`rtsgeom.radar.link` (the physics: radar equation, IF chain, noise, ADC, the RTS
channel), which re-exports these names; see there for the model.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.constants import c

from .link import (apply_radar_link, beat_hz, channel_noise_w, channel_table, dbm, if_response,
                   radar_link, thermal_noise_w)
from ..rts.channels import KIND_DIRECT, KIND_SETUP, Echoes, RtsProgram
from ..paths import exact_paths
from ..paths.table import Paths, RUT_TO_RUT
from ..rts.channels import build_echoes, program_nearest, setup_echoes
from .fmcw import beat_phase0
from .windows import window

__all__ = ["LinkBudget", "window_snr_loss", "link_budget", "link_warnings", "sheet_paths",
           "static_budget", "format_budget"]




def window_snr_loss(name: str, n: int) -> float:
    """SNR factor of a taper on a coherent sum of n samples: ``(sum w)^2 / (n sum w^2)``."""
    w = np.asarray(window(name, n), float)
    return float(w.sum() ** 2 / (n * np.sum(w ** 2)))


@dataclass(frozen=True)
class LinkBudget:
    """Link budget of a run (see :func:`link_budget`); ``to_dict`` is ``summary.json``'s."""

    modelled: bool
    noise_source: str
    noise_w: float  # per sample at the receiver input (thermal + RTS channels), before the IF
    quantisation_noise_w: float
    fft_gain_db: float
    radar: dict
    front_ends: list
    targets: list
    setup_echoes: list

    def to_dict(self) -> dict:
        """Plain JSON: a level that is not finite (no noise, no echo: -inf dBm) is None."""
        return _json_safe(self._raw_dict())

    def _raw_dict(self) -> dict:
        return {"modelled": self.modelled, "noise_source": self.noise_source,
                "noise_dbm_per_sample": float(dbm(self.noise_w)),
                "quantisation_noise_dbm": float(dbm(self.quantisation_noise_w)),
                "fft_gain_db": self.fft_gain_db, "radar": self.radar,
                "front_ends": self.front_ends, "targets": self.targets,
                "setup_echoes": self.setup_echoes}


def _json_safe(x):
    if isinstance(x, dict):
        return {k: _json_safe(v) for k, v in x.items()}
    if isinstance(x, list):
        return [_json_safe(v) for v in x]
    if isinstance(x, float) and not np.isfinite(x):
        return None
    return x


def _entry(p_in_w, h2, noise_w, nq, fs_w, gain_db) -> dict:
    """Levels of one echo: power at the ADC (referred to the receiver input, after the IF
    chain), SNR after the range and Doppler FFTs, margin to full scale."""
    p_adc = p_in_w * h2
    n = noise_w * h2 + nq
    with np.errstate(divide="ignore"):
        snr = 10 * np.log10(p_adc / n) + gain_db if n > 0 else float("inf")
    return {"adc_power_dbm": float(dbm(p_adc)), "if_response_db": float(10 * np.log10(h2)),
            "snr_after_fft_db": float(snr), "clip_margin_db": float(dbm(fs_w) - dbm(p_adc))}


def _noise(scene, program, link, setup, noise_override_w, modelled: bool,
           predict: bool) -> tuple[float, str, float, float]:
    """The noise per sample the budget uses and where it comes from: ``snr_db``'s override, or
    thermal ``k T0 F f_adc`` plus the RTS channels' noise; also both parts on their own."""
    radar = scene.radar
    n_th = thermal_noise_w(radar, link)
    n_ch = channel_noise_w(scene, program, link, setup) if len(program) else 0.0
    if noise_override_w is not None:
        return noise_override_w, ("snr_db override: fixed per-sample SNR of the strongest "
                                  "target echo (not the physical noise)"), n_th, n_ch
    src = "thermal k T0 F f_adc + RTS channel noise"
    if not modelled:
        src += (" (prediction: the scene has no [radar.link])" if predict else
                "; not in the signal (no [radar.link], no snr_db)")
    if predict and radar.snr_db is not None:  # info: what run will simulate instead
        src += (f"; the simulation's noise is radar.snr_db = {radar.snr_db:g} dB per sample "
                "for the strongest echo, not this")
    return n_th + n_ch, src, n_th, n_ch


def _target_rows(scene, raw: Echoes, e: Echoes, h2, f_b, levels) -> list[dict]:
    """One row per target: its direct echoes summed coherently over its channels per virtual
    channel (each with its beat's constant phase, :func:`rtsgeom.radar.fmcw.beat_phase0`, as
    the range-Doppler cell adds them: a synthesized target's channels reach the RuT over
    different air paths), power averaged over the virtual channels (None where it has no
    direct echo)."""
    targets = []
    phase = np.exp(1j * beat_phase0(e, scene.radar)) if len(e) else None
    for i, t in enumerate(scene.targets):
        sel = (raw.target == i) & (raw.kind == KIND_DIRECT)
        if not np.any(sel):
            targets.append({"index": i, "adc_power_dbm": None, "snr_after_fft_db": None,
                            "clip_margin_db": None})
            continue
        amp = (e.amplitude[sel] * phase[sel]).sum(axis=0)
        hh = float(np.mean(h2[sel]))
        ent = _entry(float(np.mean(np.abs(amp) ** 2)) / hh, hh, *levels)
        targets.append({"index": i, "range_m": t.range_m, "rcs_dbsm": t.rcs_dbsm,
                        "beat_hz": float(np.mean(f_b[sel])), **ent})
    return targets


def _setup_rows(scene, raw: Echoes, p_in, h2, f_b, link, levels,
                estimated_setup: Echoes | None) -> list[dict]:
    """One row per setup echo in the signal, then one per estimated echo not in it."""
    rows = []
    for j in np.flatnonzero(raw.kind == KIND_SETUP):
        ent = _entry(float(p_in[j]), float(h2[j]), *levels)
        rows.append({"index": len(rows), "range_m": float(np.mean(raw.tau_s[j]) * c / 2),
                     "beat_hz": float(np.mean(f_b[j])), "in_signal": True, **ent})
    if estimated_setup is not None and len(estimated_setup):
        est = apply_radar_link(estimated_setup, scene, link)
        fe_b = beat_hz(estimated_setup, scene.radar)
        hh = np.mean(np.abs(if_response(link, fe_b)) ** 2, axis=1)
        for j in range(len(est)):
            p = float(np.mean(np.abs(est.amplitude[j]) ** 2)) / hh[j]
            ent = _entry(p, float(hh[j]), *levels)
            rows.append({"index": len(rows), "range_m": float(np.mean(
                estimated_setup.tau_s[j]) * c / 2), "beat_hz": float(np.mean(fe_b[j])),
                "in_signal": False, "source": "sheet, physical-optics estimate", **ent})
    return rows


def _front_end_rows(scene, program: RtsProgram, link, setup) -> list[dict]:
    """One row per front end: the RuT's chirp at its ADC, its attenuations and each antenna's
    gain toward the other (scalar x pattern, dBi)."""
    if not len(scene.rts.front_ends):
        return []
    tab = channel_table(scene, program, link, setup)
    pg, (fe_rx_db, fe_tx_db) = tab["pattern_gains"], tab["fe_antenna_gain_dbi"]
    fes = []
    for q in range(len(scene.rts.front_ends)):
        rows = program.front_end == q
        fes.append({"index": q, "rut_chirp_at_adc_dbm": float(tab["input_dbm"][q]),
                    "adc_level_dbfs": float(tab["level_dbfs"][q]),
                    "max_attenuation_db": float(tab["max_attenuation_fe_db"][q]),
                    "attenuation_db": [float(a) for a in tab["attenuation_db"][rows]],
                    "rut_tx_gain_dbi": float(10 * np.log10(link.tx_gain * pg["rut_tx"][q])),
                    "rut_rx_gain_dbi": float(10 * np.log10(link.rx_gain * pg["rut_rx"][q])),
                    "fe_rx_gain_dbi": float(fe_rx_db + 10 * np.log10(pg["fe_rx"][q])),
                    "fe_tx_gain_dbi": float(fe_tx_db + 10 * np.log10(pg["fe_tx"][q]))})
    return fes


def _radar_row(link, n_th: float, n_ch: float) -> dict:
    """The radar's link values, in dBm, dBi and dB."""
    return {"tx_power_dbm": float(dbm(link.tx_power_w)),
            "tx_antenna_gain_dbi": float(10 * np.log10(link.tx_gain)),
            "rx_antenna_gain_dbi": float(10 * np.log10(link.rx_gain)),
            "noise_figure_db": float(10 * np.log10(link.noise_figure)),
            "if_highpass_hz": link.if_highpass_hz, "if_lowpass_hz": link.if_lowpass_hz,
            "adc_bits": link.adc_bits, "adc_full_scale_dbm": float(dbm(link.adc_full_scale_w)),
            "thermal_noise_dbm_per_sample": float(dbm(n_th)),
            "rts_noise_dbm_per_sample": float(dbm(n_ch)), "sources": link.sources}


def link_budget(scene, echoes: Echoes, program: RtsProgram, linked: bool,
                noise_override_w: float | None = None,
                estimated_setup: Echoes | None = None, predict: bool = False,
                setup=None) -> LinkBudget:
    """The budget per target (its direct echoes, summed coherently over its channels per
    virtual channel, power averaged over the virtual channels), per setup echo and per front
    end. ``echoes`` are the run's: already through :func:`apply_radar_link` when ``linked``
    (the scene has ``[radar.link]``), else relative ones that are taken through the preset's
    link here, so the budget is shown either way. ``noise_override_w``: ``snr_db``'s noise.
    ``estimated_setup``: relative setup echoes not in the signal (the sheet by
    :func:`sheet_paths` under ``--paths exact``), listed with ``"in_signal": false``.
    ``predict``: what a real RuT with these values would show (thermal noise and the ADC's
    quantisation even where the signal model has neither)."""
    radar = scene.radar
    link = radar_link(radar)
    raw = echoes
    e = echoes if linked else apply_radar_link(echoes, scene, link)
    # whether the scene models the link (``info`` passes relative echoes of a linked scene)
    modelled = linked or radar.link is not None
    f_b = beat_hz(raw, radar)
    # the IF response per echo (|H|^2 averaged over the virtual channels)
    h2 = np.mean(np.abs(if_response(link, f_b)) ** 2, axis=1) if len(raw) else np.zeros(0)
    with np.errstate(invalid="ignore", divide="ignore"):
        p_in = np.mean(np.abs(e.amplitude) ** 2, axis=1) / np.where(h2 > 0, h2, 1.0)
    noise, src, n_th, n_ch = _noise(scene, program, link, setup, noise_override_w, modelled,
                                    predict)
    nq = link.quantisation_noise_w if linked or predict else 0.0  # no ADC in the relative model
    gain_db = float(10 * np.log10(radar.samples_per_chirp * radar.chirps_per_tx
                                  * window_snr_loss(radar.range_window, radar.samples_per_chirp)
                                  * window_snr_loss(radar.doppler_window, radar.chirps_per_tx)))
    levels = (noise, nq, link.adc_full_scale_w, gain_db)  # _entry's noise, ADC and FFT gain
    targets = _target_rows(scene, raw, e, h2, f_b, levels)
    rows_setup = _setup_rows(scene, raw, p_in, h2, f_b, link, levels, estimated_setup)
    fes = _front_end_rows(scene, program, link, setup)
    return LinkBudget(modelled, src, float(noise), nq, gain_db, _radar_row(link, n_th, n_ch),
                      fes, targets, rows_setup)


def link_warnings(budget: LinkBudget, threshold_db: float) -> list[str]:
    """``run``'s warnings: an echo that clips the ADC, or one whose post-FFT SNR is below the
    CFAR threshold (below the noise for detection)."""
    out = []
    for kind, rows in (("target", budget.targets), ("setup echo", budget.setup_echoes)):
        for r in rows:
            if r.get("clip_margin_db") is None:
                continue
            if r["clip_margin_db"] < 0:
                out.append(f"link: {kind} {r['index']} clips the RuT's ADC by "
                           f"{-r['clip_margin_db']:.1f} dB ({r['adc_power_dbm']:.1f} dBm at "
                           f"full scale {budget.radar['adc_full_scale_dbm']:.1f} dBm)")
            if kind == "target" and r["snr_after_fft_db"] < threshold_db:
                out.append(f"link: target {r['index']} is {r['snr_after_fft_db']:.1f} dB above "
                           f"the noise after the FFTs, below the CFAR threshold "
                           f"{threshold_db:g} dB")
    return out


def sheet_paths(setup, step_m: float | None = None):
    """The sheet's specular echo per RuT Tx/Rx element pair as ``rut_to_rut`` path rows, by
    physical optics (:func:`rtsgeom.paths.crosscheck.po_sheet_response`, lambda/4 grid by
    default), for the budget when the exact paths carry no setup reflections. The delay is the
    path via the sheet point straight ahead of the pair's midpoint (the stationary point of a
    RuT near the arc centre); the gain is the PO response with that delay's phase removed."""
    # here: the physical-optics module imports scipy.optimize (~0.7 s), which `info` would pay
    from ..paths.crosscheck import po_sheet_response
    scene, rut = setup.scene, setup.rut
    if not scene.sheet.enabled:
        return None
    f = scene.radar.f_center_hz
    r0 = setup.fe.arc_radius_m + scene.sheet.radius_offset_m
    centre = np.asarray(setup.fe.arc_centre, float)
    step = step_m or c / f / 4
    rows = []
    for m in np.unique(rut.virtual_tx):
        for k in np.unique(rut.virtual_rx):
            a, b = rut.tx_world[m], rut.rx_world[k]
            mid = 0.5 * (a + b) - centre
            az = np.clip(np.arctan2(mid[0], mid[1]) if np.any(mid[:2]) else 0.0,
                         scene.sheet.angle_min_rad, scene.sheet.angle_max_rad)
            p = centre + r0 * np.array([np.sin(az), np.cos(az), 0.0])
            tau = (np.linalg.norm(a - p) + np.linalg.norm(b - p)) / c
            g = po_sheet_response(setup, a, b, f, step) * np.exp(2j * np.pi * f * tau)
            rows.append((m, k, tau, g))
    m, k, tau, g = (np.array(x) for x in zip(*rows))
    return Paths.build(front_end=np.full(m.size, -1), direction=np.full(m.size, RUT_TO_RUT),
                       rut_tx=m, rut_rx=k, delay_s=tau, gain=g, bounces=np.ones(m.size, int),
                       method="po", surfaces=np.full(m.size, "sheet"))


def static_budget(setup) -> LinkBudget:
    """The budget without a run (``rtsgeom info``): each target on its nearest front end over
    the exact paths, the sheet by physical optics, thermal noise (``snr_db`` ignored)."""
    scene = setup.scene
    program = program_nearest(scene, setup)
    echoes = build_echoes(setup, exact_paths(setup), program)
    est = None
    if scene.radar.link is not None:  # the sheet's physical-optics estimate costs ~1 s
        sp = sheet_paths(setup)
        est = setup_echoes(setup, sp) if sp is not None else None
    return link_budget(scene, echoes, program, False, None, est, predict=True, setup=setup)


def _f1(x) -> str:
    return "-" if x is None else f"{x:.1f}"


def format_budget(b: dict) -> list[str]:
    """Text lines of a budget dict (:meth:`LinkBudget.to_dict`) for ``rtsgeom info``."""
    r = b["radar"]
    lines = [f"link budget ({'modelled in the signal' if b['modelled'] else 'not modelled in the signal: no [radar.link]'}):",
             f"  RuT Tx {_f1(r['tx_power_dbm'])} dBm, antennas {_f1(r['tx_antenna_gain_dbi'])}/"
             f"{_f1(r['rx_antenna_gain_dbi'])} dBi, NF {_f1(r['noise_figure_db'])} dB, IF "
             f"HPF {r['if_highpass_hz'] / 1e3:.0f} kHz / LPF {r['if_lowpass_hz'] / 1e6:.2f} MHz, "
             f"ADC {r['adc_bits']} bit, full scale {_f1(r['adc_full_scale_dbm'])} dBm",
             f"  noise {_f1(b['noise_dbm_per_sample'])} dBm per sample ({b['noise_source']}), "
             f"quantisation {_f1(b['quantisation_noise_dbm'])} dBm, FFT gain "
             f"{_f1(b['fft_gain_db'])} dB"]
    for fe in b["front_ends"]:
        att = (f"attenuation {', '.join(_f1(a) for a in fe['attenuation_db'])} dB"
               if fe["attenuation_db"] else
               # info's budget puts each target on its nearest front end only (static_budget);
               # run's summary.json has the synthesis' attenuations on every front end it uses
               "no target on it in this budget (each target on its nearest front end: "
               "run's summary.json has the synthesis' attenuations)")
        lines.append(f"  front end {fe['index']}: RuT chirp at the back end's ADC "
                     f"{_f1(fe['rut_chirp_at_adc_dbm'])} dBm ({_f1(fe['adc_level_dbfs'])} dBFS), "
                     f"{att}; the back end attenuates at most {_f1(fe['max_attenuation_db'])} dB; "
                     f"antennas toward each other: RuT {_f1(fe.get('rut_tx_gain_dbi'))}/"
                     f"{_f1(fe.get('rut_rx_gain_dbi'))} dBi, front end "
                     f"{_f1(fe.get('fe_rx_gain_dbi'))}/{_f1(fe.get('fe_tx_gain_dbi'))} dBi")
    for kind, rows in (("target", b["targets"]), ("setup echo", b["setup_echoes"])):
        for t in rows:
            if t.get("adc_power_dbm") is None:
                continue
            lines.append(f"  {kind} {t['index']} ({t['range_m']:.2f} m): {_f1(t['adc_power_dbm'])} "
                         f"dBm at the ADC (IF {_f1(t['if_response_db'])} dB), SNR after the FFTs "
                         f"{_f1(t['snr_after_fft_db'])} dB, clip margin {_f1(t['clip_margin_db'])} dB"
                         + ("  CLIPS" if (t["clip_margin_db"] or 0) < 0 else ""))
    return lines
