"""Progress bars for the commands that can take long (`run`, `replay`, `parity`, `synth`, `import`):
one helper, so every bar looks and behaves the same.

A bar is a tqdm bar on stderr, drawn only when stderr is a terminal and the command's stdout is not
``--json`` (:func:`wanted`): a pipe, a log file or a CI job gets nothing, and stdout never carries
one. It goes when the command ends (``leave=False``), so the command's own output is all that stays.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TypeVar

import h5py

T = TypeVar("T")


def wanted(args: argparse.Namespace) -> bool:
    """Whether a command run with ``args`` shows a bar: stderr is a terminal, and no ``--json``."""
    return sys.stderr.isatty() and not getattr(args, "json", False)


@contextmanager
def bar(
    show: bool, total: float | None, *, unit: str = "s", desc: str = "emulating"
) -> Iterator[Callable[[float], None]]:
    """Yield ``advance(done)``: the bar is set to ``done`` of ``total`` (``unit``, scaled: 1.2k s).
    Does nothing when not ``show``."""
    if not show:
        yield lambda _done: None
        return
    from tqdm import tqdm  # only when a bar is shown

    # A Ctrl-C inside tqdm's constructor leaves a half-built bar whose __del__ prints a traceback:
    # hold the signals for the few microseconds it takes (they are delivered right after).
    with signals_held():
        b = tqdm(total=total, unit=unit, unit_scale=True, desc=desc, file=sys.stderr, leave=False)
    with b:

        def advance(done: float) -> None:
            b.update(done - b.n)

        yield advance


@contextmanager
def trace_bar(show: bool, span_s: float | None, desc: str = "emulating") -> Iterator[Callable[[float], None]]:
    """:func:`bar` in seconds of a trace: yields ``reached(t)`` taking trace times (the first one
    seen is the start), as ``emulate``'s ``on_chunk`` gives them."""
    with bar(show, span_s, unit="s", desc=desc) as advance:
        start: list[float] = []

        def reached(t: float) -> None:
            if not start:
                start.append(t)
            advance(t - start[0])

        yield reached


def trace_span_s(path: str | os.PathLike[str]) -> float | None:
    """The time span of an HDF5 trace without reading it (None for CSV or when unreadable: the
    emulation's own loading reports the problem)."""
    if Path(path).suffix.lower() not in (".h5", ".hdf5"):
        return None
    try:
        with h5py.File(path, "r") as f:
            t = f["t_s"]
            return float(t[-1] - t[0]) if len(t) else None
    except (OSError, KeyError, ValueError, TypeError, RuntimeError):
        return None  # a link, a compound dtype...: loading the trace reports it


def follow(chunks: Iterable[T], advance: Callable[[float], None]) -> Iterator[T]:
    """Yield trace chunks (anything with ``t_s``), setting a :func:`bar` to the trace time they
    cover so far (from the first chunk's first time) after each."""
    start: float | None = None
    for chunk in chunks:
        t = chunk.t_s  # type: ignore[attr-defined]
        if start is None and len(t):
            start = float(t[0])
        yield chunk
        if start is not None and len(t):
            advance(float(t[-1]) - start)


@contextmanager
def signals_held() -> Iterator[None]:
    """Block SIGINT and SIGTERM for the duration (delivered when the block ends)."""
    held = {signal.SIGINT, signal.SIGTERM}
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, held)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)
