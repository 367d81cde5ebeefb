"""A one-page static report of a run for people without the Rerun viewer (matplotlib, Agg backend):
the attitude error against truth (or the attitude itself when the trace has no truth), the ISR budget
per timer tick against its deadline, and the events in time.

:func:`report_figure` returns the figure and its axes (the tests read the plotted data back);
:func:`save_report` writes the PNG atomically.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # no display needed; set before pyplot is imported anywhere in this process
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from sins_fw import quaternion
from sins_fw.atomic import atomic_path
from sins_fw.harness import PS, Run
from sins_fw.metrics import attitude_errors
from sins_fw.report import aligned_estimate

#: Page size in inches and resolution: 1100 × 850 pixels.
FIGSIZE = (11.0, 8.5)
DPI = 100
SEVERITY_COLORS = {"info": "tab:blue", "warning": "tab:orange", "error": "tab:red"}
ANGLE_COLORS = ("tab:red", "tab:green", "tab:blue")
#: Within this many degrees of pitch ±90° roll and yaw are ill-conditioned (their errors are hidden).
GIMBAL_MARGIN_DEG = 85.0


@dataclass
class ReportAxes:
    """The three panels of the page."""

    attitude: Axes
    budget: Axes
    events: Axes


def _truth_rows(run: Run) -> np.ndarray | None:
    if run.truth_q is None:
        return None
    ok = np.isfinite(run.truth_q).all(axis=1)
    return ok if ok.any() else None


def _attitude_panel(ax: Axes, run: Run) -> None:
    ok = _truth_rows(run)
    if ok is None:
        for k, name in enumerate(("roll", "pitch", "yaw")):
            ax.plot(run.time_s, run.euler_deg[:, k], color=ANGLE_COLORS[k], lw=0.8, label=name)
        ax.set_ylabel("attitude (°)")
        ax.set_title("Attitude estimate (the trace has no truth)", loc="left", fontsize=10)
    else:
        err = attitude_errors(aligned_estimate(run)[0][ok], run.truth_q[ok])
        t = run.time_s[ok]
        # Roll and yaw are undefined at pitch ±90°: their errors are left out near it.
        truth_pitch = np.degrees(quaternion.to_euler(run.truth_q[ok])[1])
        gimbal = np.abs(truth_pitch) > GIMBAL_MARGIN_DEG
        for k, name in enumerate(("roll", "pitch", "yaw")):
            e = np.where(gimbal, np.nan, getattr(err, name))
            ax.plot(t, e, color=ANGLE_COLORS[k], lw=0.8, label=f"{name} error")
        ax.plot(t, err.total, color="black", lw=0.8, ls="--", label="total (rotation angle)")
        if gimbal.any():
            ax.plot([], [], " ", label=f"Euler errors hidden where |pitch| > {GIMBAL_MARGIN_DEG:g}°")
        ax.set_ylabel("estimate − truth (°)")
        worst = int(np.argmax(err.total))
        cycle = int(run.step[ok][worst])
        title = f"Attitude error: largest {err.total[worst]:.3g}° at {t[worst]:.3f} s (cycle {cycle})"
        ax.set_title(title, loc="left", fontsize=10)
    ax.legend(loc="upper left", fontsize=8, ncol=4)
    ax.grid(alpha=0.3)


def _budget_panel(ax: Axes, run: Run) -> None:
    b = run.budget
    ran = run.isr_ran
    tick_s = b["tick_ps"].astype(np.float64) * PS
    us = PS * 1e6
    busy = (b["end_ps"].astype(np.float64) - b["start_ps"]) * us
    finish = (b["end_ps"].astype(np.float64) - b["tick_ps"]) * us
    deadline = (b["deadline_ps"].astype(np.float64) - b["tick_ps"]) * us
    ax.plot(tick_s[ran], busy[ran], color="tab:blue", lw=0.8, label="ISR busy")
    ax.plot(tick_s[ran], finish[ran], color="tab:orange", lw=0.8, label="ISR end after its tick")
    ax.plot(tick_s[ran], deadline[ran], color="tab:red", lw=1.0, label="deadline (next tick)")
    late = ran & (finish > deadline)
    if late.any():
        ax.plot(
            tick_s[late],
            finish[late],
            "x",
            color="tab:red",
            ms=4,
            label=f"missed deadline ({int(late.sum())})",
        )
    if (~ran).any():
        ax.plot(
            tick_s[~ran],
            np.zeros(int((~ran).sum())),
            "v",
            color="black",
            ms=4,
            label=f"tick lost or dropped ({int((~ran).sum())})",
        )
    ax.set_ylabel("µs after the tick")
    margin = deadline - finish
    worst = (
        f"smallest margin {margin[ran].min():.1f} µs at tick {int(b['tick'][ran][np.argmin(margin[ran])])}"
        if ran.any()
        else "no ISR ran"
    )
    ax.set_title(f"ISR budget per timer tick: {worst}", loc="left", fontsize=10)
    ax.set_ylim(bottom=0)
    ax.legend(loc="upper left", fontsize=8, ncol=5)
    ax.grid(alpha=0.3)


def _events_panel(ax: Axes, run: Run) -> None:
    kinds = sorted({e["kind"] for e in run.events})
    if not kinds:
        ax.text(0.5, 0.5, "no events", ha="center", va="center", transform=ax.transAxes, fontsize=12)
        ax.set_yticks([])
    else:
        row = {k: i for i, k in enumerate(kinds)}
        for severity, color in SEVERITY_COLORS.items():
            sel = [e for e in run.events if e["severity"] == severity]
            if sel:
                ax.plot(
                    [e["t_s"] for e in sel],
                    [row[e["kind"]] for e in sel],
                    "|",
                    color=color,
                    ms=10,
                    label=f"{severity} ({len(sel)})",
                )
        counts = run.events_by_kind()
        ax.set_yticks(range(len(kinds)), [f"{k} ({counts[k]})" for k in kinds], fontsize=8)
        ax.set_ylim(-0.7, len(kinds) - 0.3)
        ax.legend(loc="upper right", fontsize=8)
    ax.set_title("Events", loc="left", fontsize=10)
    ax.set_xlabel("emulated time (s)")
    ax.grid(alpha=0.3, axis="x")


def report_figure(run: Run, *, title: str = "") -> tuple[Figure, ReportAxes]:
    """The one-page report of ``run`` as a matplotlib figure (time axes shared)."""
    fig, (a1, a2, a3) = plt.subplots(
        3, 1, figsize=FIGSIZE, dpi=DPI, sharex=True, gridspec_kw={"height_ratios": [3, 2, 1.4]}
    )
    _attitude_panel(a1, run)
    _budget_panel(a2, run)
    _events_panel(a3, run)
    overrides = " ".join(run.profile.overrides)
    head = title or "sins-fw run"
    fig.suptitle(
        f"{head} — profile {Path(run.profile.source).name} {overrides}".rstrip()
        + f" — {run.cycles} cycles, {len(run.budget['tick'])} ticks, {len(run.events)} events",
        fontsize=11,
    )
    fig.tight_layout()
    return fig, ReportAxes(a1, a2, a3)


def save_report(run: Run, path: str | os.PathLike[str], *, title: str = "") -> tuple[Path, ReportAxes]:
    """Render the report of ``run`` to a PNG at ``path`` (temporary file + rename)."""
    out = Path(path)
    fig, axes = report_figure(run, title=title)
    try:
        with atomic_path(out) as tmp:
            fig.savefig(tmp, format="png", dpi=DPI)
    finally:
        plt.close(fig)
    return out, axes
