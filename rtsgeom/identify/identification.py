"""The identification of a built setup: :func:`identify` (``rtsgeom identify``) fits every
captured front end alone (:func:`~rtsgeom.identify.fit.fit_front_end`) or, with
``radar_channels``, together with the radar's own antenna gains and phases
(:func:`~rtsgeom.identify.joint.identify_joint`); :class:`Identification` is the result."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._lib.results import Result
from ..geometry.setup import build_setup
from ..errors import CaptureError, ParameterError
from ..scene import Scene, check_scene_arg
from ..scene.schema import check_arg, fmt
from .capture import Capture
from .fit import RESIDUAL_LIMIT, FrontEndFit, check_fit, fit_front_end
from .joint import RadarChannelsFit, identify_joint
from .model import PARAMS, measure

__all__ = ["Identification", "identify", "MAX_CAPTURES", "noise_fingerprint"]


# the fitted parameters as shown: (PARAMS index, name with its unit, SI -> that unit)
SHOWN = ((0, "radial_offset_mm", 1e3), (1, "tangential_offset_mm", 1e3),
         (2, "height_offset_mm", 1e3), (3, "yaw_offset_deg", 180 / np.pi),
         (4, "delay_offset_ps", 1e12), (5, "gain_db", 20 / np.log(10)),
         (6, "phase_deg", 180 / np.pi))


@dataclass(frozen=True, repr=False)
class Identification(Result):
    """Every front end's fit; :meth:`to_dict` is ``rtsgeom identify --json``. ``print(ident)``
    is a summary; ``to_dataframe()`` one row per front end (each parameter and its std, NaN
    where not identifiable); ``plot()`` the mounting offsets with their 1-sigma bars.

    Attributes
    ----------
    scene : Scene
    fits : tuple of FrontEndFit
        One per front end identified.
    radar : RadarChannelsFit or None
    """

    scene: Scene
    fits: tuple[FrontEndFit, ...]
    radar: RadarChannelsFit | None = None  # the radar's antennas (identify_joint), or None

    def fit(self, q: int) -> FrontEndFit | None:
        return next((f for f in self.fits if f.index == q), None)

    def _summary(self):
        rows = []
        for f in self.fits:
            parts = [f"{short} {f.estimate[i] * k:.3g}+-{f.std[i] * k:.2g}"
                     for (i, _, k), short in zip(SHOWN[:4], ("r", "t", "h", "yaw"))
                     if f.reasons[i] is None]
            rows.append((f"front end {f.index}", (" ".join(parts) + " (mm, yaw deg)" if parts
                                                  else "nothing identifiable")
                         + f", residual {f.residual_rms:.2f}, {f.captures} captures"))
        return f"{self.scene.name}: {len(self.fits)} front ends identified", rows

    def _columns(self) -> dict:
        cols = {"front_end": [f.index for f in self.fits]}
        for i, name, k in SHOWN:
            ok = [f.reasons[i] is None for f in self.fits]
            cols[name] = [f.estimate[i] * k if o else np.nan for f, o in zip(self.fits, ok)]
            cols[name.rsplit("_", 1)[0] + "_std_" + name.rsplit("_", 1)[1]] = [
                f.std[i] * k if o else np.nan for f, o in zip(self.fits, ok)]
        cols["residual_rms"] = [f.residual_rms for f in self.fits]
        return cols

    def plot(self, title: str = ""):
        """Each front end's fitted radial, tangential and height offset (mm) with 1 sigma; with
        the radar's channels identified, a second panel: each antenna's phase error (deg)."""
        from ..viz.figures import STYLE, new_figure  # matplotlib: only for the figure
        import matplotlib as mpl
        cols = self._columns()
        with mpl.rc_context(STYLE):
            if self.radar is None:
                fig, ax = new_figure(figsize=(6.4, 3.6))
            else:
                fig, (ax, ax_r) = new_figure(figsize=(10.0, 3.8), ncols=2)
                self._plot_antennas(ax_r)
            q = np.asarray(cols["front_end"], float)
            for k, (_, name, _) in enumerate(SHOWN[:3]):
                std = name.rsplit("_", 1)[0] + "_std_mm"
                ax.errorbar(q + (k - 1) * 0.12, cols[name], yerr=cols[std], fmt="o",
                            capsize=3, label=name.replace("_offset_mm", ""))
            ax.axhline(0.0, color="0.4", linewidth=0.8)
            ax.set_xticks(q)
            ax.set_xlabel("front end")
            ax.set_ylabel("fitted offset (mm), 1 sigma bars")
            ax.legend(loc="best")
            what = "mounting offsets" if self.radar is None else "mounting and radar channels"
            head = title or f"{self.scene.name}: identified {what}"
            if self.radar is None:
                ax.set_title(head, parse_math=False)
            else:
                fig.suptitle(head, parse_math=False)
        return fig

    def _plot_antennas(self, ax) -> None:
        """The radar's antenna phase errors with 1 sigma (references and unseen antennas as
        open markers at the scene's value)."""
        r = self.radar
        labels, x = [], 0
        for side in ("tx", "rx"):
            _, ph, _, std, reasons = r.side(side)
            for a, (p, s, why) in enumerate(zip(ph, std, reasons)):
                fixed = why[1] is not None
                ax.errorbar([x], [np.degrees(p)], yerr=None if fixed else [np.degrees(s)],
                            fmt="o", mfc="none" if fixed else None, capsize=3,
                            color="0.5" if fixed else ("C0" if side == "tx" else "C1"))
                labels.append(f"{side.upper()}{a}" + ("*" if fixed else ""))
                x += 1
        ax.axhline(0.0, color="0.4", linewidth=0.8)
        ax.set_xticks(range(x), labels)
        ax.set_xlabel("antenna (* fixed: reference or unseen)")
        ax.set_ylabel("phase error rel. to the references (deg)")

    def to_dict(self) -> dict:
        out_fe, out_ch, keys = [], [], []

        def entry(f, i, unit, why, name):
            if f.reasons[i] is not None:
                why[name] = f.reasons[i]
                return None
            return {"value": float(f.estimate[i] * unit), "std": float(f.std[i] * unit)}

        for f in self.fits:
            why: dict = {}
            d = {"index": f.index}
            for i, name, unit in ((0, "radial_offset_mm", 1e3), (1, "tangential_offset_mm", 1e3),
                                  (2, "height_offset_mm", 1e3),
                                  (3, "yaw_offset_deg", 180 / np.pi)):
                d[name] = entry(f, i, unit, why, name)
            d["not_identifiable"] = why
            fr = [i for i in f.free if i < 4]
            d["correlations"] = [{"a": PARAMS[a], "b": PARAMS[b], "r": float(f.correlation[a, b])}
                                 for k, a in enumerate(f.free) for b in f.free[k + 1:]
                                 if (a in fr or b in fr) and abs(f.correlation[a, b]) > 0.5]
            d["residual_rms"] = f.residual_rms
            d["misfit"] = f.misfit
            d["captures"] = f.captures
            out_fe.append(d)
            why = {}
            ch = {"index": f.index, "front_end": f.index,
                  "delay_offset_s": entry(f, 4, 1.0, why, "delay_offset_s")}
            g = entry(f, 5, 20 / np.log(10), why, "gain_db")
            ch["gain_db"] = g
            ch["phase_deg"] = entry(f, 6, 180 / np.pi, why, "phase_deg")
            ch["not_identifiable"] = why
            out_ch.append(ch)
            keys.append(f.residual_rms)
        out = {"scene": self.scene.name, "front_ends": out_fe, "channels": out_ch,
                "residual_rms": float(np.sqrt(np.mean(np.square(keys)))) if keys else None,
                "residual_rms_unit": "measured noise std of one range-Doppler value",
                "residual_limit": RESIDUAL_LIMIT,
                "model_fits": all(f.misfit is None for f in self.fits)}
        if self.radar is not None:
            out["radar_channels"] = self.radar.to_dict()
        return out


#: captures one ``identify`` reads (each is reduced to its probe's bin as it is read); the CLI
#: and Python share it
MAX_CAPTURES = 1024
#: two captures whose noise agrees better than this (|cos| of :func:`noise_fingerprint`; two
#: independent recordings read about 1/sqrt(samples), 0.04 for 512) are one recording
SAME_RECORDING = 0.5


def noise_fingerprint(cap: Capture) -> np.ndarray:
    """The receiver noise of a capture, unit norm: virtual channel 0's chirps transformed at
    the Doppler bin farthest from both the probe's and zero Doppler (Hann-windowed, as the
    radar's range-Doppler map, where no echo leaks: ~-120 dB of the probe). Two files of one
    recording (a copy, the same cube as .bin and .npy, a scaled copy) share it to their
    quantisation; independent recordings do not, whatever they show."""
    from ..radar.windows import window
    x = np.asarray(cap.data)[:, 0, :].astype(complex)  # (L, N)
    top = np.max(np.abs(x))
    if top > 0 and np.isfinite(top):  # a capture scaled by 1e30 must not overflow |X|^2
        x = x / top
    n_l = x.shape[0]
    # the probe's Doppler bin (unshifted: 0 is zero Doppler)
    probe = int(np.argmax(np.sum(np.abs(np.fft.fft(x, axis=0)) ** 2, axis=1)))
    d = np.arange(n_l)

    def dist(k):
        return np.minimum(np.abs(d - k), n_l - np.abs(d - k))
    far = int(np.argmax(np.minimum(dist(probe), dist(0))))
    w = window("hann", n_l) * np.exp(-2j * np.pi * far * d / n_l)
    f = w @ x
    norm = np.linalg.norm(f)
    return f / norm if norm > 0 else f


def _check_captures(scene, captures, reference):
    """``identify``'s arguments: the scene, the captures (an iterable of :class:`Capture`,
    not a path or a string; read them with ``read_capture``) and the reference front end."""
    check_scene_arg(scene, "identify")
    if captures is None or isinstance(captures, (str, bytes, Path, Capture)) or not hasattr(
            captures, "__iter__"):
        raise ParameterError(f"identify: captures = {fmt(captures)}: must be a list (or an "
                             "iterable) of Capture (rtsgeom.identify.read_capture(path) reads "
                             "one)")
    if reference is not None:
        check_arg(reference, "reference", "int", "identify", ParameterError, lo=0, hi=10_000)


def _captures(captures):
    """Each capture checked as it arrives: a :class:`Capture`, at most :data:`MAX_CAPTURES`,
    no recording twice (:func:`noise_fingerprint`: a copy would count as independent
    evidence and shrink the standard deviations by sqrt(copies)). Only captures of one front
    end are compared: simulated captures of several front ends share their noise when made
    with one seed (``rtsgeom adc --active``), and are still independent measurements of
    different front ends."""
    if hasattr(captures, "__len__") and len(captures) > MAX_CAPTURES:
        raise ParameterError(f"identify: captures: {len(captures)}: must be at most "
                             f"{MAX_CAPTURES}")
    seen: list[tuple[int, str, np.ndarray]] = []
    for k, cap in enumerate(captures):
        if not isinstance(cap, Capture):
            raise ParameterError(f"identify: captures[{k}] = {fmt(cap)}: must be a Capture "
                                 "(rtsgeom.identify.read_capture(path) reads one)")
        if k >= MAX_CAPTURES:
            raise ParameterError(f"identify: captures: more than {MAX_CAPTURES}: must be at "
                                 f"most {MAX_CAPTURES}")
        f = noise_fingerprint(cap)
        for q, src, g in seen:
            if q == cap.active and f.shape == g.shape and abs(np.vdot(f, g)) > SAME_RECORDING:
                raise CaptureError(f"{cap.source}: the same recording as {src} (their receiver "
                                   f"noise agrees, |cos| {abs(np.vdot(f, g)):.3f}): must be an "
                                   "independent capture (a copy counts its noise twice)")
        seen.append((cap.active, cap.source, f))
        yield cap
    if not seen:
        raise ParameterError("identify: captures = []: must hold at least one capture")


def identify(scene: Scene, captures, accept_misfit: bool = False, radar_channels: bool = False,
             reference: int | None = None) -> Identification:
    """Fit the nominal ``scene``'s free parameters to probe ``captures`` (:class:`Capture`,
    any number per front end up to :data:`MAX_CAPTURES`, each an independent recording; the
    captures of one front end are fitted jointly). With
    ``radar_channels`` the radar's antenna gains and phases are fitted too, together with
    every front end (:func:`~rtsgeom.identify.joint.identify_joint`; ``reference``: the front
    end whose tangential offset fixes the array's phase ramp).

    ``captures`` may be a generator (``read_capture`` per file): each is reduced to its
    probe's bin when it arrives, so memory holds one cube at a time. Each capture is checked
    against the scene (:func:`~rtsgeom.identify.model.measure`) and each fit by
    :func:`check_fit`: a misfit raises ``CaptureError`` unless ``accept_misfit``, which keeps
    it flagged (``misfit`` in the JSON).

    Parameters
    ----------
    scene : Scene
        The nominal scene whose setup the captures were recorded on.
    captures : iterable of Capture
        The probe captures (a list, or a generator of ``read_capture``), at most
        :data:`MAX_CAPTURES`.
    accept_misfit : bool
        Keep a fit that fails :func:`check_fit`, flagged, instead of raising.
    radar_channels : bool
        Also fit the radar's antenna gains and phases, jointly with every front end.
    reference : int, optional
        With ``radar_channels``: the front end whose tangential offset fixes the array's
        phase ramp.

    Returns
    -------
    Identification
        Each front end's fit (mounting offsets, channel gain, phase and delay, their
        covariance) and, with ``radar_channels``, the radar's channels.

    Raises
    ------
    ParameterError
        No captures, more than :data:`MAX_CAPTURES`, an item that is not a capture, or an
        argument outside its allowed values.
    CaptureError
        A capture that does not fit the scene, the same recording twice, or a misfit
        (without ``accept_misfit``).
    """
    _check_captures(scene, captures, reference)
    accept_misfit = check_arg(accept_misfit, "accept_misfit", "bool", "identify",
                              ParameterError)
    radar_channels = check_arg(radar_channels, "radar_channels", "bool", "identify",
                               ParameterError)
    setup = build_setup(scene)
    groups: dict[int, list] = {}
    for cap in _captures(captures):
        groups.setdefault(cap.active, []).append(measure(setup, cap, not radar_channels))
        del cap
    if radar_channels:
        meas = [m for q in sorted(groups) for m in groups[q]]
        fits, radar = identify_joint(scene, meas, reference, accept_misfit)
        return Identification(scene, fits, radar)
    return Identification(scene, tuple(check_fit(fit_front_end(groups[q]), accept_misfit)
                                       for q in sorted(groups)))
