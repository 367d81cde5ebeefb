"""`sins-fw budget`: the per-stage timing budget of one tick and one attitude cycle, without a trace."""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

from sins_fw import budget, firmware_budget, gfsins, synth
from sins_fw.cli.common import (
    add_json_option,
    add_option,
    add_plot_option,
    add_profile_options,
    emit,
    exit_epilog,
    profile_from_args,
)
from sins_fw.cli.stop import check_stop
from sins_fw.errors import CheckFailed, InputError

#: Overruns listed in the text output (the JSON lists every one).
LISTED_OVERRUNS = 20


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "budget",
        help="per-stage timing budget of one tick and one attitude cycle (no trace needed)",
        description="Emulate a slowly turning level board through the profile's board and firmware and show "
        "where each timer tick's interrupt spends its time: entry, CS set-up, SPI, decode, attitude, Euler, "
        "navigation, exit (µs and %% of the period, typical and worst), the attitude solution against the "
        "published 0.35 ms, the op counts × unit cycles of every compute stage, read jitter and sample "
        "age, overruns and rules broken. Exit code 1 when a tick overran or a rule was broken. "
        "The model and the JSON keys: docs/budget.md.",
        epilog=exit_epilog("when a tick overran its period or the configuration breaks a rule"),
    )
    add_profile_options(p)
    add_json_option(p)
    add_plot_option(p, "draw the tick timeline and the cycle breakdown")
    add_option(
        p,
        "--duration-s",
        formerly="--seconds",
        type=float,
        default=budget.DEFAULT_SECONDS,
        help=f"emulated time after any alignment (default {budget.DEFAULT_SECONDS:g} s: one full phase "
        "pattern of 4 ms reads against the 819.2 Hz sample clock)",
    )
    p.add_argument(
        "--firmware",
        type=Path,
        metavar="FW.so",
        help="the budget of this host-built C firmware's ISR (`sins-fw build-firmware`) instead of the "
        "profile's Rust model: entry, CS set-up, SPI (from the bus log), compute, exit, and the compute "
        "by the firmware's own functions (calls, self and inclusive C28x cycles per ISR, share of the tick)",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if not (math.isfinite(args.duration_s) and args.duration_s > 0):
        raise InputError(f"--duration-s {args.duration_s}: expected a finite duration > 0")
    if args.plot is not None and (args.plot.suffix.lower() != ".png" or args.plot.is_dir()):
        raise InputError(f"--plot {args.plot}: expected a file name ending in .png")
    if args.firmware is not None:
        return _firmware(args)
    if gfsins.has_own_schema(args.profile):
        return _gfsins(args)
    report = budget.budget_report(profile_from_args(args), seconds=args.duration_s)
    if args.plot is not None:
        budget.plot_report(report, args.plot)
        report["plot"] = str(args.plot)
    emit(args, report, render(report))
    overruns, broken = report["summary"]["overruns"]["count"], report["rules_broken"]
    if overruns or broken:
        counts: dict[str, int] = {}
        for v in broken:
            counts[v["kind"]] = counts.get(v["kind"], 0) + int(v["count"])
        kinds = ", ".join(f"{k} ×{n}" for k, n in counts.items()) or "none"
        raise CheckFailed(f"{overruns} tick(s) overran; rules broken: {kinds}")
    return 0


def _us(x: float | None) -> str:
    return f"{'—':>10}" if x is None else f"{x * 1e6:10.3f}"


def render(r: dict[str, Any]) -> str:
    """The human-readable budget."""
    tick_us = r["tick_period_s"] * 1e6
    cyc = r["cycle"]
    lines = [
        f"profile   {r['profile']} {' '.join(r['overrides'])}".rstrip(),
        f"firmware  {r['algorithm']}, {r['numeric']}, code in {r['code_location']}, "
        f"schedule {r['schedule']}; SYSCLKOUT {r['sysclkout_hz'] / 1e6:g} MHz, "
        f"SPI {r['spi_baud_hz'] / 1e3:.3f} kHz",
        f"emulated  {r['emulated_s']:.3f} s of a slowly turning level board: "
        f"{r['summary']['ticks']} ticks of {tick_us:.3f} µs, "
        f"{cyc['cycles']} attitude cycles of {r['cycle_period_s'] * 1e6:.3f} µs",
        "",
        f"one timer tick ({tick_us:.3f} µs)  acquisition only          with an attitude step",
        "stage               typical µs   worst µs    typical µs   worst µs  worst % of tick",
    ]
    acq, step = r["tick"]["acquisition"], r["tick"]["step"]
    for row in (*r["stages"], "busy", "margin"):
        a, s = acq.get(row, {}), step.get(row, {})
        pct = s.get("worst_pct", a.get("worst_pct"))
        lines.append(
            f"{row:<16}{_us(a.get('typical_s'))} {_us(a.get('worst_s'))}    {_us(s.get('typical_s'))} "
            f"{_us(s.get('worst_s'))}  {'—' if pct is None else f'{pct:8.3f} %'}"
        )
    lines += [
        "",
        f"one attitude cycle ({r['cycle_period_s'] * 1e6:.3f} µs)",
        "stage               typical µs   worst µs  worst %",
    ]
    for row in (*r["stages"], "busy"):
        c = cyc.get(row, {})
        pct = c.get("worst_pct")
        lines.append(
            f"{row:<16}{_us(c.get('typical_s'))} {_us(c.get('worst_s'))}  "
            f"{'—' if pct is None else f'{pct:7.3f} %'}"
        )
    su = r["summary"]
    u, cu = su["utilisation"], su["cycle_utilisation"]
    if u["max"] is not None:
        line = (
            f"utilisation  tick: max {100 * u['max']:.2f} % (tick {u['max_tick']}), "
            f"mean {100 * u['mean']:.2f} %"
        )
        if cu["max"] is not None:
            line += f"; attitude cycle: max {100 * cu['max']:.2f} %, mean {100 * cu['mean']:.2f} %"
        lines.append(line)

    sol = r["solution"]
    if "time_s" in sol:
        p = sol["parts_s"]
        prov = sol["provenance_s"]
        if sol["published_applies"]:
            verdict = "within" if sol["within_tolerance"] else "OUTSIDE"
            against = f" = {sol['ratio']:.3f} × the published 0.35 ms ({verdict} ±15 %)"
        else:
            against = (
                " (not compared with the published 0.35 ms, measured on "
                + ", ".join(f"{k} = {v}" for k, v in budget.PUBLISHED_CONFIGURATION.items())
                + f"; this profile has {', '.join(sol['published_differs'])})"
            )
        lines += [
            "",
            f"attitude solution (burst read + decode + update + Euler, tick {sol['tick']}): "
            f"{sol['time_s'] * 1e3:.4f} ms{against}",
            f"  SPI clocking    {_us(sol['spi_clocking_s'])} µs  "
            f"{r['spi']['reads_per_tick']}×15 frames × 16 bits at {r['spi_baud_hz'] / 1e3:.3f} kHz "
            "(from the registers)",
            f"  SPI gaps        {_us(sol['spi_gaps_s'])} µs  "
            "polled loop between frames, register access, start latency",
            f"  CS set-up       {_us(p['cs_setup'])} µs  "
            "CS low, first poll and SPITXBUF write to the first SCLK edge",
        ]
        for s in ("decode", "attitude", "euler"):
            lines.append(f"  {s:<14}{_us(p[s])} µs")
        lines.append(
            f"  provenance: {prov['registers'] * 1e6:.3f} µs from registers, "
            f"{prov['sourced_costs'] * 1e6:.3f} µs from sourced costs, "
            f"{prov['estimates'] * 1e6:.3f} µs from estimates"
        )

    comp = r["compute"]
    lines += [
        "",
        f"compute stages: cycles = Σ count × unit cycles ([{comp['arith_section']}] costs) × code-location "
        f"factor {comp['code_location_factor']:g}",
    ]
    for s in ("entry", "decode", "interpolation", "attitude", "euler", "navigation", "exit"):
        st = comp[s]
        if st["cycles"] == 0:
            continue
        terms = ", ".join(f"{t['count']}×{t['unit_cycles']} {t['op']}" for t in st["terms"])
        est = 100 * st["estimated_cycles"] / st["cycles"]
        lines.append(
            f"  {s:<13} {st['cycles']:6d} cycles {st['time_s'] * 1e6:9.3f} µs  ({est:.0f} % estimate-priced)"
        )
        lines.append(f"      {terms}")
        # The stage's parts, each counted and priced like a stage (the DCM's; the wing unit's filter).
        tick_s = r["tick_period_s"]
        for part, p in st.get("parts", {}).items():
            lines.append(
                f"      part {part:<13} {p['cycles']:6d} cycles {p['time_s'] * 1e6:9.3f} µs, "
                f"{100 * p['time_s'] / tick_s:.2f} % of the tick"
            )

    rd = su["reads"]
    if rd["reads"]:
        o, a = rd["offset"], rd["sample_age"]
        lines += [
            "",
            f"reads     {rd['reads']}: first SCLK edge {o['min'] * 1e6:.3f}…{o['max'] * 1e6:.3f} µs "
            f"after the tick, jitter {rd['jitter_s'] * 1e6:.3f} µs",
            f"sample age min {a['min'] * 1e6:.3f}, mean {a['mean'] * 1e6:.3f}, max {a['max'] * 1e6:.3f} µs "
            f"({rd['sample_age_distinct']} distinct values)"
            if a["min"] is not None
            else "sample age none: the part converts on demand (no sample clock of its own)",
        ]
    ov = su["overruns"]
    if ov["count"]:
        listed = ", ".join(str(t) for t in ov["ticks"][:LISTED_OVERRUNS])
        more = (
            f" … ({ov['count'] - LISTED_OVERRUNS} more; --json lists all)"
            if ov["count"] > LISTED_OVERRUNS
            else ""
        )
        lines.append(f"overruns  {ov['count']} at ticks {listed}{more}")
        if ov["skipped_ticks"]:
            lines.append(f"          {len(ov['skipped_ticks'])} ticks never ran (dropped or lost)")
    else:
        lines.append("overruns  none")
    if r["rules_broken"]:
        lines.append("rules broken:")
        lines += [f"  {v['kind']} (×{v['count']}, {v['source']}): {v['message']}" for v in r["rules_broken"]]
    else:
        lines.append("rules broken: none")
    if "plot" in r:
        lines.append(f"plot      {r['plot']}")
    return "\n".join(lines)


def _gfsins(args: argparse.Namespace) -> int:
    """The gyro-free board: both processors' stages at 200 Hz / 10 Hz / 1 Hz (peak and mean) on
    ``sins-fw synth vehicle``'s default scenario (the thesis's chapter 5 drive)."""
    if args.plot is not None:
        raise InputError(
            f"--plot {args.plot}: the plot draws the F28335 ISR's timeline; the gyro-free board's budget is "
            "the table (--json for every figure)"
        )
    prof = gfsins.load(args.profile, args.overrides)
    seconds = args.duration_s
    # Streamed: the drive made and run a chunk at a time, the budget gathered tick by tick (memory
    # does not grow with --duration-s; the stop is checked between blocks of ticks).
    chunks = synth.generate_chunks(
        "vehicle",
        rows=gfsins.CHUNK_ROWS,
        duration_s=prof.start_s + seconds,
        **gfsins.vehicle_array(prof),
    )
    stream = gfsins.Stream(prof)
    kinds: dict[str, int] = {}
    first: dict[str, Any] | None = None
    for part in stream.parts(chunks):
        check_stop()
        for e in part["events"]:
            if e["severity"] == "error":
                kinds[e["kind"]] = kinds.get(e["kind"], 0) + 1
                first = first or e
    out = stream.budget()
    report = {
        "profile": prof.source,
        "overrides": list(prof.overrides),
        "board": "gfsins",
        "emulated_s": seconds,
        "ticks": stream.ticks,
        "period_s": out["period_s"],
        "classes": out["classes"],
        "processors": out["budget"],
        "stages": gfsins.budget_rows(out),
        "rules_broken": [{"kind": k, "count": n} for k, n in kinds.items()],
    }
    lines = [
        f"profile   {prof.source} {' '.join(prof.overrides)}".rstrip(),
        f"board     gfsins: acquisition node (MicroBlaze {prof.get('node.cpu_hz') / 1e6:g} MHz) and "
        f"C6727B DSP ({prof.get('dsp.cpu_hz') / 1e6:g} MHz), one packet per {out['period_s'] * 1e3:g} ms",
        f"emulated  {seconds:g} s after the first tick of the chapter 5 drive (synth vehicle): "
        f"{report['ticks']} ticks; rate class "
        "of a tick: 1 Hz when NMEA bytes came or the DSP took a fix, 10 Hz on the compass's three ticks "
        "of twenty, 200 Hz otherwise",
        "",
        *gfsins.render_budget(out),
        "",
        "rules broken: " + (", ".join(f"{k} ×{n}" for k, n in kinds.items()) or "none"),
    ]
    emit(args, report, "\n".join(lines))
    if kinds and first is not None:
        raise CheckFailed(
            "rules broken: "
            + ", ".join(f"{k} ×{n}" for k, n in kinds.items())
            + f"; the first at {float(first['t_s']):.6g} s: {first['message']}"
        )
    return 0


def _firmware(args: argparse.Namespace) -> int:
    """`budget --firmware FW.so`: the C firmware's ISR on the model budget's synthetic input."""
    if args.plot is not None:
        raise InputError(
            f"--plot {args.plot}: with --firmware the budget is the table (--json for every figure)"
        )
    if not args.firmware.is_file():
        raise InputError(
            f"{args.firmware}: no such firmware library (build it with `sins-fw build-firmware`)"
        )
    if gfsins.has_own_schema(args.profile):
        raise InputError(f"--profile {args.profile}: a C firmware runs on the F28335 boards' profiles")
    report = firmware_budget.firmware_budget_report(args.firmware, profile_from_args(args), args.duration_s)
    emit(args, report, firmware_budget.render(report))
    su = report["summary"]
    overruns = 0 if su is None else su["overruns"]["count"] + len(su["overruns"]["skipped_ticks"])
    if overruns or report["rules_broken"]:
        kinds = ", ".join(f"{v['kind']} ×{v['count']}" for v in report["rules_broken"]) or "none"
        raise CheckFailed(f"{overruns} tick(s) overran or never ran; rules broken: {kinds}")
    return 0
