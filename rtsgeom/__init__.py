"""rtsgeom: radar target simulator (RTS) setups as geometry.

Pipeline (one direction)::

    Scene (scene.py) -> Setup (geometry/) -> Paths (paths/) -> Echoes (rts.py)
      -> AdcCube (radar/fmcw.py) -> RangeDoppler, Detections (radar/processing.py)
      -> AoA synthesis and calibration (aoa/) -> analyses (analysis/) -> figures, report (viz/)
"""

__version__ = "0.1.0"
