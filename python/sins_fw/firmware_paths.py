"""Where the C firmware's pieces are: the replacement headers and runtime (``firmware_c``), the C ABI
library and its header, and which files of a firmware are its sources. Below both the build
(:mod:`sins_fw.firmware_build`) and the arithmetic checks (:mod:`sins_fw.firmware_arith`), which
read them.
"""

from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from sins_fw.errors import ConfigError, InputError

#: The package's folder: in an installed wheel it holds ``firmware_c`` (the replacement headers, the
#: runtime, the pass, TI's replacements) and ``cabi`` (``libsins_cabi.so`` and ``sins_fw.h``); in the
#: source tree ``firmware_c`` links to the repository's and the C ABI library is cargo's.
PACKAGE = Path(__file__).resolve().parent
ROOT = PACKAGE.parents[1]
FIRMWARE_C = Path(os.environ.get("SINS_FW_C_DIR") or PACKAGE / "firmware_c").resolve()
CABI_LIBRARY = "libsins_cabi.so"
CABI_HEADER = "sins_fw.h"
C_SUFFIXES = (".c",)
CXX_SUFFIXES = (".cpp", ".cc", ".cxx", ".C")
SOURCE_SUFFIXES = C_SUFFIXES + CXX_SUFFIXES
#: Files of a TI project that are not compiled, each reported in one line: TI's assembly (the runtime
#: provides DSP28x_usDelay, ADC_cal, SetDBGIER; the code start branch and the CSM passwords mean
#: nothing on the host) and the linker command files (the link places the register files itself).
SKIPPED_SUFFIXES = {
    ".asm": "assembly: not compiled (the runtime provides TI's DSP28x_usDelay, ADC_cal and SetDBGIER)",
    ".s": "assembly: not compiled (the runtime provides TI's DSP28x_usDelay, ADC_cal and SetDBGIER)",
    ".cmd": "linker command file: not used (the link places TI's register files at their addresses)",
    ".lib": "C28x library: not linked (IQmath is the replacement IQmathLib.h's)",
}


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


@dataclass
class Project:
    """What a build compiles: the sources, the files named and skipped (each with why), the include
    folders and the macro definitions (``NAME`` or ``NAME=VALUE``) of the project."""

    sources: list[Path] = field(default_factory=list)
    skipped: list[tuple[Path, str]] = field(default_factory=list)
    include: list[Path] = field(default_factory=list)
    defines: list[str] = field(default_factory=list)

    def add_file(self, f: Path) -> None:
        if f.suffix in SOURCE_SUFFIXES:
            if f not in self.sources:
                self.sources.append(f)
        elif f.suffix.lower() in SKIPPED_SUFFIXES and all(f != s for s, _ in self.skipped):
            self.skipped.append((f, SKIPPED_SUFFIXES[f.suffix.lower()]))


#: Folders of a CCS project that hold build output, never sources.
_BUILD_FOLDERS = {"Debug", "Release", "Flash", "RAM", "CPU1_RAM", "CPU1_FLASH", "targetConfigs"}


def read_project(paths: Sequence[str | os.PathLike[str]]) -> Project:
    """The project of the inputs: a source file as given (``.c``, ``.cpp``; ``.asm``, ``.cmd`` named
    and skipped), a folder's sources (not recursive), or a CCS project (its ``.project`` or
    ``.cproject``, or a folder holding a ``.project``): the sources of its folder and subfolders (not
    the build folders) and the linked resources of ``.project``, the include paths and predefined
    symbols of ``.cproject``'s compiler options. A missing input or a project that cannot be read is
    an :class:`~sins_fw.errors.InputError` naming it."""
    project = Project()
    for p in map(Path, paths):
        if p.is_dir() and (p / ".project").is_file():
            _read_ccs(p, project)
        elif p.is_dir():
            for f in sorted(p.iterdir()):
                if f.is_file():
                    project.add_file(f)
        elif p.is_file() and p.name in (".project", ".cproject"):
            _read_ccs(p.parent, project)
        elif p.is_file():
            if p.suffix not in SOURCE_SUFFIXES and p.suffix.lower() not in SKIPPED_SUFFIXES:
                raise InputError(
                    f"{p}: not a C or C++ source (*.c, *.cpp), TI assembly (*.asm) or CCS project"
                )
            project.add_file(p)
        else:
            raise InputError(f"{p}: no such file or folder")
    if not project.sources:
        raise InputError(f"{', '.join(map(str, paths))}: no C sources (*.c, *.cpp) there")
    return project


def sources_of(paths: Sequence[str | os.PathLike[str]]) -> list[Path]:
    """The C/C++ sources of the inputs (:func:`read_project`)."""
    return read_project(paths).sources


def _ccs_path(text: str, project_dir: Path) -> Path | None:
    """A path of a CCS project file with its variables resolved (``PROJECT_LOC``, ``PROJECT_ROOT``,
    ``PARENT-n-PROJECT_LOC``, ``${...}`` of those); None when it names a variable of the user's
    machine (the TI tools' folders, whose headers the build replaces)."""
    text = text.strip().strip('"')
    text = re.sub(r"\$\{(PROJECT_LOC|PROJECT_ROOT|ProjDirPath)\}", str(project_dir).replace("\\", "/"), text)
    m = re.match(r"^(?:\$\{)?PARENT-(\d+)-PROJECT_LOC\}?(.*)$", text)
    if m:
        base = project_dir
        for _ in range(int(m.group(1))):
            base = base.parent
        text = str(base) + m.group(2)
    text = re.sub(r"^(PROJECT_LOC|PROJECT_ROOT)", str(project_dir), text)
    if "${" in text or text.startswith("$"):
        return None
    path = Path(text.replace("\\", "/"))
    return path if path.is_absolute() else project_dir / path


def _same_folder_in(project_dir: Path, missing: Path) -> Path | None:
    """A folder of the project whose last two names are those of an include path that is not on
    this machine (``C:\\ti\\controlSUITE\\device_support\\f2833x\\v140\\DSP2833x_headers\\include``, a
    copy of which the project keeps as ``DSP2833x_headers/include``); None when there is none or more
    than one."""
    tail = [part.lower() for part in re.split(r"[\\/]+", str(missing)) if part][-2:]
    if len(tail) < 2:
        return None
    found = [
        d
        for d in project_dir.rglob(missing.name if missing.name else "*")
        if d.is_dir() and [d.parent.name.lower(), d.name.lower()] == tail
    ]
    return found[0] if len(found) == 1 else None


def _read_ccs(folder: Path, project: Project) -> None:
    dot_project = folder / ".project"
    for f in sorted(folder.rglob("*")):
        rel = f.relative_to(folder).parts
        if f.is_file() and not any(part.startswith(".") or part in _BUILD_FOLDERS for part in rel[:-1]):
            project.add_file(f)
    if dot_project.is_file():
        try:
            root = ET.parse(dot_project).getroot()
        except (ET.ParseError, OSError) as e:
            raise InputError(f"{dot_project}: not a CCS project file ({e})") from e
        for link in root.iter("link"):
            location = link.findtext("location") or link.findtext("locationURI") or ""
            target = _ccs_path(
                location.removeprefix("file:/") if location.startswith("file:/") else location, folder
            )
            if target is None:
                continue
            if target.is_dir():
                for f in sorted(target.iterdir()):
                    if f.is_file():
                        project.add_file(f)
            elif target.is_file():
                project.add_file(target)
            else:
                raise InputError(f"{dot_project}: linked resource {location}: no such file ({target})")
    cproject = folder / ".cproject"
    if cproject.is_file():
        try:
            root = ET.parse(cproject).getroot()
        except (ET.ParseError, OSError) as e:
            raise InputError(f"{cproject}: not a CCS build settings file ({e})") from e
        # The first configuration's compiler options (CCS lists Debug first; the others repeat them).
        config = next(root.iter("configuration"), root)
        for option in config.iter("option"):
            kind = (option.get("superClass") or "") + " " + (option.get("id") or "")
            values = [v.get("value") or "" for v in option.iter("listOptionValue")]
            if "INCLUDE_PATH" in kind:
                for v in values:
                    path = _ccs_path(v, folder)
                    if path is not None and not path.is_dir():
                        path = _same_folder_in(folder, path)
                    if path is not None and path.is_dir() and path not in project.include:
                        project.include.append(path)
            elif "DEFINE" in kind and "compilerID" in kind:
                for v in values:
                    v = v.strip().strip('"')
                    if v and v not in project.defines:
                        project.defines.append(v)
