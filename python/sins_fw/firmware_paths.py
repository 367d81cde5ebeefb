"""Where the C firmware's pieces are: the replacement headers and runtime (``firmware_c``), the C ABI
library and its header, and which files of a firmware are its sources. Below both the build
(:mod:`sins_fw.firmware_build`) and the arithmetic checks (:mod:`sins_fw.firmware_arith`), which
read them.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

from sins_fw.errors import ConfigError, InputError

#: The package's folder: in an installed wheel it holds ``firmware_c`` (the replacement headers, the
#: runtime, TI's replacements) and ``cabi`` (``libsins_cabi.so`` and ``sins_fw.h``); in the source tree
#: ``firmware_c`` links to the repository's and the C ABI library is cargo's.
PACKAGE = Path(__file__).resolve().parent
ROOT = PACKAGE.parents[1]
FIRMWARE_C = Path(os.environ.get("SINS_FW_C_DIR") or PACKAGE / "firmware_c").resolve()
CABI_LIBRARY = "libsins_cabi.so"
CABI_HEADER = "sins_fw.h"
SOURCE_SUFFIXES = (".c", ".cpp")


def cabi_dirs(root: Path = ROOT, package: Path = PACKAGE) -> tuple[Path, Path]:
    """The folders of the C ABI library (``libsins_cabi.so``) and of its header (``sins_fw.h``):

    1. ``$SINS_FW_CABI_DIR`` (the header beside the library, else the source tree's);
    2. in a source tree (``root`` holds ``rust/cabi``): cargo's ``$CARGO_TARGET_DIR/release`` or
       ``target/release``, the header ``rust/cabi/include``;
    3. in an installed wheel: the package's ``cabi`` folder, which holds both (``make wheel``).

    A missing library is a ConfigError saying where it was looked for and how to get it."""
    tree_header = root / "rust" / "cabi" / "include"
    env = os.environ.get("SINS_FW_CABI_DIR")
    if env:
        folder = Path(env)
        header = folder if (folder / CABI_HEADER).is_file() else tree_header
        where = "SINS_FW_CABI_DIR"
    elif (root / "rust" / "cabi" / "Cargo.toml").is_file():
        folder = Path(os.environ.get("CARGO_TARGET_DIR") or root / "target") / "release"
        header, where = tree_header, "the source tree's cargo target"
    else:
        folder = header = package / "cabi"
        where = "the installed package"
    if not (folder / CABI_LIBRARY).is_file():
        raise ConfigError(
            f"{folder / CABI_LIBRARY}: the C ABI library is missing ({where}); in the source tree build it "
            "with `cargo build --release -p sins-cabi`, or install a wheel built by `make wheel` (it ships "
            "the library), or set SINS_FW_CABI_DIR to its folder"
        )
    return folder, header


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
