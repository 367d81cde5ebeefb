"""The summary of a run (:func:`sins_fw.report.summarise`) accumulated chunk by chunk from the
output ``emulate(..., sink=...)`` streams, so that `sins-fw run` holds a chunk, not the run.

Bit for bit the whole-array summary: every figure is either exact whatever the chunking (counts,
minima, maxima, first and last values, integer medians, sets) or a mean or standard deviation over
a sequence of values, which :class:`Moments` takes in fixed blocks of :data:`BLOCK` values counted
from the sequence's start, whatever the chunks they came in: up to one block it is numpy's own
``mean``/``std`` of the whole sequence (so every run of up to 16 384 ticks summarises exactly as
before), beyond that the blocks' means and squared deviations merged in order (Chan et al.), the
same numbers for the same run however it was cut. :func:`sins_fw.report.summarise` of a whole Run
feeds it here as one chunk.
"""

from __future__ import annotations

import math
from collections import Counter
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sins_fw import budget as budget_mod
from sins_fw import metrics
from sins_fw import quaternion as quat
from sins_fw.profile import Profile

PS = 1e-12
#: Values per block of a mean or standard deviation (see the module doc).
BLOCK = 1 << 14


class Moments:
    """Count, mean and standard deviation (numpy's, population) of a sequence given in pieces;
    holds fewer than :data:`BLOCK` values."""

    def __init__(self) -> None:
        self.n = 0
        self.mean = 0.0
        self.m2 = 0.0
        self._buf: list[NDArray[np.float64]] = []
        self._buffered = 0

    def add(self, x: NDArray[Any]) -> None:
        x = np.asarray(x, dtype=np.float64)
        if not len(x):
            return
        self._buf.append(x)
        self._buffered += len(x)
        while self._buffered >= BLOCK:
            self._fold(BLOCK)

    def _fold(self, rows: int) -> None:
        joined = np.concatenate(self._buf)
        block, rest = joined[:rows], joined[rows:]
        self._buf = [rest] if len(rest) else []
        self._buffered = len(rest)
        # For one block: numpy's mean, and its std's sum of squared deviations from that mean.
        nb = len(block)
        mb = float(block.mean())
        m2b = float(np.sum((block - mb) ** 2))
        n = self.n + nb
        d = mb - self.mean
        self.mean += d * nb / n
        self.m2 += m2b + d * d * self.n * nb / n
        self.n = n

    def result(self) -> tuple[float, float] | None:
        """(mean, std), or None for an empty sequence."""
        if self.n == 0 and self._buffered:  # a single, partial block: numpy over it
            x = np.concatenate(self._buf)
            return float(x.mean()), float(x.std())
        if self._buffered:
            self._fold(self._buffered)
        if self.n == 0:
            return None
        return self.mean, math.sqrt(self.m2 / self.n)


class Stats:
    """min, max, mean, std of a sequence given in pieces (``budget._stats``)."""

    def __init__(self) -> None:
        self.lo = math.inf
        self.hi = -math.inf
        self.nan = False
        self.m = Moments()

    def add(self, x: NDArray[Any]) -> None:
        x = np.asarray(x, dtype=np.float64)
        if not len(x):
            return
        lo, hi = float(x.min()), float(x.max())
        self.nan |= math.isnan(lo) or math.isnan(hi)
        self.lo, self.hi = min(self.lo, lo), max(self.hi, hi)
        self.m.add(x)

    def result(self) -> dict[str, float | None]:
        r = self.m.result()
        if r is None:
            return {"min": None, "max": None, "mean": None, "std": None}
        lo, hi = (math.nan, math.nan) if self.nan else (self.lo, self.hi)
        return {"min": lo, "max": hi, "mean": r[0], "std": r[1]}


class _ArgExtreme:
    """The first position of the largest (or smallest) value, NaN first as np.argmax takes it."""

    def __init__(self, smallest: bool) -> None:
        self.smallest = smallest
        self.value: float | None = None
        self.tag: int | None = None

    def add(self, x: NDArray[Any], tags: NDArray[Any]) -> None:
        if not len(x):
            return
        k = int(np.argmin(x) if self.smallest else np.argmax(x))
        v = float(x[k])
        if self.value is None or (math.isnan(v) and not math.isnan(self.value)):
            self.value, self.tag = v, int(tags[k])
            return
        if math.isnan(self.value):
            return
        if (v < self.value) if self.smallest else (v > self.value):
            self.value, self.tag = v, int(tags[k])


def _median(counts: Counter[int]) -> float | None:
    """np.median of the integers counted (the mean of the two middle ones for an even count)."""
    n = sum(counts.values())
    if n == 0:
        return None
    want = [(n - 1) // 2, n // 2]
    out: list[int] = []
    seen = 0
    for v in sorted(counts):
        c = counts[v]
        while want and want[0] < seen + c:
            out.append(v)
            want.pop(0)
        seen += c
    return float(out[0]) if n % 2 else float(np.mean(np.array(out, dtype=np.int64)))


class _Budget:
    """``budget.summarise`` accumulated."""

    def __init__(self) -> None:
        self.ticks = 0
        self.ticks_run = 0
        self.periods: Counter[int] = Counter()
        self.busy, self.margin, self.solution = Stats(), Stats(), Stats()
        self.margin_min = _ArgExtreme(smallest=True)
        self.util_max = _ArgExtreme(smallest=False)
        self.util = Moments()
        self.cycle_ratio_max = -math.inf
        self.cycle_ratio = Moments()
        self.cycles = 0
        self.cycle_busy = 0  # busy ps since the last step tick
        self.last_step_ps: int | None = None
        self.overruns: list[int] = []
        self.skipped: list[int] = []
        # reads
        self.reads = 0
        self.offset, self.interval, self.age, self.stamp = Stats(), Stats(), Stats(), Stats()
        self.slot_range: dict[int, tuple[int, int]] = {}
        self.last_read_tick: int | None = None
        self.last_slot = 0
        self.last_first_start: int | None = None
        self.ages: set[int] = set()

    def add(self, b: dict[str, NDArray[Any]], cycle_t_s: NDArray[Any], part: dict[str, Any]) -> None:
        i64 = budget_mod._i64
        n = len(b["tick"])
        if n:
            self._ticks(b, cycle_t_s, i64)
        self._reads(part, b, i64)
        self.ticks += n

    def _ticks(self, b: dict[str, NDArray[Any]], cycle_t_s: NDArray[Any], i64: Any) -> None:
        skipped = budget_mod.skipped_ticks(b)
        ran = ~skipped
        tick = i64(b["tick"])
        self.ticks_run += int(ran.sum())
        period_ps = i64(b["deadline_ps"])[ran] - i64(b["tick_ps"])[ran]
        self.periods.update(Counter(period_ps.tolist()))
        busy = i64(b["end_ps"])[ran] - i64(b["start_ps"])[ran]
        margin = i64(b["deadline_ps"])[ran] - i64(b["end_ps"])[ran]
        self.busy.add(busy * PS)
        self.margin.add(margin * PS)
        self.margin_min.add(margin, tick[ran])
        util = busy / period_ps if len(busy) else np.zeros(0)
        self.util_max.add(util, tick[ran])
        self.util.add(util)
        per_tick = budget_mod.stage_durations_ps(b)
        per_tick_busy = np.where(ran, i64(b["end_ps"]) - i64(b["start_ps"]), 0)
        tick_s = b["tick_ps"].astype(np.float64) * PS
        steps = np.isin(tick_s, cycle_t_s)
        tick_ps = i64(b["tick_ps"])
        # Cycles: from one step tick (exclusive) to the next (inclusive).
        cum = np.cumsum(per_tick_busy)
        ks = np.flatnonzero(steps)
        if len(ks):
            base = np.r_[-self.cycle_busy, cum[ks[:-1]]]
            prev = np.r_[self.last_step_ps or 0, tick_ps[ks[:-1]]]
            ratios = (cum[ks] - base) / (tick_ps[ks] - prev)
            if self.last_step_ps is None:
                ratios = ratios[1:]  # the first update has no previous one
            if len(ratios):
                self.cycle_ratio_max = max(self.cycle_ratio_max, float(ratios.max()))
                self.cycle_ratio.add(ratios)
                self.cycles += len(ratios)
            self.last_step_ps = int(tick_ps[ks[-1]])
            self.cycle_busy = int(cum[-1] - cum[ks[-1]])
        else:
            self.cycle_busy += int(cum[-1])
        solution = sum(per_tick[s] for s in budget_mod.SOLUTION_STAGES)[steps]
        self.solution.add(solution * PS)
        overran = b["overrun"].astype(bool)
        self.overruns += [int(t) for t in tick[overran]]
        self.skipped += [int(t) for t in tick[skipped]]

    def _reads(self, part: dict[str, Any], b: dict[str, NDArray[Any]], i64: Any) -> None:
        rt = i64(part["read_tick"])
        if not len(rt):
            return
        start = i64(part["read_t_start_ps"])
        nominal = i64(b["tick_ps"])[np.searchsorted(i64(b["tick"]), rt)]
        offset = start - nominal
        new_tick = np.r_[rt[0] != self.last_read_tick, rt[1:] != rt[:-1]]
        g = self.reads + np.arange(len(rt))  # index of each read in the run
        before = self.reads - 1 - self.last_slot  # the previous part's last tick's first read
        slot = g - np.maximum.accumulate(np.where(new_tick, g, before))
        for s in np.unique(slot):
            o = offset[slot == s]
            lo, hi = int(o.min()), int(o.max())
            old = self.slot_range.get(int(s))
            self.slot_range[int(s)] = (lo, hi) if old is None else (min(old[0], lo), max(old[1], hi))
        first = start[slot == 0]
        first_all = np.r_[self.last_first_start, first] if self.last_first_start is not None else first
        self.interval.add(np.diff(first_all) * PS)
        if len(first):
            self.last_first_start = int(first[-1])
        self.last_read_tick, self.last_slot = int(rt[-1]), int(slot[-1])
        has = part["read_sample_index"] >= 0
        age = i64(part["read_age_ps"])[has]
        self.ages.update(np.unique(age).tolist())
        self.age.add(age * PS)
        self.stamp.add(part["read_assumed_s"][has] - part["read_sample_ps"][has].astype(np.float64) * PS)
        self.offset.add(offset * PS)
        self.reads += len(rt)

    def result(self, violations: list[dict[str, Any]]) -> dict[str, Any]:
        median = _median(self.periods)
        util = self.util.result()
        ratio = self.cycle_ratio.result()
        if self.reads:
            reads: dict[str, Any] = {
                "reads": self.reads,
                "offset": self.offset.result(),
                "jitter_s": max(hi - lo for lo, hi in self.slot_range.values()) * PS,
                "interval": self.interval.result(),
                "sample_age": self.age.result(),
                "sample_age_distinct": len(self.ages),
                "timestamp_error": self.stamp.result(),
            }
        else:
            empty = Stats().result()
            reads = {"reads": 0, "offset": empty, "jitter_s": None, "interval": empty, "sample_age": empty,
                     "sample_age_distinct": 0, "timestamp_error": empty}  # fmt: skip
        has = self.ticks_run > 0
        return {
            "ticks": self.ticks,
            "ticks_run": self.ticks_run,
            "tick_period_s": float(median * PS) if median is not None else None,
            "busy": self.busy.result(),
            "margin": {**self.margin.result(), "min_tick": self.margin_min.tag if has else None},
            "utilisation": {
                "max": self.util_max.value if has else None,
                "mean": util[0] if util is not None else None,
                "max_tick": self.util_max.tag if has else None,
            },
            "cycle_utilisation": {
                "cycles": self.cycles,
                "max": self.cycle_ratio_max if self.cycles else None,
                "mean": ratio[0] if ratio is not None else None,
            },
            "solution": self.solution.result(),
            "overruns": {"count": len(self.overruns), "ticks": self.overruns, "skipped_ticks": self.skipped},
            "violations": violations,
            "reads": reads,
        }


class _ErrorStats:
    """max |e|, RMS and final value of one error over the rows with truth."""

    def __init__(self) -> None:
        self.max_abs = -math.inf
        self.nan = False
        self.sq = Moments()
        self.final = math.nan

    def add(self, x: NDArray[np.float64]) -> None:
        if not len(x):
            return
        m = float(np.abs(x).max())
        self.nan |= math.isnan(m)
        self.max_abs = max(self.max_abs, m)
        self.sq.add(x * x)
        self.final = float(x[-1])

    def rms(self) -> float:
        r = self.sq.result()
        return math.nan if r is None else float(np.sqrt(r[0]))

    def result(self) -> dict[str, float]:
        return {
            "max_abs_deg": math.nan if self.nan else self.max_abs,
            "rms_deg": self.rms(),
            "final_deg": self.final,
        }


class _Attitude:
    """``report.attitude_summary`` accumulated."""

    def __init__(self, profile: Profile, align: str) -> None:
        if align == "auto":
            align = "initial" if profile.get("firmware.initial_attitude") == "zero" else "heading"
        self.method = align
        self.start: NDArray[np.float64] | None = None  # initial: the left factor
        self.alignment: dict[str, Any] | None = None
        self.turn: NDArray[np.float64] | None = None  # heading: the rotation about z
        self.held: list[dict[str, Any]] = []  # heading: rows before the alignment row
        self.rows = 0
        self.any_truth = False
        self.had_truth = False
        self.finite_truth = False
        self.steps_with_truth = 0
        self.final_t_s = 0.0
        self.euler = {name: _ErrorStats() for name in ("roll", "pitch", "yaw", "total")}
        # BROAD RMSE over the movement mask and over every step with truth (which one is reported
        # is known at the end: the mask when any step with truth is inside it).
        self.masked = {name: Moments() for name in ("total", "heading", "inclination")}
        self.unmasked = {name: Moments() for name in ("total", "heading", "inclination")}
        self.masked_rows = 0
        self.unmasked_rows = 0
        self.has_moving = False
        #: Called with each batch of rows with truth: (rows, valid mask, errors of the valid rows).
        self.listener: Any = None

    def add(self, part: dict[str, Any]) -> None:
        if "truth_q" not in part:
            return
        self.had_truth = True
        n = len(part["cycle_t_s"])
        rows = {
            "t": part["cycle_t_s"],
            "est": part["cycle_quat"],
            "truth": part["truth_q"],
            "moving": part.get("moving"),
            "q0": part.get("truth_q0"),
            "step": part.get("cycle_step"),
            "row0": self.rows,
            # For a listener that stamps the rows (the Rerun recording): each step's tick and its time.
            "tick": part.get("cycle_tick"),
            "index_ps": part.get("cycle_index_ps"),
        }
        self.rows += n
        if not n:
            return
        self.finite_truth |= bool(np.isfinite(part["truth_q"]).all(axis=1).any())
        self.has_moving |= rows["moving"] is not None
        if self.method == "heading" and self.turn is None:
            self.held.append(rows)
            self._try_heading()
            return
        self._rows(rows)

    def _try_heading(self) -> None:
        for rows in self.held:
            valid = metrics.valid_mask(rows["truth"], rows["moving"])
            if valid.any():
                k = int(np.argmax(valid))
                self.turn, deg = metrics.heading_turn(
                    rows["est"][k], np.asarray(rows["truth"], np.float64)[k]
                )
                self.alignment = metrics.alignment_record("heading", rows["row0"] + k, heading_deg=deg)
                held, self.held = self.held, []
                for r in held:
                    self._rows(r)
                return

    def _aligned(self, rows: dict[str, Any]) -> NDArray[np.float64]:
        est = rows["est"]
        if self.method == "heading":
            assert self.turn is not None
            return quat.multiply(self.turn, np.asarray(est, dtype=np.float64))
        if self.method == "initial":
            if self.start is None:
                q0 = rows["q0"]
                if q0 is not None and np.isfinite(q0).all():
                    self.start = np.asarray(q0, dtype=np.float64)
                    self.alignment = metrics.alignment_record("initial")
                else:
                    ok = np.isfinite(rows["truth"]).all(axis=1)
                    if not ok.any():
                        return np.asarray(est, dtype=np.float64)  # no row counts yet
                    k = int(np.argmax(ok))
                    self.start = quat.multiply(rows["truth"][k], quat.conjugate(est[k]))
                    self.alignment = metrics.alignment_record("initial", rows["row0"] + k, t_s=rows["t"][k])
            return metrics.align_initial(est, self.start)
        self.alignment = metrics.alignment_record("none")
        return np.asarray(est, dtype=np.float64)

    def _rows(self, rows: dict[str, Any]) -> None:
        est = self._aligned(rows)
        truth = rows["truth"]
        valid = metrics.valid_mask(truth)
        if not valid.any():
            return
        self.any_truth = True
        e = metrics.attitude_errors(est[valid], truth[valid])
        if self.listener is not None:
            self.listener(rows, valid, e)
        for name, st in self.euler.items():
            st.add(getattr(e, name))
        self.steps_with_truth += int(valid.sum())
        self.final_t_s = float(rows["t"][int(np.flatnonzero(valid)[-1])])
        for name, m in self.unmasked.items():
            m.add(getattr(e, name) ** 2)
        self.unmasked_rows += int(valid.sum())
        if rows["moving"] is not None:
            inside = np.asarray(rows["moving"], dtype=bool)[valid]
            for name, m in self.masked.items():
                m.add(getattr(e, name)[inside] ** 2)
            self.masked_rows += int(inside.sum())

    def result(self, cycles: int) -> dict[str, Any] | None:
        if not self.had_truth or cycles == 0 or not self.finite_truth:
            return None
        if self.method == "heading" and self.turn is None:
            # No valid movement sample: the whole-array alignment refuses it the same way.
            metrics.align_heading(np.zeros((0, 4)), np.zeros((0, 4)))
        assert self.alignment is not None
        has_mask = self.has_moving and self.masked_rows > 0
        chosen, samples = (self.masked, self.masked_rows) if has_mask else (self.unmasked, self.unmasked_rows)

        def rmse(name: str) -> float:
            r = chosen[name].result()
            return float(np.sqrt(r[0])) if r is not None else math.nan

        return {
            "alignment": self.alignment,
            "steps_with_truth": self.steps_with_truth,
            "final_t_s": self.final_t_s,
            "euler": {name: st.result() for name, st in self.euler.items()},
            "broad": {
                "mask": "movement" if has_mask else "all steps",
                "samples": samples,
                "rmse_total_deg": rmse("total"),
                "rmse_heading_deg": rmse("heading"),
                "rmse_inclination_deg": rmse("inclination"),
            },
        }


class RunSummary:
    """Feed it every part ``emulate(..., sink=...)`` hands out (:meth:`add`), then :meth:`result`
    gives :func:`sins_fw.report.summarise` of the run those parts make, bit for bit."""

    def __init__(self, profile: Profile, *, align: str = "auto") -> None:
        self.profile = profile
        self.cycles = 0
        self.last_tick_ps: int | None = None
        self.events_total = 0
        self.kinds: dict[str, dict[str, Any]] = {}
        self.errors: dict[str, dict[str, Any]] = {}  # error events per kind: count and the first
        self.error_order: list[str] = []
        self.budget = _Budget()
        self.attitude = _Attitude(profile, align)
        # The wing unit's α and its truth, one per step (a float pair per step: 16 bytes).
        self.alpha: list[tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_]]] = []
        # The wing unit's quaternion is q_w^b, from its own zero's level frame with yaw 0: not the
        # trace's C_b^n, so no attitude error is reported for it (its figure is α).
        self.wing = profile.get("firmware.algorithm") == "wing"

    def add(self, part: dict[str, Any]) -> None:
        """One part of the output (``cycle_t_s``, the step times in seconds, may stand for
        ``cycle_t_ps``)."""
        if "cycle_t_s" not in part:
            part = {**part, "cycle_t_s": part["cycle_t_ps"].astype(np.float64) * PS}
        b = {k.removeprefix("budget_"): v for k, v in part.items() if k.startswith("budget_")}
        self.cycles += len(part["cycle_t_s"])
        if len(b["tick_ps"]):
            self.last_tick_ps = int(b["tick_ps"][-1])
        self.add_events(part["events"])
        self.budget.add(b, part["cycle_t_s"], part)
        self.attitude.add(part)
        if self.wing and "wing_alpha_deg" in part and "truth_alpha_deg" in part:
            self.alpha.append((part["wing_alpha_deg"], part["truth_alpha_deg"], part["alpha_still"]))

    def add_events(self, events: list[dict[str, Any]]) -> None:
        """Events in time order (those of a part, or extra ones such as a trace's gaps)."""
        for e in events:
            tally_event(self.kinds, e)
            if e["severity"] == "error":
                v = self.errors.get(e["kind"])
                if v is None:
                    self.errors[e["kind"]] = {"count": 1, "first": e}
                    self.error_order.append(e["kind"])
                else:
                    v["count"] += 1
        self.events_total += len(events)

    def error_counts(self) -> dict[str, int]:
        """Error events per kind, in the order each kind first occurred."""
        return {k: self.errors[k]["count"] for k in self.error_order}

    def first_error(self) -> dict[str, Any] | None:
        """The first error event (None when there is none)."""
        return self.errors[self.error_order[0]]["first"] if self.error_order else None

    def violations(self) -> list[dict[str, Any]]:
        """``budget.violations``: error events per kind, sorted by kind."""
        return [
            {
                "kind": kind,
                "count": v["count"],
                "first_t_s": v["first"]["t_s"],
                "message": v["first"]["message"],
                "measured": v["first"]["measured"],
                "required": v["first"]["required"],
            }
            for kind, v in sorted(self.errors.items())
        ]

    def result(self, *, trace: str = "", t0_s: float = 0.0, stage_cycles: dict[str, int]) -> dict[str, Any]:
        full = self.budget.result(self.violations())
        out = {
            "trace": trace,
            "profile": self.profile.source,
            "overrides": list(self.profile.overrides),
            "numeric": self.profile.get("firmware.numeric"),
            "cycles": self.cycles,
            "duration_s": float(self.last_tick_ps) * PS if self.last_tick_ps is not None else 0.0,
            "trace_t0_s": t0_s,
            "events": {"total": self.events_total, "by_kind": dict(sorted(self.kinds.items()))},
            "attitude_error": None if self.wing else self.attitude.result(self.cycles),
            "budget": budget_mod.flat_budget(full),
            "stage_cycles": dict(stage_cycles),
        }
        if self.alpha:  # the wing unit on a trace with α truth
            out["wing_alpha_error"] = self.alpha_result()
        if self.wing:
            out["attitude_error_omitted"] = WING_ATTITUDE_NOTE
        return out

    def alpha_result(self) -> dict[str, Any]:
        """The wing unit's α error (:func:`sins_fw.metrics.alpha_errors`)."""
        a, t, st = (np.concatenate([x[i] for x in self.alpha]) for i in range(3))
        return metrics.alpha_errors(a, t, st)


#: Why a wing run has no attitude-error block (`sins-fw run`'s summary).
WING_ATTITUDE_NOTE = (
    "the wing unit gives the hinge angle α (its quaternion is q_w^b, from its zero's level frame with yaw 0, "
    "not the trace's C_b^n): see wing_alpha_error"
)


def tally_event(kinds: dict[str, dict[str, Any]], e: dict[str, Any]) -> None:
    """Count event ``e`` in ``kinds`` (kind → count and the first occurrence's time, severity and
    message), events coming in time order."""
    k = kinds.get(e["kind"])
    if k is None:
        kinds[e["kind"]] = {
            "count": 1,
            "severity": e["severity"],
            "first_t_s": e["t_s"],
            "first_message": e["message"],
        }
    else:
        k["count"] += 1


def run_part(run: Any) -> dict[str, Any]:
    """A whole :class:`~sins_fw.harness.Run` as one part, in the form the streamed emulation hands
    over (for :meth:`RunSummary.add` and the viewer's ``Recorder.add``; step times also back in
    integer picoseconds)."""
    part: dict[str, Any] = {
        "cycle_t_s": run.time_s,
        "cycle_t_ps": np.round(run.time_s / 1e-12).astype(np.uint64),
        "cycle_step": run.step,
        "cycle_quat": run.quat,
        "cycle_euler_deg": run.euler_deg,
        "read_tick": run.read_tick,
        "read_t_start_ps": run.read_t_start_ps,
        "read_sample_index": run.read_sample_index,
        "read_age_ps": run.read_age_ps,
        "read_assumed_s": run.read_assumed_s,
        "read_sample_ps": run.read_sample_ps,
        "read_rate": run.read_rate,
        "read_accel": run.read_accel,
        "read_words": run.read_words,
        "events": run.events,
        **{f"budget_{k}": v for k, v in run.budget.items()},
        **{f"dcm_{k}": v for k, v in run.dcm.items()},
        **{f"wing_{k}": v for k, v in run.wing.items()},
    }
    if run.truth_alpha_deg is not None:
        part["truth_alpha_deg"] = run.truth_alpha_deg
        part["alpha_still"] = run.alpha_still
    if run.truth_q is not None:
        part["truth_q"] = run.truth_q
        part["truth_q0"] = run.truth_q0
        if run.moving is not None:
            part["moving"] = run.moving
    return part
