"""What a run amounts to: its events, its attitude error against the trace's truth, and its time budget.

``summarise(run)`` returns a plain dictionary (JSON-ready); ``render(summary)`` the text `sins-fw run`
prints.

Attitude error (sins_fw.metrics): the estimate is first aligned to the truth's frame, and the
summary says how (``alignment.method``; the methods are :mod:`sins_fw.alignment`'s: ``initial``,
``heading``, ``none``).

Euler errors (roll, pitch, yaw and the total rotation angle) are over every step with truth; BROAD's
total / heading / inclination RMSE over the movement mask when the trace has one (else every step).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from sins_fw import budget, metrics
from sins_fw.alignment import ALIGNMENTS as ALIGNMENTS
from sins_fw.alignment import align_run
from sins_fw.alignment import aligned_estimate as aligned_estimate
from sins_fw.budget import SPI_RULE_KINDS as SPI_RULE_KINDS
from sins_fw.budget import flat_budget
from sins_fw.budget import is_spi_violation as is_spi_violation
from sins_fw.harness import Run
from sins_fw.report_stream import RunSummary, run_part, tally_event


def events_summary(run: Run) -> dict[str, Any]:
    """Count per kind with the first occurrence (time, severity, message)."""
    kinds: dict[str, dict[str, Any]] = {}
    for e in run.events:  # in time order
        tally_event(kinds, e)
    return {"total": len(run.events), "by_kind": dict(sorted(kinds.items()))}


def budget_summary(run: Run) -> dict[str, Any]:
    """The run's time budget: the flat view `sins-fw run` prints of :func:`sins_fw.budget.summarise`
    (ISR utilisation of the tick period, overruns, skipped ticks, SPI violations), plus that full
    summary under ``detail``."""
    return flat_budget(budget.summarise(run))


def attitude_summary(run: Run, align: str = "auto") -> dict[str, Any] | None:
    """Errors against the truth (degrees), or None when the trace has none."""
    if align not in ALIGNMENTS:
        raise ValueError(f"alignment `{align}`: expected one of {', '.join(ALIGNMENTS)}")
    truth = run.truth_q
    if truth is None or run.cycles == 0 or not np.isfinite(truth).all(axis=1).any():
        return None
    est, alignment = align_run(run, align)
    valid = metrics.valid_mask(truth)
    e = metrics.attitude_errors(est[valid], truth[valid])
    last = int(np.flatnonzero(valid)[-1])

    def stats(x: np.ndarray) -> dict[str, float]:
        return {
            "max_abs_deg": float(np.abs(x).max()),
            "rms_deg": float(np.sqrt(np.mean(x * x))),
            "final_deg": float(x[-1]),
        }

    has_mask = run.moving is not None and bool(np.any(run.moving & valid))
    broad = metrics.accuracy(est, truth, run.moving if has_mask else None, align=False)
    return {
        "alignment": alignment,
        "steps_with_truth": int(valid.sum()),
        "final_t_s": float(run.time_s[last]),
        "euler": {name: stats(getattr(e, name)) for name in ("roll", "pitch", "yaw", "total")},
        "broad": {
            "mask": "movement" if has_mask else "all steps",
            "samples": broad.samples,
            "rmse_total_deg": broad.rmse_total_deg,
            "rmse_heading_deg": broad.rmse_heading_deg,
            "rmse_inclination_deg": broad.rmse_inclination_deg,
        },
    }


def summarise(run: Run, *, trace: str = "", align: str = "auto") -> dict[str, Any]:
    """Everything `sins-fw run` reports, as a JSON-ready dictionary: the figures of
    :func:`events_summary`, :func:`attitude_summary` and :func:`budget_summary`, computed as `sins-fw
    run` computes them chunk by chunk (:class:`sins_fw.report_stream.RunSummary`, fed the whole run
    as one chunk), so that a streamed run and a whole one summarise alike, bit for bit."""
    if align not in ALIGNMENTS:
        raise ValueError(f"alignment `{align}`: expected one of {', '.join(ALIGNMENTS)}")
    acc = RunSummary(run.profile, align=align)
    acc.add(run_part(run))
    return acc.result(trace=trace, t0_s=run.t0_s, stage_cycles=run.stage_cycles)


def _fmt(x: float | None, scale: float = 1.0, spec: str = ".3f") -> str:
    return "–" if x is None else format(x * scale, spec)


def render(s: dict[str, Any]) -> str:
    """The human-readable summary."""
    fw = s.get("firmware")
    steps = "attitude steps" if fw is None else "ISR runs"
    lines = [
        f"trace          {s['trace']}",
        f"profile        {s['profile']} {' '.join(s['overrides'])}".rstrip(),
        f"numeric        {s['numeric']}",
        f"emulated       {s['duration_s']:.3f} s of virtual time, {s['cycles']} {steps}",
    ]
    ev = s["events"]
    if ev["total"]:
        lines.append(f"events         {ev['total']}")
        for kind, k in ev["by_kind"].items():
            lines.append(
                f"  {kind:<24} {k['count']:>8} × {k['severity']:<7} first at {k['first_t_s']:.6f} s: "
                f"{k['first_message']}"
            )
    else:
        lines.append("events         none")
    a = s["attitude_error"]
    if a is None and fw is not None and fw["truth_in_trace"] and not fw["attitude_globals"]:
        lines.append(
            "attitude error not compared: the globals file names no q0…q3 (the firmware's quaternion)"
        )
    elif a is None and "attitude_error_omitted" in s:
        lines.append(f"attitude error not reported: {s['attitude_error_omitted']}")
    elif a is None:
        lines.append("attitude error no truth in the trace")
    else:
        lines.append(f"attitude error against the trace's truth, {a['steps_with_truth']} steps")
        lines.append(f"  alignment    {a['alignment']['description']}")
        lines.append(f"  {'':<12} {'max |e|':>10} {'RMS':>10} {'final':>10}  (degrees)")
        for name, e in a["euler"].items():
            lines.append(
                f"  {name:<12} {e['max_abs_deg']:>10.4f} {e['rms_deg']:>10.4f} {e['final_deg']:>10.4f}"
            )
        br = a["broad"]
        lines.append(
            f"  BROAD RMSE over {br['mask']} ({br['samples']} steps): total {br['rmse_total_deg']:.4f}°, "
            f"heading {br['rmse_heading_deg']:.4f}°, inclination {br['rmse_inclination_deg']:.4f}°"
        )
    w = s.get("wing_alpha_error")
    if w is not None:
        lines.append(
            f"hinge angle α  against the trace's truth_alpha_deg ({w['steps_without_alpha']} steps before "
            "an axis: no α)"
        )
        lines.append(f"  {'':<12} {'steps':>8} {'RMS':>10} {'max |e|':>10} {'p95 |e|':>10}  (degrees)")
        for name in ("all", "static", "dynamic"):
            e = w[name]
            lines.append(
                f"  {name:<12} {e['steps']:>8} {_fmt(e['rms_deg'], 1, '.4f'):>10} "
                f"{_fmt(e['max_abs_deg'], 1, '.4f'):>10} {_fmt(e['p95_abs_deg'], 1, '.4f'):>10}"
            )
    b = s["budget"]
    lines += [
        f"budget         ISR {_fmt(b['isr_max_s'], 1e6)} µs max, {_fmt(b['isr_mean_s'], 1e6)} µs mean of a "
        f"{_fmt(b['tick_period_s'], 1e6, '.1f')} µs tick: utilisation "
        f"{_fmt(b['utilisation_max'], 100, '.2f')} % max, "
        f"{_fmt(b['utilisation_mean'], 100, '.2f')} % mean",
        f"               {b['overruns']} overruns, {b['ticks_skipped']} ticks skipped, "
        f"{b['spi_violations']} SPI violations over {b['ticks']} ticks",
    ]
    return "\n".join(lines)
