"""A one-page static report of a run for people without the Rerun viewer (matplotlib, Agg backend):
the attitude error against truth (or the attitude itself when the trace has no truth), the ISR budget
per timer tick against its deadline, and the events in time.

:func:`report_figure` returns the figure and its axes (the tests read the plotted data back);
:func:`save_report` writes the PNG atomically. Both take a Run or the :class:`PageData` gathered
from a streamed run (`sins-fw report`), whose series hold at most :data:`MAX_POINTS` points each.
"""

from __future__ import annotations

import os
import textwrap
from dataclasses import dataclass
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # no display needed; set before pyplot is imported anywhere in this process
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from numpy.typing import NDArray

from sins_fw import quaternion
from sins_fw.atomic import save_png
from sins_fw.harness import PS, Run
from sins_fw.metrics import wrap_deg
from sins_fw.profile import Profile
from sins_fw.report_stream import RunSummary, run_part

#: Page size in inches and resolution: 1100 × 850 pixels.
FIGSIZE = (11.0, 8.5)
DPI = 100
SEVERITY_COLORS = {"info": "tab:blue", "warning": "tab:orange", "error": "tab:red"}
ANGLE_COLORS = ("tab:red", "tab:green", "tab:blue")
#: Within this many degrees of pitch ±90° roll and yaw are ill-conditioned (their errors are hidden).
GIMBAL_MARGIN_DEG = 85.0


@dataclass
class ReportAxes:
    """The panels of the page."""

    attitude: Axes
    budget: Axes
    margin: Axes
    events: Axes


#: Space above the highest value of a panel, as a fraction of its range.
HEADROOM = 0.15
#: Space added above the attitude panel's data for its legend, as a fraction of the data's range.
LEGEND_ROOM = 0.25
#: Space at the top of the margin panel for the strip of missed-deadline and lost-tick marks.
MARK_STRIP = 0.45
#: The ISR's end after its tick is drawn beside its busy time when they differ by more than this
#: fraction of the axis (otherwise the two lines would lie on each other).
ISR_LINE_APART = 0.02
#: Characters of a title line before it wraps.
TITLE_WIDTH = 110


def _wrap(text: str, width: int = TITLE_WIDTH) -> str:
    return textwrap.fill(text, width=width, break_long_words=False, break_on_hyphens=False)


#: Points of one plotted series at most. Up to this many rows a series is plotted as it is; beyond,
#: as its min-max envelope over time bins (each bin's smallest and largest value at their own
#: times: every peak and dip stays visible), at most MAX_POINTS points whatever the run's length.
MAX_POINTS = 20_000


class Series:
    """One plotted line, taken in pieces, held in at most MAX_POINTS points (see MAX_POINTS)."""

    def __init__(self) -> None:
        self._t: list[NDArray[np.float64]] = []
        self._v: list[NDArray[np.float64]] = []
        self.rows = 0
        self._t0 = 0.0
        self._width = 0.0
        self._lo: NDArray[np.float64] | None = None  # per bin: smallest value, its time, largest, its time
        self._lo_t = self._hi = self._hi_t = np.zeros(0)

    def add(self, t: NDArray[Any], v: NDArray[Any]) -> None:
        t, v = np.asarray(t, dtype=np.float64), np.asarray(v, dtype=np.float64)
        if not len(t):
            return
        self.rows += len(t)
        if self._lo is None:
            self._t.append(t)
            self._v.append(v)
            if self.rows > MAX_POINTS:
                tt, vv = np.concatenate(self._t), np.concatenate(self._v)
                self._t, self._v = [], []
                self._t0 = float(tt[0])
                self._width = max(float(tt[-1] - tt[0]), 1e-9) / (MAX_POINTS // 4)
                self._lo = np.zeros(0)
                self._bin(tt, vv)
            return
        self._bin(t, v)

    def _bin(self, t: NDArray[np.float64], v: NDArray[np.float64]) -> None:
        ok = ~np.isnan(v)
        t, v = t[ok], v[ok]
        if not len(t):
            return
        idx = ((t - self._t0) // self._width).astype(np.int64)
        while int(idx.max()) >= MAX_POINTS // 2:  # too many bins: twice as wide
            self._merge()
            idx = ((t - self._t0) // self._width).astype(np.int64)
        assert self._lo is not None
        nb = int(idx.max()) + 1
        if nb > len(self._lo):
            grow = nb - len(self._lo)
            self._lo = np.r_[self._lo, np.full(grow, np.inf)]
            self._hi = np.r_[self._hi, np.full(grow, -np.inf)]
            self._lo_t = np.r_[self._lo_t, np.zeros(grow)]
            self._hi_t = np.r_[self._hi_t, np.zeros(grow)]
        for sign, val, at in ((1.0, self._lo, self._lo_t), (-1.0, self._hi, self._hi_t)):
            order = np.lexsort((sign * v, idx))
            first = np.r_[True, idx[order][1:] != idx[order][:-1]]
            k = order[first]
            b = idx[k]
            better = sign * v[k] < sign * val[b]
            val[b[better]] = v[k][better]
            at[b[better]] = t[k][better]

    def _merge(self) -> None:
        assert self._lo is not None
        n = len(self._lo) + len(self._lo) % 2
        pad = n - len(self._lo)
        lo, lo_t = np.r_[self._lo, np.full(pad, np.inf)], np.r_[self._lo_t, np.zeros(pad)]
        hi, hi_t = np.r_[self._hi, np.full(pad, -np.inf)], np.r_[self._hi_t, np.zeros(pad)]
        a = lo[1::2] < lo[0::2]
        self._lo, self._lo_t = np.where(a, lo[1::2], lo[0::2]), np.where(a, lo_t[1::2], lo_t[0::2])
        b = hi[1::2] > hi[0::2]
        self._hi, self._hi_t = np.where(b, hi[1::2], hi[0::2]), np.where(b, hi_t[1::2], hi_t[0::2])
        self._width *= 2

    def points(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The (time, value) points to plot: the rows themselves, or the envelope (time order)."""
        if self._lo is None:
            if not self._t:
                return np.zeros(0), np.zeros(0)
            return np.concatenate(self._t), np.concatenate(self._v)
        has = np.isfinite(self._lo)
        t = np.r_[self._lo_t[has], self._hi_t[has]]
        v = np.r_[self._lo[has], self._hi[has]]
        order = np.argsort(t, kind="stable")
        return t[order], v[order]


class PageData:
    """What the page plots, gathered part by part from a run's output (``emulate(..., sink=...)``
    or a whole Run as one part): bounded series, counts and the worst values."""

    def __init__(self, profile: Profile) -> None:
        self.profile = profile
        self.summary = RunSummary(profile)
        self.summary.attitude.listener = self._errors
        self.errors = {name: Series() for name in ("roll", "pitch", "yaw", "total")}
        self.gimbal = False
        self.worst: tuple[float, float, int] | None = None  # total error, time, cycle
        self.euler = [Series() for _ in range(3)]
        self.busy, self.finish, self.deadline, self.margin = Series(), Series(), Series(), Series()
        self.late, self.lost = Series(), Series()
        self.late_count = self.lost_count = 0
        self.margin_min: tuple[float, int] | None = None
        self.ticks = 0
        self.events: dict[tuple[str, str], Series] = {}
        self.alpha_error = Series()  # the wing unit's α − truth, degrees

    def add(self, part: dict[str, Any]) -> None:
        if "cycle_t_s" not in part:
            part = {**part, "cycle_t_s": part["cycle_t_ps"].astype(np.float64) * PS}
        self.summary.add(part)
        t = part["cycle_t_s"]
        for k in range(3):
            self.euler[k].add(t, part["cycle_euler_deg"][:, k])
        if "wing_alpha_deg" in part and "truth_alpha_deg" in part:
            e = wrap_deg(part["wing_alpha_deg"] - part["truth_alpha_deg"])
            known = np.isfinite(e)
            self.alpha_error.add(t[known], e[known])
        self._budget({k.removeprefix("budget_"): v for k, v in part.items() if k.startswith("budget_")})
        for e in part["events"]:
            key = (e["severity"], e["kind"])
            self.events.setdefault(key, Series()).add(np.array([e["t_s"]]), np.zeros(1))

    def _errors(self, rows: dict[str, Any], valid: NDArray[np.bool_], err: Any) -> None:
        t = rows["t"][valid]
        # Roll and yaw are undefined at pitch ±90°: their errors are left out near it.
        truth_pitch = np.degrees(quaternion.to_euler(np.asarray(rows["truth"])[valid])[1])
        gimbal = np.abs(truth_pitch) > GIMBAL_MARGIN_DEG
        self.gimbal |= bool(gimbal.any())
        for name in ("roll", "pitch", "yaw"):
            self.errors[name].add(t, np.where(gimbal, np.nan, getattr(err, name)))
        self.errors["total"].add(t, err.total)
        k = int(np.argmax(err.total))
        if self.worst is None or err.total[k] > self.worst[0]:
            step = rows["step"][valid][k] if rows["step"] is not None else 0
            self.worst = (float(err.total[k]), float(t[k]), int(step))

    def _budget(self, b: dict[str, NDArray[Any]]) -> None:
        if not len(b["tick"]):
            return
        self.ticks += len(b["tick"])
        ran = b["deadline_ps"] > b["tick_ps"]
        tick_s = b["tick_ps"].astype(np.float64) * PS
        us = PS * 1e6
        busy = (b["end_ps"].astype(np.float64) - b["start_ps"]) * us
        finish = (b["end_ps"].astype(np.float64) - b["tick_ps"]) * us
        deadline = (b["deadline_ps"].astype(np.float64) - b["tick_ps"]) * us
        self.busy.add(tick_s[ran], busy[ran])
        self.finish.add(tick_s[ran], finish[ran])
        self.deadline.add(tick_s[ran], deadline[ran])
        self.margin.add(tick_s[ran], (deadline - finish)[ran])
        late = ran & (finish > deadline)
        self.late.add(tick_s[late], finish[late])
        self.late_count += int(late.sum())
        self.lost.add(tick_s[~ran], np.zeros(int((~ran).sum())))
        self.lost_count += int((~ran).sum())
        if ran.any():
            margin = (deadline - finish)[ran]
            k = int(np.argmin(margin))
            if self.margin_min is None or margin[k] < self.margin_min[0]:
                self.margin_min = (float(margin[k]), int(b["tick"][ran][k]))

    @classmethod
    def of_run(cls, run: Run) -> PageData:
        data = cls(run.profile)
        data.add(run_part(run))
        return data


def _alpha_panel(ax: Axes, data: PageData) -> None:
    """The wing unit's α error against the trace's truth, with its static and dynamic figures."""
    ax.plot(*data.alpha_error.points(), color="black", lw=0.8, label="α − truth")
    ax.set_ylabel("α − truth (°)")
    w = data.summary.alpha_result()
    figures = "; ".join(
        f"{name} RMS {w[name]['rms_deg']:.3g}°, max {w[name]['max_abs_deg']:.3g}°, "
        f"p95 {w[name]['p95_abs_deg']:.3g}°"
        for name in ("static", "dynamic")
        if w[name]["steps"]
    )
    ax.set_title(_wrap(f"Hinge angle α error: {figures}"), loc="left", fontsize=10)
    lo, hi = ax.get_ylim()
    ax.set_ylim(lo, hi + LEGEND_ROOM * (hi - lo))
    ax.legend(loc="upper left", fontsize=8)
    ax.grid(alpha=0.3)


def _attitude_panel(ax: Axes, data: PageData) -> None:
    if data.alpha_error.rows:  # the wing unit: its output is α
        _alpha_panel(ax, data)
        return
    if data.worst is None:
        for k, name in enumerate(("roll", "pitch", "yaw")):
            ax.plot(*data.euler[k].points(), color=ANGLE_COLORS[k], lw=0.8, label=name)
        ax.set_ylabel("attitude (°)")
        ax.set_title("Attitude estimate (the trace has no truth)", loc="left", fontsize=10)
    else:
        for k, name in enumerate(("roll", "pitch", "yaw")):
            ax.plot(*data.errors[name].points(), color=ANGLE_COLORS[k], lw=0.8, label=f"{name} error")
        ax.plot(
            *data.errors["total"].points(), color="black", lw=0.8, ls="--", label="total (rotation angle)"
        )
        if data.gimbal:
            ax.plot([], [], " ", label=f"Euler errors hidden where |pitch| > {GIMBAL_MARGIN_DEG:g}°")
        ax.set_ylabel("estimate − truth (°)")
        worst, at, cycle = data.worst
        title = f"Attitude error: largest {worst:.3g}° at {at:.3f} s (cycle {cycle})"
        ax.set_title(_wrap(title), loc="left", fontsize=10)
    lo, hi = ax.get_ylim()
    ax.set_ylim(lo, hi + LEGEND_ROOM * (hi - lo))  # the legend sits above the data, not on it
    ax.legend(loc="upper left", fontsize=8, ncol=5)
    ax.grid(alpha=0.3)


def _budget_panel(ax: Axes, margin_ax: Axes, data: PageData) -> None:
    """The ISR's time per tick on an axis scaled to the work, and the margin to the deadline on its
    own axis (zero is the deadline); missed deadlines and lost ticks as marks in a strip along the
    margin axis's top, never over the data."""
    t_busy, busy = data.busy.points()
    t_end, end = data.finish.points()
    ax.plot(t_busy, busy, color="tab:blue", lw=0.8, label="ISR busy")
    top = max(float(np.max(end)) if len(end) else 0.0, float(np.max(busy)) if len(busy) else 0.0)
    # The end after the tick differs from the busy time only by the ISR's start latency; drawn when
    # that shows (queued ticks start late), otherwise it would lie on the busy line.
    start_latency = float(np.max(end) - np.max(busy)) if len(end) and len(busy) else 0.0
    if start_latency > ISR_LINE_APART * top:
        ax.plot(t_end, end, color="tab:orange", lw=0.8, label="ISR end after its tick")
    ax.set_ylim(0, top * (1 + HEADROOM) if top > 0 else 1.0)
    ax.set_ylabel("µs")
    period = float(np.median(data.deadline.points()[1])) if data.deadline.rows else None
    if len(busy):
        typical, longest = float(np.median(busy)), float(np.max(busy))
        text = f"ISR busy per timer tick: typical {typical:.1f} µs, longest {longest:.1f} µs"
        if start_latency > ISR_LINE_APART * top:
            text += f"; ends up to {float(np.max(end)):.1f} µs after its tick"
        if period:
            text += f" (the next tick comes {period:.0f} µs after)"
    else:
        text = "ISR busy per timer tick: no ISR ran"
    ax.set_title(_wrap(text), loc="left", fontsize=10)
    ax.legend(loc="lower left", fontsize=8, ncol=2)
    ax.grid(alpha=0.3)

    t_margin, margin = data.margin.points()
    margin_ax.plot(t_margin, margin, color="tab:green", lw=0.8, label="margin to the deadline")
    margin_ax.axhline(0.0, color="tab:red", lw=1.0, ls="--", label="deadline")
    lo = min(0.0, float(np.min(margin))) if len(margin) else 0.0
    hi = max(0.0, float(np.max(margin))) if len(margin) else 1.0
    span = (hi - lo) or 1.0
    # Room at the top for the strip of marks.
    margin_ax.set_ylim(lo - HEADROOM * span, hi + MARK_STRIP * span)
    if data.late_count:
        _marks(margin_ax, data.late, 0.93, "tab:red", f"missed deadline ({data.late_count})")
    if data.lost_count:
        _marks(margin_ax, data.lost, 0.83, "black", f"tick lost or dropped ({data.lost_count})")
    smallest = (
        f"smallest {data.margin_min[0]:.1f} µs at tick {data.margin_min[1]}"
        if data.margin_min is not None
        else "no ISR ran"
    )
    margin_ax.set_title(_wrap(f"Margin to the deadline: {smallest}"), loc="left", fontsize=10)
    margin_ax.set_ylabel("µs")
    margin_ax.legend(loc="lower left", fontsize=8, ncol=4)
    margin_ax.grid(alpha=0.3)


def _marks(ax: Axes, times: Series, height: float, color: str, label: str) -> None:
    """A row of ticks at the times of ``times`` in the mark strip, ``height`` up the axes (a fraction)."""
    t = times.points()[0]
    strip = ax.get_xaxis_transform()  # x in data, y in axes fraction
    ax.plot(t, np.full(len(t), height), "|", color=color, ms=7, transform=strip, label=label)


def _events_panel(ax: Axes, data: PageData) -> None:
    counts = {k: v["count"] for k, v in data.summary.kinds.items()}
    kinds = sorted(counts)
    if not kinds:
        ax.text(0.5, 0.5, "no events", ha="center", va="center", transform=ax.transAxes, fontsize=12)
        ax.set_yticks([])
    else:
        row = {k: i for i, k in enumerate(kinds)}
        for severity, color in SEVERITY_COLORS.items():
            mine = {kind: s for (sev, kind), s in data.events.items() if sev == severity}
            if mine:
                t = np.concatenate([s.points()[0] for s in mine.values()])
                y = np.concatenate([np.full(len(s.points()[0]), row[k]) for k, s in mine.items()])
                n = sum(s.rows for s in mine.values())
                ax.plot(t, y, "|", color=color, ms=10, label=f"{severity} ({n})")
        ax.set_yticks(range(len(kinds)), [f"{k} ({counts[k]})" for k in kinds], fontsize=8)
        ax.set_ylim(-0.7, len(kinds) - 0.3)
        ax.legend(loc="lower right", bbox_to_anchor=(1.0, 1.0), fontsize=8, ncol=3, frameon=False)
    ax.set_title("Events", loc="left", fontsize=10)
    ax.set_xlabel("emulated time (s)")
    ax.grid(alpha=0.3, axis="x")


def report_figure(run: Run | PageData, *, title: str = "") -> tuple[Figure, ReportAxes]:
    """The one-page report of ``run`` (a Run, or the PageData gathered from its streamed output) as
    a matplotlib figure (time axes shared)."""
    data = run if isinstance(run, PageData) else PageData.of_run(run)
    fig, (a1, a2, a3, a4) = plt.subplots(
        4, 1, figsize=FIGSIZE, dpi=DPI, sharex=True, gridspec_kw={"height_ratios": [3, 1.5, 1.5, 1.4]}
    )
    _attitude_panel(a1, data)
    _budget_panel(a2, a3, data)
    _events_panel(a4, data)
    overrides = " ".join(data.profile.overrides)
    head = title or "sins-fw run"
    fig.suptitle(
        _wrap(
            f"{head} — profile {Path(data.profile.source).name} {overrides}".rstrip()
            + f" — {data.summary.cycles} cycles, {data.ticks} ticks, {data.summary.events_total} events",
            TITLE_WIDTH - 10,
        ),
        fontsize=11,
    )
    fig.tight_layout()
    return fig, ReportAxes(a1, a2, a3, a4)


def save_report(
    run: Run | PageData, path: str | os.PathLike[str], *, title: str = ""
) -> tuple[Path, ReportAxes]:
    """Render the report of ``run`` to a PNG at ``path`` (temporary file + rename)."""
    out = Path(path)
    fig, axes = report_figure(run, title=title)
    save_png(fig, out, DPI)
    return out, axes
