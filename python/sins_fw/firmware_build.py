"""Build a user's F28335 C firmware, unmodified, for the host against the emulated board, and run it.

The sources are compiled as C++17 by the host's ``g++`` with the replacement DSP2833x headers of
``firmware_c/include`` first on the include path and ``sins_fw_prelude.h`` force-included (TI's
``interrupt``, ``cregister``, ``EALLOW``/``EDIS``, ``EINT``, ``asm``, ``void main``). Each register
access of TI's register-file objects (``SpiaRegs.SPICCR.bit.SPISWRESET = 0``) becomes a call into the
emulated board at its C28x address, a bit-field store a read-modify-write of the whole 16-bit word,
each access charged the cycles of ``firmware_model/c28x-costs.toml`` ``[io]``. The result is a shared
library linked against the C ABI library (``rust/cabi``), which :mod:`sins_fw.firmware_run` runs on a
trace.

Modelled: SPI-A, the GPIO data registers, LOSPCP, CPU timer 0, the PIE, the CPU's IER/IFR/INTM and
EALLOW (docs/c-drivers.md). The firmware's ``float``/``double`` are the host's or the C28x's
(``float_mode``), IQmathLib.h is the ``iq`` backend's (sins_fw.firmware_arith, docs/c-arithmetic.md).
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import tempfile
from collections.abc import Sequence
from pathlib import Path

from sins_fw import firmware_arith
from sins_fw.atomic import atomic_path
from sins_fw.errors import ConfigError, InputError
from sins_fw.firmware_paths import CABI_HEADER as CABI_HEADER
from sins_fw.firmware_paths import CABI_LIBRARY as CABI_LIBRARY
from sins_fw.firmware_paths import FIRMWARE_C, cabi_dirs, sources_of
from sins_fw.firmware_paths import PACKAGE as PACKAGE

#: The host replacements of TI's support sources (DSP2833x_common/source), linked into every firmware.
TI_SUPPORT = FIRMWARE_C / "ti"
#: TI's support sources that cannot build on the host (Uint32-pointer copies of the vector table,
#: registers the emulator does not model): a firmware source of one of these names is left out, the
#: replacement of the same name stands in (firmware_c/ti/README.md).
REPLACED_TI_SOURCES = (
    "DSP2833x_CpuTimers.c",
    "DSP2833x_GlobalVariableDefs.c",
    "DSP2833x_PieVect.c",
    "DSP2833x_Spi.c",
    "DSP2833x_SysCtrl.c",
)
#: How many of the compiler's error lines a build error quotes.
QUOTED_ERRORS = 5


def cabi_library_dir() -> Path:
    """The folder of ``libsins_cabi.so`` (:func:`cabi_dirs`)."""
    return cabi_dirs()[0]


def with_ti_support(sources: Sequence[Path]) -> tuple[list[Path], list[str]]:
    """The firmware's sources plus the host replacements of TI's support sources (``firmware_c/ti``),
    and the names of the firmware's own copies of TI's sources that are left out for them
    (:data:`REPLACED_TI_SOURCES`). The replacements' definitions are weak: a firmware's own
    ``InitPieCtrl`` or ``TINT0_ISR`` (its own copy of TI's DSP2833x_PieCtrl.c or DSP2833x_DefaultIsr.c,
    which build on the host) takes the place of the replacement's."""
    kept = [s for s in sources if s.name not in REPLACED_TI_SOURCES]
    replaced = sorted({s.name for s in sources if s.name in REPLACED_TI_SOURCES})
    return kept + sorted(TI_SUPPORT.glob("*.c")), replaced


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
    (file:line); ``out`` is then left as it was.

    The firmware's own sources are compiled with ``-fsanitize-coverage=trace-pc``: the compiler calls
    the runtime at every basic block, which charges the block's time and lets interrupts in there,
    so that straight-line code and loops without register access take interrupts (the runtime's
    header comment says how); the idle ``for (;;) {}``, which GCC leaves uninstrumented, gets the
    call added in the assembly (:func:`instrument_self_jumps`). ``-g`` keeps the sources' lines, for
    the error that names a loop that can never end. The runtime is compiled without the
    instrumentation.

    TI's support sources (``InitSysCtrl``, ``InitPieCtrl``, ``InitPieVectTable``, ``InitCpuTimers``,
    ``ConfigCpuTimer``, the default ISRs, ...) come from their host replacements
    (:func:`with_ti_support`), so a TI-style project links as it is."""
    sources, _ = with_ti_support(sources_of(paths))
    firmware_arith.check_float_mode(float_mode)
    if shutil.which(compiler) is None:
        raise ConfigError(f"`{compiler}` not found: a host C++ compiler is needed (Debian: build-essential)")
    libdir, cabi_include = cabi_dirs()
    include = FIRMWARE_C / "include"
    folders = sorted({str(s.parent) for s in sources if s.parent != TI_SUPPORT})
    common = [
        compiler,
        "-std=c++17",
        "-O1",
        "-g",
        "-fPIC",
        "-include",
        str(include / "sins_fw_prelude.h"),
        *firmware_arith.flags(float_mode, include),
        f"-I{include}",
        *(f"-I{d}" for d in folders),
        f"-I{cabi_include}",
    ]
    with atomic_path(out) as tmp, tempfile.TemporaryDirectory(prefix="sins-fw-build-") as work:
        language, firmware = firmware_arith.prepare(
            sources, float_mode, Path(work), common, [include, cabi_include]
        )
        objects = []
        for i, src in enumerate(firmware):
            tmp_asm = Path(work) / f"{i}_{Path(src).stem}.s"
            _compile(
                [*common, "-fsanitize-coverage=trace-pc", "-x", language, "-S", str(src), "-o", str(tmp_asm)]
            )
            tmp_asm.write_text(instrument_self_jumps(tmp_asm.read_text(encoding="utf-8")), encoding="utf-8")
            objects.append(tmp_asm.with_suffix(".o"))
            _compile([compiler, "-c", str(tmp_asm), "-o", str(objects[-1])])
        runtime = Path(work) / "sins_fw_runtime.o"
        _compile([*common, "-c", str(FIRMWARE_C / "runtime" / "sins_fw_runtime.cpp"), "-o", str(runtime)])
        _compile(
            [
                compiler,
                "-shared",
                *map(str, objects),
                str(runtime),
                f"-L{libdir}",
                "-lsins_cabi",
                f"-Wl,-rpath,{libdir.resolve()}",
                "-Wl,--no-undefined",
                "-ldl",
                "-o",
                str(tmp),
            ]
        )
    return Path(out)


#: A label and, after only directives, an unconditional jump to itself: an empty endless loop.
_SELF_JUMP = re.compile(r"^(\.L\w+):\n((?:\s*\.[^\n]*\n)*)(\s*)jmp\s+\1\n", re.MULTILINE)


def instrument_self_jumps(assembly: str) -> str:
    """Add a call to the runtime's ``sins_fw_idle`` to each jump to itself in the compiler's assembly.

    GCC's ``-fsanitize-coverage=trace-pc`` instruments a block by calling the runtime at its first
    instruction; the block of an empty endless loop (``for (;;) {}``, ``while (1);``) has no
    instruction but its jump, and GCC leaves it out, so the idle loop would never reach the runtime
    and no interrupt could come. The call goes before that jump: the loop never ends, so no register
    it might clobber is used again, and the stack is as at the function's own first call. Knowing
    the loop empty, the runtime moves time straight to the next interrupt (the passes' time, in whole
    passes), or stops the run when none can come."""
    return _SELF_JUMP.sub(r"\1:\n\2\3call\tsins_fw_idle@PLT\n\3jmp\t\1\n", assembly)


def _compile(cmd: list[str]) -> None:
    """Run the compiler; its errors (file:line) become an InputError."""
    run = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if run.returncode != 0:
        errors = [line for line in run.stderr.splitlines() if re.search(r"\berror\b", line)]
        quoted = "\n  ".join(errors[:QUOTED_ERRORS] or run.stderr.splitlines()[-QUOTED_ERRORS:])
        raise InputError(f"the firmware does not build as C++17 against the replacement headers:\n  {quoted}")
