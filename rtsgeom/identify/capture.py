"""Probe captures: one RTS front end active alone with a probe target, as the RuT records it
(the raw ADC cube), and its files (``rtsgeom adc --active I``: DCA1000 ``.bin`` or ``.npy``
plus a sidecar ``FILE.json`` recording the active front end and the probe), the input of
``rtsgeom.identify``."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.constants import c

from ..errors import CaptureError
from ..geometry import Setup
from ..paths import exact_paths
from ..rts.channels import RtsProgram, nominal_link_gain, requested_delay, target_amplitude
from ..radar.frame import simulate
from .._lib.io import atomic_path, write_bytes, write_json
from ..calibration.probes import probe_ranges
from ..radar.dca1000 import from_dca1000, to_dca1000
from ..radar.fmcw import AdcCube

__all__ = ["Capture", "capture_probe", "simulate_capture", "write_capture", "read_capture"]




@dataclass(frozen=True)
class Capture:
    """One front end active alone with a probe target: the raw ADC cube and what it was."""

    data: np.ndarray  # (L, V, N) complex, [chirp loop, virtual channel, sample]
    active: int
    range_m: float
    velocity_mps: float
    amplitude: float  # programmed amplitude of the probe's channel

    def to_meta(self) -> dict:
        return {"active_front_end": self.active, "probe_range_m": self.range_m,
                "probe_velocity_mps": self.velocity_mps, "probe_amplitude": self.amplitude}


def capture_probe(setup: Setup, range_m: float | None = None) -> tuple[float, float]:
    """Default probe (range, programmed amplitude): the calibration's first probe range and the
    amplitude that gives a 10 m^2 target (what :class:`~rtsgeom.synthesis.model.ChannelModel` programs)."""
    scene = setup.scene
    r = float(probe_ranges(setup, 1)[0]) if range_m is None else float(range_m)
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
    if not 0 < r < scene.radar.max_range_m:
        raise CaptureError(f"probe range {r:g} m: must be in (0, {scene.radar.max_range_m:g}) m")
    paths = exact_paths(setup) if paths is None else paths
    f_d = 2 * scene.radar.f_c_hz * velocity_mps / c
    prog = RtsProgram.build([0], [active], [float(requested_delay(scene, r))], [f_d], [amp])
    _, cube = simulate(setup, paths, prog, seed, scene.radar.snr_db)
    return Capture(cube.data, int(active), r, float(velocity_mps), amp)


def write_capture(cap: Capture, rut, out: Path, fmt: str) -> dict:
    """Write ``cap`` as ``.npy`` or DCA1000 ``.bin``; the sidecar ``out.json`` (both formats)
    records the probe and the active front end. Returns the sidecar's content."""
    n_l, n_v, n_s = cap.data.shape
    meta = {"kind": "rtsgeom-probe-capture", **cap.to_meta(), "shape": [n_l, n_v, n_s]}
    if fmt == "npy":
        with atomic_path(out) as tmp, open(tmp, "wb") as fh:
            np.save(fh, cap.data)
        meta["format"] = "npy"
    else:
        raw, scale = to_dca1000(AdcCube(cap.data, None, rut))
        write_bytes(out, raw)
        meta.update({"format": "dca1000-xwr18xx-complex-2lane", "scale": scale,
                     "chirps": n_l * len(rut.tx_order), "tx_order": list(rut.tx_order),
                     "num_rx": rut.num_rx, "samples_per_chirp": n_s, "dtype": "int16 (<i2)",
                     "order": "chirp (transmit order) > rx > sample pairs I0 I1 Q0 Q1"})
    write_json(Path(str(out) + ".json"), meta)
    return meta


def read_capture(path) -> Capture:
    """Read a probe capture written by ``rtsgeom adc --active`` (``.bin`` or ``.npy`` with its
    sidecar ``PATH.json``). Errors name the file and what is missing."""
    path = Path(path)
    side = Path(str(path) + ".json")
    if not path.is_file():
        raise CaptureError(f"{path}: no such capture file")
    if not side.is_file():
        raise CaptureError(f"{path}: no sidecar {side.name} (write captures with rtsgeom adc "
                           "--active I)")
    try:
        meta = json.loads(side.read_text(encoding="utf-8"))
    except json.JSONDecodeError as exc:
        raise CaptureError(f"{side}: not JSON ({exc})") from None
    if not isinstance(meta, dict):
        raise CaptureError(f"{side}: not a probe capture's sidecar (a JSON object)")
    keys = ["active_front_end", "probe_range_m", "probe_velocity_mps", "probe_amplitude"]
    npy = meta.get("format") == "npy" or path.suffix == ".npy"
    for key in keys + ([] if npy else ["num_rx", "samples_per_chirp", "chirps", "tx_order",
                                       "scale"]):
        if key not in meta:
            raise CaptureError(f"{side}: no {key!r}: not a probe capture (rtsgeom adc "
                               "--active I)")
    # numpy's own errors for a file that is no .npy / a .bin of the wrong size (ValueError,
    # EOFError) and a sidecar value of the wrong type become the capture's error
    try:
        probe = (int(meta["active_front_end"]), float(meta["probe_range_m"]),
                 float(meta["probe_velocity_mps"]), float(meta["probe_amplitude"]))
        if npy:
            data = np.load(path, allow_pickle=False)
        else:
            n_rx, n_s, chirps = (int(meta["num_rx"]), int(meta["samples_per_chirp"]),
                                 int(meta["chirps"]))
            raw = from_dca1000(path.read_bytes(), chirps, n_rx, n_s)
            n_tx = len(meta["tx_order"])
            data = raw.reshape(chirps // n_tx, n_tx * n_rx, n_s) / float(meta["scale"])
    except (ValueError, TypeError, EOFError) as exc:
        raise CaptureError(f"{path}: cannot read the capture its sidecar describes ({exc})") \
            from None
    if data.ndim != 3 or not np.iscomplexobj(data):
        raise CaptureError(f"{path}: expected a complex [loop, virtual, sample] cube, got "
                           f"{data.dtype} {list(data.shape)}")
    return Capture(np.asarray(data), *probe)
