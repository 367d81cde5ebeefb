"""`sins-fw build-firmware SOURCES -o fw.so`: a user's F28335 C firmware, unmodified, built for the host
against the emulated board (sins_fw.firmware_build)."""

from __future__ import annotations

import argparse
from pathlib import Path

from sins_fw.cli.common import add_json_option, emit, exit_epilog
from sins_fw.firmware_arith import FLOAT_MODES, diagnose_int
from sins_fw.firmware_build import build_firmware, sources_of, with_ti_support


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
    p.add_argument(
        "--float",
        choices=FLOAT_MODES,
        default="host",
        dest="float_mode",
        help="the firmware's float and double: the host's IEEE types (default), or the C28x's 32-bit "
        "float with the c28x-f32 backend's operations (docs/c-arithmetic.md)",
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
    sources = sources_of(args.sources)
    findings = diagnose_int(args.sources) if args.diagnose_int else []
    out = build_firmware(args.sources, args.out, float_mode=args.float_mode)
    _, replaced = with_ti_support(sources)
    text = f"built {out} from {len(sources)} source(s), float mode {args.float_mode}"
    if replaced:
        text += f"\nTI's {', '.join(replaced)} left out: their host replacements (firmware_c/ti) stand in"
    if args.diagnose_int:
        text += f"\n16-bit int check: {len(findings)} conversion(s) that lose bits on the C28x"
        text += "".join(f"\n  {f}" for f in findings)
    result = {
        "output": str(out),
        "sources": [str(s) for s in sources],
        "float_mode": args.float_mode,
        "replaced_ti_sources": replaced,
    }
    if args.diagnose_int:
        result["int16_conversions"] = findings
    emit(args, result, text)
    return 0
