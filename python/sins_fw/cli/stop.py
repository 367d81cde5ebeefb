"""SIGINT and SIGTERM stop a command cleanly: both raise a KeyboardInterrupt (SIGTERM its subclass
:class:`~sins_fw.errors.Terminated`) that unwinds like Ctrl-C, removing temporary files and saying how
far the command got.

Python runs a signal handler between any two bytecodes, also inside a finaliser or a weakref
callback, where the exception it raises is dropped (and printed as "Exception ignored in ..." with a
traceback). The request is therefore also remembered, long loops call :func:`check_stop` so that it
is honoured anyway, and the dropped interrupt is not printed.
"""

from __future__ import annotations

import signal
import sys
from typing import Any

from sins_fw.errors import Terminated

#: The interrupt the last signal asked for (None: none since :func:`install`).
_requested: type[KeyboardInterrupt] | None = None


def _on_signal(signum: int, frame: object) -> None:
    global _requested
    _requested = Terminated if signum == signal.SIGTERM else KeyboardInterrupt
    raise _requested()


def _quiet_when_remembered(unraisable: Any) -> None:
    """`sys.unraisablehook`: an interrupt dropped where it landed is remembered (check_stop raises it
    again), so it is not printed; anything else goes to the hook in force before."""
    if isinstance(unraisable.exc_value, KeyboardInterrupt) and _requested is not None:
        return
    _previous_hook(unraisable)


_previous_hook = sys.unraisablehook


def install() -> dict[Any, Any]:
    """Install the handlers (main thread only); returns what they replace, for :func:`restore`."""
    global _requested, _previous_hook
    _requested = None
    _previous_hook = sys.unraisablehook
    sys.unraisablehook = _quiet_when_remembered
    previous: dict[Any, Any] = {"unraisablehook": _previous_hook}
    for sig in (signal.SIGINT, signal.SIGTERM):
        previous[sig] = signal.signal(sig, _on_signal)
    return previous


def restore(previous: dict[Any, Any]) -> None:
    """Put back what :func:`install` replaced."""
    for key, handler in previous.items():
        if key == "unraisablehook":
            sys.unraisablehook = handler
        else:
            signal.signal(key, handler)


def check_stop() -> None:
    """Raise the interrupt a signal asked for if its exception was dropped where it landed."""
    if _requested is not None:
        raise _requested()
