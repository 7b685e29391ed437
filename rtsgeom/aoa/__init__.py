"""Arbitrary angle of arrival: two-channel synthesis, calibration and linearity (on top of the
signal chain)."""

from .calibration import Calibration, calibrate_pair, probe_front_ends
from .plan import plan_targets
from .model import ChannelModel
from .synthesis import MODES, PairModel

__all__ = ["Calibration", "calibrate_pair", "probe_front_ends", "plan_targets", "MODES",
           "ChannelModel", "PairModel"]
