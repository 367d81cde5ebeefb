"""`sins-fw sweep SCENARIO... --grid KEY=VALUES`: error distributions over a grid of profile settings.

Every scenario × grid point × seed is one run on the chosen engine; the result is one tidy table (a
row per run) and the percentiles of each error per scenario and grid point, plus a plot.
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

from sins_fw import montecarlo as mc
from sins_fw import sweep, synth
from sins_fw.cli.common import (
    add_runs_options,
    check_png,
    engine_from_args,
    exit_epilog,
    profile_from_args,
    run_progress,
)
from sins_fw.cli.montecarlo import (
    EXPLAINED,
    add_realisation_options,
    scenario_case,
    write_and_emit,
)
from sins_fw.errors import InputError

EXAMPLES = """\
examples:
  sins-fw sweep static --param duration-s=30 --grid spi.spibrr=9,49,127 --grid errors.seed=1..200 \\
      --out spibrr.parquet --plot spibrr.png
  sins-fw sweep static coning --point "timer.period_us=4000" --point "timer.period_us=2000" --runs 50

"""


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "sweep",
        help="error distributions over a grid of profile settings × seeds × scenarios",
        description="Error distributions over a grid of profile settings × seeds × scenarios: one run "
        "per combination, percentiles per scenario and grid point.",
        epilog=EXAMPLES + EXPLAINED + "\n\n" + exit_epilog(None),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "scenarios", nargs="+", metavar="SCENARIO", help=f"synth scenarios: {', '.join(synth.SCENARIOS)}"
    )
    p.add_argument(
        "--grid",
        action="append",
        default=[],
        metavar="KEY=VALUES",
        help="a profile key and its values, comma-separated or a range A..B (repeatable: the grid is the "
        "product); errors.seed=… gives the seeds instead of --runs",
    )
    p.add_argument(
        "--point",
        action="append",
        default=[],
        metavar='"KEY=VALUE ..."',
        help="one grid point as profile overrides (repeatable: a list of points; with --grid, the product)",
    )
    add_runs_options(p, "seeds per grid point without errors.seed in --grid", "first seed with --runs")
    add_realisation_options(p, plot_help="percentiles at each grid point")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if args.out is not None:
        sweep.check_output(args.out)
    check_png(args.plot, "--plot")
    profile = profile_from_args(args).with_overrides(f"errors.preset={args.errors}")
    grid = sweep.parse_grid(args.grid)
    if sweep.SEED_KEY in grid:
        seeds = sweep.seeds_of(grid[sweep.SEED_KEY])
    else:
        if args.runs < 1:
            raise InputError(f"--runs {args.runs}: expected at least 1")
        seeds = list(range(args.first_seed, args.first_seed + args.runs))
    points = sweep.grid_points(profile, grid, [sweep.parse_point(p) for p in args.point])
    cases = [scenario_case(name, args.preset, args.param) for name in dict.fromkeys(args.scenarios)]
    jobs = mc.jobs_for(cases, seeds, profile, points)
    traces = {c.name: c.trace() for c in cases}
    show = sys.stderr.isatty() and not args.json
    with engine_from_args(args) as engine, run_progress(len(jobs), show) as progress:
        outcomes = mc.collect(engine, jobs, traces, progress=progress)
        where = engine.describe()
    runs_per_point = len(set(seeds))
    warning = mc.few_runs_warning(runs_per_point)
    pct = sweep.percentile_table(outcomes)
    report: dict[str, Any] = {
        "scenarios": list(dict.fromkeys(args.scenarios)),
        "points": [" ".join(p) for p in points],
        "seeds": sorted(set(seeds)),
        "runs": len(outcomes),
        "errors_preset": args.errors,
        "engine": where,
        "fingerprint": str(outcomes[0].fingerprint) if outcomes else None,
        "warnings": [warning] if warning else [],
        "percentiles": [dict(zip(pct, row, strict=True)) for row in zip(*pct.values(), strict=True)],
    }
    lines = [
        f"sweep: {len(cases)} scenario(s) × {len(points)} grid point(s) × {runs_per_point} seeds of "
        f"`{args.errors}` = {len(outcomes)} runs ({where})"
    ]
    for row in report["percentiles"]:
        if row["error"] in sweep.DRAWN or row["error"].startswith("alpha_"):
            lines.append(
                f"{row['scenario']}  {row['point']}  {row['error']:<11} error at the end °: "
                f"p5 {row['p5_deg']:.4f}  p50 {row['p50_deg']:.4f}  p95 {row['p95_deg']:.4f}"
            )
    title = (
        f"sins-fw sweep {' '.join(report['scenarios'])}: {runs_per_point} seeds of `{args.errors}` per point"
    )
    return write_and_emit(
        args, report, lines, outcomes, lambda path: sweep.plot_sweep(outcomes, path, title), warning
    )
