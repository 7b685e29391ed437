"""Mounting tolerance: how many built setups keep the synthesized angle within a spec, and the
largest tolerance that keeps a target yield (paper section "Arbitrary Angle of Arrival",
"Constraints").

One engine, by concept: the draws (:mod:`.draws`: one stream of offsets, rotations, RuT pose and
the target's sub-bin position), the model of one channel set under those errors at phasor level
(:mod:`.phasors`, its tables :mod:`.tables`, the pair's and a cell's procedure :mod:`.pair`,
:mod:`.cell`, their compiled kernels :mod:`.kernels`), the one Monte-Carlo driver over channel
sets on shared draws and its result (:mod:`.montecarlo`: a pair, a cell, a whole arc), the one
yield search (:mod:`.search`), the check against the full ADC-cube chain (:mod:`.verify`), and the
study as a configured callable (:mod:`.study`: ``ToleranceStudy(...)(scene)``, its draws
configured by :mod:`.config`).
"""

from .config import MonteCarlo
from .draws import AXES, DISTRIBUTIONS, MAX_SIGMA_MM, Bounds
from .montecarlo import ToleranceModel, ToleranceResult, monte_carlo, simulate
from .phasors import ALL_CASES, CASES, NOMINAL_AMPLITUDES, ChannelPhasors
from .search import YieldSearch, max_scale_for_yield, max_sigma_for_yield
from .study import ToleranceReport, ToleranceStudy
from .verify import VerifyResult, verify_draws

__all__ = ["AXES", "DISTRIBUTIONS", "MAX_SIGMA_MM", "CASES", "ALL_CASES", "NOMINAL_AMPLITUDES", "Bounds",
           "ChannelPhasors", "ToleranceModel", "ToleranceResult", "monte_carlo",
           "max_sigma_for_yield", "max_scale_for_yield", "VerifyResult", "verify_draws",
           "MonteCarlo", "simulate", "YieldSearch", "ToleranceStudy", "ToleranceReport"]
