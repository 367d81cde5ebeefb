"""The exceptions sins-fw raises. Errors from the Rust core arrive as these classes with the core's
message, which names the file, key, register or row and what was expected.

    SinsError                 base of everything below
    ├── InputError            the user's input is wrong (CLI exit code 2)
    │   ├── ProfileError      a profile key, type or value
    │   ├── TraceError        a trace file or array: missing column, NaN, non-increasing time, ...
    │   ├── RegisterError     a register access or value the hardware model rejects
    │   └── ConfigError       a configuration the hardware cannot realise
    ├── CheckFailed           a check (parity threshold, deadline) failed (CLI exit code 1)
    └── InternalError         a bug: a panic in the core, caught before it could abort Python

    TraceWarning              (a warning) a trace reads but looks wrong: a unit, a time unit

    Terminated                SIGTERM, raised by the CLI's handler; a KeyboardInterrupt so that it
                              unwinds exactly like Ctrl-C (CLI exit code 143)
"""

from __future__ import annotations


class SinsError(Exception):
    """Base class of every sins-fw error."""


class InputError(SinsError):
    """The user's input (a file, a profile, an option) is wrong."""


class ProfileError(InputError):
    """A profile key, type or value is wrong."""


class TraceError(InputError):
    """A trace file or input array is malformed."""


class RegisterError(InputError):
    """A register access or value the hardware model rejects."""


class ConfigError(InputError):
    """A configuration the hardware cannot realise."""


class CheckFailed(SinsError):  # noqa: N818 (a verdict, not an error of the tool)
    """A check failed: a parity threshold or a deadline was exceeded."""


class InternalError(SinsError):
    """A bug in sins-fw (e.g. a Rust panic that was caught)."""


class Terminated(KeyboardInterrupt):
    """The process received SIGTERM (the CLI turns it into this exception so that output files are
    left intact and the command says how far it got, as with Ctrl-C)."""


class TraceWarning(UserWarning):
    """A trace reads, but something in it looks wrong: a unit (9.8 g at rest: m/s² in a `_g` column),
    a time unit, a rate. The message says what was seen and how to read the file otherwise."""


def utf8_text(data: bytes, where: object, expected: str, error: type[InputError], first_line: int = 1) -> str:
    """``data`` as UTF-8 text, else ``error`` naming ``where``, the line (``data`` starting at line
    ``first_line``) and the byte that is not UTF-8, and what was ``expected``."""
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as e:
        line = first_line + data.count(b"\n", 0, e.start)
        raise error(
            f"{where}: line {line}: byte 0x{data[e.start]:02x} is not UTF-8 text; expected {expected}"
        ) from None
