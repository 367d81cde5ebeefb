"""The arithmetic of a host-built firmware (sins_fw.firmware_build): plain host IEEE float, or the C28x's.

``float_mode="host"`` compiles the firmware's ``float`` and ``double`` as the host's (64-bit ``double``).
``float_mode="c28x"`` makes both the C28x's 32-bit float (TI's COFF ABI), every operation the
``c28x-f32`` backend's: each source, C or C++, is preprocessed, and on the firmware's own lines
``double`` (and ``long double``) becomes ``float`` and each floating literal ``x`` becomes
``((float)x)`` (the line markers keep the original file and line in every message), so that
``code * 0.05`` is a C28x single-precision multiplication; the build's LLVM pass
(``firmware_c/pass``) then makes every float operation, conversion and math-library call a call to
the backend (``sins_c28x_*`` of the C ABI).

:func:`diagnose_int` is the 16-bit ``int`` check: a shadow compile with ``int`` as a 16-bit ``short``
and the compiler's conversion warnings, which flag the implicit conversions that lose bits on the
C28x (docs/c-arithmetic.md).
"""

from __future__ import annotations

import os
import re
import subprocess
from collections.abc import Sequence
from pathlib import Path

from sins_fw.errors import InputError
from sins_fw.firmware_paths import FIRMWARE_C, cabi_dirs, sources_of

FLOAT_MODES = ("host", "c28x")

# One token of C source that matters here: a comment, a string or character literal (skipped), a
# preprocessing number (C11 6.4.8), or an identifier (so that digits inside names are not numbers).
_TOKEN = re.compile(
    r"""(?P<skip>//[^\n]*|/\*.*?\*/|"(?:\\.|[^"\\\n])*"|'(?:\\.|[^'\\\n])*')
      |(?P<number>\.?\d(?:[eEpP][+-]|[\w.])*)
      |[A-Za-z_]\w*""",
    re.S | re.X,
)


def _is_floating(number: str) -> bool:
    """A floating constant (decimal with a point or an exponent, or hexadecimal with ``p``)."""
    if number[:2].lower() == "0x":
        return "p" in number.lower()
    return "." in number or "e" in number.lower()


def rewrite_literals(text: str) -> str:
    """``text`` with each floating literal ``x`` (outside comments and strings) as ``((float)x)``,
    each ``long double`` and ``double`` as ``float``; everything else, line breaks included,
    unchanged."""

    def replace(m: re.Match[str]) -> str:
        number = m.group("number")
        if number is not None and _is_floating(number):
            return f"((float){number})"
        if m.group(0) == "double":
            return "float"
        return m.group(0)

    return _LONG_FLOAT.sub("float", _TOKEN.sub(replace, text))


_LONG_FLOAT = re.compile(r"\blong\s+float\b")


# A line marker of the preprocessor's output: `# LINE "FILE" FLAGS` (flag 3: a system header).
_LINE_MARKER = re.compile(r'^# \d+ "((?:\\.|[^"\\])*)"((?: \d)*)$')


def rewrite_preprocessed(text: str, ours: Sequence[Path]) -> str:
    """Preprocessed C++ ``text`` with the floating literals of the firmware's own lines rewritten
    (:func:`rewrite_literals`). Lines the line markers attribute to a system header, to a file under
    one of the folders ``ours`` (the replacement headers) or to the compiler's pseudo-files are left
    alone. A literal that a macro brings into the firmware's line (a header's ``#define SCALE 0.05``)
    is rewritten there, where it is used."""
    roots = [str(p.resolve()) + os.sep for p in ours]
    out: list[str] = []
    firmware = False
    for line in text.splitlines(keepends=True):
        marker = _LINE_MARKER.match(line.rstrip("\n"))
        if marker:
            name, marker_flags = marker.group(1), marker.group(2).split()
            path = "" if name.startswith("<") else os.path.abspath(name)
            firmware = bool(path) and "3" not in marker_flags and not any(path.startswith(r) for r in roots)
            out.append(line)
        else:
            out.append(rewrite_literals(line) if firmware else line)
    return "".join(out)


def check_float_mode(float_mode: str) -> None:
    if float_mode not in FLOAT_MODES:
        raise InputError(f"float mode `{float_mode}`: expected one of {', '.join(FLOAT_MODES)}")


def flags(float_mode: str, include: Path) -> list[str]:
    """The compiler flags of ``float_mode`` (after the prelude's ``-include``). Both modes forbid
    contracting a × b + c into a fused multiply-add, which the firmware's C does not ask for and the
    emulator's backends do not do."""
    check_float_mode(float_mode)
    del include
    return ["-ffp-contract=off"]


def prepare_one(
    source: Path,
    cxx: bool,
    float_mode: str,
    workdir: Path,
    index: int,
    preprocess: Sequence[str],
    ours: Sequence[Path],
) -> tuple[Path, str]:
    """The file the compiler builds ``source`` from and its language (for ``-x``). Host mode: the
    source as it is. C28x mode: the source preprocessed by ``preprocess`` (the compiler and the
    build's flags) and rewritten (:func:`rewrite_preprocessed`, ``ours``: the replacement headers'
    folders) into ``workdir``. A source that does not preprocess raises
    :class:`~sins_fw.errors.InputError` quoting the compiler."""
    check_float_mode(float_mode)
    language = "c++" if cxx else "c"
    if float_mode == "host":
        return source, language
    cmd = [*preprocess, "-E", "-x", language, str(source)]
    run = subprocess.run(cmd, capture_output=True, check=False, env=c_locale())
    stderr = run.stderr.decode("utf-8", errors="replace")
    if run.returncode != 0:
        raise InputError("the firmware does not build:\n  " + "\n  ".join(_errors(stderr)))
    # A scratch file in the build's temporary folder (removed with it), not an output.
    tmp_source = workdir / f"{index}_{source.stem}{'.ii' if cxx else '.i'}"
    text = run.stdout.decode("utf-8", errors="surrogateescape")
    tmp_source.write_text(rewrite_preprocessed(text, ours), encoding="utf-8", errors="surrogateescape")
    return tmp_source, "c++-cpp-output" if cxx else "cpp-output"


def _errors(stderr: str, n: int = 5) -> list[str]:
    """The compiler's first ``n`` error lines (its last lines when none says "error")."""
    lines = stderr.splitlines()
    return [line for line in lines if re.search(r"\berror\b", line)][:n] or lines[-n:]


#: The conversion warnings the 16-bit ``int`` check asks for (float ↔ int ones are a separate matter).
INT_DIAGNOSTIC_FLAGS = ("-Wconversion", "-Wno-sign-conversion", "-Wno-float-conversion", "-Woverflow")


def diagnose_int(
    paths: Sequence[str | os.PathLike[str]], compiler: str = "g++", c_compiler: str = "gcc"
) -> list[str]:
    """The implicit conversions that lose bits where ``int`` is 16-bit, as the compiler's warnings
    (``file:line:column: warning: …``) for the firmware sources (files or folders): a syntax-only
    compile of each with ``int`` mapped to ``short`` (``sins_fw_int16.h``). An empty list: none found.
    A source that does not compile raises :class:`~sins_fw.errors.InputError` quoting the compiler."""
    sources = sources_of(paths)
    include = FIRMWARE_C / "include"
    folders = sorted({str(s.parent) for s in sources})
    findings: list[str] = []
    for s in sources:
        cxx = s.suffix != ".c"
        cmd = [
            compiler if cxx else c_compiler,
            "-std=gnu++17" if cxx else "-std=gnu11",
            "-fsyntax-only",
            "-Wno-unknown-pragmas",
            *INT_DIAGNOSTIC_FLAGS,
            "-include",
            str(include / "sins_fw_prelude.h"),
            "-include",
            str(include / "sins_fw_int16.h"),
            f"-I{include}",
            *(f"-I{d}" for d in folders),
            f"-I{cabi_dirs()[1]}",
            "-x",
            "c++" if cxx else "c",
            str(s),
        ]
        run = subprocess.run(cmd, capture_output=True, check=False, env=c_locale())
        stderr = run.stderr.decode("utf-8", errors="replace")
        if run.returncode != 0:
            message = "\n  ".join(_errors(stderr))
            raise InputError(f"the 16-bit int check could not compile the firmware:\n  {message}")
        findings += [line for line in stderr.splitlines() if ": warning: " in line]
    return findings


def c_locale() -> dict[str, str]:
    """The environment with the compiler's messages in English and plain quotes."""
    return {**os.environ, "LC_ALL": "C", "LANG": "C"}
