"""Scenario playback: moving targets across the arc, frame by frame (``rtsgeom play``).

:class:`Playback` (a configured study) plays a scene's ``[scenario]``: the setup calibrated
once, then per frame the set-points (:func:`rtsgeom.scene.scenario.trajectory`), the RTS
programme (the planner of ``rtsgeom run``) and the RuT's detections through the full chain,
matched to the set targets; :class:`PlaybackResult` holds the tracks, the programme, the
summary and the figure. :func:`drive_tolerance`: the mounting-tolerance yield over the drive
(the one tolerance engine).
"""

from .result import PROGRAMME_COLUMNS, TRACK_COLUMNS, PlaybackResult
from .study import Playback, play
from .tolerance import drive_tolerance

__all__ = ["Playback", "PlaybackResult", "play", "drive_tolerance", "PROGRAMME_COLUMNS",
           "TRACK_COLUMNS"]
