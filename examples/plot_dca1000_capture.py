"""
A DCA1000 capture, read back with numpy
=======================================

``rtsgeom adc --format dca1000`` writes the raw ADC cube in the layout of TI's DCA1000 capture
card (xWR18xx, complex, 2 LVDS lanes) with a JSON side file. Any DCA1000 reader can load it;
here a plain numpy reader of a dozen lines, checked against the cube from the Python API.
"""

# %%
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

import rtsgeom

QUICK = os.environ.get("RTSGEOM_EXAMPLES_QUICK") == "1"
OUT = Path(os.environ.get("RTSGEOM_EXAMPLES_OUT", "example_output"))
OUT.mkdir(parents=True, exist_ok=True)
# the repository's scenes/ (sphinx-gallery runs a script in examples/, without a __file__)
HERE = Path(globals().get("__file__", "plot.py")).resolve().parent
SCENE = HERE.parent / "scenes" / "diewald2022.toml"

# %%
# Write the capture with the command-line tool (``nearest``: each target on its nearest front
# end, no calibration sweep, so this runs in seconds).
capture = OUT / "adc.bin"
subprocess.run([sys.executable, "-m", "rtsgeom", "adc", str(SCENE), "--format", "dca1000",
                "--amplitudes", "nearest", "--out", str(capture), "--quiet"], check=True)
meta = json.loads(Path(str(capture) + ".json").read_text())
print(meta)


# %%
# A reader from TI's layout description: int16 little endian; chirps in transmit order; per
# chirp the Rx one after the other; per Rx the samples in pairs ``I0 I1 Q0 Q1``.
def read_dca1000(path, chirps, num_rx, samples):
    raw = np.fromfile(path, dtype="<i2").reshape(chirps, num_rx, samples // 2, 4)
    i = raw[..., :2].reshape(chirps, num_rx, samples)
    q = raw[..., 2:].reshape(chirps, num_rx, samples)
    return (i + 1j * q).astype(np.complex64)


frames = read_dca1000(capture, meta["chirps"], meta["num_rx"], meta["samples_per_chirp"])
n_tx = len(meta["tx_order"])
cube = frames.reshape(-1, n_tx * meta["num_rx"], meta["samples_per_chirp"]) / meta["scale"]
print("read", cube.shape, "[chirp loop, virtual channel, sample]")

# %%
# The same cube from the Python API, to int16 precision.
run = rtsgeom.run_scene(rtsgeom.load_scene(SCENE), aoa_mode="nearest")
ref = run.cube.to_xarray()
err = np.max(np.abs(cube - ref.values)) * meta["scale"]
print(f"largest difference {err:.2f} LSB")
assert err <= 1.0

# %%
# The capture processed as the radar does, its detections assigned to the set-points by the
# same association as ``run`` and ``play`` (one optimal assignment in resolution cells).
from rtsgeom.pipeline.run import match_targets  # noqa: E402
from rtsgeom.radar import AdcCube, process  # noqa: E402

read_back = AdcCube(cube, run.cube.radar, run.cube.rut)
rd, det = process(read_back)
for m in match_targets(run.scene, det, rd, steering=read_back.steering):
    d = m["detection"]
    print(f"target {m['index']}: {m['status']}"
          + ("" if d is None else f" at {d['range_m']:.3f} m, {d['angle_deg']:.3f} deg"))

# %%
# A range profile of virtual channel 0, summed over the chirps, with the range axis from the
# chirp parameters.
import matplotlib.pyplot as plt  # noqa: E402

profile = np.abs(np.fft.fft(cube[:, 0, :] * np.hanning(cube.shape[-1]), axis=-1)).sum(axis=0)
radar = rtsgeom.load_scene(SCENE).radar
range_m = np.arange(cube.shape[-1]) * radar.range_resolution_m
fig, ax = plt.subplots(figsize=(6.4, 3.2))
ax.plot(range_m, 20 * np.log10(profile / profile.max()))
ax.set_xlabel("range (m)")
ax.set_ylabel("level (dB)")
ax.set_title("Range profile from the DCA1000 capture")
fig.tight_layout()
fig.savefig(OUT / "dca1000_range_profile.png", dpi=100)
