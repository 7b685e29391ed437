"""Every exception rtsgeom raises on purpose, in one place (as scikit-learn's ``exceptions``).

A user's input that is out of range is a ``ValueError`` subclass whose message names the field
or argument and its allowed range; a missing capability of the machine is a ``RuntimeError``
subclass that says what to install. The CLI turns each into ``rtsgeom: error: ...`` and exit
code 2; library callers catch the specific class, never a bare ``ValueError`` (which then stays
what it is: a bug). This module imports nothing, so that any module can raise them.
"""

from __future__ import annotations

__all__ = ["RtsgeomError", "SceneError", "LinkError", "ParameterError", "UsageError", "CaptureError",
           "OutputError", "AngleUnreachable", "CellUnreachable", "CalibrationFailed",
           "ClusterError", "RaytraceUnavailable", "VizError", "Terminated", "RtsgeomWarning",
           "NominalSetupWarning"]


class RtsgeomError(Exception):
    """Base of every error below that ends a command with one line (``rtsgeom: error: ...``,
    exit 2): the CLI catches this one class, so a new error needs no second list there.

    Examples
    --------
    >>> try:
    ...     rtsgeom.tolerance(scene, draws=0)
    ... except rtsgeom.RtsgeomError as exc:  # every input error rtsgeom raises on purpose
    ...     print(exc)                                               # doctest: +SKIP
    """


# -- input out of range (ValueError) ---------------------------------------------------------


class SceneError(RtsgeomError, ValueError):
    """A scene file (or a value derived from one) is invalid. The message names the field.

    ``problems`` holds every violated rule when the error came from the cross-field rules.

    Attributes
    ----------
    problems : list of str
        Every violated rule (one entry, the message, for a single field).
    """

    def __init__(self, message: str, problems: list[str] | None = None):
        super().__init__(message)
        self.problems = problems or [message]


class LinkError(SceneError):
    """A target the RTS cannot produce with its gains and dynamic range (names the field)."""


class ParameterError(RtsgeomError, ValueError):
    """An argument (not a scene field) is outside its allowed range; the message names it.

    Examples
    --------
    >>> rtsgeom.MonteCarlo(draws=-1)                 # doctest: +SKIP
    ParameterError: MonteCarlo: draws = -1: must be an integer in [0, 10000000]
    """


class UsageError(RtsgeomError, ValueError):
    """A command-line argument is invalid (exit code 2)."""


class CaptureError(RtsgeomError, ValueError):
    """A probe capture does not fit the scene, or its file or sidecar cannot be read.

    Examples
    --------
    >>> rtsgeom.identify(scene, ["wrong_shape.npy"])  # doctest: +SKIP
    CaptureError: ...: shape ... does not fit the scene's ...
    """


class OutputError(RtsgeomError, ValueError):
    """An output path that cannot or must not be written (exit code 2 in the CLI).

    Examples
    --------
    An output folder that is the scene's own folder, or a file inside the inputs, is refused
    before anything is computed (``rtsgeom._lib.io.check_output_dir``).
    """


class AngleUnreachable(RtsgeomError, ValueError):
    """The set direction lies outside what the channels can synthesize.

    Examples
    --------
    A set angle beyond the pair's measured span (``ChannelModel.solve``, ``ChannelPhasors.build``)
    raises it; the message names the angle and the span.
    """


class CellUnreachable(RtsgeomError, ValueError):
    """No cell of front ends encloses the direction."""


class CalibrationFailed(RtsgeomError, ValueError):
    """A pair's calibration found no coherence point (no probe detected over the sweep), or
    the calibrated channels do not synthesize the cell's centre."""


# -- a capability this machine lacks (RuntimeError) ------------------------------------------


class ClusterError(RtsgeomError, RuntimeError):
    """A Dask scheduler address that is malformed or cannot be reached (one line, exit 2)."""


class RaytraceUnavailable(RtsgeomError, RuntimeError):
    """Sionna RT cannot run here (package missing, no usable LLVM/CUDA backend). The message
    says what to install.

    Examples
    --------
    >>> rtsgeom.raytrace_paths(setup)   # doctest: +SKIP
    RaytraceUnavailable: Sionna RT is not installed: pip install -e '.[raytrace]'
    """


class VizError(RtsgeomError, RuntimeError):
    """Rendering is not possible here (no OpenGL context, no display, a missing package).

    Examples
    --------
    >>> rtsgeom.show(scene, png="setup.png")   # doctest: +SKIP
    VizError: no off-screen OpenGL context ...
    """


# -- control flow ------------------------------------------------------------------------------


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised like Ctrl-C so that every cleanup (staging folders, temporary files)
    runs the same way."""


# -- warnings (warnings.warn: the result is computed, but the user should know) ---------------


class RtsgeomWarning(UserWarning):
    """Base of the warnings rtsgeom emits; the CLI prints each as ``rtsgeom: warning: ...``."""


class NominalSetupWarning(RtsgeomWarning):
    """A study works on the nominal setup although the scene carries its own mounting,
    channel or RuT pose errors (the message names the fields and what shows their effect).

    Examples
    --------
    >>> import warnings
    >>> warnings.simplefilter("error", rtsgeom.NominalSetupWarning)  # make it an error
    """
