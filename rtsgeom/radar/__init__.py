"""The radar under test: FMCW ADC cube synthesis (stage 4) and its processing (stage 5)."""

from .fmcw import AdcCube, add_noise, synthesize
from .processing import Detections, RangeDoppler, detect, process, range_doppler

__all__ = ["AdcCube", "add_noise", "synthesize", "Detections", "RangeDoppler", "detect",
           "process", "range_doppler"]
