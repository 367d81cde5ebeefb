"""`sins-fw build-firmware SOURCES -o fw.so`: a user's F28335 C firmware, unmodified, built for the host
against the emulated board (sins_fw.firmware_build)."""

from __future__ import annotations

import argparse
from pathlib import Path

from sins_fw.cli.common import add_json_option, emit, exit_epilog
from sins_fw.firmware_build import build_firmware, sources_of


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "build-firmware",
        help="compile an F28335 C firmware, unmodified, for the host against the emulated board",
        epilog=exit_epilog(None),
    )
    p.add_argument("sources", nargs="+", help="C source files or folders (their *.c, *.cpp)")
    p.add_argument(
        "--out",
        "-o",
        type=Path,
        metavar="FILE.so",
        required=True,
        help="the shared library to write (e.g. fw.so)",
    )
    add_json_option(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    sources = sources_of(args.sources)
    out = build_firmware(args.sources, args.out)
    emit(
        args,
        {"output": str(out), "sources": [str(s) for s in sources]},
        f"built {out} from {len(sources)} source(s)",
    )
    return 0
