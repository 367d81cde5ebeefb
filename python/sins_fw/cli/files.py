"""Every file each command reads and writes, declared once, and the one check run before any command
does its work: no output may be one of the command's inputs, or another of its outputs.

Each subcommand's entry in :data:`FILES` names the options (argparse ``dest``) that give its inputs and
its outputs, and how each becomes the files behind it (:class:`Role`): a log folder is every file it
holds, a saved run also its recorded trace, a firmware's sources also the headers they include and the
globals file, a Monte Carlo table also its CSV copy and percentile tables. :func:`check` compares them
as the file system sees them (device and inode when the file exists: symlinks, hard links and ``..``
seen through; else the fully resolved path) and raises an InputError naming the option and the input.
``tests/test_output_safety.py`` walks every parser and fails on a file option that is not declared
here, so a new option is held to the rule too.
"""

from __future__ import annotations

import argparse
import contextlib
import os
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path

from sins_fw.atomic import check_output_folder, same_file
from sins_fw.errors import InputError, SinsError

#: A file (or folder) an option gives: (how to name it in a message, its path).
Named = tuple[str, Path]
#: How an option's value becomes the files behind it.
Expand = Callable[[argparse.Namespace, object], Iterable[Named]]

#: A folder input holding more entries than this is not walked further (a log folder holds far fewer;
#: a mistaken `/` must not make the check itself the long part).
MAX_TREE_FILES = 200_000


def _as_paths(value: object) -> list[Path]:
    if value is None:
        return []
    if isinstance(value, list | tuple):
        return [Path(v) for v in value if v is not None]
    return [Path(str(value))]


def plain(label: str) -> Expand:
    """The option's path (or paths) as it is."""
    return lambda _args, value: ((label, p) for p in _as_paths(value))


def tree(label: str) -> Expand:
    """A file as it is; a folder as every file it holds (recursively, symlinks followed to files)."""

    def expand(_args: argparse.Namespace, value: object) -> Iterator[Named]:
        for p in _as_paths(value):
            yield label, p
            if p.is_dir():
                yield from ((f"{label} {p}'s file", f) for f in walk_files(p))

    return expand


def walk_files(folder: Path) -> Iterator[Path]:
    """The files under ``folder`` (at most :data:`MAX_TREE_FILES`), without entering linked folders."""
    n = 0
    for root, _dirs, names in os.walk(folder):
        for name in names:
            n += 1
            if n > MAX_TREE_FILES:
                return
            yield Path(root) / name


@dataclass(frozen=True)
class Role:
    """One option of a command that names files: its ``dest`` and how its value expands."""

    dest: str
    expand: Expand


@dataclass(frozen=True)
class Files:
    """The inputs and outputs of one command."""

    inputs: tuple[Role, ...] = ()
    outputs: tuple[Role, ...] = ()
    #: Options that name a folder written into (checked by the command; listed so that the walk of the
    #: parsers knows them).
    folders: tuple[str, ...] = ()


# ---------------------------------------------------------------------------------------------------
# Expansions that need the command's knowledge
# ---------------------------------------------------------------------------------------------------


def _profile(args: argparse.Namespace, _value: object) -> Iterator[Named]:
    from sins_fw.cli.common import (
        profile_file,  # a command's module (it imports this one): read when its files are named
    )

    path = profile_file(args)
    if path is not None:
        yield "--profile", path


def _trace_or_run(label: str) -> Expand:
    """A trace, and when it is a saved run (`run --out`) the trace it records."""

    def expand(_args: argparse.Namespace, value: object) -> Iterator[Named]:
        for p in _as_paths(value):
            yield label, p
            recorded = _recorded_trace(p)
            if recorded is not None:
                yield f"{label}'s recorded trace", recorded
            globals_file = _recorded_globals(p)
            if globals_file is not None:
                yield f"{label}'s recorded globals file", globals_file

    return expand


def _recorded_globals(path: Path) -> Path | None:
    """The globals file a C firmware's run output records (read for its columns' units), if it exists."""
    from sins_fw.run_output import is_firmware_run  # heavy: only for a command that reads such files
    from sins_fw.traces import read_metadata  # heavy (numpy, the core)

    with contextlib.suppress(SinsError, OSError, ValueError):
        if is_firmware_run(path):
            written = read_metadata(path).get("globals")
            if written and Path(written).is_file():
                return Path(written)
    return None


def _recorded_trace(path: Path) -> Path | None:
    from sins_fw.run_output import (  # heavy (numpy, the core): only for a command that reads such files
        RUN_FORMAT,
        resolve_trace,
    )
    from sins_fw.traces import (
        read_metadata,  # heavy (numpy, the core): only for a command that reads such files
    )

    with contextlib.suppress(SinsError, OSError, ValueError, KeyError):
        if path.is_file():
            meta = read_metadata(path)
            if meta.get("format") == RUN_FORMAT:
                return Path(resolve_trace(path, meta))
    return None


def _rosbag(args: argparse.Namespace, value: object) -> Iterator[Named]:
    """A ROS 1 bag file, or a ROS 2 bag: its folder (a .db3/.mcap file in it stands for the folder)."""
    for p in _as_paths(value):
        if p.is_file() and p.suffix in (".db3", ".mcap"):
            yield from tree("FILE")(args, p.parent)
        yield from tree("FILE")(args, p)


def _firmware_globals(args: argparse.Namespace, value: object) -> Iterator[Named]:
    """`run --firmware FW.so`: the library, and the globals file read beside it when --globals is not
    given."""
    for p in _as_paths(value):
        yield "--firmware", p
        if getattr(args, "globals", None) is None:
            beside = p.with_name("globals.toml")
            if beside.is_file():
                yield "the globals file beside --firmware", beside


def _firmware_sources(args: argparse.Namespace, value: object) -> Iterator[Named]:
    """`build-firmware SOURCES`: the files and folders given, the sources found in the folders, the
    headers they include (the compiler's own dependency listing) and a globals file beside them."""
    from sins_fw.cli.build_firmware import (
        firmware_inputs,  # a command's module (it imports this one): read when its files are named
    )

    yield from firmware_inputs(args, _as_paths(value))


def _demo_recording(args: argparse.Namespace, value: object) -> Iterator[Named]:
    if value is not None and not getattr(args, "no_recording", False):
        yield "the recording", Path(str(value)) / "pitch_sweep.rrd"


def _demo_inputs(_args: argparse.Namespace, _value: object) -> Iterator[Named]:
    from sins_fw.cli.demo import (  # a command's module (it imports this one): read when its files are named
        TRACE_DIR,
        TRACES,
    )

    yield from ((f"bundled trace {name}", TRACE_DIR / name) for name in TRACES)


def _tables(args: argparse.Namespace, value: object) -> Iterator[Named]:
    """`montecarlo`/`sweep --out TABLE`: the table and the files written beside it."""
    from sins_fw.sweep import (  # heavy (numpy, the core): only for a command that reads such files
        FORMATS,
        table_files,
    )

    for p in _as_paths(value):
        if p.suffix.lower() in FORMATS:
            first, *beside = table_files(p)
            yield "--out", first
            yield from ((f"--out's {f.name}", f) for f in beside)
        else:
            yield "--out", p


_PROFILE = Role("profile", _profile)


def _out(dest: str = "out", option: str = "--out") -> Role:
    return Role(dest, plain(option))


#: The files of every subcommand, by its command line (as :func:`sins_fw.cli.common.walk_parsers`
#: names it, without ``sins-fw``).
FILES: dict[str, Files] = {
    "demo": Files(inputs=(Role("out_dir", _demo_inputs),), outputs=(Role("out_dir", _demo_recording),)),
    "run": Files(
        inputs=(
            Role("trace", _trace_or_run("TRACE")),
            _PROFILE,
            Role("firmware", _firmware_globals),
            Role("globals", plain("--globals")),
        ),
        outputs=(_out(), _out("raw_out", "--raw-out")),
    ),
    "board": Files(inputs=(_PROFILE,)),
    "budget": Files(
        inputs=(_PROFILE, Role("firmware", plain("--firmware"))), outputs=(_out("plot", "--plot"),)
    ),
    "parity": Files(
        inputs=(Role("traces", plain("TRACE")), _PROFILE, Role("thresholds", plain("--thresholds")))
    ),
    "replay": Files(inputs=(Role("trace", _trace_or_run("TRACE_OR_RUN")), _PROFILE), outputs=(_out(),)),
    "report": Files(inputs=(Role("trace", _trace_or_run("TRACE_OR_RUN")), _PROFILE), outputs=(_out(),)),
    "import broad": Files(inputs=(Role("file", plain("FILE")),), outputs=(_out(),)),
    "import trace": Files(inputs=(Role("file", plain("FILE")),), outputs=(_out(),)),
    "import ulog": Files(inputs=(Role("file", tree("FILE")),), outputs=(_out(),)),
    "import dataflash": Files(inputs=(Role("file", tree("FILE")),), outputs=(_out(),)),
    "import rosbag": Files(inputs=(Role("file", _rosbag),), outputs=(_out(),)),
    "import euroc": Files(
        inputs=(Role("file", tree("FILE")), Role("truth", plain("--truth"))), outputs=(_out(),)
    ),
    "presets": Files(),
    "montecarlo": Files(inputs=(_PROFILE,), outputs=(Role("out", _tables), _out("plot", "--plot"))),
    "sweep": Files(inputs=(_PROFILE,), outputs=(Role("out", _tables), _out("plot", "--plot"))),
    "spin-table": Files(),
    "synth": Files(outputs=(_out(),)),
    "bench": Files(outputs=(_out(),)),
    "broad-eval": Files(inputs=(Role("sources", tree("SOURCES")),)),
    "build-firmware": Files(
        inputs=(Role("sources", _firmware_sources), Role("include", tree("-I")), _PROFILE), outputs=(_out(),)
    ),
    "calibrate": Files(inputs=(Role("trace", plain("TRACE")),)),
}


def spec_of(command: str) -> Files | None:
    """The entry of ``command`` in :data:`FILES`: its own, or its parent's (`synth static` is
    `synth`'s: the scenarios share their options' meaning)."""
    words = command.split()
    while words:
        if " ".join(words) in FILES:
            return FILES[" ".join(words)]
        words.pop()
    return None


def files_of(
    command: str, args: argparse.Namespace, *, inputs: bool = True
) -> tuple[list[Named], list[Named]]:
    """The inputs (unless not ``inputs``) and outputs of ``command`` as ``args`` give them (options
    not given left out)."""
    spec = spec_of(command) or Files()

    def expand(roles: tuple[Role, ...]) -> list[Named]:
        found: list[Named] = []
        for role in roles:
            value = getattr(args, role.dest, None)
            if value is not None:
                found += list(role.expand(args, value))
        return found

    return expand(spec.inputs) if inputs else [], expand(spec.outputs)


def _holds(folder: Path, path: Path) -> bool:
    """Whether ``path`` lies under ``folder`` (both fully resolved)."""
    try:
        Path(os.path.realpath(path)).relative_to(os.path.realpath(folder))
    except ValueError:
        return False
    return True


def _stat_key(path: Path) -> tuple[int, int] | None:
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return None
    return st.st_dev, st.st_ino


def check(command: str, args: argparse.Namespace) -> None:
    """Refuse, before any work, an output of ``command`` that is one of its inputs (or a folder holding
    one), or that is another of its outputs: an InputError naming both options and paths."""
    _, outputs = files_of(command, args, inputs=False)
    if not outputs:
        return  # nothing written: the inputs (a log folder's files, ...) need not be listed
    inputs, _ = files_of(command, args)
    existing: dict[tuple[int, int], Named] = {}
    missing: dict[str, Named] = {}
    for named in inputs:
        key = _stat_key(named[1])
        if key is not None:
            existing.setdefault(key, named)
        else:
            missing.setdefault(os.path.realpath(named[1]), named)
    for i, (name, path) in enumerate(outputs):
        key = _stat_key(path)
        hit = existing.get(key) if key is not None else missing.get(os.path.realpath(path))
        if hit is not None:
            raise InputError(
                f"{name} {path} is the input {hit[0]} {hit[1]}: writing it would destroy the input; "
                "choose another output file"
            )
        if key is not None and path.is_dir():
            held = next((n for n in inputs if _holds(path, n[1])), None)
            if held is not None:
                raise InputError(
                    f"{name} {path} is a folder holding the input {held[0]} {held[1]}: expected the "
                    "name of a file to write (the input would be lost)"
                )
        for other, other_path in outputs[:i]:
            if same_file(path, other_path):
                raise InputError(
                    f"{name} {path} and {other} {other_path} are the same file: one output would "
                    "overwrite the other; choose two different files"
                )
    for name, path in outputs:
        # Missing folders are created when the file is written; the nearest that exists must take it.
        check_output_folder(path, name)
