"""`sins-fw synth NAME [params] --out TRACE`: generate a synthetic scenario with exact truth."""

from __future__ import annotations

import argparse

from sins_fw import progress, synth
from sins_fw.atomic import check_output_folder
from sins_fw.cli.common import add_json_option, add_out_option, emit, exit_epilog, param_type
from sins_fw.stream import save_chunks
from sins_fw.traces import check_output_path


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "synth",
        help="generate a synthetic trace with exact truth",
        description="Generate a synthetic physical trace (CSV or .h5 by extension). Units, frames, models: "
        "docs/traces.md. The canonical command (all parameters resolved) is recorded in the trace.",
        epilog=exit_epilog(None),
    )
    scenarios = p.add_subparsers(dest="scenario", metavar="NAME", required=True)
    for scenario in synth.SCENARIOS.values():
        s = scenarios.add_parser(
            scenario.name, help=scenario.summary, description=scenario.summary, epilog=exit_epilog(None)
        )
        for param in scenario.params:
            s.add_argument(
                param.option,
                dest=param.name,
                type=param_type(param),
                default=None,
                metavar=param.kind.upper() if param.kind != "axis" else "{x,y,z}",
                help=f"{param.help} (default {param.render(param.default)})",
            )
        if scenario.name == "indexing-table":
            s.add_argument(
                "--preset",
                choices=sorted(synth.INDEXING_PRESETS),
                help="a published experiment: sweep (10° steps over the published range of --axis), "
                "pm30 (0, +30, 0, −30, 0), yaw25.8 (fast rotation to yaw 25.8°, hold 30 s); "
                "explicit options override it",
            )
        add_out_option(s, "output trace, .csv or .h5", required=True)
        add_json_option(s)
        s.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    check_output_path(args.out)
    check_output_folder(args.out, "--out")
    scenario = synth.SCENARIOS[args.scenario]
    given = {p.name: getattr(args, p.name) for p in scenario.params if getattr(args, p.name) is not None}
    preset = getattr(args, "preset", None)
    # The bar's total: the duration when the scenario has one (an indexing table's follows its dwells).
    values = synth.resolve(args.scenario, preset, **given)
    duration = synth.wing_duration(values) if args.scenario == "wing" else values.get("duration_s")
    # Generated and written chunk by chunk: memory does not grow with the duration.
    with progress.bar(progress.wanted(args), duration, desc="generating") as advance:
        chunks = synth.generate_chunks(args.scenario, preset, **given)
        trace = save_chunks(args.out, progress.follow(chunks, advance))
    report = {
        "out": str(args.out),
        "scenario": args.scenario,
        "rows": trace.rows,
        "duration_s": trace.duration_s,
        "sample_rate_hz": trace.metadata["sample_rate_hz"],
        "generator": trace.metadata["generator"],
    }
    text = (
        f"wrote {args.out}: {args.scenario}, {trace.rows} samples, {trace.duration_s:.3f} s at "
        f"{trace.metadata['sample_rate_hz']} Hz\n  {trace.metadata['generator']}"
    )
    emit(args, report, text)
    return 0
