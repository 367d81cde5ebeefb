"""Atomic output files: every file sins-fw writes goes through here.

A file is written to a temporary file in the destination's folder (same file system, so the final
``os.replace`` is atomic) and renamed over the destination only once it is complete. Whatever stops
the writer (an error, Ctrl-C, SIGTERM turned into an exception by the CLI) leaves either the previous
file untouched or the complete new one, and never a temporary file behind.
"""

from __future__ import annotations

import contextlib
import errno
import io
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from sins_fw.errors import InputError

#: Temporary files are named ``.NAME.<random>.tmp`` beside the destination (hidden, recognisable).
TEMP_SUFFIX = ".tmp"
#: The environment variable that gives a command run by sins_fw.launch's supervisor the descriptor
#: of its ledger of temporary files (:func:`temporary_file` notes every one there).
LEDGER_ENV = "SINS_FW_TEMPORARY_LEDGER_FD"


def _ledger_fd() -> int | None:
    """The descriptor of the supervisor's ledger of temporary files, if this process has it: the
    variable names the descriptor and the file's device and inode, checked here (a program started
    by a supervised command inherits the variable, not the file)."""
    try:
        fd, dev, ino = (int(x) for x in os.environ[LEDGER_ENV].split(":"))
        st = os.fstat(fd)
    except (KeyError, ValueError, OSError):
        return None
    return fd if (st.st_dev, st.st_ino) == (dev, ino) else None


def temporary_file(dest: Path, folder: Path) -> Path:
    """Create an empty temporary file for ``dest`` in ``folder`` (``.NAME.<random>.tmp``), noted in
    the supervisor's ledger when there is one, so that it is removed even if this process is killed
    by a signal it cannot handle (sins_fw.launch). The caller removes or renames it."""
    fd, tmp = tempfile.mkstemp(prefix=f".{dest.name}.", suffix=TEMP_SUFFIX, dir=folder)
    os.close(fd)
    ledger = _ledger_fd()
    if ledger is not None:
        with contextlib.suppress(OSError):  # the ledger is a safety net, never a failure of the write
            os.write(ledger, os.fsencode(os.path.abspath(tmp)) + b"\0")
    return Path(tmp)


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
    existed = dest.exists()
    try:
        folder.mkdir(parents=True, exist_ok=True)
        tmp = str(temporary_file(dest, folder))
    except OSError as e:
        # Name the file the user asked for, not the temporary one.
        raise OSError(e.errno, e.strerror, str(dest)) from None
    try:
        yield Path(tmp)
        # mkstemp creates the file private (0600); give it the permissions a plain open() would.
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, dest)
    except BaseException as e:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        if isinstance(e, OSError) and e.filename in (None, tmp):
            # A failed write (a full disk, a file size limit): name the file the user asked for.
            kept = f"{dest} left as it was" if existed else f"{dest} not written"
            raise OSError(e.errno, f"{e.strerror or e} ({kept})", str(dest)) from None
        raise


class _KeptErrorFile(io.RawIOBase):
    """A binary file whose first failed write (or flush, truncate) is kept instead of raised: the
    writes after it are skipped as if done. For writers that cannot survive a failed write: HDF5
    leaves a dataset half-closed after one, and h5py's File.close then closes it a second time and
    crashes the interpreter (a segfault, exit 139)."""

    def __init__(self, raw: io.FileIO) -> None:
        super().__init__()
        self.raw = raw
        self.error: OSError | None = None

    def readable(self) -> bool:
        return True

    def writable(self) -> bool:
        return True

    def seekable(self) -> bool:
        return True

    def seek(self, pos: int, whence: int = os.SEEK_SET) -> int:
        return self.raw.seek(pos, whence)

    def tell(self) -> int:
        return self.raw.tell()

    def readinto(self, buffer: bytearray | memoryview) -> int:  # type: ignore[override]
        return self.raw.readinto(buffer) or 0

    def write(self, data: bytes | bytearray | memoryview) -> int:  # type: ignore[override]
        n = memoryview(data).nbytes
        if self.error is None:
            try:
                return self.raw.write(data) or 0
            except OSError as e:
                self.error = e
        self.raw.seek(n, os.SEEK_CUR)
        return n

    def truncate(self, size: int | None = None) -> int:
        if self.error is None:
            try:
                return self.raw.truncate(size)
            except OSError as e:
                self.error = e
        return self.raw.tell() if size is None else size

    def flush(self) -> None:
        if self.error is None and not self.raw.closed:
            try:
                self.raw.flush()
            except OSError as e:
                self.error = e


@contextlib.contextmanager
def kept_error_file(path: str | os.PathLike[str]) -> Iterator[io.RawIOBase]:
    """Open ``path`` (a temporary path of :func:`atomic_path`) for writing and reading through
    :class:`_KeptErrorFile`: the writer never sees a failed write; the first one is raised here,
    once the writer has closed cleanly (give the file to a library such as h5py)."""
    with open(path, "w+b", buffering=0) as raw:
        sink = _KeptErrorFile(raw)
        yield sink
        if sink.error is not None:
            raise sink.error


def same_file(a: str | os.PathLike[str], b: str | os.PathLike[str]) -> bool:
    """Whether two paths name one file: the same device and inode when both exist (so hard links,
    symlinks and ``..`` are seen through), else the same fully resolved path (symlinks followed as
    far as they lead)."""
    try:
        sa, sb = os.stat(a), os.stat(b)
    except OSError:
        return os.path.realpath(a) == os.path.realpath(b)
    return (sa.st_dev, sa.st_ino) == (sb.st_dev, sb.st_ino)


def check_output_folder(path: str | os.PathLike[str], option: str) -> None:
    """Refuse, before any work, an output (given with ``option``) whose folder cannot take it
    (InputError naming both). Missing folders are created when the file is written
    (:func:`atomic_path`), so the nearest folder that exists must be a folder in which a file can be
    created: probed by creating and removing a temporary file there, which sees permissions, a
    read-only file system and the user's rights as the write itself would."""
    dest = Path(path)
    existing = dest.parent if str(dest.parent) else Path(".")
    while not existing.exists() and existing.parent != existing:
        existing = existing.parent
    if not existing.is_dir():
        raise InputError(f"{option} {dest}: {existing} is not a folder")
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{dest.name}.", suffix=TEMP_SUFFIX, dir=existing)
    except OSError as e:
        raise InputError(f"{option} {dest}: cannot create a file in {existing} ({e.strerror or e})") from None
    os.close(fd)
    os.unlink(tmp)


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


def save_png(fig: Any, path: str | os.PathLike[str], dpi: int) -> Path:
    """Write a matplotlib figure to ``path`` as PNG atomically, and close it (whatever happens)."""
    import matplotlib.pyplot as plt  # matplotlib is a heavy import: only when a figure is saved

    try:
        with atomic_path(path) as tmp:
            fig.savefig(tmp, format="png", dpi=dpi)
    finally:
        plt.close(fig)
    return Path(path)
