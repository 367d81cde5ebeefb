"""`sins-fw budget --firmware fw.so`: the timing budget of a host-built C firmware's ISR, in the shape of
the Rust model's (:func:`sins_fw.budget.budget_report`), with its compute split by the firmware's own
functions as a profiler would.

The firmware runs (:func:`sins_fw.firmware_run.run_c_firmware`) on the same synthetic input as the
model's budget (a level board turning slowly, :func:`sins_fw.budget._synthetic_input`). Each ISR row
gives the stages the runtime and the bus log bound: ``entry`` (context save and prologue),
``cs_setup`` (the ISR's code up to the first SPI frame), ``spi`` (first frame to the chip select's
last rise, from the bus log), ``compute`` (the rest of the body: the model's decode … navigation), and
``exit``. The compute is split by function: the build's pass charges every basic block of the
firmware's code its C28x cycles and the runtime counts, per ISR, each function's own ("self") cycles,
its calls and its inclusive cycles (its own and its callees', from entry to return). The times are
those cycles at SYSCLKOUT; they do not include the register accesses' cycles or the time spent
waiting in polling loops (the SPI stage holds those)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from sins_fw import budget, synth
from sins_fw.budget import I64, _i64, _sysclk_hz, _table, skipped_ticks, summarise
from sins_fw.firmware_run import FUNCTION_TICKS, run_c_firmware
from sins_fw.harness import PS, _assemble
from sins_fw.profile import Profile
from sins_fw.traces import PhysicalTrace

#: The rows of a C ISR's tick, in execution order, and the model's budget columns bounding each.
STAGES: dict[str, tuple[str, str]] = {
    "entry": ("start_ps", "entry_end_ps"),
    "cs_setup": ("entry_end_ps", "spi_start_ps"),
    "spi": ("spi_start_ps", "spi_end_ps"),
    "compute": ("spi_end_ps", "decode_end_ps"),
    "exit": ("nav_end_ps", "end_ps"),
}


def _function_table(
    functions: np.ndarray, names: tuple[str, ...], ticks: I64, period_ps: float, sysclk_hz: float
) -> list[dict[str, Any]]:
    """One row per function that ran in an ISR, costliest (inclusive, per tick) first: its calls,
    its own and inclusive cycles in all, and per ISR (mean and max over every ISR run, 0 where it did
    not run) in µs and % of the tick."""
    n = len(ticks)
    rows = []
    if n == 0 or not len(functions):
        return rows
    where = np.searchsorted(ticks, _i64(functions["tick"]))
    cycle_ps = 1e12 / sysclk_hz
    for f in np.unique(functions["function"]):
        sel = functions["function"] == f
        per = {}
        for k in ("self", "inclusive", "calls"):
            v = np.zeros(n)
            np.add.at(v, where[sel], functions[k][sel].astype(np.float64))
            per[k] = v
        incl_ps, self_ps = per["inclusive"] * cycle_ps, per["self"] * cycle_ps
        rows.append(
            {
                "function": names[int(f)] if int(f) < len(names) else f"#{int(f)}",
                "calls": int(per["calls"].sum()),
                "isrs": int((per["calls"] > 0).sum()),
                "calls_per_isr": float(per["calls"].mean()),
                "self_cycles": int(per["self"].sum()),
                "inclusive_cycles": int(per["inclusive"].sum()),
                "self_s": {"mean": float(self_ps.mean() * PS), "max": float(self_ps.max() * PS)},
                "inclusive_s": {"mean": float(incl_ps.mean() * PS), "max": float(incl_ps.max() * PS)},
                "inclusive_pct": {
                    "mean": float(100 * incl_ps.mean() / period_ps),
                    "max": float(100 * incl_ps.max() / period_ps),
                },
            }
        )
    rows.sort(key=lambda r: (-r["inclusive_s"]["mean"], r["function"]))
    return rows


def firmware_budget_report(
    library: str | Path, profile: Profile, seconds: float = budget.DEFAULT_SECONDS
) -> dict[str, Any]:
    """Everything `sins-fw budget --firmware` shows, as plain JSON-able values (docs/budget.md)."""
    # The model's input (constant rates after any alignment) on the part's sample grid.
    t, gyro, accel = budget._synthetic_input(profile, seconds, float(synth.DEFAULT_RATE_HZ))
    parts: list[dict[str, Any]] = []
    trace = PhysicalTrace(
        t_s=t, gyro_dps=gyro, accel_g=accel, metadata={"sample_rate_hz": str(synth.DEFAULT_RATE_HZ)}
    )
    result = run_c_firmware(library, trace, profile, sink=parts.append)
    if not parts or not any(len(p["cycle_t_ps"]) for p in parts):
        events = [e for p in parts for e in p["events"]]
        run_summary = None
        rows_b: dict[str, Any] = {}
    else:
        run = _assemble(profile, 0.0, parts, {})
        events = run.events
        run_summary = summarise(run)
        rows_b = run.budget
    sysclk = _sysclk_hz(profile)
    functions = (
        np.concatenate([p["firmware_functions"] for p in parts]) if parts else np.zeros(0, FUNCTION_TICKS)
    )
    stages: dict[str, I64] = {}
    tick_table: dict[str, Any] = {}
    function_rows: list[dict[str, Any]] = []
    period_ps = float(profile.get("timer.period_us")) * 1e6
    if rows_b:
        ran = ~skipped_ticks(rows_b)
        stages = {s: _i64(rows_b[b]) - _i64(rows_b[a]) for s, (a, b) in STAGES.items()}
        stages["busy"] = _i64(rows_b["end_ps"]) - _i64(rows_b["start_ps"])
        stages["margin"] = _i64(rows_b["deadline_ps"]) - _i64(rows_b["end_ps"])
        if ran.any():
            period_ps = float(np.median(_i64(rows_b["deadline_ps"])[ran] - _i64(rows_b["tick_ps"])[ran]))
        tick_table = _table(stages, ran, period_ps, {"margin"})
        ticks = _i64(rows_b["tick"])[ran]
        function_rows = _function_table(functions, result.functions, ticks, period_ps, sysclk)
    by_kind: dict[str, list[dict[str, Any]]] = {}
    for e in events:
        if e["severity"] == "error":
            by_kind.setdefault(e["kind"], []).append(e)
    return {
        "profile": profile.source,
        "overrides": list(profile.overrides),
        "firmware": str(library),
        "float_mode": result.float_mode,
        "sysclkout_hz": sysclk,
        "emulated_s": result.now_s,
        "tick_period_s": period_ps * PS,
        "isrs": result.isr_rows,
        "stages": list(STAGES),
        "tick": tick_table,
        "functions": function_rows,
        "rules_broken": [
            {"kind": k, "count": len(v), "first_t_s": v[0]["t_s"], "message": v[0]["message"]}
            for k, v in sorted(by_kind.items())
        ],
        "summary": run_summary,
    }


def _us(x: float | None) -> str:
    return f"{'—':>10}" if x is None else f"{x * 1e6:10.3f}"


def render(r: dict[str, Any]) -> str:
    """The human-readable C budget."""
    tick_us = r["tick_period_s"] * 1e6
    lines = [
        f"profile   {r['profile']} {' '.join(r['overrides'])}".rstrip(),
        f"firmware  {r['firmware']} (float {r['float_mode']}); SYSCLKOUT {r['sysclkout_hz'] / 1e6:g} MHz, "
        "C28x cycles of each basic block priced by the build (docs/c-cycles.md)",
        f"emulated  {r['emulated_s']:.3f} s of a slowly turning level board: {r['isrs']} ISRs",
        "",
        f"one timer tick ({tick_us:.3f} µs), every ISR run",
        "stage               typical µs   worst µs  worst % of tick",
    ]
    for row in (*r["stages"], "busy", "margin"):
        s = r["tick"].get(row, {})
        pct = s.get("worst_pct")
        lines.append(
            f"{row:<16}{_us(s.get('typical_s'))} {_us(s.get('worst_s'))}  "
            f"{'—' if pct is None else f'{pct:8.3f} %'}"
        )
    lines += [
        "",
        "the ISR's code by function (C28x cycles of its blocks; inclusive = with its callees; per ISR: "
        "mean and max over every ISR)",
        f"{'function':<28}{'calls':>8}{'calls/ISR':>10}{'self µs':>10}{'max':>9}{'incl µs':>10}{'max':>9}"
        f"{'% tick max':>11}",
    ]
    for f in r["functions"]:
        lines.append(
            f"{f['function'][:27]:<28}{f['calls']:>8}{f['calls_per_isr']:>10.2f}"
            f"{f['self_s']['mean'] * 1e6:>10.3f}{f['self_s']['max'] * 1e6:>9.3f}"
            f"{f['inclusive_s']['mean'] * 1e6:>10.3f}{f['inclusive_s']['max'] * 1e6:>9.3f}"
            f"{f['inclusive_pct']['max']:>10.3f} %"
        )
    su = r["summary"]
    if su is not None:
        ov = su["overruns"]
        lines.append(
            f"overruns  {ov['count']}, ticks never run {len(ov['skipped_ticks'])}"
            if ov["count"] or ov["skipped_ticks"]
            else "overruns  none"
        )
    if r["rules_broken"]:
        lines.append("rules broken:")
        lines += [f"  {v['kind']} (×{v['count']}): {v['message']}" for v in r["rules_broken"]]
    else:
        lines.append("rules broken: none")
    return "\n".join(lines)
