"""`sins-fw presets [NAME]`: an error-model preset as a table, each value with its source."""

from __future__ import annotations

import argparse

from sins_fw import _core
from sins_fw.cli.common import add_json_option, emit, exit_epilog
from sins_fw.errors import ProfileError


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "presets", help="print a sensor error-model preset as a table with sources", epilog=exit_epilog(None)
    )
    p.add_argument("name", nargs="?", default="adis16407", help="preset name (default: adis16407)")
    add_json_option(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    names = list(_core.preset_names())
    if args.name not in names:
        raise ProfileError(f"unknown error-model preset `{args.name}`; known: {', '.join(names)}")
    rows = _core.preset_table(args.name)
    width = max((len(r["quantity"]) for r in rows), default=8)
    lines = [f"error-model preset `{args.name}` (* = unconfirmed for the ADIS16407: a sibling part's value)"]
    for r in rows:
        mark = "*" if r["unconfirmed"] else " "
        lines.append(f"{mark} {r['quantity']:<{width}}  {r['value']:>12.6g} {r['unit']:<12} {r['source']}")
    emit(args, {"preset": args.name, "rows": rows}, "\n".join(lines))
    return 0
