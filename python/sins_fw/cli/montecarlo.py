"""`sins-fw montecarlo SCENARIO --runs N`: error distributions over seeded error-model realisations.

SCENARIO is a synthetic scenario (`sins-fw synth` names, with `--preset` and `--param key=value`)
or `published`: the reference design's ±30° indexing table and 30 s yaw-hold experiments, with
where each published value falls in the emulated distribution.
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

from tqdm import tqdm

from sins_fw import montecarlo as mc
from sins_fw import synth
from sins_fw.cli.common import add_json_option, add_profile_options, emit, exit_epilog, profile_from_args
from sins_fw.errors import InputError


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "montecarlo",
        help="attitude-error distributions over seeded sensor-error realisations",
        epilog=exit_epilog(None),
    )
    p.add_argument("scenario", help=f"`published` or a synth scenario: {', '.join(synth.SCENARIOS)}")
    p.add_argument("--runs", type=int, default=20, help="realisations per case (default 20)")
    p.add_argument("--workers", type=int, default=mc.default_workers(), help="processes (default: cores)")
    p.add_argument("--first-seed", type=int, default=1, help="seed of the first realisation (default 1)")
    p.add_argument("--preset", default=None, help="scenario preset (indexing-table: sweep, pm30, yaw25.8)")
    p.add_argument("--param", action="append", default=[], metavar="KEY=VALUE", help="scenario parameter")
    p.add_argument(
        "--errors", default="adis16407", help="error-model preset (errors.preset; default adis16407)"
    )
    add_profile_options(p)
    add_json_option(p)
    p.set_defaults(func=run)


def _params(items: list[str]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep:
            raise InputError(f"--param `{item}`: expected key=value")
        out[key.strip().replace("-", "_")] = value.strip()
    return out


def run(args: argparse.Namespace) -> int:
    if args.runs < 1:
        raise InputError(f"--runs {args.runs}: expected at least 1")
    if args.workers < 1:
        raise InputError(f"--workers {args.workers}: expected at least 1")
    profile = profile_from_args(args).with_overrides(f"errors.preset={args.errors}")
    if args.scenario == "published":
        cases = mc.published_cases()
    else:
        if args.scenario not in synth.SCENARIOS:
            raise InputError(
                f"unknown scenario `{args.scenario}`; known: published, {', '.join(synth.SCENARIOS)}"
            )
        params = synth.resolve(args.scenario, args.preset, **_params(args.param))
        cases = [mc.Case(args.scenario, args.scenario, None, tuple(params.items()), (0.0, 0.0, 0.0))]
    show = sys.stderr.isatty() and not args.json
    bar = tqdm(total=len(cases) * args.runs, disable=not show, unit="run", file=sys.stderr)

    def progress(done: int, total: int) -> None:
        bar.update(done - bar.n)

    try:
        dists = mc.run_cases(
            cases,
            args.runs,
            profile=profile,
            workers=args.workers,
            first_seed=args.first_seed,
            progress=progress,
        )
    finally:
        bar.close()
    report: dict[str, Any] = {
        "scenario": args.scenario,
        "runs": args.runs,
        "errors_preset": args.errors,
        "seeds": [args.first_seed, args.first_seed + args.runs - 1],
        "percentiles": list(mc.PERCENTILES),
        "cases": {
            name: {"solved_deg": d.percentiles("solved"), "error_deg": d.percentiles("error")}
            for name, d in dists.items()
        },
    }
    lines = [
        f"{args.scenario}: {args.runs} realisations of `{args.errors}` per case (seeds {report['seeds']})"
    ]
    if args.scenario == "published":
        rows = mc.published_report(dists)
        report["published"] = rows
        lines.append(f"{'case':<20}{'angle':<16}{'published':>10}  {'p5':>8} {'p50':>8} {'p95':>8}  rank")
        for r in rows:
            p = r["percentiles_deg"]
            lines.append(
                f"{r['case']:<20}{r['angle']:<16}{r['published_deg']:>10.3f}  "
                f"{p['p5']:>8.3f} {p['p50']:>8.3f} {p['p95']:>8.3f}  {r['published_rank']:5.1f} %"
            )
    else:
        for name, d in dists.items():
            for angle, p in d.percentiles("error").items():
                lines.append(
                    f"{name} {angle:<6} error °: p5 {p['p5']:+.4f}  p50 {p['p50']:+.4f}  p95 {p['p95']:+.4f}"
                )
    emit(args, report, "\n".join(lines))
    return 0
