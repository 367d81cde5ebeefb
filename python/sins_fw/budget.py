"""The per-cycle timing budget: where each timer tick's interrupt spends its time, from the emulator's
own per-tick rows (nothing here re-derives a time the emulator already produced).

Two entry points:

* :func:`summarise` — a pure function of a :class:`~sins_fw.harness.Run`: utilisation, margins,
  overruns with their tick indices, rule violations, read-instant jitter and sample ages. `sins-fw run`
  prints it.
* :func:`budget_report` — what `sins-fw budget` shows: emulates a short synthetic input (a level
  board turning slowly) through the real emulator, so the SPI part comes from the peripheral and device
  models, and adds the per-stage price lines (op counts × unit cycles from ``c28x-costs.toml``), the
  calibration against the published 0.35 ms and the provenance of every figure (derived from
  registers, from sourced costs, or from estimates). The model and every JSON key: docs/budget.md.

Stages of one tick, each bounded by two columns of the emulator's `BudgetRow`:
entry (context save, prologue) → cs_setup (CS low, first poll and SPITXBUF write, start latency)
→ spi (first SCLK edge of the first burst to CS high after the last) → decode → attitude
(incl. the `endpoint` interpolation) → euler → navigation → exit (epilogue, PIE ack, IRET).
"""

from __future__ import annotations

import itertools
import re
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sins_fw import _core
from sins_fw.atomic import atomic_path
from sins_fw.harness import PS, Run, _assemble, cost_table_text, new_emulator
from sins_fw.profile import Profile, load_profile

#: The stages of one tick, in execution order (the core's `output::BUDGET_STAGES`).
STAGES: tuple[str, ...] = tuple(s["name"] for s in _core.BUDGET_STAGES)
#: The budget columns that bound each stage (start, end), without their `budget_` prefix.
_BOUNDS: dict[str, tuple[str, str]] = {
    s["name"]: (s["start"].removeprefix("budget_"), s["end"].removeprefix("budget_"))
    for s in _core.BUDGET_STAGES
}
#: The stages of one attitude solution as the thesis timed it: burst read + decode + update + Euler.
SOLUTION_STAGES: tuple[str, ...] = tuple(s["name"] for s in _core.BUDGET_STAGES if s["solution"])
#: The published time of one attitude solution (reference-design.md), s, and the tolerance the
#: acceptance criterion allows.
PUBLISHED_SOLUTION_S = 0.35e-3
PUBLISHED_TOLERANCE = 0.15
#: What the published time was measured on (reference-design.md): a profile that differs in one of
#: these is another board or firmware, and its solution time is not compared with 0.35 ms.
PUBLISHED_CONFIGURATION = {
    "device.part": "ADIS16407",
    "firmware.algorithm": "rk4",
    "firmware.numeric": "c28x-f32",
}


def published_differences(prof: Profile) -> list[str]:
    """The keys of :data:`PUBLISHED_CONFIGURATION` on which ``prof`` differs, as ``key = value``."""
    return [f"{k} = {prof.get(k)}" for k, v in PUBLISHED_CONFIGURATION.items() if prof.get(k) != v]


#: Default length of the synthetic input of `budget_report`: the 4 ms read period against the
#: 1/819.2 s sample clock repeats after 2.5 s (625 reads), so the sample ages cover every phase.
DEFAULT_SECONDS = 2.5
#: The slow turn of the synthetic input, °/s (body x, y, z): small enough to stay far from every
#: decode range limit, large enough that the attitude actually moves.
SLOW_TURN_DPS = (0.5, -0.3, 1.0)

I64 = NDArray[np.int64]


# --------------------------------------------------------------------------------------------- per tick


def _i64(a: NDArray[Any]) -> I64:
    return np.asarray(a).astype(np.int64)


def stage_durations_ps(budget: dict[str, NDArray[Any]]) -> dict[str, I64]:
    """Duration of each stage in every tick, ps (zero for a stage a tick did not run)."""
    return {s: _i64(budget[b]) - _i64(budget[a]) for s, (a, b) in _BOUNDS.items()}


def skipped_ticks(budget: dict[str, NDArray[Any]]) -> NDArray[np.bool_]:
    """Ticks whose ISR never ran (dropped or lost): the emulator gives them no deadline."""
    return _i64(budget["deadline_ps"]) == _i64(budget["tick_ps"])


def step_ticks(run: Run) -> NDArray[np.bool_]:
    """Ticks that ran an attitude update (the ticks the run's output rows belong to; alignment ticks
    complete a step of the schedule but run no update)."""
    # Both sides are the same integer picoseconds times the same factor: the floats are identical.
    tick_s = run.budget["tick_ps"].astype(np.float64) * PS
    return np.isin(tick_s, run.time_s)


def _stats(x: NDArray[Any]) -> dict[str, float | None]:
    if len(x) == 0:
        return {"min": None, "max": None, "mean": None, "std": None}
    x = np.asarray(x, dtype=np.float64)
    return {"min": float(x.min()), "max": float(x.max()), "mean": float(x.mean()), "std": float(x.std())}


def _cycles(run: Run) -> list[tuple[int, int]]:
    """Attitude cycles as (first, last) tick-row ranges: the ticks after one update up to and including
    the next. The first update has no previous one (its ticks include the start-up) and is left out."""
    idx = np.flatnonzero(step_ticks(run))
    return [(int(a) + 1, int(b)) for a, b in itertools.pairwise(idx)]


def _cycle_sums(run: Run, per_tick: dict[str, I64]) -> tuple[dict[str, I64], I64]:
    """Each stage summed over each attitude cycle, and each cycle's length (step tick to step tick), ps."""
    cycles = _cycles(run)
    tick_ps = _i64(run.budget["tick_ps"])
    sums = {k: np.array([v[a : b + 1].sum() for a, b in cycles], dtype=np.int64) for k, v in per_tick.items()}
    lengths = np.array([tick_ps[b] - tick_ps[a - 1] for a, b in cycles], dtype=np.int64)
    return sums, lengths


def read_timing(run: Run) -> dict[str, Any]:
    """Read instants against the nominal ticks and the device's sample clock.

    * ``offset``: first SCLK edge of each burst minus its tick's nominal arrival, s.
    * ``jitter_s``: the spread (max − min) of those offsets, per burst slot of a tick (the second and
      third burst of `back-to-back` are not jitter), worst slot.
    * ``interval``: time between consecutive first-slot reads, s.
    * ``sample_age``: first SCLK edge of the burst minus the true time of the sample it carried, s.
    * ``timestamp_error``: the time the firmware assumes the sample belongs to minus its true time, s.
    """
    tick = _i64(run.budget["tick"])
    rt = _i64(run.read_tick)
    start = _i64(run.read_t_start_ps)
    out: dict[str, Any] = {"reads": len(rt)}
    if len(rt) == 0:
        empty = _stats(np.zeros(0))
        return {**out, "offset": empty, "jitter_s": None, "interval": empty, "sample_age": empty,
                "sample_age_distinct": 0, "timestamp_error": empty}  # fmt: skip
    nominal = _i64(run.budget["tick_ps"])[np.searchsorted(tick, rt)]
    offset = start - nominal
    first_of_tick = np.r_[True, rt[1:] != rt[:-1]]
    slot = np.arange(len(rt)) - np.maximum.accumulate(np.where(first_of_tick, np.arange(len(rt)), 0))
    jitter = max(int(np.ptp(offset[slot == s])) for s in np.unique(slot))
    first = start[slot == 0]
    has_sample = run.read_sample_index >= 0
    age = _i64(run.read_age_ps)[has_sample]
    stamp = run.read_assumed_s[has_sample] - run.read_sample_ps[has_sample].astype(np.float64) * PS
    return {
        **out,
        "offset": _stats(offset * PS),
        "jitter_s": jitter * PS,
        "interval": _stats(np.diff(first) * PS),
        "sample_age": _stats(age * PS),
        "sample_age_distinct": len(np.unique(age)),
        "timestamp_error": _stats(stamp),
    }


def violations(run: Run) -> list[dict[str, Any]]:
    """Error-severity events (a hardware rule broken or a deadline missed), one entry per kind: count,
    first time and message, and the measured/required figures of the first (SI units)."""
    by_kind: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for e in run.events:
        if e["severity"] == "error":
            by_kind[e["kind"]].append(e)
    return [
        {
            "kind": kind,
            "count": len(es),
            "first_t_s": es[0]["t_s"],
            "message": es[0]["message"],
            "measured": es[0]["measured"],
            "required": es[0]["required"],
        }
        for kind, es in sorted(by_kind.items())
    ]


def summarise(run: Run) -> dict[str, Any]:
    """The budget of a whole run, as plain JSON-able values (a pure function of the Run).

    Keys: ``ticks``, ``ticks_run``, ``tick_period_s``, ``busy`` and ``margin`` (stats over the ticks
    that ran, s; the tick of the smallest margin), ``utilisation`` (busy / tick period: max, mean),
    ``cycle_utilisation`` (busy time of an attitude cycle's ticks / the cycle's length), ``solution``
    (stats of one attitude solution, s), ``overruns`` (count, the tick index of every overrun, and of
    every tick that never ran), ``violations`` (see :func:`violations`), ``reads`` (see
    :func:`read_timing`). docs/budget.md describes each.
    """
    b = run.budget
    n = len(b["tick"])
    skipped = skipped_ticks(b)
    ran = ~skipped
    tick = _i64(b["tick"])
    period_ps = _i64(b["deadline_ps"])[ran] - _i64(b["tick_ps"])[ran]
    busy = _i64(b["end_ps"])[ran] - _i64(b["start_ps"])[ran]
    margin = _i64(b["deadline_ps"])[ran] - _i64(b["end_ps"])[ran]
    util = busy / period_ps if len(busy) else np.zeros(0)
    per_tick = stage_durations_ps(b)
    per_tick_busy = np.where(ran, _i64(b["end_ps"]) - _i64(b["start_ps"]), 0)
    sums, lengths = _cycle_sums(run, {"busy": per_tick_busy})
    steps = step_ticks(run)
    solution = sum(per_tick[s] for s in SOLUTION_STAGES)[steps] if n else np.zeros(0, dtype=np.int64)
    overran = b["overrun"].astype(bool)
    return {
        "ticks": n,
        "ticks_run": int(ran.sum()),
        "tick_period_s": float(np.median(period_ps) * PS) if len(period_ps) else None,
        "busy": _stats(busy * PS),
        "margin": {
            **_stats(margin * PS),
            "min_tick": int(tick[ran][np.argmin(margin)]) if len(margin) else None,
        },
        "utilisation": {
            "max": float(util.max()) if len(util) else None,
            "mean": float(util.mean()) if len(util) else None,
            "max_tick": int(tick[ran][np.argmax(util)]) if len(util) else None,
        },
        "cycle_utilisation": {
            "cycles": len(lengths),
            "max": float((sums["busy"] / lengths).max()) if len(lengths) else None,
            "mean": float((sums["busy"] / lengths).mean()) if len(lengths) else None,
        },
        "solution": _stats(solution * PS),
        "overruns": {
            "count": int(overran.sum()),
            "ticks": [int(t) for t in tick[overran]],
            "skipped_ticks": [int(t) for t in tick[skipped]],
        },
        "violations": violations(run),
        "reads": read_timing(run),
    }


#: Event kinds that are broken SPI rules (the core's event table marks them): the device's frame
#: rules, the link's chip-select rules and the F28335 SPI-A's own.
SPI_RULE_KINDS = frozenset(k["name"] for k in _core.EVENT_KINDS if k["spi_rule"])


def is_spi_violation(kind: str) -> bool:
    """True for the event kinds counted as SPI violations."""
    return kind in SPI_RULE_KINDS


def flat_budget(full: dict[str, Any]) -> dict[str, Any]:
    """The flat view of a full budget summary (:func:`sins_fw.budget.summarise`'s keys), with the
    full one under ``detail``: what a whole run and a streamed one both report."""
    return {
        "ticks": full["ticks"],
        "tick_period_s": full["tick_period_s"],
        "isr_max_s": full["busy"]["max"],
        "isr_mean_s": full["busy"]["mean"],
        "utilisation_max": full["utilisation"]["max"],
        "utilisation_mean": full["utilisation"]["mean"],
        "overruns": full["overruns"]["count"],
        "ticks_skipped": len(full["overruns"]["skipped_ticks"]),
        "spi_violations": sum(v["count"] for v in full["violations"] if is_spi_violation(v["kind"])),
        "detail": full,
    }


# ----------------------------------------------------------------------------------- the budget command


def cost_provenance(text: str) -> dict[str, dict[str, Any]]:
    """Where each entry of a cost table comes from, read from its comment: ``section.key`` →
    ``value``, ``source`` (the tag, e.g. ``TI-FPU``, or ``estimate``), ``estimate`` (True when the
    comment marks any part of the figure as an estimate) and ``note`` (the whole comment)."""
    out: dict[str, dict[str, Any]] = {}
    section = ""
    for line in text.splitlines():
        s = line.strip()
        if m := re.match(r"^\[([A-Za-z0-9_]+)\]", s):
            section = m.group(1)
            continue
        m = re.match(r"^([A-Za-z0-9_]+)\s*=\s*([^#]+?)\s*(?:#\s*(.*))?$", s)
        if not m or not section:
            continue
        key, value, note = m.group(1), m.group(2), (m.group(3) or "").strip()
        tag = re.match(r"^(TI-[A-Z]+)", note)
        estimate = "estimate" in note.lower()
        out[f"{section}.{key}"] = {
            "value": float(value),
            "source": tag.group(1) if tag else ("estimate" if estimate else None),
            "estimate": estimate,
            "note": note,
        }
    return out


def _synthetic_input(
    profile: Profile, seconds: float, rate_hz: float | None = None
) -> tuple[NDArray[np.float64], ...]:
    """A level board turning slowly at a constant rate: still enough for the alignment of a `level`
    start, and moving so that the attitude arithmetic is not trivially on zeros. Nine rows (the
    emulator interpolates between them), or with ``rate_hz`` rows at that rate up to at least the same
    end (a trace, whose rows must be no more than 1.5 sample periods apart: the C firmware's)."""
    period_s = float(profile.get("timer.period_us")) * 1e-6
    align = (
        float(profile.get("firmware.alignment_s"))
        if profile.get("firmware.initial_attitude") == "level"
        else 0
    )
    # Whole ticks past the alignment, plus half a tick so the last one is inside the input.
    end = align + (np.ceil(seconds / period_s) + 0.5) * period_s
    t = np.linspace(0.0, end, 9) if rate_hz is None else np.arange(int(np.ceil(end * rate_hz)) + 1) / rate_hz
    gyro = np.tile(np.array(SLOW_TURN_DPS, dtype=np.float64), (len(t), 1))
    if align > 0:
        gyro[t <= align] = 0.0
    accel = np.tile(np.array([0.0, 0.0, 1.0]), (len(t), 1))
    return t, gyro, accel


def emulate_synthetic(profile: Profile, seconds: float = DEFAULT_SECONDS) -> tuple[Run, dict[str, Any]]:
    """Run the profile's board on the synthetic input for ``seconds`` (after any alignment) with the
    SPI log on; returns the Run and the bus log (see `_core.Emulator.take_bus_log`)."""
    emu = new_emulator(profile)
    emu.enable_bus_log()
    emu.push(*_synthetic_input(profile, seconds))
    emu.end()
    emu.run()
    run = _assemble(profile, 0.0, [emu.take()], dict(emu.stage_cycles()))
    run.extra["stage_costs"] = emu.stage_costs()
    return run, emu.take_bus_log()


def _sysclk_hz(profile: Profile) -> float:
    c = profile.values["clocks"]
    return float(c["crystal_hz"]) * float(c["pllcr"]) / float(c["divsel"])


def _stage_prices(costs: dict[str, Any], provenance: dict[str, dict[str, Any]], sysclk_hz: float) -> dict:
    """Each compute stage's price lines, cycles and time, and how many of its cycles come from
    cost-table entries marked as estimates."""
    factor = float(costs["code_location_factor"])
    out = {}
    for name in ("entry", "decode", "interpolation", "attitude", "euler", "navigation", "exit"):
        st = costs[name]
        lines = []
        estimated = 0.0
        for t in st["terms"]:
            if t["count"] == 0:
                continue
            cycles = t["count"] * t["unit_cycles"] * (factor if t["scaled"] else 1.0)
            prov = provenance.get(t["key"], {})
            est = bool(prov.get("estimate", True))
            estimated += cycles if est else 0.0
            lines.append({**t, "cycles": cycles, "source": prov.get("source"), "estimate": est})
        out[name] = {
            "cycles": int(st["cycles"]),
            "time_s": st["cycles"] / sysclk_hz,
            "counts": {k: int(v) for k, v in st["counts"].items() if v},
            "terms": lines,
            "estimated_cycles": estimated,
            # The DCM's attitude update, part by part (docs/budget.md, "The DCM's parts").
            "parts": {
                part: {
                    "cycles": int(p["cycles"]),
                    "time_s": p["cycles"] / sysclk_hz,
                    "counts": {k: int(v) for k, v in p["counts"].items() if v},
                }
                for part, p in st.get("parts", {}).items()
            },
        }
    return out


def _table(values: dict[str, I64], mask: NDArray[np.bool_], period_ps: float, worst_is_min: set[str]) -> dict:
    """Typical (median) and worst (max; min for margins) of each row over the masked ticks, s and % of
    the period."""
    if not mask.any():
        return {}
    out = {}
    for k, v in values.items():
        x = v[mask]
        worst = x.min() if k in worst_is_min else x.max()
        typical = np.median(x)
        out[k] = {
            "typical_s": float(typical * PS),
            "worst_s": float(worst * PS),
            "typical_pct": float(100 * typical / period_ps),
            "worst_pct": float(100 * worst / period_ps),
        }
    return out


def budget_report(
    profile: Profile | str = "reference",
    overrides: tuple[str, ...] | list[str] = (),
    seconds: float = DEFAULT_SECONDS,
) -> dict[str, Any]:
    """Everything `sins-fw budget` shows, as plain JSON-able values (keys: docs/budget.md)."""
    prof = profile if isinstance(profile, Profile) else load_profile(profile, overrides)
    if overrides and isinstance(profile, Profile):
        prof = prof.with_overrides(*overrides)
    run, bus = emulate_synthetic(prof, seconds)
    costs_text, costs_source = cost_table_text(prof)
    board = _core.board_summary(prof.text, prof.source, list(prof.overrides), costs_text, costs_source)
    provenance = cost_provenance(costs_text)
    sysclk = _sysclk_hz(prof)
    costs = run.extra["stage_costs"]
    summary = summarise(run)

    b = run.budget
    ran = ~skipped_ticks(b)
    steps = step_ticks(run)
    per_tick = stage_durations_ps(b)
    rows = {
        **per_tick,
        "busy": _i64(b["end_ps"]) - _i64(b["start_ps"]),
        "margin": _i64(b["deadline_ps"]) - _i64(b["end_ps"]),
    }
    tick_period_ps = float(b["deadline_ps"][ran][0] - b["tick_ps"][ran][0]) if ran.any() else float("nan")
    sums, lengths = _cycle_sums(run, {**per_tick, "busy": np.where(ran, rows["busy"], 0)})
    cycle_period_ps = float(np.median(lengths)) if len(lengths) else float(costs["update_period_s"]) / PS

    # One attitude solution on the worst step tick: its parts, with the SPI clocking the registers give.
    prices = _stage_prices(costs, provenance, sysclk)
    reads_per_tick = int(np.unique(run.read_tick, return_counts=True)[1].max()) if len(run.read_tick) else 0
    clocking_s = float(board["burst_clocking_s"]) * reads_per_tick
    differs = published_differences(prof)
    solution: dict[str, Any] = {
        "reference_s": PUBLISHED_SOLUTION_S,
        "tolerance": PUBLISHED_TOLERANCE,
        "published_applies": not differs,
        "published_differs": differs,
    }
    worst_step = None
    if steps.any():
        sol = sum(per_tick[s] for s in SOLUTION_STAGES)
        worst_step = int(np.flatnonzero(steps)[np.argmax(sol[steps])])
        parts = {s: float(per_tick[s][worst_step] * PS) for s in SOLUTION_STAGES}
        total = float(sol[worst_step] * PS)
        compute_s = parts["decode"] + parts["attitude"] + parts["euler"]
        # Cycles priced by cost-table entries marked as estimates (decode runs once per burst).
        estimated_cycles = prices["decode"]["estimated_cycles"] * reads_per_tick + sum(
            prices[s]["estimated_cycles"] for s in ("interpolation", "attitude", "euler")
        )
        estimated_compute_s = min(compute_s, estimated_cycles / sysclk)
        solution.update(
            {
                "tick": int(b["tick"][worst_step]),
                "time_s": total,
                "ratio": None if differs else total / PUBLISHED_SOLUTION_S,
                "within_tolerance": None
                if differs
                else bool(abs(total / PUBLISHED_SOLUTION_S - 1) <= PUBLISHED_TOLERANCE),
                "parts_s": parts,
                "spi_clocking_s": clocking_s,
                "spi_gaps_s": parts["spi"] - clocking_s,
                "compute_s": compute_s,
                "provenance_s": {
                    "registers": clocking_s,
                    "sourced_costs": compute_s - estimated_compute_s,
                    "estimates": estimated_compute_s + parts["spi"] - clocking_s + parts["cs_setup"],
                },
            }
        )

    # The SPI frames of the worst step tick (or the first tick), relative to its nominal arrival.
    show = worst_step if worst_step is not None else (int(np.flatnonzero(ran)[0]) if ran.any() else None)
    frames: list[dict[str, float]] = []
    cs: list[dict[str, Any]] = []
    if show is not None:
        t0, t1 = int(b["tick_ps"][show]), int(b["end_ps"][show])
        fs = _i64(bus["frame_start_ps"])
        # This ISR's frames only (after an overrun, the previous ISR's burst runs past the tick).
        sel = (fs >= int(b["start_ps"][show])) & (fs <= t1)
        for i in np.flatnonzero(sel):
            frames.append(
                {
                    "index": int(bus["frame_index"][i]),
                    "start_s": (int(bus["frame_start_ps"][i]) - t0) * PS,
                    "first_edge_s": (int(bus["frame_first_edge_ps"][i]) - t0) * PS,
                    "last_edge_s": (int(bus["frame_last_edge_ps"][i]) - t0) * PS,
                    "end_s": (int(bus["frame_end_ps"][i]) - t0) * PS,
                }
            )
        ct = _i64(bus["cs_t_ps"])
        for i in np.flatnonzero((ct >= int(b["start_ps"][show])) & (ct <= t1)):
            cs.append({"t_s": (int(ct[i]) - t0) * PS, "low": bool(bus["cs_low"][i])})
    show_stages = (
        {s: {"start_s": (int(b[_BOUNDS[s][0]][show]) - int(b["tick_ps"][show])) * PS,
             "end_s": (int(b[_BOUNDS[s][1]][show]) - int(b["tick_ps"][show])) * PS} for s in STAGES}
        if show is not None else {}
    )  # fmt: skip

    estimates = {
        "timing.poll_loop_cycles": prof.get("timing.poll_loop_cycles"),
        "spi.start_latency_lspclk": prof.get("spi.start_latency_lspclk"),
        **{k: v["value"] for k, v in provenance.items() if v["estimate"]},
    }
    # The rules the register values break by themselves (at t = 0; `board` also lists the events of
    # its own emulated burst, which the emulation here reports again, grouped).
    rules = [
        {"kind": v["kind"], "count": 1, "first_t_s": 0.0, "message": v["message"], "measured": v["measured"],
         "required": v["required"], "source": "registers"}
        for v in board["violations"] if v["t_s"] == 0.0
    ]  # fmt: skip
    rules += [{**v, "source": "emulation"} for v in summary["violations"]]
    return {
        "profile": prof.source,
        "overrides": list(prof.overrides),
        "algorithm": prof.get("firmware.algorithm"),
        "numeric": prof.get("firmware.numeric"),
        "code_location": prof.get("firmware.code_location"),
        "schedule": prof.get("firmware.schedule"),
        "sysclkout_hz": sysclk,
        "spi_baud_hz": board["spi_baud_hz"],
        "emulated_s": float(b["tick_ps"][-1]) * PS if len(b["tick"]) else 0.0,
        "tick_period_s": tick_period_ps * PS,
        "cycle_period_s": cycle_period_ps * PS,
        "stages": list(STAGES),
        "tick": {
            "acquisition": _table(rows, ran & ~steps, tick_period_ps, {"margin"}),
            "step": _table(rows, ran & steps, tick_period_ps, {"margin"}),
        },
        "cycle": {
            "cycles": len(lengths),
            **_table(sums, np.ones(len(lengths), dtype=bool), cycle_period_ps, set()),
        },
        "solution": solution,
        "compute": {
            "code_location_factor": costs["code_location_factor"],
            "arith_section": costs["arith_section"],
            **prices,
        },
        "spi": {
            "baud_hz": board["spi_baud_hz"],
            "frame_s": board["frame_s"],
            "burst_clocking_s": board["burst_clocking_s"],
            "burst_s": _stats((_i64(run.read_t_end_ps) - _i64(run.read_t_start_ps)) * PS),
            "reads_per_tick": reads_per_tick,
        },
        "timeline": {
            "tick": int(b["tick"][show]) if show is not None else None,
            "stages": show_stages,
            "frames": frames,
            "cs": cs,
        },
        "estimates": estimates,
        "rules_broken": rules,
        "summary": summary,
    }


# -------------------------------------------------------------------------------------------- the plot


def plot_report(report: dict[str, Any], path: str | Path) -> None:
    """Draw the budget: the worst update tick's ISR as a timeline (each stage, each SPI frame from its
    first to its last SCLK edge, and the next tick when it falls inside) and the attitude cycle as a
    stacked bar of the stages in % of the cycle, with the idle share."""
    # matplotlib is a heavy import (and needs its Agg backend set first): only when a plot is drawn.
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # after the backend is set

    colours = dict(zip(STAGES, plt.get_cmap("tab10").colors, strict=False))
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(11, 5.5), gridspec_kw={"height_ratios": [2, 1]})
    tl = report["timeline"]
    us = 1e6
    end = max((span["end_s"] for span in tl["stages"].values()), default=0.0)
    first = tl["stages"]["entry"]["start_s"] if tl["stages"] else 0.0
    if first > 0:
        ax1.broken_barh([(0, first * us)], (10, 8), facecolor="none", edgecolor="red", hatch="//",
                        label="waiting (overrun)")  # fmt: skip
    for s, span in tl["stages"].items():
        width = (span["end_s"] - span["start_s"]) * us
        if width > 0:
            ax1.broken_barh([(span["start_s"] * us, width)], (10, 8), color=colours[s], label=s)
    for f in tl["frames"]:
        ax1.broken_barh(
            [(f["first_edge_s"] * us, (f["last_edge_s"] - f["first_edge_s"]) * us)], (2, 6), color="0.35"
        )
    deadline = report["tick_period_s"]
    if deadline <= 1.1 * end:
        ax1.axvline(deadline * us, color="red", linestyle="--", label="next tick (deadline)")
    else:
        ax1.text(0.99, 0.04, f"next tick at {deadline * us:.0f} µs: margin {(deadline - end) * us:.1f} µs",
                 transform=ax1.transAxes, ha="right", fontsize=8)  # fmt: skip
    ax1.set_xlim(-0.01 * end * us, 1.12 * max(end, deadline if deadline <= 1.1 * end else 0) * us)
    ax1.set_yticks([5, 14], ["SPI frames\n(SCLK)", "ISR stages"])
    ax1.set_xlabel(f"µs after tick {tl['tick']} arrived")
    name = " ".join([Path(report["profile"]).stem, *report["overrides"]])
    ax1.set_title(
        f"{name}: {report['algorithm']}, {report['numeric']}, code in {report['code_location']}, "
        f"SPI {report['spi_baud_hz'] / 1e3:.0f} kHz"
    )
    ax1.set_ylim(0, 25)  # headroom above the stages for the legend
    ax1.legend(loc="upper center", fontsize=7, ncol=9, frameon=False)
    left = 0.0
    cycle = report["cycle"]
    for s in STAGES:
        pct = cycle.get(s, {}).get("typical_pct", 0.0)
        if pct > 0:
            ax2.barh([0], [pct], left=left, color=colours[s], label=f"{s} {pct:.2f} %")
            left += pct
    ax2.set_xlim(0, max(100.0, left))
    ax2.set_ylim(-0.5, 1.6)  # headroom for the legend
    ax2.set_yticks([])
    rest = f"idle {100 - left:.1f} %" if left <= 100 else f"OVERLOADED by {left - 100:.1f} %"
    ax2.set_xlabel(f"% of the attitude cycle ({report['cycle_period_s'] * 1e3:g} ms), typical; {rest}")
    ax2.legend(loc="upper center", fontsize=7, ncol=8, frameon=False)
    fig.tight_layout()
    try:
        with atomic_path(path) as tmp:
            fig.savefig(tmp, format="png", dpi=120)
    finally:
        plt.close(fig)
