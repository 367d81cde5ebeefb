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
import threading
from collections.abc import Iterator
from contextlib import contextmanager
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


#: The unraisable-exception hook :func:`handling` replaced.
_previous_hook = sys.unraisablehook


@contextmanager
def handling() -> Iterator[None]:
    """SIGINT and SIGTERM raise and are remembered while the block runs. Only the main thread may
    install signal handlers: elsewhere (an embedding program's thread) nothing changes."""
    global _requested, _previous_hook
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    _requested = None
    _previous_hook, sys.unraisablehook = sys.unraisablehook, _quiet_when_remembered
    handlers = {sig: signal.signal(sig, _on_signal) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for sig, handler in handlers.items():
            signal.signal(sig, handler)
        sys.unraisablehook = _previous_hook


def check_stop() -> None:
    """Raise the interrupt a signal asked for if its exception was dropped where it landed."""
    if _requested is not None:
        raise _requested()
