"""SIGINT and SIGTERM honoured at any instant, the heavy libraries' start-up included.

Python raises a signal's exception at the next bytecode of the main thread, wherever that is.
Three places cannot take it: an import (a module left half-initialised: a segmentation fault
in ``vtkmodules/__init__.py``, a ``TypeError`` from trimesh), a finalizer and a callback from C
(the exception is printed as ``Exception ignored in ...`` and dropped, so the run finished with
exit 0). A signal arriving while Python shuts down after the command (its output already
complete) ends the process by the signal's default action, without a message. :func:`honoured_signals` installs handlers that, in such a place, note the signal and
raise it a few milliseconds later once outside (an interval timer re-checks); and whatever
happens, a command that received a signal exits 130 (SIGINT) or 143 (SIGTERM), never 0.
"""

from __future__ import annotations

import signal
import threading
from contextlib import contextmanager

from ..errors import Terminated

__all__ = ["honoured_signals", "received", "raise_received"]

_RETRY_S = 0.02
_received: list[int] = []  # the signals of this command, first one first


def received() -> int | None:
    """The first signal received inside :func:`honoured_signals`, or None."""
    return _received[0] if _received else None


def raise_received() -> None:
    """Raise the first signal received inside :func:`honoured_signals` (:class:`Terminated`,
    :class:`KeyboardInterrupt`), if any: what an output folder checks immediately before it
    is swapped in (a signal whose exception was swallowed, or is still deferred, must not let
    a run it cut short replace the old folder)."""
    if _received:
        _raise(_received[0])


#: code that C calls back into, where an exception is printed and dropped ("Exception ignored
#: on calling ctypes callback function": llvmlite's object cache while numba compiles; VTK's
#: observers)
_CALLBACK_PACKAGES = ("/llvmlite/", "/vtkmodules/")
#: Python code of numpy's, which C code in numpy calls and whose exceptions it may replace: a
#: SIGTERM raised in ``np.unique`` of structured rows (building a setup) came out as
#: "TypeError: Cannot compare structured arrays", a traceback instead of exit 143
_CONVERTING_PACKAGES = ("/numpy/",)
_UNSAFE_PACKAGES = _CALLBACK_PACKAGES + _CONVERTING_PACKAGES  # built once, not per frame


def _unsafe(frame) -> bool:
    """Whether the interrupted code is inside an import, a finalizer or a C callback."""
    while frame is not None:
        code = frame.f_code
        name = code.co_filename
        if (name.startswith("<frozen importlib") or code.co_name == "__del__"
                or any(part in name for part in _UNSAFE_PACKAGES)):
            return True
        frame = frame.f_back
    return False


def _raise(signum: int):
    if signum == signal.SIGTERM:
        raise Terminated()
    raise KeyboardInterrupt()


def _on_signal(signum, frame):
    _received.append(signum)
    if _unsafe(frame):  # raise it once out of there
        signal.setitimer(signal.ITIMER_REAL, _RETRY_S)
        return
    _raise(signum)


def _on_retry(signum, frame):
    if not _received:
        return
    if _unsafe(frame):
        signal.setitimer(signal.ITIMER_REAL, _RETRY_S)
        return
    _raise(_received[0])


@contextmanager
def honoured_signals():
    """SIGINT and SIGTERM as :class:`KeyboardInterrupt` and :class:`Terminated`, deferred out of
    imports and finalizers (main thread only; elsewhere a no-op)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    _received.clear()
    old = {s: signal.signal(s, h) for s, h in ((signal.SIGINT, _on_signal),
                                               (signal.SIGTERM, _on_signal),
                                               (signal.SIGALRM, _on_retry))}
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        for s, h in old.items():
            signal.signal(s, h)
