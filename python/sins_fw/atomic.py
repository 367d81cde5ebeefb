"""Atomic output files: every file sins-fw writes goes through here.

A file is written to a temporary file in the destination's folder (same file system, so the final
``os.replace`` is atomic) and renamed over the destination only once it is complete. Whatever stops
the writer (an error, Ctrl-C, SIGTERM turned into an exception by the CLI) leaves either the previous
file untouched or the complete new one, and never a temporary file behind.
"""

from __future__ import annotations

import contextlib
import errno
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path

#: Temporary files are named ``.NAME.<random>.tmp`` beside the destination (hidden, recognisable).
TEMP_SUFFIX = ".tmp"


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; on a clean exit it replaces ``path``, on any
    exception (including KeyboardInterrupt) it is removed and ``path`` is left as it was.

    The caller writes the temporary path completely (and closes it) inside the ``with`` block.
    The destination's folder is created when missing.
    """
    dest = Path(path)
    folder = dest.parent if str(dest.parent) else Path(".")
    if folder.exists() and not folder.is_dir():
        raise NotADirectoryError(errno.ENOTDIR, f"{folder} is not a folder", str(dest))
    try:
        folder.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{dest.name}.", suffix=TEMP_SUFFIX, dir=folder)
    except OSError as e:
        # Name the file the user asked for, not the temporary one.
        raise OSError(e.errno, e.strerror, str(dest)) from None
    os.close(fd)
    try:
        yield Path(tmp)
        # mkstemp creates the file private (0600); give it the permissions a plain open() would.
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, dest)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def write_text(path: str | os.PathLike[str], text: str) -> Path:
    """Write ``text`` (UTF-8, ``\\n`` line ends) to ``path`` atomically."""
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8", newline="\n")
    return Path(path)


def write_bytes(path: str | os.PathLike[str], data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically."""
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)
    return Path(path)
