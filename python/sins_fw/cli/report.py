"""`sins-fw report TRACE --out FILE.png`: emulate a trace and draw a one-page static report (attitude
error, ISR budget, events) for people without the Rerun viewer. A C firmware's run output (`run
--firmware --out`) is drawn as recorded (:mod:`sins_fw.report_firmware`), not re-emulated."""

from __future__ import annotations

import argparse

from sins_fw.atomic import check_output_folder
from sins_fw.cli.common import (
    EVENTS_CHECK,
    add_json_option,
    add_out_option,
    add_profile_options,
    add_trace_or_run_argument,
    check_error_counts,
    check_png,
    emit,
    exit_epilog,
    firmware_run_report,
    open_firmware_run,
    profile_from_args,
)
from sins_fw.cli.stop import check_stop
from sins_fw.harness import emulate
from sins_fw.run_output import RUN_FORMAT, is_firmware_run, replay_check
from sins_fw.traces import read_metadata


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "report",
        help="emulate a trace and draw a one-page PNG report (attitude error, ISR budget, events)",
        description="Emulate a physical trace, or re-emulate and check a saved run, and draw a one-page "
        "PNG report: the attitude error, the ISR budget per tick, the events. A C firmware's run output "
        "(`run --firmware --out`) is shown as recorded, not re-emulated: its attitude and the error "
        "against the recorded trace's truth when its globals give the attitude, else its globals; and "
        "what the file records (firmware, float mode, trace).",
        epilog=exit_epilog(f"{EVENTS_CHECK}, or a saved run does not replay bit for bit"),
    )
    add_trace_or_run_argument(p)
    add_out_option(p, "the report page (.png)", metavar="FILE.png", required=True, formerly="--png")
    add_profile_options(p)
    add_json_option(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    check_png(args.out, "--out")
    check_output_folder(args.out, "--out")  # missing folders are created, as for every output
    if is_firmware_run(args.trace):
        return _report_firmware(args)
    saved_run = read_metadata(args.trace).get("format") == RUN_FORMAT if args.trace.is_file() else False
    from sins_fw.report_page import PageData, save_report  # matplotlib is a heavy import

    if saved_run:
        # A `sins-fw run --out` file: re-emulated from the trace and profile it records, checked bit
        # for bit against it (exit 1 naming the first difference), then drawn, as `replay` does.
        run_, _ = replay_check(args.trace)
        profile, data = run_.profile, PageData.of_run(run_)
    else:
        # Streamed: the page's series are gathered part by part, each bounded (report_page.MAX_POINTS).
        profile = profile_from_args(args)
        data = PageData(profile)
        emulate(args.trace, profile, sink=data.add)
    save_report(data, args.out, title=args.trace.name)
    s = data.summary
    counts = {k: v["count"] for k, v in sorted(s.kinds.items())}
    report = {
        "trace": str(args.trace),
        "profile": profile.source,
        "overrides": list(profile.overrides),
        "cycles": s.cycles,
        "events": counts,
        "png": str(args.out),
    }
    emit(
        args,
        report,
        f"report of {args.trace} ({s.cycles} cycles, {s.events_total} events) written to {args.out}",
    )
    check_error_counts(s.error_counts(), s.first_error())
    return 0


def _report_firmware(args: argparse.Namespace) -> int:
    """`report RUN` of a C firmware's run output: the page drawn from the file as recorded, a block at
    a time; nothing is re-emulated (and the file holds no events to check)."""
    from sins_fw.report_firmware import FirmwarePage, save_firmware_report  # matplotlib: heavy

    run_file, profile, trace, note = open_firmware_run(args.trace, "drawn")
    page = FirmwarePage(run_file, profile, trace=run_file.trace_path, trace_note=note)
    for part in run_file.parts(trace):
        check_stop()
        page.add(part)
    save_firmware_report(page, args.out, title=args.trace.name)
    report = firmware_run_report(args, run_file, profile, page.rows, page.has_truth, note)
    report["png"] = str(args.out)
    firmware = run_file.metadata.get("firmware", "?")
    emit(
        args,
        report,
        f"report of {args.trace}, a run of the C firmware {firmware} shown as recorded "
        f"(not re-emulated; {page.rows} ISR rows), written to {args.out}",
    )
    return 0
