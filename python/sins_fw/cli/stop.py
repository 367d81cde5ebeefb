"""SIGINT and SIGTERM stop a command cleanly: both raise a KeyboardInterrupt (SIGTERM its subclass
:class:`~sins_fw.errors.Terminated`) that unwinds like Ctrl-C, removing temporary files and saying how
far the command got.

Python runs a signal handler between any two bytecodes, also inside a finaliser or a weakref
callback, where the exception it raises is printed ("Exception ignored in ...") and dropped. The
request is therefore also remembered, and long loops call :func:`check_stop` so that it is honoured
anyway.
"""

from __future__ import annotations

import signal
from typing import Any

from sins_fw.errors import Terminated

#: The interrupt the last signal asked for (None: none since :func:`install`).
_requested: type[KeyboardInterrupt] | None = None


def _on_signal(signum: int, frame: object) -> None:
    global _requested
    _requested = Terminated if signum == signal.SIGTERM else KeyboardInterrupt
    raise _requested()


def install() -> dict[int, Any]:
    """Install the handlers (main thread only); returns the previous ones for :func:`restore`."""
    global _requested
    _requested = None
    return {sig: signal.signal(sig, _on_signal) for sig in (signal.SIGINT, signal.SIGTERM)}


def restore(previous: dict[int, Any]) -> None:
    """Put back the handlers :func:`install` replaced."""
    for sig, handler in previous.items():
        signal.signal(sig, handler)


def check_stop() -> None:
    """Raise the interrupt a signal asked for if its exception was dropped where it landed."""
    if _requested is not None:
        raise _requested()
