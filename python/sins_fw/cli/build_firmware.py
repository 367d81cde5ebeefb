"""`sins-fw build-firmware SOURCES -o fw.so`: a user's F28335 firmware (C or C++ sources, folders, or a
CCS project), unmodified, built for the host against the emulated board (sins_fw.firmware_build)."""

from __future__ import annotations

import argparse
from collections.abc import Iterator, Sequence
from pathlib import Path

from sins_fw.cli.common import add_json_option, emit, exit_epilog
from sins_fw.errors import SinsError
from sins_fw.firmware_arith import FLOAT_MODES, diagnose_int
from sins_fw.firmware_build import OPT_LEVELS, build_firmware, included_headers, with_ti_support
from sins_fw.firmware_paths import read_project, sources_of
from sins_fw.profile import load_profile


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "build-firmware",
        help="compile an F28335 firmware (C, C++, a CCS project), unmodified, for the host against the "
        "emulated board",
        epilog=exit_epilog(None),
    )
    p.add_argument(
        "sources",
        nargs="+",
        help="C/C++ source files, folders (their *.c, *.cpp), or a CCS project (.project, .cproject or its "
        "folder); TI's *.asm and *.cmd files are named and skipped",
    )
    p.add_argument(
        "--out",
        "-o",
        type=Path,
        metavar="FILE.so",
        required=True,
        help="the shared library to write (e.g. fw.so)",
    )

    def repeatable(flag: str, dest: str, metavar: str, what: str) -> None:
        p.add_argument(
            flag, dest=dest, action="append", default=[], metavar=metavar, help=f"{what} (repeatable)"
        )

    repeatable(
        "-I", "include", "DIR", "an include folder, searched before the project's and the replacement headers"
    )
    repeatable("-D", "defines", "NAME[=VALUE]", "a macro definition, as the compiler's -D")
    p.add_argument(
        "--profile",
        default="reference",
        help="the board profile whose [clocks] define TI's DSP28_PLLCR, DSP28_DIVSEL, CPU_FRQ_150MHZ and "
        "CPU_RATE (default: reference)",
    )
    p.add_argument(
        "--float",
        choices=FLOAT_MODES,
        default="host",
        dest="float_mode",
        help="the firmware's float and double: the host's IEEE types (default), or the C28x's 32-bit "
        "float with the c28x-f32 backend's operations (docs/c-arithmetic.md)",
    )
    p.add_argument(
        "--opt-level",
        choices=list(OPT_LEVELS),
        default="2",
        help="the optimisation the build's C28x cycles are those of, as cl2000's --opt_level: 2 (default; "
        "the host compiler's -O1) or off (its -O0: every variable in memory, no inlining, as a CCS "
        "Debug build) (docs/c-cycles.md)",
    )
    p.add_argument(
        "--diagnose-int",
        action="store_true",
        help="also list the implicit conversions that lose bits where int is 16-bit, as on the C28x "
        "(a compile with int as short and the compiler's conversion warnings)",
    )
    add_json_option(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    project = read_project(args.sources)
    profile = load_profile(args.profile)
    findings = diagnose_int(args.sources) if args.diagnose_int else []
    out = build_firmware(
        args.sources,
        args.out,
        float_mode=args.float_mode,
        include=args.include,
        defines=args.defines,
        profile=profile,
        opt_level=args.opt_level,
    )
    _, replaced = with_ti_support(project.sources, [*args.include, *project.include])
    text = f"built {out} from {len(project.sources)} source(s), float mode {args.float_mode}"
    for path, why in project.skipped:
        text += f"\nskipped {path}: {why}"
    if replaced:
        text += f"\nTI's {', '.join(replaced)} left out: their host replacements (firmware_c/ti) stand in"
    if args.diagnose_int:
        text += f"\n16-bit int check: {len(findings)} conversion(s) that lose bits on the C28x"
        text += "".join(f"\n  {f}" for f in findings)
    result = {
        "output": str(out),
        "sources": [str(s) for s in project.sources],
        "skipped": [{"path": str(p), "why": why} for p, why in project.skipped],
        "include": [str(i) for i in [*args.include, *project.include]],
        "defines": [*args.defines, *project.defines],
        "float_mode": args.float_mode,
        "opt_level": args.opt_level,
        "replaced_ti_sources": replaced,
    }
    if args.diagnose_int:
        result["int16_conversions"] = findings
    emit(args, result, text)
    return 0


def firmware_inputs(args: argparse.Namespace, paths: Sequence[Path]) -> Iterator[tuple[str, Path]]:
    """Every file a build of ``paths`` with ``args``' options reads, named for a message: the files and
    folders given, the sources found in them, the headers the sources include (the build's own
    listing: :func:`sins_fw.firmware_build.included_headers`) and ``globals.toml`` beside them (the
    watched globals `run --firmware` reads)."""
    yield from (("SOURCES", p) for p in paths)
    try:
        sources = sources_of(paths)
    except SinsError:
        return  # the build says what is missing
    yield from (("a source", s) for s in sources)
    folders = sorted({s.parent for s in sources})
    yield from (("the globals file", f / "globals.toml") for f in folders if (f / "globals.toml").is_file())
    try:
        profile = load_profile(getattr(args, "profile", "reference"))
    except SinsError:
        return  # the build says what is wrong with it
    headers = included_headers(
        paths,
        getattr(args, "float_mode", "host"),
        getattr(args, "include", ()),
        getattr(args, "defines", ()),
        profile,
    )
    yield from (("a header the sources include", h) for h in headers)
