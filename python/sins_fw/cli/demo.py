"""`sins-fw demo`: the main job on the bundled traces; it grows as the emulator does."""

from __future__ import annotations

import argparse

from sins_fw import __version__
from sins_fw.cli.common import add_json_option, emit
from sins_fw.profile import load_profile


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("demo", help="emulate the reference profile on the bundled traces and summarise")
    add_json_option(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    profile = load_profile("reference")
    report = {
        "version": __version__,
        "profile": profile.source,
        "numeric": profile.get("firmware.numeric"),
        "algorithm": profile.get("firmware.algorithm"),
    }
    lines = [
        f"sins-fw {__version__} demo",
        f"profile: {profile.source} (algorithm {report['algorithm']}, numeric {report['numeric']})",
    ]
    emit(args, report, "\n".join(lines))
    return 0
