"""The arithmetic of a host-built firmware (sins_fw.firmware_build): plain host IEEE float, or the C28x's.

``float_mode="host"`` compiles the firmware's ``float`` and ``double`` as the host's (64-bit ``double``).
``float_mode="c28x"`` makes both the C28x's 32-bit float (TI's COFF ABI), every operation the
``c28x-f32`` backend's (``firmware_c/include/sins_fw_c28x_float.h``): the header is force-included,
and each floating literal of the firmware's own sources and headers is rewritten into
``SINS_C28X_LITERAL(…)`` in a copy (``#line`` keeps the original file and line in every message), so
that ``code * 0.05`` is a C28x multiplication, not a host ``double`` one rounded afterwards.

:func:`diagnose_int` is the 16-bit ``int`` check: a shadow compile with ``int`` as a 16-bit ``short``
and the compiler's conversion warnings, which flag the implicit conversions that lose bits on the
C28x (docs/c-arithmetic.md).
"""

from __future__ import annotations

import os
import re
import subprocess
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from sins_fw.errors import InputError

FLOAT_MODES = ("host", "c28x")
HEADER_SUFFIXES = (".h", ".hpp")

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
    """``text`` with each floating literal ``x`` (outside comments and strings) as
    ``SINS_C28X_LITERAL(x)``; everything else, line breaks included, unchanged."""

    def replace(m: re.Match[str]) -> str:
        number = m.group("number")
        if number is not None and _is_floating(number):
            return f"SINS_C28X_LITERAL({number})"
        return m.group(0)

    return _TOKEN.sub(replace, text)


def _rewritten_copy(source: Path, target: Path) -> None:
    text = source.read_text(encoding="utf-8", errors="surrogateescape")
    target.parent.mkdir(parents=True, exist_ok=True)
    quoted = str(source.resolve()).replace("\\", "\\\\").replace('"', '\\"')
    target.write_text(
        f'#line 1 "{quoted}"\n' + rewrite_literals(text), encoding="utf-8", errors="surrogateescape"
    )


@dataclass
class Prepared:
    """What the compiler gets for one arithmetic mode: the sources, include folders to put before the
    firmware's own, and extra flags (after the prelude's ``-include``)."""

    sources: list[Path]
    include_dirs: list[Path] = field(default_factory=list)
    flags: list[str] = field(default_factory=list)


def check_float_mode(float_mode: str) -> None:
    if float_mode not in FLOAT_MODES:
        raise InputError(f"float mode `{float_mode}`: expected one of {', '.join(FLOAT_MODES)}")


def prepare(sources: Sequence[Path], float_mode: str, workdir: Path, include: Path) -> Prepared:
    """The sources, include folders and flags of ``float_mode``; the c28x mode writes its rewritten
    copies under ``workdir``. Both modes forbid contracting a × b + c into a fused multiply-add, which
    the firmware's C does not ask for and the emulator's backends do not do."""
    check_float_mode(float_mode)
    flags = ["-ffp-contract=off"]
    if float_mode == "host":
        return Prepared(list(sources), [], flags)
    copies: list[Path] = []
    for i, s in enumerate(sources):
        copy = workdir / "src" / f"{i}_{s.name}"
        _rewritten_copy(s, copy)
        copies.append(copy)
    # The firmware's own headers, rewritten likewise, found before the originals.
    mirrors: list[Path] = []
    for i, folder in enumerate(sorted({s.parent for s in sources})):
        mirror = workdir / f"inc{i}"
        for h in folder.rglob("*"):
            if h.suffix in HEADER_SUFFIXES and h.is_file():
                _rewritten_copy(h, mirror / h.relative_to(folder))
        mirrors.append(mirror)
    flags += ["-include", str(include / "sins_fw_c28x_float.h")]
    return Prepared(copies, mirrors, flags)


#: The conversion warnings the 16-bit ``int`` check asks for (float ↔ int ones are a separate matter).
INT_DIAGNOSTIC_FLAGS = ("-Wconversion", "-Wno-sign-conversion", "-Wno-float-conversion", "-Woverflow")


def diagnose_int(paths: Sequence[str | os.PathLike[str]], compiler: str = "g++") -> list[str]:
    """The implicit conversions that lose bits where ``int`` is 16-bit, as the compiler's warnings
    (``file:line:column: warning: …``) for the firmware sources (files or folders): a syntax-only
    compile of each with ``int`` mapped to ``short`` (``sins_fw_int16.h``). An empty list: none found.
    A source that does not compile raises :class:`~sins_fw.errors.InputError` quoting the compiler."""
    from sins_fw.firmware_build import FIRMWARE_C, ROOT, sources_of

    sources = sources_of(paths)
    include = FIRMWARE_C / "include"
    folders = sorted({str(s.parent) for s in sources})
    findings: list[str] = []
    for s in sources:
        cmd = [
            compiler,
            "-std=c++17",
            "-fsyntax-only",
            *INT_DIAGNOSTIC_FLAGS,
            "-include",
            str(include / "sins_fw_prelude.h"),
            "-include",
            str(include / "sins_fw_int16.h"),
            f"-I{include}",
            *(f"-I{d}" for d in folders),
            f"-I{ROOT / 'rust' / 'cabi' / 'include'}",
            "-x",
            "c++",
            str(s),
        ]
        run = subprocess.run(cmd, capture_output=True, text=True, check=False, env=_c_locale())
        lines = run.stderr.splitlines()
        if run.returncode != 0:
            errors = [line for line in lines if re.search(r"\berror\b", line)][:5]
            raise InputError(
                "the 16-bit int check could not compile the firmware:\n  " + "\n  ".join(errors or lines[-5:])
            )
        findings += [line for line in lines if ": warning: " in line]
    return findings


def _c_locale() -> dict[str, str]:
    """The environment with the compiler's messages in English and plain quotes."""
    return {**os.environ, "LC_ALL": "C", "LANG": "C"}
