"""Build a user's F28335 C firmware, unmodified, for the host against the emulated board, and run it.

The sources are compiled as C++17 by the host's ``g++`` with the replacement DSP2833x headers of
``firmware_c/include`` first on the include path and ``sins_fw_prelude.h`` force-included (TI's
``interrupt``, ``cregister``, ``EALLOW``/``EDIS``, ``EINT``, ``asm``, ``void main``). Each register
access of TI's register-file objects (``SpiaRegs.SPICCR.bit.SPISWRESET = 0``) becomes a call into the
emulated board at its C28x address, a bit-field store a read-modify-write of the whole 16-bit word,
each access charged the cycles of ``firmware_model/c28x-costs.toml`` ``[io]``. The result is a shared
library linked against the C ABI library (``rust/cabi``): :func:`run_firmware` runs its ``main`` until a
virtual time and reads its globals.

Modelled so far: SPI-A, the GPIO data registers, LOSPCP. CPU timer 0, the PIE and interrupts are not
yet (issue 20, items 1, 3). The firmware's ``float``/``double`` are the host's or the C28x's
(``float_mode``), IQmathLib.h is the ``iq`` backend's (sins_fw.firmware_arith, docs/c-arithmetic.md).
"""

from __future__ import annotations

import ctypes
import os
import re
import shutil
import subprocess
import tempfile
import tomllib
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from sins_fw import firmware_arith
from sins_fw.atomic import atomic_path
from sins_fw.errors import ConfigError, InputError
from sins_fw.profile import MODEL_DIR

ROOT = Path(__file__).resolve().parents[2]
FIRMWARE_C = Path(os.environ.get("SINS_FW_C_DIR") or ROOT / "firmware_c")
SOURCE_SUFFIXES = (".c", ".cpp")
#: How many of the compiler's error lines a build error quotes.
QUOTED_ERRORS = 5


def cabi_library_dir() -> Path:
    """The folder of ``libsins_cabi.so`` (``$SINS_FW_CABI_DIR``, else this tree's ``target/release``)."""
    target = Path(os.environ.get("CARGO_TARGET_DIR") or ROOT / "target") / "release"
    folder = Path(os.environ.get("SINS_FW_CABI_DIR") or target)
    if not (folder / "libsins_cabi.so").is_file():
        raise ConfigError(
            f"{folder / 'libsins_cabi.so'}: the C ABI library is missing; build it with "
            "`cargo build --release -p sins-cabi` (or set SINS_FW_CABI_DIR to its folder)"
        )
    return folder


def sources_of(paths: Sequence[str | os.PathLike[str]]) -> list[Path]:
    """The C/C++ sources: files as given, folders' ``*.c``/``*.cpp`` (sorted, not recursive)."""
    found: list[Path] = []
    for p in map(Path, paths):
        if p.is_dir():
            found += sorted(f for f in p.iterdir() if f.suffix in SOURCE_SUFFIXES and f.is_file())
        elif p.is_file():
            found.append(p)
        else:
            raise InputError(f"{p}: no such file or folder")
    if not found:
        raise InputError(f"{', '.join(map(str, paths))}: no C sources (*.c, *.cpp) there")
    return found


def _io_cycles() -> tuple[int, int]:
    """Cycles of one peripheral read and one write, from the cost table."""
    path = MODEL_DIR / "c28x-costs.toml"
    io = tomllib.loads(path.read_text(encoding="utf-8"))["io"]
    return int(io["peripheral_read"]), int(io["peripheral_write"])


def build_firmware(
    paths: Sequence[str | os.PathLike[str]],
    out: str | os.PathLike[str],
    *,
    compiler: str = "g++",
    float_mode: str = "host",
) -> Path:
    """Compile the firmware sources (files or folders) into the shared library ``out``, its ``float``
    and ``double`` in ``float_mode`` (``host`` or ``c28x``: sins_fw.firmware_arith). A source that
    does not compile raises :class:`~sins_fw.errors.InputError` quoting the compiler's first errors
    (file:line); ``out`` is then left as it was."""
    sources = sources_of(paths)
    firmware_arith.check_float_mode(float_mode)
    if shutil.which(compiler) is None:
        raise ConfigError(f"`{compiler}` not found: a host C++ compiler is needed (Debian: build-essential)")
    libdir = cabi_library_dir()
    read_cycles, write_cycles = _io_cycles()
    include = FIRMWARE_C / "include"
    folders = sorted({str(s.parent) for s in sources})
    cabi_include = ROOT / "rust" / "cabi" / "include"
    flags = [
        "-std=c++17",
        "-O1",
        "-fPIC",
        "-include",
        str(include / "sins_fw_prelude.h"),
        *firmware_arith.flags(float_mode, include),
        f"-I{include}",
        *(f"-I{d}" for d in folders),
        f"-I{cabi_include}",
        f"-DSINS_FW_READ_CYCLES={read_cycles}",
        f"-DSINS_FW_WRITE_CYCLES={write_cycles}",
    ]
    with atomic_path(out) as tmp, tempfile.TemporaryDirectory(prefix="sins-fw-build-") as work:
        language, firmware = firmware_arith.prepare(
            sources, float_mode, Path(work), [compiler, *flags], [include, cabi_include]
        )
        cmd = [
            compiler,
            *flags,
            "-shared",
            "-x",
            language,
            *map(str, firmware),
            "-x",
            "c++",
            str(FIRMWARE_C / "runtime" / "sins_fw_runtime.cpp"),
            "-x",
            "none",
            f"-L{libdir}",
            "-lsins_cabi",
            f"-Wl,-rpath,{libdir.resolve()}",
            "-Wl,--no-undefined",
            "-o",
            str(tmp),
        ]
        run = subprocess.run(cmd, capture_output=True, text=True, check=False)
        if run.returncode != 0:
            errors = [line for line in run.stderr.splitlines() if re.search(r"\berror\b", line)]
            quoted = "\n  ".join(errors[:QUOTED_ERRORS] or run.stderr.splitlines()[-QUOTED_ERRORS:])
            raise InputError(
                f"the firmware does not build as C++17 against the replacement headers:\n  {quoted}"
            )
    return Path(out)


@dataclass
class FirmwareRun:
    """A firmware run: where virtual time got to, how many register accesses were made, and the
    loaded library (its globals are read with :meth:`global_value`)."""

    library: ctypes.CDLL
    now_s: float
    accesses: int

    def global_value(self, name: str, ctype: type[ctypes._SimpleCData] = ctypes.c_uint16) -> int | float:
        """A global variable of the firmware, by name (default type: Uint16)."""
        try:
            return ctype.in_dll(self.library, name).value
        except ValueError:
            raise InputError(f"the firmware has no global `{name}`") from None


def run_firmware(
    library: str | os.PathLike[str],
    profile: str = "reference",
    overrides: Sequence[str] = (),
    *,
    until_s: float,
) -> FirmwareRun:
    """Run the built firmware's ``main`` on a board of ``profile`` until virtual time ``until_s`` (or
    until main returns). An emulator error (a register the model rejects) raises
    :class:`~sins_fw.errors.RegisterError`-family errors with the emulator's message. One run per
    library file and process: the firmware's globals are not reset between runs."""
    lib = ctypes.CDLL(str(Path(library).resolve()))
    lib.sins_fw_run.argtypes = [
        ctypes.c_char_p,
        ctypes.POINTER(ctypes.c_char_p),
        ctypes.c_size_t,
        ctypes.c_double,
        ctypes.c_char_p,
        ctypes.c_size_t,
    ]
    lib.sins_fw_now_ps.restype = ctypes.c_uint64
    lib.sins_fw_accesses.restype = ctypes.c_uint64
    args = (ctypes.c_char_p * max(1, len(overrides)))(*(o.encode() for o in overrides))
    message = ctypes.create_string_buffer(4096)
    rc = lib.sins_fw_run(profile.encode(), args, len(overrides), float(until_s), message, len(message))
    if rc != 0:
        raise InputError(f"{library}: {message.value.decode(errors='replace')}")
    return FirmwareRun(lib, lib.sins_fw_now_ps() / 1e12, int(lib.sins_fw_accesses()))
