"""Probe captures: one RTS front end active alone with a probe target, as the RuT records it
(the raw ADC cube), and its files (``rtsgeom adc --active I``: DCA1000 ``.bin`` or ``.npy``
plus a sidecar ``FILE.json`` recording the active front end and the probe), the input of
``rtsgeom.identify``."""

from __future__ import annotations

import dataclasses
import json
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.constants import c

from ..errors import CaptureError
from ..scene import RadarConfig
from ..scene.schema import REQUIRED, Spec, check_record, specs
from ..geometry import Setup
from ..paths import exact_paths
from ..rts.channels import RtsProgram, nominal_link_gain, requested_delay, target_amplitude
from ..radar.frame import simulate
from .._lib.io import atomic_path, write_bytes, write_json
from ..calibration.probes import probe_ranges
from ..radar.dca1000 import dca1000_bytes, dca1000_meta, from_dca1000, to_dca1000
from ..scene.presets import LAYOUT_DEFAULT, PRESETS, CaptureLayout
from ..radar.fmcw import AdcCube

__all__ = ["Capture", "capture_probe", "simulate_capture", "write_capture", "read_capture",
           "SIDECAR", "SIDECAR_DCA1000", "RADAR_KEYS", "MAX_CAPTURE_BYTES", "radar_record",
           "check_capture_radar", "sidecar_layout"]


#: the radar fields a capture records and ``identify`` compares with the scene's (a capture made
#: with another chirp or carrier reads as a silently wrong phase: 0.5 GHz of f_c turned a
#: channel's phase by 121 deg at a residual of 1.06 x noise)
RADAR_KEYS = ("f_c_hz", "bandwidth_hz", "chirp_duration_s", "chirp_repetition_s",
              "samples_per_chirp", "adc_rate_hz", "adc_start_s", "chirps_per_tx")
#: the largest capture read without a scene to size it by (bytes); with one, its exact size
MAX_CAPTURE_BYTES = 4 << 30
MAX_SIDECAR_BYTES = 1 << 20


#: a capture's sidecar, declared like the scene's fields (``scene.schema``): ranges, kinds,
#: sizes; the DCA1000 fields only for a ``.bin`` capture
SIDECAR = {
    "active_front_end": Spec("active_front_end", "int", "the front end alone on the probe",
                             lo=0, hi=10_000),
    "probe_range_m": Spec("probe_range_m", "float", "the probe's range", unit="m", lo=0.0,
                          hi=1e4, lo_open=True),
    "probe_velocity_mps": Spec("probe_velocity_mps", "float", "the probe's radial velocity",
                               unit="m/s", lo=-1e3, hi=1e3),
    "probe_amplitude": Spec("probe_amplitude", "float", "programmed amplitude of the probe's "
                            "channel", lo=0.0, hi=1e12, lo_open=True),
    "rts_delay_s": Spec("rts_delay_s", "float", "the delay programmed into the probe's RTS "
                        "channel (requested, before the RTS's delay quantisation); absent: the "
                        "scene's for probe_range_m", unit="s", lo=-1e-3, hi=1e-3, default=None),
    "kind": Spec("kind", "str", "what the file is", choices=("rtsgeom-probe-capture",),
                 default=None),
    "shape": Spec("shape", "ints", "the cube's [loop, virtual, sample]", lo=1, hi=1 << 20,
                  min_items=3, max_items=3, default=None),
    "tx_order": Spec("tx_order", "ints", "Tx per TDM slot", lo=0, hi=63, min_items=1,
                     max_items=64, default=None),
}
SIDECAR_DCA1000 = {
    "num_rx": Spec("num_rx", "int", "receivers", lo=1, hi=64),
    "samples_per_chirp": Spec("samples_per_chirp", "int", "samples per chirp", lo=16,
                              hi=8192),
    "chirps": Spec("chirps", "int", "chirps in the file", lo=1, hi=4096 * 64),
    "tx_order": Spec("tx_order", "ints", "Tx per TDM slot", lo=0, hi=63, min_items=1,
                     max_items=64),
    "scale": Spec("scale", "float", "int16 counts per capture unit", lo=1e-30, hi=1e30),
    "adc": Spec("adc", "str", "the ADC's samples (the board's layout)",
                choices=("complex", "real"), default=None),
    "lvds_lanes": Spec("lvds_lanes", "int", "the LVDS data lanes of the layout", lo=2, hi=4,
                       default=None),
    "format": Spec("format", "str", "the layout's name, dca1000-FAMILY-ADC-NLANElane",
                   default=None),
}


def _radar_fields() -> dict:
    """The scene's own declarations of :data:`RADAR_KEYS` (optional in a sidecar: captures
    written before they were recorded have none)."""
    own = dict((s.key, s) for _, s in specs(RadarConfig))
    return {k: dataclasses.replace(own[k], default=None) for k in RADAR_KEYS}


@dataclass(frozen=True)
class Capture:
    """One front end active alone with a probe target: the raw ADC cube and what it was."""

    data: np.ndarray  # (L, V, N) complex, [chirp loop, virtual channel, sample]
    active: int
    range_m: float
    velocity_mps: float
    amplitude: float  # programmed amplitude of the probe's channel
    radar: dict | None = None  # RADAR_KEYS of the radar that recorded it (None: not recorded)
    source: str = "capture"  # what messages call it (its file)
    tx_order: tuple[int, ...] | None = None  # the TDM order it was recorded in (None: the scene's)
    adc: str = "complex"  # "real": a real-only receiver's samples (imaginary part 0)
    rts_delay_s: float | None = None  # the RTS channel's programmed delay (None: the scene's)

    def __repr__(self) -> str:
        shape = "x".join(str(n) for n in np.shape(self.data))
        return (f"Capture({self.source!r}, front end {self.active}, probe {self.range_m:g} m "
                f"{self.velocity_mps:+g} m/s, {shape} {np.asarray(self.data).dtype}"
                f"{'' if self.radar is not None else ', no radar record'})")

    def to_meta(self) -> dict:
        meta = {"active_front_end": self.active, "probe_range_m": self.range_m,
                "probe_velocity_mps": self.velocity_mps, "probe_amplitude": self.amplitude}
        if self.rts_delay_s is not None:
            meta["rts_delay_s"] = self.rts_delay_s
        if self.radar is not None:
            meta["radar"] = dict(self.radar)
        return meta


def radar_record(radar) -> dict:
    """:data:`RADAR_KEYS` of a scene's ``RadarConfig`` in the scene file's units."""
    return {k: getattr(radar, k) for k in RADAR_KEYS}


def check_capture_radar(cap: Capture, radar) -> None:
    """A capture's recorded radar against the scene's (relative 1e-6): raise naming the first
    field that differs or is missing. The record is required: what the capture itself shows
    of the radar is checked too (its shape, the probe's range and Doppler in its own
    spectrum), but not the carrier: a static probe's echo is the same tone at any f_c, and
    the carrier's phase over the RTS's air path (f_c tau_air, 3.3 turns for 0.5 GHz at 1 m)
    is a common phase the channel phase takes up (a 76.5 GHz capture without the record read
    a channel phase 121 deg off at residual 1.03)."""
    if cap.radar is None:
        raise CaptureError(
            f"{cap.source}: radar is missing (required): the sidecar must record the radar "
            f"that made the capture ({', '.join(RADAR_KEYS)}; rtsgeom adc --active writes "
            "it): the carrier does not show in a static probe's capture, only in its "
            "channel phase; for a capture made with the scene's radar, copy the scene's "
            "[radar] values")
    for k in RADAR_KEYS:
        have, want = cap.radar.get(k), getattr(radar, k)
        if have is None:
            raise CaptureError(f"{cap.source}: radar.{k} is missing (required): must be the "
                               f"radar's that made the capture (the scene's is {want:g})")
        if not abs(have - want) <= 1e-6 * abs(want):
            raise CaptureError(f"{cap.source}: radar.{k} = {have:g}: must be the scene's "
                               f"{want:g} (the capture was recorded with another radar "
                               "configuration; identify it against a scene with that radar)")


def capture_probe(setup: Setup, range_m: float | None = None) -> tuple[float, float]:
    """Default probe (range, programmed amplitude): the calibration's first probe range and the
    amplitude that gives a 10 m^2 target (what :class:`~rtsgeom.synthesis.model.ChannelModel` programs)."""
    scene = setup.scene
    r = float(probe_ranges(setup, 1)[0]) if range_m is None else float(range_m)
    if not 0 < r < scene.radar.max_range_m:  # before the amplitude: 1/r^2 at r = 0
        raise CaptureError(f"probe range {r:g} m: must be in (0, {scene.radar.max_range_m:g}) m")
    lam = setup.rut.wavelength_m
    return r, float(target_amplitude(r, 10.0, lam) / nominal_link_gain(scene, lam))


def simulate_capture(setup: Setup, active: int, range_m: float | None = None,
                     velocity_mps: float = 0.0, seed=None, paths=None) -> Capture:
    """The ADC cube the RuT records with front end ``active`` alone on a probe target (receiver
    noise at the scene's SNR from ``seed``), on the setup *as built*."""
    n = setup.fe.count
    if not 0 <= active < n:
        raise CaptureError(f"active front end {active}: must be in 0..{n - 1}")
    scene = setup.scene
    r, amp = capture_probe(setup, range_m)
    paths = exact_paths(setup) if paths is None else paths
    f_d = 2 * scene.radar.f_c_hz * velocity_mps / c
    tau = float(requested_delay(scene, r))
    prog = RtsProgram.build([0], [active], [tau], [f_d], [amp])
    _, cube = simulate(setup, paths, prog, seed, scene.radar.snr_db)
    return Capture(cube.data, int(active), r, float(velocity_mps), amp,
                   radar_record(scene.radar), rts_delay_s=tau)


def write_capture(cap: Capture, rut, out: Path, fmt: str,
                  layout: CaptureLayout | None = None) -> dict:
    """Write ``cap`` as ``.npy`` or DCA1000 ``.bin``; the sidecar ``out.json`` (both formats)
    records the probe and the active front end. Returns the sidecar's content.

    ``layout``: the DCA1000 layout of the board (default: the preset's that ``rut`` was built
    from, :attr:`~rtsgeom.scene.presets.ArrayPreset.capture`); the sidecar states it
    (``format``, ``adc``, ``lvds_lanes``). A real-only layout writes the real part, the real
    IF signal such a receiver samples."""
    if layout is None:
        p = PRESETS.get(getattr(rut, "name", None))
        layout = LAYOUT_DEFAULT if p is None else p.capture
    n_l, n_v, n_s = cap.data.shape
    meta = {"kind": "rtsgeom-probe-capture", **cap.to_meta(), "shape": [n_l, n_v, n_s]}
    if fmt == "npy":
        with atomic_path(out) as tmp, open(tmp, "wb") as fh:
            np.save(fh, cap.data)
        meta["format"] = "npy"
    else:
        raw, scale = to_dca1000(AdcCube(cap.data, None, rut), layout)
        write_bytes(out, raw)
        meta.update(dca1000_meta(layout, scale, n_l * len(rut.tx_order), rut, n_s))
    write_json(Path(str(out) + ".json"), meta)
    return meta


_FORMAT = re.compile(r"^dca1000-([a-z0-9]+)-(complex|real)-([24])lane$")


def sidecar_layout(v: dict, side) -> CaptureLayout:
    """The DCA1000 layout a checked sidecar states: ``adc`` and ``lvds_lanes``, else what
    its ``format`` name says; a sidecar with neither is the xWR18xx complex 2-lane layout
    (captures written before the layout was recorded). ``format`` and the fields must agree."""
    name = v.get("format")
    parsed = _FORMAT.match(name) if name is not None else None
    if name is not None and parsed is None:
        raise CaptureError(f"{side}: format = {name!r}: must be a DCA1000 layout "
                           "dca1000-FAMILY-complex|real-2lane|4lane (e.g. "
                           f"{LAYOUT_DEFAULT.name}) for a .bin capture")
    adc = v.get("adc") or (parsed.group(2) if parsed else LAYOUT_DEFAULT.adc)
    lanes = v.get("lvds_lanes") or (int(parsed.group(3)) if parsed else LAYOUT_DEFAULT.lanes)
    if lanes not in (2, 4):
        raise CaptureError(f"{side}: lvds_lanes = {lanes}: must be 2 or 4 (the DCA1000's "
                           "layouts)")
    if parsed and (parsed.group(2), int(parsed.group(3))) != (adc, lanes):
        raise CaptureError(f"{side}: format = {name!r}: must agree with adc = {adc!r} and "
                           f"lvds_lanes = {lanes}")
    family = parsed.group(1) if parsed else LAYOUT_DEFAULT.family
    return CaptureLayout(family, adc == "complex", lanes, f"the sidecar {side}")


def _read_sidecar(side: Path) -> dict:
    """The sidecar's JSON, bounded: size, nesting and integer length errors become the
    capture's error instead of a RecursionError or a huge allocation."""
    if side.stat().st_size > MAX_SIDECAR_BYTES:
        raise CaptureError(f"{side}: {side.stat().st_size} bytes: must be a sidecar of at most "
                           f"{MAX_SIDECAR_BYTES} bytes")
    try:
        return json.loads(side.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError, ValueError) as exc:
        raise CaptureError(f"{side}: not JSON ({str(exc)[:120]})") from None
    except RecursionError:
        raise CaptureError(f"{side}: not a probe capture's sidecar (JSON nested too deeply)") \
            from None


def _npy_header(path: Path, shape, max_bytes: int) -> None:
    """Refuse a ``.npy`` whose header promises another shape or more than ``max_bytes``
    before numpy allocates it."""
    try:
        with open(path, "rb") as fh:
            version = np.lib.format.read_magic(fh)
            read = (np.lib.format.read_array_header_1_0 if version == (1, 0)
                    else np.lib.format.read_array_header_2_0)
            got, _, dtype = read(fh, max_header_size=10_000)
    except (ValueError, OSError, EOFError, SyntaxError) as exc:
        raise CaptureError(f"{path}: not a .npy array ({str(exc)[:120]})") from None
    if len(got) != 3 or dtype.kind != "c":
        raise CaptureError(f"{path}: expected a complex [loop, virtual, sample] cube, got "
                           f"{dtype} {list(got)}")
    if shape is not None and tuple(got) != tuple(shape):
        raise CaptureError(f"{path}: shape {list(got)}: must be the scene's radar "
                           f"{list(shape)} [loop, virtual, sample]")
    nbytes = int(np.prod(got, dtype=object)) * dtype.itemsize
    if nbytes > max_bytes:
        raise CaptureError(f"{path}: shape {list(got)} ({nbytes / 2**30:.3g} GiB): must be at "
                           f"most {max_bytes / 2**30:.3g} GiB")


def _read_dca1000(path: Path, side: Path, v: dict, shape, max_bytes: int
                  ) -> tuple[np.ndarray, str]:
    """A ``.bin`` capture in the layout its checked sidecar ``v`` states: (cube in capture
    units, ``"complex"`` or ``"real"``); its size checked against the sidecar and the scene's
    ``shape`` before it is read."""
    n_rx, n_s, chirps = v["num_rx"], v["samples_per_chirp"], v["chirps"]
    n_tx = len(v["tx_order"])
    if chirps % n_tx:
        raise CaptureError(f"{side}: chirps = {chirps}: must be a multiple of the "
                           f"{n_tx} TDM slots of tx_order")
    got = (chirps // n_tx, n_tx * n_rx, n_s)
    if shape is not None and got != tuple(shape):
        raise CaptureError(f"{side}: chirps, tx_order, num_rx, samples_per_chirp "
                           f"describe {list(got)}: must be the scene's radar "
                           f"{list(shape)} [loop, virtual, sample]")
    layout = sidecar_layout(v, side)
    want = dca1000_bytes(chirps, n_rx, n_s, layout)
    cube = chirps * n_rx * n_s * 8  # decoded as complex64
    if cube > max_bytes:
        raise CaptureError(f"{side}: {list(got)} ({cube / 2**30:.3g} GiB): must be "
                           f"at most {max_bytes / 2**30:.3g} GiB")
    if path.stat().st_size != want:
        raise CaptureError(f"{path}: {path.stat().st_size} bytes: must be the "
                           f"{want} bytes its sidecar describes ({layout.name})")
    raw = from_dca1000(path.read_bytes(), chirps, n_rx, n_s, layout)
    return raw.reshape(got) / np.float32(v["scale"]), layout.adc


def read_capture(path, shape=None, max_bytes: int = MAX_CAPTURE_BYTES) -> Capture:
    """Read a probe capture written by ``rtsgeom adc --active`` (``.bin`` or ``.npy`` with its
    sidecar ``PATH.json``). Errors name the file and the field (:data:`SIDECAR`).

    ``shape``: the cube the scene's radar records, (loops, virtual, samples); a file of
    another size is refused before it is read, so memory stays what the scene needs. Without
    it a capture larger than ``max_bytes`` is refused."""
    path = Path(path)
    side = Path(str(path) + ".json")
    if not path.is_file():
        what = ("a folder" if path.is_dir() else "not a regular file (a FIFO, socket or "
                "device)" if path.exists() else "no such file")
        raise CaptureError(f"{path}: {what}: must be a capture file (.bin or .npy with its "
                           "sidecar FILE.json)")
    if not side.is_file():
        raise CaptureError(f"{path}: no sidecar {side.name} (write captures with rtsgeom adc "
                           "--active I)")
    meta = _read_sidecar(side)
    if not isinstance(meta, dict):
        raise CaptureError(f"{side}: not a probe capture's sidecar (a JSON object)")
    npy = meta.get("format") == "npy" or path.suffix == ".npy"
    for key in [k for k, d in {**SIDECAR, **({} if npy else SIDECAR_DCA1000)}.items()
                if d.default is REQUIRED]:
        if key not in meta:
            raise CaptureError(f"{side}: no {key!r}: not a probe capture (rtsgeom adc "
                               "--active I)")
    v = check_record({**SIDECAR, **({} if npy else SIDECAR_DCA1000)}, meta, str(side),
                     CaptureError)
    radar = None
    if meta.get("radar") is not None:
        radar = check_record(_radar_fields(), meta["radar"], str(side), CaptureError,
                             where="radar")
    probe = (v["active_front_end"], v["probe_range_m"], v["probe_velocity_mps"],
             v["probe_amplitude"])
    adc = "complex"
    # numpy's own errors for a file that is no .npy / a .bin of the wrong size (ValueError,
    # EOFError) become the capture's error
    try:
        if npy:
            _npy_header(path, shape, max_bytes)
            data = np.load(path, allow_pickle=False)
        else:
            data, adc = _read_dca1000(path, side, v, shape, max_bytes)
    except (ValueError, TypeError, EOFError) as exc:
        if isinstance(exc, CaptureError):
            raise
        raise CaptureError(f"{path}: cannot read the capture its sidecar describes ({exc})") \
            from None
    if data.ndim != 3 or not np.iscomplexobj(data):
        raise CaptureError(f"{path}: expected a complex [loop, virtual, sample] cube, got "
                           f"{data.dtype} {list(data.shape)}")
    if v["shape"] is not None and tuple(v["shape"]) != data.shape:
        raise CaptureError(f"{side}: shape = {list(v['shape'])}: must be the capture's "
                           f"{list(data.shape)} [loop, virtual, sample]")
    bad = int(np.count_nonzero(~np.isfinite(data)))
    if bad:
        raise CaptureError(f"{path}: {bad} sample(s) not finite (NaN or inf): must be finite")
    if not np.any(data):
        raise CaptureError(f"{path}: every sample is 0: must hold the probe's echo")
    return Capture(np.asarray(data), *probe, radar=radar, source=str(path),
                   tx_order=None if v["tx_order"] is None else tuple(v["tx_order"]), adc=adc,
                   rts_delay_s=v["rts_delay_s"])
