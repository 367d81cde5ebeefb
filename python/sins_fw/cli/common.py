"""Options and output shared by the subcommands."""

from __future__ import annotations

import argparse
import json
import math
from typing import Any

from sins_fw.profile import Profile, load_profile


def add_profile_options(p: argparse.ArgumentParser) -> None:
    """`--profile P` and repeatable `--set key=value`."""
    p.add_argument("--profile", default="reference", help="profile name or path (default: reference)")
    p.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="override one profile field for this run (repeatable), e.g. --set spi.spibrr=9",
    )


def add_json_option(p: argparse.ArgumentParser) -> None:
    """`--json`: print one JSON object on stdout and nothing else."""
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout (for scripts and CI)")


def profile_from_args(args: argparse.Namespace) -> Profile:
    return load_profile(args.profile, args.overrides)


def _jsonable(x: Any) -> Any:
    if isinstance(x, float) and not math.isfinite(x):
        return None
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_jsonable(v) for v in x]
    if hasattr(x, "tolist"):
        return _jsonable(x.tolist())
    return x


def emit(args: argparse.Namespace, report: dict[str, Any], text: str) -> None:
    """Print the report as JSON (with --json) or as human-readable text."""
    if getattr(args, "json", False):
        print(json.dumps(_jsonable(report), indent=None, sort_keys=False, allow_nan=False))
    else:
        print(text)
