"""`sins-fw montecarlo SCENARIO --runs N`: error distributions over seeded error-model realisations.

SCENARIO is a synthetic scenario (`sins-fw synth` names, with `--preset` and `--param key=value`)
or `published`: the reference design's ±30° indexing table and 30 s yaw-hold experiments, with
where each published value falls in the emulated distribution.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from sins_fw import montecarlo as mc
from sins_fw import sweep, synth
from sins_fw.cli.common import (
    add_engine_options,
    add_json_option,
    add_out_option,
    add_plot_option,
    add_profile_options,
    add_runs_options,
    check_png,
    deprecated,
    emit,
    engine_from_args,
    exit_epilog,
    profile_from_args,
    run_progress,
)
from sins_fw.errors import InputError

#: What the numbers mean, shown by `--help`.
EXPLAINED = """\
error: the board's attitude estimate against the scenario's truth at the last attitude step, in
  degrees, after the alignment every report uses (a board that starts from Q = [1, 0, 0, 0] is
  compared relative to the attitude it was switched on at). pitch, roll and yaw are the differences
  of the Euler angles (yaw wrapped to ±180°); total is the angle of the rotation between estimate and
  truth, heading its part about the vertical, inclination its tilt part (the BROAD definitions).
alpha (the wing unit, firmware.algorithm = "wing"): its hinge angle α against the trace's truth
  instead: final (α − truth at the last step), static_max and dynamic_max (the largest |α − truth|
  over the still and the moving steps); no attitude error (its quaternion is the wing's own frame).
percentiles: p5 … p95 over the runs; with fewer than 20 runs p5 and p95 are the sample's extremes
  (a warning says so).
rank (published only): where the published value falls among the emulated solved angles, in percent
  of the runs below it (ties count half): 50 % is the median run, 2 % or 98 % means the published value
  is outside almost every emulated realisation.
--out writes one row per run (Parquet, HDF5 or CSV by suffix, always with a CSV copy) and the
percentiles beside it; --plot draws the error over time as percentile bands and the errors at the end
as histograms."""


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "montecarlo",
        help="attitude-error distributions over seeded sensor-error realisations",
        description="Attitude-error distributions over seeded sensor-error realisations: the same "
        "scenario and board, one run per seed of the error model.",
        epilog=EXPLAINED + "\n\n" + exit_epilog(None),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("scenario", help=f"`published` or a synth scenario: {', '.join(synth.SCENARIOS)}")
    add_runs_options(p, "realisations per case", "seed of the first realisation")
    add_realisation_options(p, plot_help="error bands over time and histograms")
    p.set_defaults(func=run)


def add_realisation_options(p: argparse.ArgumentParser, plot_help: str) -> None:
    """The options `montecarlo` and `sweep` share: the scenario's preset and parameters, the error
    model, the output table and plot, the profile, the engine and --json."""
    p.add_argument("--preset", default=None, help="scenario preset (indexing-table: sweep, pm30, yaw25.8)")
    p.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="scenario parameter, named as `sins-fw synth SCENARIO`'s option without its dashes, e.g. "
        "duration-s=30 (repeatable)",
    )
    p.add_argument(
        "--errors", default="adis16407", help="error-model preset (errors.preset; default adis16407)"
    )
    add_out_option(p, "per-run table: .parquet, .h5 or .csv")
    add_plot_option(p, plot_help)
    add_profile_options(p)
    add_engine_options(p)
    add_json_option(p)


def scenario_params(items: list[str]) -> dict[str, Any]:
    """`--param key=value` options as a dict."""
    out: dict[str, Any] = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep:
            raise InputError(f"--param `{item}`: expected key=value")
        key = key.strip()
        if "_" in key:  # the Python name (synth.generate's keyword) instead of the synth option's
            deprecated(f"--param {key}=", f"--param {key.replace('_', '-')}=")
        out[key.replace("-", "_")] = value.strip()
    return out


def scenario_case(name: str, preset: str | None, params: list[str]) -> mc.Case:
    """A synth scenario as a Monte Carlo case (a clear error for an unknown one)."""
    if name not in synth.SCENARIOS:
        raise InputError(f"unknown scenario `{name}`; known: published, {', '.join(synth.SCENARIOS)}")
    values = synth.resolve(name, preset, **scenario_params(params))
    return mc.Case(name, name, None, tuple(values.items()), (0.0, 0.0, 0.0))


def run(args: argparse.Namespace) -> int:
    if args.runs < 1:
        raise InputError(f"--runs {args.runs}: expected at least 1")
    if args.out is not None:
        sweep.check_output(args.out)
    check_png(args.plot, "--plot")
    profile = profile_from_args(args).with_overrides(f"errors.preset={args.errors}")
    if args.scenario == "published":
        cases = mc.published_cases()
    else:
        cases = [scenario_case(args.scenario, args.preset, args.param)]
    show = sys.stderr.isatty() and not args.json
    with engine_from_args(args) as engine, run_progress(len(cases) * args.runs, show) as progress:
        dists = mc.run_cases(
            cases, args.runs, profile=profile, first_seed=args.first_seed, engine=engine, progress=progress
        )
        where = engine.describe()
    warning = mc.few_runs_warning(args.runs)
    report: dict[str, Any] = {
        "scenario": args.scenario,
        "runs": args.runs,
        "errors_preset": args.errors,
        "seeds": [args.first_seed, args.first_seed + args.runs - 1],
        "engine": where,
        "percentiles": list(mc.PERCENTILES),
        "warnings": [warning] if warning else [],
        "cases": {
            name: {"alpha_error_deg": d.percentiles("alpha"), "runs_without_alpha": d.runs_without_alpha}
            if d.is_wing
            else {"solved_deg": d.percentiles("solved"), "error_deg": d.percentiles("error")}
            for name, d in dists.items()
        },
    }
    lines = [
        f"{args.scenario}: {args.runs} realisations of `{args.errors}` per case "
        f"(seeds {report['seeds']}; {where})"
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
            if d.is_wing:  # the wing unit gives α: its quaternion is the wing's own frame
                if d.runs_without_alpha:
                    lines.append(
                        f"{name} α: {d.runs_without_alpha} of {len(d.outcomes)} runs gave no α against the "
                        "truth (no hinge axis: no rest poses, no motion within 30 s of the zero)"
                    )
                for what, p in d.percentiles("alpha").items():
                    lines.append(
                        f"{name} α {what:<11} error °: "
                        f"p5 {p['p5']:+.4f}  p50 {p['p50']:+.4f}  p95 {p['p95']:+.4f}"
                    )
                continue
            for angle, p in d.percentiles("error").items():
                sign = "+" if angle in mc.ERRORS[:3] else ""  # total, heading, inclination are ≥ 0
                lines.append(
                    f"{name} {angle:<11} error at the end °: "
                    f"p5 {p['p5']:{sign}.4f}  p50 {p['p50']:{sign}.4f}  p95 {p['p95']:{sign}.4f}"
                )
    outcomes = [o for d in dists.values() for o in d.outcomes]
    title = f"sins-fw montecarlo {args.scenario}: {args.runs} realisations of `{args.errors}` per case"
    return write_and_emit(
        args, report, lines, outcomes, lambda path: sweep.plot_bands(dists, path, title), warning
    )


def write_and_emit(
    args: argparse.Namespace,
    report: dict[str, Any],
    lines: list[str],
    outcomes: list[mc.Outcome],
    plot: Callable[[Path], Path],
    warning: str | None,
) -> int:
    """The end `montecarlo` and `sweep` share: the per-run tables (--out) and the picture (--plot,
    drawn by ``plot``) written, the warning said, the report printed."""
    written = []
    if args.out is not None:
        written += sweep.write_tables(args.out, outcomes)
    if args.plot is not None:
        written.append(plot(args.plot))
    report["written"] = [str(p) for p in written]
    lines += [f"wrote {p}" for p in written]
    if warning:
        print(f"sins-fw: warning: {warning}", file=sys.stderr)
    emit(args, report, "\n".join(lines))
    return 0
